//! `garnet.Template` (garment templates) and `garnet.simulate` (the cloth simulator, as
//! `garnet simulate` runs it).

use std::path::PathBuf;
use std::sync::Arc;

use body::clearance::ClearanceOptions;
use dataset::spec::SimulatorSpec;
use garment::{build_template, CutParams, GarmentKind, GarmentTemplate};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyAnyMethods, PyDict, PyDictMethods};
use sim::drape::DrapeOptions;

use crate::arrays::{faces_to_py, floats_to_py, points_to_py};
use crate::body::{body_model, parse_skinning, Body, Pose};
use crate::errors::{detached, file_err, py_err, value_err};

/// A garment template: a garment mesh fitted on the template body, with its skinning
/// weights (a `.garment` file).
#[pyclass(frozen, module = "garnet")]
pub struct Template {
    pub template: Arc<GarmentTemplate>,
}

impl Template {
    /// Wraps `template`.
    pub fn from_template(template: GarmentTemplate) -> Self {
        Template {
            template: Arc::new(template),
        }
    }
}

/// The cut of `kind` with the keyword overrides `cut` (metres).
fn cut_params(kind: &GarmentKind, cut: Option<&Bound<'_, PyDict>>) -> PyResult<CutParams> {
    let mut c = CutParams::default_for(kind);
    let Some(cut) = cut else { return Ok(c) };
    for (k, v) in cut.iter() {
        let key: String = k.extract()?;
        let value: f32 = v
            .extract()
            .map_err(|_| value_err(format!("cut parameter {key} must be a number")))?;
        let slot = match key.as_str() {
            "body_length" => &mut c.body_length,
            "sleeve_length" => &mut c.sleeve_length,
            "ease" => &mut c.ease,
            "neckline_depth" => &mut c.neckline_depth,
            "waist_height" => &mut c.waist_height,
            "leg_length" => &mut c.leg_length,
            "flare" => &mut c.flare,
            "bridge" => &mut c.bridge,
            "thigh" => &mut c.thigh,
            _ => {
                return Err(value_err(format!(
                    "unknown cut parameter '{key}': body_length, sleeve_length, ease, \
                     neckline_depth, waist_height, leg_length, flare, bridge or thigh"
                )))
            }
        };
        *slot = value;
    }
    Ok(c)
}

#[pymethods]
impl Template {
    /// Loads a template file (`.garment`, from `garnet garment make` or `import`).
    #[new]
    fn new(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let t =
            detached(py, || Ok(GarmentTemplate::load(&path)?)).map_err(|e| file_err(&path, e))?;
        Ok(Template::from_template(t))
    }

    /// Builds the template of `kind` ("tshirt", "sweater" or "jeans") remeshed to edges of
    /// about `edge` metres (0.01 gives the paper's ~10k-vertex T-shirt; 0.004 to 0.08), as
    /// `garnet garment make` does; keyword arguments set the cut (metres): body_length,
    /// sleeve_length, ease, neckline_depth, waist_height, leg_length, flare, bridge, thigh.
    #[staticmethod]
    #[pyo3(signature = (kind, edge = 0.01, **cut))]
    fn make(
        py: Python<'_>,
        kind: &str,
        edge: f32,
        cut: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let kind = GarmentKind::parse(kind).map_err(|e| value_err(e.to_string()))?;
        if matches!(kind, GarmentKind::Custom(_)) {
            return Err(value_err("Template.make builds tshirt, sweater or jeans"));
        }
        let cut = cut_params(&kind, cut)?;
        let t = detached(py, || {
            let model = body_model()?;
            Ok(build_template(&model, &kind, &cut, edge)?)
        })
        .map_err(py_err)?;
        Ok(Template::from_template(t))
    }

    /// Writes the template to `path` (`.garment`).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let t = self.template.clone();
        detached(py, || Ok(t.save(&path)?)).map_err(py_err)
    }

    /// The garment kind's name.
    #[getter]
    fn kind(&self) -> String {
        self.template.kind.name().to_string()
    }

    /// The edge length it was remeshed to, metres.
    #[getter]
    fn edge_length(&self) -> f32 {
        self.template.edge_length
    }

    /// float32 [N,3]: the template's vertices on the template body, metres.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        points_to_py(py, self.template.mesh.vertices.clone())
    }

    /// uint32 [F,3]: the template's triangles.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        faces_to_py(py, self.template.mesh.faces.clone())
    }

    fn __repr__(&self) -> String {
        format!(
            "garnet.Template({}, {} vertices, edge {:.3} m)",
            self.template.kind.name(),
            self.template.mesh.vertices.len(),
            self.template.edge_length
        )
    }
}

