//! The training loop: epochs over an iterator of sample batches, validation after each
//! epoch, `last.garnet` and `best.garnet` checkpoints (best = lowest validation E_dist) and a
//! `metrics.csv` log; resumable from any checkpoint with its optimiser state, and from inside
//! an epoch by its mid-epoch checkpoints.

use std::fmt::Display;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use burn::optim::ModuleOptimizer;
use burn::prelude::*;
use serde::{Deserialize, Serialize};

use crate::batch::{Batch, InputSpec, Sample};
use crate::bench::process_cpu_ms;
use crate::checkpoint::{load_checkpoint, save_checkpoint, ModelSetup, TrainState};
use crate::drape::Draper;
use crate::epoch_progress::EpochProgress;
use crate::error::{ModelError, Result};
use crate::garnet::GarNet;
use crate::loss::{LossConfig, LossTerms};
use crate::metrics_log::{MetricsLog, MetricsRow};
use crate::recipe::RecipeRecord;
use crate::schedule::{CosineSchedule, TimeBudget};
use crate::topology::{GarmentTopology, TopologyTensors};
use crate::train::{adam, evaluate_batch, train_step, StepReport};

/// File name of the checkpoint written after every epoch.
pub const LAST_CHECKPOINT: &str = "last.garnet";
/// File name of the checkpoint of the epoch with the lowest validation E_dist.
pub const BEST_CHECKPOINT: &str = "best.garnet";
/// File name of the per-epoch metrics log.
pub const METRICS_LOG: &str = "metrics.csv";
/// File name of the checkpoint written inside an epoch (see
/// [`Trainer::set_checkpoint_every`]): the network, optimiser and the epoch's progress so far.
/// It is removed when the epoch ends.
pub const MID_EPOCH_CHECKPOINT: &str = "mid-epoch.garnet";

/// File name of the checkpoint that [`Trainer::set_keep_epochs`] keeps of epoch `epoch`
/// (1-based, as in `metrics.csv`): `epoch-N.garnet`.
pub fn epoch_checkpoint_name(epoch: usize) -> String {
    format!("epoch-{epoch}.garnet")
}

/// Validation results averaged over samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Validation {
    /// Loss terms.
    pub terms: LossTerms,
    /// Mean vertex distance, centimetres.
    pub e_dist_cm: f32,
    /// Mean face-normal angle, degrees.
    pub e_norm_deg: f32,
    /// Number of samples.
    pub samples: usize,
}

/// What one epoch did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EpochReport {
    /// The epoch number (1-based: epochs completed after it).
    pub epoch: usize,
    /// Training loss terms averaged over the epoch's samples.
    pub train: LossTerms,
    /// Training samples seen.
    pub train_samples: usize,
    /// Mean joint gradient norm of the epoch's steps, before clipping.
    pub grad_norm: f32,
    /// Learning rate of the epoch.
    pub lr: f64,
    /// Validation results (when a validation set was given).
    pub validation: Option<Validation>,
    /// Whether this epoch gave a new best checkpoint.
    pub is_best: bool,
    /// Wall time of the epoch including validation and checkpoints, seconds.
    pub seconds: f64,
    /// CPU time the run's training steps have used so far, every sitting, seconds (what a
    /// [`TimeBudget`] counts).
    pub train_cpu_s: f64,
}

/// Trains one network: holds it (on an autodiff device), its Adam optimiser, its setup and
/// progress. A training program is faster with [`crate::tune_allocator`] called once at
/// its start.
pub struct Trainer {
    model: GarNet,
    optim: ModuleOptimizer,
    setup: ModelSetup,
    topology: GarmentTopology,
    topo: TopologyTensors,
    topo_valid: TopologyTensors,
    spec: InputSpec,
    loss: LossConfig,
    lr: f64,
    state: TrainState,
    /// The recipe this run trains by, stored in its checkpoints.
    recipe: Option<RecipeRecord>,
    /// The name of the validation set of this run (see [`Trainer::set_validation_set`]).
    validation_set: Option<String>,
    /// Whether each epoch also writes its own checkpoint (see [`epoch_checkpoint_name`]).
    keep_epochs: bool,
    /// The name of the training set and order of this run (see [`Trainer::set_training_set`]).
    training_set: Option<String>,
    /// How often an epoch writes [`MID_EPOCH_CHECKPOINT`] (`None`: never).
    checkpoint_every: Option<Duration>,
    device: Device,
}

