//! Small procedural meshes for tests and examples: icosphere, grid, box.

use std::collections::HashMap;

use glam::Vec3;

use crate::mesh::TriMesh;

/// Largest icosphere subdivision level accepted (20 * 4^7 = 327 680 faces); larger requests
/// are clamped.
pub const MAX_ICOSPHERE_SUBDIVISIONS: u32 = 7;

impl TriMesh {
    /// A closed, manifold, outward-oriented sphere of `radius` metres centred at the origin:
    /// an icosahedron subdivided `subdivisions` times (clamped to
    /// [`MAX_ICOSPHERE_SUBDIVISIONS`]), `10 * 4^s + 2` vertices, `20 * 4^s` faces.
    pub fn icosphere(subdivisions: u32, radius: f32) -> TriMesh {
        let t = (1.0 + 5f32.sqrt()) / 2.0;
        let mut vertices: Vec<Vec3> = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ]
        .iter()
        .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
        .collect();
        let mut faces: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions.min(MAX_ICOSPHERE_SUBDIVISIONS) {
            let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
            let mut mid = |a: u32, b: u32, vertices: &mut Vec<Vec3>| -> u32 {
                let key = (a.min(b), a.max(b));
                *midpoint.entry(key).or_insert_with(|| {
                    let p = (vertices[a as usize] + vertices[b as usize]).normalize();
                    vertices.push(p);
                    (vertices.len() - 1) as u32
                })
            };
            let mut next = Vec::with_capacity(faces.len() * 4);
            for &[a, b, c] in &faces {
                let ab = mid(a, b, &mut vertices);
                let bc = mid(b, c, &mut vertices);
                let ca = mid(c, a, &mut vertices);
                next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            faces = next;
        }
        for v in &mut vertices {
            *v *= radius;
        }
        TriMesh { vertices, faces }
    }

    /// A flat sheet in the `y = 0` plane, centred at the origin, facing +Y (normals up):
    /// `nx` vertices along X by `nz` along Z, `spacing` metres apart, vertex `(i, j)` at index
    /// `j * nx + i` and position `((i - (nx-1)/2) * spacing, 0, (j - (nz-1)/2) * spacing)`;
    /// `2 (nx-1)(nz-1)` faces. Returns an empty mesh when `nx < 2` or `nz < 2`, or when the
    /// vertex count would exceed `u32`.
    pub fn grid(nx: usize, nz: usize, spacing: f32) -> TriMesh {
        if nx < 2 || nz < 2 || nx.checked_mul(nz).is_none_or(|n| n > u32::MAX as usize) {
            return TriMesh::default();
        }
        let cx = (nx - 1) as f32 * 0.5;
        let cz = (nz - 1) as f32 * 0.5;
        let mut vertices = Vec::with_capacity(nx * nz);
        for j in 0..nz {
            for i in 0..nx {
                vertices.push(Vec3::new(
                    (i as f32 - cx) * spacing,
                    0.0,
                    (j as f32 - cz) * spacing,
                ));
            }
        }
        let mut faces = Vec::with_capacity(2 * (nx - 1) * (nz - 1));
        let id = |i: usize, j: usize| (j * nx + i) as u32;
        for j in 0..nz - 1 {
            for i in 0..nx - 1 {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1));
                faces.push([a, c, b]);
                faces.push([b, c, d]);
            }
        }
        TriMesh { vertices, faces }
    }

    /// A closed, outward-oriented box centred at the origin with the given half extents
    /// (metres): 8 vertices (vertex `i` has sign bits x = bit 0, y = bit 1, z = bit 2), 12 faces.
    pub fn cuboid(half_extents: Vec3) -> TriMesh {
        let vertices = (0..8)
            .map(|i| {
                let s = |bit: u32| if i & (1 << bit) != 0 { 1.0 } else { -1.0 };
                Vec3::new(s(0), s(1), s(2)) * half_extents
            })
            .collect();
        let faces = vec![
            [0, 4, 6],
            [0, 6, 2],
            [1, 3, 7],
            [1, 7, 5],
            [0, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
            [0, 2, 3],
            [0, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
        ];
        TriMesh { vertices, faces }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(m: &TriMesh) -> bool {
        m.faces.iter().all(|f| {
            let [a, b, c] = f.map(|i| m.vertices[i as usize]);
            (b - a).cross(c - a).dot(a + b + c) > 0.0
        })
    }

    #[test]
    fn icosphere_counts_radius_orientation() {
        for s in 0..3 {
            let m = TriMesh::icosphere(s, 2.0);
            assert_eq!(m.vertices.len(), 10 * 4usize.pow(s) + 2);
            assert_eq!(m.faces.len(), 20 * 4usize.pow(s));
            assert!(m.vertices.iter().all(|v| (v.length() - 2.0).abs() < 1e-5));
            assert!(outward(&m));
            m.validate().unwrap();
        }
        assert_eq!(TriMesh::icosphere(99, 1.0).faces.len(), 20 * 4usize.pow(7));
    }

    #[test]
    fn grid_layout_and_normals() {
        let g = TriMesh::grid(3, 4, 0.5);
        assert_eq!(g.vertices.len(), 12);
        assert_eq!(g.faces.len(), 12);
        assert_eq!(g.vertices[0], Vec3::new(-0.5, 0.0, -0.75));
        assert!(g
            .face_normals()
            .iter()
            .all(|n| (*n - Vec3::Y).length() < 1e-6));
        assert!(TriMesh::grid(1, 5, 1.0).is_empty());
    }

    #[test]
    fn cuboid_is_outward() {
        let b = TriMesh::cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert!(outward(&b));
        assert!((b.surface_area() - 2.0 * (8.0 + 24.0 + 12.0)).abs() < 1e-4);
    }
}
