//! `garnet train`: trains a GarNet variant for one garment of a dataset, with validation
//! each epoch, best and last checkpoints, `--resume`, a progress bar with the loss terms
//! and a metrics log (`metrics.csv`).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use burn::module::Module;
use clap::{Args, ValueEnum};
use dataset::batches::{BatchOptions, Batches, Order};
use dataset::Dataset;
use indicatif::{ProgressBar, ProgressStyle};
use model::{
    BodyTopology, CosineSchedule, GarNetConfig, LossConfig, ModelSetup, Sample, Trainer, Variant,
    PAPER_LEARNING_RATE,
};

use crate::drape_filter_args::{filter_flags, keep_drapes, DrapeFilterArgs};
use crate::log_lines::{LogLines, LOG_EVERY};
use crate::model_device::DeviceArg;

/// Arguments of `garnet train`.
#[derive(Args, Debug, Clone)]
pub struct TrainArgs {
    /// Dataset folder (made by `garnet dataset generate`).
    #[arg(long, value_name = "DIR")]
    pub data: PathBuf,
    /// Garment name in the dataset (tshirt, sweater, jeans unless the spec named them).
    #[arg(long)]
    pub garment: String,
    /// Network variant.
    #[arg(long, value_enum, default_value_t = VariantArg::Local)]
    pub variant: VariantArg,
    /// Epochs to complete (counting those of a resumed run).
    #[arg(long, default_value_t = 30)]
    pub epochs: usize,
    /// Samples per batch.
    #[arg(long, default_value_t = 8)]
    pub batch: usize,
    /// Adam learning rate (the paper: 1e-3).
    #[arg(long, default_value_t = PAPER_LEARNING_RATE)]
    pub lr: f64,
    /// Clip the gradients of each step to this joint L2 norm (as PyTorch's
    /// `clip_grad_norm_`); kept by a resumed run unless given again. The metrics log's
    /// `train_grad_norm` column shows the norms before clipping.
    #[arg(long, value_name = "NORM")]
    pub grad_clip: Option<f32>,
    /// Mirror every other training sample left-right through the garment's plane of
    /// symmetry (a reflected drape is another valid drape: twice the drapes seen per
    /// epoch); kept by a resumed run.
    #[arg(long)]
    pub mirror: bool,
    /// Anneal the learning rate along half a cosine from --lr (at the epoch this run starts
    /// from) to this rate at --epochs; resuming with the same command continues the schedule.
    #[arg(long, value_name = "LR")]
    pub cosine_to: Option<f64>,
    /// With --cosine-to: change the rate at every step instead of once an epoch, so that a
    /// schedule of a few long epochs ends at --cosine-to (the metrics log then shows each
    /// epoch's last rate). Part of the schedule's plan: resume with it given again.
    #[arg(long, requires = "cosine_to")]
    pub cosine_per_step: bool,
    /// Output folder (checkpoints `best.garnet`, `last.garnet`, `metrics.csv`); default
    /// `runs/GARMENT-VARIANT`.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Continue from `OUT/last.garnet` (network, optimiser and progress), or from inside
    /// an epoch where `OUT/mid-epoch.garnet` is further on (see --checkpoint-minutes).
    #[arg(long)]
    pub resume: bool,
    /// Inside an epoch, write `OUT/mid-epoch.garnet` every this many minutes (0: never),
    /// so that a run stopped inside a long epoch resumes there with --resume, on the same
    /// training set, batch size and seed. Removed when the epoch ends.
    #[arg(long, value_name = "MINUTES", default_value_t = 10.0)]
    pub checkpoint_minutes: f64,
    /// Also keep every epoch's checkpoint as `OUT/epoch-N.garnet` (with the optimiser
    /// state, about 9 MB for GarNet-Local): snapshots for `garnet average`, or to branch a
    /// run from (copy one to another folder's `last.garnet` and `--resume` there).
    #[arg(long)]
    pub keep_epochs: bool,
    /// Train on at most this many training samples (quick runs).
    #[arg(long, value_name = "N")]
    pub max_samples: Option<usize>,
    /// Which training drapes to use (validation keeps every sample).
    #[command(flatten)]
    pub drapes: DrapeFilterArgs,
    /// Loss weights: turn a term off for ablations (L_vertex stays).
    #[arg(long)]
    pub no_pen: bool,
    /// See --no-pen.
    #[arg(long)]
    pub no_norm: bool,
    /// See --no-pen.
    #[arg(long)]
    pub no_bend: bool,
    /// L_vertex averages each vertex's distance to this power, in [1, 2]: 2 is the paper's
    /// squared distance, 1 the distance itself (what E_dist reports; far-off vertices of
    /// poorly settled drapes pull no harder than the rest). Given with --resume, it changes
    /// the resumed run's loss from then on (a fine-tune); otherwise a resumed run keeps its
    /// loss.
    #[arg(long, value_name = "P")]
    pub vertex_power: Option<f64>,
    /// Weight of L_vertex (the paper: 1; the other weights stay the paper's). With
    /// --vertex-power 1 in cm, a weight of 2 pulls a vertex 1 cm off as hard as the squared
    /// loss does. With --resume, as --vertex-power.
    #[arg(long, value_name = "W")]
    pub vertex_weight: Option<f64>,
    /// Length unit of the loss terms (the paper's weights balance them in centimetres).
    #[arg(long, value_enum, default_value_t = LossUnit::Cm)]
    pub loss_unit: LossUnit,
    /// The body stream sees every N-th body vertex (farthest-point order; 4 gives 3345 of
    /// the 13380, 2 the paper's ~6.9k). A new run only: a resumed run keeps its network.
    #[arg(long, value_name = "N")]
    pub body_subsample: Option<usize>,
    /// The network's widths as a JSON file of `GarNetConfig` fields (any left out take their
    /// defaults; `--variant` and `--body-subsample` override the file). A new run only: a
    /// resumed run keeps its network.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Seed of the per-epoch shuffle.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Where the network runs.
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    pub device: DeviceArg,
}

