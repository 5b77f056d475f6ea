//! The figures of a spread measurement: per drape, per sample, per garment, and the
//! report with its markdown table and CSV rows (cm, degrees, mm, percent).

use serde::{Deserialize, Serialize};

use super::STRAIN_OK;
use crate::spec::SimulatorSpec;

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
pub(super) fn per_minute(n: usize, wall_s: f64) -> f64 {
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
/// A figure with `digits` decimals, `-` when there is none.
fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".into(), |v| format!("{v:.digits$}"))
}

/// A share as a percentage, `-` when there is none.
fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |v| format!("{:.0}%", 100.0 * v))
}

/// A CSV field: quoted when it holds a comma, a quote or a line break.
pub(super) fn csv_field(s: &str) -> String {
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
