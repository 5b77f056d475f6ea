//! The skeleton of a shaped body: bones with rest joints and rest frames, and forward
//! kinematics from a [`Pose`] to per-bone rigid skinning transforms.
//!
//! Conventions (as Blender, which authored the MakeHuman `cmu_mb` rig): a bone's local +Y
//! axis runs from its head to its tail; its rest frame is the smallest rotation taking
//! +Y to that direction followed by the bone's roll about it, both evaluated in Blender's
//! Z-up world and then expressed in garnet's Y-up world. Pose rotations are bone-local
//! (in the bone's rest frame), so `t-pose.json` Euler angles and joint limits keep the
//! meaning their authors gave them.

use glam::{Mat3, Quat, Vec3};

/// One bone of a shaped rest skeleton (metres, garnet world: Y up, facing +Z).
#[derive(Clone, Debug, PartialEq)]
pub struct Bone {
    /// Name as in the rig file and the CMU BVH conversions (`Hips`, `LeftUpLeg`, ...).
    pub name: String,
    /// Index of the parent bone; parents always precede their children.
    pub parent: Option<usize>,
    /// Rest position of the joint the bone rotates about, metres.
    pub head: Vec3,
    /// Rest position of the bone's end, metres.
    pub tail: Vec3,
    /// Rest orientation: maps bone-local axes to world axes (local +Y = head->tail).
    pub frame: Quat,
}

/// A skeleton in its rest pose: bones in parent-before-child order.
#[derive(Clone, Debug, PartialEq)]
pub struct Rig {
    /// `[B]` bones, parents before children.
    pub bones: Vec<Bone>,
}

/// A pose of a rig: one bone-local rotation per bone (`[B]`, in rig bone order) and a
/// world-space translation of the root bone's head (metres).
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    /// World-space offset of the root bone's head from its rest position, metres.
    pub root_translation: Vec3,
    /// `[B]` bone-local rotations (in each bone's rest frame), rig bone order.
    pub rotations: Vec<Quat>,
}

/// A rigid transform `x -> rotation * x + translation` (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidTransform {
    /// Rotation part.
    pub rotation: Quat,
    /// Translation part, metres.
    pub translation: Vec3,
}

impl RigidTransform {
    /// The transform that moves nothing.
    pub const IDENTITY: Self = Self {
        rotation: Quat::IDENTITY,
        translation: Vec3::ZERO,
    };

    /// Applies the transform to a point.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }
}

impl Pose {
    /// The rest pose of a rig with `bone_count` bones: every rotation the identity.
    pub fn identity(bone_count: usize) -> Self {
        Self {
            root_translation: Vec3::ZERO,
            rotations: vec![Quat::IDENTITY; bone_count],
        }
    }

    /// Builds a pose from world-space rotation deltas `[B]` (the rotation each bone
    /// undergoes relative to its rest orientation, as in retargeting), inverting
    /// [`Rig::world_rotations`].
    pub fn from_world_rotations(rig: &Rig, world: &[Quat], root_translation: Vec3) -> Self {
        let rotations = rig
            .bones
            .iter()
            .zip(world)
            .map(|(bone, &w)| {
                let parent = bone.parent.map_or(Quat::IDENTITY, |p| world[p]);
                (bone.frame.inverse() * parent.inverse() * w * bone.frame).normalize()
            })
            .collect();
        Self {
            root_translation,
            rotations,
        }
    }

    /// Interpolates two poses of the same rig bone by bone (slerp) and the root
    /// translation linearly; `t` in [0, 1].
    pub fn slerp(&self, other: &Pose, t: f32) -> Pose {
        Pose {
            root_translation: self.root_translation.lerp(other.root_translation, t),
            rotations: self
                .rotations
                .iter()
                .zip(&other.rotations)
                .map(|(a, b)| a.slerp(*b, t))
                .collect(),
        }
    }
}

/// Garnet world (Y up, facing +Z) to Blender world (Z up, facing -Y): `(x, y, z) -> (x, -z, y)`.
pub const GARNET_TO_BLENDER: Mat3 = Mat3::from_cols(
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(0.0, -1.0, 0.0),
);