/// The three GarNet variants on the command line.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum VariantArg {
    /// GarNet-Local (global and local body features, mesh convolutions).
    Local,
    /// GarNet-Global (global body features, mesh convolutions).
    Global,
    /// GarNet-Naive (two-stream PointNet, no mesh convolution).
    Naive,
}

impl From<VariantArg> for Variant {
    fn from(v: VariantArg) -> Self {
        match v {
            VariantArg::Local => Variant::Local,
            VariantArg::Global => Variant::Global,
            VariantArg::Naive => Variant::Naive,
        }
    }
}

/// Length unit of the loss on the command line.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum LossUnit {
    /// Centimetres (L_vertex in cm^2).
    Cm,
    /// Metres.
    M,
}

/// A dataset's samples of one garment and split, as the network's training samples.
pub struct GarmentSplit<'a> {
    data: &'a Dataset,
    topology: BodyTopology,
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
                    Sample::new(
                        s.arrays.body,
                        &self.topology,
                        s.arrays.warped,
                        Some(s.arrays.draped),
                    )
                    .map_err(|e| format!("sample {}: {e}", s.record.index))
                })
                .collect()
        })
    }
}

/// Reads a `--config` file: a JSON object of [`GarNetConfig`] fields over the defaults of
/// `variant`, whose variant it takes.
pub fn network_config(path: &Path, variant: Variant) -> anyhow::Result<GarNetConfig> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the network config {}", path.display()))?;
    let mut fields: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a JSON object of config fields", path.display()))?;
    let defaults = serde_json::to_value(GarNetConfig::new(variant))?;
    let serde_json::Value::Object(defaults) = defaults else {
        bail!("GarNetConfig does not serialise to an object");
    };
    if let Some(unknown) = fields.keys().find(|k| !defaults.contains_key(*k)) {
        bail!(
            "{}: unknown network config field {unknown:?} (known: {})",
            path.display(),
            defaults.keys().cloned().collect::<Vec<_>>().join(", ")
        );
    }
    let mut merged = defaults;
    merged.append(&mut fields);
    let mut config: GarNetConfig = serde_json::from_value(serde_json::Value::Object(merged))
        .with_context(|| {
            format!(
                "{}: a network config field has the wrong type",
                path.display()
            )
        })?;
    config.variant = variant;
    config
        .validate()
        .with_context(|| format!("network config {}", path.display()))?;
    Ok(config)
}