impl std::fmt::Debug for Trainer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Trainer")
            .field("variant", &self.setup.config.variant)
            .field("state", &self.state)
            .field("lr", &self.lr)
            .finish()
    }
}

impl Trainer {
    /// A fresh network of `setup.config` on `device` (made an autodiff device), trained with
    /// `loss` and Adam at learning rate `lr` (the paper: 1e-3).
    pub fn new(setup: ModelSetup, loss: LossConfig, lr: f64, device: &Device) -> Result<Trainer> {
        let device = device.clone().autodiff();
        let model = setup.config.init(&device)?;
        Trainer::with_parts(
            model,
            adam(),
            setup,
            loss,
            TrainState::default(),
            lr,
            device,
        )
    }

    /// Resumes from a checkpoint: network, optimiser state (a fresh Adam when the checkpoint
    /// has none), loss config, recipe and progress; `lr` overrides the stored learning rate
    /// when given.
    pub fn resume(path: &Path, lr: Option<f64>, device: &Device) -> Result<Trainer> {
        let ck = load_checkpoint(path)?;
        let device = device.clone().autodiff();
        let model = ck.model(&device)?;
        let optim = ck.optimizer()?.unwrap_or_else(adam);
        let lr = lr.unwrap_or(if ck.state.lr > 0.0 {
            ck.state.lr
        } else {
            crate::train::PAPER_LEARNING_RATE
        });
        let mut trainer =
            Trainer::with_parts(model, optim, ck.setup, ck.loss, ck.state, lr, device)?;
        trainer.recipe = ck.recipe;
        Ok(trainer)
    }

    fn with_parts(
        model: GarNet,
        optim: ModuleOptimizer,
        setup: ModelSetup,
        loss: LossConfig,
        state: TrainState,
        lr: f64,
        device: Device,
    ) -> Result<Trainer> {
        loss.validate()?;
        if !(lr.is_finite() && lr > 0.0) {
            return Err(ModelError::InvalidInput(format!(
                "learning rate must be > 0, got {lr}"
            )));
        }
        let topology = GarmentTopology::from_mesh(&setup.template)?;
        let topo = topology.to_device(&device);
        let topo_valid = topology.to_device(&device.clone().inner());
        setup.validate()?;
        let spec = setup.input_spec();
        Ok(Trainer {
            model,
            optim,
            setup,
            topology,
            topo,
            topo_valid,
            spec,
            loss,
            lr,
            state,
            recipe: None,
            validation_set: None,
            keep_epochs: false,
            training_set: None,
            checkpoint_every: None,
            device,
        })
    }

    /// The network (on the autodiff device).
    pub fn model(&self) -> &GarNet {
        &self.model
    }

    /// Setup: config, template, body sampling.
    pub fn setup(&self) -> &ModelSetup {
        &self.setup
    }

    /// Training progress.
    pub fn state(&self) -> &TrainState {
        &self.state
    }

    /// Records the recipe this run trains by in the checkpoints it writes.
    pub fn set_recipe(&mut self, recipe: RecipeRecord) {
        self.recipe = Some(recipe);
    }

    /// The recipe this run trains by, when it was given one.
    pub fn recipe(&self) -> Option<&RecipeRecord> {
        self.recipe.as_ref()
    }

    /// Names this run's validation set (say `standard-x9-lbs:tshirt:540`). A best validation
    /// E_dist that the checkpoint says was measured on another set does not compare with
    /// this run's: it is cleared, so the next validated epoch writes `best.garnet`, and
    /// returned. Every new best is stored with this name.
    pub fn set_validation_set(&mut self, name: &str) -> Option<f32> {
        self.validation_set = Some(name.to_string());
        match &self.state.validation {
            Some(old) if old != name => {
                self.state.validation = None;
                self.state.best_e_dist_cm.take()
            }
            _ => None,
        }
    }

