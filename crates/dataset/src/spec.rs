//! The dataset spec: a TOML file naming the garments, the body-shape distribution, the
//! pose sources, the counts, the seed, the splits and the simulator settings.
//!
//! ```toml
//! format = 2                      # the spec format (crate::spec_load::SPEC_FORMAT)
//! name = "tiny"
//! seed = 1
//! shard_size = 32                 # samples per shard file
//!
//! [bodies]
//! count = 6                       # bodies drawn from the distribution
//! [bodies.distribution]           # body::shape_sampler::ShapeDistribution fields
//! female_share = 0.5
//!
//! [[garments]]
//! kind = "tshirt"                 # tshirt, sweater or jeans
//! edge = 0.04                     # template edge length, metres
//! poses_per_body = 2              # samples per body of this garment
//! cut = { sleeve_length = 0.2 }   # fixed cut parameters (metres), others default
//! cut_ranges = { ease = [0.02, 0.04] }  # drawn uniformly per body
//!
//! [[poses.amc]]                   # CMU ASF/AMC clips, paths under the mocap root
//! clips = ["cmu/02/02_01.amc"]
//! every = 60                      # every 60th frame (or: random = 10)
//! [[poses.procedural]]
//! kind = "yoga"                   # walk, yoga, dance or any
//! count = 20
//!
//! [splits.bodies]                 # body counts (or fractions summing to 1)
//! train = 4
//! test = 2
//! [splits.unseen_poses]           # optional: hold out poses too
//! seen_fraction = 0.5             # share of each motion's poses the other splits use
//! held_out = ["test"]             # these splits use only the remaining poses
//!
//! [simulator]                     # overrides of sim::drape::DrapeOptions / ClothParams
//! max_settle_steps = 200
//!
//! [output]
//! fitted = false                  # also store the surface-anchored warp
//! compact = false                 # store no body and no M: readers rebuild them
//! ```
//!
//! A field left out gets the simulator's and the garments' current defaults. A spec may
//! instead name a `base` spec and give only what differs (see [`crate::spec_load`]).
//! Unknown keys are errors; [`LoadedSpec::load`] validates every field and names the file
//! and the field in its errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use body::shape_sampler::ShapeDistribution;
use serde::{Deserialize, Serialize};

use crate::error::{DatasetError, Result};
pub use crate::spec_load::SPEC_FORMAT;

/// A dataset specification (see the module documentation for the TOML form).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    /// The spec format, [`SPEC_FORMAT`].
    pub format: i64,
    /// Free-text name of the dataset.
    #[serde(default)]
    pub name: String,
    /// Seed of every random choice of the dataset.
    pub seed: u64,
    /// Samples per shard file (the last shard may hold fewer).
    #[serde(default = "default_shard_size")]
    pub shard_size: u32,
    /// How many bodies, drawn from which shape distribution.
    pub bodies: BodySpec,
    /// The garments every body wears.
    pub garments: Vec<GarmentSpec>,
    /// Where the poses come from.
    #[serde(default)]
    pub poses: PoseSpec,
    /// How bodies (and optionally poses) are split.
    pub splits: SplitSpec,
    /// Overrides of the simulator settings.
    #[serde(default)]
    pub simulator: SimulatorSpec,
    /// What is stored besides the required arrays.
    #[serde(default)]
    pub output: OutputSpec,
}

fn default_shard_size() -> u32 {
    32
}

/// The bodies of a dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Number of bodies; body `b`'s shape is drawn from the seed and `b`.
    pub count: u32,
    /// The adult shape distribution (its fields, all optional).
    #[serde(default)]
    pub distribution: ShapeDistribution,
}

/// One garment of a dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentSpec {
    /// `tshirt`, `sweater` or `jeans`.
    pub kind: String,
    /// Name of this garment in the dataset (default: the kind); unique.
    #[serde(default)]
    pub name: Option<String>,
    /// Template edge length, metres.
    pub edge: f32,
    /// Samples of this garment per body, each in a distinct pose.
    pub poses_per_body: u32,
    /// Fixed cut parameters (metres, names of `garment::cut::RANGES`); the rest default.
    #[serde(default)]
    pub cut: BTreeMap<String, f32>,
    /// Cut parameters drawn uniformly in `[min, max]` (metres) for each body.
    #[serde(default)]
    pub cut_ranges: BTreeMap<String, [f32; 2]>,
}