/// Runs `garnet train`.
pub fn run(args: &TrainArgs) -> anyhow::Result<()> {
    let data = Dataset::open(&args.data)?;
    let mut train = GarmentSplit::new(&data, "train", &args.garment)?;
    let filter = args.drapes.filter()?;
    if let Some(filter) = &filter {
        let dropped = keep_drapes(&data, "train", &args.garment, &mut train.indices, filter)?;
        eprintln!(
            "training on {} only: left out {dropped} training drapes",
            filter.describe()
        );
    }
    if let Some(n) = args.max_samples {
        train.indices.truncate(n.max(1));
    }
    let valid = GarmentSplit::new(&data, "val", &args.garment).ok();
    let variant: Variant = args.variant.into();
    let out = args.out.clone().unwrap_or_else(|| {
        PathBuf::from("runs").join(format!("{}-{}", args.garment, variant.name()))
    });
    let device = args.device.device()?;
    let checkpoint_every = checkpoint_interval(args.checkpoint_minutes)?;
    let from = match args.resume {
        true => Trainer::resume_point(&out)
            .with_context(|| format!("choosing the checkpoint to resume in {}", out.display()))?,
        false => None,
    };
    let resumed = from.is_some();
    let mut trainer = if let Some(from) = &from {
        let trainer = Trainer::resume(from, Some(args.lr), &device)
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
        let garment_file = template.to_bytes(&args.data)?;
        let mut config = match &args.config {
            Some(path) => network_config(path, variant)?,
            None => GarNetConfig::new(variant),
        };
        if let Some(n) = args.body_subsample {
            config.body_subsample = n;
        }
        let setup = ModelSetup::new(config, template.mesh.clone(), &train.reference_body()?)?
            .with_garment_file(garment_file)
            .with_body_skinning(data.body_skinning().name())?
            .with_body_faces(train.topology.faces.clone())?;
        Trainer::new(setup, loss_config(args), args.lr, &device)?
    };
    // The count is part of the name: a dataset still being generated grows its validation
    // split, and a best figure measured on fewer drapes cannot be compared.
    let validation_set = format!(
        "{}:{}:{}",
        data.manifest().spec.name,
        args.garment,
        valid.as_ref().map_or(0, |v| v.indices.len())
    );
    if let Some(old) = trainer.set_validation_set(&validation_set) {
        eprintln!(
            "the checkpoint's best validation E_dist ({old:.3} cm) was measured on another \
             validation set; this run validates on '{validation_set}' and starts its best afresh"
        );
    }
    if args.grad_clip.is_some() {
        trainer.set_max_grad_norm(args.grad_clip)?;
    }
    if resumed && (args.vertex_power.is_some() || args.vertex_weight.is_some()) {
        let loss = with_vertex_args(trainer.loss_config().clone(), args);
        eprintln!(
            "L_vertex from here on: weight {}, distances to the power {} (the checkpoint's: \
             weight {}, power {})",
            loss.vertex,
            loss.vertex_power,
            trainer.loss_config().vertex,
            trainer.loss_config().vertex_power
        );
        trainer.set_loss_config(loss)?;
    }
    if args.mirror {
        trainer
            .set_mirror(true)
            .with_context(|| format!("--mirror with the '{}' template", args.garment))?;
    }
    if let Some(m) = trainer.mirror_map() {
        eprintln!(
            "mirroring every other training sample through x = {:.4} m (template reflections \
             within {:.2} mm of its surface)",
            m.plane_x(),
            m.max_offset() * 1e3
        );
    }
    let batches_per_epoch = train.indices.len().div_ceil(args.batch.max(1)) as u64;
    let schedule = args
        .cosine_to
        .map(|end| CosineSchedule::new(args.lr, end, trainer.state().epoch, args.epochs))
        .transpose()?
        .map(|s| match args.cosine_per_step {
            true => s.per_step(batches_per_epoch),
            false => s,
        });
    trainer.set_schedule(schedule);
    trainer.set_keep_epochs(args.keep_epochs);
    trainer.set_checkpoint_every(checkpoint_every);
    trainer.set_training_set(&training_set_name(&data, &train.indices, args));
    trainer.set_command(crate::output::command_line());
    trainer.set_train_drapes(filter_flags(filter.as_ref()));
    let params = trainer.model().num_params();
    eprintln!(
        "training {} ({params} parameters) on {} '{}' samples ({} validation), \
         batch {}, lr {}{}{}, into {}",
        trainer.setup().config.method_name(),
        train.indices.len(),
        args.garment,
        valid.as_ref().map_or(0, |v| v.indices.len()),
        args.batch,
        args.lr,
        trainer.state().schedule.map_or(String::new(), |s| format!(
            " (cosine to {} at epoch {}, from epoch {}{})",
            s.end_lr,
            s.to_epoch,
            s.from_epoch,
            if s.steps_per_epoch.is_some() {
                ", step by step"
            } else {
                ""
            }
        )),
        trainer
            .state()
            .max_grad_norm
            .map_or(String::new(), |n| format!(
                ", gradients clipped to norm {n}"
            )),
        out.display()
    );
    let bar = ProgressBar::new(batches_per_epoch);
    bar.set_style(
        ProgressStyle::with_template(
            "epoch {prefix} [{bar:30}] {pos}/{len} batches {per_sec} eta {eta} {msg}",
        )?
        .progress_chars("=> "),
    );
    let seed = args.seed;
    let train_batches = |epoch: usize, skip: usize| {
        bar.set_prefix((epoch + 1).to_string());
        bar.reset();
        bar.set_position(skip as u64);
        let bar = bar.clone();
        // Without a terminal (a log file) the bar is hidden: a line every few minutes.
        let mut log = LogLines::new(LOG_EVERY, "batches");
        train
            .batches(
                args.batch,
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
        .map(|v| move || v.batches(args.batch, Order::InOrder, 0));
    trainer.fit(args.epochs, train_batches, valid_batches, &out, |r| {
        let v = r.validation.map_or(String::new(), |v| {
            format!(
                ", val E_dist {:.3} cm E_norm {:.2} deg",
                v.e_dist_cm, v.e_norm_deg
            )
        });
        bar.suspend(|| eprintln!(
            "epoch {} ({:.1} s, lr {:.2e}): loss {:.3e} (vertex {:.3e} pen {:.3e} norm {:.3e} bend {:.3e}), grad norm {:.3e}{v}{}",
            r.epoch,
            r.seconds,
            r.lr,
            r.train.total,
            r.train.vertex,
            r.train.pen,
            r.train.norm,
            r.train.bend,
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

/// `--checkpoint-minutes` as the interval of mid-epoch checkpoints (`None` for 0: none).
fn checkpoint_interval(minutes: f64) -> anyhow::Result<Option<Duration>> {
    if !(minutes.is_finite() && minutes >= 0.0) {
        bail!("--checkpoint-minutes must be 0 (none) or more, got {minutes}");
    }
    Ok((minutes > 0.0).then(|| Duration::from_secs_f64(minutes * 60.0)))
}

/// The name of the training set and order a run's epochs take, which a mid-epoch checkpoint
/// must be resumed with: the dataset, garment, sample count and a hash of the samples, the
/// batch size, the shuffle's seed and the shards read together (the shuffle's window).
fn training_set_name(data: &Dataset, indices: &[u64], args: &TrainArgs) -> String {
    let bytes: Vec<u8> = indices.iter().flat_map(|k| k.to_le_bytes()).collect();
    format!(
        "{}:{}:{} samples (sha256 {}), batch {}, seed {}, {} shards a window",
        data.manifest().spec.name,
        args.garment,
        indices.len(),
        &dataset::hash::sha256_hex(&bytes)[..16],
        args.batch.max(1),
        args.seed,
        data.cache_shards()
    )
}

/// Fails, naming `model`, when the network `setup` learned from bodies posed another way than
/// the dataset `data` poses them: its inputs would not be what it learned from.
pub fn check_body_skinning(
    setup: &ModelSetup,
    data: &Dataset,
    model: &std::path::Path,
) -> anyhow::Result<()> {
    let expected = data.body_skinning().name();
    if setup.body_skinning != expected {
        bail!(
            "{}: the network learned from bodies posed with {}, the dataset in {} poses them \
             with {expected}",
            model.display(),
            setup.body_skinning,
            data.dir().display()
        );
    }
    Ok(())
}

/// The paper's loss weights, with the terms `args` turned off set to zero and L_vertex's
/// power and weight from `args`.
fn loss_config(args: &TrainArgs) -> LossConfig {
    let mut cfg = LossConfig::new();
    cfg.units_per_metre = match args.loss_unit {
        LossUnit::Cm => 100.0,
        LossUnit::M => 1.0,
    };
    if args.no_pen {
        cfg.pen = 0.0;
    }
    if args.no_norm {
        cfg.norm = 0.0;
    }
    if args.no_bend {
        cfg.bend = 0.0;
    }
    with_vertex_args(cfg, args)
}

/// `cfg` with L_vertex's power and weight from `args` where given.
fn with_vertex_args(mut cfg: LossConfig, args: &TrainArgs) -> LossConfig {
    if let Some(p) = args.vertex_power {
        cfg.vertex_power = p;
    }
    if let Some(w) = args.vertex_weight {
        cfg.vertex = w;
    }
    cfg
}
