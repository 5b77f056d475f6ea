//! Unit tests of the procedural poses on the synthetic A-pose rig.

use glam::Vec3;

use super::anatomy::foot_heights;
use super::*;
use crate::pose::synthetic::a_pose_rig;
use crate::rig::{Pose, Rig};

fn joint(rig: &Rig, pose: &Pose, name: &str, tail: bool) -> Vec3 {
    let (h, t) = rig.posed_joints(pose)[rig.index(name).unwrap()];
    if tail {
        t
    } else {
        h
    }
}

/// Position of `name`'s head (or tail) after setting one joint's angles, minus neutral.
fn moved(rig: &Rig, bones: &[(&str, f32, f32, f32)], probe: &str, tail: bool) -> Vec3 {
    let posed = AnatomicalPose::from_degrees(bones).to_pose(rig);
    let neutral = AnatomicalPose::neutral().to_pose(rig);
    joint(rig, &posed, probe, tail) - joint(rig, &neutral, probe, tail)
}

#[test]
fn anatomical_signs() {
    let rig = a_pose_rig();
    let up = 0.05;
    assert!(moved(&rig, &[("LeftUpLeg", 45.0, 0.0, 0.0)], "LeftLeg", false).z > up);
    assert!(moved(&rig, &[("RightUpLeg", 45.0, 0.0, 0.0)], "RightLeg", false).z > up);
    assert!(moved(&rig, &[("LeftUpLeg", 0.0, 30.0, 0.0)], "LeftLeg", false).x > up);
    assert!(moved(&rig, &[("RightUpLeg", 0.0, 30.0, 0.0)], "RightLeg", false).x < -up);
    let knee = [("LeftLeg", 90.0, 0.0, 0.0)];
    assert!(moved(&rig, &knee, "LeftFoot", false).z < -0.2);
    let internal = [("LeftUpLeg", 0.0, 0.0, 40.0), ("LeftLeg", 90.0, 0.0, 0.0)];
    assert!(
        moved(&rig, &internal, "LeftFoot", false).x - moved(&rig, &knee, "LeftFoot", false).x > up
    );
    let toes_down = [("LeftFoot", 30.0, 0.0, 0.0)];
    let d =
        moved(&rig, &toes_down, "LeftToeBase", true) - moved(&rig, &toes_down, "LeftFoot", false);
    assert!(d.y < -0.03);
    let raised = moved(&rig, &[("LeftArm", 0.0, 90.0, 0.0)], "LeftForeArm", false);
    assert!(raised.y > 0.2 && raised.x > 0.2, "{raised}");
    assert!(moved(&rig, &[("RightArm", 0.0, 90.0, 0.0)], "RightForeArm", false).x < -0.2);
    assert!(moved(&rig, &[("LeftArm", 90.0, 0.0, 0.0)], "LeftForeArm", false).z > 0.2);
    let elbow = moved(&rig, &[("LeftForeArm", 90.0, 0.0, 0.0)], "LeftHand", false);
    assert!(elbow.z > 0.2, "{elbow}");
    assert!(moved(&rig, &[("LowerBack", 20.0, 0.0, 0.0)], "Head", true).z > up);
    assert!(moved(&rig, &[("LowerBack", 0.0, 20.0, 0.0)], "Head", true).x > up);
    assert!(moved(&rig, &[("Spine1", 0.0, 0.0, 30.0)], "LeftArm", false).z < -up);
    // Neutral: arms hang straight down from the shoulders, legs straight.
    let n = AnatomicalPose::neutral().to_pose(&rig);
    let (sh, hand) = (
        joint(&rig, &n, "LeftArm", false),
        joint(&rig, &n, "LeftHand", false),
    );
    assert!((sh.x - hand.x).abs() < 1e-3 && (sh.z - hand.z).abs() < 1e-3 && hand.y < sh.y - 0.4);
}

#[test]
fn mirroring_swaps_sides() {
    let rig = a_pose_rig();
    let joints = |p: &Pose| rig.posed_joints(p);
    for k in KeyPose::ALL {
        let a = k.pose();
        assert_eq!(a.mirrored().mirrored(), a);
        let ja = joints(&a.to_pose(&rig));
        let jb = joints(&a.mirrored().to_pose(&rig));
        for (i, b) in crate::pose::cmu::CMU_BONES.iter().enumerate() {
            let m = crate::pose::cmu::mirror_index(i);
            let want = ja[m].1 * Vec3::new(-1.0, 1.0, 1.0);
            assert!((jb[i].1 - want).length() < 2e-3, "{k:?} {}", b.name);
        }
    }
}