/// The pose sources; each clip and each procedural source is one "motion".
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// CMU ASF/AMC clips.
    #[serde(default)]
    pub amc: Vec<ClipSource>,
    /// BVH clips.
    #[serde(default)]
    pub bvh: Vec<ClipSource>,
    /// Procedural poses.
    #[serde(default)]
    pub procedural: Vec<ProceduralSource>,
}

/// Motion clips and how frames are taken from each.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipSource {
    /// Clip files, relative to the mocap root.
    pub clips: Vec<String>,
    /// AMC only: the skeleton (relative to the mocap root); default `SUBJECT.asf`
    /// beside each clip (`02/02_01.amc` -> `02/02.asf`).
    #[serde(default)]
    pub asf: Option<String>,
    /// Take every `every`-th frame from `start`.
    #[serde(default)]
    pub every: Option<u32>,
    /// Or take this many distinct random frames of each clip.
    #[serde(default)]
    pub random: Option<u32>,
    /// First frame considered (0-based).
    #[serde(default)]
    pub start: u32,
    /// One past the last frame considered (default: the clip's end).
    #[serde(default)]
    pub end: Option<u32>,
    /// BVH only: metres per file unit (default: guessed by the BVH reader).
    #[serde(default)]
    pub bvh_unit: Option<f64>,
}

/// Procedural poses of one kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProceduralSource {
    /// `walk`, `yoga`, `dance` or `any`.
    pub kind: String,
    /// Number of distinct poses (each redrawn per body until it does not self-intersect).
    pub count: u32,
}

/// Splits by body, optionally also by pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SplitSpec {
    /// Split name -> number of bodies, or fraction of the bodies.
    pub bodies: BTreeMap<String, SplitSize>,
    /// Hold out poses as well (the paper's unseen-pose experiments).
    #[serde(default)]
    pub unseen_poses: Option<UnseenPoses>,
}

/// The size of a split: a body count (TOML integer) or a fraction (TOML float).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum SplitSize {
    /// A number of bodies.
    Count(u64),
    /// A share of the bodies in [0, 1].
    Fraction(f64),
}

/// Unseen-pose splits: within each motion, `seen_fraction` of its poses (evenly spaced)
/// may be used by the ordinary splits; the `held_out` splits use only the others.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnseenPoses {
    /// Share of each motion's poses open to the ordinary splits, in (0, 1).
    pub seen_fraction: f64,
    /// Splits whose bodies wear only the remaining poses.
    pub held_out: Vec<String>,
}

/// Overrides of the simulator settings (`sim::drape::DrapeOptions` and
/// `sim::ClothParams`); a missing field keeps the simulator's default.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulatorSpec {
    /// Area density, kg/m^2.
    pub density: Option<f32>,
    /// Stretch modulus, N/m.
    pub stretch_stiffness: Option<f32>,
    /// Bending modulus, N/m.
    pub bend_stiffness: Option<f32>,
    /// Velocity damping, 1/s.
    pub damping: Option<f32>,
    /// Coulomb friction coefficient.
    pub friction: Option<f32>,
    /// Collision thickness, metres.
    pub thickness: Option<f32>,
    /// Contact margin beyond the thickness, metres.
    pub contact_margin: Option<f32>,
    /// Time step, seconds.
    pub dt: Option<f32>,
    /// Solver iterations per step.
    pub iterations: Option<u32>,
    /// Chebyshev acceleration estimate in [0, 1).
    pub chebyshev_rho: Option<f32>,
    /// Steps of the shape morph.
    pub morph_steps: Option<u32>,
    /// Steps of the move into the pose.
    pub pose_steps: Option<u32>,
    /// Most distance a body vertex travels in one animation step, metres (0: always the
    /// full step counts).
    pub body_step: Option<f32>,
    /// Most settling steps.
    pub max_settle_steps: Option<u32>,
    /// Root-mean-square speed at rest, m/s.
    pub rest_speed: Option<f32>,
    /// Root-mean-square speed that counts as diverged, m/s.
    pub explode_speed: Option<f32>,
    /// Deepest garment vertex allowed inside the body, metres.
    pub max_penetration: Option<f32>,
    /// Skinning of the body during the animation (and of the bodies a reader rebuilds):
    /// `lbs` or `dqs`; the simulator's default when absent.
    pub skinning: Option<String>,
    /// Grade the garment to the target body.
    pub grade: Option<bool>,
    /// Give a garment with a waistband (the jeans) its elastic band
    /// (`sim::waistband::Waistband::default`); the simulator's default (on) when absent.
    pub waistband: Option<bool>,
    /// Where the cloth starts: `animate` (carried from the template body through the shape
    /// and pose animation) or `fitted` (placed on the posed target by surface anchors);
    /// the simulator's default when absent. Left out of the spec's hash when absent, so
    /// specs written before it keep theirs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<String>,
    /// Static friction that holds (`sim::ClothParams::static_friction`); left out of the
    /// hash when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_friction: Option<bool>,
}

