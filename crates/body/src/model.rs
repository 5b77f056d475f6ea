//! The body model: template mesh, macro targets, rig definition and skinning weights,
//! stored in one compact file, and shaping a body from a [`Phenotype`].
//!
//! The compact file is a safetensors file written by [`convert_assets`]:
//! `vertices` f32 `[V,3]` (metres; the 13380 body vertices first, then the joint-cube
//! and landmark vertices the rig needs), `faces` u32 `[F,3]` (the body's quads split in
//! two triangles), `weights.offsets` u32 `[13381]`, `weights.bones` u16 `[nnz]`,
//! `weights.values` f32 `[nnz]`, `regressors.offsets` u32 `[2B+1]` and
//! `regressors.indices` u32 (the vertices averaged for each bone's head, then tail), and
//! per macro target `target/NAME/index` u16 `[n]` and `target/NAME/delta` i16 `[n,3]`
//! in tenths of a millimetre (the source files carry three decimals of a decimetre, so
//! this is lossless). Metadata: `format`, `source_sha256`, `bones` (JSON list of
//! `{name, parent, roll}`) and `tpose` (JSON map bone -> XYZ Euler angles, radians).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use geom::io::le::{from_le, typed_tensor};
use geom::TriMesh;
use glam::{EulerRot, Quat, Vec3};
use safetensors::{Dtype, SafeTensors};
use serde::{Deserialize, Serialize};

use crate::phenotype::Phenotype;
use crate::rig::{rest_frame, Bone, Pose, Rig};
use crate::skin::{SkinWeights, Skinning};
use crate::BodyError;

mod convert;
pub use convert::convert_assets;

/// Vertices of the closed body surface (the `body` group of MakeHuman's base mesh).
pub const BODY_VERTEX_COUNT: usize = 13380;
/// Format tag of the compact file.
pub const FORMAT: &str = "garnet-body-1";
/// Size of one stored delta unit: a tenth of a millimetre, in metres.
const DELTA_UNIT: f32 = 1e-4;

/// One bone of the rig definition (shape independent).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoneDef {
    pub name: String,
    pub parent: Option<usize>,
    /// Blender roll about the bone axis, radians.
    pub roll: f32,
}

/// A sparse macro target: vertex indices and their offsets.
#[derive(Clone, Debug)]
struct Target {
    name: String,
    index: Vec<u16>,
    delta: Vec<[i16; 3]>,
}

/// The loaded body model. Cheap to share; shaping allocates only the output.
#[derive(Clone, Debug)]
pub struct BodyModel {
    template: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
    targets: Vec<Target>,
    regressors: Vec<Vec<u32>>,
    bones: Vec<BoneDef>,
    weights: Arc<SkinWeights>,
    tpose: Vec<(usize, Vec3)>,
}

/// A body of a given shape in its rest (A-)pose, ready to be posed.
#[derive(Clone, Debug)]
pub struct ShapedBody {
    /// The phenotype it was shaped from.
    pub phenotype: Phenotype,
    /// The closed body surface in rest pose: 13380 vertices, metres, feet on y = 0,
    /// pelvis joint above the origin.
    pub mesh: TriMesh,
    /// The rig with joints computed on this shape.
    pub rig: Rig,
    /// Skinning weights of the mesh vertices.
    pub weights: Arc<SkinWeights>,
}

impl BodyModel {
    /// Loads the model from the compact file, fetching and converting the assets first
    /// if needed (see [`crate::assets`]).
    pub fn load() -> Result<Self, BodyError> {
        Self::from_file(&crate::assets::ensure_body_cache()?)
    }

