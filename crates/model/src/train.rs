//! One optimisation step and one evaluation pass over a batch.

use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::prelude::Tensor;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::batch::Batch;
use crate::error::{ModelError, Result};
use crate::garnet::GarNet;
use crate::grad_clip::clip_gradient_norm;
use crate::loss::{garnet_loss, LossConfig, LossTerms};
use crate::tensors::read_points;
use crate::topology::TopologyTensors;

/// The paper's learning rate for Adam.
pub const PAPER_LEARNING_RATE: f64 = 1e-3;

/// The paper's optimiser: PyTorch's Adam (beta 0.9, 0.999, epsilon 1e-8; burn's default
/// epsilon is 1e-5, which damps the steps of parameters whose gradients are smaller than
/// that); the learning rate is given at each step.
pub fn adam() -> ModuleOptimizer {
    AdamConfig::new().with_epsilon(1e-8).init()
}

impl LossConfig {
    /// Fails when a weight or constant is negative or not finite, the power of L_vertex is
    /// outside [1, 2], or every weight is 0.
    pub fn validate(&self) -> Result<()> {
        let all = [
            self.vertex,
            self.pen,
            self.norm,
            self.bend,
            self.curvature,
            self.d_tol,
            self.pen_push,
        ];
        if all.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return Err(ModelError::InvalidInput(format!(
                "loss weights and constants must be finite and >= 0: {self:?}"
            )));
        }
        if self.vertex + self.pen + self.norm + self.bend + self.curvature == 0.0 {
            return Err(ModelError::InvalidInput("every loss weight is 0".into()));
        }
        Ok(())
    }
}

/// What one optimisation step did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// Loss terms before the update.
    pub terms: LossTerms,
    /// L2 norm of all gradients together before clipping (loss units per parameter unit).
    pub grad_norm: f32,
}

/// The network's drapes `[B,N,3]` (metres) of `batch`.
fn predict(model: &GarNet, batch: &Batch, topo: &TopologyTensors) -> Result<Tensor<3>> {
    model.forward(&batch.inputs, batch.warped.clone(), topo)
}

/// One Adam step on `batch` (which must have targets and live on an autodiff device, as
/// `model` does): forward, loss, backward, gradients scaled to a joint L2 norm of at most
/// `max_grad_norm` when given (see [`crate::grad_clip`]), update `model` in place. Fails
/// (leaving `model` unchanged) when the loss or the gradient norm is not finite.
pub fn train_step(
    model: &mut GarNet,
    optim: &mut ModuleOptimizer,
    batch: &Batch,
    topo: &TopologyTensors,
    loss_cfg: &LossConfig,
    lr: f64,
    max_grad_norm: Option<f32>,
) -> Result<StepReport> {
    let pred = predict(model, batch, topo)?;
    let loss = garnet_loss(pred, batch, topo, loss_cfg)?;
    let terms = loss.values()?;
    if !terms.total.is_finite() {
        return Err(ModelError::InvalidInput(format!(
            "training diverged: loss is not finite ({terms:?})"
        )));
    }
    let grads = loss.total.backward();
    let mut grads = GradientsParams::from_grads(grads, &*model);
    let grad_norm = clip_gradient_norm(&*model, &mut grads, max_grad_norm)?;
    if !grad_norm.is_finite() {
        return Err(ModelError::InvalidInput(format!(
            "training diverged: the gradient norm is {grad_norm} ({terms:?})"
        )));
    }
    *model = optim.step(lr, model.clone(), grads);
    Ok(StepReport { terms, grad_norm })
}

/// Predictions and errors of one evaluated batch.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Loss terms of the batch.
    pub terms: LossTerms,
    /// Mean vertex distance E_dist over the batch, centimetres.
    pub e_dist_cm: f32,
    /// Mean face-normal angle E_norm over the batch, degrees.
    pub e_norm_deg: f32,
    /// Predicted garments `[B][N]`, metres.
    pub predictions: Vec<Vec<Vec3>>,
}

/// Forward pass without gradients plus the loss and the paper's metrics (E_dist, E_norm over
/// `faces`, the template's triangles). `model` and `batch` on the same device; pass a model
/// on a plain (non-autodiff) device, e.g. `model.valid()`, to skip building a graph.
pub fn evaluate_batch(
    model: &GarNet,
    batch: &Batch,
    topo: &TopologyTensors,
    faces: &[[u32; 3]],
    loss_cfg: &LossConfig,
) -> Result<Evaluation> {
    let pred = predict(model, batch, topo)?.detach();
    let terms = garnet_loss(pred.clone(), batch, topo, loss_cfg)?.values()?;
    let predictions = read_points(pred)?;
    let targets = batch.target_points().unwrap_or(&[]);
    let (mut dist, mut norm) = (0.0f64, 0.0f64);
    for (p, g) in predictions.iter().zip(targets) {
        let e = geom::metrics::mesh_errors(g, p, faces)?;
        dist += e.e_dist_cm as f64;
        norm += e.e_norm_deg as f64;
    }
    let b = predictions.len().max(1) as f64;
    Ok(Evaluation {
        terms,
        e_dist_cm: (dist / b) as f32,
        e_norm_deg: (norm / b) as f32,
        predictions,
    })
}
