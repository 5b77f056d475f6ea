//! Segment-vs-triangles queries: which faces a segment crosses.

use glam::Vec3;
use rayon::prelude::*;

use super::slab::Slabs;
use super::Bvh;
use crate::tri::segment_triangle;

/// A face crossed by a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentHit {
    /// Index of the crossed face.
    pub face: u32,
    /// Position along the segment `[a, b]` of the crossing, in [0, 1] (`a + t (b - a)`).
    pub t: f32,
    /// Barycentric weights of the face's vertices at the crossing.
    pub bary: [f32; 3],
}

impl Bvh {
    /// Visits faces whose box meets segment `[a, b]` and that touch none of `skip_vertices`,
    /// calling `hit` for each crossing; stops early when `hit` returns `false`.
    fn for_each_segment_hit(
        &self,
        a: Vec3,
        b: Vec3,
        skip_vertices: &[u32],
        mut hit: impl FnMut(SegmentHit) -> bool,
    ) {
        if !a.is_finite() || !b.is_finite() {
            return;
        }
        self.for_each_face_on_ray(&Slabs::new(a, b - a, 1.0), |fi| {
            let f = &self.faces[fi as usize];
            if f.iter().any(|v| skip_vertices.contains(v)) {
                return true;
            }
            let [p, q, r] = self.tri(fi);
            match segment_triangle(a, b, p, q, r) {
                Some((t, bary)) => hit(SegmentHit { face: fi, t, bary }),
                None => true,
            }
        });
    }

    /// Faces crossed by the segment `[a, b]` (metres), sorted by `t` then face, skipping
    /// faces that have a vertex in `skip_vertices` (pass `&[]` to skip nothing; the list is
    /// scanned linearly, so keep it short: typically the segment's own endpoints). Faces
    /// coplanar with the segment are not reported.
    pub fn segment_hits(&self, a: Vec3, b: Vec3, skip_vertices: &[u32]) -> Vec<SegmentHit> {
        let mut out = Vec::new();
        self.for_each_segment_hit(a, b, skip_vertices, |h| {
            out.push(h);
            true
        });
        out.sort_by(|x, y| x.t.total_cmp(&y.t).then(x.face.cmp(&y.face)));
        out
    }

    /// Indices of the faces crossed by the segment `[a, b]`, ordered along the segment (the
    /// faces of [`Bvh::segment_hits`] with no vertex skipped).
    pub fn segment_faces(&self, a: Vec3, b: Vec3) -> Vec<u32> {
        self.segment_hits(a, b, &[])
            .into_iter()
            .map(|h| h.face)
            .collect()
    }

    /// Whether the segment `[a, b]` crosses any face not touching `skip_vertices`
    /// (stops at the first crossing).
    pub fn segment_intersects(&self, a: Vec3, b: Vec3, skip_vertices: &[u32]) -> bool {
        let mut any = false;
        self.for_each_segment_hit(a, b, skip_vertices, |_| {
            any = true;
            false
        });
        any
    }

    /// Edge-face crossings of the mesh with itself: for each edge `[u, v]` of `edges` (`[E]`,
    /// indices into this tree's vertices, e.g. [`crate::adjacency::edges`]), the faces it
    /// crosses among those not touching `u` or `v`. Returns `[edge index, face]` pairs sorted;
    /// empty for a mesh without self-intersections. Parallel over edges; edges with an
    /// out-of-range index are skipped.
    pub fn self_intersections(&self, edges: &[[u32; 2]]) -> Vec<[u32; 2]> {
        let n = self.vertices.len();
        let mut out: Vec<[u32; 2]> = edges
            .par_iter()
            .enumerate()
            .flat_map_iter(|(ei, &[u, v])| {
                let mut hits = Vec::new();
                if (u as usize) < n && (v as usize) < n {
                    let (a, b) = (self.vertices[u as usize], self.vertices[v as usize]);
                    self.for_each_segment_hit(a, b, &[u, v], |h| {
                        hits.push([ei as u32, h.face]);
                        true
                    });
                }
                hits
            })
            .collect();
        out.sort_unstable();
        out
    }
}

