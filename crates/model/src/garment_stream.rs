//! The garment stream (paper Fig. 3 and 4).
//!
//! ```text
//! M [B,N,3] -> STN 3x3 -> MLP (global body feature enters every layer) -> point-wise [B,N,P]
//!   -> (Global, Local) 6 residual blocks of FeaStNet convolutions, each convolution's input
//!      concatenated with the vertex positions M -> patch-wise [B,N,C]
//! [point; patch] -> shared layer -> max over vertices -> global garment feature [B,G]
//! ```

use burn::nn::Linear;
use burn::prelude::*;

use crate::config::GarNetConfig;
use crate::contact::CONTACT_WIDTH;
use crate::dense_rows::{chain_tensors, HostLayer};
use crate::error::Result;
use crate::feast::FeaStConv;
use crate::feast_rows::Epilogue;
use crate::init::ParamInit;
use crate::layers::{cat_features, lrelu, max_points, CondLinear};
use crate::stn::Stn;
use crate::tensors::{read_f32, untracked_on_flex, vec_tensor};
use crate::topology::TopologyTensors;

/// `conv` over the garment's 1-ring applied to the features `x` `[B,N,C]` concatenated with
/// the vertex positions `pos` `[B,N,3]`: `[B,N,C_out]`.
fn conv_with_positions(
    conv: &FeaStConv,
    x: Tensor<3>,
    pos: Tensor<3>,
    topo: &TopologyTensors,
) -> Tensor<3> {
    conv.forward(Tensor::cat(vec![x, pos], 2), &topo.ring, &topo.ring_weight)
}

/// The block `run` computes as plain loops on the host (drapes and evaluation: untracked
/// tensors on flex, see [`crate::feast_rows`]): `run(x, pos, N)` gets `x` `[B*N*C]` and `pos`
/// `[B*N*3]` row-major and returns `[B*N*C]`, or `None` to leave it to the tensor path
/// (as do tracked tensors, other backends and any error).
fn block_rows(
    x: &Tensor<3>,
    pos: &Tensor<3>,
    topo: &TopologyTensors,
    run: impl FnOnce(&[f32], &[f32], usize) -> Result<Option<Vec<f32>>>,
) -> Option<Tensor<3>> {
    if !(untracked_on_flex(x) && untracked_on_flex(pos)) {
        return None;
    }
    let [b, n, c] = x.dims();
    if topo.n_vertices != n {
        return None;
    }
    let xs = read_f32(x.clone()).ok()?;
    let ps = read_f32(pos.clone()).ok()?;
    let y = run(&xs, &ps, n).ok()??;
    Some(vec_tensor(y, [b, n, c], &x.device()))
}

/// A residual block of FeaStNet convolutions `C+3 -> C`, each seeing the features
/// concatenated with the vertex positions M, LeakyReLU between them, the block input added
/// before the last activation: with one convolution `y = lrelu(x + conv([x; M]))`, with two
/// `y = lrelu(x + conv2([lrelu(conv1([x; M])); M]))`.
#[derive(Module, Debug)]
pub struct ResBlock {
    /// The convolutions, in order.
    pub convs: Vec<FeaStConv>,
}

impl ResBlock {
    fn new(
        width: usize,
        convs: usize,
        heads: usize,
        init: &mut ParamInit,
        device: &Device,
    ) -> Self {
        ResBlock {
            convs: (0..convs)
                .map(|_| FeaStConv::new(width + 3, width, heads, init, device))
                .collect(),
        }
    }

    /// `x` `[B,N,C]`, `pos` `[B,N,3]` -> `[B,N,C]`.
    pub fn forward(&self, x: Tensor<3>, pos: Tensor<3>, topo: &TopologyTensors) -> Tensor<3> {
        if let Some(y) = self.forward_host(&x, &pos, topo) {
            return y;
        }
        let mut h = x.clone();
        for (i, conv) in self.convs.iter().enumerate() {
            if i > 0 {
                h = lrelu(h);
            }
            h = conv_with_positions(conv, h, pos.clone(), topo);
        }
        lrelu(x + h)
    }

