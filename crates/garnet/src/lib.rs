//! garnet: fast, accurate 3D cloth draping after GarNet (Gundogdu et al., ICCV 2019).
//!
//! This crate is the library a Rust program calls: it loads trained models, drapes garments
//! on a body in milliseconds ([`drape()`]), evaluates models on a dataset as the paper
//! reports them ([`eval::evaluate`]) and ships models with their cards ([`export::export`]).
//! The `garnet` command line is a thin layer over it. The pipeline's own crates (`geom`,
//! `body`, `garment`, `sim`, `dataset`, `model`, `render`) are re-exported for the types
//! these take and give.
//!
//! Units: metres and radians inside; reports in cm and degrees.
//!
//! ```no_run
//! use garnet::{body::BodyModel, drape, DrapeOptions, GarmentModel};
//! # fn main() -> anyhow::Result<()> {
//! let bodies = BodyModel::load()?; // fetched from PyPI and converted on first use
//! let target = bodies.shape(&garnet::body::Phenotype::default())?;
//! let pose = garnet::body::Pose::identity(target.rig.len()); // the rest A-pose
//! let device = garnet::Device::flex();
//! let models = vec![GarmentModel::load("models/tshirt-local.garnet".as_ref(), &device)?];
//! let draped = drape(&models, &target, &pose, DrapeOptions::default())?;
//! println!("{} vertices", draped.garments[0].mesh.vertices.len());
//! # Ok(()) }
//! ```

#![warn(missing_docs)]

pub mod card;
pub mod drape;
pub mod drapes;
pub mod eval;
pub mod export;
pub mod motion;
pub mod shipped;

pub use burn::prelude::Device;
pub use drape::{
    base_anchors, drape, drape_posed, Drape, DrapeOptions, DrapeTimings, DrapedGarment,
    GarmentModel, PosedBody,
};
pub use eval::{evaluate, EvalOptions, EvalReport};
pub use motion::{drape_motion, FrameRange, Motion, MotionOptions};
pub use shipped::{shipped_models, shipped_models_dir, SHIPPED_MODELS};

pub use body;
pub use dataset;
pub use garment;
pub use geom;
pub use model;
pub use render;
pub use sim;
