//! Retargeting a motion source's frame onto a shaped [`Rig`]: every rig bone takes the
//! world-space direction of the source bone of the same name.
//!
//! For a rig bone `b` driven by source bone `s`: `G_s` is the source bone's world
//! rotation relative to its rest, `a_s` its rest direction, `d_b` the rig bone's rest
//! direction, `O_b` the smallest rotation taking `d_b` to `a_s`, and the rig bone's world
//! delta is `D_b = G_s * O_b`, so that `D_b d_b = G_s a_s`. The root takes `G_root`
//! directly; rig bones without a source bone follow their parent. When the bone that
//! continues `b`'s chain (`Neck` -> `Neck1`) has no source bone, `d_b` runs from `b`'s
//! head to the head of the first chain bone below that has one (`Head`), so that `b` and
//! the bones between, turning together, span the source bone.
//!
//! The clavicles and the pelvic hip bones are the exception: their rest directions
//! reflect where a marker set or a skeleton author put the joints, not a posture (a CMU
//! clavicle points 10-20 degrees higher than the body's), so matching them would shrug
//! the shoulders. They take the source's rotation from its rest, `D_b = G_s`, keeping
//! the body's own shoulder and pelvis geometry; the bones they carry still take the
//! source's world directions.

use std::collections::HashMap;
use std::path::Path;

use glam::{DQuat, DVec3, Quat, Vec3};

use super::amc::Amc;
use super::asf::Asf;
use super::bvh::Bvh;
use super::bvh_rig::{chain_child, BvhRig};
use super::cmu::{cmu_index, CMU_BONES};
use super::error::PoseError;
use super::source::{SourceFrame, SourceSkeleton};
use crate::rig::{Bone, Pose, Rig};

/// Options of retargeting.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RetargetOptions {
    /// Keep the root's horizontal (X, Z) motion; by default it is removed so the body
    /// stays over the origin.
    pub keep_horizontal_translation: bool,
}

/// World rotation deltas `[B]` of every rig bone for one source frame (see the module
/// documentation).
pub fn retarget_rotations(
    rig: &Rig,
    skeleton: &SourceSkeleton,
    frame: &SourceFrame,
) -> Result<Vec<Quat>, PoseError> {
    if rig.is_empty() {
        return Err(PoseError::Rig("the rig has no bones".into()));
    }
    if frame.world.len() != skeleton.names.len()
        || skeleton.rest_vectors.len() != skeleton.names.len()
    {
        return Err(PoseError::Invalid(format!(
            "source frame has {} rotations for {} bones",
            frame.world.len(),
            skeleton.names.len()
        )));
    }
    let by_name: HashMap<&str, usize> = skeleton
        .names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), i))
        .collect();
    let root_g = frame
        .world
        .get(skeleton.root)
        .copied()
        .unwrap_or(DQuat::IDENTITY);
    const KEEP_REST_GEOMETRY: [&str; 4] =
        ["LeftShoulder", "RightShoulder", "LHipJoint", "RHipJoint"];
    let mut deltas: Vec<Quat> = Vec::with_capacity(rig.len());
    for bone in &rig.bones {
        let source = by_name.get(bone.name.as_str()).copied();
        let d = match (bone.parent, source) {
            (None, s) => s.map_or(root_g, |s| frame.world[s]),
            (Some(_), Some(s)) if KEEP_REST_GEOMETRY.contains(&bone.name.as_str()) => {
                frame.world[s]
            }
            (Some(_), Some(s)) => {
                let a = skeleton.rest_vectors[s];
                let d = rest_span(rig, &by_name, bone).as_dvec3();
                let g = frame.world[s];
                if a.length() > 1e-9 && d.length() > 1e-9 {
                    g * DQuat::from_rotation_arc(d.normalize(), a.normalize())
                } else {
                    g
                }
            }
            (Some(p), None) => deltas[p].as_dquat(),
        };
        deltas.push(d.normalize().as_quat());
    }
    Ok(deltas)
}