    /// [`ResBlock::forward`] as plain loops ([`block_rows`]), or `None`.
    fn forward_host(
        &self,
        x: &Tensor<3>,
        pos: &Tensor<3>,
        topo: &TopologyTensors,
    ) -> Option<Tensor<3>> {
        block_rows(x, pos, topo, |xs, ps, n| {
            let mut h: Option<Vec<f32>> = None;
            for (i, conv) in self.convs.iter().enumerate() {
                let epilogue = if i + 1 == self.convs.len() {
                    Epilogue::ResidualLrelu(xs)
                } else {
                    Epilogue::Lrelu
                };
                let input = h.as_deref().unwrap_or(xs);
                match conv.forward_rows(input, ps, n, &topo.host_ring, epilogue)? {
                    Some(y) => h = Some(y),
                    None => return Ok(None),
                }
            }
            Ok(h)
        })
    }
}

/// Garment stream.
#[derive(Module, Debug)]
pub struct GarmentStream {
    /// Input transform on M (3x3).
    pub stn: Stn,
    /// Point-wise MLP layers, each conditioned on the global body feature.
    pub mlp: Vec<CondLinear>,
    /// Layer `P -> C` into the convolutions when the point-wise width P differs from the
    /// convolution width C (none for Naive or when they match).
    pub conv_in: Option<Linear>,
    /// Residual mesh-convolution blocks (empty for GarNet-Naive).
    pub blocks: Vec<ResBlock>,
    /// Shared layer before the max pooling to the global garment feature.
    pub global: Linear,
}

/// Outputs of the garment stream.
#[derive(Clone, Debug)]
pub struct GarmentFeatures {
    /// Point-wise garment features `[B,N,P]`.
    pub points: Tensor<3>,
    /// Patch-wise garment features `[B,N,C]` (none for GarNet-Naive).
    pub patches: Option<Tensor<3>>,
    /// Global garment feature `[B,G]`.
    pub global: Tensor<2>,
}

impl GarmentStream {
    pub(crate) fn new(cfg: &GarNetConfig, init: &mut ParamInit, device: &Device) -> Self {
        let stn = Stn::new(3, &cfg.stn_mlp, &cfg.stn_fc, init, device);
        let cb = cfg.body_feature_width();
        let mut mlp = Vec::with_capacity(cfg.garment_mlp.len());
        let mut d = 3;
        if cfg.rest_input {
            d += 3;
        }
        if cfg.body_contact {
            d += CONTACT_WIDTH;
        }
        for &w in &cfg.garment_mlp {
            mlp.push(CondLinear::new(d, cb, w, init, device));
            d = w;
        }
        let p = d;
        let (conv_in, blocks, d_global) = if cfg.variant.has_mesh_conv() {
            let c = cfg.conv_width;
            let conv_in = (p != c).then(|| init.hidden(p, c, device));
            let blocks = (0..cfg.conv_blocks)
                .map(|_| ResBlock::new(c, cfg.convs_per_block, cfg.conv_heads, init, device))
                .collect();
            (conv_in, blocks, p + c)
        } else {
            (None, Vec::new(), p)
        };
        let global = init.hidden(d_global, cfg.garment_global, device);
        GarmentStream {
            stn,
            mlp,
            conv_in,
            blocks,
            global,
        }
    }

