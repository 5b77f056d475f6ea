//! Procedural test scenes: surfaces of revolution about the Y axis (a closed capsule body and
//! an open "tube shirt" hanging on it), and a flat cloth over a sphere. Used by the tests
//! and the timing test of this crate;
//! handy for benchmarks that must not depend on body or garment assets.

use std::f32::consts::{FRAC_PI_2, TAU};

use geom::TriMesh;
use glam::Vec3;

/// The "cloth dropped on a sphere" scene: `(cloth, sphere)`, a sphere of `radius` metres
/// at the origin (icosphere, 3 subdivisions) and a flat 25 x 25 vertex cloth of 2.5 cm
/// squares, level, centred over it, `gap` metres above its top.
pub fn cloth_over_sphere(radius: f32, gap: f32) -> (TriMesh, TriMesh) {
    let mut cloth = TriMesh::grid(25, 25, 0.025);
    for v in &mut cloth.vertices {
        v.y = radius + gap;
    }
    (cloth, TriMesh::icosphere(3, radius))
}

/// Revolves a profile about the Y axis through `center`.
///
/// - `profile`: `[P]` points `(r, y)` (metres, `r >= 0`), from bottom to top; a point with
///   `r == 0` at either end becomes a single pole vertex (closing the surface there), any
///   other end stays an open boundary loop.
/// - `segments`: points per ring (at least 3).
///
/// Faces are oriented with normals pointing away from the axis when the profile runs upward
/// (outward for a closed surface). Returns an empty mesh for fewer than 2 profile points or
/// fewer than 3 segments.
pub fn revolve(profile: &[(f32, f32)], segments: usize, center: Vec3) -> TriMesh {
    if profile.len() < 2 || segments < 3 {
        return TriMesh::default();
    }
    let mut vertices = Vec::new();
    // Index of the first vertex of each ring and whether it is a pole.
    let mut ring: Vec<(u32, bool)> = Vec::with_capacity(profile.len());
    for (k, &(r, y)) in profile.iter().enumerate() {
        let pole = r <= 0.0 && (k == 0 || k + 1 == profile.len());
        ring.push((vertices.len() as u32, pole));
        if pole {
            vertices.push(center + Vec3::new(0.0, y, 0.0));
        } else {
            for s in 0..segments {
                let phi = TAU * s as f32 / segments as f32;
                vertices.push(center + Vec3::new(r * phi.cos(), y, -r * phi.sin()));
            }
        }
    }
    let id = |k: usize, s: usize| -> u32 {
        let (start, pole) = ring[k];
        if pole {
            start
        } else {
            start + (s % segments) as u32
        }
    };
    let mut faces = Vec::new();
    for k in 0..profile.len() - 1 {
        for s in 0..segments {
            let (a, b) = (id(k, s), id(k, s + 1));
            let (c, d) = (id(k + 1, s + 1), id(k + 1, s));
            if a != b {
                faces.push([a, b, c]);
            }
            if c != d {
                faces.push([a, c, d]);
            }
        }
    }
    TriMesh { vertices, faces }
}

/// A closed, outward-oriented capsule with its axis along Y through `center`: a cylinder of
/// `radius` and length `2 * half_length` capped by two hemispheres (metres), meshed with edges
/// of about `edge` metres.
pub fn capsule(radius: f32, half_length: f32, center: Vec3, edge: f32) -> TriMesh {
    let edge = edge.max(1e-4);
    let segments = ((TAU * radius / edge).round() as usize).max(6);
    let cap_rings = ((FRAC_PI_2 * radius / edge).round() as usize).max(2);
    let body_rings = ((2.0 * half_length / edge).round() as usize).max(1);
    let mut profile = Vec::new();
    for i in 0..=cap_rings {
        let t = -FRAC_PI_2 + FRAC_PI_2 * i as f32 / cap_rings as f32;
        profile.push((radius * t.cos(), -half_length + radius * t.sin()));
    }
    for i in 1..body_rings {
        let y = -half_length + 2.0 * half_length * i as f32 / body_rings as f32;
        profile.push((radius, y));
    }
    for i in 0..=cap_rings {
        let t = FRAC_PI_2 * i as f32 / cap_rings as f32;
        profile.push((radius * t.cos(), half_length + radius * t.sin()));
    }
    profile[0].0 = 0.0;
    let last = profile.len() - 1;
    profile[last].0 = 0.0;
    revolve(&profile, segments, center)
}

/// An open "tube shirt": a cylinder of `radius` hanging `length` metres down from the equator
/// of a spherical dome (same radius, centred at `dome_center`) that closes over the top up to
/// a neck hole of radius `neck_radius`; meshed with edges of about `edge` metres (the
/// circumference is cut into equal segments, so ring spacing shrinks toward the neck). Two
/// boundary loops: neck and hem. With radius 0.17, length 0.65, neck 0.07 and edge 0.01 it
/// has about 9.2k vertices.
pub fn tube_shirt(
    radius: f32,
    length: f32,
    neck_radius: f32,
    dome_center: Vec3,
    edge: f32,
) -> TriMesh {
    let edge = edge.max(1e-4);
    let neck = neck_radius.clamp(0.05 * radius, 0.95 * radius);
    let segments = ((TAU * radius / edge).round() as usize).max(6);
    let body_rings = ((length / edge).round() as usize).max(1);
    let theta_neck = (neck / radius).acos();
    let dome_rings = ((radius * theta_neck / edge).round() as usize).max(1);
    let mut profile = Vec::new();
    for i in 0..body_rings {
        profile.push((radius, -length + length * i as f32 / body_rings as f32));
    }
    for i in 0..=dome_rings {
        let t = theta_neck * i as f32 / dome_rings as f32;
        profile.push((radius * t.cos(), radius * t.sin()));
    }
    revolve(&profile, segments, dome_center)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(m: &TriMesh, axis_point: Vec3) -> bool {
        m.faces.iter().all(|f| {
            let [a, b, c] = f.map(|i| m.vertices[i as usize]);
            let mid = (a + b + c) / 3.0 - axis_point;
            (b - a).cross(c - a).dot(mid) > 0.0
        })
    }

    #[test]
    fn capsule_is_closed_and_outward() {
        let c = Vec3::new(0.0, 1.0, 0.0);
        let m = capsule(0.15, 0.3, c, 0.03);
        m.validate().unwrap();
        let report = geom::adjacency::check_manifold(m.vertices.len(), &m.faces).unwrap();
        assert!(report.is_ok() && report.is_closed(), "{report}");
        assert_eq!(
            geom::adjacency::euler_characteristic(m.vertices.len(), &m.faces),
            2
        );
        assert!(outward(&m, c));
        let bvh = geom::Bvh::from_mesh(&m).unwrap();
        assert!(bvh.contains(c));
        assert!(!bvh.contains(c + Vec3::new(0.2, 0.0, 0.0)));
    }

    #[test]
    fn tube_shirt_has_two_loops() {
        let m = tube_shirt(0.17, 0.65, 0.07, Vec3::ZERO, 0.01);
        m.validate().unwrap();
        assert!(
            (8_500..10_500).contains(&m.vertices.len()),
            "{}",
            m.vertices.len()
        );
        let loops = geom::adjacency::boundary_loops(m.vertices.len(), &m.faces).unwrap();
        assert_eq!(loops.len(), 2);
        let report = geom::adjacency::check_manifold(m.vertices.len(), &m.faces).unwrap();
        assert!(report.is_ok(), "{report}");
    }
}
