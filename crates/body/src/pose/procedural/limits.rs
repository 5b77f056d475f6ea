//! Anatomical ranges of motion per joint and clamping of poses into them.
//!
//! The table is ours, from common clinical ranges of motion (hip flexion to about 125
//! degrees, knee to 150, shoulder elevation to 180, ...), narrowed for the spine segments
//! because three of them add up; angles mean what [`JointAngles`] says.

use super::anatomy::{AnatomicalPose, JointAngles, BONES};
use crate::pose::cmu::{mirror_index, CMU_BONES};

/// Ranges `(min, max)` in degrees of (flex, abd, twist) of a left-side or central bone.
fn range_deg(name: &str) -> [(f32, f32); 3] {
    match name {
        "Hips" => [(-30.0, 60.0), (-40.0, 40.0), (-45.0, 45.0)],
        "LowerBack" | "Spine" | "Spine1" => [(-15.0, 30.0), (-20.0, 20.0), (-15.0, 15.0)],
        "Neck" | "Neck1" => [(-25.0, 30.0), (-20.0, 20.0), (-40.0, 40.0)],
        "Head" => [(-15.0, 15.0), (-10.0, 10.0), (-10.0, 10.0)],
        "LeftUpLeg" => [(-30.0, 125.0), (-30.0, 60.0), (-60.0, 45.0)],
        "LeftLeg" => [(0.0, 150.0), (0.0, 0.0), (-10.0, 10.0)],
        "LeftFoot" => [(-30.0, 50.0), (-25.0, 30.0), (-25.0, 35.0)],
        "LeftToeBase" => [(-30.0, 70.0), (0.0, 0.0), (0.0, 0.0)],
        "LeftShoulder" => [(-15.0, 20.0), (-10.0, 35.0), (0.0, 0.0)],
        "LeftArm" => [(-50.0, 180.0), (-10.0, 180.0), (-70.0, 90.0)],
        "LeftForeArm" => [(0.0, 145.0), (0.0, 0.0), (-80.0, 80.0)],
        "LeftHand" => [(-60.0, 70.0), (-20.0, 35.0), (0.0, 0.0)],
        "LeftFingerBase" => [(-10.0, 60.0), (0.0, 0.0), (0.0, 0.0)],
        "LeftHandFinger1" => [(0.0, 90.0), (0.0, 0.0), (0.0, 0.0)],
        "LThumb" => [(-20.0, 40.0), (-20.0, 40.0), (0.0, 0.0)],
        // LHipJoint: rigid.
        _ => [(0.0, 0.0); 3],
    }
}

/// Per-bone anatomical ranges of motion, radians, `[31]` in CMU bone order.
#[derive(Clone, Debug, PartialEq)]
pub struct JointLimits {
    /// Lower bounds.
    pub min: [JointAngles; BONES],
    /// Upper bounds.
    pub max: [JointAngles; BONES],
}

impl Default for JointLimits {
    /// The built-in anatomical table (the right side mirrors the left).
    fn default() -> Self {
        let mut min = [JointAngles::default(); BONES];
        let mut max = [JointAngles::default(); BONES];
        for i in 0..BONES {
            let r = range_deg(CMU_BONES[mirror_index(i).min(i)].name);
            min[i] = JointAngles::deg(r[0].0, r[1].0, r[2].0);
            max[i] = JointAngles::deg(r[0].1, r[1].1, r[2].1);
        }
        Self { min, max }
    }
}

impl JointLimits {
    /// `pose` with every angle clamped into its range (NaN angles become the range's
    /// nearest value to zero).
    pub fn clamp(&self, pose: &AnatomicalPose) -> AnatomicalPose {
        let mut out = pose.clone();
        for (i, j) in out.joints.iter_mut().enumerate() {
            let (lo, hi) = (self.min[i].to_array(), self.max[i].to_array());
            let v = j.to_array();
            *j = JointAngles::from_array([0, 1, 2].map(|k| {
                let x = if v[k].is_nan() { 0.0 } else { v[k] };
                x.clamp(lo[k], hi[k])
            }));
        }
        out
    }

    /// Whether every angle of `pose` lies in its range (within `tol` radians).
    pub fn contains(&self, pose: &AnatomicalPose, tol: f32) -> bool {
        pose.joints.iter().enumerate().all(|(i, j)| {
            let (lo, hi, v) = (self.min[i].to_array(), self.max[i].to_array(), j.to_array());
            (0..3).all(|k| v[k] >= lo[k] - tol && v[k] <= hi[k] + tol)
        })
    }
}
