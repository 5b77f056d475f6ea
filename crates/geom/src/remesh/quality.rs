//! Mesh quality figures: edge-length statistics, smallest angles, valences.

use std::fmt;

use crate::adjacency::EdgeTopology;
use crate::error::Result;
use crate::mesh::TriMesh;

/// Quality figures of a triangle mesh, from [`mesh_quality`]. Lengths in metres, angles in
/// degrees; all zero (histograms empty) for a mesh without faces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshQuality {
    /// Vertices referenced by a face.
    pub vertices: usize,
    /// Unique edges.
    pub edges: usize,
    /// Triangles.
    pub triangles: usize,
    /// Mean edge length (metres).
    pub edge_mean: f32,
    /// Shortest edge (metres).
    pub edge_min: f32,
    /// Longest edge (metres).
    pub edge_max: f32,
    /// 5th percentile of edge lengths (metres).
    pub edge_p5: f32,
    /// 95th percentile of edge lengths (metres).
    pub edge_p95: f32,
    /// 1st percentile of the per-triangle smallest angle (degrees; 60 is equilateral).
    pub min_angle_p1: f32,
    /// Smallest angle of any triangle (degrees).
    pub min_angle_min: f32,
    /// Largest angle of any triangle (degrees).
    pub max_angle_max: f32,
    /// `valence_histogram[k]`: interior vertices with `k` edges (6 is regular).
    pub valence_histogram: Vec<usize>,
    /// `boundary_valence_histogram[k]`: boundary vertices with `k` edges (4 is regular).
    pub boundary_valence_histogram: Vec<usize>,
}

impl MeshQuality {
    /// Fraction of interior vertices with valence 6 (0 when there are none).
    pub fn regular_fraction(&self) -> f32 {
        let total: usize = self.valence_histogram.iter().sum();
        match (total, self.valence_histogram.get(6)) {
            (0, _) | (_, None) => 0.0,
            (t, Some(&k)) => k as f32 / t as f32,
        }
    }
}

impl fmt::Display for MeshQuality {
    /// One line, lengths in centimetres (the report convention), angles in degrees.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "V={} E={} F={}; edges cm: mean {:.3} min {:.3} p5 {:.3} p95 {:.3} max {:.3}; \
             min angle deg: p1 {:.1} min {:.1}; max angle {:.1}; valence 6: {:.1}%",
            self.vertices,
            self.edges,
            self.triangles,
            100.0 * self.edge_mean,
            100.0 * self.edge_min,
            100.0 * self.edge_p5,
            100.0 * self.edge_p95,
            100.0 * self.edge_max,
            self.min_angle_p1,
            self.min_angle_min,
            self.max_angle_max,
            100.0 * self.regular_fraction()
        )
    }
}

/// Nearest-rank percentile `p` (0..=100) of ascending `sorted`; 0 when empty.
fn percentile(sorted: &[f32], p: f32) -> f32 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = ((p / 100.0) * (sorted.len() - 1) as f32).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// The three angles (degrees) of a triangle; zeros when degenerate.
fn angles(a: glam::Vec3, b: glam::Vec3, c: glam::Vec3) -> [f32; 3] {
    let ang = |p: glam::Vec3, q: glam::Vec3, r: glam::Vec3| {
        let (u, v) = (q - p, r - p);
        u.cross(v).length().atan2(u.dot(v)).to_degrees()
    };
    [ang(a, b, c), ang(b, c, a), ang(c, a, b)]
}

