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
use serde::{Deserialize, Serialize};
use sim::drape::{drape, DrapeOptions};

use crate::cache::KeyedCache;
use crate::error::{DatasetError, Result};
use crate::generate::Progress;
use crate::plan::Plan;
use crate::poses::PoseLibrary;
use crate::sample::Maker;
use crate::spec::{LoadedSpec, SimulatorSpec};
use crate::templates::TemplateStore;

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
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
            simulator: None,
            mocap_root,
            progress: None,
        }
    }
}

/// What one drape of a sample reached.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DrapeFigures {
    /// At rest: the cloth's RMS speed fell under the rest speed within the settling steps.
    pub converged: bool,
    /// Steps of the body animation (shape morph, then pose).
    pub animation_steps: u32,
    /// Steps spent settling after the animation.
    pub settle_steps: u32,
    /// 99th percentile of the edge strain (0.01 = 1%).
    pub strain_p99: f32,
    /// Deepest garment vertex inside the body, metres.
    pub max_penetration_m: f32,
    /// Wall time of the drape, seconds.
    pub wall_time_s: f64,
}

/// One of the three drapes of a sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpreadDrape {
    /// `base`, `up` or `down` (see [`VARIANTS`]).
    pub variant: String,
    /// The cloth's density, kg/m^2.
    pub density_kg_m2: f32,
    /// What the drape reached; `None` when it failed.
    pub figures: Option<DrapeFigures>,
    /// Why the drape failed (the simulator's error); `None` when it was made.
    pub error: Option<String>,
}

/// One sample: its three drapes and the distances between them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpreadRow {
    /// Sample index in the plan.
    pub index: u64,
    /// The garment's name.
    pub garment: String,
    /// Body index.
    pub body: u32,
    /// The pose's id (`clip#frame` or `source#draw`).
    pub pose: String,
    /// `E_dist` between the base and the up drape, cm; `None` unless all three were made.
    pub e_dist_up_cm: Option<f32>,
    /// `E_dist` between the base and the down drape, cm.
    pub e_dist_down_cm: Option<f32>,
    /// `E_norm` between the base and the up drape, degrees.
    pub e_norm_up_deg: Option<f32>,
    /// `E_norm` between the base and the down drape, degrees.
    pub e_norm_down_deg: Option<f32>,
    /// The base, up and down drapes, in that order; empty when the sample could not be set
    /// up.
    pub drapes: Vec<SpreadDrape>,
    /// Why the sample could not be set up (a cut that cannot be built, a pose that cannot
    /// be found); none of its drapes ran.
    pub error: Option<String>,
}

impl SpreadRow {
    /// The figures of drape `v` (0 base, 1 up, 2 down) when it was made.
    pub fn figures(&self, v: usize) -> Option<&DrapeFigures> {
        self.drapes.get(v).and_then(|d| d.figures.as_ref())
    }

    /// Whether all three drapes were made (the distances are known).
    pub fn compared(&self) -> bool {
        self.drapes.len() == 3 && self.drapes.iter().all(|d| d.figures.is_some())
    }
}

/// A drape that failed, or a sample that could not be set up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpreadFailure {
    /// Sample index.
    pub index: u64,
    /// `base`, `up` or `down`; `all` for a sample that could not be set up.
    pub variant: String,
    /// What went wrong.
    pub message: String,
}

