//! Errors of the pose sources, and small helpers the file readers share.

use std::path::{Path, PathBuf};

/// Everything that can go wrong while reading motion files, retargeting or sampling poses.
#[derive(Debug, thiserror::Error)]
pub enum PoseError {
    /// A motion file is malformed: the file, the 1-based line and what is wrong.
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        /// The file being read.
        path: PathBuf,
        /// 1-based line number of the problem (the last line for a truncated file).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A motion file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A motion file's skeleton cannot be placed on garnet's rig: the file and why (the
    /// parts it lacks, the joints it could not place).
    #[error("{}: {message}", path.display())]
    Skeleton {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A frame index past the end of a clip.
    #[error("frame {frame} is out of range: the clip has {count} frames")]
    FrameOutOfRange {
        /// The requested 0-based frame.
        frame: usize,
        /// Number of frames in the clip.
        count: usize,
    },
    /// The rig cannot receive the pose (no bones, no root...).
    #[error("rig: {0}")]
    Rig(String),
    /// Arguments that do not fit together (an AMC read against another ASF, a NaN
    /// parameter...).
    #[error("{0}")]
    Invalid(String),
    /// [`crate::pose::ProceduralPoseGenerator::sample_accepted`] found no acceptable pose.
    #[error("no acceptable pose in {tries} tries")]
    Rejected {
        /// Number of poses drawn and rejected.
        tries: usize,
    },
}

impl PoseError {
    /// A [`PoseError::Parse`] error.
    pub fn parse(path: &Path, line: usize, message: impl Into<String>) -> Self {
        Self::Parse {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }
}

/// Reads a whole text file (bytes that are not UTF-8 are replaced, so comments in odd
/// encodings do not fail the read).
pub(crate) fn read_text(path: &Path) -> Result<String, PoseError> {
    let bytes = std::fs::read(path).map_err(|source| PoseError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    })
}

/// Parses a finite number; `what` names the value in the error message.
pub(crate) fn parse_num(tok: &str, path: &Path, line: usize, what: &str) -> Result<f64, PoseError> {
    match tok.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(PoseError::parse(
            path,
            line,
            format!("{what}: non-finite value '{tok}'"),
        )),
        Err(_) => Err(PoseError::parse(
            path,
            line,
            format!("{what}: non-numeric value '{tok}'"),
        )),
    }
}

/// Parses exactly `N` finite numbers from `toks`.
pub(crate) fn parse_array<const N: usize>(
    toks: &[&str],
    path: &Path,
    line: usize,
    what: &str,
) -> Result<[f64; N], PoseError> {
    if toks.len() != N {
        return Err(PoseError::parse(
            path,
            line,
            format!("{what}: expected {N} values, found {}", toks.len()),
        ));
    }
    let mut out = [0.0; N];
    for (o, t) in out.iter_mut().zip(toks) {
        *o = parse_num(t, path, line, what)?;
    }
    Ok(out)
}
