//! A small library of yoga-like and dance-like key poses, defined anatomically (degrees,
//! see [`JointAngles`](super::JointAngles) for the meaning of each angle). Asymmetric
//! poses are written with the left side leading; mirror them for the other side.

use super::anatomy::AnatomicalPose;

/// The family a key pose belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PoseFamily {
    /// Yoga-like: held, often asymmetric stances.
    Yoga,
    /// Dance-like or casual stances.
    Dance,
}

/// A named key pose of the library.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum KeyPose {
    /// Standing relaxed, arms slightly away from the body.
    Stand,
    /// Tree: on the left leg, the right foot against the left thigh, arms overhead.
    Tree,
    /// Warrior II: wide stance, left knee bent to the side, arms horizontal.
    WarriorII,
    /// Triangle: wide straight-legged stance, torso bent to the left, arms vertical.
    Triangle,
    /// Chair: knees and hips bent as if sitting, arms raised forward.
    Chair,
    /// Both arms raised overhead, a slight back bend.
    ArmsRaised,
    /// High lunge: left knee bent forward, right leg extended back on its toes.
    Lunge,
    /// On the right leg, the left knee raised to hip height, arms out.
    OneLegBalance,
    /// Standing side bend to the left, right arm reaching overhead.
    SideBend,
    /// Standing with both hands on the hips, elbows out.
    HandsOnHips,
    /// Arabesque: on the left leg, the right leg extended behind, arms forward and out.
    Arabesque,
    /// Plie in second position: turned-out legs apart, knees bent, arms open.
    Plie,
    /// Disco point: right arm up diagonally, left hand on the hip, weight on one leg.
    DiscoPoint,
    /// Mid side-step of a social dance, arms bent.
    SideStep,
}

impl KeyPose {
    /// Every key pose.
    pub const ALL: [KeyPose; 14] = [
        KeyPose::Stand,
        KeyPose::Tree,
        KeyPose::WarriorII,
        KeyPose::Triangle,
        KeyPose::Chair,
        KeyPose::ArmsRaised,
        KeyPose::Lunge,
        KeyPose::OneLegBalance,
        KeyPose::SideBend,
        KeyPose::HandsOnHips,
        KeyPose::Arabesque,
        KeyPose::Plie,
        KeyPose::DiscoPoint,
        KeyPose::SideStep,
    ];

    /// The key poses of one family.
    pub fn family_members(family: PoseFamily) -> Vec<KeyPose> {
        Self::ALL
            .into_iter()
            .filter(|k| k.family() == family)
            .collect()
    }

    /// The family of the pose.
    pub fn family(self) -> PoseFamily {
        use KeyPose::*;
        match self {
            Tree | WarriorII | Triangle | Chair | ArmsRaised | Lunge | OneLegBalance | SideBend => {
                PoseFamily::Yoga
            }
            Stand | HandsOnHips | Arabesque | Plie | DiscoPoint | SideStep => PoseFamily::Dance,
        }
    }

