//! PointNet's spatial transformer network (T-Net): predicts a k x k matrix from a point set
//! and applies it to every point.

use burn::nn::Linear;
use burn::prelude::*;

use crate::init::ParamInit;
use crate::layers::{lrelu, PointMlp};

/// A spatial transformer for `k`-dimensional point features: shared per-point MLP, max pooling
/// over points, fully connected layers, then a zero-initialised layer to `k*k` values added to
/// the identity (so it starts as the identity transform).
#[derive(Module, Debug)]
pub struct Stn {
    /// Per-point MLP `k -> ...`.
    pub mlp: PointMlp,
    /// Fully connected layers after the pooling, each with LeakyReLU(0.1).
    pub fc: Vec<Linear>,
    /// Last layer to the `k*k` matrix entries (row-major), no activation.
    pub out: Linear,
}

impl Stn {
    pub(crate) fn new(
        k: usize,
        mlp: &[usize],
        fc: &[usize],
        init: &mut ParamInit,
        device: &Device,
    ) -> Self {
        let mlp = PointMlp::new(k, mlp, init, device);
        let mut d = mlp.d_out();
        let mut layers = Vec::with_capacity(fc.len());
        for &w in fc {
            layers.push(init.hidden(d, w, device));
            d = w;
        }
        let out = init.scaled(d, k * k, 0.0, device);
        Stn {
            mlp,
            fc: layers,
            out,
        }
    }

    /// The dimension k of the transformed features.
    pub fn k(&self) -> usize {
        self.mlp
            .layers
            .first()
            .map(|l| l.weight.val().dims()[0])
            .unwrap_or(0)
    }

    /// The predicted transforms: `x` `[B,P,k]` -> `[B,k,k]` (identity plus the learned part).
    pub fn transform(&self, x: Tensor<3>) -> Tensor<3> {
        let [b, _, k] = x.dims();
        let pooled = self.mlp.pooled(vec![x.clone()]);
        let h = self
            .fc
            .iter()
            .fold(pooled, |h, layer| lrelu(layer.forward(h)));
        let t = self.out.forward(h).reshape([b, k, k]);
        let eye = Tensor::<2>::eye(k, &x.device()).unsqueeze_dim::<3>(0);
        t + eye
    }

    /// Applies the predicted transform to every point: `x` `[B,P,k]` -> `x T` `[B,P,k]`.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let t = self.transform(x.clone());
        x.matmul(t)
    }
}
