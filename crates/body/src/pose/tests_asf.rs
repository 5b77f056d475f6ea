//! Unit tests of the ASF and AMC readers and the ASF forward kinematics.

use std::path::Path;

use glam::DVec3;

use super::test_util::{MINI_AMC, MINI_ASF};
use super::{Amc, Asf, Dof, PoseError};

fn mini() -> (Asf, Amc) {
    let asf = Asf::parse(MINI_ASF, Path::new("mini.asf")).unwrap();
    let amc = Amc::parse(MINI_AMC, Path::new("mini.amc"), &asf).unwrap();
    (asf, amc)
}

fn line_of(e: PoseError) -> (usize, String) {
    match e {
        PoseError::Parse { line, message, .. } => (line, message),
        other => panic!("not a parse error: {other}"),
    }
}

#[test]
fn parses_skeleton() {
    let (asf, _) = mini();
    assert_eq!(asf.bones.len(), 4);
    assert_eq!(asf.name, "VICON");
    assert!((asf.metres_per_unit() - 0.0254 / 0.45).abs() < 1e-12);
    let femur = &asf.bones[asf.bone_index("lfemur").unwrap()];
    assert_eq!(femur.dofs, vec![Dof::Rx, Dof::Ry, Dof::Rz]);
    assert!((femur.limits[0].0 + 160f64.to_radians()).abs() < 1e-12);
    assert!((femur.axis.z - 20f64.to_radians()).abs() < 1e-12);
    assert_eq!(femur.parent, asf.bone_index("lhipjoint"));
    let hip = &asf.bones[0];
    assert!((hip.direction.length() - 1.0).abs() < 1e-12 && hip.parent.is_none());
    let order = asf.order();
    for (k, &i) in order.iter().enumerate() {
        if let Some(p) = asf.bones[i].parent {
            assert!(order[..k].contains(&p));
        }
    }
    assert_eq!(asf.value_layout(), (vec![6, 6, 9, 10], 13));
}

