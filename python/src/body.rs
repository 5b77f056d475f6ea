//! `garnet.Body` and `garnet.Pose`: a shaped body in a pose, built as the command line's
//! `--random-shape` / phenotype flags and pose flags build it.

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use anyhow::{bail, Context};
use body::pose::{Clip, PoseKind, ProceduralPoseGenerator, RetargetOptions};
use body::self_contact::sample_valid_pose;
use body::shape_sampler::ShapeDistribution;
use body::{BodyModel, Phenotype, ShapedBody, Skinning};
use glam::{Quat, Vec3};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyDictMethods};

use crate::arrays::{faces_to_py, points_from_py, points_to_py, quats_to_py, vec3_to_py};
use crate::errors::{detached, file_err, py_err, value_err};

/// The body model, loaded once (fetched and converted into the `GARNET_HOME` cache on first
/// use, as by the command line).
pub fn body_model() -> anyhow::Result<Arc<BodyModel>> {
    static MODEL: OnceLock<Arc<BodyModel>> = OnceLock::new();
    if let Some(m) = MODEL.get() {
        return Ok(m.clone());
    }
    let loaded = Arc::new(BodyModel::load()?);
    Ok(MODEL.get_or_init(|| loaded).clone())
}

/// Where a pose comes from: some depend on the body they are applied to.
#[derive(Clone)]
enum Source {
    Rest,
    TPose,
    Clip { clip: Arc<Clip>, frame: usize },
    Procedural { seed: u64, kind: PoseKind },
    Fixed(body::Pose),
}

/// A body pose, or the recipe of one.
///
/// A clip frame is retargeted onto the rig of the body it is applied to and a procedural
/// pose is drawn against that body (self-intersecting draws rejected), as `garnet drape
/// --pose-amc/--pose-bvh/--pose-procedural` do: such a pose gets its rotations when given
/// to `Body(..., pose=...)`; `body.pose` is then the concrete pose.
#[pyclass(frozen, module = "garnet")]
#[derive(Clone)]
pub struct Pose {
    source: Source,
    description: String,
}

impl Pose {
    /// A concrete pose described by `description`.
    pub fn concrete(pose: body::Pose, description: &str) -> Self {
        Pose {
            source: Source::Fixed(pose),
            description: description.into(),
        }
    }

    /// The concrete pose of this recipe for `target` (shaped by `model`).
    fn resolve(&self, model: &BodyModel, target: &ShapedBody) -> anyhow::Result<body::Pose> {
        let opts = RetargetOptions::default();
        Ok(match &self.source {
            Source::Rest => body::Pose::identity(target.rig.len()),
            Source::TPose => model.tpose(),
            Source::Clip { clip, frame } => clip.pose(*frame, &target.rig, &opts)?,
            Source::Procedural { seed, kind } => {
                let mut generator = ProceduralPoseGenerator::new(*seed, *kind);
                sample_valid_pose(target, &mut generator, 200)
                    .with_context(|| format!("procedural pose, seed {seed}"))?
            }
            Source::Fixed(p) => p.clone(),
        })
    }

    fn fixed(&self) -> PyResult<&body::Pose> {
        match &self.source {
            Source::Fixed(p) => Ok(p),
            _ => Err(value_err(format!(
                "the pose '{}' depends on the body it is applied to: use body.pose of a Body made with it",
                self.description
            ))),
        }
    }
}

/// The ASF skeleton beside an AMC clip: `DIR/02_01.amc` -> `DIR/02.asf`.
fn default_asf(amc: &Path) -> anyhow::Result<PathBuf> {
    let stem = amc.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let subject = stem.split('_').next().unwrap_or(stem);
    let asf = amc.with_file_name(format!("{subject}.asf"));
    if !asf.is_file() {
        bail!(
            "{}: no skeleton {} beside the clip; give it with asf=",
            amc.display(),
            asf.display()
        );
    }
    Ok(asf)
}

/// The file name of `path` for descriptions.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// The skinning named `name` ("dqs" or "lbs").
pub fn parse_skinning(name: &str) -> PyResult<Skinning> {
    Skinning::from_name(name)
        .ok_or_else(|| value_err(format!("unknown skinning '{name}': dqs or lbs")))
}