/// Optional arrays stored per sample.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Also store the template warped by surface anchors then DQS (`warp_fitted`).
    #[serde(default)]
    pub fitted: bool,
    /// Store neither the posed body nor M: both follow from the phenotype, the pose and
    /// the template, and [`crate::Dataset::sample`] rebuilds them (with the body model).
    /// A sample then takes about a tenth of the space.
    #[serde(default)]
    pub compact: bool,
}

/// A spec read from a file: the resolved spec (its base and overrides applied), its
/// source, and its hash.
#[derive(Clone, Debug)]
pub struct LoadedSpec {
    /// The parsed, resolved, validated spec.
    pub spec: Spec,
    /// The file it came from (named in errors).
    pub path: PathBuf,
    /// Hex sha256 of the spec's canonical JSON: equal for specs that mean the same,
    /// whatever their comments, layout and bases.
    pub hash: String,
}

impl LoadedSpec {
    /// Reads, resolves and validates the spec at `path`.
    pub fn load(path: &Path) -> Result<Self> {
        Self::load_with(path, &[])
    }

    /// [`LoadedSpec::load`] with the poses per body of some garments replaced:
    /// `(garment name, samples per body)` (see [`crate::spec_load::parse_poses_override`]).
    pub fn load_with(path: &Path, poses: &[(String, u32)]) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| DatasetError::io(path, e))?;
        Self::parse_with(&text, path, poses)
    }

    /// Parses, resolves and validates `text`; `path` is named in errors, and a `base` is
    /// found relative to its folder.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        Self::parse_with(text, path, &[])
    }

    /// [`LoadedSpec::parse`] with the poses overrides of [`LoadedSpec::load_with`].
    pub fn parse_with(text: &str, path: &Path, poses: &[(String, u32)]) -> Result<Self> {
        let (mut table, merged) = crate::spec_load::resolve(text, path)?;
        crate::spec_load::override_poses(&mut table, poses, path)?;
        check_distribution_keys(&table, path)?;
        let spec: Spec = if merged || !poses.is_empty() {
            Spec::deserialize(toml::Value::Table(table))
                .map_err(|e| DatasetError::spec(path, "spec (with its base)", e.message()))?
        } else {
            // From the text itself, so that errors name the line.
            toml::from_str(text).map_err(|e| toml_error(path, text, e))?
        };
        crate::spec_check::validate(&spec, path)?;
        Ok(Self {
            hash: spec_hash(&spec),
            spec,
            path: path.to_path_buf(),
        })
    }

    /// The resolved spec as a TOML spec file (no base, every override applied): what a
    /// dataset folder keeps as `spec.toml`.
    pub fn resolved_toml(&self) -> String {
        let body = toml::to_string(&self.spec).expect("a spec serialises as TOML");
        format!(
            "# The resolved spec of this dataset (its base and overrides applied), as garnet \
             wrote it.\n{body}"
        )
    }
}

