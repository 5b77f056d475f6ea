//! The seeded procedural pose generator.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

use super::anatomy::{AnatomicalPose, JointAngles, BONES};
use super::library::{KeyPose, PoseFamily};
use super::limits::JointLimits;
use super::walk::{walk_pose, WalkParams};
use crate::pose::cmu::{mirror_index, CMU_BONES};
use crate::pose::error::PoseError;
use crate::pose::retarget::rig_leg_length;
use crate::rig::{Pose, Rig};

/// What kind of poses a [`ProceduralPoseGenerator`] draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PoseKind {
    /// Instants of a walk: random phase, stride and arm swing.
    Walk,
    /// Yoga-like key poses, mirrored at random, blended and perturbed.
    Yoga,
    /// Dance-like key poses, sometimes blended with a walk, perturbed.
    Dance,
    /// Any of the above, equally likely.
    Any,
}

/// Standard deviations in degrees of the noise on (flex, abd, twist) of a left-side or
/// central bone.
fn noise_deg(name: &str) -> [f32; 3] {
    match name {
        "Hips" => [3.0, 3.0, 6.0],
        "LowerBack" | "Spine" | "Spine1" => [4.0, 3.0, 4.0],
        "Neck" | "Neck1" => [5.0, 4.0, 8.0],
        "Head" => [3.0, 3.0, 3.0],
        "LeftUpLeg" => [8.0, 5.0, 8.0],
        "LeftLeg" => [6.0, 0.0, 2.0],
        "LeftFoot" => [6.0, 4.0, 5.0],
        "LeftToeBase" => [5.0, 0.0, 0.0],
        "LeftShoulder" => [4.0, 4.0, 0.0],
        "LeftArm" => [10.0, 10.0, 12.0],
        "LeftForeArm" => [10.0, 0.0, 12.0],
        "LeftHand" => [10.0, 6.0, 0.0],
        "LeftFingerBase" | "LeftHandFinger1" => [10.0, 0.0, 0.0],
        "LThumb" => [8.0, 8.0, 0.0],
        _ => [0.0; 3],
    }
}

/// A reproducible source of random poses: the same seed gives the same sequence, and
/// [`ProceduralPoseGenerator::pose_at`] gives pose `i` of the sequence directly (for
/// sharded dataset generation).
#[derive(Clone, Debug, PartialEq)]
pub struct ProceduralPoseGenerator {
    /// The seed of the sequence.
    pub seed: u64,
    /// What kind of poses to draw.
    pub kind: PoseKind,
    /// Index of the pose the next [`ProceduralPoseGenerator::sample`] returns.
    pub next_index: u64,
    /// The joint limits every pose is clamped into.
    pub limits: JointLimits,
}

/// SplitMix64 finaliser, to turn (seed, index) into a well-mixed RNG seed.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl ProceduralPoseGenerator {
    /// A generator of `kind` poses from `seed`, starting at index 0, with the default
    /// joint limits.
    pub fn new(seed: u64, kind: PoseKind) -> Self {
        Self {
            seed,
            kind,
            next_index: 0,
            limits: JointLimits::default(),
        }
    }

    /// Anatomical pose `index` of the sequence; `leg_length` (metres) sets the walk's
    /// stride range.
    pub fn anatomical_at(&self, index: u64, leg_length: f32) -> AnatomicalPose {
        let mut rng = StdRng::seed_from_u64(mix(self.seed ^ mix(index)));
        let kind = match self.kind {
            PoseKind::Any => {
                [PoseKind::Walk, PoseKind::Yoga, PoseKind::Dance][rng.random_range(0..3)]
            }
            k => k,
        };
        let leg = if leg_length.is_finite() && leg_length > 0.1 {
            leg_length
        } else {
            0.85
        };
        let (pose, noise) = match kind {
            PoseKind::Walk => (random_walk(&mut rng, leg), 0.4),
            PoseKind::Yoga => (random_key(&mut rng, PoseFamily::Yoga), 1.0),
            _ => {
                let p = random_key(&mut rng, PoseFamily::Dance);
                if rng.random_bool(0.3) {
                    let w = random_walk(&mut rng, leg);
                    let t = rng.random_range(0.3..0.7);
                    (p.lerp(&w, t), 1.0)
                } else {
                    (p, 1.0)
                }
            }
        };
        self.limits.clamp(&add_noise(&mut rng, &pose, noise))
    }

    /// Pose `index` of the sequence on `rig` (feet on the rest floor level).
    pub fn pose_at(&self, index: u64, rig: &Rig) -> Pose {
        self.anatomical_at(index, rig_leg_length(rig)).to_pose(rig)
    }

    /// The next pose of the sequence on `rig`.
    pub fn sample(&mut self, rig: &Rig) -> Pose {
        let pose = self.pose_at(self.next_index, rig);
        self.next_index += 1;
        pose
    }

    /// Draws poses until `accept` takes one (for instance, one whose posed body mesh does
    /// not intersect itself); errors after `max_tries` rejections.
    pub fn sample_accepted(
        &mut self,
        rig: &Rig,
        mut accept: impl FnMut(&Pose) -> bool,
        max_tries: usize,
    ) -> Result<Pose, PoseError> {
        for _ in 0..max_tries {
            let pose = self.sample(rig);
            if accept(&pose) {
                return Ok(pose);
            }
        }
        Err(PoseError::Rejected { tries: max_tries })
    }
}

fn random_walk(rng: &mut StdRng, leg: f32) -> AnatomicalPose {
    walk_pose(&WalkParams {
        phase: rng.random_range(0.0..1.0),
        stride_length: leg * rng.random_range(0.6..2.0),
        leg_length: leg,
        arm_swing: rng.random_range(0.4..1.5),
    })
}

/// A key pose of `family`, mirrored half of the time, blended a little toward standing
/// or toward another pose of the family.
fn random_key(rng: &mut StdRng, family: PoseFamily) -> AnatomicalPose {
    let members = KeyPose::family_members(family);
    let pick = |rng: &mut StdRng| {
        let p = members[rng.random_range(0..members.len())].pose();
        if rng.random_bool(0.5) {
            p.mirrored()
        } else {
            p
        }
    };
    let main = pick(rng);
    if rng.random_bool(0.5) {
        let t = rng.random_range(0.0..0.35);
        main.lerp(&KeyPose::Stand.pose(), t)
    } else {
        let other = pick(rng);
        main.lerp(&other, rng.random_range(0.0..0.2))
    }
}

/// Gaussian noise on every angle, `scale` times the per-bone standard deviations.
fn add_noise(rng: &mut StdRng, pose: &AnatomicalPose, scale: f32) -> AnatomicalPose {
    let mut out = pose.clone();
    for i in 0..BONES {
        let sd = noise_deg(CMU_BONES[mirror_index(i).min(i)].name);
        let v = out.joints[i].to_array();
        let noisy = [0, 1, 2].map(|k| {
            let s = (sd[k] * scale).to_radians();
            match Normal::new(0.0f32, s) {
                Ok(n) if s > 0.0 => v[k] + n.sample(rng),
                _ => v[k],
            }
        });
        out.joints[i] = JointAngles::from_array(noisy);
    }
    out
}
