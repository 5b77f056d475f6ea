//! Edge-face incidence and boundaries.

use std::collections::HashMap;

use super::{check_indices, edge_key, key_edge, Csr};
use crate::error::Result;

/// Marker in [`EdgeTopology::face_edges`] for the missing edge of a degenerate face.
pub const NO_EDGE: u32 = u32::MAX;

/// Edge-face incidence of a triangle mesh.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EdgeTopology {
    /// `[E]` unique undirected edges `[a, b]`, `a < b`, sorted (same as [`super::edges`]).
    pub edges: Vec<[u32; 2]>,
    /// `E` rows: the faces incident to each edge, ascending.
    pub edge_faces: Csr,
    /// `[F]`: for face `[v0, v1, v2]`, the edge indices of `(v0,v1)`, `(v1,v2)`, `(v2,v0)`;
    /// [`NO_EDGE`] for the self-loop of a degenerate face.
    pub face_edges: Vec<[u32; 3]>,
    /// `E` rows parallel to `edge_faces`: `true` where that face traverses the edge from
    /// `a` to `b` (the edge's stored order), `false` where from `b` to `a`.
    pub edge_face_forward: Vec<bool>,
}

impl EdgeTopology {
    /// Builds the incidence for `[F]` faces over `n_vertices` vertices in O(F log F).
    pub fn new(n_vertices: usize, faces: &[[u32; 3]]) -> Result<Self> {
        check_indices(n_vertices, faces)?;
        // (key, face, corner) for every non-degenerate directed face edge.
        let mut inc: Vec<(u64, u32, u8)> = Vec::with_capacity(faces.len() * 3);
        for (fi, f) in faces.iter().enumerate() {
            for k in 0..3u8 {
                let (a, b) = (f[k as usize], f[(k as usize + 1) % 3]);
                if a != b {
                    inc.push((edge_key(a, b), fi as u32, k));
                }
            }
        }
        inc.sort_unstable();
        let mut edges = Vec::new();
        let mut offsets = vec![0u32];
        let mut indices = Vec::with_capacity(inc.len());
        let mut forward = Vec::with_capacity(inc.len());
        let mut face_edges = vec![[NO_EDGE; 3]; faces.len()];
        let mut i = 0;
        while i < inc.len() {
            let key = inc[i].0;
            let e = edges.len() as u32;
            edges.push(key_edge(key));
            while i < inc.len() && inc[i].0 == key {
                let (_, fi, k) = inc[i];
                indices.push(fi);
                forward.push(
                    faces[fi as usize][k as usize] < faces[fi as usize][(k as usize + 1) % 3],
                );
                face_edges[fi as usize][k as usize] = e;
                i += 1;
            }
            offsets.push(indices.len() as u32);
        }
        Ok(EdgeTopology {
            edges,
            edge_faces: Csr { offsets, indices },
            face_edges,
            edge_face_forward: forward,
        })
    }

    /// Faces incident to edge `e` (empty if `e` is out of range).
    pub fn faces_of(&self, e: usize) -> &[u32] {
        self.edge_faces.row(e)
    }

    /// Indices of the boundary edges (exactly one incident face), ascending.
    pub fn boundary_edges(&self) -> Vec<u32> {
        (0..self.edges.len())
            .filter(|&e| self.faces_of(e).len() == 1)
            .map(|e| e as u32)
            .collect()
    }

    /// For every interior edge (exactly two incident faces) `[a, b, c, d]`: the edge `a < b`
    /// and the vertices `c`, `d` opposite it in its two faces (the "diamond" used by dihedral
    /// bending models). Degenerate neighbours are skipped.
    pub fn interior_diamonds(&self, faces: &[[u32; 3]]) -> Vec<[u32; 4]> {
        let mut out = Vec::new();
        for (e, &[a, b]) in self.edges.iter().enumerate() {
            if let &[f, g] = self.faces_of(e) {
                let opp = |fi: u32| {
                    faces
                        .get(fi as usize)
                        .and_then(|t| t.iter().copied().find(|&v| v != a && v != b))
                };
                if let (Some(c), Some(d)) = (opp(f), opp(g)) {
                    out.push([a, b, c, d]);
                }
            }
        }
        out
    }
}

