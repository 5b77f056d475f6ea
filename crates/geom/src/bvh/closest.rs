//! Closest-point queries.

use glam::{Vec3, Vec3A};
use rayon::prelude::*;

use super::{Bvh, Node};
use crate::tri::closest_point_on_triangle;

/// The closest point of a mesh to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestHit {
    /// Index of the face holding the point.
    pub face: u32,
    /// The closest point on the mesh (metres).
    pub point: Vec3,
    /// Barycentric weights of the face's three vertices at `point` (non-negative, sum 1).
    pub bary: [f32; 3],
    /// Distance from the query point to `point` (metres).
    pub distance: f32,
}

/// Squared distance from `p` to a node's box (0 inside). The per-axis gaps are taken four
/// lanes at once (`Vec3A`) and summed as `Vec3` sums them, so the value is the plain one's.
#[inline]
fn box_dist2(n: &Node, p: Vec3A) -> f32 {
    let d = (Vec3A::from(n.min) - p).max(p - Vec3A::from(n.max));
    Vec3::from(d.max(Vec3A::ZERO)).length_squared()
}

impl Bvh {
    /// Closest point on the mesh to `p`; `None` for an empty mesh or a non-finite `p`.
    pub fn closest_point(&self, p: Vec3) -> Option<ClosestHit> {
        self.closest_point_within(p, f32::INFINITY)
    }

    /// Closest point on the mesh to `p` if it lies within `max_distance` metres (inclusive);
    /// otherwise `None`. A small `max_distance` makes the query much cheaper (collision
    /// detection with a thickness).
    pub fn closest_point_within(&self, p: Vec3, max_distance: f32) -> Option<ClosestHit> {
        if self.nodes.is_empty() || !p.is_finite() || max_distance.is_nan() || max_distance < 0.0 {
            return None;
        }
        let pa = Vec3A::from(p);
        let mut best_d2 = max_distance * max_distance;
        let mut best: Option<(u32, Vec3, [f32; 3])> = None;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        if box_dist2(&self.nodes[0], pa) <= best_d2 {
            stack.push(0);
        }
        while let Some(ni) = stack.pop() {
            let n = &self.nodes[ni as usize];
            if box_dist2(n, pa) > best_d2 {
                continue;
            }
            if n.is_leaf() {
                for &fi in self.leaf_faces(n) {
                    let [a, b, c] = self.tri(fi);
                    let (q, w) = closest_point_on_triangle(p, a, b, c);
                    let d2 = q.distance_squared(p);
                    if d2 < best_d2 || (best.is_none() && d2 <= best_d2) {
                        best_d2 = d2;
                        best = Some((fi, q, w));
                    }
                }
            } else {
                let (l, r) = (n.start, n.start + 1);
                let dl = box_dist2(&self.nodes[l as usize], pa);
                let dr = box_dist2(&self.nodes[r as usize], pa);
                // Push the farther child first so the nearer one is explored first.
                let (near, dn, far, df) = if dl <= dr {
                    (l, dl, r, dr)
                } else {
                    (r, dr, l, dl)
                };
                if df <= best_d2 {
                    stack.push(far);
                }
                if dn <= best_d2 {
                    stack.push(near);
                }
            }
        }
        best.map(|(face, point, bary)| ClosestHit {
            face,
            point,
            bary,
            distance: point.distance(p),
        })
    }

    /// [`Bvh::closest_point_within`] for every point of `points` (`[Q]`), in parallel;
    /// `[Q]` results. Pass `f32::INFINITY` for no distance limit.
    pub fn closest_points(&self, points: &[Vec3], max_distance: f32) -> Vec<Option<ClosestHit>> {
        points
            .par_iter()
            .map(|&p| self.closest_point_within(p, max_distance))
            .collect()
    }
}

/// Reference: closest point by checking every face (O(F)); `None` for no faces. Faces with
/// out-of-range indices are skipped.
pub fn closest_point_brute(vertices: &[Vec3], faces: &[[u32; 3]], p: Vec3) -> Option<ClosestHit> {
    let mut best: Option<ClosestHit> = None;
    for (fi, f) in faces.iter().enumerate() {
        let (Some(&a), Some(&b), Some(&c)) = (
            vertices.get(f[0] as usize),
            vertices.get(f[1] as usize),
            vertices.get(f[2] as usize),
        ) else {
            continue;
        };
        let (q, w) = closest_point_on_triangle(p, a, b, c);
        let d = q.distance(p);
        if best.is_none_or(|h| d < h.distance) {
            best = Some(ClosestHit {
                face: fi as u32,
                point: q,
                bary: w,
                distance: d,
            });
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::super::tests::{noisy_sphere, Rng};
    use super::*;

    #[test]
    fn matches_brute_force() {
        let m = noisy_sphere(3, 7);
        let bvh = Bvh::from_mesh(&m).unwrap();
        let mut rng = Rng(11);
        let queries: Vec<Vec3> = (0..500).map(|_| rng.vec3(1.6)).collect();
        let hits = bvh.closest_points(&queries, f32::INFINITY);
        for (q, h) in queries.iter().zip(hits) {
            let h = h.unwrap();
            let r = closest_point_brute(&m.vertices, &m.faces, *q).unwrap();
            assert!(
                (h.distance - r.distance).abs() <= 1e-6,
                "{q}: {} vs {}",
                h.distance,
                r.distance
            );
            let f = m.faces[h.face as usize].map(|i| m.vertices[i as usize]);
            let rebuilt = h.bary[0] * f[0] + h.bary[1] * f[1] + h.bary[2] * f[2];
            assert!((rebuilt - h.point).length() < 1e-5);
            assert!((h.point.distance(*q) - h.distance).abs() < 1e-6);
        }
    }

    #[test]
    fn max_distance_and_refit() {
        let m = noisy_sphere(2, 3);
        let mut bvh = Bvh::from_mesh(&m).unwrap();
        let p = Vec3::new(0.0, 3.0, 0.0);
        let d = bvh.closest_point(p).unwrap().distance;
        assert!(bvh.closest_point_within(p, d - 1e-3).is_none());
        assert!(bvh.closest_point_within(p, d + 1e-3).is_some());
        assert!(bvh.closest_point_within(p, -1.0).is_none());
        assert!(bvh.closest_point(Vec3::NAN).is_none());
        // Move the mesh; the refitted tree must agree with brute force on the moved mesh.
        let moved: Vec<Vec3> = m
            .vertices
            .iter()
            .map(|v| *v * 1.3 + Vec3::new(0.2, -0.1, 0.4))
            .collect();
        bvh.refit(&moved).unwrap();
        let mut rng = Rng(5);
        for _ in 0..200 {
            let q = rng.vec3(2.0);
            let a = bvh.closest_point(q).unwrap().distance;
            let b = closest_point_brute(&moved, &m.faces, q).unwrap().distance;
            assert!((a - b).abs() <= 1e-6);
        }
    }
}