/// Blender's bone rest frame for a unit direction `dir` and `roll` (radians), both in
/// Blender's world: the smallest rotation taking +Y to `dir`, then a rotation by `roll`
/// about local +Y. A direction (anti)parallel to -Y uses the half turn about Z.
pub fn blender_bone_frame(dir: Vec3, roll: f32) -> Mat3 {
    const SAFE_THRESHOLD: f32 = 6.1e-3;
    let (x, y, z) = (dir.x, dir.y, dir.z);
    let theta = 1.0 + y;
    let theta_alt = x * x + z * z;
    let align = if theta > SAFE_THRESHOLD || theta_alt > 1e-10 {
        // Rodrigues' rotation about Y x dir, written without trigonometry; near -Y
        // 1 + y loses precision, so use its series in x^2 + z^2 instead.
        let t = if theta > SAFE_THRESHOLD {
            theta
        } else {
            theta_alt * 0.5 + theta_alt * theta_alt * 0.125
        };
        Mat3::from_cols(
            Vec3::new(1.0 - x * x / t, -x, -x * z / t),
            Vec3::new(x, y, z),
            Vec3::new(-x * z / t, -z, 1.0 - z * z / t),
        )
    } else {
        Mat3::from_diagonal(Vec3::new(-1.0, -1.0, 1.0))
    };
    align * Mat3::from_rotation_y(roll)
}

/// A bone's rest frame in garnet's world from its head, tail and Blender roll (radians).
pub fn rest_frame(head: Vec3, tail: Vec3, roll: f32) -> Quat {
    let dir_blender = (GARNET_TO_BLENDER * (tail - head)).normalize_or(Vec3::Y);
    let frame_blender = blender_bone_frame(dir_blender, roll);
    Quat::from_mat3(&(GARNET_TO_BLENDER.transpose() * frame_blender)).normalize()
}

impl Rig {
    /// Number of bones.
    pub fn len(&self) -> usize {
        self.bones.len()
    }

    /// Whether the rig has no bones.
    pub fn is_empty(&self) -> bool {
        self.bones.is_empty()
    }

    /// Index of the bone called `name`, if any.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.bones.iter().position(|b| b.name == name)
    }

    /// Indices of the children of bone `i`.
    pub fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.bones
            .iter()
            .enumerate()
            .filter(move |(_, b)| b.parent == Some(i))
            .map(|(j, _)| j)
    }

    /// Bone `i` and every bone below it (children, their children...): the limb it moves.
    pub fn limb(&self, i: usize) -> Vec<usize> {
        let mut out = vec![i];
        let mut stack: Vec<usize> = self.children(i).collect();
        while let Some(c) = stack.pop() {
            out.push(c);
            stack.extend(self.children(c));
        }
        out
    }

    /// Swings a limb rigidly: sets the world rotation deltas `world` (`[B]`) of `bone` and
    /// every bone below it to the rotation that turns `bone`'s rest direction (head to tail)
    /// to `dir` (any length). [`Pose::from_world_rotations`] makes the pose.
    pub fn swing_limb(&self, world: &mut [Quat], bone: usize, dir: Vec3) {
        let b = &self.bones[bone];
        let swing = Quat::from_rotation_arc((b.tail - b.head).normalize(), dir.normalize());
        for c in self.limb(bone) {
            world[c] = swing;
        }
    }

    /// World-space rotation deltas `[B]` of every bone for `pose` (rest -> posed).
    pub fn world_rotations(&self, pose: &Pose) -> Vec<Quat> {
        let mut world: Vec<Quat> = Vec::with_capacity(self.bones.len());
        for (bone, local) in self.bones.iter().zip(&pose.rotations) {
            let parent = bone.parent.map_or(Quat::IDENTITY, |p| world[p]);
            world.push((parent * bone.frame * *local * bone.frame.inverse()).normalize());
        }
        world
    }

    /// Forward kinematics: the rigid skinning transform `[B]` of every bone, mapping a
    /// rest-pose point attached to the bone to its posed position (metres).
    /// Every bone's head follows its parent's transform; the root's head moves by
    /// `pose.root_translation`.
    pub fn skinning_transforms(&self, pose: &Pose) -> Vec<RigidTransform> {
        assert_eq!(
            pose.rotations.len(),
            self.bones.len(),
            "pose/rig bone count"
        );
        let world = self.world_rotations(pose);
        let mut out: Vec<RigidTransform> = Vec::with_capacity(self.bones.len());
        for (bone, &rotation) in self.bones.iter().zip(&world) {
            let posed_head = match bone.parent {
                Some(p) => out[p].apply(bone.head),
                None => bone.head + pose.root_translation,
            };
            out.push(RigidTransform {
                rotation,
                translation: posed_head - rotation * bone.head,
            });
        }
        out
    }

    /// Posed head and tail of every bone `[B]` (metres).
    pub fn posed_joints(&self, pose: &Pose) -> Vec<(Vec3, Vec3)> {
        self.skinning_transforms(pose)
            .iter()
            .zip(&self.bones)
            .map(|(t, b)| (t.apply(b.head), t.apply(b.tail)))
            .collect()
    }
}
