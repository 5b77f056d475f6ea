//! A parametric walk cycle: joint angles as smooth periodic functions of the gait phase,
//! shaped after typical gait-lab curves, their amplitudes scaled by the stride.

use super::anatomy::{AnatomicalPose, JointAngles};

/// Parameters of one instant of a walk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkParams {
    /// Gait phase in [0, 1): 0 is the left heel strike, 0.5 the right one.
    pub phase: f32,
    /// Stride length (two steps), metres.
    pub stride_length: f32,
    /// Hip-to-ankle leg length of the body, metres (a normal stride is about 1.65 leg
    /// lengths).
    pub leg_length: f32,
    /// Arm swing scale (1 is a relaxed walk, 0 no swing).
    pub arm_swing: f32,
}

impl Default for WalkParams {
    fn default() -> Self {
        Self {
            phase: 0.0,
            stride_length: 1.4,
            leg_length: 0.85,
            arm_swing: 1.0,
        }
    }
}

/// Periodic bump centred at `c` of width `w` (phase units), 1 at the centre.
fn bump(phase: f32, c: f32, w: f32) -> f32 {
    let mut d = (phase - c).rem_euclid(1.0);
    if d > 0.5 {
        d -= 1.0;
    }
    (-0.5 * (d / w) * (d / w)).exp()
}

fn cos_turn(x: f32) -> f32 {
    (std::f32::consts::TAU * x).cos()
}

/// Sagittal angles in degrees of one leg at its own phase: (hip flex, knee flex, ankle
/// plantarflexion, toe extension).
fn leg(phase: f32, k: f32) -> (f32, f32, f32, f32) {
    let hip = k * (10.0 + 20.0 * cos_turn(phase - 0.97));
    let knee = 4.0 + k * (15.0 * bump(phase, 0.13, 0.06) + 55.0 * bump(phase, 0.72, 0.11));
    let ankle = k
        * (5.0 * bump(phase, 0.06, 0.04) - 10.0 * bump(phase, 0.42, 0.12)
            + 18.0 * bump(phase, 0.62, 0.05));
    let toe = k * 25.0 * bump(phase, 0.56, 0.06);
    (hip, knee, ankle, toe)
}

/// The anatomical pose of a walk at `p.phase`. The pose does not depend on cadence;
/// stride and arm swing scale the amplitudes.
pub fn walk_pose(p: &WalkParams) -> AnatomicalPose {
    let phase = if p.phase.is_finite() {
        p.phase.rem_euclid(1.0)
    } else {
        0.0
    };
    let ratio = if p.leg_length > 0.0 {
        p.stride_length / p.leg_length
    } else {
        1.65
    };
    let k = (ratio / 1.65).clamp(0.15, 1.6);
    let swing = if p.arm_swing.is_finite() {
        p.arm_swing.clamp(0.0, 2.0)
    } else {
        1.0
    };
    let mut pose = AnatomicalPose::neutral();
    let pelvis_turn = -4.0 * k * cos_turn(phase);
    let list = 3.0 * k * (bump(phase, 0.15, 0.08) - bump(phase, 0.65, 0.08));
    pose.set("Hips", JointAngles::deg(2.0, -list, pelvis_turn));
    pose.set(
        "LowerBack",
        JointAngles::deg(0.0, 0.6 * list, -0.5 * pelvis_turn),
    );
    pose.set(
        "Spine",
        JointAngles::deg(2.0, 0.4 * list, -0.5 * pelvis_turn),
    );
    pose.set("Spine1", JointAngles::deg(1.0, 0.0, -0.5 * pelvis_turn));
    pose.set("Neck", JointAngles::deg(-3.0, 0.0, 0.5 * pelvis_turn));
    for (side, offset) in [("Left", 0.0), ("Right", 0.5)] {
        let ph = (phase + offset).rem_euclid(1.0);
        let (hip, knee, ankle, toe) = leg(ph, k);
        pose.set(&format!("{side}UpLeg"), JointAngles::deg(hip, 2.0, -3.0));
        pose.set(&format!("{side}Leg"), JointAngles::deg(knee, 0.0, 0.0));
        pose.set(&format!("{side}Foot"), JointAngles::deg(ankle, 0.0, 7.0));
        pose.set(&format!("{side}ToeBase"), JointAngles::deg(toe, 0.0, 0.0));
        let shoulder = -swing * k * 18.0 * cos_turn(ph - 0.97);
        pose.set(&format!("{side}Arm"), JointAngles::deg(shoulder, 8.0, 0.0));
        let elbow = 12.0 + 0.6 * shoulder.max(0.0) + 4.0 * swing;
        pose.set(
            &format!("{side}ForeArm"),
            JointAngles::deg(elbow, 0.0, 10.0),
        );
        pose.set(&format!("{side}Hand"), JointAngles::deg(8.0, 0.0, 0.0));
        pose.set(
            &format!("{side}FingerBase"),
            JointAngles::deg(10.0, 0.0, 0.0),
        );
        pose.set(
            &format!("{side}HandFinger1"),
            JointAngles::deg(15.0, 0.0, 0.0),
        );
    }
    pose
}
