//! GarNet: body stream + garment stream + fusion; predicts per-vertex translations of the
//! warped garment M and returns `G = M + T` (paper eq. 1).

use burn::prelude::*;

use crate::batch::NetInputs;
use crate::body_stream::{BodyStream, LocalPool};
use crate::config::{GarNetConfig, Variant};
use crate::contact::CONTACT_WIDTH;
use crate::error::{ModelError, Result};
use crate::fusion::Fusion;
use crate::garment_stream::GarmentStream;
use crate::init::ParamInit;
use crate::topology::TopologyTensors;

/// The GarNet network (any of the three variants, see [`GarNet::variant`]).
#[derive(Module, Debug)]
pub struct GarNet {
    /// PointNet body stream.
    pub body: BodyStream,
    /// Garment stream (with mesh convolutions unless Naive).
    pub garment: GarmentStream,
    /// Local body pooling (GarNet-Local only).
    pub local: Option<LocalPool>,
    /// Fusion network.
    pub fusion: Fusion,
    /// Input and output length unit, metres (see [`GarNetConfig::input_scale`]).
    pub input_scale: f32,
    /// Centre subtracted from input positions `[3]`, metres.
    pub input_centre: Vec<f32>,
    /// Whether the garment stream takes body-contact features ([`GarNetConfig::body_contact`]).
    pub body_contact: bool,
    /// Whether the garment stream takes the template's vertices ([`GarNetConfig::rest_input`]).
    pub rest_input: bool,
}

impl GarNetConfig {
    /// Builds the network on `device` with seeded initial values (same config and seed, same
    /// parameters). Fails when the config does not [`validate`](GarNetConfig::validate).
    pub fn init(&self, device: &Device) -> Result<GarNet> {
        self.validate()?;
        let mut init = ParamInit::new(self.seed);
        let body = BodyStream::new(self, &mut init, device);
        let garment = GarmentStream::new(self, &mut init, device);
        let local = self
            .variant
            .has_local()
            .then(|| LocalPool::new(self, &mut init, device));
        let mut d_vertex = self.garment_point_width();
        if self.variant.has_mesh_conv() {
            d_vertex += self.conv_width;
        }
        if self.variant.has_local() {
            d_vertex += self.local_width;
        }
        let d_global = self.garment_global + self.body_feature_width();
        let fusion = Fusion::new(d_vertex, d_global, &self.fusion, &mut init, device);
        Ok(GarNet {
            body,
            garment,
            local,
            fusion,
            input_scale: self.input_scale,
            input_centre: self.input_centre.clone(),
            body_contact: self.body_contact,
            rest_input: self.rest_input,
        })
    }
}

impl GarNet {
    /// The variant, read from the structure (local pooling: Local; mesh convolutions:
    /// Global; neither: Naive).
    pub fn variant(&self) -> Variant {
        if self.local.is_some() {
            Variant::Local
        } else if self.garment.blocks.is_empty() {
            Variant::Naive
        } else {
            Variant::Global
        }
    }

    /// Predicted translations `T` `[B,N,3]` (metres). Positions are moved to the network's
    /// unit ([`GarNetConfig::input_scale`]) inside.
    ///
    /// - `inputs`: the body points the stream sees `[B,P,3]` (see
    ///   [`crate::local::BodySampling::stream_points`]), metres; the neighbour tables,
    ///   required by GarNet-Local; the body-contact features of M `[B,N,CONTACT_WIDTH]` (see
    ///   [`crate::contact`]), required by a network with [`GarNet::body_contact`] and refused
    ///   by the others; the template's vertices `[B,N,3]` (metres), likewise with
    ///   [`GarNet::rest_input`].
    /// - `warped`: the DQS-warped garment M `[B,N,3]`, metres.
    /// - `topo`: the garment template's connectivity (N vertices).
    pub fn translations(
        &self,
        inputs: &NetInputs,
        warped: Tensor<3>,
        topo: &TopologyTensors,
    ) -> Result<Tensor<3>> {
        let body = inputs.body_stream.clone();
        let local = inputs.local.as_ref();
        let [b, v, cb] = body.dims();
        let [bm, n, cm] = warped.dims();
        if cb != 3 || cm != 3 || b != bm || b == 0 || v == 0 {
            return Err(ModelError::InvalidInput(format!(
                "GarNet takes body [B,P,3] and M [B,N,3] with B, P > 0, got [{b},{v},{cb}] and \
                 [{bm},{n},{cm}]"
            )));
        }
        if n != topo.n_vertices {
            return Err(ModelError::VertexCount {
                what: "warped garment M".into(),
                expected: topo.n_vertices,
                got: n,
            });
        }
        let extras = [
            (
                &inputs.contact,
                self.body_contact,
                CONTACT_WIDTH,
                "body-contact features",
            ),
            (&inputs.rest, self.rest_input, 3, "template vertices"),
        ];
        for (given, wanted, width, what) in extras {
            if given.as_ref().map(|t| t.dims()) != wanted.then_some([b, n, width]) {
                return Err(ModelError::InvalidInput(format!(
                    "this network {} {what} [{b},{n},{width}], got {:?}",
                    if wanted { "needs" } else { "takes no" },
                    given.as_ref().map(|t| t.dims())
                )));
            }
        }
        let centre = Tensor::<1>::from_floats(self.input_centre.as_slice(), &body.device())
            .reshape([1, 1, 3]);
        let unit = self.input_scale as f64;
        let body = (body - centre.clone()) / unit;
        let warped = (warped - centre.clone()) / unit;
        let mut extra = Vec::new();
        if let Some(r) = &inputs.rest {
            extra.push((r.clone() - centre) / unit);
        }
        extra.extend(inputs.contact.clone());
        let body_features = self.body.forward(body);
        let garment = self
            .garment
            .forward(warped, body_features.global.clone(), extra, topo);
        let mut per_vertex = vec![garment.points];
        if let Some(p) = garment.patches {
            per_vertex.push(p);
        }
        if let Some(pool) = &self.local {
            let idx = local.ok_or_else(|| {
                ModelError::InvalidInput("GarNet-Local needs the batch's local tables".into())
            })?;
            if idx.n_garment != n
                || idx.pool.dims()[0] != b * idx.n_centres * idx.pool_k
                || idx.knn_k == 0
                || idx.knn.len() != idx.knn_k
                || idx.knn.iter().any(|c| c.dims()[0] != b * n)
            {
                return Err(ModelError::InvalidInput(format!(
                    "local tables are for {} garment vertices and another batch size",
                    idx.n_garment
                )));
            }
            per_vertex.push(pool.forward(body_features.points, idx));
        }
        let global = Tensor::cat(vec![garment.global, body_features.global], 1);
        Ok(self.fusion.forward(per_vertex, global) * unit)
    }

