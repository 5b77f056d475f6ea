//! The error type of the geometry crate.
//!
//! Every reader reports where a problem is: the file path and, for text formats (OBJ, ASCII
//! PLY, PLY headers) the 1-based line number, for binary formats (binary PLY, GLB) the byte
//! offset from the start of the file.

use std::path::{Path, PathBuf};

/// Result alias used throughout the crate.
pub type Result<T, E = GeomError> = std::result::Result<T, E>;

/// Everything that can go wrong in this crate. No function of the crate panics on bad input:
/// it returns one of these instead.
#[derive(Debug, thiserror::Error)]
pub enum GeomError {
    /// The operating system refused to read or write a file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A text file (OBJ, ASCII PLY, a PLY header) holds something that cannot be parsed.
    /// Displayed as `path:line: message`, the convention of compilers and editors.
    #[error("{}:{line}: {msg}", path.display())]
    Text {
        /// The file concerned.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        msg: String,
    },
    /// A binary file (binary PLY, GLB) holds something that cannot be parsed.
    #[error("{}: byte {offset}: {msg}", path.display())]
    Binary {
        /// The file concerned.
        path: PathBuf,
        /// Byte offset from the start of the file where the problem was found.
        offset: u64,
        /// What is wrong.
        msg: String,
    },
    /// A file is well-formed at the byte level but its content is unusable (for example a
    /// glTF accessor pointing past its buffer, or an unsupported file extension).
    #[error("{}: {msg}", path.display())]
    Format {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong.
        msg: String,
    },
    /// A mesh fails [`crate::TriMesh::validate`]: non-finite coordinates, out-of-range
    /// indices, too many vertices for `u32` indices.
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// An argument is unusable (mismatched lengths, `k` larger than the point count, ...).
    #[error("invalid input: {0}")]
    InvalidInput(String),
}

impl GeomError {
    /// An I/O error on `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        GeomError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// A parse error at 1-based `line` of the text file `path`.
    pub fn text(path: &Path, line: usize, msg: impl Into<String>) -> Self {
        GeomError::Text {
            path: path.to_path_buf(),
            line,
            msg: msg.into(),
        }
    }

    /// A parse error at byte `offset` of the binary file `path`.
    pub fn binary(path: &Path, offset: u64, msg: impl Into<String>) -> Self {
        GeomError::Binary {
            path: path.to_path_buf(),
            offset,
            msg: msg.into(),
        }
    }

    /// A content error in the file `path`.
    pub fn format(path: &Path, msg: impl Into<String>) -> Self {
        GeomError::Format {
            path: path.to_path_buf(),
            msg: msg.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_path_and_position() {
        let p = Path::new("dir/a.obj");
        assert_eq!(
            GeomError::text(p, 7, "bad token").to_string(),
            "dir/a.obj:7: bad token"
        );
        assert_eq!(
            GeomError::binary(Path::new("b.ply"), 120, "truncated").to_string(),
            "b.ply: byte 120: truncated"
        );
        assert_eq!(
            GeomError::format(p, "no mesh").to_string(),
            "dir/a.obj: no mesh"
        );
    }
}
