//! Turning a body region into cloth: offset by the ease, smoothed so the cloth spans
//! the hollows of the skin (navel, spine, between muscles), and kept outside the body.

use geom::adjacency::{boundary_loops, one_ring};
use geom::bvh::Bvh;
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
    /// Smoothing rounds (each a Taubin pair of steps followed by the push-out).
    pub rounds: usize,
}

impl InflateOptions {
    /// Options for a garment of the given ease (metres).
    pub fn for_ease(ease: f32) -> Self {
        Self { ease, min_gap: (0.4 * ease).max(0.004), rounds: 40 }
    }
}

/// Inflates `region` (a part of the body surface `body`, same units) in place.
pub fn inflate(region: &mut TriMesh, body: &Bvh, opts: &InflateOptions) -> Result<(), GarmentError> {
    let n = region.vertices.len();
    let normals = geom::normals::vertex_normals(&region.vertices, &region.faces);
    for (p, nrm) in region.vertices.iter_mut().zip(&normals) {
        *p += *nrm * opts.ease;
    }
    let ring = one_ring(n, &region.faces)?;
    // Boundary vertices smooth along their loop only, so openings keep their place.
    let mut neighbours: Vec<Vec<u32>> = (0..n).map(|i| ring.row(i).to_vec()).collect();
    for l in boundary_loops(n, &region.faces)? {
        for k in 0..l.len() {
            let prev = l[(k + l.len() - 1) % l.len()];
            let next = l[(k + 1) % l.len()];
            neighbours[l[k] as usize] = vec![prev, next];
        }
    }
    for _ in 0..opts.rounds {
        laplacian_step(&mut region.vertices, &neighbours, 0.5);
        laplacian_step(&mut region.vertices, &neighbours, -0.53);
        push_out(&mut region.vertices, body, opts.min_gap);
    }
    Ok(())
}

/// One uniform Laplacian step `p += factor * (mean of neighbours - p)`.
fn laplacian_step(p: &mut [Vec3], neighbours: &[Vec<u32>], factor: f32) {
    let moved: Vec<Vec3> = (0..p.len())
        .into_par_iter()
        .map(|i| {
            let nb = &neighbours[i];
            if nb.is_empty() {
                return p[i];
            }
            let mean = nb.iter().map(|&j| p[j as usize]).sum::<Vec3>() / nb.len() as f32;
            p[i] + factor * (mean - p[i])
        })
        .collect();
    p.copy_from_slice(&moved);
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
            let Some(hit) = body.closest_point_within(*p, search) else { return 0 };
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