    /// The predicted draped garment `G = M + T` `[B,N,3]` (metres); arguments as
    /// [`GarNet::translations`].
    pub fn forward(
        &self,
        inputs: &NetInputs,
        warped: Tensor<3>,
        topo: &TopologyTensors,
    ) -> Result<Tensor<3>> {
        let t = self.translations(inputs, warped.clone(), topo)?;
        Ok(warped + t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parameters of a fully connected layer.
    fn fc(i: usize, o: usize, bias: bool) -> usize {
        i * o + if bias { o } else { 0 }
    }

    fn mlp(d: usize, widths: &[usize]) -> (usize, usize) {
        let mut total = 0;
        let mut d = d;
        for &w in widths {
            total += fc(d, w, true);
            d = w;
        }
        (total, d)
    }

    fn stn(k: usize, c: &GarNetConfig) -> usize {
        let (mut total, d) = mlp(k, &c.stn_mlp);
        let (fcs, d) = mlp(d, &c.stn_fc);
        total += fcs + fc(d, k * k, true);
        total
    }

    /// The parameter count written out from the architecture of section 3.2, independently
    /// of the module code.
    fn expected_params(c: &GarNetConfig) -> usize {
        let cb = c.body_feature_width();
        let (m1, c1) = mlp(3, &c.body_mlp1);
        let (m2, _) = mlp(c1 + 3, &c.body_mlp2);
        let body = stn(3, c) + m1 + stn(c1, c) + m2;
        let mut garment = stn(3, c);
        let mut d = 3;
        for &w in &c.garment_mlp {
            garment += fc(d, w, true) + fc(cb, w, false);
            d = w;
        }
        let p = d;
        let mut d_vertex = p;
        let mut d_global_in = p;
        if c.variant.has_mesh_conv() {
            let w = c.conv_width;
            if p != w {
                garment += fc(p, w, true);
            }
            let feast =
                fc(w + 3, c.conv_heads, false) + c.conv_heads + fc((w + 3) * c.conv_heads, w, true);
            garment += c.conv_blocks * c.convs_per_block * feast;
            d_vertex += w;
            d_global_in += w;
        }
        garment += fc(d_global_in, c.garment_global, true);
        let mut local = 0;
        if c.variant.has_local() {
            local = fc(cb, c.local_width, true);
            d_vertex += c.local_width;
        }
        let h = &c.fusion;
        let mut fusion = fc(d_vertex, h[0], true) + fc(c.garment_global + cb, h[0], false);
        let (hidden, last) = mlp(h[0], &h[1..]);
        fusion += hidden + fc(last, 3, true);
        body + garment + local + fusion
    }

    #[test]
    fn parameter_counts_follow_the_architecture() {
        let device = Device::flex();
        let mut counts = Vec::new();
        for variant in Variant::ALL {
            for cfg in [GarNetConfig::new(variant), GarNetConfig::tiny(variant)] {
                let model = cfg.init(&device).unwrap();
                assert_eq!(model.variant(), variant);
                assert_eq!(model.num_params(), expected_params(&cfg), "{variant:?}");
            }
            let n = GarNetConfig::new(variant)
                .init(&device)
                .unwrap()
                .num_params();
            println!("GarNet-{}: {n} parameters (default widths)", variant.name());
            counts.push(n);
        }
        // Local > Global > Naive.
        assert!(counts[0] > counts[1] && counts[1] > counts[2]);
    }

    #[test]
    fn naive_has_no_mesh_convolution() {
        let device = Device::flex();
        let naive = GarNetConfig::new(Variant::Naive).init(&device).unwrap();
        assert!(naive.garment.blocks.is_empty());
        assert!(naive.garment.conv_in.is_none());
        assert!(naive.local.is_none());
        let global = GarNetConfig::new(Variant::Global).init(&device).unwrap();
        assert_eq!(global.garment.blocks.len(), 6);
        assert!(GarNetConfig::new(Variant::Global)
            .with_conv_blocks(0)
            .init(&device)
            .is_err());
    }

    #[test]
    fn same_seed_same_parameters() {
        let device = Device::flex();
        let cfg = GarNetConfig::tiny(Variant::Local).with_seed(42);
        let a = cfg.init(&device).unwrap();
        let b = cfg.init(&device).unwrap();
        let c = cfg.clone().with_seed(43).init(&device).unwrap();
        let w = |m: &GarNet| crate::tensors::read_f32(m.fusion.first.point.weight.val()).unwrap();
        assert_eq!(w(&a), w(&b));
        assert_ne!(w(&a), w(&c));
    }
}
