//! Turning a body region into cloth: offset by the ease, smoothed so the cloth spans
//! the hollows of the skin (navel, spine, between muscles), and kept outside the body.

use geom::bvh::Bvh;
use geom::smooth::{SmoothOptions, Smoother};
use geom::TriMesh;
use glam::Vec3;
use rayon::prelude::*;

use crate::GarmentError;

/// Settings of [`inflate`].
#[derive(Clone, Copy, Debug)]
pub struct InflateOptions {
    /// Offset of the cloth from the skin, metres.
    pub ease: f32,
    /// Smallest gap kept between cloth and skin, metres.
    pub min_gap: f32,
    /// Rounds of plain Laplacian smoothing (each followed by the push-out): they bridge
    /// narrow hollows such as the gluteal cleft, at the cost of a little ease.
    pub bridge_rounds: u32,
    /// Rounds of Taubin smoothing (each followed by the push-out): they remove small
    /// bumps without shrinking the cloth.
    pub rounds: u32,
}

/// Bridging rounds of a cut with `bridge` 1.
pub const BRIDGE_ROUNDS: u32 = 12;

impl InflateOptions {
    /// Options for a garment of `ease` metres spanning the body's hollows by `bridge` (0 to
    /// 1, the share of [`BRIDGE_ROUNDS`]).
    pub fn new(ease: f32, bridge: f32) -> Self {
        Self {
            ease,
            min_gap: (0.4 * ease).max(0.004),
            bridge_rounds: (BRIDGE_ROUNDS as f32 * bridge.clamp(0.0, 1.0)).round() as u32,
            rounds: 40,
        }
    }
}

/// Inflates `region` (a part of the body surface `body`, same units) in place:
/// offset along the normals by the ease plus each vertex's `extra` (`[n]` metres), then
/// smoothing rounds that keep every vertex at least `min_gap` outside the body. Openings
/// are smoothed along themselves only.
pub fn inflate(
    region: &mut TriMesh,
    extra: &[f32],
    body: &Bvh,
    opts: &InflateOptions,
) -> Result<(), GarmentError> {
    if extra.len() != region.vertices.len() {
        return Err(GarmentError::Parameter(format!(
            "{} extra offsets for {} region vertices",
            extra.len(),
            region.vertices.len()
        )));
    }
    let normals = geom::normals::vertex_normals(&region.vertices, &region.faces);
    for ((p, nrm), e) in region.vertices.iter_mut().zip(&normals).zip(extra) {
        *p += *nrm * (opts.ease + e);
    }
    let smoother = Smoother::new(region.vertices.len(), &region.faces)?;
    let phases = [
        (SmoothOptions::laplacian(1, 0.5), opts.bridge_rounds),
        (SmoothOptions::taubin(1), opts.rounds),
    ];
    for (step, rounds) in phases {
        for _ in 0..rounds {
            smoother.smooth(&mut region.vertices, &step, None)?;
            push_out(&mut region.vertices, body, opts.min_gap);
        }
    }
    Ok(())
}

/// Moves every point that is inside the body or closer than `min_gap` to it out along
/// the normal of its closest body face to exactly `min_gap`. Returns how many moved.
pub fn push_out(points: &mut [Vec3], body: &Bvh, min_gap: f32) -> usize {
    let faces = body.faces();
    let verts = body.vertices();
    let search = min_gap + 0.05;
    points
        .par_iter_mut()
        .map(|p| {
            let Some(hit) = body.closest_point_within(*p, search) else {
                return 0;
            };
            let f = faces[hit.face as usize];
            let [a, b, c] = f.map(|i| verts[i as usize]);
            let normal = (b - a).cross(c - a).normalize_or_zero();
            let gap = (*p - hit.point).dot(normal);
            if gap < min_gap {
                *p = hit.point + normal * min_gap;
                1
            } else {
                0
            }
        })
        .sum()
}
