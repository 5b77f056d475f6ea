//! GarNet (Gundogdu et al., ICCV 2019) in burn 0.22: the three networks (Naive, Global,
//! Local), the physics-inspired loss, training, checkpoints and draping.
//!
//! The same code runs on every burn backend: the device decides (`Device::flex()` on the CPU,
//! always compiled in; `cuda` and `wgpu` behind the cargo features of the same names).
//! Training uses `device.autodiff()`; inference a plain device.
//!
//! Units: metres (the loss terms: centimetres, see [`LOSS_UNITS_PER_METRE`]). Shapes: `B` samples, `V` body vertices (13380), `P` body points the body
//! stream sees (a fixed subset, 3345 by default), `N` garment vertices, `F` garment faces, `K`
//! neighbourhood width; point tensors are `[B,V,3]`, `[B,P,3]`, `[B,N,3]`.
//!
//! The flow, as a CLI uses it:
//!
//! ```no_run
//! use burn::prelude::Device;
//! use model::*;
//! # fn data() -> (geom::TriMesh, Vec<glam::Vec3>, BodyTopology, Vec<Sample>) { unimplemented!() }
//! # fn main() -> Result<()> {
//! let (template, reference_body, body_topology, samples) = data();
//! let config = GarNetConfig::new(Variant::Local);
//! let setup = ModelSetup::new(config, template, &reference_body)?;
//! let mut trainer = Trainer::new(setup, LossConfig::new(), PAPER_LEARNING_RATE, &Device::flex())?;
//! let batches = || samples.chunks(4).map(|c| Ok::<_, String>(c.to_vec())).collect::<Vec<_>>();
//! trainer.fit(100, |_epoch, _skip| batches(), Some(|| batches()), "runs/local".as_ref(), |r| {
//!     println!("epoch {} train {:?}", r.epoch, r.train)
//! })?;
//! let draper = Draper::load("runs/local/best.garnet".as_ref(), &Device::flex())?;
//! let draped = draper.drape(&samples[0].body, &samples[0].warped)?;
//! # Ok(()) }
//! ```
//!
//! Widths (defaults of [`GarNetConfig`]) and parameter counts: see `docs/model.md`.

#![warn(missing_docs)]

pub mod alloc;
pub mod batch;
pub mod bench;
pub mod body_stream;
pub mod checkpoint;
pub mod config;
pub mod contact;
pub mod curvature_loss;
pub mod dense_rows;
pub mod drape;
pub mod epoch_progress;
pub mod error;
pub mod feast;
pub mod feast_rows;
pub mod frame;
pub mod fusion;
pub mod garment_stream;
pub mod garnet;
pub mod grad_clip;
mod init;
pub mod layers;
pub mod local;
pub mod loss;
pub mod metrics_log;
pub mod recipe;
pub mod schedule;
pub mod stn;
pub mod synthetic;
pub mod tensors;
pub mod topology;
pub mod train;
pub mod trainer;

pub use alloc::tune_allocator;
pub use batch::{Batch, BodyTopology, InputSpec, KnownBodies, NetInputs, Sample};
pub use checkpoint::{load_checkpoint, save_checkpoint, Checkpoint, ModelSetup, TrainState};
pub use config::{Base, GarNetConfig, Variant};
pub use drape::Draper;
pub use error::{ModelError, Result};
pub use frame::CanonicalFrame;
pub use garnet::GarNet;
pub use init::LEAKY_SLOPE;
pub use local::{BodySampling, LocalIndices};
pub use loss::{garnet_loss, LossConfig, LossTerms, NormalLoss, VertexLoss, LOSS_UNITS_PER_METRE};
pub use recipe::{Recipe, RecipeRecord};
pub use schedule::{CosineSchedule, TimeBudget};
pub use topology::{GarmentTopology, TopologyTensors};
pub use train::{adam, evaluate_batch, train_step, Evaluation, StepReport, PAPER_LEARNING_RATE};
pub use trainer::{EpochReport, Trainer, Validation};

/// burn's optimiser type used for GarNet (Adam).
pub use burn::optim::ModuleOptimizer as Optimizer;
