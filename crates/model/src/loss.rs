//! GarNet's training loss (paper section 3.3):
//!
//! ```text
//! L = w_vertex L_vertex + w_pen L_pen + w_norm L_norm + w_bend L_bend   (1, 1.0, 0.3, 0.5)
//! ```
//!
//! - `L_vertex = 1/N sum_i |G^G_i - G^P_i|^2` (square centimetres: every length of the loss
//!   is in centimetres, [`LOSS_UNITS_PER_METRE`]); with [`VertexLoss::Distance`]
//!   `1/N sum_i |G^G_i - G^P_i|`, the mean distance that E_dist reports (centimetres);
//! - `L_pen = 1/N sum_j 1{|G^P_j - G^G_j| < d_tol} ReLU(-n_i . (G^P_j - (B_i + 0.2 e n_i)))`
//!   (centimetres), with i the body vertex nearest to G^P_j (found on the CPU at every step),
//!   n_i its unit normal, e the body's mean edge length and d_tol = 0.05 m (5 cm);
//! - `L_norm = 1/F sum_f (1 - F^G_f . F^P_f)^2` over unit face normals (no unit), the
//!   paper's; or with [`NormalLoss::Tilt`] `1/F sum_f s_f |F^G_f - F^P_f|` (centimetres),
//!   where `s_f = sqrt(2 area)` of the label's face: how far a face's corners move when it
//!   tilts (a tilt of angle t moves them about `s_f t`), a length like the other terms';
//! - `L_bend = 1/|N2| sum_{i,k} | |G^P_i - G^P_k| - |G^G_i - G^G_k| |` over vertex pairs two
//!   edges apart (centimetres);
//! - `L_curv`, GarNet++'s curvature term, off by default (weight 0): how each vertex's
//!   neighbourhood spreads along the label's principal axes, prediction against label
//!   (centimetres; [`crate::curvature_loss`]).
//!
//! Every term is averaged over the batch too. Each weight can be set to 0 for ablations; the
//! first four terms are computed and reported either way, L_curv (which costs a 3x3
//! eigendecomposition per label vertex on the CPU) only when it is weighted, else reported
//! as 0.

use burn::prelude::*;
use burn::tensor::activation::relu;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::batch::Batch;
use crate::curvature_loss::curvature_loss;
use crate::error::{ModelError, Result};
use crate::tensors::{gather_rows, index_tensor, read_f32, read_points, vec_tensor};
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
    /// Weight of L_curv, GarNet++'s curvature term (0: off, as in GarNet).
    #[config(default = 0.0)]
    pub curvature: f64,
    /// d_tol: L_pen only counts vertices closer than this to their target (metres, 0.05).
    #[config(default = 0.05)]
    pub d_tol: f64,
    /// The matched body point is pushed out along its normal by this fraction of the body's
    /// mean edge length (0.2).
    #[config(default = 0.2)]
    pub pen_push: f64,
    /// How L_vertex measures each vertex's distance to its label.
    #[config(default = "VertexLoss::Squared")]
    pub vertex_loss: VertexLoss,
    /// How L_norm measures a face's turn from its label's.
    #[config(default = "NormalLoss::Paper")]
    pub normal_loss: NormalLoss,
}

/// How L_norm measures the turn of each face's normal from its label's.
#[derive(Config, Debug, Copy, PartialEq, Eq)]
pub enum NormalLoss {
    /// The paper's `(1 - cos t)^2` (no unit): about `t^4 / 4` for a turn of t radians, so
    /// its gradient vanishes at the 10-25 degree errors networks make, and beside L_vertex
    /// in centimetres it barely steers training.
    Paper,
    /// The corners' displacement of the tilt, `s_f |F^G - F^P|` = `s_f 2 sin(t/2)`
    /// (centimetres): linear in the angle, in the unit of L_vertex.
    Tilt,
}

impl NormalLoss {
    /// Lower-case name: `paper` or `tilt`.
    pub fn name(self) -> &'static str {
        match self {
            NormalLoss::Paper => "paper",
            NormalLoss::Tilt => "tilt",
        }
    }

    /// Parses [`NormalLoss::name`].
    pub fn parse(s: &str) -> Result<NormalLoss> {
        match s {
            "paper" => Ok(NormalLoss::Paper),
            "tilt" => Ok(NormalLoss::Tilt),
            _ => Err(ModelError::InvalidInput(format!(
                "unknown L_norm kind {s:?} (paper or tilt)"
            ))),
        }
    }
}

