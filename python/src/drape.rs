//! `garnet.Draper`: a trained `.garnet` model draping its garment on bodies, through the
//! facade's `garnet::drape` with the options `garnet drape` uses.

use std::path::PathBuf;
use std::sync::Mutex;

use garnet::{drape, Device, DrapeOptions, GarmentModel};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{faces_to_py, points_to_py};
use crate::body::{Body, Pose};
use crate::errors::{detached, file_err, py_err};
use crate::simulate::Template;

/// A trained GarNet model (a `.garnet` file) on the CPU.
#[pyclass(frozen, module = "garnet")]
pub struct Draper {
    // The network is used by one drape at a time.
    model: Mutex<GarmentModel>,
    path: PathBuf,
    kind: String,
    method: String,
}

#[pymethods]
impl Draper {
    /// Loads the model file at `path`. Raises FileNotFoundError when it is missing and
    /// garnet.GarnetError when it is damaged or of another format.
    #[new]
    fn new(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let model = detached(py, || GarmentModel::load(&path, &Device::flex()))
            .map_err(|e| file_err(&path, e))?;
        Ok(Draper {
            kind: model.template().kind.name().to_string(),
            method: model.method_name(),
            model: Mutex::new(model),
            path,
        })
    }

    /// Drapes the model's garment on `body` in its pose, as `garnet drape` does: the limbs
    /// are first cleared out of the body (unless `keep_pose`) and garment vertices the
    /// network leaves inside the body, or nearer its skin than the cloth thickness (4 mm),
    /// are moved out to it (unless `raw`).
    #[pyo3(signature = (body, raw = false, keep_pose = false))]
    fn drape(
        &self,
        py: Python<'_>,
        body: PyRef<'_, Body>,
        raw: bool,
        keep_pose: bool,
    ) -> PyResult<DrapeResult> {
        let opts = DrapeOptions {
            clear_limbs: !keep_pose,
            push_out: !raw,
        };
        let (shaped, pose) = (body.shaped.clone(), body.pose.clone());
        let model = &self.model;
        let mut out = detached(py, || {
            let model = model.lock().unwrap_or_else(|p| p.into_inner());
            drape(std::slice::from_ref(&*model), &shaped, &pose, opts)
        })
        .map_err(py_err)?;
        let g = out.garments.remove(0);
        Ok(DrapeResult {
            garment: g.mesh,
            body: out.body,
            pose: out.pose,
            kind: g.kind,
            pushed_out: g.pushed_out,
            timings: [
                g.timings.warp_ms,
                g.timings.network_ms,
                g.timings.push_out_ms,
                out.collider_ms.unwrap_or(0.0),
            ],
        })
    }

    /// The garment kind ("tshirt", "sweater", "jeans" or a user garment's name).
    #[getter]
    fn kind(&self) -> String {
        self.kind.clone()
    }

    /// The network's name in reports ("GarNet-local +contact +rest").
    #[getter]
    fn method(&self) -> String {
        self.method.clone()
    }

    /// The model file.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The garment template the network drapes.
    #[getter]
    fn template(&self) -> Template {
        let model = self.model.lock().unwrap_or_else(|p| p.into_inner());
        Template::from_template(model.template().clone())
    }

    fn __repr__(&self) -> String {
        format!(
            "garnet.Draper({}, {} {})",
            self.path.display(),
            self.kind,
            self.method
        )
    }
}

/// One draped garment and the posed body it lies on.
#[pyclass(frozen, module = "garnet")]
pub struct DrapeResult {
    garment: geom::TriMesh,
    body: geom::TriMesh,
    pose: body::Pose,
    kind: String,
    pushed_out: usize,
    /// warp, network, push-out, collider (ms).
    timings: [f64; 4],
}

#[pymethods]
impl DrapeResult {
    /// float32 [N,3]: the draped garment's vertices, metres (the body's frame).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        points_to_py(py, self.garment.vertices.clone())
    }

    /// uint32 [F,3]: the garment's triangles (the template's).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        faces_to_py(py, self.garment.faces.clone())
    }

    /// float32 [V,3]: the posed body the garment was draped on, metres (after the limb
    /// clearance, skinned as the model's training bodies were).
    #[getter]
    fn body_vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        points_to_py(py, self.body.vertices.clone())
    }

    /// uint32 [F,3]: the body's triangles.
    #[getter]
    fn body_faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        faces_to_py(py, self.body.faces.clone())
    }

    /// The pose the body was draped in (after the limb clearance).
    #[getter]
    fn pose(&self) -> Pose {
        Pose::concrete(self.pose.clone(), "draped pose")
    }

    /// The garment kind.
    #[getter]
    fn kind(&self) -> String {
        self.kind.clone()
    }

    /// How many vertices the push-out moved (0 with raw=True).
    #[getter]
    fn pushed_out(&self) -> usize {
        self.pushed_out
    }

    /// What the time went to, milliseconds: warp_ms (the template's DQS warp), network_ms
    /// (the forward pass), push_out_ms, collider_ms (the body's collider for the push-out,
    /// built beside the network).
    #[getter]
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let names = ["warp_ms", "network_ms", "push_out_ms", "collider_ms"];
        for (k, v) in names.iter().zip(self.timings) {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "garnet.DrapeResult({}, {} vertices, network {:.1} ms)",
            self.kind,
            self.garment.vertices.len(),
            self.timings[1]
        )
    }
}
