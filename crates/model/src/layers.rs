//! Small building blocks: shared per-point MLPs, layers conditioned on a per-sample vector,
//! LeakyReLU and max pooling over points.

use burn::nn::Linear;
use burn::prelude::*;

use crate::dense_rows::{chain_tensors, HostLayer};
use crate::error::Result;
use crate::init::{ParamInit, LEAKY_SLOPE};
use crate::tensors::read_f32;

/// LeakyReLU with GarNet's slope 0.1. On a tensor tracked by autodiff, as `x * s` with the
/// slope `s` (1 where `x >= 0`, else 0.1) computed outside the graph: the same values and
/// gradients as burn's `leaky_relu` (slope 1 at 0 included), whose flex backward (a masked
/// select) took 61 ms forward and backward on a `[1,3345,512]` tensor against 1.9 ms for
/// this (2 loaded cores). Without gradients burn's own single-pass `leaky_relu` is faster
/// (the product form made a 1.4k-vertex GarNet-Local drape ~40% slower). Untracked tensors
/// (inference) take that path.
pub fn lrelu<const D: usize>(x: Tensor<D>) -> Tensor<D> {
    if !x.is_tracked() {
        return burn::tensor::activation::leaky_relu(x, LEAKY_SLOPE);
    }
    let slope =
        x.clone().detach().greater_equal_elem(0.0).float() * (1.0 - LEAKY_SLOPE) + LEAKY_SLOPE;
    x * slope
}

/// `parts` `[B,P,d_i]` concatenated along the features (the one part itself).
pub fn cat_features(mut parts: Vec<Tensor<3>>) -> Tensor<3> {
    match parts.len() {
        1 => parts.remove(0),
        _ => Tensor::cat(parts, 2),
    }
}

/// Element-wise maximum of `a` and `b` (same shape) as `a m + b (1 - m)`, `m = [a > b]`
/// computed outside the graph: exact for finite inputs, the gradient to exactly one side
/// (to `b` on ties), and a product instead of flex's masked select (`max_pair`: 67 ms
/// forward and backward on a `[1,3345,512]` pair, this a few ms). Without gradients,
/// `max_pair` itself.
pub fn maximum<const D: usize>(a: Tensor<D>, b: Tensor<D>) -> Tensor<D> {
    if !a.is_tracked() && !b.is_tracked() {
        return a.max_pair(b);
    }
    let m = a.clone().detach().greater(b.clone().detach()).float();
    let rest = m.clone().neg() + 1.0;
    a * m + b * rest
}

/// Max over the points of `x` `[B,P,C]`: `[B,C]`, per sample with [`max_rows`].
pub fn max_points(x: Tensor<3>) -> Tensor<2> {
    let [b, p, c] = x.dims();
    let per_sample: Vec<Tensor<2>> = (0..b)
        .map(|i| max_rows(x.clone().narrow(0, i, 1).reshape([p, c])))
        .collect();
    if b == 1 {
        per_sample.into_iter().next().expect("one sample")
    } else {
        Tensor::cat(per_sample, 0)
    }
}

/// Max over the rows of `x` `[P,C]`: `[1,C]`, as a halving tree of element-wise maxima (the
/// first `ceil(len/2)` rows against the last `ceil(len/2)`, which overlap by one row when
/// `len` is odd, harmless for a maximum) over contiguous row blocks. On flex, `max_dim(0)`
/// costs ~3 ns per element (10 ms for the 6690 x 512 body features) against ~0.4 ns here;
/// gradients flow through [`maximum`] to exactly one of each compared pair, as through
/// `max_dim`.
pub fn max_rows(x: Tensor<2>) -> Tensor<2> {
    let mut x = x;
    let mut len = x.dims()[0];
    while len > 1 {
        let half = len.div_ceil(2);
        let a = x.clone().narrow(0, 0, half);
        let b = x.narrow(0, len - half, half);
        x = maximum(a, b);
        len = half;
    }
    x
}

/// A shared per-point MLP (1x1 convolutions): each layer is a fully connected layer applied to
/// every point, then LeakyReLU(0.1).
#[derive(Module, Debug)]
pub struct PointMlp {
    /// The layers, input to output.
    pub layers: Vec<Linear>,
}

