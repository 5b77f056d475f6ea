//! Pose sources: motion files (CMU ASF/AMC, and BVH of the common rigs), retargeting onto
//! a shaped [`Rig`](crate::rig::Rig), and a seeded procedural pose generator.
//!
//! Units inside are metres and radians; degrees and file length units appear only at file
//! boundaries. The world is garnet's: Y up, the body facing +Z, its left side at +X.

mod amc;
mod asf;
mod asf_fk;
mod asf_parse;
mod bvh;
mod bvh_parse;
mod bvh_rig;
mod bvh_write;
pub mod cmu;
mod error;
pub mod euler;
pub mod joint_names;
pub mod procedural;
mod retarget;
mod source;
pub mod synthetic;
pub mod synthetic_clip;
#[cfg(test)]
mod test_util;
#[cfg(test)]
mod tests_asf;
#[cfg(test)]
mod tests_bvh;
#[cfg(test)]
mod tests_retarget;

pub use amc::Amc;
pub use asf::{Asf, AsfBone, AsfRoot, AsfUnits, Dof};
pub use asf_fk::AsfPose;
pub use bvh::{Bvh, BvhChannel, BvhJoint};
pub use bvh_rig::BvhRig;
pub use bvh_write::{bvh_string, save_bvh, BvhWriteOptions};
pub use error::PoseError;
pub use procedural::{
    AnatomicalPose, JointAngles, JointLimits, KeyPose, PoseFamily, PoseKind,
    ProceduralPoseGenerator, WalkParams,
};
pub use retarget::{
    retarget, retarget_rotations, retarget_translation, rig_leg_length, Clip, ClipData,
    RetargetOptions,
};
pub use source::{SourceFrame, SourceSkeleton};
