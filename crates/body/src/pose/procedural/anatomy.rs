//! Anatomical joint angles of the 31-bone CMU skeleton and how they pose a rig.
//!
//! Angles are defined in a world-aligned frame (X left, Y up, Z forward) on a canonical
//! neutral skeleton: standing, legs straight down, arms hanging straight down, feet
//! forward, spine and neck as the rig's rest. A bone's world rotation is its parent's
//! composed with its own anatomical rotation `A = R(flex) * R(abd) * R(twist)` (twist
//! first, about the segment's long axis), as an ASF skeleton composes them; the rig is
//! then posed through the same retargeting as motion files, so the result does not
//! depend on the rig's bone rolls.

use glam::{DQuat, DVec3, Vec3};

use super::super::cmu::{cmu_index, mirror_index, CMU_BONES};
use super::super::retarget::retarget_rotations;
use super::super::source::{SourceFrame, SourceSkeleton};
use crate::rig::{Pose, Rig};

/// Number of bones of the CMU skeleton.
pub const BONES: usize = CMU_BONES.len();

/// Anatomical angles of one joint, radians. The meaning per bone (positive direction,
/// same on both sides: the right side mirrors the left):
/// - spine, neck, head and the root (pelvis): `flex` bends forward, `abd` bends to the
///   body's left, `twist` turns to the body's left;
/// - hip (`*UpLeg`) and shoulder (`*Arm`): `flex` raises the limb forward, `abd` raises
///   it sideways away from the body, `twist` rotates it internally;
/// - knee (`*Leg`): `flex` bends it, `twist` rotates the shin internally;
/// - ankle (`*Foot`): `flex` points the toes down (plantarflexion), `abd` inverts the
///   sole, `twist` turns the toes outward;
/// - toes: `flex` bends them up; clavicle (`*Shoulder`): `flex` protracts, `abd` elevates;
/// - elbow (`*ForeArm`): `flex` bends it, `twist` pronates; wrist (`*Hand`): `flex`
///   flexes toward the palm, `abd` deviates toward the thumb; fingers and thumb: `flex`
///   curls them, `abd` spreads the thumb.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointAngles {
    /// Flexion, radians.
    pub flex: f32,
    /// Abduction or lateral bend, radians.
    pub abd: f32,
    /// Axial rotation, radians.
    pub twist: f32,
}

impl JointAngles {
    /// Angles from degrees.
    pub fn deg(flex: f32, abd: f32, twist: f32) -> Self {
        Self {
            flex: flex.to_radians(),
            abd: abd.to_radians(),
            twist: twist.to_radians(),
        }
    }

    /// The three angles as an array `[flex, abd, twist]`.
    pub fn to_array(self) -> [f32; 3] {
        [self.flex, self.abd, self.twist]
    }

    /// Angles from an array `[flex, abd, twist]`.
    pub fn from_array(a: [f32; 3]) -> Self {
        Self {
            flex: a[0],
            abd: a[1],
            twist: a[2],
        }
    }
}

/// A pose of the CMU skeleton as anatomical joint angles, `[31]` in [`CMU_BONES`] order;
/// the root's angles orient the pelvis.
#[derive(Clone, Debug, PartialEq)]
pub struct AnatomicalPose {
    /// Angles per bone in [`CMU_BONES`] order.
    pub joints: [JointAngles; BONES],
}

impl Default for AnatomicalPose {
    fn default() -> Self {
        Self::neutral()
    }
}

/// Axes of (flex, abd, twist) of a left-side or central bone in the world-aligned frame.
fn axes(i: usize) -> [DVec3; 3] {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    match CMU_BONES[mirror_index(i).min(i)].name {
        "LeftUpLeg" | "LeftArm" | "LeftForeArm" => [-x, z, -y],
        "LeftLeg" => [x, z, -y],
        "LeftFoot" => [x, -z, y],
        "LeftToeBase" => [-x, z, y],
        "LeftShoulder" => [-y, z, x],
        "LeftHand" => [-z, -x, -y],
        "LeftFingerBase" | "LeftHandFinger1" | "LThumb" => [-z, -x, -y],
        _ => [x, -z, y],
    }
}

