//! The error type of every fallible call in this crate.

/// What can go wrong while rendering, composing or reading/writing pictures.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A face refers to a vertex that does not exist.
    #[error(
        "mesh {mesh}: face {face} refers to vertex {index}, but the mesh has {vertices} vertices"
    )]
    FaceIndex {
        /// Position of the mesh in the scene slice.
        mesh: usize,
        /// Face number within that mesh.
        face: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices of the mesh.
        vertices: usize,
    },
    /// A per-vertex or per-face colour slice has the wrong length.
    #[error("mesh {mesh}: {what} has {got} entries, expected {expected}")]
    ColorCount {
        /// Position of the mesh in the scene slice.
        mesh: usize,
        /// `"vertex_colors"` or `"face_colors"`.
        what: &'static str,
        /// Length of the slice given.
        got: usize,
        /// Length it must have (vertex or face count).
        expected: usize,
    },
    /// A requested picture size is zero or too large.
    #[error("invalid picture size {width}x{height}: {reason}")]
    Size {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// Why it was refused.
        reason: &'static str,
    },
    /// An RGB buffer does not hold `width * height * 3` bytes.
    #[error("pixel buffer has {got} bytes, expected {expected}")]
    BufferSize {
        /// Bytes given.
        got: usize,
        /// Bytes needed.
        expected: usize,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// PNG encoding failed.
    #[error("png encoding: {0}")]
    PngEncode(#[from] png::EncodingError),
    /// PNG decoding failed or the PNG has a layout this crate does not read.
    #[error("png decoding: {0}")]
    PngDecode(String),
}
