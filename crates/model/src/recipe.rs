//! Training recipes: everything that trains one network from scratch, in one TOML file
//! (`recipes/GARMENT-VARIANT.toml`). A checkpoint stores the recipe it was trained by
//! ([`RecipeRecord`]), so a model card can say how to train it again.
//!
//! ```toml
//! format = 1
//! garment = "tshirt"          # the garment's name in the dataset
//! variant = "local"           # local | global | naive
//! data = "out/standard-lbs"   # the dataset folder (`garnet train --data` overrides it)
//!
//! [network]                   # GarNetConfig widths; any left out keep their defaults
//! body_contact = true
//! rest_input = true
//!
//! [loss]                      # weights of the terms; L_vertex squared or the distance
//! vertex = 1.0
//! curvature = 0.0             # GarNet++'s L_curv (off)
//! vertex_loss = "squared"
//! normal_loss = "paper"       # or "tilt": L_norm in centimetres, linear in the angle
//!
//! [schedule]
//! epochs = 30
//! batch = 1
//! lr = 3e-4                   # Adam's rate, held for `warmup_epochs`,
//! warmup_epochs = 1
//! cosine_to = 1e-5            # then along half a cosine to this rate at `epochs`
//! per_step = true             # the cosine followed step by step, not epoch by epoch
//! grad_clip = 200.0
//! # minutes = 30.0          # or a compute budget: stop after 30 CPU minutes of training
//! # warmup_minutes = 1.0    # steps, the cosine over the budget (epochs is then a cap)
//!
//! [drapes]                    # which training drapes to use (validation keeps all)
//! at_rest = true
//! max_strain_pct = 5.0
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::config::{Base, GarNetConfig, Variant};
use crate::error::{ModelError, Result};
use crate::loss::{LossConfig, NormalLoss, VertexLoss};
use crate::schedule::{CosineSchedule, TimeBudget};

/// The recipe format this build reads and writes.
pub const RECIPE_FORMAT: u32 = 1;

/// A training recipe (see the module docs for the file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Recipe {
    /// Format version, [`RECIPE_FORMAT`].
    pub format: u32,
    /// The garment's name in the dataset (`tshirt`, `sweater`, `jeans` unless the dataset's
    /// spec named them otherwise).
    pub garment: String,
    /// The network variant: `local`, `global` or `naive`.
    pub variant: String,
    /// The dataset folder (made by `garnet dataset generate`), relative to the working
    /// directory.
    pub data: PathBuf,
    /// The network's widths and inputs.
    #[serde(default)]
    pub network: NetworkRecipe,
    /// The loss.
    #[serde(default)]
    pub loss: LossRecipe,
    /// Epochs, batch and learning rate.
    pub schedule: ScheduleRecipe,
    /// Which training drapes to use.
    #[serde(default)]
    pub drapes: DrapesRecipe,
}

/// The network's widths and inputs: fields of [`GarNetConfig`]; a field left out keeps the
/// config's default.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkRecipe {
    /// [`GarNetConfig::body_subsample`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub body_subsample: Option<usize>,
    /// [`GarNetConfig::body_mlp2`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub body_mlp2: Option<Vec<usize>>,
    /// [`GarNetConfig::garment_mlp`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub garment_mlp: Option<Vec<usize>>,
    /// [`GarNetConfig::conv_width`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conv_width: Option<usize>,
    /// [`GarNetConfig::conv_blocks`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conv_blocks: Option<usize>,
    /// [`GarNetConfig::local_width`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub local_width: Option<usize>,
    /// [`GarNetConfig::garment_global`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub garment_global: Option<usize>,
    /// [`GarNetConfig::fusion`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fusion: Option<Vec<usize>>,
    /// [`GarNetConfig::body_contact`] (default false: the paper's inputs).
    #[serde(default)]
    pub body_contact: bool,
    /// [`GarNetConfig::rest_input`] (default false: the paper's inputs).
    #[serde(default)]
    pub rest_input: bool,
    /// [`GarNetConfig::base`] by its [`Base::name`] (`dqs`, the paper's, when left out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base: Option<String>,
    /// [`GarNetConfig::seed`]: the initial parameters' seed.
    #[serde(default)]
    pub seed: u64,
}

