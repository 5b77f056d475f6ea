//! Errors of garment building, import, storage and warping.

use std::path::PathBuf;

/// Everything that can go wrong with a garment.
#[derive(Debug, thiserror::Error)]
pub enum GarmentError {
    /// A cut parameter or an option is out of range.
    #[error("invalid garment parameter: {0}")]
    Parameter(String),
    /// A mesh failed a check (user garments, built templates).
    #[error("{what}: {reason}")]
    Rejected { what: String, reason: String },
    /// A template file is unreadable or malformed.
    #[error("{path}: {message}")]
    File { path: PathBuf, message: String },
    /// The body model failed.
    #[error(transparent)]
    Body(#[from] body::BodyError),
    /// A geometry routine failed.
    #[error(transparent)]
    Geom(#[from] geom::GeomError),
}

impl GarmentError {
    /// A [`GarmentError::File`] error for `path`.
    pub fn file(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::File {
            path: path.into(),
            message: message.into(),
        }
    }

    /// A [`GarmentError::Rejected`] error.
    pub fn rejected(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Rejected {
            what: what.into(),
            reason: reason.into(),
        }
    }
}
