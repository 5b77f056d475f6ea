//! `garnet train --recipe recipes/GARMENT-VARIANT.toml`: trains a GarNet network for one
//! garment of a dataset by a recipe (network, loss, schedule, training drapes; see
//! [`model::recipe`]), with validation each epoch, best and last checkpoints, `--resume`, a
//! progress bar with the loss terms and a metrics log (`metrics.csv`). The checkpoints store
//! the recipe, so `garnet export` puts the command on the model card.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use burn::module::Module;
use clap::Args;
use dataset::batches::{BatchOptions, Batches, Order};
use dataset::Dataset;
use garnet::drapes::{check_body_skinning, keep_drapes};
use garnet::export::recipe_filter;
use indicatif::{ProgressBar, ProgressStyle};
use model::{BodyTopology, ModelSetup, Recipe, RecipeRecord, Sample, Trainer};

use crate::log_lines::{LogLines, LOG_EVERY};
use crate::model_device::DeviceArg;

/// Arguments of `garnet train`.
#[derive(Args, Debug, Clone)]
pub struct TrainArgs {
    /// The training recipe (TOML: garment, variant, dataset, network, loss, schedule,
    /// training drapes); one per shipped model in `recipes/`.
    #[arg(long, value_name = "FILE.toml")]
    pub recipe: PathBuf,
    /// Dataset folder, instead of the recipe's `data`.
    #[arg(long, value_name = "DIR")]
    pub data: Option<PathBuf>,
    /// Output folder (checkpoints `best.garnet`, `last.garnet`, `metrics.csv`); default
    /// `runs/GARMENT-VARIANT`.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Continue from `OUT/last.garnet` (network, optimiser and progress), or from inside an
    /// epoch where `OUT/mid-epoch.garnet` is further on; the run must have the same recipe
    /// (the epoch count aside).
    #[arg(long)]
    pub resume: bool,
    /// Epochs to complete, instead of the recipe's (a cosine schedule then ends there).
    #[arg(long, value_name = "N")]
    pub epochs: Option<usize>,
    /// A compute budget in CPU minutes of training, instead of the recipe's `[schedule]
    /// minutes` (the cosine then ends there; a resumed run keeps the time it has used).
    #[arg(long, value_name = "MINUTES")]
    pub minutes: Option<f64>,
    /// Train on at most this many training samples (quick runs), instead of the recipe's.
    #[arg(long, value_name = "N")]
    pub max_samples: Option<usize>,
    /// Seed of the per-epoch shuffle, instead of the recipe's.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Where the network runs.
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    pub device: DeviceArg,
}

impl TrainArgs {
    /// The recipe with this command line's overrides applied, and the command that names
    /// them (for model cards).
    pub fn recipe_record(&self) -> anyhow::Result<RecipeRecord> {
        let mut recipe = Recipe::load(&self.recipe)?;
        let mut command = format!("garnet train --recipe {}", self.recipe.display());
        if let Some(d) = &self.data {
            recipe.data = d.clone();
            command += &format!(" --data {}", d.display());
        }
        if let Some(e) = self.epochs {
            recipe.schedule.epochs = e;
            command += &format!(" --epochs {e}");
        }
        if let Some(m) = self.minutes {
            recipe.schedule.minutes = Some(m);
            command += &format!(" --minutes {m}");
        }
        if let Some(n) = self.max_samples {
            recipe.drapes.max_samples = Some(n);
            command += &format!(" --max-samples {n}");
        }
        if let Some(s) = self.seed {
            recipe.schedule.seed = s;
            command += &format!(" --seed {s}");
        }
        recipe.validate().with_context(|| {
            format!(
                "{} with the command line's overrides",
                self.recipe.display()
            )
        })?;
        Ok(RecipeRecord { recipe, command })
    }
}