    /// When `keep` is set, every epoch of [`Trainer::run_epoch`] also writes its checkpoint
    /// (network, Adam state and progress, as `last.garnet`) to
    /// `out_dir/`[`epoch_checkpoint_name`]: snapshots to compare epochs by, or to branch a
    /// run from (copy one to another folder's `last.garnet`).
    pub fn set_keep_epochs(&mut self, keep: bool) {
        self.keep_epochs = keep;
    }

    /// Names this run's training set and the order its epochs take it in (say the dataset,
    /// split, garment, sample count and a hash of the samples, the batch size and the
    /// shuffle's seed). A mid-epoch checkpoint stores it, and [`Trainer::fit`] refuses to
    /// go on with its epoch in another set or order: the batches it would skip would not be
    /// the ones it trained on.
    pub fn set_training_set(&mut self, name: &str) {
        self.training_set = Some(name.to_string());
    }

    /// While an epoch trains, writes [`MID_EPOCH_CHECKPOINT`] to the run's folder once
    /// `every` has passed since the epoch's start or the last such write (`None`: never),
    /// so that a run stopped inside an epoch resumes there ([`Trainer::resume_point`]).
    pub fn set_checkpoint_every(&mut self, every: Option<Duration>) {
        self.checkpoint_every = every;
    }

    /// The checkpoint a run in `out_dir` resumes from: [`MID_EPOCH_CHECKPOINT`] when it is
    /// further on than [`LAST_CHECKPOINT`] (more steps), else [`LAST_CHECKPOINT`]; `None`
    /// when neither exists. Fails when a file cannot be read as a checkpoint.
    pub fn resume_point(out_dir: &Path) -> Result<Option<PathBuf>> {
        let (last, _, _) = Trainer::output_paths(out_dir);
        let mid = out_dir.join(MID_EPOCH_CHECKPOINT);
        let steps = |p: &Path| -> Result<Option<u64>> {
            match p.is_file() {
                true => Ok(Some(load_checkpoint(p)?.state.step)),
                false => Ok(None),
            }
        };
        Ok(match (steps(&mid)?, steps(&last)?) {
            (Some(m), l) if l.is_none_or(|l| m > l) => Some(mid),
            (_, Some(_)) => Some(last),
            _ => None,
        })
    }

    /// The learning rate.
    pub fn lr(&self) -> f64 {
        self.lr
    }

    /// Sets the learning rate for the next steps (a schedule, when set, overrides it at the
    /// start of each epoch of [`Trainer::fit`]).
    pub fn set_lr(&mut self, lr: f64) {
        self.lr = lr;
    }

    /// Clips the gradients of the next steps to a joint L2 norm of `max_norm` (`None`: no
    /// clipping); stored in the checkpoints, so a resumed run keeps it.
    pub fn set_max_grad_norm(&mut self, max_norm: Option<f32>) -> Result<()> {
        if max_norm.is_some_and(|m| !(m.is_finite() && m > 0.0)) {
            return Err(ModelError::InvalidInput(format!(
                "the gradient norm to clip at must be > 0, got {max_norm:?}"
            )));
        }
        self.state.max_grad_norm = max_norm;
        Ok(())
    }

    /// Follows `schedule` from the next epoch of [`Trainer::fit`] on (`None`: the rate stays
    /// as set). Keeps a stored schedule with the same plan (see
    /// [`CosineSchedule::same_plan`]), so resuming with the same command continues it.
    pub fn set_schedule(&mut self, schedule: Option<CosineSchedule>) {
        self.state.schedule = match (self.state.schedule, schedule) {
            (Some(old), Some(new)) if old.same_plan(&new) => Some(old),
            (_, new) => new,
        };
    }

    /// Trains for `budget` (`None`: by epochs only): [`Trainer::fit`] stops once the steps
    /// have used its CPU time, over every sitting, and the rate follows it, overriding any
    /// [`Trainer::set_schedule`]. A resumed run keeps the time it has used, so a larger
    /// budget extends it.
    pub fn set_budget(&mut self, budget: Option<TimeBudget>) {
        self.state.budget = budget;
    }

    /// Whether the run has a budget and has used it.
    pub fn budget_spent(&self) -> bool {
        self.state
            .budget
            .is_some_and(|b| b.spent(self.state.train_cpu_s))
    }