    /// `(bone, flex, abd, twist)` in degrees.
    #[rustfmt::skip]
    fn table(self) -> &'static [(&'static str, f32, f32, f32)] {
        use KeyPose::*;
        match self {
            Stand => &[
                ("LeftUpLeg", 0.0, 3.0, 0.0), ("RightUpLeg", 0.0, 3.0, 0.0),
                ("LeftFoot", 0.0, 0.0, 8.0), ("RightFoot", 0.0, 0.0, 8.0),
                ("LeftArm", 0.0, 8.0, 0.0), ("RightArm", 0.0, 8.0, 0.0),
                ("LeftForeArm", 12.0, 0.0, 10.0), ("RightForeArm", 12.0, 0.0, 10.0),
                ("LeftHandFinger1", 15.0, 0.0, 0.0), ("RightHandFinger1", 15.0, 0.0, 0.0),
            ],
            Tree => &[
                ("LeftUpLeg", 0.0, 2.0, 0.0), ("LeftLeg", 2.0, 0.0, 0.0),
                ("RightUpLeg", 45.0, 50.0, -50.0), ("RightLeg", 140.0, 0.0, 0.0),
                ("RightFoot", 30.0, 0.0, 0.0),
                ("LeftShoulder", 0.0, 15.0, 0.0), ("RightShoulder", 0.0, 15.0, 0.0),
                ("LeftArm", 0.0, 160.0, 0.0), ("RightArm", 0.0, 160.0, 0.0),
                ("LeftForeArm", 10.0, 0.0, 0.0), ("RightForeArm", 10.0, 0.0, 0.0),
            ],
            WarriorII => &[
                ("LeftUpLeg", 46.7, 52.2, -25.9), ("LeftLeg", 85.0, 0.0, 0.0),
                ("LeftFoot", -17.8, 4.1, 24.0),
                ("RightUpLeg", -5.0, 47.2, 10.0), ("RightFoot", -20.6, 5.6, -10.0),
                ("LeftArm", 0.0, 90.0, 0.0), ("RightArm", 0.0, 90.0, 0.0),
                ("Neck", 0.0, 0.0, 30.0), ("Neck1", 0.0, 0.0, 30.0),
            ],
            Triangle => &[
                ("Hips", 0.0, 30.0, 0.0),
                ("LowerBack", 0.0, 15.0, 0.0), ("Spine", 0.0, 15.0, 0.0),
                ("Spine1", 0.0, 10.0, 0.0),
                ("LeftUpLeg", 23.0, 60.0, -49.2), ("LeftFoot", 24.7, 15.5, 35.0),
                ("RightUpLeg", 1.5, -13.1, 10.0), ("RightFoot", -0.7, -1.9, 0.0),
                ("LeftArm", 0.0, 90.0, 0.0), ("RightArm", 0.0, 90.0, 0.0),
            ],
            Chair => &[
                ("Hips", 25.0, 0.0, 0.0), ("LowerBack", 5.0, 0.0, 0.0), ("Spine", 5.0, 0.0, 0.0),
                ("LeftUpLeg", 90.0, 5.0, 0.0), ("RightUpLeg", 90.0, 5.0, 0.0),
                ("LeftLeg", 90.0, 0.0, 0.0), ("RightLeg", 90.0, 0.0, 0.0),
                ("LeftFoot", -25.0, 0.0, 0.0), ("RightFoot", -25.0, 0.0, 0.0),
                ("LeftArm", 160.0, 10.0, 0.0), ("RightArm", 160.0, 10.0, 0.0),
                ("LeftForeArm", 5.0, 0.0, 0.0), ("RightForeArm", 5.0, 0.0, 0.0),
            ],
            ArmsRaised => &[
                ("Spine", -5.0, 0.0, 0.0), ("Spine1", -5.0, 0.0, 0.0), ("Neck", -10.0, 0.0, 0.0),
                ("LeftShoulder", 0.0, 15.0, 0.0), ("RightShoulder", 0.0, 15.0, 0.0),
                ("LeftArm", 10.0, 165.0, 0.0), ("RightArm", 10.0, 165.0, 0.0),
                ("LeftUpLeg", 0.0, 3.0, 0.0), ("RightUpLeg", 0.0, 3.0, 0.0),
            ],
            Lunge => &[
                ("Hips", 30.0, 0.0, 0.0), ("LowerBack", -12.0, 0.0, 0.0),
                ("Spine", -10.0, 0.0, 0.0), ("Spine1", -8.0, 0.0, 0.0),
                ("LeftUpLeg", 112.0, 5.0, 0.0), ("LeftLeg", 82.0, 0.0, 0.0),
                ("RightUpLeg", -30.0, 5.0, 0.0), ("RightLeg", 5.0, 0.0, 0.0),
                ("RightFoot", 4.7, 0.0, 0.0), ("RightToeBase", 66.9, 0.0, 0.0),
                ("LeftArm", 165.0, 5.0, 0.0), ("RightArm", 165.0, 5.0, 0.0),
            ],
            OneLegBalance => &[
                ("LeftUpLeg", 90.0, 5.0, 0.0), ("LeftLeg", 90.0, 0.0, 0.0),
                ("LeftFoot", 20.0, 0.0, 0.0), ("RightUpLeg", 0.0, 2.0, 0.0),
                ("LeftArm", 0.0, 80.0, 0.0), ("RightArm", 0.0, 80.0, 0.0),
                ("LeftForeArm", 10.0, 0.0, 0.0), ("RightForeArm", 10.0, 0.0, 0.0),
            ],
            SideBend => &[
                ("LowerBack", 0.0, 12.0, 0.0), ("Spine", 0.0, 12.0, 0.0),
                ("Spine1", 0.0, 10.0, 0.0), ("Neck", 0.0, 5.0, 0.0),
                ("LeftUpLeg", 0.0, 8.0, 0.0), ("RightUpLeg", 0.0, 8.0, 0.0),
                ("RightArm", 0.0, 165.0, 0.0), ("LeftArm", 0.0, 10.0, 0.0),
            ],
            HandsOnHips => &[
                ("LeftUpLeg", 0.0, 5.0, 0.0), ("RightUpLeg", 0.0, 5.0, 0.0),
                ("LeftArm", -20.0, 45.0, 30.0), ("RightArm", -20.0, 45.0, 30.0),
                ("LeftForeArm", 100.0, 0.0, 30.0), ("RightForeArm", 100.0, 0.0, 30.0),
            ],
            Arabesque => &[
                ("Hips", 20.0, 0.0, 0.0), ("LowerBack", -10.0, 0.0, 0.0), ("Spine", -5.0, 0.0, 0.0),
                ("LeftUpLeg", 20.0, 0.0, -10.0),
                ("RightUpLeg", -30.0, 10.0, -20.0), ("RightFoot", 40.0, 0.0, 0.0),
                ("LeftArm", 90.0, 0.0, 0.0), ("RightArm", 0.0, 80.0, 0.0),
            ],
            Plie => &[
                ("LeftUpLeg", 35.0, 35.0, -45.0), ("RightUpLeg", 35.0, 35.0, -45.0),
                ("LeftLeg", 70.0, 0.0, 0.0), ("RightLeg", 70.0, 0.0, 0.0),
                ("LeftFoot", -22.0, -8.0, 20.0), ("RightFoot", -22.0, -8.0, 20.0),
                ("LeftArm", 15.0, 70.0, 0.0), ("RightArm", 15.0, 70.0, 0.0),
                ("LeftForeArm", 20.0, 0.0, 0.0), ("RightForeArm", 20.0, 0.0, 0.0),
            ],
            DiscoPoint => &[
                ("Hips", 0.0, 0.0, 10.0), ("Spine1", 0.0, -8.0, -10.0),
                ("LeftUpLeg", 10.0, 23.0, -10.0), ("LeftLeg", 16.9, 0.0, 0.0),
                ("LeftFoot", 28.0, 0.0, 0.0), ("RightUpLeg", 0.0, 3.0, 0.0),
                ("RightArm", 20.0, 150.0, 0.0),
                ("LeftArm", -20.0, 45.0, 30.0), ("LeftForeArm", 100.0, 0.0, 30.0),
            ],
            SideStep => &[
                ("Hips", 0.0, -5.0, 10.0),
                ("LeftUpLeg", 0.0, 20.0, 0.0), ("LeftLeg", 15.0, 0.0, 0.0),
                ("RightUpLeg", 5.0, 5.0, 0.0), ("RightLeg", 25.0, 0.0, 0.0),
                ("RightFoot", -19.1, 0.0, 0.0),
                ("LeftArm", 30.0, 30.0, 0.0), ("LeftForeArm", 90.0, 0.0, 0.0),
                ("RightArm", -10.0, 25.0, 0.0), ("RightForeArm", 70.0, 0.0, 0.0),
            ],
        }
    }

    /// The pose's anatomical angles.
    pub fn pose(self) -> AnatomicalPose {
        AnatomicalPose::from_degrees(self.table())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose::cmu::cmu_index;

    #[test]
    fn library_is_complete_and_well_named() {
        assert!(KeyPose::ALL.len() >= 8);
        assert!(KeyPose::family_members(PoseFamily::Yoga).len() >= 6);
        assert!(KeyPose::family_members(PoseFamily::Dance).len() >= 4);
        for k in KeyPose::ALL {
            for (name, ..) in k.table() {
                assert!(cmu_index(name).is_some(), "{k:?}: unknown bone {name}");
            }
        }
    }
}
