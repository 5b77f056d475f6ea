//! How repeatable a spec's labels are: some samples of one split draped three times from
//! scratch, with the spec's cloth density `d`, with `d (1 + s)` and with `d (1 - s)`,
//! everything else the same. A step `s` of 0.1% changes nothing a person could see, so
//! the simulator's drape should barely move: the distances between the base drape and
//! the two others measure how far the labels of the dataset would move for nothing.
//!
//! Units: metres and radians inside; the report gives centimetres (`E_dist`) and degrees
//! (`E_norm`), as [`geom::metrics::mesh_errors`] does.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use body::{BodyModel, Phenotype};
use rayon::prelude::*;
use sim::drape::{drape, DrapeOptions};

use crate::cache::KeyedCache;
use crate::error::{DatasetError, Result};
use crate::generate::Progress;
use crate::plan::Plan;
use crate::poses::PoseLibrary;
use crate::sample::Maker;
use crate::spec::{LoadedSpec, SimulatorSpec};
use crate::templates::TemplateStore;

mod report;
#[cfg(test)]
mod tests;

use report::per_minute;
pub use report::{
    summarise, DrapeFigures, GarmentSpread, SpreadDrape, SpreadFailure, SpreadReport, SpreadRow,
};

/// The split measured when none is named.
pub const DEFAULT_SPLIT: &str = "test";
/// Samples per garment when no number is given.
pub const DEFAULT_PER_GARMENT: usize = 40;
/// The relative density step when none is given (0.1%).
pub const DEFAULT_STEP: f32 = 0.001;
/// Relative density steps must lie in `(0, MAX_STEP)`.
pub const MAX_STEP: f32 = 0.1;
/// The three drapes of a sample: the spec's density, `d (1 + s)`, `d (1 - s)`.
pub const VARIANTS: [&str; 3] = ["base", "up", "down"];
/// Strain p99 under which a drape counts as unstrained (2%).
pub const STRAIN_OK: f32 = 0.02;

/// Settings of a spread measurement.
pub struct SpreadOptions<'a> {
    /// The split whose samples are draped (a name of the spec's `[splits.bodies]`).
    pub split: String,
    /// Samples per garment, spread evenly over the split's samples of that garment (all of
    /// them when it has fewer); at least 1.
    pub per_garment: usize,
    /// Relative density step `s`, in `(0, MAX_STEP)`: the other drapes use `d (1 + s)` and
    /// `d (1 - s)` kg/m^2.
    pub step: f32,
    /// The garments measured, by name (empty: every garment of the spec).
    pub garments: Vec<String>,
    /// Worker threads (drapes in parallel).
    pub jobs: usize,
    /// A simulator settings file (see [`SimulatorSpec::load`]) whose keys replace those of
    /// the spec's `[simulator]` table, key by key.
    pub simulator: Option<PathBuf>,
    /// The folder clip paths are relative to (needed when the spec names clips).
    pub mocap_root: Option<PathBuf>,
    /// Called after each drape (`done` and `total` count drapes).
    pub progress: Option<&'a (dyn Fn(&Progress) + Sync)>,
}

impl SpreadOptions<'_> {
    /// The test split, 40 samples per garment, a 0.1% step, one job per core, the spec's
    /// simulator settings, no progress hook.
    pub fn new(mocap_root: Option<PathBuf>) -> Self {
        Self {
            split: DEFAULT_SPLIT.to_string(),
            per_garment: DEFAULT_PER_GARMENT,
            step: DEFAULT_STEP,
            garments: Vec::new(),
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
            simulator: None,
            mocap_root,
            progress: None,
        }
    }
}

/// first), ascending and distinct; all `count` when `n >= count`.
pub fn spread_evenly(count: usize, n: usize) -> Vec<usize> {
    if n >= count {
        return (0..count).collect();
    }
    (0..n).map(|i| i * count / n).collect()
}

/// Per garment of the plan (in spec order), the sample indices measured: `n` of split
/// `split`'s samples of that garment, spread evenly over them in plan order
/// ([`spread_evenly`]).
pub fn chosen_samples(plan: &Plan, split: usize, n: usize) -> Vec<Vec<u64>> {
    let bodies = plan.split_bodies(split);
    plan.garments
        .iter()
        .enumerate()
        .map(|(g, garment)| {
            let ppb = garment.poses_per_body as u64;
            let all: Vec<u64> = bodies
                .iter()
                .flat_map(|&b| {
                    let first = plan.offsets[g] + b as u64 * ppb;
                    first..first + ppb
                })
                .collect();
            spread_evenly(all.len(), n)
                .into_iter()
                .map(|i| all[i])
                .collect()
        })
        .collect()
}