/// The rest vector a driven rig bone is aligned by: head to tail, or, when the bone that
/// continues its chain is not driven, head to the head of the first chain bone below that
/// is (see the module documentation).
fn rest_span(rig: &Rig, driven: &HashMap<&str, usize>, bone: &Bone) -> Vec3 {
    let own = bone.tail - bone.head;
    let Some(b) = cmu_index(&bone.name) else {
        return own;
    };
    let in_rig = |c: usize| rig.index(CMU_BONES[c].name).map(|i| &rig.bones[i]);
    let mut c = chain_child(b);
    if c.is_some_and(|c| driven.contains_key(CMU_BONES[c].name)) {
        return own;
    }
    while let Some(ci) = c {
        let Some(below) = in_rig(ci) else { break };
        if driven.contains_key(CMU_BONES[ci].name) {
            return below.head - bone.head;
        }
        c = chain_child(ci);
    }
    own
}

/// Hip-to-ankle length of a rig (thigh plus shin, mean of both legs), metres; falls back
/// to the root's height above the lowest joint.
pub fn rig_leg_length(rig: &Rig) -> f32 {
    let len = |n: &str| {
        rig.index(n)
            .map(|i| (rig.bones[i].tail - rig.bones[i].head).length())
    };
    let legs: Vec<f32> = [("LeftUpLeg", "LeftLeg"), ("RightUpLeg", "RightLeg")]
        .iter()
        .filter_map(|(a, b)| Some(len(a)? + len(b)?))
        .collect();
    if legs.is_empty() {
        let lowest = rig
            .bones
            .iter()
            .flat_map(|b| [b.head.y, b.tail.y])
            .fold(f32::INFINITY, f32::min);
        rig.bones.first().map_or(0.0, |b| b.head.y - lowest)
    } else {
        legs.iter().sum::<f32>() / legs.len() as f32
    }
}

/// The rig's root translation for a source frame: the source root position scaled by the
/// ratio of leg lengths, its height taken relative to the source's standing rest root
/// height, plus the lift that puts the rig's feet on its floor when it takes the source's
/// rest pose (so a standing source keeps the rig standing on y = 0); horizontal motion
/// kept only if asked.
pub fn retarget_translation(
    rig: &Rig,
    skeleton: &SourceSkeleton,
    frame: &SourceFrame,
    opts: &RetargetOptions,
) -> Vec3 {
    let scale = if skeleton.leg_length > 1e-9 {
        rig_leg_length(rig) as f64 / skeleton.leg_length
    } else {
        1.0
    };
    let p = frame.root_position;
    let y = scale * (p.y - skeleton.rest_root_height) + rest_pose_lift(rig, skeleton) as f64;
    let t = if opts.keep_horizontal_translation {
        DVec3::new(scale * p.x, y, scale * p.z)
    } else {
        DVec3::new(0.0, y, 0.0)
    };
    t.as_vec3()
}

/// Lowest point of the feet (ankles, toe joints) of `rig` in `pose`, metres.
fn lowest_foot_point(rig: &Rig, pose: &Pose) -> Option<f32> {
    let joints = rig.posed_joints(pose);
    ["LeftFoot", "RightFoot", "LeftToeBase", "RightToeBase"]
        .iter()
        .filter_map(|n| rig.index(n))
        .flat_map(|i| [joints[i].0.y, joints[i].1.y])
        .reduce(f32::min)
}

/// How far the rig's root must rise, when the rig takes the source's rest pose with no
/// translation, for its feet to stand as low as in the rig's own rest pose (metres).
fn rest_pose_lift(rig: &Rig, skeleton: &SourceSkeleton) -> f32 {
    let rest_frame = SourceFrame {
        world: vec![DQuat::IDENTITY; skeleton.names.len()],
        root_position: DVec3::ZERO,
    };
    let Ok(deltas) = retarget_rotations(rig, skeleton, &rest_frame) else {
        return 0.0;
    };
    let posed = Pose::from_world_rotations(rig, &deltas, Vec3::ZERO);
    match (
        lowest_foot_point(rig, &Pose::identity(rig.len())),
        lowest_foot_point(rig, &posed),
    ) {
        (Some(rest), Some(posed)) => rest - posed,
        _ => 0.0,
    }
}

