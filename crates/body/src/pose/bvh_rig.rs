//! Placing a BVH skeleton of any common convention on garnet's 31-bone CMU rig, and the
//! file's axes from its rest pose.
//!
//! Joints are placed by name ([`super::joint_names`]) and by position in the hierarchy:
//! the spine joints between pelvis and neck are spread over CMU's three (`LowerBack`,
//! `Spine`, `Spine1`: the first, the second if there are three or more, the last), the
//! neck joints over its two, the thumb and the first other finger of each hand over
//! `LThumb`, `LeftFingerBase` and `LeftHandFinger1`. Rig bones a file lacks follow their
//! parent: a bone between two placed ones (`Neck1` under a one-joint neck) turns with the
//! placed bone above it, which then spans both.
//!
//! Up is the rest pose's direction from the feet to the head, rounded to the nearest axis
//! (`+Y`, `+Z`, ...); the body's left is the direction from the right hip and shoulder to
//! the left ones, rounded to the nearest axis across it; the body faces `left x up`.

use glam::{DMat3, DQuat, DVec3};

use super::bvh::{Bvh, BvhJoint};
use super::cmu::CMU_BONES;
use super::error::PoseError;
use super::joint_names::{role, Limb, Role, Side};
use super::source::{SourceFrame, SourceSkeleton};

/// How a BVH skeleton sits on garnet's rig (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct BvhRig {
    /// The CMU rig bone each file joint drives (`LeftUpLeg`), `[joints]`; `None` for a
    /// joint the rig has no place for (end joints, extra spine joints, props).
    pub placed: Vec<Option<&'static str>>,
    /// The rotation from the file's axes to garnet's (Y up, the body facing +Z).
    pub to_garnet: DQuat,
    /// The file's up axis (a unit axis such as `+Z`).
    pub up: DVec3,
    /// The axis the rest body faces in the file.
    pub forward: DVec3,
    /// File joint of each driven rig bone, `[E]`.
    joints: Vec<usize>,
    /// The file joint each driven bone points to, if it points to a joint, `[E]`.
    tails: Vec<Option<usize>>,
    /// Rest vector of each driven bone, garnet axes, metres, `[E]`.
    rest: Vec<DVec3>,
    /// Index in `joints` of the pelvis.
    root: usize,
}

/// Rig bones a file must have to be placed, with the words errors use for them.
const REQUIRED: [(&str, &str); 15] = [
    ("Hips", "hips (pelvis)"),
    ("LowerBack", "spine"),
    ("Head", "head"),
    ("LeftUpLeg", "left thigh"),
    ("LeftLeg", "left shin"),
    ("LeftFoot", "left foot"),
    ("RightUpLeg", "right thigh"),
    ("RightLeg", "right shin"),
    ("RightFoot", "right foot"),
    ("LeftArm", "left upper arm"),
    ("LeftForeArm", "left forearm"),
    ("LeftHand", "left hand"),
    ("RightArm", "right upper arm"),
    ("RightForeArm", "right forearm"),
    ("RightHand", "right hand"),
];

const LIMBS: [Limb; 9] = [
    Limb::HipJoint,
    Limb::UpLeg,
    Limb::Leg,
    Limb::Foot,
    Limb::Toe,
    Limb::Shoulder,
    Limb::Arm,
    Limb::ForeArm,
    Limb::Hand,
];

/// CMU rig name of a limb bone.
fn limb_bone(side: Side, limb: Limb) -> &'static str {
    let names = match limb {
        Limb::HipJoint => ["LHipJoint", "RHipJoint"],
        Limb::UpLeg => ["LeftUpLeg", "RightUpLeg"],
        Limb::Leg => ["LeftLeg", "RightLeg"],
        Limb::Foot => ["LeftFoot", "RightFoot"],
        Limb::Toe => ["LeftToeBase", "RightToeBase"],
        Limb::Shoulder => ["LeftShoulder", "RightShoulder"],
        Limb::Arm => ["LeftArm", "RightArm"],
        Limb::ForeArm => ["LeftForeArm", "RightForeArm"],
        Limb::Hand => ["LeftHand", "RightHand"],
    };
    names[(side == Side::Right) as usize]
}

fn cmu(name: &str) -> usize {
    CMU_BONES.iter().position(|b| b.name == name).unwrap_or(0)
}