/// The figures of one garment. Shares are in [0, 1]; a figure over no drapes is `None`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GarmentSpread {
    /// The garment's name.
    pub garment: String,
    /// Samples measured.
    pub samples: usize,
    /// Drapes, three a sample.
    pub drapes: usize,
    /// Of those, failed (a sample that could not be set up counts its three).
    pub failed: usize,
    /// Samples whose three drapes were all made: the distances are means over these.
    pub compared: usize,
    /// Mean `E_dist` between the base and the up drapes, cm.
    pub e_dist_up_cm: Option<f64>,
    /// Mean `E_dist` between the base and the down drapes, cm.
    pub e_dist_down_cm: Option<f64>,
    /// The mean of the two, cm.
    pub e_dist_cm: Option<f64>,
    /// Mean `E_norm` between the base and the up drapes, degrees.
    pub e_norm_up_deg: Option<f64>,
    /// Mean `E_norm` between the base and the down drapes, degrees.
    pub e_norm_down_deg: Option<f64>,
    /// The mean of the two, degrees.
    pub e_norm_deg: Option<f64>,
    /// Share of the base drapes made that are at rest.
    pub base_at_rest: Option<f64>,
    /// Share of the compared samples whose three drapes are all at rest.
    pub all_at_rest: Option<f64>,
    /// The largest `max_penetration_m` of the drapes made, metres.
    pub max_penetration_m: Option<f32>,
    /// Share of the drapes made whose strain p99 is under [`STRAIN_OK`] (2%).
    pub strain_ok: Option<f64>,
    /// Median settling steps of the drapes made.
    pub median_settle_steps: Option<f64>,
    /// Median animation steps of the drapes made.
    pub median_animation_steps: Option<f64>,
    /// Wall time of this garment's drapes (they run one garment after another), seconds.
    pub wall_s: f64,
    /// Drapes per minute of that wall time.
    pub drapes_per_min: f64,
    /// Mean wall time of a drape made (`stats.wall_time_s`), seconds.
    pub mean_drape_s: Option<f64>,
    /// The failed drapes and samples, with their messages.
    pub failures: Vec<SpreadFailure>,
}

/// What `garnet dataset spread` measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpreadReport {
    /// The spec's name.
    pub spec_name: String,
    /// The spec file.
    pub spec_path: String,
    /// Hex sha256 of the resolved spec ([`LoadedSpec::hash`]).
    pub spec_hash: String,
    /// The split measured.
    pub split: String,
    /// Samples per garment asked for.
    pub per_garment: usize,
    /// Relative density step.
    pub step: f32,
    /// The densities of the base, up and down drapes, kg/m^2.
    pub densities_kg_m2: [f32; 3],
    /// The simulator settings file whose keys replaced the spec's, if any.
    pub simulator_file: Option<String>,
    /// The simulator settings used: the spec's `[simulator]` with the file's keys over
    /// them (a key absent keeps the simulator's default).
    pub simulator: SimulatorSpec,
    /// Worker threads.
    pub jobs: usize,
    /// Wall time of the whole run, seconds.
    pub wall_s: f64,
    /// Drapes per minute of the whole run's wall time.
    pub drapes_per_min: f64,
    /// Per garment, in spec order.
    pub garments: Vec<GarmentSpread>,
    /// Per sample, garment after garment, in plan order.
    pub rows: Vec<SpreadRow>,
}

/// `n` positions spread evenly over a list of `count` (every `count / n`-th, from the
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

/// The mean of `values`; `None` for none.
fn mean(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values
        .into_iter()
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// The median of `values` (the mean of the two middle ones for an even count); `None`
/// for none.
fn median(mut values: Vec<f64>) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(match n % 2 {
        1 => values[n / 2],
        _ => (values[n / 2 - 1] + values[n / 2]) / 2.0,
    })
}

/// The share of `flags` that are true; `None` for none.
fn share(flags: impl IntoIterator<Item = bool>) -> Option<f64> {
    mean(flags.into_iter().map(|f| f as u8 as f64))
}