    /// The loss configuration.
    pub fn loss_config(&self) -> &LossConfig {
        &self.loss
    }

    /// `samples` as a training batch on the autodiff device.
    pub fn train_batch(&self, samples: &[Sample]) -> Result<Batch> {
        Batch::new(samples, &self.topology, &self.spec, &self.device)
    }

    /// `samples` as a validation batch on the plain device.
    pub fn valid_batch(&self, samples: &[Sample]) -> Result<Batch> {
        Batch::new(
            samples,
            &self.topology,
            &self.spec,
            &self.device.clone().inner(),
        )
    }

    /// One optimiser step on `samples` (which need targets); returns the loss terms and the
    /// gradient norm.
    pub fn step(&mut self, samples: &[Sample]) -> Result<StepReport> {
        let batch = self.train_batch(samples)?;
        let report = train_step(
            &mut self.model,
            &mut self.optim,
            &batch,
            &self.topo,
            &self.loss,
            self.lr,
            self.state.max_grad_norm,
        )?;
        self.state.step += 1;
        self.state.lr = self.lr;
        Ok(report)
    }

    /// One pass over `batches` (each a `Vec<Sample>` or the data source's error), one step
    /// per batch, going on from the progress a mid-epoch checkpoint brought (whose batches
    /// `batches` must leave out); writes [`MID_EPOCH_CHECKPOINT`] to `out_dir` as
    /// [`Trainer::set_checkpoint_every`] says. Returns the epoch's progress: its loss terms
    /// and gradient norms summed over every sitting. Does not advance the epoch counter (see
    /// [`Trainer::run_epoch`]).
    pub fn train_epoch<I, E>(&mut self, batches: I, out_dir: Option<&Path>) -> Result<EpochProgress>
    where
        I: IntoIterator<Item = std::result::Result<Vec<Sample>, E>>,
        E: Display,
    {
        let mut progress = self
            .state
            .partial
            .take()
            .unwrap_or_else(|| EpochProgress::new(self.training_set.clone()));
        match self.train_batches(batches, &mut progress, out_dir) {
            Ok(()) => Ok(progress),
            Err(e) => {
                // Stopped inside the epoch: a later `fit` on this trainer goes on from here.
                self.state.partial = Some(progress);
                Err(e)
            }
        }
    }

    /// The steps of [`Trainer::train_epoch`], counted into `progress`.
    fn train_batches<I, E>(
        &mut self,
        batches: I,
        progress: &mut EpochProgress,
        out_dir: Option<&Path>,
    ) -> Result<()>
    where
        I: IntoIterator<Item = std::result::Result<Vec<Sample>, E>>,
        E: Display,
    {
        let (start, before) = (Instant::now(), progress.seconds);
        let clock = CpuClock::start(self.state.train_cpu_s);
        let mut saved = start;
        for batch in batches {
            if self.budget_spent() {
                break;
            }
            let samples = batch.map_err(|e| ModelError::Data(e.to_string()))?;
            if samples.is_empty() {
                progress.add_empty();
                continue;
            }
            // The budget's or the schedule's rate for this step (the schedule's is the
            // epoch's rate unless it goes step by step).
            if let Some(b) = self.state.budget {
                self.lr = b.lr(self.state.train_cpu_s);
            } else if let Some(s) = self.state.schedule {
                self.lr = s.lr_of_step(self.state.epoch, progress.batches);
            }
            let report = self.step(&samples)?;
            self.state.train_cpu_s = clock.seconds();
            progress.add(&report, samples.len());
            progress.seconds = before + start.elapsed().as_secs_f64();
            let due = self.checkpoint_every.is_some_and(|e| saved.elapsed() >= e);
            if let (Some(dir), true) = (out_dir, due) {
                self.state.partial = Some(progress.clone());
                let written = self.save(&dir.join(MID_EPOCH_CHECKPOINT));
                self.state.partial = None;
                written?;
                saved = Instant::now();
            }
        }
        Ok(())
    }

