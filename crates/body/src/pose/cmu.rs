//! Naming of the 31-bone CMU skeleton: the rig (BVH) names, the ASF names and the
//! hierarchy, in parent-before-child order.

/// One bone of the CMU skeleton.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CmuBone {
    /// Name in the `cmu_mb` rig and the CMU BVH conversions (`Hips`, `LeftUpLeg`, ...).
    pub name: &'static str,
    /// Name in the CMU ASF files (`root`, `lfemur`, ...).
    pub asf: &'static str,
    /// Index of the parent in [`CMU_BONES`]; `None` for the root.
    pub parent: Option<usize>,
}

const fn b(name: &'static str, asf: &'static str, parent: Option<usize>) -> CmuBone {
    CmuBone { name, asf, parent }
}

/// The 31 bones of the CMU skeleton, parents before children.
pub const CMU_BONES: [CmuBone; 31] = [
    b("Hips", "root", None),
    b("LHipJoint", "lhipjoint", Some(0)),
    b("LeftUpLeg", "lfemur", Some(1)),
    b("LeftLeg", "ltibia", Some(2)),
    b("LeftFoot", "lfoot", Some(3)),
    b("LeftToeBase", "ltoes", Some(4)),
    b("RHipJoint", "rhipjoint", Some(0)),
    b("RightUpLeg", "rfemur", Some(6)),
    b("RightLeg", "rtibia", Some(7)),
    b("RightFoot", "rfoot", Some(8)),
    b("RightToeBase", "rtoes", Some(9)),
    b("LowerBack", "lowerback", Some(0)),
    b("Spine", "upperback", Some(11)),
    b("Spine1", "thorax", Some(12)),
    b("Neck", "lowerneck", Some(13)),
    b("Neck1", "upperneck", Some(14)),
    b("Head", "head", Some(15)),
    b("LeftShoulder", "lclavicle", Some(13)),
    b("LeftArm", "lhumerus", Some(17)),
    b("LeftForeArm", "lradius", Some(18)),
    b("LeftHand", "lwrist", Some(19)),
    b("LeftFingerBase", "lhand", Some(20)),
    b("LeftHandFinger1", "lfingers", Some(21)),
    b("LThumb", "lthumb", Some(20)),
    b("RightShoulder", "rclavicle", Some(13)),
    b("RightArm", "rhumerus", Some(24)),
    b("RightForeArm", "rradius", Some(25)),
    b("RightHand", "rwrist", Some(26)),
    b("RightFingerBase", "rhand", Some(27)),
    b("RightHandFinger1", "rfingers", Some(28)),
    b("RThumb", "rthumb", Some(27)),
];

/// Index in [`CMU_BONES`] of the bone with rig name `name` (aliases such as
/// `LeftHandIndex1` accepted, see [`canonical_name`]).
pub fn cmu_index(name: &str) -> Option<usize> {
    let name = canonical_name(name);
    CMU_BONES.iter().position(|b| b.name == name)
}

/// The rig name for an ASF bone name (`lfemur` -> `LeftUpLeg`), if it is a CMU bone.
pub fn rig_name_for_asf(asf: &str) -> Option<&'static str> {
    CMU_BONES.iter().find(|b| b.asf == asf).map(|b| b.name)
}

/// Maps the aliases some CMU BVH conversions use to the rig's names
/// (`LeftHandIndex1` -> `LeftHandFinger1`); other names are returned unchanged.
pub fn canonical_name(name: &str) -> &str {
    match name {
        "LeftHandIndex1" => "LeftHandFinger1",
        "RightHandIndex1" => "RightHandFinger1",
        other => other,
    }
}

/// The index of the mirror image (left <-> right) of CMU bone `i`; central bones map
/// to themselves.
pub fn mirror_index(i: usize) -> usize {
    match i {
        1..=5 => i + 5,
        6..=10 => i - 5,
        17..=23 => i + 7,
        24..=30 => i - 7,
        _ => i,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_consistent() {
        for (i, bone) in CMU_BONES.iter().enumerate() {
            if let Some(p) = bone.parent {
                assert!(p < i, "{} before its parent", bone.name);
            }
            let m = mirror_index(i);
            assert_eq!(mirror_index(m), i);
            let mirrored = CMU_BONES[m].name;
            let swapped = bone
                .name
                .replacen("Left", "#", 1)
                .replacen("Right", "Left", 1)
                .replacen('#', "Right", 1)
                .replacen("LHip", "#", 1)
                .replacen("RHip", "LHip", 1)
                .replacen('#', "RHip", 1)
                .replacen("LThumb", "#", 1)
                .replacen("RThumb", "LThumb", 1)
                .replacen('#', "RThumb", 1);
            assert_eq!(mirrored, swapped);
            assert_eq!(cmu_index(bone.name), Some(i));
            assert_eq!(rig_name_for_asf(bone.asf), Some(bone.name));
        }
        assert_eq!(cmu_index("LeftHandIndex1"), Some(22));
    }
}