/// The loss's weights (the paper's by default) and how L_vertex measures a distance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LossRecipe {
    /// Weight of L_vertex (1).
    pub vertex: f64,
    /// Weight of L_pen (1).
    pub pen: f64,
    /// Weight of L_norm (0.3).
    pub norm: f64,
    /// Weight of L_bend (0.5).
    pub bend: f64,
    /// Weight of L_curv, GarNet++'s curvature term (0: off).
    pub curvature: f64,
    /// `squared` (the paper's) or `distance` (see [`VertexLoss`]).
    pub vertex_loss: String,
    /// `paper` (the paper's) or `tilt` (see [`NormalLoss`]).
    pub normal_loss: String,
}

impl Default for LossRecipe {
    fn default() -> Self {
        let paper = LossConfig::new();
        LossRecipe {
            vertex: paper.vertex,
            pen: paper.pen,
            norm: paper.norm,
            bend: paper.bend,
            curvature: paper.curvature,
            vertex_loss: paper.vertex_loss.name().into(),
            normal_loss: paper.normal_loss.name().into(),
        }
    }
}

/// Epochs, batch size and the learning-rate schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScheduleRecipe {
    /// Epochs to train.
    pub epochs: usize,
    /// Samples per batch (default 8).
    #[serde(default = "default_batch")]
    pub batch: usize,
    /// Adam's learning rate (default the paper's 1e-3).
    #[serde(default = "default_lr")]
    pub lr: f64,
    /// Epochs at `lr` before the cosine starts (default 0).
    #[serde(default)]
    pub warmup_epochs: usize,
    /// The rate the cosine ends at, at `epochs` (none: `lr` throughout).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cosine_to: Option<f64>,
    /// Follow the cosine step by step instead of once an epoch (default false).
    #[serde(default)]
    pub per_step: bool,
    /// Clip each step's gradients to this joint L2 norm (none: no clipping).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grad_clip: Option<f32>,
    /// Seed of the per-epoch shuffle (default 0).
    #[serde(default)]
    pub seed: u64,
    /// A compute budget, CPU minutes of training steps (every thread of the process; see
    /// [`crate::TimeBudget`]): the run stops when it is used, and the rate is held for
    /// `warmup_minutes`, then follows the cosine to `cosine_to` over the rest of the budget
    /// (step by step). `epochs` stays a cap. None: the run is measured in epochs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub minutes: Option<f64>,
    /// With `minutes`: CPU minutes at `lr` before the cosine starts (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub warmup_minutes: f64,
    /// Inside an epoch, write a resumable checkpoint every this many minutes (default 10;
    /// 0: never).
    #[serde(default = "default_checkpoint_minutes")]
    pub checkpoint_minutes: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn default_batch() -> usize {
    8
}

fn default_lr() -> f64 {
    crate::train::PAPER_LEARNING_RATE
}

fn default_checkpoint_minutes() -> f64 {
    10.0
}

/// Which training drapes a recipe uses (every drape by default; validation keeps all).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrapesRecipe {
    /// Only drapes that came to rest within the simulator's step budget.
    #[serde(default)]
    pub at_rest: bool,
    /// Only drapes whose strain p99 is at most this, percent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_strain_pct: Option<f32>,
    /// Only drapes whose garment slid at most this far on the body, cm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_slide_cm: Option<f32>,
    /// At most this many training samples (quick runs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_samples: Option<usize>,
}

impl DrapesRecipe {
    /// Whether any filter is set (`max_samples` aside).
    pub fn filters(&self) -> bool {
        self.at_rest || self.max_strain_pct.is_some() || self.max_slide_cm.is_some()
    }
}

