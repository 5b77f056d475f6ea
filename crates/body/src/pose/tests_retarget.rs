//! Unit tests of retargeting onto a small synthetic rig.

use std::path::Path;

use glam::{DQuat, DVec3, Quat, Vec3};

use super::test_util::{mini_rig, MINI_AMC, MINI_ASF};
use super::{retarget, Amc, Asf, PoseError, RetargetOptions, SourceFrame, SourceSkeleton};
use crate::rig::Rig;

fn posed_dir(rig: &Rig, pose: &crate::rig::Pose, name: &str) -> Vec3 {
    let (h, t) = rig.posed_joints(pose)[rig.index(name).unwrap()];
    (t - h).normalize()
}

#[test]
fn bone_directions_match_the_source() {
    let rig = mini_rig();
    let asf = Asf::parse(MINI_ASF, Path::new("mini.asf")).unwrap();
    let amc = Amc::parse(MINI_AMC, Path::new("mini.amc"), &asf).unwrap();
    let skel = SourceSkeleton::from_asf(&asf);
    for f in 0..2 {
        let asf_pose = asf.pose_of(&amc, f).unwrap();
        let (_, ends) = asf.joint_positions(&asf_pose);
        let frame = SourceFrame::from_asf(&asf, &asf_pose);
        let pose = retarget(&rig, &skel, &frame, &RetargetOptions::default()).unwrap();
        for (rig_name, asf_name) in [
            ("LeftUpLeg", "lfemur"),
            ("LeftLeg", "ltibia"),
            ("LowerBack", "lowerback"),
        ] {
            let (h, t) = ends[asf.bone_index(asf_name).unwrap()];
            let want = (t - h).normalize().as_vec3();
            let got = posed_dir(&rig, &pose, rig_name);
            assert!(
                (got - want).length() < 1e-5,
                "{rig_name} frame {f}: {got} vs {want}"
            );
        }
        // The pelvic hip bone keeps the rig's own rest direction, turned by the source's
        // rotation from its rest.
        let hip = rig.index("LHipJoint").unwrap();
        let g = frame.world[skel.names.iter().position(|n| n == "LHipJoint").unwrap()].as_quat();
        let rest = (rig.bones[hip].tail - rig.bones[hip].head).normalize();
        assert!((posed_dir(&rig, &pose, "LHipJoint") - g * rest).length() < 1e-5);
        // The root takes the source root's rotation; the undriven bone follows its parent.
        let world = rig.world_rotations(&pose);
        assert!(world[0].angle_between(asf_pose.root_rotation.as_quat()) < 1e-5);
        assert!(world[5].angle_between(world[4]) < 1e-5);
    }
}

#[test]
fn root_translation_scales_by_leg_length() {
    let rig = mini_rig();
    let asf = Asf::parse(MINI_ASF, Path::new("mini.asf")).unwrap();
    let amc = Amc::parse(MINI_AMC, Path::new("mini.amc"), &asf).unwrap();
    let skel = SourceSkeleton::from_asf(&asf);
    let s = asf.metres_per_unit();
    let rest_h = (2.0 / 2f64.sqrt() + 14.0) * s;
    assert!((skel.rest_root_height - rest_h).abs() < 1e-9);
    assert!((skel.leg_length - 14.0 * s).abs() < 1e-9);
    let rig_leg = super::rig_leg_length(&rig) as f64;
    let ratio = rig_leg / (14.0 * s);
    let frame = SourceFrame::from_asf(&asf, &asf.pose_of(&amc, 1).unwrap());
    let keep = RetargetOptions {
        keep_horizontal_translation: true,
    };
    let t = retarget(&rig, &skel, &frame, &keep)
        .unwrap()
        .root_translation
        .as_dvec3();
    let want = DVec3::new(
        1.0 * s * ratio,
        (17.0 * s - rest_h) * ratio,
        2.0 * s * ratio,
    );
    assert!((t - want).length() < 1e-5, "{t} vs {want}");
    let t = retarget(&rig, &skel, &frame, &RetargetOptions::default())
        .unwrap()
        .root_translation;
    assert!(t.x == 0.0 && t.z == 0.0 && (t.y as f64 - want.y).abs() < 1e-6);
}

#[test]
fn antiparallel_and_degenerate_bones_do_not_fail() {
    let rig = mini_rig();
    let skel = SourceSkeleton {
        names: vec!["Hips".into(), "LeftUpLeg".into(), "LeftLeg".into()],
        rest_vectors: vec![DVec3::ZERO, DVec3::Y, DVec3::ZERO],
        root: 0,
        rest_root_height: 1.0,
        leg_length: 0.0,
    };
    let g = DQuat::from_rotation_x(0.7);
    let frame = SourceFrame {
        world: vec![DQuat::IDENTITY, g, g],
        root_position: DVec3::new(0.0, 1.0, 0.0),
    };
    let pose = retarget(&rig, &skel, &frame, &RetargetOptions::default()).unwrap();
    assert!(pose
        .rotations
        .iter()
        .all(|q| q.is_finite() && q.is_normalized()));
    let up = posed_dir(&rig, &pose, "LeftUpLeg");
    assert!((up - (g * DVec3::Y).as_vec3()).length() < 1e-4);
    let bad = SourceFrame {
        world: vec![DQuat::IDENTITY],
        root_position: DVec3::ZERO,
    };
    assert!(matches!(
        retarget(&rig, &skel, &bad, &RetargetOptions::default()),
        Err(PoseError::Invalid(_))
    ));
    let empty = Rig { bones: vec![] };
    assert!(matches!(
        retarget(&empty, &skel, &frame, &RetargetOptions::default()),
        Err(PoseError::Rig(_))
    ));
    let _ = Quat::IDENTITY;
}