/// Quality figures of `mesh` (vertices `[N]` in metres, faces `[F]`). Valences count unique
/// edges at each referenced vertex; a vertex on a boundary edge counts as boundary. Fails only
/// on out-of-range indices.
pub fn mesh_quality(mesh: &TriMesh) -> Result<MeshQuality> {
    let n = mesh.vertices.len();
    let topo = EdgeTopology::new(n, &mesh.faces)?;
    let mut lens: Vec<f32> = topo
        .edges
        .iter()
        .map(|&[a, b]| mesh.vertices[a as usize].distance(mesh.vertices[b as usize]))
        .collect();
    lens.sort_unstable_by(f32::total_cmp);
    let mut min_angles = Vec::with_capacity(mesh.faces.len());
    let mut max_angle = 0f32;
    for f in &mesh.faces {
        let [a, b, c] = f.map(|i| mesh.vertices[i as usize]);
        let t = angles(a, b, c);
        min_angles.push(t[0].min(t[1]).min(t[2]));
        max_angle = max_angle.max(t[0].max(t[1]).max(t[2]));
    }
    min_angles.sort_unstable_by(f32::total_cmp);
    let mut valence = vec![0usize; n];
    let mut boundary = vec![false; n];
    for (e, &[a, b]) in topo.edges.iter().enumerate() {
        valence[a as usize] += 1;
        valence[b as usize] += 1;
        if topo.faces_of(e).len() == 1 {
            boundary[a as usize] = true;
            boundary[b as usize] = true;
        }
    }
    let mut referenced = vec![false; n];
    for f in &mesh.faces {
        for &v in f {
            referenced[v as usize] = true;
        }
    }
    let mut hist = Vec::new();
    let mut bhist = Vec::new();
    for v in (0..n).filter(|&v| referenced[v]) {
        let h: &mut Vec<usize> = if boundary[v] { &mut bhist } else { &mut hist };
        if h.len() <= valence[v] {
            h.resize(valence[v] + 1, 0);
        }
        h[valence[v]] += 1;
    }
    let mean = if lens.is_empty() {
        0.0
    } else {
        (lens.iter().map(|&x| x as f64).sum::<f64>() / lens.len() as f64) as f32
    };
    Ok(MeshQuality {
        vertices: referenced.iter().filter(|&&r| r).count(),
        edges: lens.len(),
        triangles: mesh.faces.len(),
        edge_mean: mean,
        edge_min: lens.first().copied().unwrap_or(0.0),
        edge_max: lens.last().copied().unwrap_or(0.0),
        edge_p5: percentile(&lens, 5.0),
        edge_p95: percentile(&lens, 95.0),
        min_angle_p1: percentile(&min_angles, 1.0),
        min_angle_min: min_angles.first().copied().unwrap_or(0.0),
        max_angle_max: max_angle,
        valence_histogram: hist,
        boundary_valence_histogram: bhist,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn equilateral_and_grid() {
        let h = 3f32.sqrt() / 2.0;
        let t = TriMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(0.5, h, 0.0)],
            vec![[0, 1, 2]],
        );
        let q = mesh_quality(&t).unwrap();
        assert!((q.min_angle_min - 60.0).abs() < 1e-3 && (q.max_angle_max - 60.0).abs() < 1e-3);
        assert!((q.edge_mean - 1.0).abs() < 1e-6 && q.edge_p5 == q.edge_p95);
        assert_eq!(q.boundary_valence_histogram, vec![0, 0, 3]);
        let g = TriMesh::grid(4, 4, 0.5);
        let q = mesh_quality(&g).unwrap();
        assert_eq!((q.vertices, q.edges, q.triangles), (16, 33, 18));
        assert!((q.min_angle_min - 45.0).abs() < 1e-3 && (q.max_angle_max - 90.0).abs() < 1e-3);
        assert_eq!(q.valence_histogram, vec![0, 0, 0, 0, 0, 0, 4]);
        assert_eq!(q.edge_min, 0.5);
        assert!(q.to_string().contains("valence 6: 100.0%"), "{q}");
        assert_eq!(
            mesh_quality(&TriMesh::default()).unwrap(),
            MeshQuality::default()
        );
        assert!(mesh_quality(&TriMesh::new(vec![], vec![[0, 1, 2]])).is_err());
    }
}
