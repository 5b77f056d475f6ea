//! Manifold and orientation checks.

use std::fmt;

use super::topology::EdgeTopology;
use crate::error::Result;

/// What [`check_manifold`] found. Index lists are ascending and complete.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ManifoldReport {
    /// Number of vertices N given to the check.
    pub num_vertices: usize,
    /// Number of unique edges E.
    pub num_edges: usize,
    /// Number of faces F.
    pub num_faces: usize,
    /// Faces with a repeated vertex index.
    pub degenerate_faces: Vec<u32>,
    /// Edges (as `[a, b]`, `a < b`) shared by more than two faces.
    pub non_manifold_edges: Vec<[u32; 2]>,
    /// Edges shared by two faces that traverse them in the same direction (inconsistent
    /// orientation).
    pub inconsistent_edges: Vec<[u32; 2]>,
    /// Vertices whose incident faces form more than one fan (e.g. two cones touching at a tip).
    pub non_manifold_vertices: Vec<u32>,
    /// Number of boundary edges (exactly one incident face).
    pub boundary_edges: usize,
    /// Number of vertices referenced by no face.
    pub unreferenced_vertices: usize,
}

impl ManifoldReport {
    /// Every edge in one or two faces, every vertex fan single, no degenerate face.
    pub fn is_manifold(&self) -> bool {
        self.degenerate_faces.is_empty()
            && self.non_manifold_edges.is_empty()
            && self.non_manifold_vertices.is_empty()
    }

    /// Every interior edge traversed in opposite directions by its two faces.
    pub fn is_consistently_oriented(&self) -> bool {
        self.inconsistent_edges.is_empty()
    }

    /// No boundary edge.
    pub fn is_closed(&self) -> bool {
        self.boundary_edges == 0
    }

    /// Manifold and consistently oriented (boundaries allowed).
    pub fn is_ok(&self) -> bool {
        self.is_manifold() && self.is_consistently_oriented()
    }

    /// Euler characteristic `V - E + F`.
    pub fn euler_characteristic(&self) -> i64 {
        self.num_vertices as i64 - self.num_edges as i64 + self.num_faces as i64
    }
}

impl fmt::Display for ManifoldReport {
    /// One line: counts, then each failing check with up to five examples.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "V={} E={} F={} chi={} boundary_edges={} unreferenced_vertices={}",
            self.num_vertices,
            self.num_edges,
            self.num_faces,
            self.euler_characteristic(),
            self.boundary_edges,
            self.unreferenced_vertices
        )?;
        fn list<T: fmt::Debug>(f: &mut fmt::Formatter<'_>, what: &str, v: &[T]) -> fmt::Result {
            if !v.is_empty() {
                let shown: Vec<_> = v.iter().take(5).collect();
                let more = if v.len() > 5 { ", ..." } else { "" };
                write!(f, "; {} {what} (e.g. {shown:?}{more})", v.len())?;
            }
            Ok(())
        }
        list(f, "degenerate faces", &self.degenerate_faces)?;
        list(f, "edges in more than two faces", &self.non_manifold_edges)?;
        list(f, "inconsistently oriented edges", &self.inconsistent_edges)?;
        list(f, "vertices with several fans", &self.non_manifold_vertices)?;
        if self.is_ok() {
            write!(f, "; manifold and consistently oriented")?;
        }
        Ok(())
    }
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[x as usize];
        parent[x as usize] = parent[p as usize];
        x = p;
    }
    x
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

