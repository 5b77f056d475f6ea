//! Errors of the body model: assets, phenotypes, poses.

use std::path::PathBuf;

/// Everything that can go wrong while fetching, converting or using the body model.
#[derive(Debug, thiserror::Error)]
pub enum BodyError {
    /// An asset file is missing, unreadable or malformed.
    #[error("{path}: {message}")]
    Asset { path: PathBuf, message: String },
    /// Fetching the assets failed (pip missing, no network, wrong checksum...).
    #[error("fetching body assets: {0}")]
    Fetch(String),
    /// A parameter is out of range or not finite.
    #[error("invalid parameter: {0}")]
    Parameter(String),
    /// A bone name that the rig does not have.
    #[error("unknown bone '{0}'")]
    UnknownBone(String),
    /// A pose file or generator failed.
    #[error(transparent)]
    Pose(#[from] crate::pose::PoseError),
}

impl BodyError {
    /// An [`BodyError::Asset`] error for `path`.
    pub fn asset(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::Asset {
            path: path.into(),
            message: message.into(),
        }
    }
}