fn parse_kind(kind: &str) -> PyResult<PoseKind> {
    match kind.to_ascii_lowercase().as_str() {
        "walk" => Ok(PoseKind::Walk),
        "yoga" => Ok(PoseKind::Yoga),
        "dance" => Ok(PoseKind::Dance),
        "any" => Ok(PoseKind::Any),
        _ => Err(value_err(format!(
            "unknown pose kind '{kind}': walk, yoga, dance or any"
        ))),
    }
}

fn check_frame(clip: &Clip, frame: usize, path: &Path) -> PyResult<()> {
    if frame >= clip.frame_count() {
        return Err(value_err(format!(
            "{}: frame {frame} is past the clip's {} frames",
            path.display(),
            clip.frame_count()
        )));
    }
    Ok(())
}

#[pymethods]
impl Pose {
    /// The rest A-pose (every bone rotation the identity).
    #[staticmethod]
    fn rest() -> Self {
        Pose {
            source: Source::Rest,
            description: "rest A-pose".into(),
        }
    }

    /// The T-pose (arms horizontal).
    #[staticmethod]
    fn tpose() -> Self {
        Pose {
            source: Source::TPose,
            description: "T-pose".into(),
        }
    }

    /// Frame `frame` (0-based) of a CMU AMC clip; the skeleton is `asf`, or `SUBJECT.asf`
    /// beside the clip. Retargeted onto the body it is applied to.
    #[staticmethod]
    #[pyo3(signature = (amc, frame = 0, asf = None))]
    fn from_amc(
        py: Python<'_>,
        amc: PathBuf,
        frame: usize,
        asf: Option<PathBuf>,
    ) -> PyResult<Self> {
        let loaded = detached(py, || {
            let asf = match &asf {
                Some(a) => a.clone(),
                None => default_asf(&amc)?,
            };
            Ok(Clip::from_asf_amc(&asf, &amc)?)
        })
        .map_err(|e| file_err(&amc, e))?;
        check_frame(&loaded, frame, &amc)?;
        Ok(Pose {
            description: format!("{} frame {frame}", file_name(&amc)),
            source: Source::Clip {
                clip: Arc::new(loaded),
                frame,
            },
        })
    }

    /// Frame `frame` (0-based) of a CMU-style BVH clip, retargeted onto the body it is
    /// applied to.
    #[staticmethod]
    #[pyo3(signature = (bvh, frame = 0))]
    fn from_bvh(py: Python<'_>, bvh: PathBuf, frame: usize) -> PyResult<Self> {
        let loaded =
            detached(py, || Ok(Clip::from_bvh(&bvh, None)?)).map_err(|e| file_err(&bvh, e))?;
        check_frame(&loaded, frame, &bvh)?;
        Ok(Pose {
            description: format!("{} frame {frame}", file_name(&bvh)),
            source: Source::Clip {
                clip: Arc::new(loaded),
                frame,
            },
        })
    }

    /// A procedural pose drawn from `seed` against the body it is applied to
    /// (self-intersecting draws are rejected); `kind`: "walk", "yoga", "dance" or "any".
    #[staticmethod]
    #[pyo3(signature = (seed, kind = "any"))]
    fn procedural(seed: u64, kind: &str) -> PyResult<Self> {
        let kind = parse_kind(kind)?;
        Ok(Pose {
            description: format!("procedural {kind:?} {seed}").to_lowercase(),
            source: Source::Procedural { seed, kind },
        })
    }