/// Checks `[F]` faces over `n_vertices` vertices: degenerate faces, edges in more than two
/// faces, inconsistent orientation, vertices with more than one fan, boundary and
/// unreferenced counts. Fails only on out-of-range indices.
pub fn check_manifold(n_vertices: usize, faces: &[[u32; 3]]) -> Result<ManifoldReport> {
    let topo = EdgeTopology::new(n_vertices, faces)?;
    let mut r = ManifoldReport {
        num_vertices: n_vertices,
        num_edges: topo.edges.len(),
        num_faces: faces.len(),
        ..Default::default()
    };
    let degenerate = |f: &[u32; 3]| f[0] == f[1] || f[1] == f[2] || f[2] == f[0];
    r.degenerate_faces = (0..faces.len())
        .filter(|&i| degenerate(&faces[i]))
        .map(|i| i as u32)
        .collect();

    // Corners (3 f + k) of the same vertex are united when their faces share an edge at it.
    let mut parent: Vec<u32> = (0..faces.len() as u32 * 3).collect();
    let corner = |fi: u32, v: u32| -> u32 {
        let f = &faces[fi as usize];
        fi * 3 + f.iter().position(|&x| x == v).unwrap_or(0) as u32
    };
    for (e, &[a, b]) in topo.edges.iter().enumerate() {
        let fs = topo.faces_of(e);
        match fs.len() {
            1 => r.boundary_edges += 1,
            2 => {
                let o = topo.edge_faces.offsets[e] as usize;
                if topo.edge_face_forward[o] == topo.edge_face_forward[o + 1] {
                    r.inconsistent_edges.push([a, b]);
                }
            }
            _ => r.non_manifold_edges.push([a, b]),
        }
        let good: Vec<u32> = fs
            .iter()
            .copied()
            .filter(|&f| !degenerate(&faces[f as usize]))
            .collect();
        for w in good.windows(2) {
            union(&mut parent, corner(w[0], a), corner(w[1], a));
            union(&mut parent, corner(w[0], b), corner(w[1], b));
        }
    }
    // Per vertex: the first fan root seen, and whether a second one turned up.
    let mut root = vec![u32::MAX; n_vertices];
    let mut multi = vec![false; n_vertices];
    let mut referenced = vec![false; n_vertices];
    for (fi, f) in faces.iter().enumerate() {
        for &v in f {
            referenced[v as usize] = true;
        }
        if degenerate(f) {
            continue;
        }
        for (k, &v) in f.iter().enumerate() {
            let rt = find(&mut parent, fi as u32 * 3 + k as u32);
            let slot = &mut root[v as usize];
            if *slot == u32::MAX {
                *slot = rt;
            } else if *slot != rt {
                multi[v as usize] = true;
            }
        }
    }
    r.non_manifold_vertices = (0..n_vertices)
        .filter(|&v| multi[v])
        .map(|v| v as u32)
        .collect();
    r.unreferenced_vertices = referenced.iter().filter(|&&x| !x).count();
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriMesh;

    #[test]
    fn sphere_is_closed_manifold() {
        let s = TriMesh::icosphere(2, 1.0);
        let r = check_manifold(s.vertices.len(), &s.faces).unwrap();
        assert!(r.is_ok() && r.is_closed(), "{r}");
        assert_eq!(r.euler_characteristic(), 2);
        assert!(r.to_string().contains("manifold and consistently oriented"));
    }

    #[test]
    fn detects_each_failure() {
        // Flipped face -> inconsistent edges.
        let mut s = TriMesh::icosphere(1, 1.0);
        s.faces[3].swap(0, 1);
        let r = check_manifold(s.vertices.len(), &s.faces).unwrap();
        assert_eq!(r.inconsistent_edges.len(), 3);
        assert!(r.is_manifold() && !r.is_ok());

        // Three faces on one edge.
        let faces = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        let r = check_manifold(6, &faces).unwrap();
        assert_eq!(r.non_manifold_edges, vec![[0, 1]]);
        assert_eq!(r.unreferenced_vertices, 1);

        // Bow-tie: two triangles touching at vertex 0 only.
        let faces = [[0, 1, 2], [0, 3, 4]];
        let r = check_manifold(5, &faces).unwrap();
        assert_eq!(r.non_manifold_vertices, vec![0]);
        assert!(!r.is_manifold());
        assert!(
            r.to_string().contains("1 vertices with several fans"),
            "{r}"
        );

        // Degenerate face.
        let r = check_manifold(3, &[[0, 1, 1]]).unwrap();
        assert_eq!(r.degenerate_faces, vec![0]);

        assert!(check_manifold(2, &[[0, 1, 2]]).is_err());
    }

    #[test]
    fn open_grid_is_manifold_with_boundary() {
        let g = TriMesh::grid(5, 5, 1.0);
        let r = check_manifold(g.vertices.len(), &g.faces).unwrap();
        assert!(r.is_ok() && !r.is_closed());
        assert_eq!(r.boundary_edges, 16);
    }
}
