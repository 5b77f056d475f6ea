//! Growing a trained network: extra residual blocks of mesh convolutions appended to the
//! garment stream ([`GarNetConfig::extra_blocks`]), each starting as the identity, so the
//! grown network drapes exactly as its parent and training goes on from there with more
//! depth, instead of starting a deeper network from scratch; and wider layers
//! ([`crate::widen`]), likewise draping as before.

use std::path::Path;

use burn::module::Module;
use burn::prelude::*;

use crate::checkpoint::{load_checkpoint, save_checkpoint};
use crate::config::GarNetConfig;
use crate::error::{ModelError, Result};
use crate::garment_stream::ExtraBlock;
use crate::garnet::GarNet;
use crate::widen::widen_network;

/// `model` (built from `config`) with `extra` more identity-initialised blocks on `device`,
/// and its config. GarNet-Naive, without mesh convolutions, is refused.
pub fn grow_network(
    mut model: GarNet,
    config: &GarNetConfig,
    extra: usize,
    device: &Device,
) -> Result<(GarNet, GarNetConfig)> {
    if !config.variant.has_mesh_conv() {
        return Err(ModelError::InvalidInput(
            "GarNet-Naive has no mesh convolutions to grow".into(),
        ));
    }
    if model.garment.extra.len() != config.extra_blocks {
        return Err(ModelError::InvalidInput(format!(
            "the network has {} extra blocks, its config says {}",
            model.garment.extra.len(),
            config.extra_blocks
        )));
    }
    let grown = config
        .clone()
        .with_extra_blocks(config.extra_blocks + extra);
    grown.validate()?;
    for i in config.extra_blocks..grown.extra_blocks {
        model.garment.extra.push(ExtraBlock::new(
            config.conv_width,
            config.conv_heads,
            config.seed,
            i,
            device,
        ));
    }
    Ok((model, grown))
}

/// How to grow a trained network: wider layers first ([`crate::widen`]), then more blocks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GrowPlan {
    /// Residual blocks to append ([`grow_network`]).
    pub extra_blocks: usize,
    /// Features of the mesh convolutions, if wider than the network's.
    pub conv_width: Option<usize>,
    /// Hidden widths of the fusion network, if wider than the network's.
    pub fusion: Option<Vec<usize>>,
}

/// Reads the checkpoint `input`, grows its network as `plan` says and writes it to `out`
/// without optimiser state (a resumed run starts Adam afresh). Progress (but not that of an
/// epoch it stopped inside: a run from it begins its next epoch afresh) and the best
/// validation figure carry over (the grown network drapes as its parent); `command` is
/// recorded after the training command. Returns the grown network's parameter count.
pub fn grow_checkpoint(input: &Path, out: &Path, plan: &GrowPlan, command: &str) -> Result<usize> {
    if plan.extra_blocks == 0 && plan.conv_width.is_none() && plan.fusion.is_none() {
        return Err(ModelError::InvalidInput(
            "growing needs extra blocks or wider layers".into(),
        ));
    }
    let ck = load_checkpoint(input)?;
    let device = Device::flex();
    let mut config = ck.setup.config.clone();
    let mut model = ck.model(&device)?;
    if plan.conv_width.is_some() || plan.fusion.is_some() {
        let conv_width = plan.conv_width.unwrap_or(config.conv_width);
        let fusion = plan.fusion.clone().unwrap_or_else(|| config.fusion.clone());
        (model, config) = widen_network(model, &config, conv_width, &fusion, &device)?;
    }
    if plan.extra_blocks > 0 {
        (model, config) = grow_network(model, &config, plan.extra_blocks, &device)?;
    }
    let mut setup = ck.setup;
    setup.config = config;
    let mut state = ck.state;
    // Not the network any epoch stopped in: a run from it begins its next epoch afresh.
    state.partial = None;
    state.append_command(command);
    save_checkpoint(out, &model, None, &setup, &ck.loss, &state)?;
    Ok(model.num_params())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Variant;

    #[test]
    fn naive_and_zero_blocks_are_refused() {
        let device = Device::flex();
        let cfg = GarNetConfig::tiny(Variant::Naive);
        let net = cfg.init(&device).unwrap();
        assert!(grow_network(net, &cfg, 2, &device).is_err());
        assert!(GarNetConfig::tiny(Variant::Naive)
            .with_extra_blocks(1)
            .validate()
            .is_err());
    }

    #[test]
    fn grown_network_equals_a_fresh_network_of_the_grown_config_in_its_new_blocks() {
        let device = Device::flex();
        let cfg = GarNetConfig::tiny(Variant::Global).with_extra_blocks(1);
        let (grown, grown_cfg) =
            grow_network(cfg.init(&device).unwrap(), &cfg, 2, &device).unwrap();
        assert_eq!(grown_cfg.extra_blocks, 3);
        let fresh = grown_cfg.init(&device).unwrap();
        assert_eq!(grown.num_params(), fresh.num_params());
        let values = |m: &GarNet| crate::average::parameter_values(m).unwrap();
        assert_eq!(values(&grown), values(&fresh));
        let w = |b: &ExtraBlock| crate::tensors::read_f32(b.conv.w.weight.val()).unwrap();
        assert!(w(&grown.garment.extra[2]).iter().all(|&v| v == 0.0));
        // Each block draws its own assignment directions.
        let u = |b: &ExtraBlock| crate::tensors::read_f32(b.conv.u.weight.val()).unwrap();
        assert_ne!(u(&grown.garment.extra[1]), u(&grown.garment.extra[2]));
    }
}
