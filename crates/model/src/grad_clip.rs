//! Global gradient-norm clipping, as PyTorch's `clip_grad_norm_`: every gradient of the
//! network is scaled by one factor so that the L2 norm over all of them together is at most
//! a threshold. burn's own `GradientClipping::Norm` clips each parameter tensor on its own,
//! which changes the direction of the step; this keeps it.

use burn::module::{Module, ModuleVisitor, Param};
use burn::optim::GradientsParams;
use burn::prelude::*;

use crate::error::Result;
use crate::tensors::read_scalar;

/// Sums the squared gradients of the parameters it visits.
struct SquaredSum<'a> {
    grads: &'a GradientsParams,
    sum: Option<Tensor<1>>,
}

impl ModuleVisitor for SquaredSum<'_> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        if let Some(g) = self.grads.get::<D>(param.id) {
            let s = g.powi_scalar(2).sum();
            self.sum = Some(match self.sum.take() {
                Some(acc) => acc + s,
                None => s,
            });
        }
    }
}

/// Multiplies the gradients of the parameters it visits by a factor.
struct Scale<'a> {
    grads: &'a mut GradientsParams,
    factor: f32,
}

impl ModuleVisitor for Scale<'_> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        if let Some(g) = self.grads.remove::<D>(param.id) {
            self.grads.register(param.id, g.mul_scalar(self.factor));
        }
    }
}

/// The L2 norm over all gradients in `grads` of `module`'s float parameters (0 when there
/// are none), in the loss's units per parameter unit.
pub fn gradient_norm<M: Module>(module: &M, grads: &GradientsParams) -> Result<f32> {
    let mut v = SquaredSum { grads, sum: None };
    module.visit(&mut v);
    match v.sum {
        Some(s) => Ok(read_scalar(s)?.sqrt()),
        None => Ok(0.0),
    }
}

/// Scales all of `module`'s gradients in `grads` by one factor so that their joint L2 norm
/// is at most `max_norm` (nothing changes when it already is, or when `max_norm` is `None`).
/// Returns the norm before clipping.
pub fn clip_gradient_norm<M: Module>(
    module: &M,
    grads: &mut GradientsParams,
    max_norm: Option<f32>,
) -> Result<f32> {
    let norm = gradient_norm(module, grads)?;
    if let Some(max) = max_norm {
        if norm.is_finite() && norm > max {
            let mut s = Scale {
                grads,
                factor: max / norm,
            };
            module.visit(&mut s);
        }
    }
    Ok(norm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::nn::{Linear, LinearConfig};

    /// Gradients of sum(w.x + b) for a 3 -> 2 linear layer and a fixed input.
    fn layer_and_grads() -> (Linear, GradientsParams) {
        let device = Device::flex().autodiff();
        let layer = LinearConfig::new(3, 2).init(&device);
        let x = Tensor::<2>::from_floats([[1.0, -2.0, 2.0], [0.5, 0.0, 1.0]], &device);
        let grads = layer.forward(x).sum().backward();
        let grads = GradientsParams::from_grads(grads, &layer);
        (layer, grads)
    }

    /// The plain reference: d/dW of sum(Wx + b) over the two rows is, for each output, the
    /// column sums of x (1.5, -2, 3), and d/db is the row count (2) for each output.
    fn expected_norm() -> f32 {
        let per_output = 1.5f32 * 1.5 + 4.0 + 9.0 + 2.0 * 2.0;
        (2.0 * per_output).sqrt()
    }

    fn bias_grad(layer: &Linear, grads: &GradientsParams) -> Vec<f32> {
        let id = layer.bias.as_ref().unwrap().id;
        crate::tensors::read_f32(grads.get::<1>(id).unwrap()).unwrap()
    }

    #[test]
    fn norm_matches_the_hand_computed_gradients() {
        let (layer, grads) = layer_and_grads();
        let n = gradient_norm(&layer, &grads).unwrap();
        assert!((n - expected_norm()).abs() < 1e-5, "{n}");
    }

    #[test]
    fn clipping_scales_every_gradient_by_one_factor() {
        let (layer, mut grads) = layer_and_grads();
        let bias_before = bias_grad(&layer, &grads);
        let before = clip_gradient_norm(&layer, &mut grads, Some(1.0)).unwrap();
        assert!((before - expected_norm()).abs() < 1e-5);
        let after = gradient_norm(&layer, &grads).unwrap();
        assert!((after - 1.0).abs() < 1e-5, "{after}");
        let bias_after = bias_grad(&layer, &grads);
        for (a, b) in bias_after.iter().zip(&bias_before) {
            assert!((a - b / before).abs() < 1e-6, "{a} vs {b}");
        }
    }

    #[test]
    fn no_threshold_or_a_large_one_leaves_the_gradients_alone() {
        for max in [None, Some(100.0)] {
            let (layer, mut grads) = layer_and_grads();
            let n = clip_gradient_norm(&layer, &mut grads, max).unwrap();
            assert_eq!(n, gradient_norm(&layer, &grads).unwrap());
        }
    }
}
