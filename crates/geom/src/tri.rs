//! Single-triangle primitives: closest point, segment and ray intersection, solid angle, and
//! the exact (brute-force) generalized winding number used as a reference.

use glam::{DVec3, Vec3};

/// Closest point on the segment `[a, b]` to `p`, and its parameter `t` in [0, 1]
/// (`t = 0` for a zero-length segment).
#[inline]
pub fn closest_point_on_segment(p: Vec3, a: Vec3, b: Vec3) -> (Vec3, f32) {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + t * ab, t)
}

/// Closest point on a degenerate triangle: the best of its three edges.
fn closest_on_edges(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f32; 3]) {
    let (q0, t0) = closest_point_on_segment(p, a, b);
    let (q1, t1) = closest_point_on_segment(p, b, c);
    let (q2, t2) = closest_point_on_segment(p, c, a);
    let cands = [
        (q0, [1.0 - t0, t0, 0.0]),
        (q1, [0.0, 1.0 - t1, t1]),
        (q2, [t2, 0.0, 1.0 - t2]),
    ];
    let mut best = cands[0];
    for c in &cands[1..] {
        if c.0.distance_squared(p) < best.0.distance_squared(p) {
            best = *c;
        }
    }
    best
}

/// Closest point on triangle `(a, b, c)` to `p` and its barycentric coordinates
/// `[wa, wb, wc]` (non-negative, sum 1), after Ericson, *Real-Time Collision Detection* 5.1.5.
/// Degenerate (zero-area) triangles are handled as their three edges; never NaN for finite
/// input.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f32; 3]) {
    let ab = b - a;
    let ac = c - a;
    let n2 = ab.cross(ac).length_squared();
    if n2 <= 0.0 || !n2.is_finite() {
        return closest_on_edges(p, a, b, c);
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    let q = a + ab * v + ac * w;
    if !q.is_finite() {
        return closest_on_edges(p, a, b, c);
    }
    (q, [1.0 - v - w, v, w])
}

/// Intersection of the ray `origin + t * dir` (or of the segment `t in [0, t_max]`) with
/// triangle `(a, b, c)` by Moeller-Trumbore: `Some((t, [wa, wb, wc]))` with `t` in
/// `[0, t_max]`. Boundaries count as hits; degenerate triangles and rays parallel to the
/// triangle's plane (within about 1e-10 rad, which includes coplanar segments) never hit.
///
/// Computed in f64: near-grazing crossings divide by a small determinant, and in f32 the
/// rounding noise there produced false hits far from the triangle. The f32 inputs are exact
/// in f64, so the answer is reliable down to the 1e-10 cut-off.
#[inline]
pub fn ray_triangle(
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
    a: Vec3,
    b: Vec3,
    c: Vec3,
) -> Option<(f32, [f32; 3])> {
    let r = RayPlane::new(origin, dir, a, b, c);
    if !r.det.is_finite() || r.det.abs() <= 1e-10 * r.scale {
        return None;
    }
    if !(0.0..=1.0).contains(&r.u) || r.v < 0.0 || r.u + r.v > 1.0 {
        return None;
    }
    if !(0.0..=t_max as f64).contains(&r.t) {
        return None;
    }
    Some((
        r.t as f32,
        [(1.0 - r.u - r.v) as f32, r.u as f32, r.v as f32],
    ))
}

/// Where a ray meets the plane of a triangle, in f64 (Moeller-Trumbore): the crossing is
/// `origin + t dir = a + u (b - a) + v (c - a)`. `t`, `u` and `v` are meaningless (inf or
/// NaN) when `det` is 0 or not finite.
struct RayPlane {
    /// Triple product of the edges `b - a`, `c - a` and `dir`.
    det: f64,
    /// `|b - a| |c - a| |dir|`: `det / scale` is the sine-like measure of how far the ray is
    /// from parallel to the plane.
    scale: f64,
    t: f64,
    u: f64,
    v: f64,
}