impl PointMlp {
    /// An MLP `d_in -> widths[0] -> ... -> widths[last]`.
    pub(crate) fn new(
        d_in: usize,
        widths: &[usize],
        init: &mut ParamInit,
        device: &Device,
    ) -> Self {
        let mut layers = Vec::with_capacity(widths.len());
        let mut d = d_in;
        for &w in widths {
            layers.push(init.hidden(d, w, device));
            d = w;
        }
        PointMlp { layers }
    }

    /// `x` `[B,P,d_in]` -> `[B,P,widths[last]]`.
    pub fn forward<const D: usize>(&self, x: Tensor<D>) -> Tensor<D> {
        self.layers
            .iter()
            .fold(x, |x, layer| lrelu(layer.forward(x)))
    }

    /// The layers on the host, LeakyReLU after each (see [`crate::dense_rows`]).
    pub fn host_layers(&self) -> Result<Vec<HostLayer>> {
        self.layers
            .iter()
            .map(|l| HostLayer::read(l, true))
            .collect()
    }

    /// [`PointMlp::forward`] of `parts` `[B,P,d_i]` concatenated along the features (`d_in`
    /// in all) -> `[B,P,d_out]`; as plain loops where the parts are untracked on flex
    /// ([`crate::dense_rows`]: never concatenated), with burn's ops otherwise.
    pub fn rows(&self, parts: Vec<Tensor<3>>) -> Tensor<3> {
        match chain_tensors(&parts, || self.host_layers(), true, false) {
            Some((Some(rows), _)) => rows,
            _ => self.forward(cat_features(parts)),
        }
    }

    /// The max pooling `[B,d_out]` of [`PointMlp::rows`], where the plain loops never write
    /// the rows out.
    pub fn pooled(&self, parts: Vec<Tensor<3>>) -> Tensor<2> {
        match chain_tensors(&parts, || self.host_layers(), false, true) {
            Some((_, Some(pooled))) => pooled,
            _ => max_points(self.forward(cat_features(parts))),
        }
    }

    /// [`PointMlp::rows`] and their max pooling, in one pass of the plain loops.
    pub fn rows_and_pooled(&self, parts: Vec<Tensor<3>>) -> (Tensor<3>, Tensor<2>) {
        match chain_tensors(&parts, || self.host_layers(), true, true) {
            Some((Some(rows), Some(pooled))) => (rows, pooled),
            _ => {
                let rows = self.forward(cat_features(parts));
                (rows.clone(), max_points(rows))
            }
        }
    }

    /// Output width.
    pub fn d_out(&self) -> usize {
        self.layers
            .last()
            .map(|l| l.weight.val().dims()[1])
            .unwrap_or(0)
    }
}

/// A per-point layer whose input is the point's features concatenated with a per-sample
/// vector `c` (the same for every point of a sample). `W [x; c] + b = W_x x + (W_c c + b)`, so
/// the per-sample part is computed once per sample and added as a bias instead of being
/// concatenated to every point.
#[derive(Module, Debug)]
pub struct CondLinear {
    /// `W_x` and `b`: `[d_point, d_out]`, `[d_out]`.
    pub point: Linear,
    /// `W_c`: `[d_cond, d_out]`, no bias.
    pub cond: Linear,
}

impl CondLinear {
    pub(crate) fn new(
        d_point: usize,
        d_cond: usize,
        d_out: usize,
        init: &mut ParamInit,
        device: &Device,
    ) -> Self {
        let (point, cond) = init.hidden_split(d_point, d_cond, d_out, device);
        CondLinear { point, cond }
    }

    /// The layer on the host for the samples of `c` `[B,d_cond]`: `W_x`, `b` and the
    /// per-sample bias `W_c c`, LeakyReLU after when `lrelu` (see [`crate::dense_rows`]).
    pub fn host_layer(&self, c: Tensor<2>, lrelu: bool) -> Result<HostLayer> {
        let per_sample = read_f32(self.cond.forward(c))?;
        Ok(HostLayer::read(&self.point, lrelu)?.with_sample_bias(&per_sample))
    }