/// The simulator settings `base` with every key that `over` names replacing base's, key by
/// key (a key `over` leaves out keeps base's value).
pub fn merged_simulator(base: &SimulatorSpec, over: &SimulatorSpec) -> SimulatorSpec {
    let json = |s: &SimulatorSpec| match serde_json::to_value(s) {
        Ok(serde_json::Value::Object(m)) => m,
        _ => unreachable!("simulator settings serialise as an object"),
    };
    let mut merged = json(base);
    for (key, value) in json(over) {
        if !value.is_null() {
            merged.insert(key, value);
        }
    }
    serde_json::from_value(serde_json::Value::Object(merged))
        .expect("merged simulator settings deserialise")
}

/// Errors name the spec or settings file and the problem: an unknown split, no samples
/// asked for, a step outside `(0, 0.1)`, missing clips, a bad simulator setting.
pub fn spread(
    model: &BodyModel,
    spec: &LoadedSpec,
    opts: &SpreadOptions<'_>,
) -> Result<SpreadReport> {
    let t0 = Instant::now();
    let file = spec.path.display();
    if opts.per_garment == 0 {
        return Err(DatasetError::Invalid(format!(
            "{file}: 0 samples per garment asked for (--per-garment): give at least 1"
        )));
    }
    if !(opts.step > 0.0 && opts.step < MAX_STEP) {
        return Err(DatasetError::Invalid(format!(
            "{file}: the density step {} (--step) is not in (0, {MAX_STEP})",
            opts.step
        )));
    }
    let library = PoseLibrary::load(&spec.spec, opts.mocap_root.as_deref())
        .map_err(|e| DatasetError::Invalid(format!("{file}: {e}")))?;
    let plan = Plan::new(spec, &library.frame_counts())?;
    let known: Vec<&str> = plan.split_names.iter().map(String::as_str).collect();
    DatasetError::check_known("split", [opts.split.as_str()], &known)
        .map_err(|e| DatasetError::Invalid(format!("{file}: {e}")))?;
    let split = known
        .iter()
        .position(|&n| n == opts.split)
        .expect("checked");
    if plan.split_bodies(split).is_empty() {
        return Err(DatasetError::Invalid(format!(
            "{file}: split '{}' has no bodies",
            opts.split
        )));
    }
    let garment_names: Vec<&str> = plan.garments.iter().map(|g| g.name.as_str()).collect();
    DatasetError::check_known(
        "garment",
        opts.garments.iter().map(String::as_str),
        &garment_names,
    )
    .map_err(|e| DatasetError::Invalid(format!("{file}: {e}")))?;
    let simulator = match &opts.simulator {
        Some(path) => merged_simulator(&spec.spec.simulator, &SimulatorSpec::load(path)?),
        None => spec.spec.simulator.clone(),
    };
    let mut drape_options = simulator.drape_options().map_err(|(field, message)| {
        DatasetError::spec(
            opts.simulator.as_deref().unwrap_or(&spec.path),
            field,
            message,
        )
    })?;
    // Every thread of the pool runs a drape of its own (as `generate` does).
    drape_options.cloth.split_solve = false;
    let d = drape_options.cloth.density;
    let densities = [d, d * (1.0 + opts.step), d * (1.0 - opts.step)];
    let jobs = opts.jobs.max(1);
    let maker = Maker {
        model,
        template_body: model.shape(&Phenotype::default())?,
        spec: &spec.spec,
        plan: &plan,
        library: &library,
        drape_options,
        templates: TemplateStore::in_memory(plan.garments.len() + 2 * jobs + 2),
        bodies: KeyedCache::new(2 * jobs + 4),
        morphs: KeyedCache::new(1),
    };
    // (garment index, its samples) of the garments measured.
    let chosen: Vec<(usize, Vec<u64>)> = chosen_samples(&plan, split, opts.per_garment)
        .into_iter()
        .enumerate()
        .filter(|(g, _)| {
            opts.garments.is_empty() || opts.garments.contains(&plan.garments[*g].name)
        })
        .collect();
    let total = 3 * chosen.iter().map(|(_, s)| s.len()).sum::<usize>() as u64;
    let (done, failed) = (AtomicU64::new(0), AtomicU64::new(0));
    let notify = |drapes: u64, failures: u64| {
        let done = done.fetch_add(drapes, Ordering::SeqCst) + drapes;
        let failed = failed.fetch_add(failures, Ordering::SeqCst) + failures;
        if let Some(f) = opts.progress {
            f(&Progress {
                done,
                total,
                failed,
                made: done,
            });
        }
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| DatasetError::Invalid(format!("starting {jobs} threads: {e}")))?;
    let (mut garments, mut rows) = (Vec::new(), Vec::new());
    for &(g, ref samples) in &chosen {
        let tg = Instant::now();
        let made: Vec<Result<SpreadRow>> = pool.install(|| {
            samples
                .par_iter()
                .with_max_len(1)
                .map(|&k| sample_row(&maker, k, &densities, &notify))
                .collect()
        });
        let made = made.into_iter().collect::<Result<Vec<_>>>()?;
        garments.push(summarise(
            &plan.garments[g].name,
            &made,
            tg.elapsed().as_secs_f64(),
        ));
        rows.extend(made);
    }
    let wall_s = t0.elapsed().as_secs_f64();
    Ok(SpreadReport {
        spec_name: spec.spec.name.clone(),
        spec_path: spec.path.display().to_string(),
        spec_hash: spec.hash.clone(),
        split: opts.split.clone(),
        per_garment: opts.per_garment,
        step: opts.step,
        densities_kg_m2: densities,
        simulator_file: opts.simulator.as_ref().map(|p| p.display().to_string()),
        simulator,
        jobs,
        wall_s,
        drapes_per_min: per_minute(total as usize, wall_s),
        garments,
        rows,
    })
}