/// A dataset's samples of one garment and split, as the network's training samples.
pub struct GarmentSplit<'a> {
    data: &'a Dataset,
    topology: BodyTopology,
    /// The anchors M is placed with when the network's base is anchored (`None`: the
    /// stored DQS warp).
    pub anchors: Option<std::sync::Arc<garment::warp::SurfaceAnchors>>,
    /// Stored sample indices.
    pub indices: Vec<u64>,
}

impl<'a> GarmentSplit<'a> {
    /// The samples of `garment` in `split` of `data`; errors when there are none.
    pub fn new(data: &'a Dataset, split: &str, garment: &str) -> anyhow::Result<Self> {
        let indices = data.select(Some(split), Some(garment))?;
        if indices.is_empty() {
            bail!(
                "{}: no '{garment}' samples in split '{split}'",
                data.dir().display()
            );
        }
        let faces = data.body_faces()?;
        let first = data.sample(indices[0])?;
        let topology = BodyTopology::new(first.arrays.body.len(), faces)?;
        Ok(Self {
            data,
            topology,
            anchors: None,
            indices,
        })
    }

    /// The garment template the samples share (metres).
    pub fn template(&self) -> anyhow::Result<std::sync::Arc<garment::GarmentTemplate>> {
        let first = self.data.sample(self.indices[0])?;
        Ok(self.data.template(&first.record.template)?)
    }

    /// The first sample's posed body `[V]` (metres): the reference of the body sampling.
    pub fn reference_body(&self) -> anyhow::Result<Vec<glam::Vec3>> {
        Ok(self.data.sample(self.indices[0])?.arrays.body)
    }

    /// Batches of the samples in `order` after the first `skip` (never read), converted to
    /// network samples (with targets).
    pub fn batches(
        &self,
        batch_size: usize,
        order: Order,
        skip: usize,
    ) -> impl Iterator<Item = Result<Vec<Sample>, String>> + '_ {
        let opts = BatchOptions {
            batch_size,
            order,
            drop_last: false,
        };
        let batches = Batches::new(self.data, &self.indices, opts).skip_batches(skip);
        batches.map(move |b| {
            let b = b.map_err(|e| e.to_string())?;
            b.into_iter()
                .map(|s| {
                    let a = s.arrays;
                    let warped = match &self.anchors {
                        Some(anchors) => anchors.place(&geom::TriMesh::new(
                            a.body.clone(),
                            self.topology.faces.clone(),
                        )),
                        None => a.warped,
                    };
                    Sample::new(a.body, &self.topology, warped, Some(a.draped))
                        .map_err(|e| format!("sample {}: {e}", s.record.index))
                })
                .collect()
        })
    }
}