impl SimulatorSpec {
    /// Reads simulator settings from the TOML file at `path`: the keys of a spec's
    /// `[simulator]` table, either under a `[simulator]` header (so a dataset spec itself
    /// gives its simulator settings, with those of its base) or at the top level of the
    /// file. Errors name the file
    /// and the line or key at fault; an unknown key is one.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| DatasetError::io(path, e))?;
        let table: toml::Table = toml::from_str(&text).map_err(|e| toml_error(path, &text, e))?;
        if table.contains_key("base") {
            // A dataset spec over a base: its simulator settings, merged with the base's.
            let (merged, _) = crate::spec_load::resolve(&text, path)?;
            let settings = merged.get("simulator").cloned();
            let settings = settings.unwrap_or_else(|| toml::Value::Table(toml::Table::new()));
            return SimulatorSpec::deserialize(settings)
                .map_err(|e| DatasetError::spec(path, "simulator", e.message()));
        }
        if table.contains_key("simulator") {
            /// A file with a `[simulator]` table and anything else beside it.
            #[derive(Deserialize)]
            struct Wrapped {
                simulator: SimulatorSpec,
            }
            let w: Wrapped = toml::from_str(&text).map_err(|e| toml_error(path, &text, e))?;
            Ok(w.simulator)
        } else {
            toml::from_str(&text).map_err(|e| toml_error(path, &text, e))
        }
    }
}

/// The fields in which spec `was` differs from `now`, each as `field: WAS -> NOW` (a
/// dotted path with indices, `garments[0].poses_per_body: 36 -> 99`).
pub fn differences(was: &Spec, now: &Spec) -> Vec<String> {
    fn walk(path: &str, a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<String>) {
        use serde_json::Value;
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
                for k in keys {
                    let (u, v) = (&x.get(k), &y.get(k));
                    let here = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    walk(
                        &here,
                        u.unwrap_or(&Value::Null),
                        v.unwrap_or(&Value::Null),
                        out,
                    );
                }
            }
            (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
                for (i, (u, v)) in x.iter().zip(y).enumerate() {
                    walk(&format!("{path}[{i}]"), u, v, out);
                }
            }
            _ if a != b => out.push(format!("{path}: {a} -> {b}")),
            _ => {}
        }
    }
    let json = |s: &Spec| serde_json::to_value(s).expect("a spec serialises");
    let mut out = Vec::new();
    walk("", &json(was), &json(now), &mut out);
    out
}

/// Hex sha256 of the canonical JSON of `spec`.
pub fn spec_hash(spec: &Spec) -> String {
    let json = serde_json::to_string(spec).expect("a spec serialises");
    crate::hash::sha256_hex(json.as_bytes())
}

/// A TOML syntax or type error as a spec error: the field is the line it is on (1-based)
/// and that line's text.
pub(crate) fn toml_error(path: &Path, text: &str, e: toml::de::Error) -> DatasetError {
    let field = match e.span() {
        Some(span) => {
            let at = span.start.min(text.len());
            let line = text.as_bytes()[..at]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            let content = text.lines().nth(line - 1).unwrap_or("").trim();
            format!("line {line} (`{content}`)")
        }
        None => "TOML".into(),
    };
    DatasetError::spec(path, field, e.message().trim())
}

/// `bodies.distribution` is a foreign struct that ignores unknown keys: check them here.
fn check_distribution_keys(table: &toml::Table, path: &Path) -> Result<()> {
    let Some(dist) = table
        .get("bodies")
        .and_then(|b| b.get("distribution"))
        .and_then(|d| d.as_table())
    else {
        return Ok(());
    };
    let known = toml::Table::try_from(ShapeDistribution::default()).expect("serialises");
    for key in dist.keys() {
        if !known.contains_key(key) {
            let names: Vec<&str> = known.keys().map(String::as_str).collect();
            return Err(DatasetError::spec(
                path,
                format!("bodies.distribution.{key}"),
                format!("unknown field, expected one of {}", names.join(", ")),
            ));
        }
    }
    Ok(())
}
