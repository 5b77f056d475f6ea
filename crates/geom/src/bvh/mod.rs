//! A bounding volume hierarchy over the faces of a triangle mesh.
//!
//! Built top-down with a binned surface-area heuristic in O(F log F) into a flat node array
//! (children stored after their parent, siblings adjacent), it answers:
//! - closest point on the mesh ([`Bvh::closest_point`], with an optional maximum distance);
//! - inside/outside of a closed, consistently oriented mesh ([`Bvh::contains`]) and signed
//!   distance ([`Bvh::signed_distance`], negative inside);
//! - faces crossed by a segment ([`Bvh::segment_hits`]), optionally skipping faces incident to
//!   given vertices, and the mesh's own edge-face crossings ([`Bvh::self_intersections`]);
//! - [`Bvh::refit`] to follow moving vertices without rebuilding.
//!
//! Batch versions of the queries run in parallel with rayon.

mod build;
mod closest;
mod inside;
mod segment;
mod slab;

use glam::Vec3;

pub use closest::{closest_point_brute, ClosestHit};
pub use segment::{segment_hits_brute, SegmentHit};

use crate::error::{GeomError, Result};

/// Largest number of faces in a leaf.
const MAX_LEAF: usize = 4;

/// One node: an axis-aligned box and either two children (`count == 0`, children at `start`
/// and `start + 1`) or a leaf of `count` faces at `order[start..start + count]`.
#[derive(Clone, Copy, Debug, Default)]
struct Node {
    min: Vec3,
    max: Vec3,
    start: u32,
    count: u32,
}

impl Node {
    #[inline]
    fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// A BVH over the faces of a triangle mesh; it keeps its own copy of the vertices and faces.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    vertices: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
    nodes: Vec<Node>,
    /// Face indices in leaf order.
    order: Vec<u32>,
}

fn check_vertices(vertices: &[Vec3]) -> Result<()> {
    if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
        return Err(GeomError::InvalidMesh(format!(
            "vertex {i} has a non-finite coordinate {}",
            vertices[i]
        )));
    }
    Ok(())
}

impl Bvh {
    /// Builds the hierarchy over `faces` (`[F]`) of `vertices` (`[N]`, metres).
    /// Fails on non-finite coordinates or out-of-range indices. An empty face list gives an
    /// empty tree whose queries find nothing.
    pub fn new(vertices: &[Vec3], faces: &[[u32; 3]]) -> Result<Bvh> {
        check_vertices(vertices)?;
        crate::adjacency::check_indices(vertices.len(), faces)?;
        if faces.len() >= u32::MAX as usize / 2 {
            return Err(GeomError::InvalidMesh(format!(
                "{} faces are too many",
                faces.len()
            )));
        }
        let (nodes, order) = build::build(vertices, faces);
        let mut bvh = Bvh {
            vertices: vertices.to_vec(),
            faces: faces.to_vec(),
            nodes,
            order,
        };
        bvh.refit_bounds();
        Ok(bvh)
    }

    /// [`Bvh::new`] over a [`crate::TriMesh`].
    pub fn from_mesh(mesh: &crate::TriMesh) -> Result<Bvh> {
        Bvh::new(&mesh.vertices, &mesh.faces)
    }

    /// Replaces the vertex positions (`[N]`, same N as at build) and updates every box
    /// bottom-up in O(N + nodes) without changing the tree. Query quality degrades if the mesh
    /// deforms a lot; rebuild then. Fails (leaving the tree unchanged) on a length mismatch or
    /// non-finite coordinates.
    pub fn refit(&mut self, vertices: &[Vec3]) -> Result<()> {
        if vertices.len() != self.vertices.len() {
            return Err(GeomError::InvalidInput(format!(
                "refit with {} vertices, the BVH was built with {}",
                vertices.len(),
                self.vertices.len()
            )));
        }
        check_vertices(vertices)?;
        self.vertices.copy_from_slice(vertices);
        self.refit_bounds();
        Ok(())
    }

