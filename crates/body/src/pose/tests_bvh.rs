//! Unit tests of the BVH reader and writer.

use std::path::Path;

use glam::{DQuat, DVec3};

use super::test_util::{MINI_AMC, MINI_ASF};
use super::{bvh_string, Amc, Asf, Bvh, BvhWriteOptions, PoseError};

const TWO_JOINTS: &str = "\
HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT LeftUpLeg
  {
    OFFSET 10 0 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 -100 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0
1 90 2 90 0 0 30 40 50
";

fn parse_err(text: &str) -> (usize, String) {
    match Bvh::parse(text, Path::new("t.bvh"), Some(0.01)).unwrap_err() {
        PoseError::Parse { line, message, .. } => (line, message),
        other => panic!("not a parse error: {other}"),
    }
}

#[test]
fn reads_hierarchy_and_motion() {
    let bvh = Bvh::parse(TWO_JOINTS, Path::new("t.bvh"), Some(0.01)).unwrap();
    assert_eq!(bvh.joints.len(), 2);
    assert_eq!(bvh.channel_count, 9);
    assert_eq!(bvh.frame_count(), 2);
    assert!((bvh.frame_rate() - 30.0).abs() < 1e-3);
    assert_eq!(bvh.joints[1].first_channel, 6);
    let (world, pos) = bvh.pose(Some(1)).unwrap();
    let r = |a: DVec3, d: f64| DQuat::from_axis_angle(a, d.to_radians());
    let root = r(DVec3::Z, 90.0);
    let leg = root * r(DVec3::X, 30.0) * r(DVec3::Y, 40.0) * r(DVec3::Z, 50.0);
    assert!(world[0].angle_between(root) < 1e-9 && world[1].angle_between(leg) < 1e-9);
    assert!((pos[0] - DVec3::new(0.01, 0.9, 0.02)).length() < 1e-12);
    assert!((pos[1] - (pos[0] + root * DVec3::new(0.1, 0.0, 0.0))).length() < 1e-12);
    let ends = bvh.end_sites(&world, &pos);
    assert!((ends[0] - (pos[1] + leg * DVec3::new(0.0, -1.0, 0.0))).length() < 1e-12);
    assert!(matches!(
        bvh.pose(Some(2)),
        Err(PoseError::FrameOutOfRange { .. })
    ));
}

#[test]
fn detects_the_length_unit() {
    let scaled = |s: f64| TWO_JOINTS.replace("0 -100 0", &format!("0 {} 0", -s));
    let unit = |t: &str| {
        Bvh::parse(t, Path::new("t.bvh"), None)
            .unwrap()
            .metres_per_unit
    };
    assert_eq!(unit(&scaled(1.6)), 1.0);
    assert_eq!(unit(&scaled(160.0)), 0.01);
    assert_eq!(unit(&scaled(1600.0)), 0.001);
    assert_eq!(unit(&scaled(63.0)), 0.0254);
    assert_eq!(unit(&scaled(28.0)), 0.0254 / 0.45);
}

#[test]
fn errors_name_the_line() {
    let cases = [
        (
            TWO_JOINTS.replace("1 90 2 90 0 0 30 40 50\n", ""),
            19,
            "ends after 1 of 2 frames",
        ),
        (
            TWO_JOINTS.replace("0 0 30 40 50", "0 0 30 40"),
            20,
            "8 values, expected 9",
        ),
        (
            TWO_JOINTS.replace("0 0 30 40 50", "0 0 30 40 50 60"),
            20,
            "10 values, expected 9",
        ),
        (
            TWO_JOINTS.replace("0 0 30 40 50", "0 0 30 nan 50"),
            20,
            "non-finite",
        ),
        (
            TWO_JOINTS.replace("Xrotation Yrotation Zrotation", "Xrotation Yrotation"),
            9,
            "wrong channel count",
        ),
        (
            TWO_JOINTS.replace("CHANNELS 3", "CHANNELS 7"),
            9,
            "bad channel count",
        ),
        (
            TWO_JOINTS.replace("OFFSET 10 0 0", "OFFSET 10 zero 0"),
            8,
            "non-numeric",
        ),
        (
            TWO_JOINTS.replace("Frames: 2", "Frames: 1"),
            20,
            "more frames than the 1 declared",
        ),
        (
            TWO_JOINTS.replace("Frames: 2", "Frame: 2"),
            17,
            "expected 'Frames:'",
        ),
        (
            TWO_JOINTS.split("MOTION").next().unwrap().to_string(),
            15,
            "no MOTION",
        ),
        (
            TWO_JOINTS.replace("  }\n}\n", "  }\n"),
            15,
            "hierarchy ends",
        ),
    ];
    for (text, want_line, want) in cases {
        let (line, msg) = parse_err(&text);
        assert!(msg.contains(want), "{msg} lacks {want}");
        assert_eq!(line, want_line, "{msg}");
    }
}

#[test]
fn written_bvh_reproduces_the_asf_clip() {
    let asf = Asf::parse(MINI_ASF, Path::new("mini.asf")).unwrap();
    let amc = Amc::parse(MINI_AMC, Path::new("mini.amc"), &asf).unwrap();
    let text = bvh_string(&asf, &amc, &BvhWriteOptions::default()).unwrap();
    assert!(text.contains("JOINT LeftUpLeg") && text.contains("End Site"));
    let bvh = Bvh::parse(&text, Path::new("mini.bvh"), Some(asf.metres_per_unit())).unwrap();
    assert_eq!(bvh.frame_count(), 2);
    for f in 0..2 {
        let (root, ends) = asf.joint_positions(&asf.pose_of(&amc, f).unwrap());
        let (world, pos) = bvh.pose(Some(f)).unwrap();
        assert!((pos[0] - root).length() < 1e-6);
        for (i, b) in asf.bones.iter().enumerate() {
            let name = super::cmu::rig_name_for_asf(&b.name).unwrap();
            let j = bvh.joint_index(name).unwrap();
            assert!((pos[j] - ends[i].0).length() < 1e-6, "{name} frame {f}");
        }
        let tips = bvh.end_sites(&world, &pos);
        let leaf_tails = [
            asf.bone_index("ltibia").unwrap(),
            asf.bone_index("lowerback").unwrap(),
        ];
        for (t, &i) in tips.iter().zip(&leaf_tails) {
            assert!((*t - ends[i].1).length() < 1e-6);
        }
    }
    let opts = BvhWriteOptions {
        frame_time: f64::NAN,
        ..Default::default()
    };
    assert!(bvh_string(&asf, &amc, &opts).is_err());
}

#[test]
fn names_with_spaces_and_position_channels_that_repeat_the_offset() {
    // A 3ds Max style name, and a joint whose position channels repeat its OFFSET (read as
    // its position, not added to it) in frame 0 and move it in frame 1.
    let text = TWO_JOINTS
        .replace("JOINT LeftUpLeg", "JOINT Bip01 L Thigh")
        .replace(
            "CHANNELS 3 Xrotation Yrotation Zrotation",
            "CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation",
        )
        .replace("0 90 0 0 0 0 0 0 0\n", "0 90 0 0 0 0 10 0 0 0 0 0\n")
        .replace("1 90 2 90 0 0 30 40 50", "0 90 0 0 0 0 12 0 0 0 0 0");
    let bvh = Bvh::parse(&text, Path::new("t.bvh"), Some(0.01)).unwrap();
    assert_eq!(bvh.joints[1].name, "Bip01 L Thigh");
    let x = |f| bvh.pose(f).unwrap().1[1].x;
    assert!((x(None) - 0.1).abs() < 1e-12);
    assert!((x(Some(0)) - 0.1).abs() < 1e-12);
    assert!((x(Some(1)) - 0.12).abs() < 1e-12);
    // Position channels near zero add to the OFFSET.
    let added = text
        .replace(" 10 0 0 0 0 0\n", " 0 0 0 0 0 0\n")
        .replace(" 12 0 0", " 2 0 0");
    let bvh = Bvh::parse(&added, Path::new("t.bvh"), Some(0.01)).unwrap();
    assert!((bvh.pose(Some(1)).unwrap().1[1].x - 0.12).abs() < 1e-12);
}