impl Recipe {
    /// Reads and checks the recipe at `path`; errors name the file and the problem.
    pub fn load(path: &Path) -> Result<Recipe> {
        let text = std::fs::read_to_string(path).map_err(|e| ModelError::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
        Recipe::parse(&text)
            .map_err(|e| ModelError::InvalidInput(format!("{}: {e}", path.display())))
    }

    /// Parses and checks a recipe's TOML text.
    pub fn parse(text: &str) -> Result<Recipe> {
        let format = toml::from_str::<toml::Table>(text)
            .map_err(|e| ModelError::InvalidInput(format!("not a recipe: {e}")))?
            .get("format")
            .and_then(|f| f.as_integer());
        if format != Some(RECIPE_FORMAT as i64) {
            return Err(ModelError::InvalidInput(format!(
                "recipe format {} is not the one this build reads (`format = {RECIPE_FORMAT}`)",
                format.map_or("missing".into(), |f| f.to_string())
            )));
        }
        let recipe: Recipe =
            toml::from_str(text).map_err(|e| ModelError::InvalidInput(format!("recipe: {e}")))?;
        recipe.validate()?;
        Ok(recipe)
    }

    /// The recipe as TOML text ([`Recipe::parse`] reads it back equal).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a recipe is plain data")
    }

    /// Fails on an unknown variant or L_vertex kind, a bad network or loss, or a schedule
    /// that cannot run (no epochs, a zero batch, a rate that is not positive, a warm-up as
    /// long as the run, a negative filter).
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(ModelError::InvalidInput(m));
        if self.garment.is_empty() {
            return bad("the recipe names no garment".into());
        }
        self.network_config()?.validate()?;
        self.loss_config()?.validate()?;
        let s = &self.schedule;
        if s.epochs == 0 || s.batch == 0 {
            return bad(format!(
                "schedule: epochs and batch must be at least 1, got {} and {}",
                s.epochs, s.batch
            ));
        }
        let rate_ok = |r: f64| r.is_finite() && r > 0.0;
        if !rate_ok(s.lr) || s.cosine_to.is_some_and(|r| !rate_ok(r)) {
            return bad(format!(
                "schedule: learning rates must be > 0, got lr {} and cosine_to {:?}",
                s.lr, s.cosine_to
            ));
        }
        if s.minutes.is_some() {
            if s.warmup_epochs != 0 || s.per_step {
                return bad("schedule: a budget in minutes takes warmup_minutes, not \
                            warmup_epochs or per_step (it always goes step by step)"
                    .into());
            }
            self.time_budget()?;
        } else if s.warmup_minutes != 0.0 {
            return bad("schedule: warmup_minutes needs a budget (minutes)".into());
        }
        if s.minutes.is_none() && s.cosine_to.is_some() && s.warmup_epochs >= s.epochs {
            return bad(format!(
                "schedule: the cosine needs warmup_epochs ({}) below epochs ({})",
                s.warmup_epochs, s.epochs
            ));
        }
        if s.cosine_to.is_none() && s.per_step {
            return bad("schedule: per_step needs cosine_to".into());
        }
        if s.grad_clip.is_some_and(|g| !(g.is_finite() && g > 0.0)) {
            return bad(format!(
                "schedule: grad_clip must be > 0, got {:?}",
                s.grad_clip
            ));
        }
        if !(s.checkpoint_minutes.is_finite() && s.checkpoint_minutes >= 0.0) {
            return bad(format!(
                "schedule: checkpoint_minutes must be >= 0, got {}",
                s.checkpoint_minutes
            ));
        }
        let d = &self.drapes;
        let negative = |v: Option<f32>| v.is_some_and(|v| !(v.is_finite() && v >= 0.0));
        if negative(d.max_strain_pct) || negative(d.max_slide_cm) {
            return bad(format!(
                "drapes: max_strain_pct and max_slide_cm must be >= 0, got {:?} and {:?}",
                d.max_strain_pct, d.max_slide_cm
            ));
        }
        if d.max_samples == Some(0) {
            return bad("drapes: max_samples must be at least 1".into());
        }
        Ok(())
    }

    /// The network variant.
    pub fn variant(&self) -> Result<Variant> {
        Variant::parse(&self.variant)
    }

    /// The network's config: [`GarNetConfig`]'s defaults with the recipe's fields.
    pub fn network_config(&self) -> Result<GarNetConfig> {
        let n = &self.network;
        let mut c = GarNetConfig::new(self.variant()?)
            .with_body_contact(n.body_contact)
            .with_rest_input(n.rest_input)
            .with_seed(n.seed);
        if let Some(v) = &n.base {
            c.base = Base::parse(v)?;
        }
        if let Some(v) = n.body_subsample {
            c.body_subsample = v;
        }
        if let Some(v) = &n.body_mlp2 {
            c.body_mlp2 = v.clone();
        }
        if let Some(v) = &n.garment_mlp {
            c.garment_mlp = v.clone();
        }
        if let Some(v) = n.conv_width {
            c.conv_width = v;
        }
        if let Some(v) = n.conv_blocks {
            c.conv_blocks = v;
        }
        if let Some(v) = n.local_width {
            c.local_width = v;
        }
        if let Some(v) = n.garment_global {
            c.garment_global = v;
        }
        if let Some(v) = &n.fusion {
            c.fusion = v.clone();
        }
        Ok(c)
    }

    /// The loss's config.
    pub fn loss_config(&self) -> Result<LossConfig> {
        let l = &self.loss;
        Ok(LossConfig::new()
            .with_vertex(l.vertex)
            .with_pen(l.pen)
            .with_norm(l.norm)
            .with_bend(l.bend)
            .with_curvature(l.curvature)
            .with_vertex_loss(VertexLoss::parse(&l.vertex_loss)?)
            .with_normal_loss(NormalLoss::parse(&l.normal_loss)?))
    }

    /// The learning-rate schedule of a run whose epochs have `steps_per_epoch` steps: `None`
    /// for a constant rate or a budget in minutes ([`Recipe::time_budget`]), else `lr` until
    /// `warmup_epochs`, then the cosine to `cosine_to` at `epochs`.
    pub fn lr_schedule(&self, steps_per_epoch: u64) -> Result<Option<CosineSchedule>> {
        let s = &self.schedule;
        let (Some(end), None) = (s.cosine_to, s.minutes) else {
            return Ok(None);
        };
        let cosine = CosineSchedule::new(s.lr, end, s.warmup_epochs, s.epochs)?;
        Ok(Some(if s.per_step {
            cosine.per_step(steps_per_epoch)
        } else {
            cosine
        }))
    }

    /// The compute budget of `[schedule] minutes` (`None` without one): `lr` for
    /// `warmup_minutes`, then the cosine to `cosine_to` (or `lr` throughout without it).
    pub fn time_budget(&self) -> Result<Option<TimeBudget>> {
        let s = &self.schedule;
        s.minutes
            .map(|m| TimeBudget::new(m, s.warmup_minutes, s.lr, s.cosine_to.unwrap_or(s.lr)))
            .transpose()
    }
}

