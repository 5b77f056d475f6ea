//! `garnet._garnet`: the native module of the `garnet` Python package.
//!
//! It wraps the workspace's crates: bodies and poses (`body`), GarNet drapes (the `garnet`
//! facade, exactly as `garnet drape` calls it), the cloth simulator (`sim`, as
//! `garnet simulate` calls it), datasets (`dataset`) and the paper's metrics (`geom`).
//! Arrays cross as numpy arrays (float32 metres, uint32 indices). Every call runs with the
//! interpreter detached and any panic caught: errors reach Python as `FileNotFoundError`,
//! `ValueError` or `garnet.GarnetError`, carrying the messages the command line prints.

use pyo3::prelude::*;

mod arrays;
mod body;
mod dataset;
mod drape;
mod errors;
mod metrics;
mod simulate;

pub use errors::GarnetError;

/// The folder of the shipped models (`models/` in the working directory when it holds
/// them, else the repository's).
#[pyfunction]
fn shipped_models_dir() -> std::path::PathBuf {
    garnet::shipped_models_dir()
}

/// The paths of the three shipped GarNet-Local models (T-shirt, sweater, jeans); raises
/// when one is missing.
#[pyfunction]
fn shipped_models() -> PyResult<Vec<std::path::PathBuf>> {
    garnet::shipped_models().map_err(errors::py_err)
}

#[pymodule]
fn _garnet(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // The package drapes in this process: malloc tuned for the networks' large temporaries
    // (see model::alloc), once, when it is imported.
    garnet::model::tune_allocator();
    m.add("GarnetError", m.py().get_type::<GarnetError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<body::Pose>()?;
    m.add_class::<body::Body>()?;
    m.add_class::<drape::Draper>()?;
    m.add_class::<drape::DrapeResult>()?;
    m.add_class::<simulate::Template>()?;
    m.add_class::<simulate::SimulationResult>()?;
    m.add_class::<dataset::Dataset>()?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::e_dist, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::e_norm, m)?)?;
    m.add_function(wrap_pyfunction!(shipped_models_dir, m)?)?;
    m.add_function(wrap_pyfunction!(shipped_models, m)?)?;
    Ok(())
}