    /// Loads the model from a compact file written by [`convert_assets`].
    pub fn from_file(path: &Path) -> Result<Self, BodyError> {
        let bytes = std::fs::read(path).map_err(|e| BodyError::asset(path, e.to_string()))?;
        let bad = |m: String| BodyError::asset(path, m);
        let (_, meta) =
            SafeTensors::read_metadata(&bytes).map_err(|e| bad(format!("not a body file: {e}")))?;
        let meta = meta.metadata().clone().unwrap_or_default();
        if meta.get("format").map(String::as_str) != Some(FORMAT) {
            return Err(bad(format!(
                "not a {FORMAT} file; delete it to convert again"
            )));
        }
        let st = SafeTensors::deserialize(&bytes).map_err(|e| bad(e.to_string()))?;
        let get = |name: &str, dtype: Dtype| typed_tensor(&st, name, dtype).map_err(bad);
        let template: Vec<Vec3> = from_le::<f32>(get("vertices", Dtype::F32)?.data())
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        let faces: Vec<[u32; 3]> = from_le::<u32>(get("faces", Dtype::U32)?.data())
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let bones: Vec<BoneDef> = serde_json::from_str(
            meta.get("bones")
                .ok_or_else(|| bad("no bones metadata".into()))?,
        )
        .map_err(|e| bad(format!("bones metadata: {e}")))?;
        let tpose_map: HashMap<String, [f32; 3]> = serde_json::from_str(
            meta.get("tpose")
                .ok_or_else(|| bad("no tpose metadata".into()))?,
        )
        .map_err(|e| bad(format!("tpose metadata: {e}")))?;
        let mut tpose = Vec::new();
        for (name, e) in tpose_map {
            let b = bones
                .iter()
                .position(|b| b.name == name)
                .ok_or_else(|| bad(format!("tpose names unknown bone {name}")))?;
            tpose.push((b, Vec3::from(e)));
        }
        let reg_off = from_le::<u32>(get("regressors.offsets", Dtype::U32)?.data());
        let reg_idx = from_le::<u32>(get("regressors.indices", Dtype::U32)?.data());
        let regressors = reg_off
            .windows(2)
            .map(|w| {
                reg_idx
                    .get(w[0] as usize..w[1] as usize)
                    .map(<[u32]>::to_vec)
            })
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| bad("regressor offsets out of range".into()))?;
        let weights = SkinWeights {
            offsets: from_le::<u32>(get("weights.offsets", Dtype::U32)?.data()),
            bones: from_le::<u16>(get("weights.bones", Dtype::U16)?.data()),
            weights: from_le::<f32>(get("weights.values", Dtype::F32)?.data()),
        };
        let mut targets = Vec::new();
        for (name, _) in st.tensors() {
            let Some(tname) = name
                .strip_prefix("target/")
                .and_then(|n| n.strip_suffix("/index"))
            else {
                continue;
            };
            let index = from_le::<u16>(get(&name, Dtype::U16)?.data());
            let delta: Vec<[i16; 3]> =
                from_le::<i16>(get(&format!("target/{tname}/delta"), Dtype::I16)?.data())
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2]])
                    .collect();
            targets.push(Target {
                name: tname.to_string(),
                index,
                delta,
            });
        }
        targets.sort_by(|a, b| a.name.cmp(&b.name));
        let model = Self {
            template,
            faces,
            targets,
            regressors,
            bones,
            weights: Arc::new(weights),
            tpose,
        };
        model.check().map_err(bad)?;
        Ok(model)
    }

    /// Internal consistency of a loaded file (sizes and index ranges).
    fn check(&self) -> Result<(), String> {
        let v = self.template.len();
        if v < BODY_VERTEX_COUNT || self.weights.len() != BODY_VERTEX_COUNT {
            return Err(format!(
                "expected {BODY_VERTEX_COUNT} body vertices with weights"
            ));
        }
        if self
            .faces
            .iter()
            .flatten()
            .any(|&i| i as usize >= BODY_VERTEX_COUNT)
        {
            return Err("face index out of range".into());
        }
        if self.regressors.len() != 2 * self.bones.len()
            || self.regressors.iter().flatten().any(|&i| i as usize >= v)
        {
            return Err("bad joint regressors".into());
        }
        if self
            .weights
            .bones
            .iter()
            .any(|&b| b as usize >= self.bones.len())
        {
            return Err("weight names an unknown bone".into());
        }
        for t in &self.targets {
            if t.index.len() != t.delta.len() || t.index.iter().any(|&i| i as usize >= v) {
                return Err(format!("target {} is malformed", t.name));
            }
        }
        Ok(())
    }

    /// The rig's bone definitions, parents before children.
    pub fn bones(&self) -> &[BoneDef] {
        &self.bones
    }

    /// Names of the macro targets in the model.
    pub fn target_names(&self) -> impl Iterator<Item = &str> {
        self.targets.iter().map(|t| t.name.as_str())
    }

    /// Shapes a body: blends the macro targets with the phenotype's coefficients,
    /// places the feet on y = 0 and the pelvis above the origin, and computes the rig's
    /// joints on the result.
    pub fn shape(&self, phenotype: &Phenotype) -> Result<ShapedBody, BodyError> {
        phenotype.validate()?;
        let mut vertices = self.template.clone();
        let weights = phenotype.label_weights();
        let weight = |label: &str| {
            weights
                .iter()
                .find(|(l, _)| *l == label)
                .map_or(0.0, |(_, w)| *w)
        };
        for t in &self.targets {
            let c: f32 = t
                .name
                .split('-')
                .filter(|l| *l != "universal")
                .map(weight)
                .product();
            if c.abs() < 1e-7 {
                continue;
            }
            let s = c * DELTA_UNIT;
            for (&i, d) in t.index.iter().zip(&t.delta) {
                vertices[i as usize] += s * Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
            }
        }
        let joint = |k: usize| -> Vec3 {
            let idx = &self.regressors[k];
            idx.iter().map(|&i| vertices[i as usize]).sum::<Vec3>() / idx.len() as f32
        };
        let heads: Vec<Vec3> = (0..self.bones.len()).map(|b| joint(2 * b)).collect();
        let tails: Vec<Vec3> = (0..self.bones.len()).map(|b| joint(2 * b + 1)).collect();
        let body = &vertices[..BODY_VERTEX_COUNT];
        let floor = body.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
        let shift = Vec3::new(-heads[0].x, -floor, -heads[0].z);
        let rig = Rig {
            bones: self
                .bones
                .iter()
                .enumerate()
                .map(|(b, def)| Bone {
                    name: def.name.clone(),
                    parent: def.parent,
                    head: heads[b] + shift,
                    tail: tails[b] + shift,
                    frame: rest_frame(heads[b], tails[b], def.roll),
                })
                .collect(),
        };
        Ok(ShapedBody {
            phenotype: *phenotype,
            mesh: TriMesh {
                vertices: body.iter().map(|&p| p + shift).collect(),
                faces: self.faces.clone(),
            },
            rig,
            weights: self.weights.clone(),
        })
    }

    /// The T-pose of the rig (arms horizontal), from the assets' `t-pose.json`.
    pub fn tpose(&self) -> Pose {
        let mut pose = Pose::identity(self.bones.len());
        for &(b, e) in &self.tpose {
            pose.rotations[b] = Quat::from_euler(EulerRot::ZYX, e.z, e.y, e.x);
        }
        pose
    }
}

