//! GarNet's training loss (paper section 3.3):
//!
//! ```text
//! L = w_vertex L_vertex + w_pen L_pen + w_norm L_norm + w_bend L_bend   (1, 1.0, 0.3, 0.5)
//! ```
//!
//! - `L_vertex = 1/N sum_i |G^G_i - G^P_i|^2` (square metres);
//! - `L_pen = 1/N sum_j 1{|G^P_j - G^G_j| < d_tol} ReLU(-n_i . (G^P_j - (B_i + 0.2 e n_i)))`
//!   (metres), with i the body vertex nearest to G^P_j (found on the CPU at every step),
//!   n_i its unit normal, e the body's mean edge length and d_tol = 0.05 m;
//! - `L_norm = 1/F sum_f (1 - F^G_f . F^P_f)^2` over unit face normals (no unit);
//! - `L_bend = 1/|N2| sum_{i,k} | |G^P_i - G^P_k| - |G^G_i - G^G_k| |` over vertex pairs two
//!   edges apart (metres).
//!
//! Every term is averaged over the batch too. Each weight can be set to 0 for ablations; the
//! terms are computed and reported either way.

use burn::prelude::*;
use burn::tensor::activation::relu;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::batch::Batch;
use crate::error::{ModelError, Result};
use crate::tensors::{index_tensor, read_f32, read_points, vec_tensor};
use crate::topology::TopologyTensors;

/// Added to squared lengths before a square root (square metres), so that the gradient of a
/// length stays finite at 0; changes a 1 cm length by 5e-11 m.
const SQRT_EPS: f64 = 1e-12;

/// Weights and constants of the loss.
#[derive(Config, Debug, PartialEq)]
pub struct LossConfig {
    /// Weight of L_vertex (1 in the paper).
    #[config(default = 1.0)]
    pub vertex: f64,
    /// Weight of L_pen, lambda_pen (1.0).
    #[config(default = 1.0)]
    pub pen: f64,
    /// Weight of L_norm, lambda_norm (0.3).
    #[config(default = 0.3)]
    pub norm: f64,
    /// Weight of L_bend, lambda_bend (0.5).
    #[config(default = 0.5)]
    pub bend: f64,
    /// d_tol: L_pen only counts vertices closer than this to their target (metres, 0.05).
    #[config(default = 0.05)]
    pub d_tol: f64,
    /// The matched body point is pushed out along its normal by this fraction of the body's
    /// mean edge length (0.2).
    #[config(default = 0.2)]
    pub pen_push: f64,
}

/// Loss values of one step or averaged over many (f32; the units of each term).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LossTerms {
    /// Weighted sum.
    pub total: f32,
    /// L_vertex, square metres.
    pub vertex: f32,
    /// L_pen, metres.
    pub pen: f32,
    /// L_norm, no unit.
    pub norm: f32,
    /// L_bend, metres.
    pub bend: f32,
}

impl LossTerms {
    /// `self * w` term by term (for running means).
    pub fn scaled(self, w: f32) -> LossTerms {
        LossTerms {
            total: self.total * w,
            vertex: self.vertex * w,
            pen: self.pen * w,
            norm: self.norm * w,
            bend: self.bend * w,
        }
    }

    /// Term-by-term sum.
    pub fn add(self, o: LossTerms) -> LossTerms {
        LossTerms {
            total: self.total + o.total,
            vertex: self.vertex + o.vertex,
            pen: self.pen + o.pen,
            norm: self.norm + o.norm,
            bend: self.bend + o.bend,
        }
    }
}

/// The loss as tensors: `total` carries the graph for `backward`.
#[derive(Clone, Debug)]
pub struct LossTensors {
    /// Weighted sum `[1]`.
    pub total: Tensor<1>,
    /// L_vertex `[1]`.
    pub vertex: Tensor<1>,
    /// L_pen `[1]`.
    pub pen: Tensor<1>,
    /// L_norm `[1]`.
    pub norm: Tensor<1>,
    /// L_bend `[1]`.
    pub bend: Tensor<1>,
}

impl LossTensors {
    /// Reads the five values back (one transfer).
    pub fn values(&self) -> Result<LossTerms> {
        let all = Tensor::cat(
            vec![
                self.total.clone().detach(),
                self.vertex.clone().detach(),
                self.pen.clone().detach(),
                self.norm.clone().detach(),
                self.bend.clone().detach(),
            ],
            0,
        );
        let v = read_f32(all)?;
        Ok(LossTerms {
            total: v[0],
            vertex: v[1],
            pen: v[2],
            norm: v[3],
            bend: v[4],
        })
    }
}

/// L_vertex: mean over the B*N vertices of the squared distance. `pred`, `target` `[B,N,3]`.
pub fn vertex_loss(pred: Tensor<3>, target: Tensor<3>) -> Tensor<1> {
    (pred - target).square().sum_dim(2).mean()
}

/// Unit face normals `[B,F,3]` of `vertices` `[B,N,3]` with the faces' corner index tensors
/// (`[F]` each).
pub fn face_normals(vertices: Tensor<3>, faces: &[Tensor<1, Int>; 3]) -> Tensor<3> {
    let v0 = vertices.clone().select(1, faces[0].clone());
    let v1 = vertices.clone().select(1, faces[1].clone());
    let v2 = vertices.select(1, faces[2].clone());
    let n = (v1 - v0.clone()).cross(v2 - v0, 2);
    let len = (n.clone().square().sum_dim(2) + SQRT_EPS).sqrt();
    n / len
}

