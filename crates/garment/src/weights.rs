//! Skinning weights of a garment, transferred from the body it was fitted on.

use body::{ShapedBody, SkinWeights};
use geom::bvh::Bvh;
use geom::TriMesh;
use rayon::prelude::*;

use crate::GarmentError;

/// Influences kept per garment vertex (the body's weights have at most 8).
pub const MAX_INFLUENCES: usize = 8;

/// Dense weights `[B]` of a body vertex.
fn dense_row(weights: &SkinWeights, v: usize, bones: usize) -> Vec<f32> {
    let mut row = vec![0.0; bones];
    for (b, w) in weights.row(v) {
        row[b] += w;
    }
    row
}

/// Sparse rows from dense per-vertex weights: the largest [`MAX_INFLUENCES`], normalised.
fn sparsify(dense: &[Vec<f32>]) -> Result<SkinWeights, GarmentError> {
    let rows: Vec<Vec<(u16, f32)>> = dense
        .iter()
        .map(|d| {
            let mut row: Vec<(u16, f32)> = d
                .iter()
                .enumerate()
                .filter(|(_, w)| **w > 1e-4)
                .map(|(b, w)| (b as u16, *w))
                .collect();
            row.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            row.truncate(MAX_INFLUENCES);
            row
        })
        .collect();
    SkinWeights::from_rows(&rows).map_err(|v| {
        GarmentError::rejected(
            "skinning weights",
            format!("garment vertex {v} has no weight"),
        )
    })
}

/// Weights of points given by barycentric coordinates `bary` `[M]` on faces `face` `[M]`
/// of a mesh (`source_faces`) whose vertex `i` carries the body vertex
/// `source_vertex[i]`'s weights: the exact transfer for a garment built from a body
/// region.
pub fn weights_from_correspondence(
    body: &ShapedBody,
    source_faces: &[[u32; 3]],
    source_vertex: &[u32],
    face: &[u32],
    bary: &[[f32; 3]],
) -> Result<SkinWeights, GarmentError> {
    let bones = body.rig.len();
    let dense: Vec<Vec<f32>> = face
        .par_iter()
        .zip(bary)
        .map(|(&f, bary)| {
            let mut row = vec![0.0; bones];
            for (k, &corner) in source_faces[f as usize].iter().enumerate() {
                let v = source_vertex[corner as usize] as usize;
                for (b, w) in body.weights.row(v) {
                    row[b] += bary[k] * w;
                }
            }
            row
        })
        .collect();
    sparsify(&dense)
}

/// Weights of any garment mesh fitted on `body` (rest pose): each vertex takes the
/// weights of its closest body point (interpolated over the body face), then
/// `smoothing` rounds of averaging over the garment's 1-ring remove the seams this
/// leaves where the closest point jumps between body parts.
pub fn transfer_weights(
    garment: &TriMesh,
    body: &ShapedBody,
    body_bvh: &Bvh,
    smoothing: usize,
) -> Result<SkinWeights, GarmentError> {
    let bones = body.rig.len();
    let mut dense: Vec<Vec<f32>> = garment
        .vertices
        .par_iter()
        .map(|&p| {
            let hit = body_bvh.closest_point(p).expect("non-empty body");
            let f = body.mesh.faces[hit.face as usize];
            let mut row = vec![0.0; bones];
            for (k, &v) in f.iter().enumerate() {
                for (b, w) in dense_row(&body.weights, v as usize, bones)
                    .iter()
                    .enumerate()
                {
                    row[b] += hit.bary[k] * w;
                }
            }
            row
        })
        .collect();
    let ring = geom::adjacency::one_ring(garment.vertices.len(), &garment.faces)?;
    for _ in 0..smoothing {
        dense = (0..dense.len())
            .into_par_iter()
            .map(|i| {
                let nb = ring.row(i);
                let mut row = dense[i].clone();
                for &j in nb {
                    for (r, w) in row.iter_mut().zip(&dense[j as usize]) {
                        *r += w;
                    }
                }
                row.iter_mut().for_each(|r| *r /= (nb.len() + 1) as f32);
                row
            })
            .collect();
    }
    sparsify(&dense)
}