    /// A pose given by its arrays: `rotations` float [B,4] bone-local unit quaternions
    /// (x, y, z, w), `root_translation` float [3] metres (default 0).
    #[staticmethod]
    #[pyo3(signature = (rotations, root_translation = None))]
    fn from_arrays(
        rotations: &Bound<'_, PyAny>,
        root_translation: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let q = points_from_py(rotations, "rotations", 4)?;
        let rotations: Vec<Quat> = q
            .chunks_exact(4)
            .map(|c| Quat::from_xyzw(c[0], c[1], c[2], c[3]).normalize())
            .collect();
        let root = match root_translation {
            None => Vec3::ZERO,
            Some(r) => {
                let np = r.py().import("numpy")?;
                let r2 = np
                    .call_method1("reshape", (r, (1, 3)))
                    .map_err(|e| value_err(format!("root_translation must have shape [3]: {e}")))?;
                Vec3::from_slice(&points_from_py(&r2, "root_translation", 3)?)
            }
        };
        Ok(Pose {
            description: "pose from arrays".into(),
            source: Source::Fixed(body::Pose {
                root_translation: root,
                rotations,
            }),
        })
    }

    /// What the pose is, in words ("procedural walk 4", "02_01.amc frame 30").
    #[getter]
    fn description(&self) -> String {
        self.description.clone()
    }

    /// float32 [B,4]: bone-local rotations (x, y, z, w) of a concrete pose (`body.pose`).
    #[getter]
    fn rotations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        Ok(quats_to_py(py, &self.fixed()?.rotations))
    }

    /// float32 [3]: root translation of a concrete pose, metres.
    #[getter]
    fn root_translation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        Ok(vec3_to_py(py, self.fixed()?.root_translation))
    }

    fn __repr__(&self) -> String {
        format!("garnet.Pose({})", self.description)
    }
}

/// A body: a shape (phenotype) in a pose, as `garnet drape` and `garnet body` make it.
#[pyclass(frozen, module = "garnet")]
pub struct Body {
    pub shaped: Arc<ShapedBody>,
    pub pose: body::Pose,
    pose_description: String,
    skinning: Skinning,
    posed: geom::TriMesh,
}

impl Body {
    fn build(
        py: Python<'_>,
        phenotype: Option<Phenotype>,
        seed: Option<u64>,
        pose: Option<&Pose>,
        skinning: &str,
    ) -> PyResult<Self> {
        let skinning = parse_skinning(skinning)?;
        let pose = pose.cloned().unwrap_or_else(Pose::rest);
        let (shaped, resolved, posed) = detached(py, || {
            let model = body_model()?;
            let phenotype = match (phenotype, seed) {
                (_, Some(seed)) => ShapeDistribution::default().sample(&model, seed)?.phenotype,
                (Some(p), None) => p,
                (None, None) => Phenotype::default(),
            };
            let shaped = model.shape(&phenotype)?;
            let resolved = pose.resolve(&model, &shaped)?;
            let posed = shaped.posed(&resolved, skinning)?;
            Ok((shaped, resolved, posed))
        })
        .map_err(py_err)?;
        Ok(Body {
            shaped: Arc::new(shaped),
            pose: resolved,
            pose_description: pose.description,
            skinning,
            posed,
        })
    }
}

/// The phenotype of `dict` (keys as `Body.phenotype` gives them; the rest default).
fn phenotype_from_dict(dict: &Bound<'_, PyDict>) -> PyResult<Phenotype> {
    let mut p = Phenotype::default();
    let names: Vec<&str> = p.named_values().iter().map(|(n, _)| *n).collect();
    for (k, v) in dict.iter() {
        let key: String = k
            .extract()
            .map_err(|_| value_err("phenotype keys must be strings"))?;
        let value: f64 = v
            .extract()
            .map_err(|_| value_err(format!("phenotype {key} must be a number")))?;
        let value = value as f32;
        match key.as_str() {
            "gender" => p.gender = value,
            "age" => p.age = value,
            "muscle" => p.muscle = value,
            "weight" => p.weight = value,
            "height" => p.height = value,
            "proportions" => p.proportions = value,
            "cupsize" => p.cupsize = value,
            "firmness" => p.firmness = value,
            "african" => p.african = value,
            "asian" => p.asian = value,
            "caucasian" => p.caucasian = value,
            _ => {
                return Err(value_err(format!(
                    "unknown phenotype parameter '{key}': one of {}",
                    names.join(", ")
                )))
            }
        }
    }
    p.validate().map_err(|e| value_err(e.to_string()))?;
    Ok(p)
}

