//! Procedural poses: anatomical joint angles with limits, a parametric walk cycle, a
//! library of yoga-like and dance-like key poses, and a seeded generator that blends
//! and perturbs them.

mod anatomy;
mod generator;
mod library;
mod limits;
#[cfg(test)]
mod tests;
mod walk;

pub use anatomy::{AnatomicalPose, JointAngles, BONES};
pub use generator::{PoseKind, ProceduralPoseGenerator};
pub use library::{KeyPose, PoseFamily};
pub use limits::JointLimits;
pub use walk::{walk_pose, WalkParams};
