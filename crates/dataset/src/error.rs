//! The error type of dataset generation and reading.

use std::path::{Path, PathBuf};

/// Everything that can go wrong with a dataset. Every variant that concerns a file names
/// it; spec errors also name the field.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// A spec file is malformed or holds an invalid value: the file, the field (a path
    /// such as `garments[1].edge`) and what is wrong.
    #[error("{}: {field}: {message}", file.display())]
    Spec {
        /// The spec file.
        file: PathBuf,
        /// The offending field, as a dotted path with indices.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder concerned.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A dataset file is damaged or does not belong here (checksum mismatch, unparsable
    /// shard or manifest, a shard of another spec).
    #[error("{}: {message}", path.display())]
    Corrupt {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// An argument does not fit the dataset (unknown split, sample index out of range,
    /// merging datasets of different specs...).
    #[error("{0}")]
    Invalid(String),
    /// The body model failed.
    #[error(transparent)]
    Body(#[from] body::BodyError),
    /// Building or warping a garment failed.
    #[error(transparent)]
    Garment(#[from] garment::GarmentError),
    /// A geometry routine or mesh file failed.
    #[error(transparent)]
    Geom(#[from] geom::GeomError),
}

impl DatasetError {
    /// A [`DatasetError::Spec`] error.
    pub fn spec(file: &Path, field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Spec {
            file: file.to_path_buf(),
            field: field.into(),
            message: message.into(),
        }
    }

    /// A [`DatasetError::Io`] error for `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// Errors unless every name in `names` is one of `known` (the names of the dataset's
    /// splits or garments, `what` saying which), naming the first unknown one and listing
    /// the known.
    pub fn check_known<'a>(
        what: &str,
        names: impl IntoIterator<Item = &'a str>,
        known: &[&str],
    ) -> Result<()> {
        match names.into_iter().find(|n| !known.contains(n)) {
            Some(bad) => Err(Self::Invalid(format!(
                "no {what} '{bad}' (the {what}s are {})",
                known.join(", ")
            ))),
            None => Ok(()),
        }
    }

    /// A [`DatasetError::Corrupt`] error for `path`.
    pub fn corrupt(path: &Path, message: impl Into<String>) -> Self {
        Self::Corrupt {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Result alias of the crate.
pub type Result<T, E = DatasetError> = std::result::Result<T, E>;