/// Retargets one source frame onto `rig`.
pub fn retarget(
    rig: &Rig,
    skeleton: &SourceSkeleton,
    frame: &SourceFrame,
    opts: &RetargetOptions,
) -> Result<Pose, PoseError> {
    let deltas = retarget_rotations(rig, skeleton, frame)?;
    let t = retarget_translation(rig, skeleton, frame, opts);
    Ok(Pose::from_world_rotations(rig, &deltas, t))
}

/// The motion data of a [`Clip`].
#[derive(Clone, Debug, PartialEq)]
pub enum ClipData {
    /// An ASF skeleton and an AMC motion recorded on it.
    AsfAmc {
        /// The skeleton.
        asf: Box<Asf>,
        /// The motion.
        amc: Box<Amc>,
    },
    /// A BVH file and how its skeleton sits on garnet's rig.
    Bvh {
        /// The file.
        bvh: Box<Bvh>,
        /// Its joints' places on the rig and its axes.
        rig: Box<BvhRig>,
    },
}

/// A motion clip that can pose a rig frame by frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// The motion data.
    pub data: ClipData,
    /// The source skeleton as the retargeter sees it.
    pub skeleton: SourceSkeleton,
    /// Frames per second (AMC files do not say; CMU clips are 120).
    pub frame_rate: f64,
}

impl Clip {
    /// A clip from an ASF skeleton and an AMC motion file, at 120 frames per second.
    pub fn from_asf_amc(
        asf_path: impl AsRef<Path>,
        amc_path: impl AsRef<Path>,
    ) -> Result<Clip, PoseError> {
        let asf = Asf::read(asf_path)?;
        let amc = Amc::read(amc_path, &asf)?;
        Ok(Clip {
            skeleton: SourceSkeleton::from_asf(&asf),
            data: ClipData::AsfAmc {
                asf: Box::new(asf),
                amc: Box::new(amc),
            },
            frame_rate: 120.0,
        })
    }

    /// A clip from a BVH file of any common rig (CMU, Mixamo, 3ds Max biped, generic
    /// names; any up axis and facing); `metres_per_unit` as in [`Bvh::read`]. A skeleton
    /// that cannot be placed on garnet's rig is refused (see [`BvhRig::new`]).
    pub fn from_bvh(
        path: impl AsRef<Path>,
        metres_per_unit: Option<f64>,
    ) -> Result<Clip, PoseError> {
        let bvh = Bvh::read(path, metres_per_unit)?;
        let rig = BvhRig::new(&bvh)?;
        Ok(Clip {
            skeleton: rig.skeleton(&bvh),
            frame_rate: bvh.frame_rate(),
            data: ClipData::Bvh {
                bvh: Box::new(bvh),
                rig: Box::new(rig),
            },
        })
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        match &self.data {
            ClipData::AsfAmc { amc, .. } => amc.frame_count(),
            ClipData::Bvh { bvh, .. } => bvh.frame_count(),
        }
    }

    /// Frames per second.
    pub fn frame_rate(&self) -> f64 {
        self.frame_rate
    }

    /// Frame `frame` (0-based) as world rotations of the source skeleton (garnet's axes).
    pub fn source_frame(&self, frame: usize) -> Result<SourceFrame, PoseError> {
        match &self.data {
            ClipData::AsfAmc { asf, amc } => {
                Ok(SourceFrame::from_asf(asf, &asf.pose_of(amc, frame)?))
            }
            ClipData::Bvh { bvh, rig } => rig.frame(bvh, frame),
        }
    }

    /// Frame `frame` (0-based) retargeted onto `rig`.
    pub fn pose(&self, frame: usize, rig: &Rig, opts: &RetargetOptions) -> Result<Pose, PoseError> {
        retarget(rig, &self.skeleton, &self.source_frame(frame)?, opts)
    }
}
