//! The small records that describe samples and failures, shared by shard metadata, part
//! files and the manifest.
//!
//! Everything in a [`SampleRecord`] or [`FailureRecord`] is a pure function of the spec
//! and the sample index, so shards holding them are byte-identical between runs; wall
//! times ([`Timing`]) are kept apart, in part files and the manifest only.

use serde::{Deserialize, Serialize};
use sim::stats::DrapeStats;

/// The simulator's statistics of a drape, without its wall time (deterministic).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SimStats {
    /// Steps of the body animation (shape morph, then pose).
    pub animation_steps: u32,
    /// Steps spent settling after the animation.
    pub settle_steps: u32,
    /// Kinetic energy at the end, joules.
    pub final_kinetic_energy: f32,
    /// Largest depth of a garment vertex inside the body, metres.
    pub max_penetration_m: f32,
    /// 99th percentile of the garment vertices' depths inside the body, metres.
    pub p99_penetration_m: f32,
    /// Median edge strain (length / rest - 1).
    pub strain_p50: f32,
    /// 90th percentile of the edge strain.
    pub strain_p90: f32,
    /// 99th percentile of the edge strain.
    pub strain_p99: f32,
    /// Largest edge strain.
    pub strain_max: f32,
    /// Whether the cloth came to rest within the step budget.
    pub converged: bool,
    /// The largest turn of a limb joint by the pose's clearance correction, degrees.
    pub limb_turn_deg: f32,
    /// Walks of garment vertices out of the body the shortest way (caught between
    /// overlapping body parts; see `sim::stats::DrapeStats::walked_out`).
    pub walked_out: u32,
    /// How far the garment slid on the body, metres (`sim::stats::DrapeStats::slid_m`).
    pub slid_m: f32,
}

impl From<&DrapeStats> for SimStats {
    fn from(s: &DrapeStats) -> Self {
        Self {
            animation_steps: s.animation_steps,
            settle_steps: s.settle_steps,
            final_kinetic_energy: s.final_kinetic_energy,
            max_penetration_m: s.max_penetration_m,
            p99_penetration_m: s.p99_penetration_m,
            strain_p50: s.strain_p50,
            strain_p90: s.strain_p90,
            strain_p99: s.strain_p99,
            strain_max: s.strain_max,
            converged: s.converged,
            limb_turn_deg: s.limb_turn_deg,
            walked_out: s.walked_out,
            slid_m: s.slid_m,
        }
    }
}

/// Which drapes to keep by their simulator statistics (poor labels: garments that never
/// came to rest, were stretched far beyond what cloth does, caught on a body part, or slid
/// down the body).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DrapeFilter {
    /// Keep only drapes that came to rest within the step budget.
    pub at_rest: bool,
    /// Keep only drapes whose strain p99 is at most this (a fraction, 0.05 = 5%).
    pub max_strain_p99: Option<f32>,
    /// Keep only drapes whose garment slid at most this far on the body (metres,
    /// [`SimStats::slid_m`]).
    pub max_slid_m: Option<f32>,
}

impl DrapeFilter {
    /// Whether a drape with statistics `s` passes.
    pub fn keeps(&self, s: &SimStats) -> bool {
        (!self.at_rest || s.converged)
            && self.max_strain_p99.is_none_or(|m| s.strain_p99 <= m)
            && self.max_slid_m.is_none_or(|m| s.slid_m <= m)
    }

    /// The filter in words ("drapes at rest with strain p99 at most 5%").
    pub fn describe(&self) -> String {
        let mut text = String::from("drapes");
        if self.at_rest {
            text += " at rest";
        }
        if let Some(m) = self.max_strain_p99 {
            text += &format!(" with strain p99 at most {}%", m * 100.0);
        }
        if let Some(m) = self.max_slid_m {
            let and = if self.max_strain_p99.is_some() {
                " and"
            } else {
                ""
            };
            text += &format!("{and} whose garment slid at most {} cm", m * 100.0);
        }
        text
    }
}

/// What a stored sample is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleRecord {
    /// Sample index in the plan.
    pub index: u64,
    /// Garment name.
    pub garment: String,
    /// Id of the template (file `templates/ID.garment`).
    pub template: String,
    /// Body index.
    pub body: u32,
    /// Split name.
    pub split: String,
    /// Pose id: `CLIP#FRAME` or `procedural[S]:KIND#DRAW`.
    pub pose: String,
    /// The body's stature, metres.
    pub stature_m: f32,
    /// The body's mass index, kg/m^2.
    pub bmi: f32,
    /// Simulator statistics.
    pub stats: SimStats,
}

/// A sample whose drape failed: listed, never stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FailureRecord {
    /// Sample index in the plan.
    pub index: u64,
    /// Garment name.
    pub garment: String,
    /// Body index.
    pub body: u32,
    /// Split name.
    pub split: String,
    /// Pose id.
    pub pose: String,
    /// Why it failed (the simulator's error, or a pose that could not be drawn).
    pub reason: String,
}

/// Wall times of one sample on the machine that made it, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// The whole sample: body, pose, template, drape, warp and writing.
    pub sample_s: f64,
    /// The drape alone (the simulator's `wall_time_s`; 0 if it failed early).
    pub drape_s: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drape_filter_keeps_what_it_says() {
        let ok = SimStats {
            converged: true,
            strain_p99: 0.02,
            ..Default::default()
        };
        let restless = SimStats {
            converged: false,
            ..ok.clone()
        };
        let strained = SimStats {
            strain_p99: 0.3,
            ..ok.clone()
        };
        let all = DrapeFilter::default();
        assert!(all.keeps(&ok) && all.keeps(&restless) && all.keeps(&strained));
        let f = DrapeFilter {
            at_rest: true,
            max_strain_p99: Some(0.05),
            max_slid_m: None,
        };
        assert!(f.keeps(&ok) && !f.keeps(&restless) && !f.keeps(&strained));
        assert_eq!(f.describe(), "drapes at rest with strain p99 at most 5%");
        let slid = |d: f32| SimStats {
            slid_m: d,
            ..ok.clone()
        };
        let g = DrapeFilter {
            max_slid_m: Some(0.1),
            ..f
        };
        assert!(g.keeps(&slid(0.04)) && g.keeps(&slid(0.1)));
        assert!(!g.keeps(&slid(0.17)) && !g.keeps(&restless));
        assert_eq!(
            g.describe(),
            "drapes at rest with strain p99 at most 5% and whose garment slid at most 10 cm"
        );
    }
}
