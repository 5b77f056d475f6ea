//! Inside/outside tests and signed distance for closed, consistently oriented meshes.
//!
//! A point's winding number is counted along a ray as (exits - entries), each crossing
//! signed by the face normal; three rays in fixed generic directions vote, so a ray grazing
//! an edge or vertex (counted twice or not at all) is outvoted. Unlike crossing parity, this
//! stays right where a posed body overlaps itself (winding number 2 there). A first ray that
//! passes clear of every edge, vertex and near-parallel face along it already counts the
//! exact winding number, so the vote is only taken when it does not.

use glam::Vec3;
use rayon::prelude::*;

use super::slab::Slabs;
use super::Bvh;
use crate::tri::{ray_crossing, ray_triangle, RayCrossing};

/// +1 when the ray along `dir` leaves through triangle `(a, b, c)` (its normal points along
/// the ray), -1 when it enters.
#[inline]
fn crossing_sign(a: Vec3, b: Vec3, c: Vec3, dir: Vec3) -> i32 {
    if (b - a).cross(c - a).dot(dir) > 0.0 {
        1
    } else {
        -1
    }
}

/// Ray directions: unit vectors far from the axes and from each other, so grid-aligned
/// meshes do not put edges in their path.
const DIRS: [Vec3; 3] = [
    Vec3::new(0.540_649_2, 0.660_793_4, 0.520_625_1),
    Vec3::new(-0.610_305_2, 0.370_185_1, -0.700_350_3),
    Vec3::new(0.391_057_3, -0.802_168_8, -0.451_219_9),
];

/// Barycentric and distance margin of a crossing that [`Bvh::clear_winding`] trusts: a
/// ray within this of an edge, a vertex or its origin (about a nanometre on a body in
/// metres) is left to the three-ray vote.
const CLEAR_MARGIN: f64 = 1e-9;

impl Bvh {
    /// Calls `f(t, s)` for every face the ray `p + t dir`, `t > 0`, crosses: `s` is +1 for an
    /// exit (the face normal points along the ray), -1 for an entry.
    fn for_each_crossing(&self, p: Vec3, dir: Vec3, mut f: impl FnMut(f32, i32)) {
        self.for_each_face_on_ray(&Slabs::new(p, dir, f32::INFINITY), |fi| {
            let [a, b, c] = self.tri(fi);
            if let Some((t, _)) = ray_triangle(p, dir, f32::INFINITY, a, b, c) {
                if t > 0.0 {
                    f(t, crossing_sign(a, b, c, dir));
                }
            }
            true
        });
    }

    /// [`Bvh::ray_winding`] when no face along the ray is too close to call
    /// ([`ray_crossing`] with [`CLEAR_MARGIN`]); `None` (stopping at the first such face)
    /// otherwise. Where it answers, it equals `ray_winding(p, dir)`.
    fn clear_winding(&self, p: Vec3, dir: Vec3) -> Option<i32> {
        let mut w = Some(0);
        self.for_each_face_on_ray(&Slabs::new(p, dir, f32::INFINITY), |fi| {
            let [a, b, c] = self.tri(fi);
            match ray_crossing(p, dir, a, b, c, CLEAR_MARGIN) {
                RayCrossing::Miss => true,
                RayCrossing::Through(_) => {
                    w = w.map(|w| w + crossing_sign(a, b, c, dir));
                    true
                }
                RayCrossing::Grazing => {
                    w = None;
                    false
                }
            }
        });
        w
    }

    /// Winding number of `p` counted along the ray from `p` in direction `dir`:
    /// exits minus entries (a crossing is an exit when the face normal points along the ray).
    pub fn ray_winding(&self, p: Vec3, dir: Vec3) -> i32 {
        let mut w = 0;
        self.for_each_crossing(p, dir, |_, s| w += s);
        w
    }

    /// How far along the ray from `p` in direction `dir` (unit) the first point outside the
    /// mesh lies, counting the winding number along this ray alone (see
    /// [`Bvh::ray_winding`]): 0 when `p` is outside by this ray; the distance of the crossing
    /// after which no part of the mesh encloses the ray any more otherwise (where a posed
    /// body overlaps itself, the exit out of both parts, not the first surface met). `None`
    /// for an empty mesh, a non-finite `p` or a count that never drops to 0 (a ray
    /// grazing an edge). Metres if `dir` is a unit vector.
    pub fn ray_exit(&self, p: Vec3, dir: Vec3) -> Option<f32> {
        if self.nodes.is_empty() || !p.is_finite() {
            return None;
        }
        // (distance, +1 exit / -1 entry) of every crossing beyond p.
        let mut hits: Vec<(f32, i32)> = Vec::new();
        self.for_each_crossing(p, dir, |t, s| hits.push((t, s)));
        let mut w: i32 = hits.iter().map(|h| h.1).sum();
        if w <= 0 {
            return Some(0.0);
        }
        hits.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (t, s) in hits {
            w -= s;
            if w <= 0 {
                return Some(t);
            }
        }
        None
    }