impl AnatomicalPose {
    /// The canonical neutral stance: every angle zero.
    pub fn neutral() -> Self {
        Self {
            joints: [JointAngles::default(); BONES],
        }
    }

    /// Builds a pose from `(bone name, flex, abd, twist)` in degrees; unlisted bones are
    /// zero. Unknown names are ignored (the tables are checked by tests).
    pub fn from_degrees(entries: &[(&str, f32, f32, f32)]) -> Self {
        let mut p = Self::neutral();
        for &(name, f, a, t) in entries {
            if let Some(i) = cmu_index(name) {
                p.joints[i] = JointAngles::deg(f, a, t);
            }
        }
        p
    }

    /// The angles of the bone called `name`, if it is a CMU bone.
    pub fn get(&self, name: &str) -> Option<JointAngles> {
        cmu_index(name).map(|i| self.joints[i])
    }

    /// Sets the angles of the bone called `name` (ignored if it is not a CMU bone).
    pub fn set(&mut self, name: &str, angles: JointAngles) {
        if let Some(i) = cmu_index(name) {
            self.joints[i] = angles;
        }
    }

    /// The left-right mirror image (left and right limbs swapped, central lateral bends
    /// and turns reversed).
    pub fn mirrored(&self) -> Self {
        let mut out = Self::neutral();
        for (i, j) in out.joints.iter_mut().enumerate() {
            let m = mirror_index(i);
            *j = self.joints[m];
            if m == i {
                j.abd = -j.abd;
                j.twist = -j.twist;
            }
        }
        out
    }

    /// Linear blend of the angles: `self` at `t = 0`, `other` at `t = 1`.
    pub fn lerp(&self, other: &Self, t: f32) -> Self {
        let mut out = self.clone();
        for (o, b) in out.joints.iter_mut().zip(&other.joints) {
            let a = o.to_array();
            let b = b.to_array();
            *o = JointAngles::from_array([0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * t));
        }
        out
    }

    /// World rotation of every CMU bone `[31]` on the canonical neutral skeleton.
    pub fn canonical_world(&self) -> Vec<DQuat> {
        let mut world: Vec<DQuat> = Vec::with_capacity(BONES);
        for (i, (bone, j)) in CMU_BONES.iter().zip(&self.joints).enumerate() {
            let [fx, ax, tx] = axes(i);
            let m = if mirror_index(i) < i {
                DVec3::new(-1.0, 1.0, 1.0)
            } else {
                DVec3::ONE
            };
            // Mirroring a rotation about `a` by `t` gives one about `M a` by `-t`.
            let sign = if m.x < 0.0 { -1.0 } else { 1.0 };
            let r = |axis: DVec3, t: f32| DQuat::from_axis_angle(axis * m, sign * t as f64);
            let a = r(fx, j.flex) * r(ax, j.abd) * r(tx, j.twist);
            let parent = bone.parent.map_or(DQuat::IDENTITY, |p| world[p]);
            world.push((parent * a).normalize());
        }
        world
    }

    /// World rotation deltas `[B]` of `rig`'s bones (rest -> posed).
    pub fn world_deltas(&self, rig: &Rig) -> Vec<glam::Quat> {
        let skeleton = canonical_skeleton(rig);
        let frame = SourceFrame {
            world: self.canonical_world(),
            root_position: DVec3::ZERO,
        };
        retarget_rotations(rig, &skeleton, &frame)
            .unwrap_or_else(|_| vec![glam::Quat::IDENTITY; rig.len()])
    }

    /// Poses `rig`: rotations from the angles, and a vertical root translation that puts
    /// the lowest point of the feet (heels, balls, toe tips) at the rest feet's level.
    pub fn to_pose(&self, rig: &Rig) -> Pose {
        let deltas = self.world_deltas(rig);
        let mut pose = Pose::from_world_rotations(rig, &deltas, Vec3::ZERO);
        pose.root_translation.y = floor_offset(rig, &pose);
        pose
    }
}