/// Runs `garnet train`.
pub fn run(args: &TrainArgs) -> anyhow::Result<()> {
    let record = args.recipe_record()?;
    let recipe = &record.recipe;
    let garment = recipe.garment.as_str();
    let variant = recipe.variant()?;
    let data = Dataset::open(&recipe.data)?;
    let mut train = GarmentSplit::new(&data, "train", garment)?;
    let filter = recipe_filter(recipe);
    if let Some(filter) = &filter {
        let dropped = keep_drapes(&data, "train", garment, &mut train.indices, filter)?;
        eprintln!(
            "training on {} only: left out {dropped} training drapes",
            filter.describe()
        );
    }
    if let Some(n) = recipe.drapes.max_samples {
        train.indices.truncate(n);
    }
    let mut valid = GarmentSplit::new(&data, "val", garment).ok();
    let base = recipe.network_config()?.base;
    if base != model::Base::Dqs {
        let anchors = garnet::base_anchors(base, &*train.template()?, &body::BodyModel::load()?)?;
        train.anchors = anchors.map(std::sync::Arc::new);
        if let Some(v) = &mut valid {
            v.anchors = train.anchors.clone();
        }
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{garment}-{}", variant.name())));
    let device = args.device.device()?;
    let s = &recipe.schedule;
    let checkpoint_every = checkpoint_interval(s.checkpoint_minutes)?;
    let from = match args.resume {
        true => Trainer::resume_point(&out)
            .with_context(|| format!("choosing the checkpoint to resume in {}", out.display()))?,
        false => None,
    };
    let mut trainer = if let Some(from) = &from {
        let trainer = Trainer::resume(from, Some(s.lr), &device)
            .with_context(|| format!("resuming {}", from.display()))?;
        match &trainer.state().partial {
            Some(p) => eprintln!(
                "resuming from {} inside epoch {}, after {} batches",
                from.display(),
                trainer.state().epoch + 1,
                p.batches
            ),
            None => eprintln!("resuming from {}", from.display()),
        }
        check_same_recipe(trainer.recipe(), recipe, from)?;
        check_body_skinning(trainer.setup(), &data, from)?;
        trainer
    } else {
        if args.resume {
            eprintln!(
                "no {} yet: starting afresh",
                out.join(model::trainer::LAST_CHECKPOINT).display()
            );
        }
        // A stopped epoch of the run this one replaces: --resume must not go back to it.
        let stale = out.join(model::trainer::MID_EPOCH_CHECKPOINT);
        if stale.is_file() {
            std::fs::remove_file(&stale)
                .with_context(|| format!("removing {}", stale.display()))?;
            eprintln!(
                "removed {}: it was a stopped epoch of the run this one replaces",
                stale.display()
            );
        }
        let template = train.template()?;
        let garment_file = template.to_bytes(&recipe.data)?;
        let setup = ModelSetup::new(
            recipe.network_config()?,
            template.mesh.clone(),
            &train.reference_body()?,
        )?
        .with_garment_file(garment_file)
        .with_body_skinning(data.body_skinning().name())?
        .with_body_faces(train.topology.faces.clone())?;
        Trainer::new(setup, recipe.loss_config()?, s.lr, &device)?
    };
    // The count is part of the name: a dataset still being generated grows its validation
    // split, and a best figure measured on fewer drapes cannot be compared.
    let validation_set = format!(
        "{}:{garment}:{}",
        data.manifest().spec.name,
        valid.as_ref().map_or(0, |v| v.indices.len())
    );
    if let Some(old) = trainer.set_validation_set(&validation_set) {
        eprintln!(
            "the checkpoint's best validation E_dist ({old:.3} cm) was measured on another \
             validation set; this run validates on '{validation_set}' and starts its best afresh"
        );
    }
    trainer.set_max_grad_norm(s.grad_clip)?;
    let batches_per_epoch = train.indices.len().div_ceil(s.batch) as u64;
    trainer.set_schedule(recipe.lr_schedule(batches_per_epoch)?);
    trainer.set_budget(recipe.time_budget()?);
    trainer.set_checkpoint_every(checkpoint_every);
    trainer.set_training_set(&training_set_name(&data, &train.indices, recipe));
    trainer.set_recipe(record.clone());
    let params = trainer.model().num_params();
    eprintln!(
        "training {} ({params} parameters) on {} '{garment}' samples ({} validation) by {}, \
         into {}",
        trainer.setup().config.method_name(),
        train.indices.len(),
        valid.as_ref().map_or(0, |v| v.indices.len()),
        record.command,
        out.display()
    );
    let bar = ProgressBar::new(batches_per_epoch);
    bar.set_style(
        ProgressStyle::with_template(
            "epoch {prefix} [{bar:30}] {pos}/{len} batches {per_sec} eta {eta} {msg}",
        )?
        .progress_chars("=> "),
    );
    let (seed, batch) = (s.seed, s.batch);
    let train_batches = |epoch: usize, skip: usize| {
        bar.set_prefix((epoch + 1).to_string());
        bar.reset();
        bar.set_position(skip as u64);
        let bar = bar.clone();
        // Without a terminal (a log file) the bar is hidden: a line every few minutes.
        let mut log = LogLines::new(LOG_EVERY, "batches");
        train
            .batches(
                batch,
                Order::Shuffled {
                    seed,
                    epoch: epoch as u64,
                },
                skip,
            )
            .inspect(move |_| {
                bar.inc(1);
                if bar.is_hidden() {
                    let line = log.line(Instant::now(), bar.position(), batches_per_epoch);
                    if let Some(line) = line {
                        eprintln!("epoch {}: {line}", epoch + 1);
                    }
                }
            })
    };
    let valid_batches = valid
        .as_ref()
        .map(|v| move || v.batches(batch, Order::InOrder, 0));
    trainer.fit(s.epochs, train_batches, valid_batches, &out, |r| {
        let v = r.validation.map_or(String::new(), |v| {
            format!(
                ", val E_dist {:.3} cm E_norm {:.2} deg",
                v.e_dist_cm, v.e_norm_deg
            )
        });
        bar.suspend(|| eprintln!(
            "epoch {} ({:.1} s, {:.1} CPU min in all, lr {:.2e}): loss {:.3e} (vertex {:.3e} pen {:.3e} norm {:.3e} bend {:.3e} curvature {:.3e}), grad norm {:.3e}{v}{}",
            r.epoch,
            r.seconds,
            r.train_cpu_s / 60.0,
            r.lr,
            r.train.total,
            r.train.vertex,
            r.train.pen,
            r.train.norm,
            r.train.bend,
            r.train.curvature,
            r.grad_norm,
            if r.is_best { " *best" } else { "" }
        ))
    })?;
    bar.finish_and_clear();
    let (last, best, metrics) = Trainer::output_paths(&out);
    eprintln!(
        "wrote {}, {} and {}",
        best.display(),
        last.display(),
        metrics.display()
    );
    Ok(())
}

/// Fails, naming the checkpoint `from`, when the run it belongs to was trained by another
/// recipe than `recipe` (the epoch count and budget aside: a run may be extended), or by
/// none.
fn check_same_recipe(
    stored: Option<&RecipeRecord>,
    recipe: &Recipe,
    from: &Path,
) -> anyhow::Result<()> {
    let Some(stored) = stored else {
        bail!(
            "{}: the checkpoint records no recipe; train into another --out",
            from.display()
        );
    };
    let mut same_epochs = stored.recipe.clone();
    same_epochs.schedule.epochs = recipe.schedule.epochs;
    same_epochs.schedule.minutes = recipe.schedule.minutes;
    if &same_epochs != recipe {
        bail!(
            "{}: the run was trained by another recipe ({}); resume it with that recipe or \
             train into another --out",
            from.display(),
            stored.command
        );
    }
    Ok(())
}

/// The recipe's `checkpoint_minutes` as the interval of mid-epoch checkpoints (`None` for 0: none).
fn checkpoint_interval(minutes: f64) -> anyhow::Result<Option<Duration>> {
    if !(minutes.is_finite() && minutes >= 0.0) {
        bail!("checkpoint_minutes must be 0 (none) or more, got {minutes}");
    }
    Ok((minutes > 0.0).then(|| Duration::from_secs_f64(minutes * 60.0)))
}

/// The name of the training set and order a run's epochs take, which a mid-epoch checkpoint
/// must be resumed with: the dataset, garment, sample count and a hash of the samples, the
/// batch size, the shuffle's seed and the shards read together (the shuffle's window).
fn training_set_name(data: &Dataset, indices: &[u64], recipe: &Recipe) -> String {
    let bytes: Vec<u8> = indices.iter().flat_map(|k| k.to_le_bytes()).collect();
    format!(
        "{}:{}:{} samples (sha256 {}), batch {}, seed {}, {} shards a window",
        data.manifest().spec.name,
        recipe.garment,
        indices.len(),
        &dataset::hash::sha256_hex(&bytes)[..16],
        recipe.schedule.batch,
        recipe.schedule.seed,
        data.cache_shards()
    )
}