/// The CMU bone that continues bone `b`'s chain (`Spine1` -> `Neck`, `LeftHand` ->
/// `LeftFingerBase`), if any.
pub(super) fn chain_child(b: usize) -> Option<usize> {
    CMU_BONES
        .get(b + 1)
        .filter(|c| c.parent == Some(b))
        .map(|_| b + 1)
}

/// Whether joint `a` is a proper ancestor of joint `b`.
fn is_ancestor(joints: &[BvhJoint], a: usize, mut b: usize) -> bool {
    while let Some(p) = joints[b].parent {
        if p == a {
            return true;
        }
        b = p;
    }
    false
}

/// Ancestors of joint `j` (itself included) whose role is `r`, root first.
fn chain_above(joints: &[BvhJoint], roles: &[Option<Role>], j: usize, r: Role) -> Vec<usize> {
    let mut out = Vec::new();
    let mut at = Some(j);
    while let Some(k) = at {
        if roles[k] == Some(r) {
            out.push(k);
        }
        at = joints[k].parent;
    }
    out.reverse();
    out
}

/// The CMU bone (index in [`CMU_BONES`]) each joint stands for `[joints]`, and the words
/// for the required parts not found.
pub(super) fn assign(joints: &[BvhJoint]) -> (Vec<Option<usize>>, Vec<&'static str>) {
    let roles: Vec<Option<Role>> = joints.iter().map(|j| role(&j.name)).collect();
    let first = |r: Role| roles.iter().position(|&x| x == Some(r));
    let mut bones: Vec<Option<usize>> = vec![None; joints.len()];
    for side in [Side::Left, Side::Right] {
        for limb in LIMBS {
            if let Some(j) = first(Role::Limb(side, limb)) {
                bones[j] = Some(cmu(limb_bone(side, limb)));
            }
        }
        // A "shoulder" that is the forearm's parent is the upper arm (`LeftShoulder`,
        // `LeftElbow`) when no joint is named as one.
        let at = |bones: &[Option<usize>], limb| {
            let b = cmu(limb_bone(side, limb));
            bones.iter().position(|&x| x == Some(b))
        };
        if let (None, Some(s), Some(f)) = (
            at(&bones, Limb::Arm),
            at(&bones, Limb::Shoulder),
            at(&bones, Limb::ForeArm),
        ) {
            if joints[f].parent == Some(s) {
                bones[s] = Some(cmu(limb_bone(side, Limb::Arm)));
            }
        }
    }
    let thigh = bones.iter().position(|&b| b == Some(cmu("LeftUpLeg")));
    let hips: Vec<usize> = (0..joints.len())
        .filter(|&j| roles[j] == Some(Role::Hips))
        .collect();
    let pelvis = hips
        .iter()
        .rev()
        .find(|&&h| thigh.is_some_and(|t| is_ancestor(joints, h, t)))
        .or(hips.first());
    if let Some(&h) = pelvis {
        bones[h] = Some(0);
    }
    let head = first(Role::Head);
    let necks = head.map_or(Vec::new(), |h| chain_above(joints, &roles, h, Role::Neck));
    let top = necks.first().copied().or(head);
    let spine = top.map_or(Vec::new(), |t| chain_above(joints, &roles, t, Role::Spine));
    for (chain, rig) in [
        (&spine, &["LowerBack", "Spine", "Spine1"][..]),
        (&necks, &["Neck", "Neck1"]),
    ] {
        let n = chain.len();
        for (k, &j) in chain.iter().enumerate() {
            let slot = match k {
                0 => Some(0),
                _ if k == n - 1 => Some(rig.len() - 1),
                1 if rig.len() > 2 => Some(1),
                _ => None,
            };
            bones[j] = slot.map(|s| cmu(rig[s]));
        }
    }
    if let Some(h) = head {
        bones[h] = Some(cmu("Head"));
    }
    for side in [Side::Left, Side::Right] {
        place_fingers(joints, &roles, &mut bones, side);
    }
    let missing = REQUIRED
        .iter()
        .filter(|(name, _)| !bones.contains(&Some(cmu(name))))
        .map(|(_, words)| *words)
        .collect();
    (bones, missing)
}

