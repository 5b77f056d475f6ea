//! The fusion network: four per-vertex MLP blocks over
//! `[garment point-wise; patch-wise; global garment; global body (; local body)]` -> the 3
//! translation components (metres). The two global features are the same for every vertex of
//! a sample, so the first layer takes them as a per-sample bias ([`CondLinear`]).

use burn::nn::Linear;
use burn::prelude::*;

use crate::dense_rows::{chain_tensors, HostLayer};
use crate::init::ParamInit;
use crate::layers::{cat_features, lrelu, CondLinear};

/// Fusion MLP.
#[derive(Module, Debug)]
pub struct Fusion {
    /// First block: per-vertex features plus the per-sample global features.
    pub first: CondLinear,
    /// Further hidden blocks.
    pub hidden: Vec<Linear>,
    /// Last block to the translation `[3]`, no activation (initialised small, so an untrained
    /// network starts near M).
    pub out: Linear,
}

impl Fusion {
    /// `d_vertex` per-vertex input width, `d_global` per-sample width, `widths` hidden widths.
    pub(crate) fn new(
        d_vertex: usize,
        d_global: usize,
        widths: &[usize],
        init: &mut ParamInit,
        device: &Device,
    ) -> Self {
        let first = CondLinear::new(d_vertex, d_global, widths[0], init, device);
        let mut hidden = Vec::with_capacity(widths.len().saturating_sub(1));
        for pair in widths.windows(2) {
            hidden.push(init.hidden(pair[0], pair[1], device));
        }
        let out = init.scaled(*widths.last().unwrap_or(&widths[0]), 3, 0.01, device);
        Fusion { first, hidden, out }
    }

    /// `per_vertex` `[B,N,d_i]` parts (concatenated along the features: `d_vertex` in all),
    /// `global` `[B,d_global]` -> translations `[B,N,3]`. Untracked on flex, the four blocks
    /// run as plain loops ([`crate::dense_rows`]) and the parts are never concatenated.
    pub fn forward(&self, per_vertex: Vec<Tensor<3>>, global: Tensor<2>) -> Tensor<3> {
        let layers = || {
            let first = self.first.host_layer(global.clone(), true)?;
            let mut layers = vec![first];
            for l in &self.hidden {
                layers.push(HostLayer::read(l, true)?);
            }
            layers.push(HostLayer::read(&self.out, false)?);
            Ok(layers)
        };
        if let Some((Some(rows), _)) = chain_tensors(&per_vertex, layers, true, false) {
            return rows;
        }
        let per_vertex = cat_features(per_vertex);
        let bias = self.first.cond_bias(global);
        let h = lrelu(self.first.forward(per_vertex, bias));
        let h = self.hidden.iter().fold(h, |h, l| lrelu(l.forward(h)));
        self.out.forward(h)
    }
}
