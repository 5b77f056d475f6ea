//! Inference: drape the trained garment on a body.

use std::path::Path;

use burn::prelude::*;
use glam::Vec3;

use crate::batch::InputSpec;
use crate::checkpoint::{load_checkpoint, ModelSetup};
use crate::error::{check_count, check_finite, ModelError, Result};
use crate::garnet::GarNet;
use crate::tensors::{points_tensor, read_points};
use crate::topology::{GarmentTopology, TopologyTensors};

/// A trained network ready to drape: the network on a plain (non-autodiff) device, its
/// setup and the template topology already on the device.
pub struct Draper {
    model: GarNet,
    setup: ModelSetup,
    topology: GarmentTopology,
    topo: TopologyTensors,
    spec: InputSpec,
    device: Device,
}

impl std::fmt::Debug for Draper {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Draper")
            .field("variant", &self.setup.config.variant)
            .field("n_garment", &self.topology.n_vertices)
            .field("n_body", &self.setup.body_sampling.n_body)
            .finish()
    }
}

impl Draper {
    /// Wraps `model` with its `setup`, on `device` (the model is moved there, without
    /// autodiff). Fails when the model and the setup disagree. A program that drapes on the
    /// CPU is faster with [`crate::tune_allocator`] called once at its start.
    pub fn new(model: GarNet, setup: ModelSetup, device: &Device) -> Result<Draper> {
        let device = device.clone().inner();
        if model.variant() != setup.config.variant {
            return Err(ModelError::InvalidInput(format!(
                "network is GarNet-{} but the setup says {}",
                model.variant().name(),
                setup.config.variant.name()
            )));
        }
        setup.validate()?;
        let topology = GarmentTopology::from_mesh(&setup.template)?;
        let topo = topology.to_device(&device);
        let spec = setup.input_spec();
        let model = model.valid().to_device(&device);
        Ok(Draper {
            model,
            setup,
            topology,
            topo,
            spec,
            device,
        })
    }

    /// Loads a checkpoint (see [`crate::checkpoint`]) onto `device`.
    pub fn load(path: &Path, device: &Device) -> Result<Draper> {
        let ck = load_checkpoint(path)?;
        let device = device.clone().inner();
        let model = ck.model(&device)?;
        Draper::new(model, ck.setup, &device)
    }

    /// The setup (config, template, body sampling).
    pub fn setup(&self) -> &ModelSetup {
        &self.setup
    }

    /// The network.
    pub fn model(&self) -> &GarNet {
        &self.model
    }

    /// The template's topology.
    pub fn topology(&self) -> &GarmentTopology {
        &self.topology
    }

    /// Checks one input pair: `body` `[V]` with V as trained, `warped` `[N]` with N the
    /// template's; all coordinates finite.
    fn check(&self, body: &[Vec3], warped: &[Vec3]) -> Result<()> {
        check_count(
            "warped garment M (template vertex count)",
            self.setup.template.num_vertices(),
            warped.len(),
        )?;
        check_count("body vertices", self.setup.body_sampling.n_body, body.len())?;
        check_finite("body vertices", body)?;
        check_finite("warped garment M", warped)?;
        Ok(())
    }

    /// Drapes: `body` `[V]` posed body vertices and `warped` `[N]` the template warped onto
    /// that body (DQS), metres -> the predicted draped garment `[N]`, metres. Fails with a
    /// clear error on a wrong vertex count or a NaN/infinite coordinate.
    pub fn drape(&self, body: &[Vec3], warped: &[Vec3]) -> Result<Vec<Vec3>> {
        let mut out = self.drape_batch(&[(body, warped)])?;
        Ok(out.pop().unwrap_or_default())
    }

    /// Drapes several (body `[V]`, warped `[N]`) pairs in one forward pass (equal V).
    pub fn drape_batch(&self, items: &[(&[Vec3], &[Vec3])]) -> Result<Vec<Vec<Vec3>>> {
        if items.is_empty() {
            return Ok(Vec::new());
        }
        for (body, warped) in items {
            self.check(body, warped)?;
        }
        let (frames, bodies, warped) = self.spec.to_canonical(items);
        let bodies: Vec<&[Vec3]> = bodies.iter().map(Vec::as_slice).collect();
        let warped: Vec<&[Vec3]> = warped.iter().map(Vec::as_slice).collect();
        let inputs = self.spec.inputs(&bodies, None, &warped, &self.device)?;
        let pred = self
            .model
            .forward(&inputs, points_tensor(&warped, &self.device), &self.topo)?;
        let pred = read_points(pred)?;
        Ok(pred
            .into_iter()
            .zip(&frames)
            .map(|(g, f)| g.into_iter().map(|p| f.to_world(p)).collect())
            .collect())
    }
}
