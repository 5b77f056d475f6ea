//! `garnet.Dataset`: a dataset folder (from `garnet dataset generate`) as a sequence of
//! dicts of numpy arrays, usable as a PyTorch map-style dataset as it is.

use std::path::PathBuf;

use dataset::DatasetError;
use numpy::PyArray2;
use pyo3::exceptions::PyIndexError;
use pyo3::prelude::*;
use pyo3::types::{PyAnyMethods, PyDict, PyDictMethods};

use crate::arrays::{faces_to_py, floats_to_py, points_to_py, quats_to_py, vec3_to_py};
use crate::errors::{detached, file_err, py_err, value_err};
use crate::simulate::Template;

/// A dataset folder opened for reading, the stored samples of one split and garment (or
/// all) in ascending sample index. Every file is checked against the manifest's sha256
/// when read; shards are read lazily, a few kept in memory.
///
/// `dataset[i]` is a dict: "body" float32 [V,3] (the posed body, metres), "warped"
/// float32 [N,3] (M, the template warped onto the body by DQS, metres), "draped" float32
/// [N,3] (G, the simulated garment, metres), "rotations" float32 [B,4] (bone-local
/// quaternions x, y, z, w), "root_translation" float32 [3] (metres), "phenotype" float32
/// [11], "faces" uint32 [F,3] (the garment's triangles), "fitted" float32 [N,3] when the
/// spec stored it, and "index" (the sample index), "garment", "template", "body_index",
/// "split", "pose" (its id), "stature_m", "bmi", "stats" (the simulator's statistics). The
/// arrays own the buffers read from the shard (no further copy): `torch.from_numpy` and
/// `DataLoader`'s collation use them as they are.
#[pyclass(frozen, sequence, module = "garnet")]
pub struct Dataset {
    inner: dataset::Dataset,
    indices: Vec<u64>,
}

/// A dataset error: a damaged file is a GarnetError, an unknown name a ValueError.
fn dataset_err(e: DatasetError) -> PyErr {
    match e {
        DatasetError::Invalid(m) => value_err(m),
        e => py_err(e.into()),
    }
}

#[pymethods]
impl Dataset {
    /// Opens the dataset in folder `dir`, keeping its samples of `split` ("train", "val",
    /// "test", ...) and `garment` (None: all), at most `cache_shards` shards in memory.
    #[new]
    #[pyo3(signature = (dir, split = None, garment = None, cache_shards = 2))]
    fn new(
        py: Python<'_>,
        dir: PathBuf,
        split: Option<String>,
        garment: Option<String>,
        cache_shards: usize,
    ) -> PyResult<Self> {
        let inner = detached(py, || Ok(dataset::Dataset::open(&dir)?))
            .map_err(|e| file_err(&dir, e))?
            .with_cache_shards(cache_shards);
        let indices = inner
            .select(split.as_deref(), garment.as_deref())
            .map_err(dataset_err)?;
        Ok(Dataset { inner, indices })
    }

    fn __len__(&self) -> usize {
        self.indices.len()
    }

    fn __getitem__<'py>(&self, py: Python<'py>, i: isize) -> PyResult<Bound<'py, PyDict>> {
        let n = self.indices.len() as isize;
        let j = if i < 0 { i + n } else { i };
        if !(0..n).contains(&j) {
            return Err(PyIndexError::new_err(format!(
                "index {i} is out of range for a dataset of {n} samples"
            )));
        }
        self.sample(py, self.indices[j as usize])
    }

    /// The stored sample of index `index` (the dataset's own numbering, as in "index"), as
    /// `dataset[i]` gives it.
    fn sample<'py>(&self, py: Python<'py>, index: u64) -> PyResult<Bound<'py, PyDict>> {
        let inner = &self.inner;
        let (s, template) = detached(py, || {
            let s = inner.sample(index)?;
            let t = inner.template(&s.record.template)?;
            Ok((s, t))
        })
        .map_err(|e| match e.downcast::<DatasetError>() {
            Ok(d) => dataset_err(d),
            Err(e) => py_err(e),
        })?;
        let (r, a) = (s.record, s.arrays);
        let d = PyDict::new(py);
        d.set_item("body", points_to_py(py, a.body))?;
        d.set_item("warped", points_to_py(py, a.warped))?;
        d.set_item("draped", points_to_py(py, a.draped))?;
        d.set_item("rotations", quats_to_py(py, &a.rotations))?;
        d.set_item("root_translation", vec3_to_py(py, a.root_translation))?;
        d.set_item("phenotype", floats_to_py(py, a.phenotype))?;
        d.set_item("faces", faces_to_py(py, template.mesh.faces.clone()))?;
        if let Some(f) = a.fitted {
            d.set_item("fitted", points_to_py(py, f))?;
        }
        d.set_item("index", r.index)?;
        d.set_item("garment", r.garment)?;
        d.set_item("template", r.template)?;
        d.set_item("body_index", r.body)?;
        d.set_item("split", r.split)?;
        d.set_item("pose", r.pose)?;
        d.set_item("stature_m", r.stature_m)?;
        d.set_item("bmi", r.bmi)?;
        let stats = serde_json::to_string(&r.stats).expect("statistics serialise");
        d.set_item("stats", py.import("json")?.call_method1("loads", (stats,))?)?;
        Ok(d)
    }

    /// The sample indices this dataset holds, ascending ([len]).
    #[getter]
    fn indices(&self) -> Vec<u64> {
        self.indices.clone()
    }

    /// The dataset's split names.
    #[getter]
    fn splits(&self) -> Vec<String> {
        self.inner.manifest().splits.keys().cloned().collect()
    }

    /// The dataset's garment names.
    #[getter]
    fn garments(&self) -> Vec<String> {
        let m = self.inner.manifest();
        m.garments.iter().map(|g| g.name.clone()).collect()
    }

    /// The dataset folder.
    #[getter]
    fn dir(&self) -> PathBuf {
        self.inner.dir().to_path_buf()
    }

    /// uint32 [F,3]: the body's triangles (indices into a sample's "body").
    #[getter]
    fn body_faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let inner = &self.inner;
        let faces = detached(py, || Ok(inner.body_faces()?)).map_err(py_err)?;
        Ok(faces_to_py(py, faces))
    }

    /// Template `id` (a sample's "template"): its rest shape and faces.
    fn template(&self, py: Python<'_>, id: &str) -> PyResult<Template> {
        let inner = &self.inner;
        let t = detached(py, || Ok(inner.template(id)?)).map_err(py_err)?;
        Ok(Template { template: t })
    }

    fn __repr__(&self) -> String {
        format!(
            "garnet.Dataset({}, {} samples)",
            self.inner.dir().display(),
            self.indices.len()
        )
    }
}
