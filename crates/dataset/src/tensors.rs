//! The arrays of one sample and their safetensors names.
//!
//! Sample `k` is stored as tensors named `KKKKKKKKKK.NAME` (ten digits), all f32,
//! little-endian, row-major:
//!
//! | name | shape | meaning |
//! |---|---|---|
//! | `body` | `[V,3]` | the posed body's vertices, metres (V = 13380) |
//! | `warped` | `[N,3]` | M: the template skinned onto the posed body by joints only (DQS), metres |
//! | `draped` | `[N,3]` | G: the simulator's draped garment, metres |
//! | `fitted` | `[N,3]` | optional: the template carried by surface anchors, then DQS, metres |
//! | `phenotype` | `[11]` | the body's phenotype values, `body::Phenotype::named_values` order |
//! | `pose.root` | `[3]` | the pose's root translation, metres |
//! | `pose.rotations` | `[B,4]` | the pose's bone-local rotations, quaternions x, y, z, w (B = 31) |
//!
//! A compact dataset (spec `[output] compact = true`) stores neither `body` nor `warped`:
//! [`SampleArrays::read`] leaves them empty and [`crate::Dataset::sample`] rebuilds them.

use std::path::Path;

use geom::io::le::{from_le, to_le};
use glam::{Quat, Vec3};
use safetensors::{Dtype, SafeTensors};

use crate::error::{DatasetError, Result};

/// The arrays of one sample (see the module table for shapes and units).
#[derive(Clone, Debug, PartialEq)]
pub struct SampleArrays {
    /// `[V]` posed body vertices, metres (empty when read from a compact sample).
    pub body: Vec<Vec3>,
    /// `[N]` M, the warped template, metres (empty when read from a compact sample).
    pub warped: Vec<Vec3>,
    /// `[N]` G, the draped garment, metres.
    pub draped: Vec<Vec3>,
    /// `[N]` the surface-anchored warp, metres, if the spec asked for it.
    pub fitted: Option<Vec<Vec3>>,
    /// `[11]` phenotype values.
    pub phenotype: Vec<f32>,
    /// Root translation of the pose, metres.
    pub root_translation: Vec3,
    /// `[B]` bone-local rotations of the pose.
    pub rotations: Vec<Quat>,
}

/// One tensor ready to serialise: name, shape, little-endian f32 bytes.
pub type RawTensor = (String, Vec<usize>, Vec<u8>);

/// The tensor name of array `name` of sample `k`.
pub fn tensor_name(k: u64, name: &str) -> String {
    format!("{k:010}.{name}")
}

fn vec3s(v: &[Vec3]) -> Vec<u8> {
    to_le(v.iter().flat_map(|p| p.to_array()))
}

impl SampleArrays {
    /// The tensors of sample `k`; `compact`: without `body` and `warped`.
    pub fn to_tensors(&self, k: u64, compact: bool) -> Vec<RawTensor> {
        let n = |name: &str| tensor_name(k, name);
        let mut t = Vec::new();
        if !compact {
            t.push((n("body"), vec![self.body.len(), 3], vec3s(&self.body)));
            t.push((n("warped"), vec![self.warped.len(), 3], vec3s(&self.warped)));
        }
        t.extend([
            (n("draped"), vec![self.draped.len(), 3], vec3s(&self.draped)),
            (
                n("phenotype"),
                vec![self.phenotype.len()],
                to_le(self.phenotype.iter().copied()),
            ),
            (
                n("pose.root"),
                vec![3],
                to_le(self.root_translation.to_array()),
            ),
            (
                n("pose.rotations"),
                vec![self.rotations.len(), 4],
                to_le(self.rotations.iter().flat_map(|q| q.to_array())),
            ),
        ]);
        if let Some(f) = &self.fitted {
            t.push((n("fitted"), vec![f.len(), 3], vec3s(f)));
        }
        t
    }

    /// Reads sample `k` from `st` (a file at `path`, named in errors). A compact sample's
    /// `body` and `warped` are left empty.
    pub fn read(st: &SafeTensors<'_>, k: u64, path: &Path) -> Result<Self> {
        let floats = |name: &str, cols: usize, required: bool| -> Result<Option<Vec<f32>>> {
            let full = tensor_name(k, name);
            let t = match st.tensor(&full) {
                Ok(t) => t,
                Err(_) if !required => return Ok(None),
                Err(_) => {
                    return Err(DatasetError::corrupt(
                        path,
                        format!("missing tensor {full}"),
                    ))
                }
            };
            let shape = t.shape();
            let ok = t.dtype() == Dtype::F32
                && match cols {
                    1 => shape.len() == 1,
                    c => shape.len() == 2 && shape[1] == c,
                };
            if !ok {
                return Err(DatasetError::corrupt(
                    path,
                    format!("tensor {full} is {:?} {shape:?}", t.dtype()),
                ));
            }
            Ok(Some(from_le::<f32>(t.data())))
        };
        let points = |v: Vec<f32>| v.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>();
        let need = |name: &str, cols: usize| -> Result<Vec<f32>> {
            Ok(floats(name, cols, true)?.expect("required"))
        };
        let (body, warped) = match (floats("body", 3, false)?, floats("warped", 3, false)?) {
            (Some(b), Some(w)) => (points(b), points(w)),
            (None, None) => (Vec::new(), Vec::new()),
            _ => {
                return Err(DatasetError::corrupt(
                    path,
                    format!("sample {k}: only one of body and warped is stored"),
                ))
            }
        };
        let draped = points(need("draped", 3)?);
        let root = need("pose.root", 1)?;
        if root.len() != 3 {
            return Err(DatasetError::corrupt(
                path,
                format!("sample {k}: pose.root is not [3]"),
            ));
        }
        let out = Self {
            body,
            warped,
            draped,
            fitted: floats("fitted", 3, false)?.map(points),
            phenotype: need("phenotype", 1)?,
            root_translation: Vec3::from_slice(&root),
            rotations: need("pose.rotations", 4)?
                .chunks_exact(4)
                .map(Quat::from_slice)
                .collect(),
        };
        if (!out.warped.is_empty() && out.warped.len() != out.draped.len())
            || out
                .fitted
                .as_ref()
                .is_some_and(|f| f.len() != out.draped.len())
        {
            return Err(DatasetError::corrupt(
                path,
                format!("sample {k}: garment arrays differ in length"),
            ));
        }
        Ok(out)
    }
}