impl ShapedBody {
    /// Standing height: the vertical extent of the rest mesh, metres.
    pub fn height(&self) -> f32 {
        let (lo, hi) = self
            .mesh
            .vertices
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.y), hi.max(p.y))
            });
        hi - lo
    }

    /// The body mesh in `pose`, skinned with `method`: 13380 vertices, metres.
    pub fn posed(&self, pose: &Pose, method: Skinning) -> Result<TriMesh, BodyError> {
        if pose.rotations.len() != self.rig.len() {
            return Err(BodyError::Parameter(format!(
                "pose has {} bone rotations, the rig has {} bones",
                pose.rotations.len(),
                self.rig.len()
            )));
        }
        if !pose.root_translation.is_finite() || pose.rotations.iter().any(|q| !q.is_finite()) {
            return Err(BodyError::Parameter(
                "pose contains NaN or infinite values".into(),
            ));
        }
        let transforms = self.rig.skinning_transforms(pose);
        Ok(TriMesh {
            vertices: self.weights.apply(&self.mesh.vertices, &transforms, method),
            faces: self.mesh.faces.clone(),
        })
    }

    /// Body volume (m^3) of the closed rest mesh, by the divergence theorem.
    pub fn volume(&self) -> f32 {
        let v = &self.mesh.vertices;
        self.mesh
            .faces
            .iter()
            .map(|f| v[f[0] as usize].dot(v[f[1] as usize].cross(v[f[2] as usize])))
            .sum::<f32>()
            / 6.0
    }
}
