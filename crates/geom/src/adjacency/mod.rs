//! Mesh connectivity: unique edges, 1-ring neighbours (CSR), 2-ring pairs, vertex-face
//! incidence, edge-face incidence, boundaries, manifold checks and the Euler characteristic.
//!
//! Functions that take `n_vertices` check every face index against it and fail with
//! [`GeomError::InvalidMesh`] rather than panic. Degenerate faces (a repeated index) contribute
//! no self-loop edge `(a, a)`.

mod manifold;
mod topology;

pub use manifold::{check_manifold, ManifoldReport};
pub use topology::{boundary_loops, EdgeTopology, NO_EDGE};

use crate::error::{GeomError, Result};

/// Fails if a face index is `>= n_vertices`, naming the face.
pub fn check_indices(n_vertices: usize, faces: &[[u32; 3]]) -> Result<()> {
    match faces
        .iter()
        .position(|f| f.iter().any(|&i| i as usize >= n_vertices))
    {
        None => Ok(()),
        Some(fi) => Err(GeomError::InvalidMesh(format!(
            "face {fi} = {:?} has a vertex index out of range ({n_vertices} vertices)",
            faces[fi]
        ))),
    }
}

/// Unique undirected edges `[E]` of `faces` (`[F]`), each as `[a, b]` with `a < b`, sorted
/// lexicographically. Self-loops of degenerate faces are left out.
pub fn edges(faces: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut keys: Vec<u64> = Vec::with_capacity(faces.len() * 3);
    for f in faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            if a != b {
                keys.push(edge_key(a, b));
            }
        }
    }
    keys.sort_unstable();
    keys.dedup();
    keys.into_iter().map(key_edge).collect()
}

/// Packs an undirected edge into a sortable key (smaller index in the high half).
#[inline]
pub(crate) fn edge_key(a: u32, b: u32) -> u64 {
    ((a.min(b) as u64) << 32) | a.max(b) as u64
}

#[inline]
pub(crate) fn key_edge(k: u64) -> [u32; 2] {
    [(k >> 32) as u32, k as u32]
}

/// A compressed sparse row table: row `i` is `indices[offsets[i]..offsets[i+1]]`.
///
/// - `offsets`: `[R+1]`, non-decreasing, `offsets[0] = 0`, `offsets[R] = indices.len()`.
/// - `indices`: the concatenated rows.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Csr {
    /// `[R+1]` row starts.
    pub offsets: Vec<u32>,
    /// Concatenated rows.
    pub indices: Vec<u32>,
}

