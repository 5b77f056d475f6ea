//! A garment template and its file format.
//!
//! A template file is one safetensors file (`.garment`) holding: `vertices` f32 `[N,3]`
//! (metres, on the template body in rest pose), `faces` u32 `[F,3]`, `uvs` f32 `[F,3,2]`
//! (per face corner), `weights.offsets` u32 `[N+1]`, `weights.bones` u16 `[nnz]`,
//! `weights.values` f32 `[nnz]`, and the template body's rig: `rig.heads` and
//! `rig.tails` f32 `[B,3]`, `rig.frames` f32 `[B,4]` (quaternions x, y, z, w). Metadata
//! (JSON strings): `format` (`garnet-garment-1`), `kind`, `cut`, `edge_length`,
//! `body_phenotype` and `bones` (names and parents). Every value round-trips exactly.

use std::collections::HashMap;
use std::path::Path;

use body::rig::Bone;
use body::{Phenotype, Rig, ShapedBody, SkinWeights};
use geom::io::le::{from_le, to_le, typed_tensor};
use geom::TriMesh;
use glam::{Quat, Vec3};
use safetensors::{tensor::TensorView, Dtype, SafeTensors};
use serde::{Deserialize, Serialize};

use crate::{CutParams, GarmentError, GarmentKind};

/// Format tag of template files.
pub const FORMAT: &str = "garnet-garment-1";

/// A garment template: the garment on the template body in rest pose, ready to be
/// warped onto any body and draped.
#[derive(Clone, Debug, PartialEq)]
pub struct GarmentTemplate {
    pub kind: GarmentKind,
    /// Cut parameters it was built with (`None` for imported garments).
    pub cut: Option<CutParams>,
    /// Target edge length it was remeshed to, metres (mean edge length if imported).
    pub edge_length: f32,
    /// The garment surface: `[N]` vertices (metres), `[F]` faces.
    pub mesh: TriMesh,
    /// `[F]` texture coordinates of each face's three corners.
    pub uvs: Vec<[[f32; 2]; 3]>,
    /// Skinning weights `[N]` for the rig.
    pub weights: SkinWeights,
    /// Phenotype of the template body it is fitted on.
    pub body_phenotype: Phenotype,
    /// The template body's rest rig (its joints).
    pub rig: Rig,
}

#[derive(Serialize, Deserialize)]
struct BoneMeta {
    name: String,
    parent: Option<usize>,
}

fn json<T: Serialize>(value: &T) -> String {
    serde_json::to_string(value).expect("metadata serialises")
}

impl GarmentTemplate {
    /// A template of `mesh` (fitted on `body` in rest pose) with its `weights`: computes
    /// the UVs and validates the whole.
    pub fn assemble(
        kind: GarmentKind,
        cut: Option<CutParams>,
        edge_length: f32,
        mesh: TriMesh,
        weights: SkinWeights,
        body: ShapedBody,
    ) -> Result<Self, GarmentError> {
        let uvs = crate::uv::corner_uvs(&mesh, &weights, &body.rig);
        let template = Self {
            kind,
            cut,
            edge_length,
            mesh,
            uvs,
            weights,
            body_phenotype: body.phenotype,
            rig: body.rig,
        };
        template.validate()?;
        Ok(template)
    }

    /// Checks the template's arrays agree in size and hold finite values.
    pub fn validate(&self) -> Result<(), GarmentError> {
        let bad = |m: String| {
            Err(GarmentError::rejected(
                format!("{} template", self.kind.name()),
                m,
            ))
        };
        self.mesh.validate()?;
        if self.uvs.len() != self.mesh.faces.len() {
            return bad(format!(
                "{} UV triples for {} faces",
                self.uvs.len(),
                self.mesh.faces.len()
            ));
        }
        if self.weights.len() != self.mesh.vertices.len()
            || self.weights.offsets.last().map(|&o| o as usize) != Some(self.weights.bones.len())
        {
            return bad(format!(
                "{} weight rows for {} vertices",
                self.weights.len(),
                self.mesh.vertices.len()
            ));
        }
        let w = &self.weights;
        let monotonic = w.offsets.first() == Some(&0) && w.offsets.windows(2).all(|p| p[0] <= p[1]);
        if !monotonic
            || w.bones.len() != w.weights.len()
            || w.bones.iter().any(|&b| b as usize >= self.rig.len())
        {
            return bad("malformed skinning weights".into());
        }
        Ok(())
    }

    /// Writes the template to `path` (atomically).
    pub fn save(&self, path: &Path) -> Result<(), GarmentError> {
        let bytes = self.to_bytes(path)?;
        geom::io::write_bytes_atomic(path, &bytes)?;
        Ok(())
    }