/// Places the thumb and the first finger (two joints) of one hand.
fn place_fingers(
    joints: &[BvhJoint],
    roles: &[Option<Role>],
    bones: &mut [Option<usize>],
    side: Side,
) {
    let (thumb, base, tip) = match side {
        Side::Left => ("LThumb", "LeftFingerBase", "LeftHandFinger1"),
        Side::Right => ("RThumb", "RightFingerBase", "RightHandFinger1"),
    };
    let hand_bone = cmu(limb_bone(side, Limb::Hand));
    let Some(hand) = bones.iter().position(|&b| b == Some(hand_bone)) else {
        return;
    };
    if let Some(t) = (0..joints.len())
        .find(|&j| roles[j] == Some(Role::Thumb(side)) && is_ancestor(joints, hand, j))
    {
        bones[t] = Some(cmu(thumb));
    }
    let rank = |j: usize| match roles[j] {
        Some(Role::Finger(s, r)) if s == side => Some(r),
        _ => None,
    };
    let Some(f) = (0..joints.len())
        .filter(|&j| joints[j].parent == Some(hand) && rank(j).is_some())
        .min_by_key(|&j| rank(j))
    else {
        return;
    };
    bones[f] = Some(cmu(base));
    if let Some(g) = (0..joints.len()).find(|&j| joints[j].parent == Some(f) && rank(j).is_some()) {
        bones[g] = Some(cmu(tip));
    }
}

/// Rest positions of the joints `[joints]`: the OFFSETs summed down the hierarchy (file
/// units and axes).
pub(super) fn rest_positions(joints: &[BvhJoint]) -> Vec<DVec3> {
    let mut pos: Vec<DVec3> = Vec::with_capacity(joints.len());
    for j in joints {
        pos.push(j.parent.map_or(DVec3::ZERO, |p| pos[p]) + j.offset);
    }
    pos
}

/// The signed coordinate axis nearest to `v` (non-zero).
fn snap(v: DVec3) -> DVec3 {
    let a = v.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        DVec3::X
    } else if a.y >= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    axis * v.dot(axis).signum()
}

fn joint_for(bones: &[Option<usize>], name: &str) -> Option<usize> {
    let b = cmu(name);
    bones.iter().position(|&x| x == Some(b))
}

/// The up axis of the rest skeleton in file axes (feet to head, rounded to an axis), if
/// the names place the head and both feet.
pub(super) fn rest_up(bones: &[Option<usize>], pos: &[DVec3]) -> Option<DVec3> {
    let at = |n: &str| joint_for(bones, n).map(|j| pos[j]);
    let up = at("Head")? - 0.5 * (at("LeftFoot")? + at("RightFoot")?);
    (up.length() > 1e-12).then(|| snap(up))
}

impl BvhRig {
    /// Places `bvh`'s skeleton on garnet's rig and finds its axes. Errors
    /// ([`PoseError::Skeleton`], naming the file) when a required part (hips, spine, head,
    /// thighs, shins, feet, upper arms, forearms, hands) has no joint, listing those parts
    /// and the joints whose names were not recognised, or when the rest pose does not
    /// stand (the head not above the hips, a knee not below its hip).
    pub fn new(bvh: &Bvh) -> Result<BvhRig, PoseError> {
        let err = |message: String| PoseError::Skeleton {
            path: bvh.path.clone(),
            message,
        };
        let (bones, missing) = assign(&bvh.joints);
        if !missing.is_empty() {
            let unknown: Vec<&str> = bvh
                .joints
                .iter()
                .filter(|j| role(&j.name).is_none())
                .map(|j| j.name.as_str())
                .collect();
            return Err(err(format!(
                "cannot place the skeleton ({} joints) on garnet's rig: no joint for {}; \
                 joints not recognised: {}",
                bvh.joints.len(),
                missing.join(", "),
                if unknown.is_empty() {
                    "none".into()
                } else {
                    unknown.join(", ")
                }
            )));
        }
        let (_, pos) = bvh.pose(None)?;
        let at = |n: &str| joint_for(&bones, n).map_or(DVec3::ZERO, |j| pos[j]);
        let up = rest_up(&bones, &pos)
            .ok_or_else(|| err("the rest pose's head and feet coincide".into()))?;
        let stands = (at("Head") - at("Hips")).dot(up) > 0.0
            && ["Left", "Right"]
                .iter()
                .all(|s| (at(&format!("{s}Leg")) - at(&format!("{s}UpLeg"))).dot(up) < 0.0);
        if !stands {
            return Err(err(format!(
                "the rest pose does not stand: along the up axis {up} (feet to head) the \
                 head is not above the hips or a knee not below its hip"
            )));
        }
        let across = at("LeftUpLeg") - at("RightUpLeg") + at("LeftArm") - at("RightArm");
        let across = across - up * across.dot(up);
        if across.length() < 1e-9 {
            return Err(err(
                "the rest pose's left and right hips and arms coincide".into()
            ));
        }
        let left = snap(across);
        let forward = left.cross(up);
        let to_garnet = DQuat::from_mat3(&DMat3::from_cols(left, up, forward).transpose());
        let placed = bones.iter().map(|b| b.map(|b| CMU_BONES[b].name)).collect();
        let mut rig = BvhRig {
            placed,
            to_garnet,
            up,
            forward,
            joints: Vec::new(),
            tails: Vec::new(),
            rest: Vec::new(),
            root: 0,
        };
        for (s, b) in bones.iter().enumerate() {
            let Some(b) = *b else { continue };
            if b == 0 {
                rig.root = rig.joints.len();
            }
            let tail = tail_joint(&bvh.joints, &bones, s, b);
            let joint = &bvh.joints[s];
            let v = match tail {
                Some(t) => pos[t] - pos[s],
                None => {
                    joint.end_site.unwrap_or_else(|| mean_child_offset(bvh, s))
                        * bvh.metres_per_unit
                }
            };
            rig.joints.push(s);
            rig.tails.push(tail);
            rig.rest
                .push(if b == 0 { DVec3::ZERO } else { to_garnet * v });
        }
        Ok(rig)
    }

