//! Mesh file I/O (OBJ, PLY, GLB), animations (animated GLB, PC2 point caches) and the
//! atomic-write helper every crate uses.
//!
//! Readers never panic on bad input: errors name the file and the line (text) or byte offset
//! (binary). Writers validate the mesh first and write through [`write_atomic`].

mod anim;
mod atomic;
mod glb;
mod glb_read;
pub mod le;
mod obj;
mod ply;

use std::path::Path;

pub use anim::{
    encode_animated_glb, encode_pc2, parse_pc2, read_pc2, write_animated_glb, write_pc2,
    AnimatedMesh, PointCache,
};
pub use atomic::{write_atomic, write_bytes_atomic};
pub use glb::{encode_glb, encode_glb_colored, write_glb, GlbMesh, DEFAULT_COLOR};
pub use glb_read::{parse_glb, read_glb, read_glb_merged, GlbPrimitive};
pub use obj::{parse_obj, read_obj, read_obj_data, write_obj, write_obj_data, ObjData, ObjGroup};
pub use ply::{encode_ply, parse_ply, read_ply, write_ply};

use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;

/// The mesh formats known by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront `.obj`.
    Obj,
    /// Stanford `.ply`.
    Ply,
    /// glTF 2.0 binary `.glb`.
    Glb,
}

impl MeshFormat {
    /// The format of `path` by its (case-insensitive) extension.
    pub fn from_path(path: &Path) -> Result<MeshFormat> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(MeshFormat::Obj),
            Some("ply") => Ok(MeshFormat::Ply),
            Some("glb") => Ok(MeshFormat::Glb),
            _ => Err(GeomError::format(
                path,
                "unknown mesh extension (expected .obj, .ply or .glb)",
            )),
        }
    }
}

/// Reads a triangle mesh, choosing the reader by extension (`.obj`, `.ply`, `.glb`; a GLB's
/// primitives are merged into one mesh).
pub fn read_mesh(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    match MeshFormat::from_path(path)? {
        MeshFormat::Obj => read_obj(path),
        MeshFormat::Ply => read_ply(path),
        MeshFormat::Glb => read_glb_merged(path),
    }
}

/// Writes a triangle mesh atomically, choosing the writer by extension (`.obj`, `.ply` binary
/// little endian, `.glb` with [`DEFAULT_COLOR`] and the file stem as name).
pub fn write_mesh(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    let path = path.as_ref();
    match MeshFormat::from_path(path)? {
        MeshFormat::Obj => write_obj(path, mesh),
        MeshFormat::Ply => write_ply(path, mesh),
        MeshFormat::Glb => {
            let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh");
            write_glb(
                path,
                &[GlbMesh {
                    mesh,
                    name,
                    color: DEFAULT_COLOR,
                }],
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatch_round_trips() {
        let d = tempfile::tempdir().unwrap();
        let m = TriMesh::icosphere(2, 0.7);
        for ext in ["obj", "PLY", "glb"] {
            let p = d.path().join(format!("m.{ext}"));
            write_mesh(&p, &m).unwrap();
            assert_eq!(read_mesh(&p).unwrap(), m, "{ext}");
        }
        let e = write_mesh(d.path().join("m.stl"), &m)
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.stl"), "{e}");
        let e = read_mesh(d.path().join("missing.obj"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.obj"), "{e}");
    }
}
