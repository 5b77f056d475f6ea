//! Test meshes, from `geom`'s primitives (a test-only dependency), as the plain arrays
//! the renderer takes.

use geom::TriMesh;
use glam::Vec3;

/// An icosphere of radius `r` centred at `c`, subdivided `levels` times (20 * 4^levels faces),
/// faces counter-clockwise seen from outside.
pub(crate) fn icosphere(c: Vec3, r: f32, levels: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let m = TriMesh::icosphere(levels, r);
    (m.vertices.iter().map(|p| c + *p).collect(), m.faces)
}

/// An axis-aligned box from `lo` to `hi`, 12 triangles, CCW seen from outside.
pub(crate) fn cuboid(lo: Vec3, hi: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let m = TriMesh::cuboid((hi - lo) * 0.5);
    let centre = (lo + hi) * 0.5;
    (m.vertices.iter().map(|p| centre + *p).collect(), m.faces)
}