#[pymethods]
impl Body {
    /// A body of `phenotype` (a dict of gender, age, muscle, weight, height, proportions,
    /// cupsize, firmness in [0, 1] and race shares african, asian, caucasian; keys left out
    /// keep the default, 0.5 and equal shares) in `pose` (default the rest A-pose),
    /// skinned with `skinning` ("dqs" or "lbs") for `vertices`.
    #[new]
    #[pyo3(signature = (phenotype = None, pose = None, skinning = "dqs"))]
    fn new(
        py: Python<'_>,
        phenotype: Option<&Bound<'_, PyDict>>,
        pose: Option<PyRef<'_, Pose>>,
        skinning: &str,
    ) -> PyResult<Self> {
        let p = phenotype.map(phenotype_from_dict).transpose()?;
        Body::build(
            py,
            Some(p.unwrap_or_default()),
            None,
            pose.as_deref(),
            skinning,
        )
    }

    /// A random realistic adult (stature and BMI like real adults) drawn from `seed`: the
    /// body of `garnet drape --random-shape SEED`.
    #[staticmethod]
    #[pyo3(signature = (seed, pose = None, skinning = "dqs"))]
    fn random(
        py: Python<'_>,
        seed: u64,
        pose: Option<PyRef<'_, Pose>>,
        skinning: &str,
    ) -> PyResult<Self> {
        Body::build(py, None, Some(seed), pose.as_deref(), skinning)
    }

    /// The same shape in another pose.
    #[pyo3(signature = (pose, skinning = None))]
    fn with_pose(
        &self,
        py: Python<'_>,
        pose: PyRef<'_, Pose>,
        skinning: Option<&str>,
    ) -> PyResult<Self> {
        let skinning = match skinning {
            Some(s) => parse_skinning(s)?,
            None => self.skinning,
        };
        let shaped = self.shaped.clone();
        let pose: Pose = (*pose).clone();
        let (resolved, posed) = detached(py, || {
            let model = body_model()?;
            let resolved = pose.resolve(&model, &shaped)?;
            let posed = shaped.posed(&resolved, skinning)?;
            Ok((resolved, posed))
        })
        .map_err(py_err)?;
        Ok(Body {
            shaped,
            pose: resolved,
            pose_description: pose.description.clone(),
            skinning,
            posed,
        })
    }

    /// float32 [V,3]: the posed body's vertices, metres (y up, feet near y = 0).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        points_to_py(py, self.posed.vertices.clone())
    }

    /// uint32 [F,3]: the body's triangles (indices into `vertices`).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        faces_to_py(py, self.posed.faces.clone())
    }

    /// float32 [V,3]: the shaped body in its rest A-pose, metres.
    #[getter]
    fn rest_vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        points_to_py(py, self.shaped.mesh.vertices.clone())
    }

    /// float32 [B,3]: the posed joints (bone heads), metres, in `bone_names` order.
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        let heads = self.shaped.rig.posed_joints(&self.pose);
        points_to_py(py, heads.into_iter().map(|(h, _)| h).collect())
    }

    /// The rig's bone names [B].
    #[getter]
    fn bone_names(&self) -> Vec<String> {
        self.shaped
            .rig
            .bones
            .iter()
            .map(|b| b.name.clone())
            .collect()
    }

    /// Standing height: the vertical extent of the rest mesh, metres.
    #[getter]
    fn height(&self) -> f32 {
        self.shaped.height()
    }

    /// The phenotype, a dict of its 11 parameters.
    #[getter]
    fn phenotype<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in self.shaped.phenotype.named_values() {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The concrete pose the body is in.
    #[getter]
    fn pose(&self) -> Pose {
        Pose {
            source: Source::Fixed(self.pose.clone()),
            description: self.pose_description.clone(),
        }
    }

    /// The skinning of `vertices`: "dqs" or "lbs".
    #[getter]
    fn skinning(&self) -> &'static str {
        self.skinning.name()
    }

    pub fn __repr__(&self) -> String {
        format!(
            "garnet.Body({:.1} cm, {})",
            self.shaped.height() * 100.0,
            self.pose_description
        )
    }
}
