//! Weight averaging of networks of one architecture: the parameters of several checkpoints
//! of one run (say the last epochs of a run at a low constant learning rate) averaged
//! element by element into one network, as stochastic weight averaging (Izmailov et al.
//! 2018) and checkpoint averaging in machine translation do. The averaged network drapes as
//! fast as any of them, unlike an ensemble of their outputs.
//!
//! burn has no averaging of modules; this reads every float parameter in the order
//! [`Module::visit`] walks them and writes the means back with [`Module::map`] in the same
//! order, so the result keeps the first network's structure and parameter ids.

use std::path::Path;

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::prelude::*;

use crate::checkpoint::{load_checkpoint, save_checkpoint, ModelSetup, TrainState};
use crate::error::{ModelError, Result};
use crate::garnet::GarNet;
use crate::loss::LossConfig;
use crate::tensors::read_f32;

/// One float parameter read back: its shape and row-major values.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamValues {
    /// Tensor shape.
    pub shape: Vec<usize>,
    /// Row-major values.
    pub values: Vec<f32>,
}

/// Collects every float parameter of a module, in visiting order.
struct Collect {
    params: Vec<ParamValues>,
    error: Option<String>,
}

impl ModuleVisitor for Collect {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let t = param.val();
        let shape = t.dims().to_vec();
        match read_f32(t) {
            Ok(values) => self.params.push(ParamValues { shape, values }),
            Err(e) => self.error = Some(e.to_string()),
        }
    }
}

/// Every float parameter of `module` (shape and values), in the order burn visits them.
pub fn parameter_values<M: Module>(module: &M) -> Result<Vec<ParamValues>> {
    let mut c = Collect {
        params: Vec::new(),
        error: None,
    };
    module.visit(&mut c);
    match c.error {
        Some(e) => Err(ModelError::InvalidInput(format!(
            "reading a parameter: {e}"
        ))),
        None => Ok(c.params),
    }
}

/// Replaces the float parameters of a module, in visiting order, by given values.
struct Replace {
    next: std::vec::IntoIter<ParamValues>,
}

impl ModuleMapper for Replace {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        let p = self
            .next
            .next()
            .expect("one value per parameter: counted before mapping");
        param.map(|t| {
            let device = t.device();
            let shape: [usize; D] = p.shape.try_into().expect("shape checked before mapping");
            Tensor::from_data(TensorData::new(p.values, shape), &device)
        })
    }
}

/// The element-wise mean of `networks` (at least one, all of one architecture), on the
/// device of the first: each parameter is the mean of the networks' values, summed in f64.
/// Networks whose parameters differ in number or shape are an error.
pub fn average_networks(networks: &[GarNet]) -> Result<GarNet> {
    weighted_sum(networks, &vec![1.0; networks.len()], networks.len() as f64)
}

/// The affine combination `sum_k weights[k] * networks[k]` of networks of one architecture,
/// element by element, summed in f64, on the device of the first. The weights (one per
/// network, finite, summing to 1 within 1e-6) may be unequal, to weigh some snapshots more,
/// or negative, to extrapolate along the line from one network through another
/// (`[-1, 2]`: twice the step from the first to the second). Other weights, and networks
/// whose parameters differ in number or shape, are an error.
pub fn combine_networks(networks: &[GarNet], weights: &[f64]) -> Result<GarNet> {
    check_weights(weights, networks.len())?;
    weighted_sum(networks, weights, 1.0)
}