    /// The skeleton as the retargeter sees it: one bone per driven rig bone, rest vectors
    /// in garnet's axes (metres).
    pub fn skeleton(&self, bvh: &Bvh) -> SourceSkeleton {
        let names = self
            .joints
            .iter()
            .map(|&j| self.placed[j].unwrap_or_default().to_string())
            .collect();
        let (world, pos) = bvh.pose(None).unwrap_or_default();
        let ends = bvh.end_sites(&world, &pos);
        let y = |p: &DVec3| (self.to_garnet * *p).y;
        let root_y = y(&pos[self.joints[self.root]]);
        let lowest = pos.iter().chain(&ends).map(y).fold(root_y, f64::min);
        SourceSkeleton::new(names, self.rest.clone(), self.root, root_y - lowest)
    }

    /// Frame `f` of `bvh` in garnet's axes: each driven bone's world rotation from its
    /// rest, turned so that its rest vector lands on the posed joint it points to (which
    /// joints between them the rig lacks may have moved), and the pelvis position
    /// (metres).
    pub fn frame(&self, bvh: &Bvh, f: usize) -> Result<SourceFrame, PoseError> {
        let (world, pos) = bvh.pose(Some(f))?;
        let c = self.to_garnet;
        let rotations = self
            .joints
            .iter()
            .zip(&self.tails)
            .zip(&self.rest)
            .map(|((&s, tail), rest)| {
                let g = c * world[s] * c.inverse();
                let Some(t) = tail else { return g };
                let (from, to) = (g * *rest, c * (pos[*t] - pos[s]));
                if from.length() > 1e-12 && to.length() > 1e-12 {
                    (DQuat::from_rotation_arc(from.normalize(), to.normalize()) * g).normalize()
                } else {
                    g
                }
            })
            .collect();
        Ok(SourceFrame {
            world: rotations,
            root_position: c * pos[self.joints[self.root]],
        })
    }
}

/// The joint that file joint `s` (driving CMU bone `b`) points to: the first joint below
/// it that drives a bone further down `b`'s chain.
fn tail_joint(joints: &[BvhJoint], bones: &[Option<usize>], s: usize, b: usize) -> Option<usize> {
    if b == 0 {
        return None;
    }
    let mut c = chain_child(b);
    while let Some(ci) = c {
        if let Some(t) = bones.iter().position(|&x| x == Some(ci)) {
            if is_ancestor(joints, s, t) {
                return Some(t);
            }
        }
        c = chain_child(ci);
    }
    None
}

/// The mean OFFSET of joint `j`'s children (file units); zero for a leaf.
fn mean_child_offset(bvh: &Bvh, j: usize) -> DVec3 {
    let kids: Vec<DVec3> = bvh
        .joints
        .iter()
        .filter(|c| c.parent == Some(j))
        .map(|c| c.offset)
        .collect();
    kids.iter().sum::<DVec3>() / (kids.len().max(1) as f64)
}
