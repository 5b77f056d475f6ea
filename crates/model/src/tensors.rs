//! Conversions between plain Rust data ([`glam::Vec3`] point lists, index lists) and tensors.

use burn::prelude::*;
use glam::Vec3;

use crate::error::{ModelError, Result};

/// A 1-D int tensor `[L]` from indices.
pub fn index_tensor(indices: impl IntoIterator<Item = i64>, device: &Device) -> Tensor<1, Int> {
    let v: Vec<i64> = indices.into_iter().collect();
    let n = v.len();
    Tensor::from_data(TensorData::new(v, [n]), device)
}

/// A float tensor of `shape` from row-major `values` (length = product of `shape`).
pub fn vec_tensor<const D: usize>(
    values: Vec<f32>,
    shape: [usize; D],
    device: &Device,
) -> Tensor<D> {
    Tensor::from_data(TensorData::new(values, shape), device)
}

/// Stacks B point lists of equal length N into `[B,N,3]` (metres).
pub fn points_tensor(samples: &[&[Vec3]], device: &Device) -> Tensor<3> {
    let b = samples.len();
    let n = samples.first().map(|s| s.len()).unwrap_or(0);
    let mut flat = Vec::with_capacity(b * n * 3);
    for s in samples {
        for p in s.iter() {
            flat.extend_from_slice(&p.to_array());
        }
    }
    vec_tensor(flat, [b, n, 3], device)
}

/// Reads a float tensor back as row-major f32 values.
pub fn read_f32<const D: usize>(t: Tensor<D>) -> Result<Vec<f32>> {
    t.try_into_vec_as::<f32>()
        .map_err(|e| ModelError::Backend(format!("{e:?}")))
}

/// Reads `[B,N,3]` back as B point lists.
pub fn read_points(t: Tensor<3>) -> Result<Vec<Vec<Vec3>>> {
    let [b, n, c] = t.dims();
    if c != 3 {
        return Err(ModelError::Backend(format!(
            "expected [B,N,3], got [{b},{n},{c}]"
        )));
    }
    if n == 0 {
        return Ok(vec![Vec::new(); b]);
    }
    let flat = read_f32(t)?;
    Ok(flat
        .chunks_exact(n * 3)
        .map(|s| s.chunks_exact(3).map(Vec3::from_slice).collect())
        .collect())
}

/// Reads a one-element tensor as f32.
pub fn read_scalar(t: Tensor<1>) -> Result<f32> {
    let v = read_f32(t)?;
    v.first()
        .copied()
        .ok_or_else(|| ModelError::Backend("empty tensor read as a scalar".into()))
}
