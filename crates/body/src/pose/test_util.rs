//! Small hand-made skeletons, clips and rigs for the unit tests.

use glam::Vec3;

use crate::rig::{rest_frame, Bone, Rig};

/// A four-bone ASF in the CMU style (left leg and lower back).
pub const MINI_ASF: &str = "\
# test skeleton
:version 1.10
:name VICON
:units
  mass 1.0
  length 0.45
  angle deg
:documentation
   hand-made
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name lhipjoint
     direction 1 -1 0
     length 2
     axis 0 0 0  XYZ
  end
  begin
     id 2
     name lfemur
     direction 0 -1 0
     length 7
     axis 0 0 20  XYZ
    dof rx ry rz
    limits (-160.0 20.0)
           (-70.0 70.0)
           (-60.0 70.0)
  end
  begin
     id 3
     name ltibia
     direction 0 -1 0
     length 7
     axis 0 0 20 XYZ
    dof rx
    limits (-10.0 170.0)
  end
  begin
     id 4
     name lowerback
     direction 0 1 0
     length 2
     axis 0 0 0 XYZ
    dof rx ry rz
  end
:hierarchy
  begin
    root lhipjoint lowerback
    lhipjoint lfemur
    lfemur ltibia
  end
";

/// Two frames of [`MINI_ASF`]: rest, then the hip flexed 90 degrees (`rx -90`).
pub const MINI_AMC: &str = "\
#!OML:ASF mini.asf
:FULLY-SPECIFIED
:DEGREES
1
root 0 16 0 0 0 0
lowerback 0 0 0
lfemur 0 0 0
ltibia 0
2
root 1 17 2 0 90 0
lfemur -90 0 0
ltibia 0
lowerback 10 0 0
";

fn bone(name: &str, parent: Option<usize>, head: [f32; 3], tail: [f32; 3]) -> Bone {
    let (head, tail) = (Vec3::from(head), Vec3::from(tail));
    Bone {
        name: name.into(),
        parent,
        head,
        tail,
        frame: rest_frame(head, tail, 0.3),
    }
}

/// A six-bone rig: hips, lower back, spine, and a left leg whose thigh points down and
/// slightly out, plus an extra bone (`Tail`) that no motion source drives.
pub fn mini_rig() -> Rig {
    Rig {
        bones: vec![
            bone("Hips", None, [0.0, 0.9, 0.0], [0.0, 1.0, 0.0]),
            bone("LowerBack", Some(0), [0.0, 1.0, 0.0], [0.0, 1.15, -0.02]),
            bone("LHipJoint", Some(0), [0.0, 0.9, 0.0], [0.1, 0.88, 0.0]),
            bone("LeftUpLeg", Some(2), [0.1, 0.88, 0.0], [0.13, 0.48, 0.02]),
            bone("LeftLeg", Some(3), [0.13, 0.48, 0.02], [0.15, 0.07, 0.0]),
            bone("Tail", Some(4), [0.15, 0.07, 0.0], [0.15, 0.02, 0.1]),
        ],
    }
}