/// `sum_k weights[k] * networks[k] / divisor`, element by element, summed in f64 (the mean
/// divides once at the end, so that it stays the plain mean bit for bit).
fn weighted_sum(networks: &[GarNet], weights: &[f64], divisor: f64) -> Result<GarNet> {
    let first = networks
        .first()
        .ok_or_else(|| ModelError::InvalidInput("no networks to average".into()))?;
    let mut sums: Vec<(Vec<usize>, Vec<f64>)> = parameter_values(first)?
        .into_iter()
        .map(|p| (p.shape, vec![0.0; p.values.len()]))
        .collect();
    for (k, (net, &w)) in networks.iter().zip(weights).enumerate() {
        let params = parameter_values(net)?;
        if params.len() != sums.len() {
            return Err(ModelError::InvalidInput(format!(
                "network {} has {} parameter tensors, network 1 has {}",
                k + 1,
                params.len(),
                sums.len()
            )));
        }
        for (i, (p, (shape, sum))) in params.iter().zip(sums.iter_mut()).enumerate() {
            if &p.shape != shape {
                return Err(ModelError::InvalidInput(format!(
                    "parameter {i} of network {} has shape {:?}, network 1's {:?}",
                    k + 1,
                    p.shape,
                    shape
                )));
            }
            for (s, &v) in sum.iter_mut().zip(&p.values) {
                *s += w * v as f64;
            }
        }
    }
    let combined: Vec<ParamValues> = sums
        .into_iter()
        .map(|(shape, sum)| ParamValues {
            shape,
            values: sum.into_iter().map(|s| (s / divisor) as f32).collect(),
        })
        .collect();
    Ok(first.clone().map(&mut Replace {
        next: combined.into_iter(),
    }))
}

/// Checks that `weights` are `n` finite numbers summing to 1 (within 1e-6): an affine
/// combination, so a network combined with itself stays itself.
fn check_weights(weights: &[f64], n: usize) -> Result<()> {
    if weights.len() != n {
        return Err(ModelError::InvalidInput(format!(
            "{} weights for {n} networks: give one weight per network",
            weights.len()
        )));
    }
    if let Some(w) = weights.iter().find(|w| !w.is_finite()) {
        return Err(ModelError::InvalidInput(format!(
            "weight {w} is not a finite number"
        )));
    }
    let total: f64 = weights.iter().sum();
    if (total - 1.0).abs() > 1e-6 {
        return Err(ModelError::InvalidInput(format!(
            "the weights {weights:?} sum to {total}, not 1"
        )));
    }
    Ok(())
}

/// What [`average_checkpoints`] wrote.
#[derive(Clone, Debug)]
pub struct AverageReport {
    /// The epochs of the averaged checkpoints, in the order given.
    pub epochs: Vec<usize>,
    /// Parameters per network.
    pub parameters: usize,
}