/// The recipe a network was trained by and the command that ran it (for model cards),
/// as a checkpoint stores them.
#[derive(Clone, Debug, PartialEq)]
pub struct RecipeRecord {
    /// The recipe, with the command line's overrides applied.
    pub recipe: Recipe,
    /// The training command (`garnet train --recipe recipes/tshirt-local.toml`).
    pub command: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXAMPLE: &str = r#"
format = 1
garment = "tshirt"
variant = "local"
data = "out/standard-lbs"

[network]
body_contact = true
rest_input = true
conv_width = 48
fusion = [256, 128, 64]

[loss]
vertex = 2.0
vertex_loss = "distance"

[schedule]
epochs = 30
batch = 1
lr = 3e-4
warmup_epochs = 1
cosine_to = 1e-5
per_step = true
grad_clip = 200.0

[drapes]
at_rest = true
max_strain_pct = 5.0
"#;

    #[test]
    fn a_recipe_gives_the_network_loss_and_schedule_it_names() {
        let r = Recipe::parse(EXAMPLE).unwrap();
        let c = r.network_config().unwrap();
        assert_eq!(c.variant, Variant::Local);
        assert_eq!((c.conv_width, c.fusion.clone()), (48, vec![256, 128, 64]));
        assert!(c.body_contact && c.rest_input);
        assert_eq!(c.body_mlp2, GarNetConfig::new(Variant::Local).body_mlp2);
        let l = r.loss_config().unwrap();
        assert_eq!(
            (l.vertex, l.norm, l.vertex_loss),
            (2.0, 0.3, VertexLoss::Distance)
        );
        let s = r.lr_schedule(100).unwrap().unwrap();
        assert_eq!(s.lr(0), 3e-4);
        assert_eq!(s.lr_of_step(0, 99), 3e-4);
        assert!((s.lr(30) - 1e-5).abs() < 1e-12);
        assert_eq!(Recipe::parse(&r.to_toml()).unwrap(), r);
    }