    /// The per-sample bias `W_c c`: `c` `[B,d_cond]` -> `[B,1,d_out]`.
    pub fn cond_bias(&self, c: Tensor<2>) -> Tensor<3> {
        self.cond.forward(c).unsqueeze_dim(1)
    }

    /// `W_x x + b + bias`: `x` `[B,P,d_point]`, `bias` `[B,1,d_out]` -> `[B,P,d_out]`
    /// (no activation).
    pub fn forward(&self, x: Tensor<3>, bias: Tensor<3>) -> Tensor<3> {
        self.point.forward(x) + bias
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tensors::read_f32;

    /// Values and gradients of [`lrelu`] and [`maximum`] against burn's `leaky_relu` and
    /// `max_pair` (the plain references), zeros and ties included.
    #[test]
    fn lrelu_and_maximum_match_burn() {
        use burn::tensor::activation::leaky_relu;
        let device = Device::flex().autodiff();
        let x = Tensor::<2>::random([9, 37], burn::tensor::Distribution::Default, &device) - 0.5;
        let x = Tensor::cat(vec![x, Tensor::zeros([1, 37], &device)], 0).require_grad();
        let w = Tensor::<2>::random([10, 37], burn::tensor::Distribution::Default, &device);
        let check = |ours: Tensor<2>, theirs: Tensor<2>, of: &[Tensor<2>]| {
            assert_eq!(
                read_f32(ours.clone()).unwrap(),
                read_f32(theirs.clone()).unwrap()
            );
            let g1 = (ours * w.clone()).sum().backward();
            let g2 = (theirs * w.clone()).sum().backward();
            for t in of {
                assert_eq!(
                    read_f32(t.grad(&g1).unwrap()).unwrap(),
                    read_f32(t.grad(&g2).unwrap()).unwrap()
                );
            }
        };
        check(
            lrelu(x.clone()),
            leaky_relu(x.clone(), LEAKY_SLOPE),
            std::slice::from_ref(&x),
        );
        // Without gradients: the same values (the plain path).
        let plain = x.clone().inner();
        assert_eq!(
            read_f32(lrelu(plain.clone())).unwrap(),
            read_f32(leaky_relu(plain.clone(), LEAKY_SLOPE)).unwrap()
        );
        assert_eq!(
            read_f32(maximum(plain.clone(), plain.clone() * 0.5)).unwrap(),
            read_f32(plain.clone().max_pair(plain * 0.5)).unwrap()
        );
        // Every third entry of b ties with a.
        let b = Tensor::<2>::random([10, 37], burn::tensor::Distribution::Default, &device);
        let tie = Tensor::<2>::from_data(
            TensorData::new(
                (0..370).map(|i| (i % 3 == 0) as u8 as f32).collect(),
                [10, 37],
            ),
            &device,
        );
        let b = (x.clone().detach() * tie.clone() + b * (tie.neg() + 1.0)).into_data();
        let b = Tensor::<2>::from_data(b, &device).require_grad();
        check(
            maximum(x.clone(), b.clone()),
            b.clone().max_pair(x.clone()),
            &[x, b],
        );
    }

    #[test]
    fn max_points_equals_max_dim_with_the_same_gradient() {
        let device = Device::flex().autodiff();
        for (b, p, c) in [(1, 1, 3), (2, 7, 5), (3, 64, 4), (1, 1001, 2)] {
            let x = Tensor::<3>::random([b, p, c], burn::tensor::Distribution::Default, &device)
                .require_grad();
            let ours = max_points(x.clone());
            let theirs: Tensor<2> = x.clone().max_dim(1).reshape([b, c]);
            assert_eq!(
                read_f32(ours.clone()).unwrap(),
                read_f32(theirs.clone()).unwrap()
            );
            let g1 = x.grad(&(ours.sum() * 2.0).backward()).unwrap();
            let g2 = x.grad(&(theirs.sum() * 2.0).backward()).unwrap();
            assert_eq!(
                read_f32(g1).unwrap(),
                read_f32(g2).unwrap(),
                "[{b},{p},{c}]"
            );
        }
    }
}