/// The figures of garment `garment` from its sample rows, whose drapes took `wall_s`
/// seconds of wall time.
pub fn summarise(garment: &str, rows: &[SpreadRow], wall_s: f64) -> GarmentSpread {
    let mut failures = Vec::new();
    for r in rows {
        if let Some(m) = &r.error {
            failures.push(SpreadFailure {
                index: r.index,
                variant: "all".into(),
                message: m.clone(),
            });
        }
        for d in &r.drapes {
            if let Some(m) = &d.error {
                failures.push(SpreadFailure {
                    index: r.index,
                    variant: d.variant.clone(),
                    message: m.clone(),
                });
            }
        }
    }
    let made: Vec<&DrapeFigures> = rows
        .iter()
        .flat_map(|r| r.drapes.iter().filter_map(|d| d.figures.as_ref()))
        .collect();
    let compared: Vec<&SpreadRow> = rows.iter().filter(|r| r.compared()).collect();
    let of = |f: fn(&SpreadRow) -> Option<f32>| {
        mean(compared.iter().filter_map(|r| f(r).map(f64::from)))
    };
    let (du, dd) = (of(|r| r.e_dist_up_cm), of(|r| r.e_dist_down_cm));
    let (nu, nd) = (of(|r| r.e_norm_up_deg), of(|r| r.e_norm_down_deg));
    let both = |a: Option<f64>, b: Option<f64>| Some((a? + b?) / 2.0);
    let drapes = 3 * rows.len();
    GarmentSpread {
        garment: garment.to_string(),
        samples: rows.len(),
        drapes,
        failed: drapes - made.len(),
        compared: compared.len(),
        e_dist_up_cm: du,
        e_dist_down_cm: dd,
        e_dist_cm: both(du, dd),
        e_norm_up_deg: nu,
        e_norm_down_deg: nd,
        e_norm_deg: both(nu, nd),
        base_at_rest: share(
            rows.iter()
                .filter_map(|r| r.figures(0))
                .map(|f| f.converged),
        ),
        all_at_rest: share(
            compared
                .iter()
                .map(|r| (0..3).all(|v| r.figures(v).is_some_and(|f| f.converged))),
        ),
        max_penetration_m: made
            .iter()
            .map(|f| f.max_penetration_m)
            .max_by(f32::total_cmp),
        strain_ok: share(made.iter().map(|f| f.strain_p99 < STRAIN_OK)),
        median_settle_steps: median(made.iter().map(|f| f.settle_steps as f64).collect()),
        median_animation_steps: median(made.iter().map(|f| f.animation_steps as f64).collect()),
        wall_s,
        drapes_per_min: per_minute(drapes, wall_s),
        mean_drape_s: mean(made.iter().map(|f| f.wall_time_s)),
        failures,
    }
}

/// `n` per minute of `wall_s` seconds (0 for no time).
fn per_minute(n: usize, wall_s: f64) -> f64 {
    if wall_s > 0.0 {
        n as f64 * 60.0 / wall_s
    } else {
        0.0
    }
}

/// Measures how repeatable the drapes of `spec` are (see the module documentation): the
/// samples of split `opts.split` chosen by [`chosen_samples`], each draped from scratch
/// with `sim::drape::drape` at three densities, the drapes in parallel over `opts.jobs`
/// threads, garment after garment. A failed drape is counted and listed, not an error.
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
    let chosen = chosen_samples(&plan, split, opts.per_garment);
    let total = 3 * chosen.iter().map(Vec::len).sum::<usize>() as u64;
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
    for (g, samples) in chosen.iter().enumerate() {
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

/// A figure with `digits` decimals, `-` when there is none.
fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".into(), |v| format!("{v:.digits$}"))
}

/// A share as a percentage, `-` when there is none.
fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |v| format!("{:.0}%", 100.0 * v))
}

