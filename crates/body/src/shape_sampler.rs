//! A sampler of realistic adult body shapes.
//!
//! The phenotype's `height` and `weight` axes are not calibrated (an adult male at
//! height 1 stands 2.4 m), so shapes are drawn in measurable terms, stature and body
//! mass index per sex, and the phenotype is solved to hit them on the actual mesh
//! (stature = vertical extent, mass = volume x body density). The default
//! distributions follow adult anthropometric surveys (stature: men 1.76 m, women
//! 1.63 m, standard deviations about 7 cm; BMI log-normal with median 25.5).

use rand::{rngs::StdRng, Rng, SeedableRng};
use rand_distr::{Distribution, LogNormal, Normal};
use serde::{Deserialize, Serialize};

use crate::model::{BodyModel, ShapedBody};
use crate::phenotype::Phenotype;
use crate::BodyError;

/// Whole-body density used to turn mesh volume into mass, kg/m^3.
pub const BODY_DENSITY: f32 = 985.0;

/// Parameters of the adult shape distribution.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ShapeDistribution {
    /// Share of female bodies, [0, 1].
    pub female_share: f32,
    /// Mean and standard deviation of male stature, metres.
    pub male_stature: (f32, f32),
    /// Mean and standard deviation of female stature, metres.
    pub female_stature: (f32, f32),
    /// Median and log-standard deviation of the body mass index, kg/m^2.
    pub bmi: (f32, f32),
    /// Range of BMI kept (draws outside are redrawn), kg/m^2.
    pub bmi_range: (f32, f32),
    /// Range of the age parameter (2/3 = 25 years, 1 = 90 years).
    pub age_range: (f32, f32),
    /// Standard deviation of the muscle parameter around 0.5.
    pub muscle_sd: f32,
    /// Statures further than this many standard deviations from the mean are redrawn.
    pub max_sigma: f32,
}

impl Default for ShapeDistribution {
    fn default() -> Self {
        Self {
            female_share: 0.5,
            male_stature: (1.76, 0.07),
            female_stature: (1.63, 0.065),
            bmi: (25.5, 0.16),
            bmi_range: (17.5, 38.0),
            age_range: (2.0 / 3.0, 0.9),
            muscle_sd: 0.15,
            max_sigma: 2.5,
        }
    }
}

/// What a sampled shape was aimed at and what it reached.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShapeSample {
    pub phenotype: Phenotype,
    /// Target and achieved stature, metres.
    pub target_stature: f32,
    pub stature: f32,
    /// Target and achieved body mass index, kg/m^2.
    pub target_bmi: f32,
    pub bmi: f32,
}

/// Stature (m) and BMI (kg/m^2) of a shaped body.
pub fn stature_and_bmi(body: &ShapedBody) -> (f32, f32) {
    let h = body.height();
    (h, body.volume() * BODY_DENSITY / (h * h))
}

impl ShapeDistribution {
    /// Draws one body shape, reproducibly from `seed`, and solves its height and
    /// weight parameters so that the mesh has the drawn stature and BMI (to about
    /// 2 mm and 0.2 kg/m^2 where the model can reach them).
    pub fn sample(&self, model: &BodyModel, seed: u64) -> Result<ShapeSample, BodyError> {
        let (mut phenotype, target_stature, target_bmi) = self.draw(seed)?;
        let (stature, bmi) =
            solve_height_weight(model, &mut phenotype, target_stature, target_bmi)?;
        Ok(ShapeSample {
            phenotype,
            target_stature,
            stature,
            target_bmi,
            bmi,
        })
    }

    /// The random part of [`ShapeDistribution::sample`]: a valid phenotype (height and
    /// weight still at 0.5) with its target stature (m) and BMI (kg/m^2).
    pub fn draw(&self, seed: u64) -> Result<(Phenotype, f32, f32), BodyError> {
        let mut rng = StdRng::seed_from_u64(seed);
        let female = rng.random::<f32>() < self.female_share;
        let (mean, sd) = if female {
            self.female_stature
        } else {
            self.male_stature
        };
        let stature_dist =
            Normal::new(mean, sd).map_err(|e| BodyError::Parameter(format!("stature: {e}")))?;
        let bmi_dist = LogNormal::new(self.bmi.0.ln(), self.bmi.1)
            .map_err(|e| BodyError::Parameter(format!("bmi: {e}")))?;
        let target_stature = loop {
            let s = stature_dist.sample(&mut rng);
            if (s - mean).abs() <= self.max_sigma * sd {
                break s;
            }
        };
        let target_bmi = loop {
            let b = bmi_dist.sample(&mut rng);
            if (self.bmi_range.0..=self.bmi_range.1).contains(&b) {
                break b;
            }
        };
        let shares: [f32; 3] = std::array::from_fn(|_| rng.random_range(0.05..=1.0));
        let phenotype = Phenotype {
            gender: if female {
                rng.random_range(0.9..=1.0)
            } else {
                rng.random_range(0.0..=0.1)
            },
            age: rng.random_range(self.age_range.0..=self.age_range.1),
            muscle: (0.5 + self.muscle_sd * Normal::new(0.0f32, 1.0).unwrap().sample(&mut rng))
                .clamp(0.05, 0.95),
            proportions: rng.random_range(0.0..=0.5),
            cupsize: rng.random_range(0.3..=0.8),
            firmness: rng.random_range(0.3..=0.8),
            african: shares[0],
            asian: shares[1],
            caucasian: shares[2],
            ..Phenotype::default()
        };
        phenotype.validate()?;
        Ok((phenotype, target_stature, target_bmi))
    }
}