    /// Evaluates the network (without autodiff) on `batches`; averages over samples.
    pub fn validate<I, E>(&self, batches: I) -> Result<Validation>
    where
        I: IntoIterator<Item = std::result::Result<Vec<Sample>, E>>,
        E: Display,
    {
        let model = self.model.valid();
        let mut sum = LossTerms::default();
        let (mut dist, mut norm) = (0.0f64, 0.0f64);
        let mut count = 0usize;
        for batch in batches {
            let samples = batch.map_err(|e| ModelError::Data(e.to_string()))?;
            if samples.is_empty() {
                continue;
            }
            let b = self.valid_batch(&samples)?;
            let ev = evaluate_batch(
                &model,
                &b,
                &self.topo_valid,
                &self.setup.template.faces,
                &self.loss,
            )?;
            let w = samples.len();
            sum = sum + ev.terms.scaled(w as f32);
            dist += ev.e_dist_cm as f64 * w as f64;
            norm += ev.e_norm_deg as f64 * w as f64;
            count += w;
        }
        let c = count.max(1) as f64;
        Ok(Validation {
            terms: sum.scaled(1.0 / c as f32),
            e_dist_cm: (dist / c) as f32,
            e_norm_deg: (norm / c) as f32,
            samples: count,
        })
    }

    /// Writes a checkpoint of the current network, optimiser state and progress to `path`.
    pub fn save(&self, path: &Path) -> Result<()> {
        save_checkpoint(
            path,
            &self.model,
            Some(&self.optim),
            &self.setup,
            &self.loss,
            &self.state,
            self.recipe.as_ref(),
        )
    }

    /// A [`Draper`] of the current network on the plain device.
    pub fn draper(&self) -> Result<Draper> {
        Draper::new(
            self.model.clone(),
            self.setup.clone(),
            &self.device.clone().inner(),
        )
    }

    /// One epoch: trains on `train`, validates on `valid` (when given), advances the epoch
    /// counter, writes `out_dir/last.garnet`, `out_dir/best.garnet` when validation E_dist
    /// improved (or, without validation, every epoch), `out_dir/epoch-N.garnet` when
    /// [`Trainer::set_keep_epochs`] is on, and appends a row to `out_dir/metrics.csv`.
    pub fn run_epoch<I, J, E>(
        &mut self,
        train: I,
        valid: Option<J>,
        out_dir: &Path,
    ) -> Result<EpochReport>
    where
        I: IntoIterator<Item = std::result::Result<Vec<Sample>, E>>,
        J: IntoIterator<Item = std::result::Result<Vec<Sample>, E>>,
        E: Display,
    {
        let start = Instant::now();
        std::fs::create_dir_all(out_dir).map_err(|e| ModelError::Io {
            path: out_dir.to_path_buf(),
            source: e,
        })?;
        let earlier_sittings = self.state.partial.as_ref().map_or(0.0, |p| p.seconds);
        let trained = self.train_epoch(train, Some(out_dir))?;
        let (train_terms, train_samples) = (trained.mean_terms(), trained.samples);
        let grad_norm = trained.mean_grad_norm();
        let validation = match valid {
            Some(v) => Some(self.validate(v)?),
            None => None,
        };
        self.state.epoch += 1;
        let is_best = match &validation {
            Some(v) if v.samples > 0 => {
                let better = self.state.best_e_dist_cm.is_none_or(|b| v.e_dist_cm < b);
                if better {
                    self.state.best_e_dist_cm = Some(v.e_dist_cm);
                    self.state.validation = self.validation_set.clone();
                }
                better
            }
            _ => true,
        };
        self.save(&out_dir.join(LAST_CHECKPOINT))?;
        if is_best {
            self.save(&out_dir.join(BEST_CHECKPOINT))?;
        }
        if self.keep_epochs {
            self.save(&out_dir.join(epoch_checkpoint_name(self.state.epoch)))?;
        }
        let mid = out_dir.join(MID_EPOCH_CHECKPOINT);
        if mid.is_file() {
            std::fs::remove_file(&mid).map_err(|e| ModelError::Io {
                path: mid,
                source: e,
            })?;
        }
        let seconds = earlier_sittings + start.elapsed().as_secs_f64();
        let row = MetricsRow {
            epoch: self.state.epoch,
            step: self.state.step,
            lr: self.lr,
            seconds,
            train: train_terms,
            train_samples,
            grad_norm,
            validation,
            is_best,
            train_cpu_s: self.state.train_cpu_s,
        };
        MetricsLog::new(out_dir.join(METRICS_LOG)).append(&row)?;
        Ok(EpochReport {
            epoch: self.state.epoch,
            train: train_terms,
            train_samples,
            grad_norm,
            lr: self.lr,
            validation,
            is_best,
            seconds,
            train_cpu_s: self.state.train_cpu_s,
        })
    }

