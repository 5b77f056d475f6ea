//! Body-contact features of the warped garment M: where the body surface is, seen from each
//! garment vertex (an input of networks with [`crate::GarNetConfig::body_contact`]).
//!
//! The paper's network must infer from point features how far each vertex of M is from the
//! skin, and on which side (a fifth of M's vertices start inside the body); the local pooling
//! looks at body points about 7 cm apart. These features give it directly: for vertex `m` with
//! nearest body vertex `b` (outward unit normal `n`), the offset `b - m`, the normal `n` and the
//! signed distance `(m - b) . n` (positive outside), lengths in [`CONTACT_UNIT`]s clamped to
//! [`CONTACT_CLAMP`] (contact beyond 10 cm does not matter).

use glam::Vec3;

use crate::error::{check_count, Result};

/// Features per garment vertex: offset (3), normal (3), signed distance (1).
pub const CONTACT_WIDTH: usize = 7;

/// Length unit of the offsets and signed distances, metres.
pub const CONTACT_UNIT: f32 = 0.01;

/// Largest magnitude of a length feature, in [`CONTACT_UNIT`]s.
pub const CONTACT_CLAMP: f32 = 10.0;

/// The features `[N * CONTACT_WIDTH]` (row-major) of `warped` M `[N]`, for a body `[V]` with
/// unit vertex normals `normals` `[V]` and `index` over its vertices; all in one frame,
/// metres. Fails on mismatched counts.
pub fn contact_features(
    index: &geom::KnnIndex,
    body: &[Vec3],
    normals: &[Vec3],
    warped: &[Vec3],
) -> Result<Vec<f32>> {
    check_count("body normals", body.len(), normals.len())?;
    check_count("indexed body vertices", body.len(), index.len())?;
    let nearest = index.query(warped, 1)?.indices;
    let mut out = Vec::with_capacity(warped.len() * CONTACT_WIDTH);
    for (m, &j) in warped.iter().zip(&nearest) {
        out.extend(vertex_features(*m, body[j as usize], normals[j as usize]));
    }
    Ok(out)
}

/// The features of garment vertex `m` with nearest body vertex `b` of normal `n` (metres).
fn vertex_features(m: Vec3, b: Vec3, n: Vec3) -> [f32; CONTACT_WIDTH] {
    let unit = |x: f32| (x / CONTACT_UNIT).clamp(-CONTACT_CLAMP, CONTACT_CLAMP);
    let o = b - m;
    [
        unit(o.x),
        unit(o.y),
        unit(o.z),
        n.x,
        n.y,
        n.z,
        unit((m - b).dot(n)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::ellipsoid_body;

    /// Against a brute-force nearest vertex, and by hand on points outside and inside.
    #[test]
    fn features_match_a_brute_force_search_and_signs() {
        let (body, normals) = ellipsoid_body(400);
        let index = geom::KnnIndex::new(&body).unwrap();
        let queries: Vec<Vec3> = (0..50)
            .map(|i| {
                let t = i as f32 * 0.37;
                Vec3::new(t.sin() * 0.25, 1.0 + t.cos() * 0.4, (2.0 * t).sin() * 0.2)
            })
            .collect();
        let got = contact_features(&index, &body, &normals, &queries).unwrap();
        assert_eq!(got.len(), 50 * CONTACT_WIDTH);
        for (q, m) in queries.iter().enumerate() {
            let j = (0..body.len())
                .min_by(|&a, &b| body[a].distance(*m).total_cmp(&body[b].distance(*m)))
                .unwrap();
            let want = vertex_features(*m, body[j], normals[j]);
            assert_eq!(&got[q * CONTACT_WIDTH..(q + 1) * CONTACT_WIDTH], &want[..]);
        }
        // By hand: 3 cm outside along the normal, then 2 cm inside; far away clamps.
        let (b, n) = (Vec3::new(0.0, 1.0, 0.1), Vec3::Z);
        let out = vertex_features(b + n * 0.03, b, n);
        assert!(
            (out[2] + 3.0).abs() < 1e-4 && (out[6] - 3.0).abs() < 1e-4,
            "{out:?}"
        );
        assert_eq!(&out[3..6], &[0.0, 0.0, 1.0]);
        let inside = vertex_features(b - n * 0.02, b, n);
        assert!((inside[6] + 2.0).abs() < 1e-4);
        let far = vertex_features(b + n * 0.5, b, n);
        assert_eq!((far[2], far[6]), (-CONTACT_CLAMP, CONTACT_CLAMP));
        assert!(contact_features(&index, &body, &normals[1..], &queries).is_err());
    }
}