/// Solves the phenotype's `height` and `weight` (then `muscle`, if the model's heaviest
/// `weight` still falls short of the BMI) so that the shaped mesh has `stature` (m) and
/// `bmi` (kg/m^2), keeping parameters in [0, 1]. Returns the achieved stature and BMI:
/// targets the model cannot reach end at the nearest reachable shape.
pub fn solve_height_weight(
    model: &BodyModel,
    p: &mut Phenotype,
    stature: f32,
    bmi: f32,
) -> Result<(f32, f32), BodyError> {
    let mut cur = newton_height_and(model, p, stature, bmi, |p| &mut p.weight, 1.0)?;
    if p.weight >= 1.0 && cur.1 < bmi - 0.2 {
        // Heavier still: some more muscle, short of a body-builder's build.
        cur = newton_height_and(
            model,
            p,
            stature,
            bmi,
            |p| &mut p.muscle,
            MAX_FALLBACK_MUSCLE.max(p.muscle),
        )?;
    }
    // Where the mass parameters saturated, stature still wins: secant on height alone.
    let mut prev = (p.height, cur.0);
    for _ in 0..4 {
        if (stature - cur.0).abs() < 0.002 {
            break;
        }
        let h = p.height;
        let slope = if prev.0 != h {
            (cur.0 - prev.1) / (h - prev.0)
        } else {
            0.5
        };
        p.height = (h + (stature - cur.0) / slope.max(0.05)).clamp(0.0, 1.0);
        prev = (h, cur.0);
        cur = stature_and_bmi(&model.shape(p)?);
    }
    Ok(cur)
}

/// The most muscle the BMI solve adds when the heaviest `weight` is not enough.
const MAX_FALLBACK_MUSCLE: f32 = 0.7;

/// Newton iterations on (height, `second`) with a finite-difference Jacobian; `second`
/// stays in [0, `second_max`].
fn newton_height_and(
    model: &BodyModel,
    p: &mut Phenotype,
    stature: f32,
    bmi: f32,
    second: fn(&mut Phenotype) -> &mut f32,
    second_max: f32,
) -> Result<(f32, f32), BodyError> {
    const STEP: f32 = 0.05;
    let eval =
        |p: &Phenotype| -> Result<(f32, f32), BodyError> { Ok(stature_and_bmi(&model.shape(p)?)) };
    // Finite-difference column for one parameter: d(stature, bmi)/d parameter, stepping
    // backwards at the upper bound.
    let column = |p: &Phenotype, cur: (f32, f32), get: fn(&mut Phenotype) -> &mut f32| {
        let mut q = *p;
        let x = *get(&mut q);
        let h = if x + STEP <= 1.0 { STEP } else { -STEP };
        // (Stepping past `second_max` only probes the slope.)
        *get(&mut q) = x + h;
        eval(&q).map(|d| ((d.0 - cur.0) / h, (d.1 - cur.1) / h))
    };
    let mut cur = eval(p)?;
    for _ in 0..6 {
        let r = (stature - cur.0, bmi - cur.1);
        if r.0.abs() < 0.002 && r.1.abs() < 0.2 {
            break;
        }
        let (a, c) = column(p, cur, |p| &mut p.height)?;
        let (b, d) = column(p, cur, second)?;
        let det = a * d - b * c;
        if det.abs() < 1e-9 {
            break;
        }
        let (old_h, old_x) = (p.height, *second(p));
        p.height = (old_h + (d * r.0 - b * r.1) / det).clamp(0.0, 1.0);
        *second(p) = (old_x + (-c * r.0 + a * r.1) / det).clamp(0.0, second_max);
        cur = eval(p)?;
        if p.height == old_h && *second(p) == old_x {
            break;
        }
    }
    Ok(cur)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression: race shares were drawn up to 1.05, outside the valid range.
    #[test]
    fn every_draw_is_a_valid_phenotype() {
        let dist = ShapeDistribution::default();
        for seed in 0..5000 {
            let (p, stature, bmi) = dist.draw(seed).unwrap();
            assert!(p.validate().is_ok(), "seed {seed}: {p:?}");
            assert!(
                (1.4..2.0).contains(&stature) && (17.0..=38.0).contains(&bmi),
                "seed {seed}"
            );
        }
    }
}