/// Averages the networks of the checkpoints `inputs` (at least two, each written for the
/// same setup and loss: architecture, template, body sampling) and writes the mean network
/// to `out` without optimiser state (a resumed run starts Adam afresh). With `weights`
/// (one per input, summing to 1; see [`combine_networks`]) it writes that weighted
/// combination instead of the plain mean. The written
/// progress is the last input's, without a best validation figure nor an epoch stopped
/// inside (a run from it begins its next epoch afresh), and its command is the last input's
/// followed by `command`. Its training drapes ([`TrainState::train_drapes`]) are the ones
/// `train_drapes` reads from every input's progress when they all agree, else unrecorded.
pub fn average_checkpoints(
    inputs: &[&Path],
    weights: Option<&[f64]>,
    out: &Path,
    command: &str,
    train_drapes: impl Fn(&TrainState) -> Option<String>,
) -> Result<AverageReport> {
    if inputs.len() < 2 {
        return Err(ModelError::InvalidInput(format!(
            "averaging needs at least two checkpoints, got {}",
            inputs.len()
        )));
    }
    if let Some(w) = weights {
        check_weights(w, inputs.len())?;
    }
    let device = Device::flex();
    let mut networks = Vec::with_capacity(inputs.len());
    let mut epochs = Vec::with_capacity(inputs.len());
    let mut drapes = Vec::with_capacity(inputs.len());
    let mut reference: Option<(ModelSetup, LossConfig, TrainState)> = None;
    for path in inputs {
        let ck = load_checkpoint(path)?;
        if let Some((setup, loss, _)) = &reference {
            let what = if ck.setup != *setup {
                Some("network setup (architecture, garment template or body sampling)")
            } else if ck.loss != *loss {
                Some("loss")
            } else {
                None
            };
            if let Some(what) = what {
                return Err(ModelError::checkpoint(
                    path,
                    format!(
                        "its {what} differs from {}'s: not averageable",
                        inputs[0].display()
                    ),
                ));
            }
        }
        networks.push(ck.model(&device)?);
        epochs.push(ck.state.epoch);
        drapes.push(train_drapes(&ck.state));
        reference = Some((ck.setup, ck.loss, ck.state));
    }
    let (setup, loss, mut state) = reference.expect("at least two inputs");
    let mean = match weights {
        Some(w) => combine_networks(&networks, w)?,
        None => average_networks(&networks)?,
    };
    state.best_e_dist_cm = None;
    state.validation = None;
    state.averaged_epochs = epochs.clone();
    state.averaged_weights = weights.map(<[f64]>::to_vec).unwrap_or_default();
    // Not the network any epoch stopped in: a run from it begins its next epoch afresh.
    state.partial = None;
    state.train_drapes = drapes[0]
        .clone()
        .filter(|_| drapes.windows(2).all(|w| w[0] == w[1]));
    state.append_command(command);
    save_checkpoint(out, &mean, None, &setup, &loss, &state)?;
    Ok(AverageReport {
        epochs,
        parameters: mean.num_params(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{GarNetConfig, Variant};

    fn net(seed: u64) -> GarNet {
        let mut cfg = GarNetConfig::tiny(Variant::Local);
        cfg.seed = seed;
        cfg.init(&Device::flex()).unwrap()
    }

    #[test]
    fn mean_of_two_networks_matches_a_plain_loop() {
        let (a, b) = (net(1), net(2));
        let (pa, pb) = (parameter_values(&a).unwrap(), parameter_values(&b).unwrap());
        assert_ne!(pa, pb, "different seeds give different networks");
        let mean = parameter_values(&average_networks(&[a, b]).unwrap()).unwrap();
        assert_eq!(mean.len(), pa.len());
        for ((m, x), y) in mean.iter().zip(&pa).zip(&pb) {
            assert_eq!(m.shape, x.shape);
            for ((&m, &x), &y) in m.values.iter().zip(&x.values).zip(&y.values) {
                let plain = ((x as f64 + y as f64) / 2.0) as f32;
                assert_eq!(m.to_bits(), plain.to_bits());
            }
        }
    }

    #[test]
    fn mean_of_copies_is_the_network_bit_for_bit() {
        let a = net(3);
        let mean = average_networks(&[a.clone(), a.clone(), a.clone()]).unwrap();
        assert_eq!(
            parameter_values(&mean).unwrap(),
            parameter_values(&a).unwrap()
        );
    }

    #[test]
    fn weighted_combination_matches_a_plain_loop() {
        let (a, b, c) = (net(1), net(2), net(3));
        let weights = [-0.5, 1.25, 0.25];
        let (pa, pb, pc) = (
            parameter_values(&a).unwrap(),
            parameter_values(&b).unwrap(),
            parameter_values(&c).unwrap(),
        );
        let combined = parameter_values(&combine_networks(&[a, b, c], &weights).unwrap()).unwrap();
        for (i, m) in combined.iter().enumerate() {
            for (j, &m) in m.values.iter().enumerate() {
                let (x, y, z) = (pa[i].values[j], pb[i].values[j], pc[i].values[j]);
                let expected =
                    (weights[0] * x as f64 + weights[1] * y as f64 + weights[2] * z as f64) as f32;
                assert_eq!(m.to_bits(), expected.to_bits());
            }
        }
    }

    #[test]
    fn weights_must_be_one_per_network_and_sum_to_one() {
        let (a, b) = (net(1), net(2));
        let nets = [a.clone(), b];
        for (weights, says) in [
            (vec![1.0], "1 weights for 2 networks"),
            (vec![0.5, 0.6], "sum to"),
            (vec![f64::NAN, 1.0], "not a finite number"),
        ] {
            let err = combine_networks(&nets, &weights).unwrap_err().to_string();
            assert!(err.contains(says), "{err}");
        }
        let same = combine_networks(&[a.clone(), a.clone()], &[-1.0, 2.0]).unwrap();
        assert_eq!(
            parameter_values(&same).unwrap(),
            parameter_values(&a).unwrap()
        );
    }

    #[test]
    fn networks_of_other_widths_are_refused() {
        let mut wide = GarNetConfig::tiny(Variant::Local);
        wide.fusion[0] += 4;
        let other = wide.init(&Device::flex()).unwrap();
        let err = average_networks(&[net(1), other]).unwrap_err().to_string();
        assert!(err.contains("shape"), "{err}");
        assert!(average_networks(&[]).is_err());
    }
}