/// L_norm: mean over the B*F faces of `(1 - F^G . F^P)^2`. `pred`, `target` `[B,N,3]`.
pub fn normal_loss(pred: Tensor<3>, target: Tensor<3>, faces: &[Tensor<1, Int>; 3]) -> Tensor<1> {
    let fp = face_normals(pred, faces);
    let fg = face_normals(target, faces).detach();
    ((fp * fg).sum_dim(2).neg() + 1.0).square().mean()
}

/// Lengths `[B,P,1]` between the vertices of each pair (metres).
fn pair_lengths(v: Tensor<3>, pairs: &[Tensor<1, Int>; 2]) -> Tensor<3> {
    let a = v.clone().select(1, pairs[0].clone());
    let b = v.select(1, pairs[1].clone());
    ((a - b).square().sum_dim(2) + SQRT_EPS).sqrt()
}

/// L_bend: mean over the B*P two-ring pairs of the absolute change of their distance.
/// `pred`, `target` `[B,N,3]`, `pairs` two `[P]` index tensors.
pub fn bending_loss(pred: Tensor<3>, target: Tensor<3>, pairs: &[Tensor<1, Int>; 2]) -> Tensor<1> {
    let lp = pair_lengths(pred, pairs);
    let lg = pair_lengths(target, pairs).detach();
    (lp - lg).abs().mean()
}

/// The CPU part of L_pen for a batch: for every predicted vertex `pred[b][j]`, the index of
/// the nearest body vertex as a row of the batch-flattened body table (`b*V + i`, `[B*N]`),
/// and whether the vertex is within `d_tol` (metres) of its target (`[B*N]`, 1 or 0).
pub fn penetration_matches(
    pred: &[Vec<Vec3>],
    targets: &[Vec<Vec3>],
    body_index: &[std::sync::Arc<geom::KnnIndex>],
    d_tol: f32,
) -> Result<(Vec<i64>, Vec<f32>)> {
    if pred.len() != targets.len() || pred.len() != body_index.len() {
        return Err(ModelError::InvalidInput(
            "penetration matches need one target and one body per prediction".into(),
        ));
    }
    let mut nearest = Vec::new();
    let mut close = Vec::new();
    for (b, ((p, t), index)) in pred.iter().zip(targets).zip(body_index).enumerate() {
        let offset = (b * index.len()) as i64;
        let found = index.query(p, 1)?;
        nearest.extend(found.indices.iter().map(|&i| offset + i as i64));
        close.extend(
            p.iter()
                .zip(t)
                .map(|(a, g)| if a.distance(*g) < d_tol { 1.0 } else { 0.0 }),
        );
    }
    Ok((nearest, close))
}

/// L_pen from precomputed matches: `pred` `[B,N,3]`, `body` and `body_normals` `[B,V,3]`,
/// `body_edge` `[B]` (metres), `nearest` `[B*N]` rows of the flattened body, `close`
/// `[B,N,1]` (1 where the vertex is within d_tol of its target), `push` the fraction of the
/// edge length the body point is moved out by.
pub fn penetration_loss(
    pred: Tensor<3>,
    body: Tensor<3>,
    body_normals: Tensor<3>,
    body_edge: Tensor<1>,
    nearest: Tensor<1, Int>,
    close: Tensor<3>,
    push: f64,
) -> Tensor<1> {
    let [b, n, _] = pred.dims();
    let v = body.dims()[1];
    let normals = body_normals
        .reshape([b * v, 3])
        .select(0, nearest.clone())
        .reshape([b, n, 3]);
    let points = body
        .reshape([b * v, 3])
        .select(0, nearest)
        .reshape([b, n, 3]);
    let offset = body_edge.reshape([b, 1, 1]) * push;
    let pushed = points + normals.clone() * offset;
    let side = (normals * (pred - pushed)).sum_dim(2); // [B,N,1]
    (relu(side.neg()) * close).mean()
}

/// The full loss of predictions `pred` `[B,N,3]` for `batch` (which must have targets).
pub fn garnet_loss(
    pred: Tensor<3>,
    batch: &Batch,
    topo: &TopologyTensors,
    cfg: &LossConfig,
) -> Result<LossTensors> {
    let target = batch
        .target
        .clone()
        .ok_or_else(|| ModelError::InvalidInput("the loss needs a batch with targets".into()))?;
    let targets = batch
        .target_points
        .as_ref()
        .ok_or_else(|| ModelError::InvalidInput("the loss needs a batch with targets".into()))?;
    let device = pred.device();
    let [b, n, _] = pred.dims();
    let pred_points = read_points(pred.clone().detach())?;
    let (nearest, close) =
        penetration_matches(&pred_points, targets, &batch.body_index, cfg.d_tol as f32)?;
    let vertex = vertex_loss(pred.clone(), target.clone());
    let pen = penetration_loss(
        pred.clone(),
        batch.body.clone(),
        batch.body_normals.clone(),
        batch.body_edge.clone(),
        index_tensor(nearest, &device),
        vec_tensor(close, [b, n, 1], &device),
        cfg.pen_push,
    );
    let norm = normal_loss(pred.clone(), target.clone(), &topo.faces);
    let bend = bending_loss(pred, target, &topo.bend_pairs);
    let weighted = [
        (cfg.vertex, &vertex),
        (cfg.pen, &pen),
        (cfg.norm, &norm),
        (cfg.bend, &bend),
    ];
    let mut total: Option<Tensor<1>> = None;
    for (w, term) in weighted {
        if w != 0.0 {
            let t = term.clone() * w;
            total = Some(match total {
                Some(acc) => acc + t,
                None => t,
            });
        }
    }
    let total = total.unwrap_or_else(|| Tensor::zeros([1], &device));
    Ok(LossTensors {
        total,
        vertex,
        pen,
        norm,
        bend,
    })
}