/// Boundary loops of `[F]` faces over `n_vertices` vertices: each loop is an ordered vertex
/// cycle (first vertex not repeated at the end) following the boundary edges in the direction
/// their face traverses them (for counter-clockwise faces the surface lies to the left).
/// On non-manifold or inconsistently oriented input a chain that cannot be closed is returned
/// as far as it goes.
pub fn boundary_loops(n_vertices: usize, faces: &[[u32; 3]]) -> Result<Vec<Vec<u32>>> {
    let topo = EdgeTopology::new(n_vertices, faces)?;
    // Directed boundary edges start -> end, as traversed by their only face.
    let mut outgoing: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut starts = Vec::new();
    for e in topo.boundary_edges() {
        let [a, b] = topo.edges[e as usize];
        let fwd = topo.edge_face_forward[topo.edge_faces.offsets[e as usize] as usize];
        let (s, t) = if fwd { (a, b) } else { (b, a) };
        outgoing.entry(s).or_default().push(t);
        starts.push(s);
    }
    for v in outgoing.values_mut() {
        v.sort_unstable_by(|a, b| b.cmp(a)); // pop() takes the smallest first: deterministic
    }
    let mut loops = Vec::new();
    for s in starts {
        let Some(first) = outgoing.get_mut(&s).and_then(|v| v.pop()) else {
            continue;
        };
        let mut cycle = vec![s];
        let mut cur = first;
        while cur != s {
            cycle.push(cur);
            match outgoing.get_mut(&cur).and_then(|v| v.pop()) {
                Some(next) => cur = next,
                None => break,
            }
        }
        loops.push(cycle);
    }
    Ok(loops)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriMesh;

    #[test]
    fn incidence_of_two_triangles() {
        let faces = [[0, 1, 2], [2, 1, 3]];
        let t = EdgeTopology::new(4, &faces).unwrap();
        assert_eq!(t.edges, vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]);
        assert_eq!(t.faces_of(2), &[0, 1]);
        assert_eq!(t.face_edges[0], [0, 2, 1]);
        assert_eq!(t.face_edges[1], [2, 3, 4]);
        assert_eq!(t.boundary_edges(), vec![0, 1, 3, 4]);
        assert_eq!(t.interior_diamonds(&faces), vec![[1, 2, 0, 3]]);
        // edge (1,2): face 0 goes 1->2 (forward), face 1 goes 2->1.
        let o = t.edge_faces.offsets[2] as usize;
        assert_eq!(&t.edge_face_forward[o..o + 2], &[true, false]);
    }

    #[test]
    fn grid_has_one_ccw_boundary_loop() {
        let g = TriMesh::grid(4, 3, 1.0);
        let loops = boundary_loops(g.vertices.len(), &g.faces).unwrap();
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), 2 * (4 + 3) - 4);
        // Surface to the left of the walk, normals +Y: signed area about +Y is positive
        // when the loop runs counter-clockwise seen from above.
        let l = &loops[0];
        let mut area = 0.0;
        for i in 0..l.len() {
            let p = g.vertices[l[i] as usize];
            let q = g.vertices[l[(i + 1) % l.len()] as usize];
            area += p.z * q.x - p.x * q.z;
        }
        assert!(area > 0.0, "{area}");
        assert!(boundary_loops(12, &TriMesh::icosphere(0, 1.0).faces)
            .unwrap()
            .is_empty());
    }

    #[test]
    fn two_holes() {
        // A sphere with two faces removed far apart has two 3-vertex loops.
        let mut s = TriMesh::icosphere(1, 1.0);
        let f0 = s.faces[0];
        let far = s
            .faces
            .iter()
            .rposition(|f| f.iter().all(|v| !f0.contains(v)))
            .unwrap();
        s.faces.remove(far);
        s.faces.remove(0);
        let loops = boundary_loops(s.vertices.len(), &s.faces).unwrap();
        assert_eq!(loops.len(), 2);
        assert!(loops.iter().all(|l| l.len() == 3));
    }
}
