//! Seeded parameter initialisation: the same config and seed give the same network on every
//! backend and machine (burn's own initialisers draw from a process-wide generator, which
//! parallel tests and runs would interleave).

use burn::module::Param;
use burn::nn::Linear;
use burn::prelude::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Negative slope of every LeakyReLU in GarNet (paper section 3.4).
pub const LEAKY_SLOPE: f64 = 0.1;

/// Scale of the initial weights of a per-sample (global feature) input against He
/// initialisation: max-pooled features are large and positive (mean ~5 at init), so at full
/// scale their bias outweighs the per-point term ~5x.
pub(crate) const COND_GAIN: f32 = 0.2;

/// A seeded source of initial parameter values.
pub(crate) struct ParamInit {
    rng: StdRng,
}

impl ParamInit {
    /// A generator seeded with `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        ParamInit {
            rng: StdRng::seed_from_u64(seed),
        }
    }

    /// `n` values uniform in `[-bound, bound]`.
    fn uniform(&mut self, n: usize, bound: f32) -> Vec<f32> {
        (0..n)
            .map(|_| self.rng.random_range(-bound..=bound))
            .collect()
    }

    /// A fully connected layer `d_in -> d_out` (weight `[d_in, d_out]`, bias `[d_out]`)
    /// followed by a LeakyReLU(0.1): weights He-uniform for that slope,
    /// `bound = sqrt(6 / ((1 + 0.1^2) d_in))`, bias uniform in `+-1/sqrt(d_in)` (PyTorch's).
    pub(crate) fn hidden(&mut self, d_in: usize, d_out: usize, device: &Device) -> Linear {
        let gain = (6.0 / ((1.0 + LEAKY_SLOPE * LEAKY_SLOPE) * d_in as f64)).sqrt() as f32;
        self.linear(d_in, d_out, gain, Some(1.0 / (d_in as f32).sqrt()), device)
    }

    /// [`ParamInit::hidden`] for an input that is the concatenation of a per-point part
    /// (`d_point` rows of the weight) and a per-sample part (`d_cond` rows): the two weight
    /// blocks `[d_point, d_out]`, `[d_cond, d_out]` and the bias `[d_out]`. Each block is
    /// He-uniform for its own fan-in, the per-sample block scaled by [`COND_GAIN`]: one
    /// initialisation over the whole input (fan-in `d_point + d_cond`) shrinks the per-point
    /// weights by `sqrt(d_cond / d_point)` (13x for 3 coordinates beside a 512-d body
    /// feature), and the garment's vertices became indistinguishable behind the per-sample
    /// bias (measured: per-vertex feature spread 240x under the bias).
    pub(crate) fn hidden_split(
        &mut self,
        d_point: usize,
        d_cond: usize,
        d_out: usize,
        device: &Device,
    ) -> (Linear, Linear) {
        let he = |fan_in: usize| {
            (6.0 / ((1.0 + LEAKY_SLOPE * LEAKY_SLOPE) * fan_in as f64)).sqrt() as f32
        };
        let wp = self.uniform(d_point * d_out, he(d_point));
        let wc = self.uniform(d_cond * d_out, he(d_cond) * COND_GAIN);
        let tensor = |v: Vec<f32>, rows: usize| {
            Param::from_tensor(Tensor::from_data(TensorData::new(v, [rows, d_out]), device))
        };
        let point = Linear {
            weight: tensor(wp, d_point),
            bias: Some(self.vector(d_out, 1.0 / (d_point as f32).sqrt(), device)),
        };
        let cond = Linear {
            weight: tensor(wc, d_cond),
            bias: None,
        };
        (point, cond)
    }

    /// A layer without bias, weights uniform in `+-1/sqrt(d_in)`.
    pub(crate) fn no_bias(&mut self, d_in: usize, d_out: usize, device: &Device) -> Linear {
        self.linear(d_in, d_out, 1.0 / (d_in as f32).sqrt(), None, device)
    }

    /// A layer with weights uniform in `+-scale/sqrt(d_in)` and a zero bias: `scale = 0` gives
    /// the zero layer the spatial transformers end with (they start as the identity), a small
    /// `scale` the output layer that starts GarNet near "no translation".
    pub(crate) fn scaled(
        &mut self,
        d_in: usize,
        d_out: usize,
        scale: f32,
        device: &Device,
    ) -> Linear {
        let mut layer = self.linear(d_in, d_out, scale / (d_in as f32).sqrt(), None, device);
        layer.bias = Some(Param::from_tensor(Tensor::zeros([d_out], device)));
        layer
    }

    /// A vector `[n]` uniform in `+-bound`.
    pub(crate) fn vector(&mut self, n: usize, bound: f32, device: &Device) -> Param<Tensor<1>> {
        let values = self.uniform(n, bound);
        Param::from_tensor(Tensor::from_data(TensorData::new(values, [n]), device))
    }

    fn linear(
        &mut self,
        d_in: usize,
        d_out: usize,
        weight_bound: f32,
        bias_bound: Option<f32>,
        device: &Device,
    ) -> Linear {
        let w = self.uniform(d_in * d_out, weight_bound);
        let weight =
            Param::from_tensor(Tensor::from_data(TensorData::new(w, [d_in, d_out]), device));
        let bias = bias_bound.map(|b| self.vector(d_out, b, device));
        Linear { weight, bias }
    }
}
