//! The triangle mesh type shared by every pipeline stage.

use glam::Vec3;

use crate::error::{GeomError, Result};

/// An indexed triangle mesh.
///
/// - `vertices`: `[N]` positions in metres (Y up, body facing +Z).
/// - `faces`: `[F]` triangles as counter-clockwise vertex indices seen from outside
///   (outward normals for a closed surface).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// `[N]` vertex positions, metres.
    pub vertices: Vec<Vec3>,
    /// `[F]` triangles, indices into `vertices`, counter-clockwise seen from outside.
    pub faces: Vec<[u32; 3]>,
}

impl TriMesh {
    /// A mesh from `[N]` vertices and `[F]` faces; not validated (see [`TriMesh::validate`]).
    pub fn new(vertices: Vec<Vec3>, faces: Vec<[u32; 3]>) -> Self {
        TriMesh { vertices, faces }
    }

    /// A mesh from row-major flat arrays: `vertices` `[N*3]` (metres), `faces` `[F*3]`.
    /// Fails when a length is not a multiple of 3 or the mesh does not validate.
    pub fn from_flat(vertices: &[f32], faces: &[u32]) -> Result<Self> {
        if vertices.len() % 3 != 0 || faces.len() % 3 != 0 {
            return Err(GeomError::InvalidInput(format!(
                "flat arrays must have lengths divisible by 3, got {} coordinates and {} indices",
                vertices.len(),
                faces.len()
            )));
        }
        let mesh = TriMesh {
            vertices: vertices.chunks_exact(3).map(Vec3::from_slice).collect(),
            faces: faces.chunks_exact(3).map(|f| [f[0], f[1], f[2]]).collect(),
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Vertex positions as a row-major `[N*3]` array (metres).
    pub fn vertices_flat(&self) -> Vec<f32> {
        self.vertices.iter().flat_map(|v| v.to_array()).collect()
    }

    /// Face indices as a row-major `[F*3]` slice (no copy).
    pub fn faces_flat(&self) -> &[u32] {
        self.faces.as_flattened()
    }

    /// Number of vertices N.
    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }

    /// Number of faces F.
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// `true` when the mesh has no faces.
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Checks that every coordinate is finite, that N fits `u32` indices and that every face
    /// index is below N. The message names the first offending vertex or face.
    pub fn validate(&self) -> Result<()> {
        let n = self.vertices.len();
        if n > u32::MAX as usize {
            return Err(GeomError::InvalidMesh(format!(
                "{n} vertices do not fit u32 indices"
            )));
        }
        if let Some((i, v)) = self
            .vertices
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite())
        {
            return Err(GeomError::InvalidMesh(format!(
                "vertex {i} has a non-finite coordinate ({}, {}, {})",
                v.x, v.y, v.z
            )));
        }
        if let Some((fi, f)) = self
            .faces
            .iter()
            .enumerate()
            .find(|(_, f)| f.iter().any(|&i| i as usize >= n))
        {
            return Err(GeomError::InvalidMesh(format!(
                "face {fi} = {f:?} has a vertex index out of range (mesh has {n} vertices)"
            )));
        }
        Ok(())
    }

    /// Axis-aligned bounds `(min, max)` of the vertices (metres); `None` when there are none.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.vertices.first()?;
        Some(
            self.vertices
                .iter()
                .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))),
        )
    }

    /// Unit face normals `[F]` (zero for degenerate faces); see [`crate::normals::face_normals`].
    pub fn face_normals(&self) -> Vec<Vec3> {
        crate::normals::face_normals(&self.vertices, &self.faces)
    }

    /// Area-weighted unit vertex normals `[N]`; see [`crate::normals::vertex_normals`].
    pub fn vertex_normals(&self) -> Vec<Vec3> {
        crate::normals::vertex_normals(&self.vertices, &self.faces)
    }

    /// Total surface area (square metres). Faces with out-of-range indices count zero.
    pub fn surface_area(&self) -> f32 {
        let sum: f64 = crate::normals::face_areas(&self.vertices, &self.faces)
            .iter()
            .map(|&a| a as f64)
            .sum();
        sum as f32
    }

    /// Mean length of the unique edges (metres); 0 for a mesh without edges.
    pub fn mean_edge_length(&self) -> f32 {
        let edges = crate::adjacency::edges(&self.faces);
        let mut sum = 0f64;
        let mut count = 0usize;
        for [a, b] in edges {
            if let (Some(p), Some(q)) =
                (self.vertices.get(a as usize), self.vertices.get(b as usize))
            {
                sum += p.distance(*q) as f64;
                count += 1;
            }
        }
        if count == 0 {
            0.0
        } else {
            (sum / count as f64) as f32
        }
    }

    /// Appends `other`, offsetting its face indices by the current vertex count.
    /// Fails (leaving `self` unchanged) if the result would exceed `u32` indices.
    pub fn append(&mut self, other: &TriMesh) -> Result<()> {
        let offset = self.vertices.len();
        if offset + other.vertices.len() > u32::MAX as usize {
            return Err(GeomError::InvalidInput(
                "merged mesh would exceed u32 vertex indices".into(),
            ));
        }
        let off = offset as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.faces.extend(other.faces.iter().map(|f| {
            [
                f[0].wrapping_add(off),
                f[1].wrapping_add(off),
                f[2].wrapping_add(off),
            ]
        }));
        Ok(())
    }

    /// Reverses the winding of every face (flips normals).
    pub fn flip_faces(&mut self) {
        for f in &mut self.faces {
            f.swap(1, 2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validate_rejects_nan_and_bad_index() {
        let mut m = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        assert!(m.validate().is_ok());
        m.faces.push([0, 1, 3]);
        let e = m.validate().unwrap_err().to_string();
        assert!(e.contains("face 1") && e.contains("3 vertices"), "{e}");
        m.faces.pop();
        m.vertices[1].y = f32::NAN;
        let e = m.validate().unwrap_err().to_string();
        assert!(e.contains("vertex 1") && e.contains("NaN"), "{e}");
        m.vertices[1].y = f32::INFINITY;
        assert!(m.validate().is_err());
    }

    #[test]
    fn flat_round_trip_and_errors() {
        let m = TriMesh::from_flat(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], &[0, 1, 2]).unwrap();
        assert_eq!(m.vertices_flat(), vec![0., 0., 0., 1., 0., 0., 0., 1., 0.]);
        assert_eq!(m.faces_flat(), &[0, 1, 2]);
        assert!(TriMesh::from_flat(&[0., 0.], &[]).is_err());
        assert!(TriMesh::from_flat(&[0., 0., 0.], &[0, 0, 1]).is_err());
    }

    #[test]
    fn append_bounds_area() {
        let mut a = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        let b = a.clone();
        a.append(&b).unwrap();
        assert_eq!(a.faces[1], [3, 4, 5]);
        assert!((a.surface_area() - 1.0).abs() < 1e-6);
        assert_eq!(a.bounds(), Some((Vec3::ZERO, Vec3::new(1., 1., 0.))));
        assert_eq!(TriMesh::default().bounds(), None);
        let e = (2.0 + 2f32.sqrt()) / 3.0;
        assert!((b.mean_edge_length() - e).abs() < 1e-6);
        a.flip_faces();
        assert_eq!(a.faces[0], [0, 2, 1]);
    }
}