#[test]
fn key_poses_are_within_limits_and_stand_on_the_floor() {
    let rig = a_pose_rig();
    let limits = JointLimits::default();
    for k in KeyPose::ALL {
        let a = k.pose();
        assert!(limits.contains(&a, 1e-4), "{k:?} outside the limits");
        let pose = a.to_pose(&rig);
        let feet = foot_heights(&rig, &pose);
        let lowest = feet.iter().copied().fold(f32::INFINITY, f32::min);
        assert!(
            lowest.abs() < 1e-4 && feet.iter().all(|h| *h > -1e-4),
            "{k:?}: {feet:?}"
        );
        let head = joint(&rig, &pose, "Head", true);
        assert!(head.y > joint(&rig, &pose, "Hips", false).y, "{k:?}");
    }
    let mut nan = KeyPose::Tree.pose();
    nan.joints[3].flex = f32::NAN;
    nan.joints[18].abd = 9.0;
    let c = limits.clamp(&nan);
    assert!(limits.contains(&c, 0.0) && c.joints[3].flex == 0.0);
    assert_eq!(limits.clamp(&c), c);
}

#[test]
fn walk_cycle_is_periodic_and_symmetric() {
    let rig = a_pose_rig();
    for i in 0..10 {
        let phase = i as f32 / 10.0;
        let p = WalkParams {
            phase,
            ..Default::default()
        };
        let a = walk_pose(&p);
        let b = walk_pose(&WalkParams {
            phase: phase + 1.0,
            ..p
        });
        let c = walk_pose(&WalkParams {
            phase: phase + 0.5,
            ..p
        });
        let close = |x: &AnatomicalPose, y: &AnatomicalPose| {
            x.joints
                .iter()
                .zip(&y.joints)
                .all(|(u, v)| (0..3).all(|k| (u.to_array()[k] - v.to_array()[k]).abs() < 1e-4))
        };
        assert!(close(&a, &b) && close(&c, &a.mirrored()), "phase {phase}");
        assert!(JointLimits::default().contains(&a, 1e-4));
        let feet = foot_heights(&rig, &a.to_pose(&rig));
        assert!(
            feet.iter().all(|h| *h > -1e-4 && *h < 0.3),
            "phase {phase}: {feet:?}"
        );
    }
    let hip_range = |stride: f32| {
        let v: Vec<f32> = (0..20)
            .map(|i| {
                walk_pose(&WalkParams {
                    phase: i as f32 / 20.0,
                    stride_length: stride,
                    ..Default::default()
                })
                .get("LeftUpLeg")
                .unwrap()
                .flex
            })
            .collect();
        v.iter().copied().fold(f32::MIN, f32::max) - v.iter().copied().fold(f32::MAX, f32::min)
    };
    assert!(hip_range(1.6) > hip_range(0.8) * 1.5);
}

#[test]
fn generator_is_reproducible_and_plausible() {
    let rig = a_pose_rig();
    for kind in [
        PoseKind::Walk,
        PoseKind::Yoga,
        PoseKind::Dance,
        PoseKind::Any,
    ] {
        let mut g = ProceduralPoseGenerator::new(42, kind);
        let mut h = ProceduralPoseGenerator::new(42, kind);
        let other = ProceduralPoseGenerator::new(43, kind);
        for i in 0..12 {
            let p = g.sample(&rig);
            assert_eq!(p, h.sample(&rig));
            assert_eq!(p, g.pose_at(i, &rig));
            assert_ne!(p, other.pose_at(i, &rig));
            assert!(JointLimits::default().contains(&g.anatomical_at(i, 0.8), 1e-4));
            let feet = foot_heights(&rig, &p);
            assert!(feet.iter().copied().fold(f32::INFINITY, f32::min).abs() < 1e-4);
            let head = joint(&rig, &p, "Head", true);
            assert!(
                head.y > joint(&rig, &p, "Hips", false).y + 0.2,
                "{kind:?} {i}"
            );
            assert!(p.rotations.iter().all(|q| q.is_finite()));
        }
    }
}

#[test]
fn sample_accepted_retries_then_gives_up() {
    let rig = a_pose_rig();
    let mut g = ProceduralPoseGenerator::new(1, PoseKind::Any);
    let third = g.pose_at(2, &rig);
    let mut calls = 0;
    let got = g
        .sample_accepted(
            &rig,
            |_| {
                calls += 1;
                calls == 3
            },
            10,
        )
        .unwrap();
    assert_eq!(got, third);
    assert_eq!(g.next_index, 3);
    let err = g.sample_accepted(&rig, |_| false, 4).unwrap_err();
    assert!(matches!(err, crate::pose::PoseError::Rejected { tries: 4 }));
}