    /// Whether `p` is inside the mesh (winding number at least 1 along a majority of three
    /// rays). Meaningful for closed, outward-oriented meshes; `false` for an empty mesh or a
    /// non-finite `p`. Points within about a micrometre of the surface may go either way.
    pub fn contains(&self, p: Vec3) -> bool {
        if !p.is_finite() {
            return false;
        }
        // One ray with no face too close to call counts the winding number exactly, as a
        // majority of the three would (they can only disagree through grazing rays); this
        // halves the ray casts of the simulator's inside tests.
        if let Some(w) = self.clear_winding(p, DIRS[0]) {
            return w > 0;
        }
        // A majority of three: when the first two rays agree, the third cannot change it
        // (saves a third of the ray casts: the rays almost always agree).
        let inside = |d: Vec3| self.ray_winding(p, d) > 0;
        let (a, b) = (inside(DIRS[0]), inside(DIRS[1]));
        if a == b {
            a
        } else {
            inside(DIRS[2])
        }
    }

    /// Signed distance from `p` to the mesh (metres): negative inside (see [`Bvh::contains`]),
    /// positive outside; `None` for an empty mesh or a non-finite `p`.
    pub fn signed_distance(&self, p: Vec3) -> Option<f32> {
        let d = self.closest_point(p)?.distance;
        Some(if self.contains(p) { -d } else { d })
    }

    /// [`Bvh::contains`] for every point of `points` (`[Q]`), in parallel; `[Q]` results.
    pub fn contains_points(&self, points: &[Vec3]) -> Vec<bool> {
        points.par_iter().map(|&p| self.contains(p)).collect()
    }