/// The simulator's options: the defaults (or the `simulator` settings: a dict or a TOML
/// file with the keys of a dataset spec's `[simulator]` table), then the keywords.
fn drape_options(
    simulator: Option<&Bound<'_, PyAny>>,
    skinning: Option<&str>,
    keep_pose: bool,
    max_settle_steps: Option<u32>,
    max_penetration_mm: Option<f32>,
) -> PyResult<DrapeOptions> {
    let mut opts = match simulator {
        None => DrapeOptions::default(),
        Some(s) if s.is_instance_of::<PyDict>() => {
            let json: String = s
                .py()
                .import("json")?
                .call_method1("dumps", (s,))?
                .extract()?;
            let spec: SimulatorSpec = serde_json::from_str(&json)
                .map_err(|e| value_err(format!("simulator settings: {e}")))?;
            spec.drape_options()
                .map_err(|(field, m)| value_err(format!("simulator.{field}: {m}")))?
        }
        Some(s) => {
            let path: PathBuf = s.extract().map_err(|_| {
                value_err("simulator must be a dict of settings or the path of a TOML file")
            })?;
            dataset::simulator::load_drape_options(&path).map_err(|e| file_err(&path, e.into()))?
        }
    };
    if let Some(s) = skinning {
        opts.skinning = parse_skinning(s)?;
    }
    opts.clearance = (!keep_pose).then(ClearanceOptions::default);
    if let Some(steps) = max_settle_steps {
        opts.max_settle_steps = steps;
    }
    if let Some(mm) = max_penetration_mm {
        if !(mm.is_finite() && mm >= 0.0) {
            return Err(value_err(format!(
                "max_penetration_mm must be a non-negative number of millimetres, got {mm}"
            )));
        }
        opts.max_penetration = mm * 1e-3;
    }
    Ok(opts)
}

/// Drapes `template` (a Template or the path of a `.garment` file) on `body` with the
/// cloth simulator, as `garnet simulate` does: the body morphs from the template body to
/// its shape, moves into its pose (limbs first cleared out of the body unless
/// `keep_pose`), and the cloth settles. `skinning` ("lbs", the default, or "dqs"),
/// `simulator` (a dict or TOML file of a dataset spec's `[simulator]` keys),
/// `max_settle_steps` and `max_penetration_mm` as the command's flags. Raises
/// garnet.GarnetError when the drape diverges or leaves cloth inside the body.
#[pyfunction]
#[pyo3(signature = (template, body, *, keep_pose = false, skinning = None, simulator = None, max_settle_steps = None, max_penetration_mm = None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    py: Python<'_>,
    template: &Bound<'_, PyAny>,
    body: PyRef<'_, Body>,
    keep_pose: bool,
    skinning: Option<&str>,
    simulator: Option<&Bound<'_, PyAny>>,
    max_settle_steps: Option<u32>,
    max_penetration_mm: Option<f32>,
) -> PyResult<SimulationResult> {
    let template = match template.cast::<Template>() {
        Ok(t) => t.get().template.clone(),
        Err(_) => {
            let path: PathBuf = template.extract().map_err(|_| {
                value_err("template must be a garnet.Template or the path of a .garment file")
            })?;
            let t = detached(py, || Ok(GarmentTemplate::load(&path)?))
                .map_err(|e| file_err(&path, e))?;
            Arc::new(t)
        }
    };
    let opts = drape_options(
        simulator,
        skinning,
        keep_pose,
        max_settle_steps,
        max_penetration_mm,
    )?;
    let (target, pose) = (body.shaped.clone(), body.pose.clone());
    let what = body.__repr__();
    let result = detached(py, || {
        let model = body_model()?;
        let template_body = model.shape(&template.body_phenotype)?;
        sim::drape::drape(
            &template,
            &template_body,
            &target,
            &pose,
            &opts,
            &mut |_, _, _| {},
        )
        .map_err(anyhow::Error::from)
        .map_err(|e| e.context(format!("draping {} ({what})", template.kind.name())))
    })
    .map_err(py_err)?;
    let stats = serde_json::to_string(&result.stats).expect("statistics serialise");
    let stats: Py<PyDict> = py
        .import("json")?
        .call_method1("loads", (stats,))?
        .cast_into::<PyDict>()?
        .unbind();
    Ok(SimulationResult {
        garment: result.garment,
        body: result.body,
        pose: result.pose,
        vertex_strain: result.vertex_strain,
        stats,
        summary: result.stats.summary(),
    })
}

/// A finished simulated drape.
#[pyclass(frozen, module = "garnet")]
pub struct SimulationResult {
    garment: geom::TriMesh,
    body: geom::TriMesh,
    pose: body::Pose,
    vertex_strain: Vec<f32>,
    stats: Py<PyDict>,
    summary: String,
}

#[pymethods]
impl SimulationResult {
    /// float32 [N,3]: the draped garment, metres (vertex i is the template's vertex i).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        points_to_py(py, self.garment.vertices.clone())
    }

    /// uint32 [F,3]: the garment's triangles (the template's).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        faces_to_py(py, self.garment.faces.clone())
    }

    /// float32 [V,3]: the body the garment rests on, metres.
    #[getter]
    fn body_vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        points_to_py(py, self.body.vertices.clone())
    }

    /// uint32 [F,3]: the body's triangles.
    #[getter]
    fn body_faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        faces_to_py(py, self.body.faces.clone())
    }

    /// float32 [N]: the largest strain (length / rest - 1) of each vertex's edges.
    #[getter]
    fn vertex_strain<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f32>> {
        floats_to_py(py, self.vertex_strain.clone())
    }

    /// The pose the body took (after the limb clearance).
    #[getter]
    fn pose(&self) -> Pose {
        Pose::concrete(self.pose.clone(), "simulated pose")
    }

    /// The drape's statistics (as `garnet simulate --stats` writes them): wall_time_s,
    /// animation_steps, settle_steps, converged, max_penetration_m, strain_p50/p90/p99/max,
    /// ...
    #[getter]
    fn stats(&self, py: Python<'_>) -> Py<PyDict> {
        self.stats.clone_ref(py)
    }

    /// The statistics in one line, as `garnet simulate` prints them.
    #[getter]
    fn summary(&self) -> String {
        self.summary.clone()
    }

    fn __repr__(&self) -> String {
        format!("garnet.SimulationResult({})", self.summary)
    }
}