impl RayPlane {
    #[inline]
    fn new(origin: Vec3, dir: Vec3, a: Vec3, b: Vec3, c: Vec3) -> RayPlane {
        let (o, d, a) = (origin.as_dvec3(), dir.as_dvec3(), a.as_dvec3());
        let e1 = b.as_dvec3() - a;
        let e2 = c.as_dvec3() - a;
        let h = d.cross(e2);
        let det = e1.dot(h);
        let scale = e1.length() * e2.length() * d.length();
        let inv = 1.0 / det;
        let s = o - a;
        let q = s.cross(e1);
        RayPlane {
            det,
            scale,
            t: inv * e2.dot(q),
            u: inv * s.dot(h),
            v: inv * d.dot(q),
        }
    }
}

/// How the ray `origin + t dir`, `t > 0`, meets a triangle, told apart with a margin so that
/// a count of crossings along the ray can be trusted (see [`ray_crossing`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RayCrossing {
    /// Clear of the triangle (or of its plane behind the origin) by more than the margin.
    Miss,
    /// Through the triangle's interior, at least the margin from its edges, `t` (in units
    /// of `dir`) beyond the origin.
    Through(f32),
    /// Too close to call: within the margin of an edge, a vertex or the origin, or nearly
    /// parallel to the plane. [`ray_triangle`] may go either way here, and a neighbour face
    /// may too, so a crossing count along this ray is not to be trusted.
    Grazing,
}

/// [`ray_triangle`] for an unbounded ray (`t > 0`), with a margin: a barycentric weight
/// within `margin` of 0, a `t` within `margin` of 0, or a ray within about `1e-5` rad of the
/// plane (where the f32 orientation sign of a crossing is unreliable) gives
/// [`RayCrossing::Grazing`]. When the answer is [`RayCrossing::Through`] or
/// [`RayCrossing::Miss`], [`ray_triangle`] with `t_max = inf` gives the same (a hit with a
/// positive `t`, or none with a positive `t`).
#[inline]
pub fn ray_crossing(
    origin: Vec3,
    dir: Vec3,
    a: Vec3,
    b: Vec3,
    c: Vec3,
    margin: f64,
) -> RayCrossing {
    let r = RayPlane::new(origin, dir, a, b, c);
    if !r.det.is_finite() || r.det.abs() <= 1e-5 * r.scale {
        return RayCrossing::Grazing;
    }
    let w = 1.0 - r.u - r.v;
    let lowest = r.u.min(r.v).min(w);
    if lowest < -margin || r.t < -margin {
        return RayCrossing::Miss;
    }
    if lowest <= margin || r.t <= margin {
        return RayCrossing::Grazing;
    }
    RayCrossing::Through(r.t as f32)
}

