//! Face and vertex normals.
//!
//! These kernels run every simulation step, so they take plain slices and never fail: a face
//! with an index outside `vertices` contributes nothing and gets a zero normal (reject such
//! meshes up front with [`crate::TriMesh::validate`]); a degenerate face (zero area) gets a
//! zero normal; a vertex whose incident faces cancel out or are all degenerate gets a zero
//! normal. No output is ever NaN for finite input.

use glam::Vec3;

#[inline]
fn corners(vertices: &[Vec3], f: &[u32; 3]) -> Option<[Vec3; 3]> {
    Some([
        *vertices.get(f[0] as usize)?,
        *vertices.get(f[1] as usize)?,
        *vertices.get(f[2] as usize)?,
    ])
}

/// Twice-area-weighted normal of one face: `(b - a) x (c - a)`, length = 2 * area.
#[inline]
fn cross(vertices: &[Vec3], f: &[u32; 3]) -> Vec3 {
    match corners(vertices, f) {
        Some([a, b, c]) => (b - a).cross(c - a),
        None => Vec3::ZERO,
    }
}

/// Unit face normals `[F]` (counter-clockwise winding = front); zero for degenerate faces.
///
/// - `vertices`: `[N]` positions; `faces`: `[F]` triangles.
pub fn face_normals(vertices: &[Vec3], faces: &[[u32; 3]]) -> Vec<Vec3> {
    faces
        .iter()
        .map(|f| cross(vertices, f).normalize_or_zero())
        .collect()
}

/// Area-weighted face normals `[F]`: direction of the face normal, length = face area (m^2).
pub fn face_area_normals(vertices: &[Vec3], faces: &[[u32; 3]]) -> Vec<Vec3> {
    faces.iter().map(|f| 0.5 * cross(vertices, f)).collect()
}

/// Face areas `[F]` in square metres.
pub fn face_areas(vertices: &[Vec3], faces: &[[u32; 3]]) -> Vec<f32> {
    faces
        .iter()
        .map(|f| 0.5 * cross(vertices, f).length())
        .collect()
}

/// Area-weighted unit vertex normals `[N]` (`N = vertices.len()`): each vertex gets the
/// normalised sum of its incident faces' area-weighted normals; zero where that sum is zero
/// (unreferenced vertices, degenerate fans).
pub fn vertex_normals(vertices: &[Vec3], faces: &[[u32; 3]]) -> Vec<Vec3> {
    let mut out = vec![Vec3::ZERO; vertices.len()];
    vertex_normals_into(vertices, faces, &mut out);
    out
}

/// [`vertex_normals`] written into `out` (resized to `[N]`), to reuse an allocation every step.
pub fn vertex_normals_into(vertices: &[Vec3], faces: &[[u32; 3]], out: &mut Vec<Vec3>) {
    out.clear();
    out.resize(vertices.len(), Vec3::ZERO);
    for f in faces {
        if corners(vertices, f).is_none() {
            continue;
        }
        let n = cross(vertices, f);
        for &i in f {
            out[i as usize] += n;
        }
    }
    for n in out.iter_mut() {
        *n = n.normalize_or_zero();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriMesh;

    #[test]
    fn sphere_vertex_normals_point_outward() {
        let m = TriMesh::icosphere(2, 1.5);
        for (v, n) in m.vertices.iter().zip(m.vertex_normals()) {
            assert!((n.length() - 1.0).abs() < 1e-5);
            assert!(n.dot(v.normalize()) > 0.99);
        }
        let a: f32 = face_area_normals(&m.vertices, &m.faces)
            .iter()
            .map(|n| n.length())
            .sum();
        assert!((a - m.surface_area()).abs() < 1e-4);
    }

    #[test]
    fn degenerate_and_invalid_faces_give_zero_not_nan() {
        let v = vec![Vec3::ZERO, Vec3::X, 2.0 * Vec3::X, Vec3::Y];
        let faces = vec![[0, 1, 2], [0, 0, 3], [0, 1, 9]];
        let fnorm = face_normals(&v, &faces);
        assert_eq!(fnorm, vec![Vec3::ZERO; 3]);
        let vn = vertex_normals(&v, &faces);
        assert!(vn.iter().all(|n| *n == Vec3::ZERO));
        assert_eq!(face_areas(&v, &faces), vec![0.0; 3]);
    }

    #[test]
    fn area_weighting() {
        // A big face and a small face sharing vertex 0, at right angles.
        let v = vec![
            Vec3::ZERO,
            10.0 * Vec3::X,
            10.0 * Vec3::Y,
            Vec3::Z,
            0.1 * Vec3::X,
        ];
        let faces = vec![[0, 1, 2], [0, 3, 4]];
        let n = vertex_normals(&v, &faces)[0];
        assert!(n.z > 0.99 && n.y > 0.0);
    }
}