#[test]
fn parses_motion() {
    let (asf, amc) = mini();
    assert_eq!(amc.frame_count(), 2);
    assert_eq!(amc.frame_numbers, vec![1, 2]);
    assert_eq!(amc.root(1)[..3], [1.0, 17.0, 2.0]);
    assert!((amc.root(1)[4] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    let lb = asf.bone_index("lowerback").unwrap();
    assert!((amc.bone(1, lb)[0] - 10f64.to_radians()).abs() < 1e-12);
    assert!(amc.fits(&asf));
}

#[test]
fn kinematics_follow_the_asf_convention() {
    let (asf, amc) = mini();
    let rest = asf.pose_of(&amc, 0).unwrap();
    let (_, ends) = asf.joint_positions(&rest);
    let s = asf.metres_per_unit();
    let femur = asf.bone_index("lfemur").unwrap();
    let tibia = asf.bone_index("ltibia").unwrap();
    assert!((ends[femur].1 - ends[femur].0 - DVec3::new(0.0, -7.0 * s, 0.0)).length() < 1e-12);
    // rx = -90 about the femur's local X (the world X turned 20 degrees about Z) swings
    // the thigh forward (+Z), with the root turned 90 degrees about Y.
    let p = asf.pose_of(&amc, 1).unwrap();
    let (root, ends) = asf.joint_positions(&p);
    assert!((root - DVec3::new(1.0, 17.0, 2.0) * s).length() < 1e-12);
    let thigh = (ends[femur].1 - ends[femur].0).normalize();
    let (s20, c20) = 20f64.to_radians().sin_cos();
    let expected_unturned = DVec3::new(-s20 * c20, -s20 * s20, c20);
    let expected = glam::DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2) * expected_unturned;
    assert!((thigh - expected).length() < 1e-9, "{thigh} vs {expected}");
    assert!((ends[tibia].0 - ends[femur].1).length() < 1e-12);
}

#[test]
fn out_of_range_frame_is_an_error() {
    let (asf, amc) = mini();
    assert!(matches!(
        asf.pose_of(&amc, 2),
        Err(PoseError::FrameOutOfRange { frame: 2, count: 2 })
    ));
}

#[test]
fn asf_errors_name_the_line() {
    let p = Path::new("x.asf");
    let bad_len = MINI_ASF.replace(
        "length 7\n     axis 0 0 20  XYZ",
        "length seven\n     axis 0 0 20  XYZ",
    );
    let (line, msg) = line_of(Asf::parse(&bad_len, p).unwrap_err());
    assert_eq!(line, 27);
    assert!(
        msg.contains("non-numeric") && msg.contains("seven"),
        "{msg}"
    );
    let truncated: String = MINI_ASF.lines().take(30).collect::<Vec<_>>().join("\n");
    let (line, msg) = line_of(Asf::parse(&truncated, p).unwrap_err());
    assert_eq!(line, 30);
    assert!(msg.contains("truncated"), "{msg}");
    let undefined = MINI_ASF.replace("lfemur ltibia", "lfemur ltibia rtibia");
    let (line, msg) = line_of(Asf::parse(&undefined, p).unwrap_err());
    assert_eq!(line, 55);
    assert!(
        msg.contains("rtibia") && msg.contains("never defined"),
        "{msg}"
    );
    let no_hier = MINI_ASF.split(":hierarchy").next().unwrap();
    assert!(line_of(Asf::parse(no_hier, p).unwrap_err())
        .1
        .contains(":hierarchy"));
    let nan = MINI_ASF.replace("direction 0 1 0", "direction 0 nan 0");
    assert!(line_of(Asf::parse(&nan, p).unwrap_err())
        .1
        .contains("non-finite"));
    let limits = MINI_ASF.replace("           (-60.0 70.0)\n", "");
    assert!(line_of(Asf::parse(&limits, p).unwrap_err())
        .1
        .contains("limit values"));
    let orphan = MINI_ASF.replace("    lfemur ltibia\n", "");
    assert!(line_of(Asf::parse(&orphan, p).unwrap_err())
        .1
        .contains("ltibia"));
    assert!(Asf::parse("", p).is_err());
    assert!(Asf::parse("garbage here", p).is_err());
}

#[test]
fn amc_errors_name_the_line() {
    let (asf, _) = mini();
    let p = Path::new("x.amc");
    let cases = [
        (
            MINI_AMC.replace("ltibia 0\n2", "rtibia 0\n2"),
            8,
            "unknown bone 'rtibia'",
        ),
        (
            MINI_AMC.replace("lfemur -90 0 0", "lfemur -90 0"),
            11,
            "has 2 values, expected 3",
        ),
        (
            MINI_AMC.replace("lfemur -90 0 0", "lfemur -90 x 0"),
            11,
            "non-numeric",
        ),
        (
            MINI_AMC.replace("lfemur -90 0 0", "lfemur -90 NaN 0"),
            11,
            "non-finite",
        ),
        (
            MINI_AMC.replace("lowerback 10 0 0\n", ""),
            12,
            "ends in the middle of frame 2",
        ),
        (
            MINI_AMC.replace("lowerback 0 0 0\n", ""),
            4,
            "frame 1 has no values for lowerback",
        ),
        (
            MINI_AMC.replace("ltibia 0\n2", "ltibia 0\nltibia 0\n2"),
            9,
            "given twice",
        ),
        (
            MINI_AMC.replace(":DEGREES\n1\n", ":DEGREES\n"),
            4,
            "before the first frame",
        ),
        (":FULLY-SPECIFIED\n".to_string(), 1, "no frames"),
    ];
    for (text, want_line, want) in cases {
        let (line, msg) = line_of(Amc::parse(&text, p, &asf).unwrap_err());
        assert!(msg.contains(want), "{msg} lacks {want}");
        assert_eq!(line, want_line, "{msg}");
    }
}