/// Reference: faces crossed by `[a, b]` checking every face (O(F)), same ordering and
/// skipping rules as [`Bvh::segment_hits`].
pub fn segment_hits_brute(
    vertices: &[Vec3],
    faces: &[[u32; 3]],
    a: Vec3,
    b: Vec3,
    skip_vertices: &[u32],
) -> Vec<SegmentHit> {
    let mut out = Vec::new();
    for (fi, f) in faces.iter().enumerate() {
        if f.iter().any(|v| skip_vertices.contains(v)) {
            continue;
        }
        let (Some(&p), Some(&q), Some(&r)) = (
            vertices.get(f[0] as usize),
            vertices.get(f[1] as usize),
            vertices.get(f[2] as usize),
        ) else {
            continue;
        };
        if let Some((t, bary)) = segment_triangle(a, b, p, q, r) {
            out.push(SegmentHit {
                face: fi as u32,
                t,
                bary,
            });
        }
    }
    out.sort_by(|x, y| x.t.total_cmp(&y.t).then(x.face.cmp(&y.face)));
    out
}

#[cfg(test)]
mod tests {
    use super::super::tests::{noisy_sphere, Rng};
    use super::*;
    use crate::adjacency::edges;
    use crate::TriMesh;

    #[test]
    fn matches_brute_force() {
        let m = noisy_sphere(3, 21);
        let bvh = Bvh::from_mesh(&m).unwrap();
        let mut rng = Rng(8);
        let mut total = 0;
        for i in 0..400 {
            let a = rng.vec3(1.5);
            let b = if i % 2 == 0 {
                a + rng.vec3(0.3)
            } else {
                rng.vec3(1.5)
            };
            let skip = if i % 3 == 0 {
                vec![m.faces[i][0], m.faces[i + 1][1]]
            } else {
                vec![]
            };
            let got = bvh.segment_hits(a, b, &skip);
            let want = segment_hits_brute(&m.vertices, &m.faces, a, b, &skip);
            assert_eq!(got, want, "segment {a} -> {b}");
            assert_eq!(bvh.segment_intersects(a, b, &skip), !want.is_empty());
            if skip.is_empty() {
                let faces: Vec<u32> = want.iter().map(|h| h.face).collect();
                assert_eq!(bvh.segment_faces(a, b), faces);
            }
            total += want.len();
        }
        assert!(total > 100, "too few crossings to be a test: {total}");
    }

    #[test]
    fn axis_aligned_segments() {
        let cube = TriMesh::cuboid(Vec3::ONE);
        let bvh = Bvh::from_mesh(&cube).unwrap();
        // Through two opposite faces, parallel to an axis (zero direction components).
        let h = bvh.segment_hits(Vec3::new(0.3, 0.2, -2.0), Vec3::new(0.3, 0.2, 2.0), &[]);
        assert_eq!(h.len(), 2);
        assert!((h[0].t - 0.25).abs() < 1e-6 && (h[1].t - 0.75).abs() < 1e-6);
        assert!(bvh
            .segment_hits(Vec3::new(0.3, 0.2, -0.5), Vec3::new(0.3, 0.2, 0.5), &[])
            .is_empty());
    }

    #[test]
    fn self_intersections_of_overlapping_shells() {
        let s = TriMesh::icosphere(2, 1.0);
        let bvh = Bvh::from_mesh(&s).unwrap();
        let e = edges(&s.faces);
        assert!(bvh.self_intersections(&e).is_empty());
        let mut two = s.clone();
        let mut moved = s.clone();
        for v in &mut moved.vertices {
            v.x += 0.8;
        }
        two.append(&moved).unwrap();
        let bvh = Bvh::from_mesh(&two).unwrap();
        let e = edges(&two.faces);
        let hits = bvh.self_intersections(&e);
        assert!(!hits.is_empty());
        // Brute-force check of the same pairs.
        let mut want = Vec::new();
        for (ei, &[u, v]) in e.iter().enumerate() {
            let (a, b) = (two.vertices[u as usize], two.vertices[v as usize]);
            for h in segment_hits_brute(&two.vertices, &two.faces, a, b, &[u, v]) {
                want.push([ei as u32, h.face]);
            }
        }
        want.sort_unstable();
        assert_eq!(hits, want);
    }
}