/// Serialises `tensors` with one metadata entry `key` = `meta` (a single key keeps the
/// header deterministic: safetensors stores metadata in a hash map).
pub fn serialize(tensors: &[RawTensor], key: &str, meta: String) -> Result<Vec<u8>> {
    let views = tensors
        .iter()
        .map(|(name, shape, bytes)| {
            safetensors::tensor::TensorView::new(Dtype::F32, shape.clone(), bytes)
                .map(|v| (name.as_str(), v))
        })
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|e| DatasetError::Invalid(format!("tensor layout: {e}")))?;
    let metadata = std::collections::HashMap::from([(key.to_string(), meta)]);
    safetensors::serialize(views, Some(metadata))
        .map_err(|e| DatasetError::Invalid(format!("serialising tensors: {e}")))
}

/// The tensors and the metadata entry `key` of safetensors `bytes` (from `path`).
pub fn parse<'a>(bytes: &'a [u8], key: &str, path: &Path) -> Result<(SafeTensors<'a>, String)> {
    let (_, header) = SafeTensors::read_metadata(bytes)
        .map_err(|e| DatasetError::corrupt(path, format!("not a safetensors file: {e}")))?;
    let meta = header
        .metadata()
        .as_ref()
        .and_then(|m| m.get(key).cloned())
        .ok_or_else(|| DatasetError::corrupt(path, format!("no {key} metadata")))?;
    let st =
        SafeTensors::deserialize(bytes).map_err(|e| DatasetError::corrupt(path, e.to_string()))?;
    Ok((st, meta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_round_trip() {
        let a = SampleArrays {
            body: vec![Vec3::new(1.0, 2.0, 3.0); 4],
            warped: vec![Vec3::X; 2],
            draped: vec![Vec3::Y; 2],
            fitted: Some(vec![Vec3::Z; 2]),
            phenotype: vec![0.5; 11],
            root_translation: Vec3::new(0.1, 0.0, -0.2),
            rotations: vec![Quat::from_rotation_y(0.3); 31],
        };
        let bytes = serialize(&a.to_tensors(7, false), "m", "{}".into()).unwrap();
        let (st, meta) = parse(&bytes, "m", Path::new("x")).unwrap();
        assert_eq!(meta, "{}");
        assert_eq!(SampleArrays::read(&st, 7, Path::new("x")).unwrap(), a);
        let e = SampleArrays::read(&st, 8, Path::new("x")).unwrap_err();
        assert!(
            e.to_string().contains("missing tensor 0000000008.draped"),
            "{e}"
        );
        // Same input, same bytes.
        assert_eq!(
            bytes,
            serialize(&a.to_tensors(7, false), "m", "{}".into()).unwrap()
        );
    }

    #[test]
    fn compact_arrays_leave_body_and_warp_empty() {
        let a = SampleArrays {
            body: vec![Vec3::ONE; 4],
            warped: vec![Vec3::X; 2],
            draped: vec![Vec3::Y; 2],
            fitted: None,
            phenotype: vec![0.5; 11],
            root_translation: Vec3::ZERO,
            rotations: vec![Quat::IDENTITY; 31],
        };
        let bytes = serialize(&a.to_tensors(3, true), "m", "{}".into()).unwrap();
        let (st, _) = parse(&bytes, "m", Path::new("x")).unwrap();
        let back = SampleArrays::read(&st, 3, Path::new("x")).unwrap();
        assert!(back.body.is_empty() && back.warped.is_empty());
        assert_eq!(back.draped, a.draped);
        // Only one of the two stored: a damaged sample, not a compact one.
        let mut half = a.to_tensors(3, true);
        half.push(a.to_tensors(3, false).swap_remove(0));
        let bytes = serialize(&half, "m", "{}".into()).unwrap();
        let (st, _) = parse(&bytes, "m", Path::new("x")).unwrap();
        let e = SampleArrays::read(&st, 3, Path::new("x")).unwrap_err();
        assert!(e.to_string().contains("only one of body and warped"), "{e}");
    }
}