impl Csr {
    /// Number of rows R.
    pub fn num_rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Row `i`; an empty slice when `i` is out of range.
    pub fn row(&self, i: usize) -> &[u32] {
        match (self.offsets.get(i), self.offsets.get(i + 1)) {
            (Some(&s), Some(&e)) => self.indices.get(s as usize..e as usize).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// Builds rows from `(row, value)` pairs with every row `< num_rows`; each row keeps the
    /// order of `pairs`.
    fn from_pairs(num_rows: usize, pairs: &[(u32, u32)]) -> Csr {
        let mut offsets = vec![0u32; num_rows + 1];
        for &(r, _) in pairs {
            offsets[r as usize + 1] += 1;
        }
        for i in 0..num_rows {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut indices = vec![0u32; pairs.len()];
        for &(r, v) in pairs {
            let slot = &mut fill[r as usize];
            indices[*slot as usize] = v;
            *slot += 1;
        }
        Csr { offsets, indices }
    }
}

/// 1-ring neighbours of every vertex as a CSR table with `n_vertices` rows; each row is sorted
/// ascending and holds every vertex sharing an edge with it (never itself).
pub fn one_ring(n_vertices: usize, faces: &[[u32; 3]]) -> Result<Csr> {
    check_indices(n_vertices, faces)?;
    let e = edges(faces);
    let mut pairs = Vec::with_capacity(e.len() * 2);
    for &[a, b] in &e {
        pairs.push((a, b));
        pairs.push((b, a));
    }
    // Edges are sorted by (a, b), so (b, a) pairs arrive out of order: sort once.
    pairs.sort_unstable();
    Ok(Csr::from_pairs(n_vertices, &pairs))
}

/// Faces incident to every vertex as a CSR table with `n_vertices` rows, each in ascending
/// face order (a degenerate face appears once per distinct vertex).
pub fn vertex_faces(n_vertices: usize, faces: &[[u32; 3]]) -> Result<Csr> {
    check_indices(n_vertices, faces)?;
    let mut pairs = Vec::with_capacity(faces.len() * 3);
    for (fi, f) in faces.iter().enumerate() {
        for k in 0..3 {
            if !f[..k].contains(&f[k]) {
                pairs.push((f[k], fi as u32));
            }
        }
    }
    Ok(Csr::from_pairs(n_vertices, &pairs))
}

/// The 2-ring pairs `[P]`: unordered vertex pairs `[i, k]` with `i < k` whose shortest path
/// along edges is exactly two edges (neighbours of neighbours that are not neighbours),
/// sorted. These are the pairs of the distance-based bending constraint.
pub fn two_ring_pairs(n_vertices: usize, faces: &[[u32; 3]]) -> Result<Vec<[u32; 2]>> {
    let ring = one_ring(n_vertices, faces)?;
    let mut mark = vec![u32::MAX; n_vertices];
    let mut out = Vec::new();
    for i in 0..n_vertices {
        let iu = i as u32;
        mark[i] = iu;
        for &j in ring.row(i) {
            mark[j as usize] = iu;
        }
        let start = out.len();
        for &j in ring.row(i) {
            for &k in ring.row(j as usize) {
                if k > iu && mark[k as usize] != iu {
                    mark[k as usize] = iu;
                    out.push([iu, k]);
                }
            }
        }
        out[start..].sort_unstable();
    }
    Ok(out)
}

/// Euler characteristic `V - E + F` with `V = n_vertices` (unreferenced vertices count),
/// `E` the unique edges and `F = faces.len()`; 2 for a closed genus-0 surface.
pub fn euler_characteristic(n_vertices: usize, faces: &[[u32; 3]]) -> i64 {
    n_vertices as i64 - edges(faces).len() as i64 + faces.len() as i64
}

/// Lengths `[E]` (metres) of `edges` over `vertices`; 0 for an edge with an out-of-range index.
pub fn edge_lengths(vertices: &[glam::Vec3], edges: &[[u32; 2]]) -> Vec<f32> {
    edges
        .iter()
        .map(
            |&[a, b]| match (vertices.get(a as usize), vertices.get(b as usize)) {
                (Some(p), Some(q)) => p.distance(*q),
                _ => 0.0,
            },
        )
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriMesh;
    use std::collections::{HashSet, VecDeque};

    #[test]
    fn edges_of_two_triangles() {
        let faces = [[0, 1, 2], [2, 1, 3]];
        assert_eq!(edges(&faces), vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]);
        assert_eq!(edges(&[[4, 4, 1]]), vec![[1, 4]]);
    }

    #[test]
    fn one_ring_rows() {
        let faces = [[0, 1, 2], [2, 1, 3]];
        let r = one_ring(5, &faces).unwrap();
        assert_eq!(r.offsets.len(), 6);
        assert_eq!(r.row(1), &[0, 2, 3]);
        assert_eq!(r.row(4), &[] as &[u32]);
        assert_eq!(r.row(99), &[] as &[u32]);
        assert!(one_ring(3, &faces).is_err());
        let vf = vertex_faces(4, &faces).unwrap();
        assert_eq!(vf.row(2), &[0, 1]);
        assert_eq!(vf.row(3), &[1]);
    }

    /// Reference: BFS distances from every vertex.
    fn two_ring_bfs(n: usize, faces: &[[u32; 3]]) -> Vec<[u32; 2]> {
        let ring = one_ring(n, faces).unwrap();
        let mut out = Vec::new();
        for s in 0..n {
            let mut dist = vec![usize::MAX; n];
            dist[s] = 0;
            let mut q = VecDeque::from([s]);
            while let Some(v) = q.pop_front() {
                for &w in ring.row(v) {
                    if dist[w as usize] == usize::MAX {
                        dist[w as usize] = dist[v] + 1;
                        q.push_back(w as usize);
                    }
                }
            }
            out.extend(
                (s + 1..n)
                    .filter(|&k| dist[k] == 2)
                    .map(|k| [s as u32, k as u32]),
            );
        }
        out
    }

    #[test]
    fn two_ring_matches_bfs() {
        for m in [TriMesh::icosphere(2, 1.0), TriMesh::grid(6, 5, 0.1)] {
            let n = m.vertices.len();
            let got = two_ring_pairs(n, &m.faces).unwrap();
            assert_eq!(got, two_ring_bfs(n, &m.faces));
            let set: HashSet<_> = got.iter().collect();
            assert_eq!(set.len(), got.len());
        }
    }

    #[test]
    fn euler_of_sphere_and_grid() {
        let s = TriMesh::icosphere(3, 1.0);
        assert_eq!(euler_characteristic(s.vertices.len(), &s.faces), 2);
        let g = TriMesh::grid(4, 4, 1.0);
        assert_eq!(euler_characteristic(g.vertices.len(), &g.faces), 1);
        let l = edge_lengths(&g.vertices, &edges(&g.faces));
        assert!(l
            .iter()
            .all(|&x| x == 1.0 || (x - 2f32.sqrt()).abs() < 1e-6));
    }
}