/// The canonical neutral skeleton of `rig`: its bones' rest vectors, with the legs and
/// arms turned straight down, the feet and toes straight forward-down in the sagittal
/// plane, and the thumbs turned with their hands.
fn canonical_skeleton(rig: &Rig) -> SourceSkeleton {
    let rest = |name: &str| {
        rig.index(name)
            .map(|i| (rig.bones[i].tail - rig.bones[i].head).as_dvec3())
            .unwrap_or(DVec3::ZERO)
    };
    let names: Vec<String> = CMU_BONES.iter().map(|b| b.name.to_string()).collect();
    let vectors = CMU_BONES
        .iter()
        .map(|b| {
            let v = rest(b.name);
            let down = -DVec3::Y * v.length();
            match b.name {
                "LeftUpLeg" | "LeftLeg" | "RightUpLeg" | "RightLeg" | "LeftArm" | "LeftForeArm"
                | "LeftHand" | "LeftFingerBase" | "LeftHandFinger1" | "RightArm"
                | "RightForeArm" | "RightHand" | "RightFingerBase" | "RightHandFinger1" => down,
                "LeftFoot" | "LeftToeBase" | "RightFoot" | "RightToeBase" => {
                    let s = DVec3::new(0.0, v.y, v.z);
                    if s.length() > 1e-9 {
                        s.normalize() * v.length()
                    } else {
                        v
                    }
                }
                "LThumb" | "RThumb" => {
                    let hand = rest(if b.name == "LThumb" {
                        "LeftHand"
                    } else {
                        "RightHand"
                    });
                    if hand.length() > 1e-9 {
                        DQuat::from_rotation_arc(hand.normalize(), -DVec3::Y) * v
                    } else {
                        v
                    }
                }
                _ => v,
            }
        })
        .collect();
    SourceSkeleton {
        names,
        rest_vectors: vectors,
        root: 0,
        rest_root_height: 0.0,
        leg_length: 0.0,
    }
}

/// Foot landmarks `(bone, rest point)`: heels below the ankles at the rest floor level,
/// ankles, balls and toe tips.
fn foot_landmarks(rig: &Rig) -> (Vec<(usize, Vec3)>, f32) {
    let mut marks = Vec::new();
    let mut floor = f32::INFINITY;
    for (foot, toe) in [("LeftFoot", "LeftToeBase"), ("RightFoot", "RightToeBase")] {
        if let Some(t) = rig.index(toe) {
            let b = &rig.bones[t];
            floor = floor.min(b.head.y).min(b.tail.y);
            marks.push((t, b.head));
            marks.push((t, b.tail));
        }
        if let Some(f) = rig.index(foot) {
            floor = floor.min(rig.bones[f].tail.y);
        }
    }
    for foot in ["LeftFoot", "RightFoot"] {
        if let Some(f) = rig.index(foot) {
            let h = rig.bones[f].head;
            marks.push((f, h));
            if floor.is_finite() {
                marks.push((f, Vec3::new(h.x, floor, h.z)));
            }
        }
    }
    (marks, floor)
}

/// Vertical translation that brings the lowest posed foot landmark to the rest floor.
fn floor_offset(rig: &Rig, pose: &Pose) -> f32 {
    let (marks, floor) = foot_landmarks(rig);
    if marks.is_empty() || !floor.is_finite() {
        return 0.0;
    }
    let xf = rig.skinning_transforms(pose);
    let lowest = marks
        .iter()
        .map(|&(b, p)| xf[b].apply(p).y)
        .fold(f32::INFINITY, f32::min);
    floor - lowest
}

/// Posed foot landmark heights above the rest floor `[marks]` (for tests).
#[cfg(test)]
pub(crate) fn foot_heights(rig: &Rig, pose: &Pose) -> Vec<f32> {
    let (marks, floor) = foot_landmarks(rig);
    let xf = rig.skinning_transforms(pose);
    marks
        .iter()
        .map(|&(b, p)| xf[b].apply(p).y - floor)
        .collect()
}