    /// [`Bvh::signed_distance`] for every point of `points` (`[Q]`), in parallel; `[Q]`
    /// results, NaN where the distance is undefined (empty mesh, non-finite point).
    pub fn signed_distances(&self, points: &[Vec3]) -> Vec<f32> {
        points
            .par_iter()
            .map(|&p| self.signed_distance(p).unwrap_or(f32::NAN))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{noisy_sphere, Rng};
    use super::*;
    use crate::tri::winding_number;
    use crate::TriMesh;

    #[test]
    fn directions_are_unit() {
        for d in DIRS {
            assert!((d.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn sphere_inside_matches_analytic() {
        let r = 0.8;
        let m = TriMesh::icosphere(3, r);
        let bvh = Bvh::from_mesh(&m).unwrap();
        // The icosphere lies between the inscribed radius and r.
        let inner = r * 0.99;
        let mut rng = Rng(2);
        let pts: Vec<Vec3> = (0..2000).map(|_| rng.vec3(1.2)).collect();
        let inside = bvh.contains_points(&pts);
        let sd = bvh.signed_distances(&pts);
        for ((p, ins), d) in pts.iter().zip(inside).zip(sd) {
            let l = p.length();
            if l < inner {
                assert!(ins, "{p} should be inside");
                assert!(d < 0.0 && (d + (r - l)).abs() < 0.01);
            } else if l > r * 1.001 {
                assert!(!ins, "{p} should be outside");
                assert!(d > 0.0);
            }
        }
    }

    #[test]
    fn noisy_mesh_matches_winding_number_and_grid_points() {
        let m = noisy_sphere(3, 9);
        let bvh = Bvh::from_mesh(&m).unwrap();
        let mut pts: Vec<Vec3> = Vec::new();
        // Grid-aligned points (x = 0 plane and axis lines hit vertices of the icosphere).
        for i in -6..=6 {
            for j in -6..=6 {
                pts.push(Vec3::new(0.0, i as f32 * 0.2, j as f32 * 0.2));
            }
        }
        let mut rng = Rng(4);
        pts.extend((0..500).map(|_| rng.vec3(1.3)));
        for p in pts {
            let w = winding_number(&m.vertices, &m.faces, p);
            if (w - 0.5).abs() < 0.45 {
                continue; // on the surface
            }
            assert_eq!(bvh.contains(p), w > 0.5, "{p}: winding {w}");
        }
    }

    /// A BVH over two overlapping unit icospheres (subdivision `sub`) centred at x = 0 and
    /// x = 0.5.
    fn two_spheres(sub: u32) -> Bvh {
        let mut m = TriMesh::icosphere(sub, 1.0);
        let mut other = TriMesh::icosphere(sub, 1.0);
        for v in &mut other.vertices {
            v.x += 0.5;
        }
        m.append(&other).unwrap();
        Bvh::from_mesh(&m).unwrap()
    }

    #[test]
    fn overlapping_shells_count_as_inside() {
        let bvh = two_spheres(2);
        assert!(bvh.contains(Vec3::new(0.25, 0.0, 0.0))); // inside both: winding 2
        assert!(bvh.contains(Vec3::new(-0.7, 0.0, 0.0)));
        assert!(!bvh.contains(Vec3::new(2.0, 0.0, 0.0)));
        let cube = Bvh::from_mesh(&TriMesh::cuboid(Vec3::ONE)).unwrap();
        assert!(cube.contains(Vec3::ZERO) && !cube.contains(Vec3::splat(1.5)));
        assert!(cube.contains(Vec3::new(0.999, 0.0, 0.0)));
    }

    #[test]
    fn contains_is_the_majority_of_the_three_rays() {
        let bvh = two_spheres(2);
        let mut rng = Rng(31);
        for _ in 0..2000 {
            let p = rng.vec3(1.6);
            let votes = DIRS.iter().filter(|&&d| bvh.ray_winding(p, d) > 0).count();
            assert_eq!(bvh.contains(p), votes >= 2, "{p}");
        }
    }

    #[test]
    fn a_clear_ray_counts_what_the_plain_count_does() {
        let bvh = two_spheres(2);
        let m = TriMesh::icosphere(2, 1.0);
        let mut rng = Rng(12);
        let (mut answered, mut declined) = (0, 0);
        for i in 0..3000 {
            // Random points, points on the spheres' vertices and edges (rays from there
            // start on the surface) and rays aimed exactly at a vertex.
            let p = match i % 3 {
                0 => rng.vec3(1.6),
                1 => m.vertices[i % m.vertices.len()],
                _ => m.vertices[i % m.vertices.len()] * 0.5 + m.vertices[(i + 1) % 42] * 0.5,
            };
            let dir = if i % 10 == 0 {
                (m.vertices[(i / 10) % m.vertices.len()] * 1.0001 - p).normalize()
            } else {
                DIRS[i % 3]
            };
            match bvh.clear_winding(p, dir) {
                Some(w) => {
                    assert_eq!(w, bvh.ray_winding(p, dir), "{p} {dir}");
                    answered += 1;
                }
                None => declined += 1,
            }
        }
        // Most rays answer; those from surface points or aimed at a vertex decline.
        assert!(answered > 1500 && declined > 100, "{answered} {declined}");
    }

    #[test]
    fn ray_exit_leaves_every_overlapping_shell() {
        // Two unit spheres centred at x = 0 and x = 0.5 (icospheres: radius within 1% of 1).
        let bvh = two_spheres(3);
        let p = Vec3::new(0.25, 0.0, 0.0); // inside both
        let d = DIRS[0];
        // Along +x the first surface met is the first sphere's at x = 1, still inside the
        // second; the exit is the second sphere's surface at x = 1.5.
        let t = bvh.ray_exit(p, Vec3::X.lerp(d, 1e-3).normalize()).unwrap();
        assert!((t - 1.25).abs() < 0.02, "{t}");
        let t = bvh.ray_exit(p, -Vec3::X.lerp(d, 1e-3).normalize()).unwrap();
        assert!((t - 1.25).abs() < 0.02, "{t}");
        // Outside: 0. Just past every exit found, the point is outside.
        assert_eq!(bvh.ray_exit(Vec3::new(3.0, 0.0, 0.0), d), Some(0.0));
        let mut rng = Rng(9);
        for _ in 0..200 {
            let q = rng.vec3(1.2);
            let dir = rng.vec3(1.0).normalize();
            let Some(t) = bvh.ray_exit(q, dir) else {
                continue;
            };
            assert_eq!(t == 0.0, !bvh.contains(q), "{q}");
            assert!(!bvh.contains(q + dir * (t + 1e-3)), "{q} {dir} {t}");
        }
        assert_eq!(Bvh::default().ray_exit(p, d), None);
        assert_eq!(bvh.ray_exit(Vec3::NAN, d), None);
    }
}