    /// `warped` M `[B,N,3]` (network unit), `body_global` `[B,Cb]`, and the extra per-vertex
    /// inputs of the first layer (with [`GarNetConfig::rest_input`] the template's vertices
    /// `[B,N,3]` in the network unit, with [`GarNetConfig::body_contact`] the contact features
    /// `[B,N,CONTACT_WIDTH]`, in that order) -> point-wise, patch-wise and global garment
    /// features.
    pub fn forward(
        &self,
        warped: Tensor<3>,
        body_global: Tensor<2>,
        extra: Vec<Tensor<3>>,
        topo: &TopologyTensors,
    ) -> GarmentFeatures {
        let parts = [vec![self.stn.forward(warped.clone())], extra].concat();
        let points = self.point_features(parts, body_global);
        let patches = if self.blocks.is_empty() {
            None
        } else {
            let mut c = match &self.conv_in {
                Some(l) => lrelu(l.forward(points.clone())),
                None => points.clone(),
            };
            for block in &self.blocks {
                c = block.forward(c, warped.clone(), topo);
            }
            Some(c)
        };
        let g_in = match &patches {
            Some(c) => vec![points.clone(), c.clone()],
            None => vec![points.clone()],
        };
        GarmentFeatures {
            points,
            patches,
            global: self.global_feature(g_in),
        }
    }

    /// The point-wise MLP on `parts` `[B,N,d_i]` (concatenated along the features), each
    /// layer conditioned on `body_global` `[B,Cb]` -> `[B,N,P]`; as plain loops where the
    /// parts are untracked on flex ([`crate::dense_rows`]).
    fn point_features(&self, parts: Vec<Tensor<3>>, body_global: Tensor<2>) -> Tensor<3> {
        let layers = || {
            self.mlp
                .iter()
                .map(|l| l.host_layer(body_global.clone(), true))
                .collect()
        };
        if let Some((Some(rows), _)) = chain_tensors(&parts, layers, true, false) {
            return rows;
        }
        let mut h = cat_features(parts);
        for layer in &self.mlp {
            let bias = layer.cond_bias(body_global.clone());
            h = lrelu(layer.forward(h, bias));
        }
        h
    }

    /// The global garment feature `[B,G]`: the shared layer on `parts` `[B,N,d_i]`
    /// (concatenated along the features), max-pooled over the vertices; as plain loops
    /// where the parts are untracked on flex, without writing the layer's `[B,N,G]` out.
    fn global_feature(&self, parts: Vec<Tensor<3>>) -> Tensor<2> {
        let layers = || Ok(vec![HostLayer::read(&self.global, true)?]);
        match chain_tensors(&parts, layers, false, true) {
            Some((_, Some(global))) => global,
            _ => max_points(lrelu(self.global.forward(cat_features(parts)))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::feast_rows::tests::largest_difference;
    use crate::topology::GarmentTopology;
    use rand::{Rng, SeedableRng};

    /// The blocks' plain loops (untracked tensors on flex) against the same blocks written
    /// with burn's ops: residual blocks of one and two convolutions.
    #[test]
    fn blocks_on_the_host_match_the_tensor_ops() {
        let device = Device::flex();
        let mesh = geom::TriMesh::grid(12, 9, 0.1);
        let topo = GarmentTopology::from_mesh(&mesh)
            .unwrap()
            .to_device(&device);
        let (b, n, c) = (2, mesh.num_vertices(), 6);
        let mut rng = rand::rngs::StdRng::seed_from_u64(2);
        let mut random =
            |len: usize| -> Vec<f32> { (0..len).map(|_| rng.random_range(-1.0..1.0)).collect() };
        let x = vec_tensor(random(b * n * c), [b, n, c], &device);
        let pos = vec_tensor(random(b * n * 3), [b, n, 3], &device);
        let conv = |f: &FeaStConv, h: Tensor<3>| conv_with_positions(f, h, pos.clone(), &topo);
        let compare = |got: Tensor<3>, want: Tensor<3>, what: &str| {
            let (got, want) = (read_f32(got).unwrap(), read_f32(want).unwrap());
            let worst = largest_difference(&got, &want);
            assert!(worst < 1e-5, "{what}: {worst}");
        };
        let mut init = ParamInit::new(4);
        for convs in [1, 2] {
            let block = ResBlock::new(c, convs, 8, &mut init, &device);
            let mut h = conv(&block.convs[0], x.clone());
            if convs == 2 {
                h = conv(&block.convs[1], lrelu(h));
            }
            let want = lrelu(x.clone() + h);
            let got = block.forward_host(&x, &pos, &topo).expect("the host path");
            compare(got, want, "residual block");
        }
    }
}