    /// The template as the bytes of a `.garment` file; `path` names it in errors.
    pub fn to_bytes(&self, path: &Path) -> Result<Vec<u8>, GarmentError> {
        self.validate()?;
        let (n, f, b) = (
            self.mesh.vertices.len(),
            self.mesh.faces.len(),
            self.rig.len(),
        );
        let w = &self.weights;
        let bones = &self.rig.bones;
        let tensors: Vec<(&str, Dtype, Vec<usize>, Vec<u8>)> = vec![
            (
                "vertices",
                Dtype::F32,
                vec![n, 3],
                to_le(self.mesh.vertices.iter().flat_map(|v| v.to_array())),
            ),
            (
                "faces",
                Dtype::U32,
                vec![f, 3],
                to_le(self.mesh.faces.iter().flatten().copied()),
            ),
            (
                "uvs",
                Dtype::F32,
                vec![f, 3, 2],
                to_le(self.uvs.iter().flatten().flatten().copied()),
            ),
            (
                "weights.offsets",
                Dtype::U32,
                vec![w.offsets.len()],
                to_le(w.offsets.iter().copied()),
            ),
            (
                "weights.bones",
                Dtype::U16,
                vec![w.bones.len()],
                to_le(w.bones.iter().copied()),
            ),
            (
                "weights.values",
                Dtype::F32,
                vec![w.weights.len()],
                to_le(w.weights.iter().copied()),
            ),
            (
                "rig.heads",
                Dtype::F32,
                vec![b, 3],
                to_le(bones.iter().flat_map(|b| b.head.to_array())),
            ),
            (
                "rig.tails",
                Dtype::F32,
                vec![b, 3],
                to_le(bones.iter().flat_map(|b| b.tail.to_array())),
            ),
            (
                "rig.frames",
                Dtype::F32,
                vec![b, 4],
                to_le(bones.iter().flat_map(|b| b.frame.to_array())),
            ),
        ];
        let views: Vec<(&str, TensorView<'_>)> = tensors
            .iter()
            .map(|(name, d, shape, bytes)| {
                (
                    *name,
                    TensorView::new(*d, shape.clone(), bytes).expect("consistent tensor"),
                )
            })
            .collect();
        let bone_meta: Vec<BoneMeta> = bones
            .iter()
            .map(|b| BoneMeta {
                name: b.name.clone(),
                parent: b.parent,
            })
            .collect();
        let meta: HashMap<String, String> = HashMap::from([
            ("format".into(), FORMAT.into()),
            ("kind".into(), json(&self.kind)),
            ("cut".into(), json(&self.cut)),
            ("edge_length".into(), json(&self.edge_length)),
            ("body_phenotype".into(), json(&self.body_phenotype)),
            ("bones".into(), json(&bone_meta)),
        ]);
        safetensors::serialize(views, Some(meta))
            .map_err(|e| GarmentError::file(path, e.to_string()))
    }

    /// Reads a template written by [`GarmentTemplate::save`]; a malformed file is an
    /// error naming the file and the problem.
    pub fn load(path: &Path) -> Result<Self, GarmentError> {
        let bytes = std::fs::read(path).map_err(|e| GarmentError::file(path, e.to_string()))?;
        Self::from_bytes(&bytes, path)
    }

    /// Reads a template from the bytes of a `.garment` file; `path` names it in errors.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, GarmentError> {
        let bad = |m: String| GarmentError::file(path, m);
        let (_, meta) = SafeTensors::read_metadata(bytes)
            .map_err(|e| bad(format!("not a garment template: {e}")))?;
        let meta = meta.metadata().clone().unwrap_or_default();
        if meta.get("format").map(String::as_str) != Some(FORMAT) {
            return Err(bad(format!("not a {FORMAT} file")));
        }
        fn field<T: for<'de> Deserialize<'de>>(
            meta: &HashMap<String, String>,
            key: &str,
            path: &Path,
        ) -> Result<T, GarmentError> {
            let text = meta
                .get(key)
                .ok_or_else(|| GarmentError::file(path, format!("missing metadata {key}")))?;
            serde_json::from_str(text)
                .map_err(|e| GarmentError::file(path, format!("metadata {key}: {e}")))
        }
        let st = SafeTensors::deserialize(bytes).map_err(|e| bad(e.to_string()))?;
        let data = |name: &str, dtype: Dtype| -> Result<&[u8], GarmentError> {
            Ok(typed_tensor(&st, name, dtype).map_err(bad)?.data())
        };
        let vec3s = |name: &str| -> Result<Vec<Vec3>, GarmentError> {
            Ok(from_le::<f32>(data(name, Dtype::F32)?)
                .chunks_exact(3)
                .map(Vec3::from_slice)
                .collect())
        };
        let bone_meta: Vec<BoneMeta> = field(&meta, "bones", path)?;
        let (heads, tails) = (vec3s("rig.heads")?, vec3s("rig.tails")?);
        let frames: Vec<Quat> = from_le::<f32>(data("rig.frames", Dtype::F32)?)
            .chunks_exact(4)
            .map(Quat::from_slice)
            .collect();
        if heads.len() != bone_meta.len()
            || tails.len() != bone_meta.len()
            || frames.len() != bone_meta.len()
        {
            return Err(bad("rig arrays do not match the bone list".into()));
        }
        let rig = Rig {
            bones: bone_meta
                .into_iter()
                .zip(heads.into_iter().zip(tails).zip(frames))
                .map(|(m, ((head, tail), frame))| Bone {
                    name: m.name,
                    parent: m.parent,
                    head,
                    tail,
                    frame,
                })
                .collect(),
        };
        let template = Self {
            kind: field(&meta, "kind", path)?,
            cut: field(&meta, "cut", path)?,
            edge_length: field(&meta, "edge_length", path)?,
            mesh: TriMesh {
                vertices: vec3s("vertices")?,
                faces: from_le::<u32>(data("faces", Dtype::U32)?)
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2]])
                    .collect(),
            },
            uvs: from_le::<f32>(data("uvs", Dtype::F32)?)
                .chunks_exact(6)
                .map(|c| [[c[0], c[1]], [c[2], c[3]], [c[4], c[5]]])
                .collect(),
            weights: SkinWeights {
                offsets: from_le(data("weights.offsets", Dtype::U32)?),
                bones: from_le(data("weights.bones", Dtype::U16)?),
                weights: from_le(data("weights.values", Dtype::F32)?),
            },
            body_phenotype: field(&meta, "body_phenotype", path)?,
            rig,
        };
        template.validate().map_err(|e| bad(e.to_string()))?;
        Ok(template)
    }
}
