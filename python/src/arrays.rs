//! Arrays between Rust and numpy: points `[N,3]` float32, faces `[F,3]` uint32, quaternions
//! `[B,4]` float32 (x, y, z, w). Arrays handed to Python own the Rust buffer (no copy) where
//! the element layout allows it.

use glam::{Quat, Vec3};
use numpy::ndarray::{Array1, Array2};
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyAnyMethods;

use crate::errors::value_err;

// `Vec3` is three packed f32 (`Vec3A` is the SIMD one): a `Vec<Vec3>` is a `Vec<f32>` of
// three times its length.
const _: () = assert!(std::mem::size_of::<Vec3>() == 12 && std::mem::align_of::<Vec3>() == 4);

/// `[N]` points as one flat `Vec<f32>` of `3N`, reusing the allocation.
fn flatten_points(points: Vec<Vec3>) -> Vec<f32> {
    let mut points = std::mem::ManuallyDrop::new(points);
    let (ptr, len, cap) = (points.as_mut_ptr(), points.len(), points.capacity());
    // SAFETY: Vec3 is #[repr(C)] { x, y, z: f32 } (size 12, align 4, checked above), so the
    // allocation of `cap` Vec3 is one of `3 cap` f32 with the same alignment.
    unsafe { Vec::from_raw_parts(ptr.cast::<f32>(), len * 3, cap * 3) }
}

/// `[N]` faces as one flat `Vec<u32>` of `3N`, reusing the allocation.
fn flatten_faces(faces: Vec<[u32; 3]>) -> Vec<u32> {
    let mut faces = std::mem::ManuallyDrop::new(faces);
    let (ptr, len, cap) = (faces.as_mut_ptr(), faces.len(), faces.capacity());
    // SAFETY: [u32; 3] has size 12 and align 4: `cap` of them are `3 cap` u32.
    unsafe { Vec::from_raw_parts(ptr.cast::<u32>(), len * 3, cap * 3) }
}

/// Points `[N]` as a float32 array `[N,3]` owning their buffer.
pub fn points_to_py(py: Python<'_>, points: Vec<Vec3>) -> Bound<'_, PyArray2<f32>> {
    let n = points.len();
    let flat = flatten_points(points);
    let arr = Array2::from_shape_vec((n, 3), flat).expect("3 floats a point");
    PyArray2::from_owned_array(py, arr)
}

/// Faces `[F]` as a uint32 array `[F,3]` owning their buffer.
pub fn faces_to_py(py: Python<'_>, faces: Vec<[u32; 3]>) -> Bound<'_, PyArray2<u32>> {
    let n = faces.len();
    let flat = flatten_faces(faces);
    let arr = Array2::from_shape_vec((n, 3), flat).expect("3 indices a face");
    PyArray2::from_owned_array(py, arr)
}

/// Quaternions `[B]` as a float32 array `[B,4]` (x, y, z, w).
pub fn quats_to_py<'py>(py: Python<'py>, quats: &[Quat]) -> Bound<'py, PyArray2<f32>> {
    let flat: Vec<f32> = quats.iter().flat_map(|q| q.to_array()).collect();
    let arr = Array2::from_shape_vec((quats.len(), 4), flat).expect("4 floats a quaternion");
    PyArray2::from_owned_array(py, arr)
}

/// One vector as a float32 array `[3]`.
pub fn vec3_to_py(py: Python<'_>, v: Vec3) -> Bound<'_, PyArray1<f32>> {
    PyArray1::from_owned_array(py, Array1::from(v.to_array().to_vec()))
}

/// Floats as a float32 array `[N]` owning them.
pub fn floats_to_py(py: Python<'_>, v: Vec<f32>) -> Bound<'_, PyArray1<f32>> {
    PyArray1::from_vec(py, v)
}

/// `obj` (any array-like: numpy array, list, CPU torch tensor) as a C-contiguous numpy
/// array of `dtype`.
fn as_numpy<'py>(obj: &Bound<'py, PyAny>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    np.call_method1("ascontiguousarray", (obj, dtype))
}

/// The shape of numpy array `a` as text (`[10, 3]`).
fn shape_text(shape: &[usize]) -> String {
    format!("{shape:?}")
}

/// `obj` as `[N,3]` points (float32, metres); `what` names it in the `ValueError` of a
/// wrong shape or a value that is not finite.
pub fn points_from_py(obj: &Bound<'_, PyAny>, what: &str, cols: usize) -> PyResult<Vec<f32>> {
    let arr = as_numpy(obj, "float32").map_err(|e| {
        value_err(format!(
            "{what} must be a float array of shape [N, {cols}]: {e}"
        ))
    })?;
    let arr = arr
        .cast_into::<PyArrayDyn<f32>>()
        .map_err(|e| value_err(format!("{what}: {e}")))?;
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || shape[1] != cols {
        return Err(value_err(format!(
            "{what} must have shape [N, {cols}], got {}",
            shape_text(&shape)
        )));
    }
    let ro = arr.readonly();
    let flat: Vec<f32> = ro.as_array().iter().copied().collect();
    if let Some(i) = flat.iter().position(|v| !v.is_finite()) {
        return Err(value_err(format!(
            "{what} holds a value that is not finite (row {}: {})",
            i / cols,
            flat[i]
        )));
    }
    Ok(flat)
}

/// `obj` as `[N]` points `Vec3`.
pub fn vec3s_from_py(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Vec3>> {
    Ok(points_from_py(obj, what, 3)?
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect())
}

/// `obj` as `[F,3]` faces (non-negative integers under 2^32); `what` names it in errors.
pub fn faces_from_py(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[u32; 3]>> {
    let arr = as_numpy(obj, "int64").map_err(|e| {
        value_err(format!(
            "{what} must be an integer array of shape [F, 3]: {e}"
        ))
    })?;
    let arr = arr
        .cast_into::<PyArrayDyn<i64>>()
        .map_err(|e| value_err(format!("{what}: {e}")))?;
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(value_err(format!(
            "{what} must have shape [F, 3], got {}",
            shape_text(&shape)
        )));
    }
    let ro = arr.readonly();
    let flat: Vec<i64> = ro.as_array().iter().copied().collect();
    let mut faces = Vec::with_capacity(shape[0]);
    for (f, tri) in flat.chunks_exact(3).enumerate() {
        let mut out = [0u32; 3];
        for (o, &i) in out.iter_mut().zip(tri) {
            *o = u32::try_from(i)
                .map_err(|_| value_err(format!("{what}: face {f} has vertex index {i}")))?;
        }
        faces.push(out);
    }
    Ok(faces)
}
