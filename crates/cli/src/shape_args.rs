//! Command-line arguments that choose a body shape.

use body::shape_sampler::ShapeDistribution;
use body::{BodyModel, Phenotype};
use clap::Args;

/// Body shape: explicit phenotype parameters, or a random realistic adult.
#[derive(Args, Debug, Clone)]
pub struct ShapeArgs {
    /// Draw a realistic adult shape (stature and BMI like real adults) from this seed;
    /// overrides the phenotype flags.
    #[arg(long, value_name = "SEED")]
    pub random_shape: Option<u64>,
    /// 0 male .. 1 female.
    #[arg(long, default_value_t = 0.5)]
    pub gender: f32,
    /// 0 baby, 1/3 child, 2/3 young adult, 1 old.
    #[arg(long, default_value_t = 0.5)]
    pub age: f32,
    /// 0 .. 1 (0.5 average).
    #[arg(long, default_value_t = 0.5)]
    pub muscle: f32,
    /// 0 .. 1 (0.5 average).
    #[arg(long, default_value_t = 0.5)]
    pub weight: f32,
    /// 0 .. 1 (uncalibrated: prefer --random-shape for realistic statures).
    #[arg(long, default_value_t = 0.5)]
    pub height: f32,
    /// 0 ideal .. 1 uncommon.
    #[arg(long, default_value_t = 0.5)]
    pub proportions: f32,
    /// Race shares african, asian, caucasian (normalised), e.g. `--race 0.2,0.3,0.5`.
    #[arg(long, value_delimiter = ',', num_args = 3, default_values_t = [1.0, 1.0, 1.0])]
    pub race: Vec<f32>,
}

impl ShapeArgs {
    /// The flag defaults (the default phenotype), as clap would fill them.
    pub fn defaults() -> Self {
        Self {
            random_shape: None,
            gender: 0.5,
            age: 0.5,
            muscle: 0.5,
            weight: 0.5,
            height: 0.5,
            proportions: 0.5,
            race: vec![1.0, 1.0, 1.0],
        }
    }

    /// The phenotype these arguments describe (solving a random shape if asked).
    pub fn phenotype(&self, model: &BodyModel) -> anyhow::Result<Phenotype> {
        if let Some(seed) = self.random_shape {
            let s = ShapeDistribution::default().sample(model, seed)?;
            eprintln!(
                "shape {seed}: stature {:.1} cm (target {:.1}), BMI {:.1} (target {:.1})",
                s.stature * 100.0,
                s.target_stature * 100.0,
                s.bmi,
                s.target_bmi
            );
            return Ok(s.phenotype);
        }
        let p = Phenotype {
            gender: self.gender,
            age: self.age,
            muscle: self.muscle,
            weight: self.weight,
            height: self.height,
            proportions: self.proportions,
            african: self.race[0],
            asian: self.race[1],
            caucasian: self.race[2],
            ..Phenotype::default()
        };
        p.validate()?;
        Ok(p)
    }
}
