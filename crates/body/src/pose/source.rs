//! What the retargeter needs from a motion source: the source skeleton's rest bone
//! vectors named as the rig names them, and per frame every bone's world rotation.

use glam::{DQuat, DVec3};

use super::asf::Asf;
use super::asf_fk::AsfPose;
use super::cmu::rig_name_for_asf;

/// A motion source's skeleton as the retargeter sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceSkeleton {
    /// The rig bone each source bone drives (`Hips`, `LeftUpLeg`, ...), `[S]`.
    pub names: Vec<String>,
    /// Rest vector head->tail of each source bone in world axes (Y up, facing +Z),
    /// metres, `[S]`; zero for a bone without length.
    pub rest_vectors: Vec<DVec3>,
    /// Index of the root bone.
    pub root: usize,
    /// Height of the rest root above the lowest rest joint, metres.
    pub rest_root_height: f64,
    /// Hip-to-ankle length (thigh plus shin, mean of the legs found), metres.
    pub leg_length: f64,
}

/// One frame of a motion source.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceFrame {
    /// World rotation of every source bone relative to its rest, `[S]`.
    pub world: Vec<DQuat>,
    /// Root (pelvis) position, metres, in garnet's axes (Y up, facing +Z).
    pub root_position: DVec3,
}

impl SourceSkeleton {
    /// A skeleton from its bones; the leg length is measured from the `LeftUpLeg`,
    /// `LeftLeg`, `RightUpLeg` and `RightLeg` rest vectors (the rest root height without them).
    pub(super) fn new(
        names: Vec<String>,
        rest_vectors: Vec<DVec3>,
        root: usize,
        rest_root_height: f64,
    ) -> Self {
        let len = |n: &str| {
            names
                .iter()
                .position(|m| m == n)
                .map(|i| rest_vectors[i].length())
        };
        let legs: Vec<f64> = [("LeftUpLeg", "LeftLeg"), ("RightUpLeg", "RightLeg")]
            .iter()
            .filter_map(|(a, b)| Some(len(a)? + len(b)?))
            .filter(|l| *l > 0.0)
            .collect();
        let leg_length = if legs.is_empty() {
            rest_root_height
        } else {
            legs.iter().sum::<f64>() / legs.len() as f64
        };
        Self {
            names,
            rest_vectors,
            root,
            rest_root_height,
            leg_length,
        }
    }

    /// The skeleton of an ASF file: the root (named `Hips`) first, then the bones in file
    /// order, CMU bones renamed to the rig's names.
    pub fn from_asf(asf: &Asf) -> Self {
        let s = asf.metres_per_unit();
        let mut names = vec!["Hips".to_string()];
        let mut vectors = vec![DVec3::ZERO];
        for b in &asf.bones {
            names.push(rig_name_for_asf(&b.name).unwrap_or(&b.name).to_string());
            vectors.push(b.direction * b.length * s);
        }
        let (root, ends) = asf.joint_positions(&asf.rest_pose());
        let lowest = ends
            .iter()
            .flat_map(|(h, t)| [h.y, t.y])
            .fold(root.y, f64::min);
        Self::new(names, vectors, 0, root.y - lowest)
    }
}

impl SourceFrame {
    /// A posed ASF frame, bones ordered as in [`SourceSkeleton::from_asf`].
    pub fn from_asf(asf: &Asf, pose: &AsfPose) -> Self {
        let mut world = Vec::with_capacity(pose.world.len() + 1);
        world.push(pose.root_rotation);
        world.extend_from_slice(&pose.world);
        Self {
            world,
            root_position: pose.root_position * asf.metres_per_unit(),
        }
    }
}
