//! Timing helpers (used by `garnet bench model`): forward time per
//! drape and training-step time on synthetic inputs of chosen sizes.

use std::time::Instant;

use burn::prelude::*;
use serde::{Deserialize, Serialize};

use crate::checkpoint::ModelSetup;
use crate::config::GarNetConfig;
use crate::drape::Draper;
use crate::error::Result;
use crate::loss::LossConfig;
use crate::synthetic::{ellipsoid_body, synthetic_sample, tube_garment, BODY_CENTRE};
use crate::trainer::Trainer;

/// Wall times of repeated runs, milliseconds, and the process CPU time they used.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// Median.
    pub median_ms: f64,
    /// Fastest run.
    pub min_ms: f64,
    /// Slowest run.
    pub max_ms: f64,
    /// Timed runs (after one untimed warm-up).
    pub runs: usize,
    /// Mean CPU time of the process (all threads) per timed run, milliseconds (Linux only,
    /// 10 ms clock resolution over all runs). On a machine shared with other work, wall time
    /// grows with the load while CPU time stays near the work done: `cpu_ms / wall` shows how
    /// many cores the run really had.
    pub cpu_ms: Option<f64>,
}

/// CPU time (user + system, all threads) of this process so far, milliseconds; `None` where
/// `/proc/self/stat` is not available.
pub fn process_cpu_ms() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may hold spaces).
    let rest = stat.rsplit(')').next()?;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    // USER_HZ is 100 on every Linux platform Rust supports.
    Some(ticks * 10.0)
}

impl Timing {
    /// Times `f` `runs` times (at least 1) after one warm-up call.
    pub fn measure<F: FnMut() -> Result<()>>(runs: usize, mut f: F) -> Result<Timing> {
        f()?;
        let mut ms = Vec::with_capacity(runs.max(1));
        let cpu0 = process_cpu_ms();
        for _ in 0..runs.max(1) {
            let t = Instant::now();
            f()?;
            ms.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let cpu_ms = match (cpu0, process_cpu_ms()) {
            (Some(a), Some(b)) => Some((b - a) / ms.len() as f64),
            _ => None,
        };
        ms.sort_by(|a, b| a.total_cmp(b));
        let n = ms.len();
        let median = if n % 2 == 1 {
            ms[n / 2]
        } else {
            0.5 * (ms[n / 2 - 1] + ms[n / 2])
        };
        Ok(Timing {
            median_ms: median,
            min_ms: ms[0],
            max_ms: ms[n - 1],
            runs: n,
            cpu_ms,
        })
    }
}

/// Forward timing of one variant at one size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ForwardBench {
    /// Variant name.
    pub variant: String,
    /// Garment vertices N.
    pub n_garment: usize,
    /// Body vertices V.
    pub n_body: usize,
    /// Trainable parameters.
    pub params: usize,
    /// One drape (batch 1): input checks, neighbour tables (Local), upload, forward, read-back.
    pub drape: Timing,
}

/// Training-step timing of one variant at one size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainBench {
    /// Variant name.
    pub variant: String,
    /// Garment vertices N.
    pub n_garment: usize,
    /// Body vertices V.
    pub n_body: usize,
    /// Samples per step.
    pub batch_size: usize,
    /// One step: batch building, forward, loss (with the CPU nearest-vertex search),
    /// backward, Adam update.
    pub step: Timing,
}

/// The setup of a synthetic benchmark: `config`, a tube garment of about `n_garment`
/// vertices, and the body sampling of an `n_body`-point ellipsoid body.
pub fn synthetic_setup(
    config: &GarNetConfig,
    n_garment: usize,
    n_body: usize,
) -> Result<ModelSetup> {
    let (body, _) = ellipsoid_body(n_body);
    ModelSetup::new(config.clone(), tube_garment(n_garment), &body)
}

/// Times [`Draper::drape`] of a freshly initialised `config` network on `device` (batch 1):
/// a tube garment of about `n_garment` vertices on an `n_body`-point ellipsoid body.
pub fn bench_forward(
    config: &GarNetConfig,
    n_garment: usize,
    n_body: usize,
    runs: usize,
    device: &Device,
) -> Result<ForwardBench> {
    let device = device.clone().inner();
    let setup = synthetic_setup(config, n_garment, n_body)?;
    let model = config.init(&device)?;
    let params = model.num_params();
    let draper = Draper::new(model, setup, &device)?;
    let (body, _) = ellipsoid_body(n_body);
    let body: Vec<_> = body
        .iter()
        .map(|p| BODY_CENTRE + (*p - BODY_CENTRE) * 1.05)
        .collect();
    let warped = draper.setup().template.vertices.clone();
    let drape = Timing::measure(runs, || draper.drape(&body, &warped).map(|_| ()))?;
    Ok(ForwardBench {
        variant: config.variant.name().to_string(),
        n_garment: warped.len(),
        n_body,
        params,
        drape,
    })
}

/// Times [`Trainer::step`] (full loss, Adam at 1e-3) of a fresh `config` network on
/// `device` with batches of `batch_size` synthetic samples.
pub fn bench_train_step(
    config: &GarNetConfig,
    n_garment: usize,
    n_body: usize,
    batch_size: usize,
    runs: usize,
    device: &Device,
) -> Result<TrainBench> {
    let setup = synthetic_setup(config, n_garment, n_body)?;
    let samples = (0..batch_size.max(1))
        .map(|i| synthetic_sample(n_body, &setup.template, 1.0 + 0.02 * i as f32, i as f32))
        .collect::<Result<Vec<_>>>()?;
    let mut trainer = Trainer::new(setup, LossConfig::new(), 1e-3, device)?;
    let step = Timing::measure(runs, || trainer.step(&samples).map(|_| ()))?;
    Ok(TrainBench {
        variant: config.variant.name().to_string(),
        n_garment: samples[0].warped.len(),
        n_body,
        batch_size: samples.len(),
        step,
    })
}
