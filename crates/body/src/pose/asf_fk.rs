//! Forward kinematics of an ASF skeleton driven by AMC frames.
//!
//! A bone's world rotation is `L = L_parent * C * M * C^-1`, with `C` the bone's `axis`
//! frame and `M` its dof rotations applied in the order of its `dof` line; the root's is
//! `C_r * M_r * C_r^-1` with `C_r` from `orientation`. Bone directions are given in world
//! axes of the rest skeleton, whose world rotations are all the identity, so `L` is also
//! the bone's rotation relative to its rest.

use glam::{DQuat, DVec3};

use super::amc::Amc;
use super::asf::{Asf, Dof};
use super::error::PoseError;
use super::euler::{applied_in_order, Axis};

/// One posed frame of an ASF skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct AsfPose {
    /// Root position, file length unit (`root.position` plus the frame's translation).
    pub root_position: DVec3,
    /// World rotation of the root relative to its rest.
    pub root_rotation: DQuat,
    /// World rotation of every bone relative to its rest, `[bones]` in file order.
    pub world: Vec<DQuat>,
}

/// Rotation of the rotational dofs in `dofs` with their `values`, applied in order.
fn dof_rotation(dofs: &[Dof], values: &[f64]) -> DQuat {
    let (axes, angles): (Vec<Axis>, Vec<f64>) = dofs
        .iter()
        .zip(values)
        .filter_map(|(d, &v)| d.rotation_axis().map(|a| (a, v)))
        .unzip();
    applied_in_order(&axes, &angles)
}

impl Asf {
    /// The rest pose: root at `root.position`, every rotation the identity.
    pub fn rest_pose(&self) -> AsfPose {
        AsfPose {
            root_position: self.root.position,
            root_rotation: DQuat::IDENTITY,
            world: vec![DQuat::IDENTITY; self.bones.len()],
        }
    }

    /// Frame `frame` of `amc` posed on this skeleton; errors if the frame is out of range
    /// or the AMC was read for a different skeleton.
    pub fn pose_of(&self, amc: &Amc, frame: usize) -> Result<AsfPose, PoseError> {
        if frame >= amc.frame_count() {
            return Err(PoseError::FrameOutOfRange {
                frame,
                count: amc.frame_count(),
            });
        }
        if !amc.fits(self) {
            return Err(PoseError::Invalid(format!(
                "{} was not read for skeleton {}",
                amc.path.display(),
                self.path.display()
            )));
        }
        let root_vals = amc.root(frame);
        let mut translation = DVec3::ZERO;
        for (d, &v) in self.root.order.iter().zip(root_vals) {
            match d {
                Dof::Tx => translation.x += v,
                Dof::Ty => translation.y += v,
                Dof::Tz => translation.z += v,
                _ => {}
            }
        }
        let c_root = applied_in_order(&self.root.axis, &self.root.orientation.to_array());
        let root_rotation =
            (c_root * dof_rotation(&self.root.order, root_vals) * c_root.inverse()).normalize();
        let mut world = vec![DQuat::IDENTITY; self.bones.len()];
        for &i in self.order() {
            let bone = &self.bones[i];
            let parent = bone.parent.map_or(root_rotation, |p| world[p]);
            let c = applied_in_order(&bone.axis_order, &bone.axis.to_array());
            let m = dof_rotation(&bone.dofs, amc.bone(frame, i));
            world[i] = (parent * c * m * c.inverse()).normalize();
        }
        Ok(AsfPose {
            root_position: self.root.position + translation,
            root_rotation,
            world,
        })
    }

    /// Posed root position and every bone's head and tail `[bones]` (file order), metres.
    pub fn joint_positions(&self, pose: &AsfPose) -> (DVec3, Vec<(DVec3, DVec3)>) {
        let s = self.metres_per_unit();
        let root = pose.root_position * s;
        let mut ends = vec![(DVec3::ZERO, DVec3::ZERO); self.bones.len()];
        for &i in self.order() {
            let bone = &self.bones[i];
            let head = bone.parent.map_or(root, |p| ends[p].1);
            let tail = head + pose.world[i] * (bone.direction * bone.length * s);
            ends[i] = (head, tail);
        }
        (root, ends)
    }
}