/// Intersection of the segment `[p, q]` with triangle `(a, b, c)`: `Some((t, bary))` with the
/// crossing at `p + t (q - p)`, `t` in [0, 1]. See [`ray_triangle`] for the edge cases.
#[inline]
pub fn segment_triangle(p: Vec3, q: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<(f32, [f32; 3])> {
    ray_triangle(p, q - p, 1.0, a, b, c)
}

/// Signed solid angle (steradians, in [-2 pi, 2 pi]) subtended at `p` by triangle `(a, b, c)`,
/// positive when `p` sees the back of the triangle (is on the side opposite its normal) —
/// van Oosterom and Strackee (1983), in f64.
pub fn solid_angle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let (p, a, b, c) = (p.as_dvec3(), a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    let (a, b, c): (DVec3, DVec3, DVec3) = (a - p, b - p, c - p);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

/// Exact generalized winding number of `p` with respect to the triangles `faces` over
/// `vertices` (sum of solid angles / 4 pi), O(F): about 1 inside a closed outward-oriented
/// surface, 0 outside, fractional for open surfaces. Faces with out-of-range indices are
/// skipped. A reference for the accelerated inside test of [`crate::Bvh`].
pub fn winding_number(vertices: &[Vec3], faces: &[[u32; 3]], p: Vec3) -> f64 {
    let mut sum = 0.0;
    for f in faces {
        if let (Some(&a), Some(&b), Some(&c)) = (
            vertices.get(f[0] as usize),
            vertices.get(f[1] as usize),
            vertices.get(f[2] as usize),
        ) {
            sum += solid_angle(p, a, b, c);
        }
    }
    sum / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriMesh;

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let cases = [
            (Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.2, 0.2, 0.0)),
            (Vec3::new(-1.0, -1.0, 0.0), a),
            (Vec3::new(2.0, -0.1, 0.0), b),
            (Vec3::new(-0.1, 2.0, 0.0), c),
            (Vec3::new(0.5, -1.0, 0.3), Vec3::new(0.5, 0.0, 0.0)),
            (Vec3::new(-1.0, 0.5, 0.0), Vec3::new(0.0, 0.5, 0.0)),
            (Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.5, 0.5, 0.0)),
        ];
        for (p, want) in cases {
            let (q, w) = closest_point_on_triangle(p, a, b, c);
            assert!((q - want).length() < 1e-6, "{p} -> {q}, want {want}");
            let r = w[0] * a + w[1] * b + w[2] * c;
            assert!((r - q).length() < 1e-6 && (w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn a_crossing_called_through_or_miss_is_what_ray_triangle_finds() {
        let (a, b, c) = (
            Vec3::ZERO,
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(0.2, 1.0, 0.3),
        );
        let mut seen = [0usize; 3];
        let mut x = 0.37f32;
        let mut next = || {
            x = (x * 997.0 + 0.31).fract();
            x
        };
        for i in 0..20000 {
            let o = Vec3::new(next() * 2.0 - 0.5, next() * 2.0 - 0.5, next() * 2.0 - 1.0);
            // Rays at random, rays aimed at the edges and vertices, rays along the plane.
            let target = match i % 4 {
                0 => a.lerp(b, next()),
                1 => [a, b, c][i % 3],
                _ => Vec3::new(next(), next(), next() * 0.3),
            };
            let mut d = (target - o).normalize();
            if i % 50 == 0 {
                d = (b - a).normalize();
            }
            let plain = ray_triangle(o, d, f32::INFINITY, a, b, c).filter(|h| h.0 > 0.0);
            match ray_crossing(o, d, a, b, c, 1e-9) {
                RayCrossing::Through(t) => {
                    assert_eq!(plain.map(|h| h.0), Some(t), "{o} {d}");
                    seen[0] += 1;
                }
                RayCrossing::Miss => {
                    assert_eq!(plain, None, "{o} {d}");
                    seen[1] += 1;
                }
                RayCrossing::Grazing => seen[2] += 1,
            }
        }
        assert!(seen.iter().all(|&k| k > 100), "{seen:?}");
    }

    #[test]
    fn degenerate_triangles_do_not_nan() {
        let p = Vec3::new(0.3, 1.0, 0.0);
        for (a, b, c) in [
            (Vec3::ZERO, Vec3::X, 2.0 * Vec3::X),
            (Vec3::ZERO, Vec3::ZERO, Vec3::X),
            (Vec3::ONE, Vec3::ONE, Vec3::ONE),
        ] {
            let (q, w) = closest_point_on_triangle(p, a, b, c);
            assert!(q.is_finite() && w.iter().all(|x| x.is_finite()));
        }
        let (q, _) = closest_point_on_triangle(p, Vec3::ZERO, Vec3::X, 2.0 * Vec3::X);
        assert!((q - Vec3::new(0.3, 0.0, 0.0)).length() < 1e-6);
        assert!(segment_triangle(p, -p, Vec3::ZERO, Vec3::X, 2.0 * Vec3::X).is_none());
    }

    #[test]
    fn segment_crossings() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let (t, w) = segment_triangle(
            Vec3::new(0.25, 0.25, 1.0),
            Vec3::new(0.25, 0.25, -1.0),
            a,
            b,
            c,
        )
        .unwrap();
        assert!((t - 0.5).abs() < 1e-6 && (w[1] - 0.25).abs() < 1e-6);
        assert!(segment_triangle(
            Vec3::new(0.25, 0.25, 1.0),
            Vec3::new(0.25, 0.25, 0.5),
            a,
            b,
            c
        )
        .is_none());
        assert!(
            segment_triangle(Vec3::new(2.0, 2.0, 1.0), Vec3::new(2.0, 2.0, -1.0), a, b, c)
                .is_none()
        );
    }

    #[test]
    fn winding_number_of_sphere() {
        let s = TriMesh::icosphere(2, 1.0);
        assert!(
            (winding_number(&s.vertices, &s.faces, Vec3::new(0.1, 0.2, 0.3)) - 1.0).abs() < 1e-6
        );
        assert!(winding_number(&s.vertices, &s.faces, Vec3::new(1.5, 0.2, 0.3)).abs() < 1e-6);
    }
}
