//! Errors as Python exceptions, and running Rust work with the interpreter detached and
//! panics caught.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;

create_exception!(
    garnet,
    GarnetError,
    PyException,
    "An error of garnet (a damaged file, a drape that failed, ...); its message is the one the \
     `garnet` command line prints."
);

/// The Python exception of `e`, its message the whole chain as the CLI prints it (`{:#}`):
/// `FileNotFoundError` when a file was missing, `ValueError` for an unusable parameter,
/// `garnet.GarnetError` otherwise.
pub fn py_err(e: anyhow::Error) -> PyErr {
    let message = format!("{e:#}");
    for cause in e.chain() {
        if let Some(io) = cause.downcast_ref::<std::io::Error>() {
            if io.kind() == std::io::ErrorKind::NotFound {
                return PyFileNotFoundError::new_err(message);
            }
        }
        if is_bad_value(cause) {
            return PyValueError::new_err(message);
        }
    }
    GarnetError::new_err(message)
}

/// Whether `cause` says a parameter or input was unusable.
fn is_bad_value(cause: &(dyn std::error::Error + 'static)) -> bool {
    if let Some(e) = cause.downcast_ref::<body::BodyError>() {
        return matches!(
            e,
            body::BodyError::Parameter(_) | body::BodyError::UnknownBone(_)
        );
    }
    if let Some(e) = cause.downcast_ref::<garment::GarmentError>() {
        return match e {
            garment::GarmentError::Parameter(_) => true,
            garment::GarmentError::Body(b) => is_bad_value(b),
            garment::GarmentError::Geom(g) => is_bad_value(g),
            _ => false,
        };
    }
    if let Some(e) = cause.downcast_ref::<sim::SimError>() {
        return matches!(
            e,
            sim::SimError::InvalidInput(_) | sim::SimError::InvalidParams(_)
        );
    }
    if let Some(e) = cause.downcast_ref::<geom::GeomError>() {
        return matches!(e, geom::GeomError::InvalidInput(_));
    }
    false
}

/// [`py_err`], but a `FileNotFoundError` whenever `path` does not exist (the crates name
/// the file in their message but do not all keep the I/O error).
pub fn file_err(path: &Path, e: anyhow::Error) -> PyErr {
    if !path.exists() {
        return PyFileNotFoundError::new_err(format!("{e:#}"));
    }
    py_err(e)
}

/// A `ValueError` with `message`.
pub fn value_err(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// Runs `f` with the interpreter detached (other Python threads run meanwhile); a panic
/// becomes an error instead of crossing into Python.
pub fn detached<T, F>(py: Python<'_>, f: F) -> anyhow::Result<T>
where
    T: Send,
    F: FnOnce() -> anyhow::Result<T> + Send,
{
    py.detach(|| guarded(f))
}

/// Runs `f`, turning a panic into an error.
pub fn guarded<T>(f: impl FnOnce() -> anyhow::Result<T>) -> anyhow::Result<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(anyhow::anyhow!("internal error in garnet: {what}"))
        }
    }
}
