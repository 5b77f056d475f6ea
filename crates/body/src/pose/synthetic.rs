//! A stand-in for the shaped `cmu_mb` rig, for tests and examples that must not need the
//! body assets: the 31 CMU bones in the A-pose, with joint positions and rolls rounded
//! from the MakeHuman default body (about 1.64 m tall, feet on y = 0, facing +Z).

use glam::Vec3;

use super::cmu::CMU_BONES;
use crate::rig::{rest_frame, Bone, Rig};

/// Head, tail (metres, garnet world) and Blender roll (radians) of every CMU bone of the
/// left side and the middle, in [`CMU_BONES`] order; the right side mirrors the left.
const JOINTS: [([f32; 3], [f32; 3], f32); 31] = [
    ([0.0, 0.872, 0.013], [0.0, 0.952, -0.026], 0.0), // Hips
    ([0.0, 0.872, 0.013], [0.101, 0.864, 0.005], 2.907), // LHipJoint
    ([0.101, 0.864, 0.005], [0.142, 0.473, 0.037], -0.091), // LeftUpLeg
    ([0.142, 0.473, 0.037], [0.181, 0.067, 0.023], -0.092), // LeftLeg
    ([0.181, 0.067, 0.023], [0.195, 0.023, 0.153], -0.5), // LeftFoot
    ([0.195, 0.023, 0.153], [0.196, 0.02, 0.172], -1.047), // LeftToeBase
    ([0.0; 3], [0.0; 3], 0.0),                        // right side: mirrored
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0, 0.952, -0.026], [0.0, 1.093, -0.008], 0.0), // LowerBack
    ([0.0, 1.093, -0.008], [0.0, 1.237, -0.019], 0.0), // Spine
    ([0.0, 1.237, -0.019], [0.0, 1.412, 0.005], 0.0),  // Spine1
    ([0.0, 1.412, 0.005], [0.0, 1.462, 0.025], 0.0),   // Neck
    ([0.0, 1.462, 0.025], [0.0, 1.513, 0.044], 0.0),   // Neck1
    ([0.0, 1.513, 0.044], [0.0, 1.661, 0.037], 0.0),   // Head
    ([0.023, 1.341, 0.022], [0.17, 1.318, 0.019], 1.657), // LeftShoulder
    ([0.17, 1.318, 0.019], [0.331, 1.138, 0.02], 2.368), // LeftArm
    ([0.331, 1.138, 0.02], [0.453, 1.013, 0.183], 2.305), // LeftForeArm
    ([0.453, 1.013, 0.183], [0.464, 0.998, 0.209], 2.637), // LeftHand
    ([0.464, 0.998, 0.209], [0.481, 0.973, 0.278], -1.821), // LeftFingerBase
    ([0.481, 0.973, 0.278], [0.484, 0.958, 0.298], -1.116), // LeftHandFinger1
    ([0.454, 1.006, 0.227], [0.434, 0.997, 0.248], 2.495), // LThumb
    ([0.0; 3], [0.0; 3], 0.0),                         // right arm: mirrored
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
    ([0.0; 3], [0.0; 3], 0.0),
];

/// A synthetic A-pose rig with the 31 `cmu_mb` bones (see the module documentation).
pub fn a_pose_rig() -> Rig {
    let mirror = |v: [f32; 3]| Vec3::new(-v[0], v[1], v[2]);
    let bones = CMU_BONES
        .iter()
        .enumerate()
        .map(|(i, cmu)| {
            let (head, tail, roll) = match i {
                6..=10 => {
                    let (h, t, r) = JOINTS[i - 5];
                    (mirror(h), mirror(t), -r)
                }
                24..=30 => {
                    let (h, t, r) = JOINTS[i - 7];
                    (mirror(h), mirror(t), -r)
                }
                _ => {
                    let (h, t, r) = JOINTS[i];
                    (Vec3::from(h), Vec3::from(t), r)
                }
            };
            Bone {
                name: cmu.name.to_string(),
                parent: cmu.parent,
                head,
                tail,
                frame: rest_frame(head, tail, roll),
            }
        })
        .collect();
    Rig { bones }
}