/// Sample `k` draped at each of `densities` (kg/m^2; base, up, down) from scratch, the
/// three in parallel, and compared; `notify(drapes, failed)` after each drape.
fn sample_row(
    maker: &Maker<'_>,
    k: u64,
    densities: &[f32; 3],
    notify: &(dyn Fn(u64, u64) + Sync),
) -> Result<SpreadRow> {
    let desc = maker.plan.sample(k);
    let mut row = SpreadRow {
        index: k,
        garment: maker.plan.garments[desc.garment].name.clone(),
        body: desc.body,
        pose: maker.plan.pool.pose_id(desc.pose),
        e_dist_up_cm: None,
        e_dist_down_cm: None,
        e_norm_up_deg: None,
        e_norm_down_deg: None,
        drapes: Vec::new(),
        error: None,
    };
    let (body, template, pose) = match maker.inputs(&desc)? {
        Ok(inputs) => inputs,
        Err(m) => {
            notify(3, 3);
            row.error = Some(m);
            return Ok(row);
        }
    };
    let drapes: Vec<std::result::Result<sim::drape::Drape, String>> = densities
        .par_iter()
        .with_max_len(1)
        .map(|&density| {
            let mut o: DrapeOptions = maker.drape_options.clone();
            o.cloth.density = density;
            let r = drape(
                &template,
                &maker.template_body,
                &body.0,
                &pose,
                &o,
                &mut |_, _, _| {},
            )
            .map_err(|e| format!("drape: {e}"));
            notify(1, r.is_err() as u64);
            r
        })
        .collect();
    if let [Ok(base), Ok(up), Ok(down)] = &drapes[..] {
        let faces = &base.garment.faces;
        let (b, u, d) = (
            &base.garment.vertices,
            &up.garment.vertices,
            &down.garment.vertices,
        );
        use geom::metrics::{e_dist, e_norm, m_to_cm, rad_to_deg};
        row.e_dist_up_cm = Some(m_to_cm(e_dist(b, u)?));
        row.e_dist_down_cm = Some(m_to_cm(e_dist(b, d)?));
        row.e_norm_up_deg = Some(rad_to_deg(e_norm(b, u, faces)?));
        row.e_norm_down_deg = Some(rad_to_deg(e_norm(b, d, faces)?));
    }
    row.drapes = drapes
        .into_iter()
        .zip(VARIANTS)
        .zip(densities)
        .map(|((r, variant), &density)| {
            let (figures, error) = match r {
                Ok(dr) => {
                    let s = &dr.stats;
                    let f = DrapeFigures {
                        converged: s.converged,
                        animation_steps: s.animation_steps,
                        settle_steps: s.settle_steps,
                        strain_p99: s.strain_p99,
                        max_penetration_m: s.max_penetration_m,
                        wall_time_s: s.wall_time_s,
                    };
                    (Some(f), None)
                }
                Err(m) => (None, Some(m)),
            };
            SpreadDrape {
                variant: variant.to_string(),
                density_kg_m2: density,
                figures,
                error,
            }
        })
        .collect();
    Ok(row)
}