/// The loss's length unit, units per metre: L_vertex is in cm^2 (or cm), L_pen and L_bend
/// in cm, as the paper reports its errors. The paper's weights balance the terms in these
/// units (in metres the unit-free L_norm and the linear L_pen, L_bend outweigh L_vertex's
/// gradient 10-100 times; see docs/findings.md).
pub const LOSS_UNITS_PER_METRE: f64 = 100.0;

/// How L_vertex measures each vertex's distance to its label.
#[derive(Config, Debug, Copy, PartialEq, Eq)]
pub enum VertexLoss {
    /// The paper's squared distance (cm^2): the network learns the conditional mean drape.
    Squared,
    /// The distance itself (cm), the quantity E_dist averages: a median-like fit, which a
    /// few vertices far from their label pull on no harder than the rest.
    Distance,
}

impl VertexLoss {
    /// The power of each vertex's distance that L_vertex averages: 2 or 1.
    pub fn power(self) -> f64 {
        match self {
            VertexLoss::Squared => 2.0,
            VertexLoss::Distance => 1.0,
        }
    }

    /// Lower-case name: `squared` or `distance`.
    pub fn name(self) -> &'static str {
        match self {
            VertexLoss::Squared => "squared",
            VertexLoss::Distance => "distance",
        }
    }

    /// Parses [`VertexLoss::name`].
    pub fn parse(s: &str) -> Result<VertexLoss> {
        match s {
            "squared" => Ok(VertexLoss::Squared),
            "distance" => Ok(VertexLoss::Distance),
            _ => Err(ModelError::InvalidInput(format!(
                "unknown L_vertex kind {s:?} (squared or distance)"
            ))),
        }
    }
}

/// Loss values of one step or averaged over many (f32; the units of each term).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LossTerms {
    /// Weighted sum.
    pub total: f32,
    /// L_vertex: cm^2 ([`VertexLoss::Squared`]) or cm ([`VertexLoss::Distance`]).
    pub vertex: f32,
    /// L_pen, loss units (cm).
    pub pen: f32,
    /// L_norm: no unit ([`NormalLoss::Paper`]) or loss units, cm ([`NormalLoss::Tilt`]).
    pub norm: f32,
    /// L_bend, loss units (cm).
    pub bend: f32,
    /// L_curv, loss units (cm); 0 when its weight is 0.
    #[serde(default)]
    pub curvature: f32,
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
            curvature: self.curvature * w,
        }
    }
}

impl std::ops::Add for LossTerms {
    type Output = LossTerms;