    /// Recomputes node boxes from the current vertices, children before parents. Leaf boxes
    /// are padded by a millionth of their magnitude so rounding never loses a hit.
    fn refit_bounds(&mut self) {
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            let (lo, hi) = if n.is_leaf() {
                let mut lo = Vec3::splat(f32::INFINITY);
                let mut hi = Vec3::splat(f32::NEG_INFINITY);
                for &fi in &self.order[n.start as usize..(n.start + n.count) as usize] {
                    for &v in &self.faces[fi as usize] {
                        let p = self.vertices[v as usize];
                        lo = lo.min(p);
                        hi = hi.max(p);
                    }
                }
                let pad = 1e-6 * (1.0 + lo.abs().max(hi.abs()).max_element());
                (lo - Vec3::splat(pad), hi + Vec3::splat(pad))
            } else {
                let (l, r) = (
                    self.nodes[n.start as usize],
                    self.nodes[n.start as usize + 1],
                );
                (l.min.min(r.min), l.max.max(r.max))
            };
            self.nodes[i].min = lo;
            self.nodes[i].max = hi;
        }
    }

    /// The vertices `[N]` the tree currently bounds.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The faces `[F]` of the tree.
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// Number of nodes (0 for an empty mesh).
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Bounds `(min, max)` of the whole mesh (padded slightly); `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.nodes.first().map(|n| (n.min, n.max))
    }

    /// Maximum depth of the tree (root = 1; 0 when empty).
    pub fn depth(&self) -> usize {
        let mut best = 0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((i, d)) = stack.pop() {
            let Some(n) = self.nodes.get(i) else { continue };
            best = best.max(d);
            if !n.is_leaf() {
                stack.push((n.start as usize, d + 1));
                stack.push((n.start as usize + 1, d + 1));
            }
        }
        best
    }

    #[inline]
    fn tri(&self, fi: u32) -> [Vec3; 3] {
        self.faces[fi as usize].map(|v| self.vertices[v as usize])
    }

    #[inline]
    fn leaf_faces(&self, n: &Node) -> &[u32] {
        &self.order[n.start as usize..(n.start + n.count) as usize]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::TriMesh;

    /// A deterministic pseudo-random generator for tests (SplitMix64).
    pub(crate) struct Rng(pub u64);
    impl Rng {
        pub(crate) fn next_f32(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 40) as f32 / (1u64 << 24) as f32
        }
        pub(crate) fn vec3(&mut self, scale: f32) -> Vec3 {
            Vec3::new(
                self.next_f32() - 0.5,
                self.next_f32() - 0.5,
                self.next_f32() - 0.5,
            ) * 2.0
                * scale
        }
    }

    /// An icosphere with radial noise: a random-ish closed mesh.
    pub(crate) fn noisy_sphere(sub: u32, seed: u64) -> TriMesh {
        let mut m = TriMesh::icosphere(sub, 1.0);
        let mut rng = Rng(seed);
        for v in &mut m.vertices {
            *v *= 1.0 + 0.15 * (rng.next_f32() - 0.5);
        }
        m
    }

    #[test]
    fn build_contains_every_face_once() {
        let m = noisy_sphere(3, 1);
        let b = Bvh::from_mesh(&m).unwrap();
        let mut seen = b.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..m.faces.len() as u32).collect::<Vec<_>>());
        // Every face lies in the box of its leaf and every child inside its parent.
        for (i, n) in b.nodes.iter().enumerate() {
            if n.is_leaf() {
                assert!(n.count as usize <= MAX_LEAF);
                for &f in b.leaf_faces(n) {
                    for p in b.tri(f) {
                        assert!(p.cmpge(n.min).all() && p.cmple(n.max).all());
                    }
                }
            } else {
                assert!(n.start as usize > i);
                for c in [n.start, n.start + 1] {
                    let c = b.nodes[c as usize];
                    assert!(c.min.cmpge(n.min).all() && c.max.cmple(n.max).all());
                }
            }
        }
        assert!(b.depth() < 30, "depth {}", b.depth());
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut m = TriMesh::icosphere(0, 1.0);
        assert!(Bvh::new(&m.vertices, &[[0, 1, 12]]).is_err());
        let mut b = Bvh::from_mesh(&m).unwrap();
        assert!(b.refit(&m.vertices[..5]).is_err());
        m.vertices[3].z = f32::NAN;
        assert!(b.refit(&m.vertices).is_err());
        assert!(Bvh::from_mesh(&m).is_err());
        let empty = Bvh::new(&[], &[]).unwrap();
        assert!(empty.closest_point(Vec3::ZERO).is_none());
        assert!(!empty.contains(Vec3::ZERO));
        assert_eq!(empty.depth(), 0);
    }

    #[test]
    fn identical_centroids_still_build() {
        // Many copies of one triangle: no split by centroid is possible.
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let faces = vec![[0, 1, 2]; 100];
        let b = Bvh::new(&v, &faces).unwrap();
        assert!(b.depth() <= 10);
        assert_eq!(b.closest_point(Vec3::Z).unwrap().distance, 1.0);
    }
}
