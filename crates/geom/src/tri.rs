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
    let (o, d, a) = (origin.as_dvec3(), dir.as_dvec3(), a.as_dvec3());
    let e1 = b.as_dvec3() - a;
    let e2 = c.as_dvec3() - a;
    let h = d.cross(e2);
    let det = e1.dot(h);
    // det is the triple product of e1, dir, e2; relative to their lengths it measures how far
    // the ray is from parallel to the triangle's plane.
    let scale = e1.length() * e2.length() * d.length();
    if !det.is_finite() || det.abs() <= 1e-10 * scale {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = inv * s.dot(h);
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = inv * d.dot(q);
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = inv * e2.dot(q);
    if !(0.0..=t_max as f64).contains(&t) {
        return None;
    }
    Some((t as f32, [(1.0 - u - v) as f32, u as f32, v as f32]))
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