    #[test]
    fn bad_recipes_are_refused_with_the_reason() {
        let cases = [
            (EXAMPLE.replace("format = 1", "format = 0"), "format"),
            (EXAMPLE.replace("format = 1\n", ""), "format missing"),
            (EXAMPLE.replace("\"local\"", "\"huge\""), "variant"),
            (EXAMPLE.replace("\"distance\"", "\"cubed\""), "L_vertex"),
            (
                EXAMPLE.replace("vertex = 2.0", "vertex = 2.0\nnormal_loss = \"cos\""),
                "L_norm",
            ),
            (
                EXAMPLE.replace("[network]", "[network]\nbase = \"smpl\""),
                "dqs or anchored",
            ),
            (EXAMPLE.replace("epochs = 30", "epochs = 0"), "epochs"),
            (
                EXAMPLE.replace("warmup_epochs = 1", "warmup_epochs = 30"),
                "warmup",
            ),
            (EXAMPLE.replace("lr = 3e-4", "lr = -1.0"), "rates"),
            (
                EXAMPLE.replace("at_rest = true", "at_rest = true\nmirror = true"),
                "mirror",
            ),
            (
                EXAMPLE.replace("max_strain_pct = 5.0", "max_strain_pct = -5.0"),
                "max_strain",
            ),
            ("garment = ".to_string(), "not a recipe"),
        ];
        for (text, want) in cases {
            let err = Recipe::parse(&text).unwrap_err().to_string();
            assert!(err.contains(want), "{want}: {err}");
        }
    }

    #[test]
    fn a_budget_in_minutes_replaces_the_epoch_schedule() {
        let text = EXAMPLE
            .replace(
                "warmup_epochs = 1\n",
                "minutes = 30.0\nwarmup_minutes = 1.5\n",
            )
            .replace("per_step = true\n", "");
        let r = Recipe::parse(&text).unwrap();
        assert_eq!(r.lr_schedule(100).unwrap(), None);
        let b = r.time_budget().unwrap().unwrap();
        assert_eq!(b, TimeBudget::new(30.0, 1.5, 3e-4, 1e-5).unwrap());
        assert_eq!(Recipe::parse(&r.to_toml()).unwrap(), r);
        assert_eq!(Recipe::parse(EXAMPLE).unwrap().time_budget().unwrap(), None);
        let refused = [
            (text.replace("minutes = 30.0", "minutes = 0.0"), "budget"),
            (
                text.replace("warmup_minutes = 1.5", "warmup_minutes = 30.0"),
                "warm-up",
            ),
            (
                text.replace("minutes = 30.0\n", "per_step = true\n"),
                "needs a budget",
            ),
            (
                text.replace("batch = 1", "batch = 1\nper_step = true"),
                "per_step",
            ),
        ];
        for (t, want) in refused {
            let err = Recipe::parse(&t).unwrap_err().to_string();
            assert!(err.contains(want), "{want}: {err}");
        }
    }

    #[test]
    fn a_missing_file_is_named() {
        let err = Recipe::load(Path::new("no/such/recipe.toml")).unwrap_err();
        assert!(err.to_string().contains("no/such/recipe.toml"), "{err}");
    }
}