    /// Term-by-term sum.
    fn add(self, o: LossTerms) -> LossTerms {
        LossTerms {
            total: self.total + o.total,
            vertex: self.vertex + o.vertex,
            pen: self.pen + o.pen,
            norm: self.norm + o.norm,
            bend: self.bend + o.bend,
            curvature: self.curvature + o.curvature,
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
    /// L_curv `[1]` (0 when unweighted).
    pub curvature: Tensor<1>,
}

impl LossTensors {
    /// Reads the six values back (one transfer).
    pub fn values(&self) -> Result<LossTerms> {
        let all = Tensor::cat(
            vec![
                self.total.clone().detach(),
                self.vertex.clone().detach(),
                self.pen.clone().detach(),
                self.norm.clone().detach(),
                self.bend.clone().detach(),
                self.curvature.clone().detach(),
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
            curvature: v[5],
        })
    }
}

/// L_vertex: mean over the B*N vertices of the distance to the power `power` (2: the
/// squared distance; otherwise the squared distance plus a tiny epsilon, to the power
/// `power / 2`, so that the gradient stays finite at 0). `pred`, `target` `[B,N,3]` in
/// metres; the result in metres to the power `power`, `[1]`.
pub fn vertex_loss(pred: Tensor<3>, target: Tensor<3>, power: f64) -> Tensor<1> {
    let squared = (pred - target).square().sum_dim(2);
    if power == 2.0 {
        squared.mean()
    } else {
        (squared + SQRT_EPS).powf_scalar(power / 2.0).mean()
    }
}

/// Unit face normals `[B,F,3]` of `vertices` `[B,N,3]` with the faces' corner index tensors
/// (`[F]` each).
pub fn face_normals(vertices: Tensor<3>, faces: &[Tensor<1, Int>; 3]) -> Tensor<3> {
    let n = face_cross(vertices, faces);
    let len = (n.clone().square().sum_dim(2) + SQRT_EPS).sqrt();
    n / len
}

/// Each face's `(v1 - v0) x (v2 - v0)` `[B,F,3]` (twice its area along its normal) of
/// `vertices` `[B,N,3]`.
fn face_cross(vertices: Tensor<3>, faces: &[Tensor<1, Int>; 3]) -> Tensor<3> {
    let v0 = gather_rows(vertices.clone(), &faces[0]);
    let v1 = gather_rows(vertices.clone(), &faces[1]);
    let v2 = gather_rows(vertices, &faces[2]);
    (v1 - v0.clone()).cross(v2 - v0, 2)
}

/// L_norm: mean over the B*F faces of `(1 - F^G . F^P)^2`. `pred`, `target` `[B,N,3]`.
pub fn normal_loss(pred: Tensor<3>, target: Tensor<3>, faces: &[Tensor<1, Int>; 3]) -> Tensor<1> {
    let fp = face_normals(pred, faces);
    let fg = face_normals(target, faces).detach();
    ((fp * fg).sum_dim(2).neg() + 1.0).square().mean()
}

/// L_norm as a tilt ([`NormalLoss::Tilt`]): mean over the B*F faces of
/// `sqrt(2 area(F^G)) |F^G - F^P|`, metres. `pred`, `target` `[B,N,3]` metres.
pub fn tilt_loss(pred: Tensor<3>, target: Tensor<3>, faces: &[Tensor<1, Int>; 3]) -> Tensor<1> {
    let fp = face_normals(pred, faces);
    let cross = face_cross(target, faces).detach();
    let twice_area = (cross.clone().square().sum_dim(2) + SQRT_EPS).sqrt();
    let fg = cross / twice_area.clone();
    let turn = ((fp - fg).square().sum_dim(2) + SQRT_EPS).sqrt();
    (turn * twice_area.sqrt()).mean()
}

/// Lengths `[B,P,1]` between the vertices of each pair (metres).
fn pair_lengths(v: Tensor<3>, pairs: &[Tensor<1, Int>; 2]) -> Tensor<3> {
    let a = gather_rows(v.clone(), &pairs[0]);
    let b = gather_rows(v, &pairs[1]);
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
    let unit = LOSS_UNITS_PER_METRE;
    let pred_points = read_points(pred.clone().detach())?;
    let (nearest, close) =
        penetration_matches(&pred_points, targets, &batch.body_index, cfg.d_tol as f32)?;
    let vertex = vertex_loss(pred.clone(), target.clone(), cfg.vertex_loss.power());
    let pen = penetration_loss(
        pred.clone(),
        batch.body.clone(),
        batch.body_normals.clone(),
        batch.body_edge.clone(),
        index_tensor(nearest, &device),
        vec_tensor(close, [b, n, 1], &device),
        cfg.pen_push,
    );
    let norm = match cfg.normal_loss {
        NormalLoss::Paper => normal_loss(pred.clone(), target.clone(), &topo.faces),
        NormalLoss::Tilt => tilt_loss(pred.clone(), target.clone(), &topo.faces) * unit,
    };
    let curvature = if cfg.curvature > 0.0 {
        curvature_loss(pred.clone(), targets, topo)? * unit
    } else {
        Tensor::zeros([1], &device)
    };
    let bend = bending_loss(pred, target, &topo.bend_pairs);
    let vertex = vertex * unit.powf(cfg.vertex_loss.power());
    let pen = pen * unit;
    let bend = bend * unit;
    let weighted = [
        (cfg.vertex, &vertex),
        (cfg.pen, &pen),
        (cfg.norm, &norm),
        (cfg.bend, &bend),
        (cfg.curvature, &curvature),
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
        curvature,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::{InputSpec, Sample};
    use crate::local::BodySampling;
    use crate::tensors::{points_tensor, read_scalar};
    use crate::topology::GarmentTopology;

    /// Two triangles over the unit square (target G), faces [0,1,2] and [0,2,3]; the only
    /// two-ring pair is (1, 3).
    fn square() -> geom::TriMesh {
        geom::TriMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    /// The prediction: vertex 2 lifted by 1 m, vertex 3 moved by 0.5 m along y.
    fn prediction() -> Vec<Vec3> {
        let mut p = square().vertices;
        p[2].z += 1.0;
        p[3].y += 0.5;
        p
    }

    /// A batch of one sample over the square with a two-vertex body 1 cm below it (normals
    /// +z, mean edge 0.1 m, so pushed 2 cm out to z = +0.01).
    fn batch(device: &Device) -> (Batch, TopologyTensors) {
        let mesh = square();
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let sample = Sample {
            body: vec![Vec3::new(0.0, 0.0, -0.01), Vec3::new(1.0, 0.9, -0.01)],
            body_normals: vec![Vec3::Z, Vec3::Z],
            body_edge: 0.1,
            warped: mesh.vertices.clone(),
            target: Some(mesh.vertices.clone()),
        };
        let spec = InputSpec {
            sampling: BodySampling {
                n_body: 2,
                stream: vec![0, 1],
                n_centres: 1,
            },
            local: None,
            canonical_rest: None,
            contact_faces: None,
            rest_input: None,
        };
        let b = Batch::new(&[sample], &topo, &spec, device).unwrap();
        (b, topo.to_device(device))
    }

    fn close(a: f32, b: f64) {
        assert!((a as f64 - b).abs() < 1e-6, "{a} != {b}");
    }

    #[test]
    fn each_term_matches_its_hand_computed_value() {
        let device = Device::flex();
        let (b, topo) = batch(&device);
        let pred = points_tensor(&[&prediction()], &device);
        let target = b.target.clone().unwrap();
        // (0 + 0 + 1 + 0.25) / 4
        close(
            read_scalar(vertex_loss(pred.clone(), target.clone(), 2.0)).unwrap(),
            0.3125,
        );
        // The distances themselves: (0 + 0 + 1 + 0.5) / 4.
        close(
            read_scalar(vertex_loss(pred.clone(), target.clone(), 1.0)).unwrap(),
            0.375,
        );
        // Both faces tilt to normals (0,-1,1)/sqrt2 and (-1,0,1)/sqrt2: (1 - 1/sqrt2)^2 each.
        let tilt = (1.0 - 0.5f64.sqrt()).powi(2);
        close(
            read_scalar(normal_loss(pred.clone(), target.clone(), &topo.faces)).unwrap(),
            tilt,
        );
        // As a tilt: each face turns 45 degrees, |F^G - F^P| = 2 sin(22.5 deg), and each of
        // the label's faces has sqrt(2 area) = 1 m.
        let turn = 2.0 * (std::f64::consts::PI / 8.0).sin();
        close(
            read_scalar(tilt_loss(pred.clone(), target.clone(), &topo.faces)).unwrap(),
            turn,
        );
        let tilt_cfg = LossConfig::new().with_normal_loss(NormalLoss::Tilt);
        let t = garnet_loss(pred.clone(), &b, &topo, &tilt_cfg)
            .unwrap()
            .values()
            .unwrap();
        assert!(
            ((t.norm as f64 - 100.0 * turn) / (100.0 * turn)).abs() < 1e-5,
            "{t:?}"
        );
        // Pair (1,3): |(1,-1.5,0)| - |(1,-1,0)| = sqrt(3.25) - sqrt(2).
        let bend = 3.25f64.sqrt() - 2f64.sqrt();
        close(
            read_scalar(bending_loss(pred.clone(), target.clone(), &topo.bend_pairs)).unwrap(),
            bend,
        );
        // Vertices 0 and 1 sit at z = 0, 1 cm under their pushed body points (z = 0.01):
        // 0.01 each; vertices 2 and 3 are > d_tol from their targets and do not count.
        // In centimetres: lengths x100, L_vertex x1e4, L_norm unchanged.
        let cm = garnet_loss(pred.clone(), &b, &topo, &LossConfig::new())
            .unwrap()
            .values()
            .unwrap();
        let rel = |a: f32, b: f64| ((a as f64 - b) / b).abs() < 1e-5;
        assert!(rel(cm.vertex, 3125.0) && rel(cm.pen, 0.5), "{cm:?}");
        assert!(rel(cm.bend, 100.0 * bend) && rel(cm.norm, tilt), "{cm:?}");
        assert!(
            rel(cm.total, 3125.0 + 0.5 + 0.3 * tilt + 50.0 * bend),
            "{cm:?}"
        );
        // L_vertex as the mean distance in centimetres, (0 + 0 + 100 + 50) / 4, weighted 2.
        let dist_cfg = LossConfig::new()
            .with_vertex_loss(VertexLoss::Distance)
            .with_vertex(2.0);
        let dist = garnet_loss(pred, &b, &topo, &dist_cfg)
            .unwrap()
            .values()
            .unwrap();
        assert!(rel(dist.vertex, 37.5) && rel(dist.pen, 0.5), "{dist:?}");
        assert!(
            rel(dist.total, 75.0 + 0.5 + 0.3 * tilt + 50.0 * bend),
            "{dist:?}"
        );
    }

    #[test]
    fn penetration_counts_only_close_vertices_on_the_wrong_side() {
        let device = Device::flex();
        let (b, topo) = batch(&device);
        let cfg = LossConfig::new();
        // Vertex 0 3 cm up (within d_tol, 2 cm outside its pushed body point), vertices 2 and
        // 3 2 cm up (1 cm outside): no penalty; vertex 1 stays 1 cm inside: 0.01 / 4.
        let mut p = square().vertices;
        p[0].z = 0.03;
        p[2].z = 0.02;
        p[3].z = 0.02;
        let pen = garnet_loss(points_tensor(&[&p], &device), &b, &topo, &cfg)
            .unwrap()
            .values()
            .unwrap()
            .pen;
        close(pen, 1.0 / 4.0);
        // Vertex 1 6 cm down: inside, but farther than d_tol from its target: no penalty.
        p[1].z = -0.06;
        let pen = garnet_loss(points_tensor(&[&p], &device), &b, &topo, &cfg)
            .unwrap()
            .values()
            .unwrap()
            .pen;
        close(pen, 0.0);
    }

    #[test]
    fn weights_switch_terms_off_but_terms_are_still_reported() {
        let device = Device::flex();
        let (b, topo) = batch(&device);
        let pred = points_tensor(&[&prediction()], &device);
        let cfg = LossConfig::new()
            .with_norm(0.0)
            .with_bend(0.0)
            .with_pen(0.0);
        let t = garnet_loss(pred, &b, &topo, &cfg)
            .unwrap()
            .values()
            .unwrap();
        close(t.total, 3125.0);
        assert!(t.bend > 10.0 && t.norm > 0.05);
        assert!(LossConfig::new()
            .with_vertex(0.0)
            .with_pen(0.0)
            .with_norm(0.0)
            .with_bend(0.0)
            .validate()
            .is_err());
        assert!(LossConfig::new().with_d_tol(-1.0).validate().is_err());
        assert!(LossConfig::new()
            .with_vertex_loss(VertexLoss::Distance)
            .validate()
            .is_ok());
        assert_eq!(VertexLoss::parse("distance").unwrap(), VertexLoss::Distance);
        assert!(VertexLoss::parse("cubed").is_err());
    }

    /// Central differences of the full loss against its autodiff gradient, for every
    /// coordinate of a prediction on a 4x4 grid with penetrating, non-penetrating, masked
    /// and unmasked vertices (all kinks at least a few h away), with the paper's squared
    /// L_vertex, with the distance itself, and with L_curv weighted.
    #[test]
    fn full_loss_gradient_matches_finite_differences() {
        for (kind, curvature) in [
            (VertexLoss::Squared, 0.0),
            (VertexLoss::Distance, 0.0),
            (VertexLoss::Distance, 1.0),
        ] {
            full_loss_gradient_check(kind, curvature);
        }
    }

    fn full_loss_gradient_check(vertex_loss: VertexLoss, curvature: f64) {
        let plain = Device::flex();
        let ad = plain.clone().autodiff();
        let mesh = geom::TriMesh::grid(4, 4, 0.1);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let target = crate::synthetic::smooth_displacement(&mesh.vertices, 0.3);
        let n = target.len();
        // Offsets of 1-3 cm (counted by L_pen) or 8-9 cm (masked out), varied directions.
        let pred: Vec<Vec3> = target
            .iter()
            .enumerate()
            .map(|(i, g)| {
                let far = i % 5 == 0;
                let s = if far {
                    0.08 + 0.001 * i as f32
                } else {
                    0.01 + 0.001 * i as f32
                };
                let a = i as f32 * 1.3;
                *g + s * Vec3::new(
                    a.cos() * 0.6,
                    a.sin() * 0.6,
                    if i % 2 == 0 { -0.53 } else { 0.53 },
                )
            })
            .collect();
        // Body: a point 4 mm under each target vertex along -y (the grid lies in the y = 0
        // plane), normals +y; pushed out by 0.2 * 5 cm it ends 6 mm above the target.
        let body: Vec<Vec3> = target
            .iter()
            .map(|g| *g - Vec3::new(0.0, 0.004, 0.0))
            .collect();
        let sample = Sample {
            body: body.clone(),
            body_normals: vec![Vec3::Y; n],
            body_edge: 0.05,
            warped: mesh.vertices.clone(),
            target: Some(target.clone()),
        };
        let spec = InputSpec {
            sampling: BodySampling {
                n_body: n,
                stream: (0..n as u32).collect(),
                n_centres: 1,
            },
            local: None,
            canonical_rest: None,
            contact_faces: None,
            rest_input: None,
        };
        let cfg = LossConfig::new()
            .with_vertex_loss(vertex_loss)
            .with_curvature(curvature);
        let loss_at = |p: &[Vec3]| -> f64 {
            let b = Batch::new(std::slice::from_ref(&sample), &topo, &spec, &plain).unwrap();
            let tt = topo.to_device(&plain);
            garnet_loss(points_tensor(&[p], &plain), &b, &tt, &cfg)
                .unwrap()
                .values()
                .unwrap()
                .total as f64
        };
        let b_ad = Batch::new(std::slice::from_ref(&sample), &topo, &spec, &ad).unwrap();
        let tt_ad = topo.to_device(&ad);
        let p_ad = points_tensor(&[&pred], &ad).require_grad();
        let loss = garnet_loss(p_ad.clone(), &b_ad, &tt_ad, &cfg).unwrap();
        let grads = loss.total.backward();
        let g = crate::tensors::read_f32(p_ad.grad(&grads).unwrap()).unwrap();
        let terms = loss.values().unwrap();
        assert!(
            terms.pen > 0.0 && (curvature == 0.0 || terms.curvature > 0.1),
            "the example must exercise L_pen (and L_curv when weighted): {terms:?}"
        );
        let h = 2e-4f32;
        // The loss is summed in f32, so a central difference moves in steps of the total's
        // unit in the last place over 2h (1.2e-3 for the distance L_vertex's total of 4.6):
        // a difference that small is all the arithmetic can resolve, whatever the SIMD width
        // that did the sums. A larger h would cross the kinks.
        let total = terms.total;
        let quantum = (f32::from_bits(total.to_bits() + 1) - total) as f64 / (2.0 * h as f64);
        let mut worst = 0.0f64;
        for i in 0..n {
            for c in 0..3 {
                let mut plus = pred.clone();
                plus[i][c] += h;
                let mut minus = pred.clone();
                minus[i][c] -= h;
                let fd = (loss_at(&plus) - loss_at(&minus)) / (2.0 * h as f64);
                let ad = g[i * 3 + c] as f64;
                let off = ((fd - ad).abs() - 1.5 * quantum).max(0.0);
                worst = worst.max(off / (1e-3 + ad.abs()));
                assert!(
                    off <= 2e-4 + 2e-2 * ad.abs(),
                    "{vertex_loss:?}, L_curv {curvature}, vertex {i} coord {c}: finite difference {fd}, autodiff {ad} \
                     (differences resolve {quantum})"
                );
            }
        }
        assert!(worst < 0.1, "worst relative error {worst}");
    }
}