    /// Runs epochs until `epochs` are completed (counting those of a resumed checkpoint), or
    /// until the [`Trainer::set_budget`] budget is used (its last epoch then ends early):
    /// `train(epoch, skip)` gives the training batches of each epoch (shuffle there) without
    /// its first `skip`, which a mid-epoch checkpoint trained already (0 otherwise);
    /// `valid()` the validation batches; `on_epoch` sees each report. Returns the reports of
    /// this call. Fails before training when a mid-epoch checkpoint's epoch was taken from
    /// another training set than [`Trainer::set_training_set`] names.
    pub fn fit<I, J, E, FT, FV, FR>(
        &mut self,
        epochs: usize,
        mut train: FT,
        mut valid: Option<FV>,
        out_dir: &Path,
        mut on_epoch: FR,
    ) -> Result<Vec<EpochReport>>
    where
        I: IntoIterator<Item = std::result::Result<Vec<Sample>, E>>,
        J: IntoIterator<Item = std::result::Result<Vec<Sample>, E>>,
        E: Display,
        FT: FnMut(usize, usize) -> I,
        FV: FnMut() -> J,
        FR: FnMut(&EpochReport),
    {
        if let Some(p) = &self.state.partial {
            if p.training_set != self.training_set {
                let name = |s: &Option<String>| s.clone().unwrap_or_else(|| "unnamed".into());
                return Err(ModelError::InvalidInput(format!(
                    "the checkpoint stopped inside epoch {} after {} batches of another training \
                     set or order ({}; this run: {}): go on with the same data, batch size and \
                     seed, or delete {} to train epoch {} afresh from {}",
                    self.state.epoch + 1,
                    p.batches,
                    name(&p.training_set),
                    name(&self.training_set),
                    MID_EPOCH_CHECKPOINT,
                    self.state.epoch + 1,
                    LAST_CHECKPOINT,
                )));
            }
        }
        let mut reports = Vec::new();
        while self.state.epoch < epochs && !self.budget_spent() {
            let epoch = self.state.epoch;
            let skip = self.state.partial.as_ref().map_or(0, |p| p.batches);
            let v = valid.as_mut().map(|f| f());
            let report = self.run_epoch(train(epoch, skip), v, out_dir)?;
            on_epoch(&report);
            reports.push(report);
        }
        Ok(reports)
    }

    /// Where [`Trainer::run_epoch`] writes its files under `out_dir`: (last, best, metrics).
    pub fn output_paths(out_dir: &Path) -> (PathBuf, PathBuf, PathBuf) {
        (
            out_dir.join(LAST_CHECKPOINT),
            out_dir.join(BEST_CHECKPOINT),
            out_dir.join(METRICS_LOG),
        )
    }
}

/// The training time of a run: CPU time of the process since [`CpuClock::start`] plus what
/// earlier sittings used; wall time where the process's CPU time cannot be read.
struct CpuClock {
    before_s: f64,
    cpu0_ms: Option<f64>,
    wall0: Instant,
}

impl CpuClock {
    /// A clock that has already counted `before_s` seconds.
    fn start(before_s: f64) -> CpuClock {
        CpuClock {
            before_s,
            cpu0_ms: process_cpu_ms(),
            wall0: Instant::now(),
        }
    }

    /// Seconds counted so far.
    fn seconds(&self) -> f64 {
        let now = match (self.cpu0_ms, process_cpu_ms()) {
            (Some(a), Some(b)) => (b - a) / 1e3,
            _ => self.wall0.elapsed().as_secs_f64(),
        };
        self.before_s + now
    }
}
