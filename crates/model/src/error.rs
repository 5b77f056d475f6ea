//! The error type of the model crate.

use std::path::PathBuf;

/// Result alias used throughout the crate.
pub type Result<T, E = ModelError> = std::result::Result<T, E>;

/// Everything that can go wrong in this crate. Public functions return one of these on bad
/// input instead of panicking.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// An input array has the wrong length: `what` needed `expected` items, got `got`.
    #[error("{what}: expected {expected} vertices, got {got}")]
    VertexCount {
        /// Which input is wrong (e.g. "body vertices", "warped garment M").
        what: String,
        /// The count the model or template requires.
        expected: usize,
        /// The count supplied.
        got: usize,
    },
    /// An input holds NaN or infinite coordinates.
    #[error("{what}: vertex {index} is not finite ({value:?})")]
    NonFinite {
        /// Which input is wrong.
        what: String,
        /// Index of the first offending vertex.
        index: usize,
        /// Its coordinates.
        value: [f32; 3],
    },
    /// An input or configuration is unusable for another reason (empty batch, mismatched
    /// samples, a variant that needs data the batch lacks, ...).
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// A geometry routine (adjacency, k-nearest neighbours) refused its input.
    #[error(transparent)]
    Geom(#[from] geom::GeomError),
    /// A checkpoint file cannot be read or written.
    #[error("checkpoint {}: {msg}", path.display())]
    Checkpoint {
        /// The checkpoint file.
        path: PathBuf,
        /// What is wrong.
        msg: String,
    },
    /// The data source of a training loop failed.
    #[error("data: {0}")]
    Data(String),
    /// A file other than a checkpoint (the metrics log) cannot be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The tensor backend failed to execute or to read back a tensor.
    #[error("tensor backend: {0}")]
    Backend(String),
}

impl ModelError {
    /// A [`ModelError::Checkpoint`] for `path` with message `msg`.
    pub(crate) fn checkpoint(path: &std::path::Path, msg: impl Into<String>) -> Self {
        ModelError::Checkpoint {
            path: path.to_path_buf(),
            msg: msg.into(),
        }
    }
}

/// Fails with [`ModelError::VertexCount`] when `got != expected`.
pub(crate) fn check_count(what: &str, expected: usize, got: usize) -> Result<()> {
    if got != expected {
        return Err(ModelError::VertexCount {
            what: what.to_string(),
            expected,
            got,
        });
    }
    Ok(())
}

/// Fails with [`ModelError::NonFinite`] at the first vertex of `points` with a NaN or
/// infinite coordinate.
pub(crate) fn check_finite(what: &str, points: &[glam::Vec3]) -> Result<()> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(ModelError::NonFinite {
            what: what.to_string(),
            index,
            value: points[index].to_array(),
        });
    }
    Ok(())
}