/// A CSV field: quoted when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl SpreadReport {
    /// The per-garment figures as a markdown table (cm, degrees, mm, percent).
    pub fn markdown(&self) -> String {
        let mut t = format!(
            "{} ({}), split {}, density {} kg/m^2 +/- {}%\n\n",
            self.spec_name,
            &self.spec_hash[..self.spec_hash.len().min(16)],
            self.split,
            self.densities_kg_m2[0],
            100.0 * self.step
        );
        t.push_str(
            "| garment | drapes | failed | E_dist cm (up / down) | E_dist cm | E_norm deg (up / down) | E_norm deg | at rest (base / all 3) | max pen. mm | strain p99 < 2% | settle steps | anim. steps | drapes/min | s/drape |\n\
             |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        );
        for g in &self.garments {
            t.push_str(&format!(
                "| {} | {} | {} | {} / {} | {} | {} / {} | {} | {} / {} | {} | {} | {} | {} | {:.1} | {} |\n",
                g.garment,
                g.drapes,
                g.failed,
                cell(g.e_dist_up_cm, 3),
                cell(g.e_dist_down_cm, 3),
                cell(g.e_dist_cm, 3),
                cell(g.e_norm_up_deg, 2),
                cell(g.e_norm_down_deg, 2),
                cell(g.e_norm_deg, 2),
                pct(g.base_at_rest),
                pct(g.all_at_rest),
                cell(g.max_penetration_m.map(|m| 1000.0 * m as f64), 2),
                pct(g.strain_ok),
                cell(g.median_settle_steps, 0),
                cell(g.median_animation_steps, 0),
                g.drapes_per_min,
                cell(g.mean_drape_s, 2),
            ));
        }
        t
    }

    /// The per-sample rows as CSV (a header, then a line a sample): distances in cm and
    /// degrees, the three drapes' rest and settling steps, the base drape's strain p99,
    /// the three drapes' wall time added up (s), and the failure messages.
    pub fn csv(&self) -> String {
        let mut t = String::from(
            "index,garment,body,pose,e_dist_up_cm,e_dist_down_cm,e_norm_up_deg,e_norm_down_deg,\
             converged_base,converged_up,converged_down,settle_base,settle_up,settle_down,\
             strain_p99_base,wall_s,error\n",
        );
        let opt = |v: Option<String>| v.unwrap_or_default();
        for r in &self.rows {
            let mut fields = vec![
                r.index.to_string(),
                csv_field(&r.garment),
                r.body.to_string(),
                csv_field(&r.pose),
            ];
            for v in [
                r.e_dist_up_cm,
                r.e_dist_down_cm,
                r.e_norm_up_deg,
                r.e_norm_down_deg,
            ] {
                fields.push(opt(v.map(|v| v.to_string())));
            }
            for v in 0..3 {
                fields.push(opt(r.figures(v).map(|f| f.converged.to_string())));
            }
            for v in 0..3 {
                fields.push(opt(r.figures(v).map(|f| f.settle_steps.to_string())));
            }
            fields.push(opt(r.figures(0).map(|f| f.strain_p99.to_string())));
            let wall: f64 = (0..3)
                .filter_map(|v| r.figures(v))
                .map(|f| f.wall_time_s)
                .sum();
            fields.push(format!("{wall:.3}"));
            let errors: Vec<String> = r
                .error
                .iter()
                .map(|m| format!("all: {m}"))
                .chain(
                    r.drapes
                        .iter()
                        .filter_map(|d| d.error.as_ref().map(|m| format!("{}: {m}", d.variant))),
                )
                .collect();
            fields.push(csv_field(&errors.join("; ")));
            t.push_str(&fields.join(","));
            t.push('\n');
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_spread_evenly_and_deterministically() {
        assert_eq!(spread_evenly(10, 5), vec![0, 2, 4, 6, 8]);
        assert_eq!(spread_evenly(10, 3), vec![0, 3, 6]);
        assert_eq!(spread_evenly(3, 40), vec![0, 1, 2]);
        assert_eq!(spread_evenly(0, 4), Vec::<usize>::new());
        for (count, n) in [(800, 40), (1000, 7), (41, 40), (5, 1)] {
            let picks = spread_evenly(count, n);
            assert_eq!(picks.len(), n);
            assert!(picks.windows(2).all(|w| w[0] < w[1]), "{picks:?}");
            assert!(*picks.last().unwrap() < count);
            // Gaps differ by at most one: evenly spread.
            let gaps: Vec<usize> = picks.windows(2).map(|w| w[1] - w[0]).collect();
            if let (Some(lo), Some(hi)) = (gaps.iter().min(), gaps.iter().max()) {
                assert!(hi - lo <= 1, "{gaps:?}");
            }
            assert_eq!(picks, spread_evenly(count, n));
        }
    }

    #[test]
    fn chosen_samples_follow_the_split_in_plan_order() {
        let text = r#"
format = 2
seed = 3
[bodies]
count = 6
[[garments]]
kind = "tshirt"
edge = 0.05
poses_per_body = 2
[[garments]]
kind = "jeans"
edge = 0.05
poses_per_body = 1
[[poses.procedural]]
kind = "walk"
count = 4
[splits.bodies]
train = 3
test = 3
"#;
        let spec = LoadedSpec::parse(text, std::path::Path::new("spread.toml")).unwrap();
        let library = PoseLibrary::load(&spec.spec, None).unwrap();
        let plan = Plan::new(&spec, &library.frame_counts()).unwrap();
        let test = plan.split_names.iter().position(|n| n == "test").unwrap();
        let all = chosen_samples(&plan, test, 100);
        assert_eq!(all.len(), 2);
        assert_eq!((all[0].len(), all[1].len()), (6, 3));
        for (g, ks) in all.iter().enumerate() {
            assert!(ks.windows(2).all(|w| w[0] < w[1]));
            for &k in ks {
                let d = plan.sample(k);
                assert_eq!((d.garment, d.split), (g, test));
            }
        }
        let two = chosen_samples(&plan, test, 2);
        assert_eq!(two[0], vec![all[0][0], all[0][3]]);
        assert_eq!(two[1], vec![all[1][0], all[1][1]]);
        assert_eq!(two, chosen_samples(&plan, test, 2));
    }

    #[test]
    fn overrides_replace_the_spec_key_by_key() {
        let spec = SimulatorSpec {
            density: Some(0.2),
            max_settle_steps: Some(300),
            skinning: Some("lbs".into()),
            waistband: Some(false),
            ..Default::default()
        };
        let over = SimulatorSpec {
            max_settle_steps: Some(50),
            friction: Some(0.3),
            waistband: Some(true),
            ..Default::default()
        };
        let m = merged_simulator(&spec, &over);
        assert_eq!(
            m,
            SimulatorSpec {
                density: Some(0.2),
                max_settle_steps: Some(50),
                friction: Some(0.3),
                skinning: Some("lbs".into()),
                waistband: Some(true),
                ..Default::default()
            }
        );
        assert_eq!(merged_simulator(&spec, &SimulatorSpec::default()), spec);
        assert_eq!(merged_simulator(&SimulatorSpec::default(), &over), over);
    }

    fn figures(converged: bool, settle: u32, strain: f32, pen: f32, wall: f64) -> DrapeFigures {
        DrapeFigures {
            converged,
            animation_steps: 50,
            settle_steps: settle,
            strain_p99: strain,
            max_penetration_m: pen,
            wall_time_s: wall,
        }
    }

    fn row(
        index: u64,
        dist: [f32; 2],
        norm: [f32; 2],
        drapes: [Option<DrapeFigures>; 3],
    ) -> SpreadRow {
        let all = drapes.iter().all(Option::is_some);
        SpreadRow {
            index,
            garment: "tshirt".into(),
            body: index as u32,
            pose: format!("walk#{index}"),
            e_dist_up_cm: all.then_some(dist[0]),
            e_dist_down_cm: all.then_some(dist[1]),
            e_norm_up_deg: all.then_some(norm[0]),
            e_norm_down_deg: all.then_some(norm[1]),
            drapes: drapes
                .into_iter()
                .zip(VARIANTS)
                .map(|(f, v)| SpreadDrape {
                    variant: v.into(),
                    density_kg_m2: 0.15,
                    error: f.is_none().then(|| "drape: diverged".to_string()),
                    figures: f,
                })
                .collect(),
            error: None,
        }
    }

    #[test]
    fn aggregation_of_hand_made_rows() {
        let f = figures;
        let rows = vec![
            row(
                1,
                [0.1, 0.3],
                [1.0, 2.0],
                [
                    Some(f(true, 100, 0.01, 0.0005, 1.0)),
                    Some(f(true, 120, 0.01, 0.0, 2.0)),
                    Some(f(false, 400, 0.03, 0.0002, 3.0)),
                ],
            ),
            row(
                2,
                [0.5, 0.7],
                [3.0, 4.0],
                [
                    Some(f(true, 80, 0.015, 0.0001, 1.0)),
                    Some(f(true, 90, 0.01, 0.0, 1.0)),
                    Some(f(true, 100, 0.01, 0.0, 1.0)),
                ],
            ),
            // The up drape failed: no distances, its base still counts.
            row(
                3,
                [9.0, 9.0],
                [9.0, 9.0],
                [
                    Some(f(false, 400, 0.05, 0.0009, 2.0)),
                    None,
                    Some(f(true, 60, 0.01, 0.0, 2.0)),
                ],
            ),
            SpreadRow {
                drapes: Vec::new(),
                error: Some("procedural pose: no valid pose".into()),
                ..row(4, [0.0; 2], [0.0; 2], [None, None, None])
            },
        ];
        let g = summarise("tshirt", &rows, 30.0);
        let close = |a: Option<f64>, b: f64| {
            assert!((a.unwrap() - b).abs() < 1e-6, "{a:?} vs {b}");
        };
        assert_eq!((g.samples, g.drapes, g.failed, g.compared), (4, 12, 4, 2));
        close(g.e_dist_up_cm, 0.3);
        close(g.e_dist_down_cm, 0.5);
        close(g.e_dist_cm, 0.4);
        close(g.e_norm_up_deg, 2.0);
        close(g.e_norm_down_deg, 3.0);
        close(g.e_norm_deg, 2.5);
        // Base drapes made: rows 1, 2, 3; at rest: 1 and 2.
        close(g.base_at_rest, 2.0 / 3.0);
        // Compared rows 1 and 2: only 2 has all three at rest.
        close(g.all_at_rest, 0.5);
        assert_eq!(g.max_penetration_m, Some(0.0009));
        // 8 drapes made; strain p99 under 2%: all but two.
        close(g.strain_ok, 6.0 / 8.0);
        // Settle steps 60 80 90 100 100 120 400 400: median (100 + 100) / 2.
        close(g.median_settle_steps, 100.0);
        close(g.median_animation_steps, 50.0);
        close(g.mean_drape_s, 13.0 / 8.0);
        close(Some(g.drapes_per_min), 24.0);
        assert_eq!(g.failures.len(), 2);
        assert_eq!(
            (g.failures[0].index, g.failures[0].variant.as_str()),
            (3, "up")
        );
        assert_eq!(
            (g.failures[1].index, g.failures[1].variant.as_str()),
            (4, "all")
        );
        assert!(g.failures[1].message.contains("no valid pose"));
        // No rows: no figures, no division by zero.
        let none = summarise("jeans", &[], 0.0);
        assert_eq!(
            (none.samples, none.e_dist_cm, none.drapes_per_min),
            (0, None, 0.0)
        );
    }

    #[test]
    fn report_renders_a_table_and_csv() {
        let f = figures(true, 10, 0.01, 0.0, 1.5);
        let rows = vec![row(
            7,
            [0.25, 0.5],
            [1.0, 1.5],
            [Some(f.clone()), Some(f.clone()), Some(f)],
        )];
        let report = SpreadReport {
            spec_name: "t".into(),
            spec_path: "t.toml".into(),
            spec_hash: "0123456789abcdef0123".into(),
            split: "test".into(),
            per_garment: 1,
            step: 0.001,
            densities_kg_m2: [0.15, 0.15015, 0.14985],
            simulator_file: None,
            simulator: SimulatorSpec::default(),
            jobs: 1,
            wall_s: 4.5,
            drapes_per_min: 40.0,
            garments: vec![summarise("tshirt", &rows, 4.5)],
            rows,
        };
        let md = report.markdown();
        assert!(
            md.contains("| tshirt | 3 | 0 | 0.250 / 0.500 | 0.375 |"),
            "{md}"
        );
        let csv = report.csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(
            lines[1],
            "7,tshirt,7,walk#7,0.25,0.5,1,1.5,true,true,true,10,10,10,0.01,4.500,"
        );
        assert_eq!(
            lines[0].split(',').count(),
            lines[1].split(',').count(),
            "{csv}"
        );
        let json = serde_json::to_string(&report).unwrap();
        let back: SpreadReport = serde_json::from_str(&json).unwrap();
        assert_eq!(back, report);
        assert_eq!(csv_field("a,b \"c\""), "\"a,b \"\"c\"\"\"");
    }
}
