//! The GarNet paper's metrics, in the units its tables report.

use pyo3::prelude::*;

use crate::arrays::{faces_from_py, vec3s_from_py};
use crate::errors::value_err;

/// E_dist: the mean distance between the vertices of `gt` and `pred` (float [N,3] each,
/// metres), in centimetres.
#[pyfunction]
pub fn e_dist(gt: &Bound<'_, PyAny>, pred: &Bound<'_, PyAny>) -> PyResult<f32> {
    let (gt, pred) = (vec3s_from_py(gt, "gt")?, vec3s_from_py(pred, "pred")?);
    let m = geom::metrics::e_dist(&gt, &pred).map_err(|e| value_err(e.to_string()))?;
    Ok(geom::metrics::m_to_cm(m))
}

/// E_norm: the mean angle between the face normals of `gt` and `pred` (float [N,3] each,
/// same topology) over `faces` (int [F,3]), in degrees.
#[pyfunction]
pub fn e_norm(
    gt: &Bound<'_, PyAny>,
    pred: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
) -> PyResult<f32> {
    let (gt, pred) = (vec3s_from_py(gt, "gt")?, vec3s_from_py(pred, "pred")?);
    let faces = faces_from_py(faces, "faces")?;
    let errors =
        geom::metrics::mesh_errors(&gt, &pred, &faces).map_err(|e| value_err(e.to_string()))?;
    Ok(errors.e_norm_deg)
}
