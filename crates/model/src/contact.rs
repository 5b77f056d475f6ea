//! Body-contact features of the warped garment M: where the body surface is, seen from each
//! garment vertex (an input of networks with [`crate::GarNetConfig::body_contact`]).
//!
//! The paper's network must infer from point features how far each vertex of M is from the
//! skin, and on which side (a fifth of M's vertices start inside the body); the local pooling
//! looks at body points about 7 cm apart. These features give it directly: for vertex `m` with
//! nearest body vertex `b` (outward unit normal `n`), the offset `b - m`, the normal `n` and the
//! signed distance `(m - b) . n` (positive outside), lengths in [`CONTACT_UNIT`]s clamped to
//! [`CONTACT_CLAMP`] (contact beyond 10 cm does not matter). With
//! [`crate::GarNetConfig::contact_surface`], `b` is the closest point of the body's surface
//! instead and `n` the vertex normals interpolated there, so the features change smoothly as
//! the vertex moves instead of jumping from one body vertex to the next.

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

/// The features `[N * CONTACT_WIDTH]` of `warped` M `[N]` measured to the closest point of the
/// body surface that `bvh` holds, with its unit vertex normals `normals` `[V]` interpolated
/// there; one frame, metres. Fails on mismatched counts.
pub fn surface_contact_features(
    bvh: &geom::Bvh,
    normals: &[Vec3],
    warped: &[Vec3],
) -> Result<Vec<f32>> {
    check_count("body normals", bvh.vertices().len(), normals.len())?;
    let faces = bvh.faces();
    let mut out = Vec::with_capacity(warped.len() * CONTACT_WIDTH);
    for m in warped {
        let hit = bvh.closest_point(*m).ok_or_else(|| {
            crate::error::ModelError::InvalidInput(format!(
                "no closest body point to garment vertex {m} (an empty body or a non-finite \
                 vertex)"
            ))
        })?;
        let f = faces[hit.face as usize];
        let n = (0..3).fold(Vec3::ZERO, |n, k| n + normals[f[k] as usize] * hit.bary[k]);
        out.extend(vertex_features(*m, hit.point, n.normalize_or_zero()));
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

    /// Against the brute-force closest point with the normal interpolated there; moving a
    /// vertex a little moves its features a little, where the nearest vertex jumps.
    #[test]
    fn surface_features_match_the_closest_point_and_change_smoothly() {
        let sphere = geom::TriMesh::icosphere(2, 0.3);
        let normals = geom::normals::vertex_normals(&sphere.vertices, &sphere.faces);
        let bvh = geom::Bvh::from_mesh(&sphere).unwrap();
        let queries: Vec<Vec3> = (0..40)
            .map(|i| {
                let t = i as f32 * 0.41;
                Vec3::new(t.sin(), (2.0 * t).cos(), t.cos()).normalize() * (0.26 + 0.002 * i as f32)
            })
            .collect();
        let got = surface_contact_features(&bvh, &normals, &queries).unwrap();
        for (q, m) in queries.iter().enumerate() {
            let hit = geom::bvh::closest_point_brute(&sphere.vertices, &sphere.faces, *m).unwrap();
            let f = sphere.faces[hit.face as usize];
            let n = (0..3)
                .fold(Vec3::ZERO, |n, k| n + normals[f[k] as usize] * hit.bary[k])
                .normalize();
            let want = vertex_features(*m, hit.point, n);
            let row = &got[q * CONTACT_WIDTH..(q + 1) * CONTACT_WIDTH];
            let worst = row
                .iter()
                .zip(&want)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f32::max);
            assert!(worst < 1e-4, "query {q}: {row:?} against {want:?}");
        }
        // A vertex 1 cm outside, moved 1 mm at a time along the surface for 12 cm.
        let path: Vec<Vec3> = (0..120)
            .map(|i| {
                let a = 0.2 + 0.001 * i as f32 / 0.31;
                Vec3::new(a.sin(), a.cos(), 0.1).normalize() * 0.31
            })
            .collect();
        let index = geom::KnnIndex::new(&sphere.vertices).unwrap();
        let steps = |f: &[f32]| {
            f.chunks(CONTACT_WIDTH)
                .collect::<Vec<_>>()
                .windows(2)
                .map(|w| {
                    (0..3)
                        .map(|k| (w[1][k] - w[0][k]).abs())
                        .fold(0.0, f32::max)
                })
                .fold(0.0, f32::max)
        };
        let surface = surface_contact_features(&bvh, &normals, &path).unwrap();
        let nearest = contact_features(&index, &sphere.vertices, &normals, &path).unwrap();
        // In cm: 1 mm steps move the surface offsets by at most about 0.1 cm each; the
        // nearest vertex jumps by about an edge (about 5 cm on this sphere).
        assert!(steps(&surface) < 0.2, "{}", steps(&surface));
        assert!(steps(&nearest) > 1.0, "{}", steps(&nearest));
        assert!(surface_contact_features(&bvh, &normals[1..], &path).is_err());
    }
}
