//! Pose readers on the real CMU clips (skipped when the shared mocap folder is absent)
//! and on the hand-made malformed fixtures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use body::pose::synthetic::a_pose_rig;
use body::pose::{
    bvh_string, save_bvh, Amc, Asf, Bvh, BvhWriteOptions, Clip, PoseError, RetargetOptions,
};
use body::rig::{Pose, Rig};

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The CMU subject 02 folder, or `None` (with a message) when it is absent.
fn cmu02() -> Option<PathBuf> {
    let dir = crate_dir().join("../../../shared/mocap/cmu/02");
    if dir.join("02.asf").is_file() && dir.join("02_01.amc").is_file() {
        Some(dir)
    } else {
        println!("skipped: {} not found", dir.display());
        None
    }
}

fn fixture(name: &str) -> PathBuf {
    crate_dir().join("tests/fixtures").join(name)
}

#[test]
fn cmu_walk_parses() {
    let Some(dir) = cmu02() else { return };
    let asf = Asf::read(dir.join("02.asf")).unwrap();
    assert_eq!(asf.bones.len(), 30);
    let femur = &asf.bones[asf.bone_index("lfemur").unwrap()];
    assert!((femur.length * asf.metres_per_unit() - 0.4286).abs() < 1e-3);
    let t = Instant::now();
    let amc = Amc::read(dir.join("02_01.amc"), &asf).unwrap();
    println!(
        "02_01.amc: {} frames read in {:?}",
        amc.frame_count(),
        t.elapsed()
    );
    assert_eq!(amc.frame_count(), 343);
    assert_eq!(amc.frame_numbers[342], 343);
}

#[test]
fn long_amc_reads_fast() {
    let Some(dir) = cmu02() else { return };
    let asf = Asf::read(dir.join("02.asf")).unwrap();
    let text = std::fs::read_to_string(dir.join("02_01.amc")).unwrap();
    // The 29 bone lines of the first frame (the line after the frame number "1").
    let lines: Vec<&str> = text.lines().collect();
    let first = lines.iter().position(|l| l.trim() == "1").unwrap();
    let body: String = lines[first + 1..first + 30]
        .iter()
        .map(|l| format!("{l}\n"))
        .collect();
    let mut long = String::from(":FULLY-SPECIFIED\n:DEGREES\n");
    for f in 1..=4000 {
        long.push_str(&format!("{f}\n{body}"));
    }
    let t = Instant::now();
    let amc = Amc::parse(&long, Path::new("long.amc"), &asf).unwrap();
    let took = t.elapsed();
    println!("4000-frame AMC parsed in {took:?}");
    assert_eq!(amc.frame_count(), 4000);
    assert!(took.as_secs_f64() < 2.0);
}

/// Posed head/tail of a rig bone.
fn at(rig: &Rig, pose: &Pose, name: &str) -> (glam::Vec3, glam::Vec3) {
    rig.posed_joints(pose)[rig.index(name).unwrap()]
}

#[test]
fn retargeted_walk_stands_upright() {
    let Some(dir) = cmu02() else { return };
    let clip = Clip::from_asf_amc(dir.join("02.asf"), dir.join("02_01.amc")).unwrap();
    assert_eq!(clip.frame_count(), 343);
    assert_eq!(clip.frame_rate(), 120.0);
    let rig = a_pose_rig();
    let opts = RetargetOptions::default();
    let t = Instant::now();
    let pose = clip.pose(0, &rig, &opts).unwrap();
    println!("one frame retargeted in {:?}", t.elapsed());
    for f in [0, 85, 170, 255, 342] {
        let pose = if f == 0 {
            pose.clone()
        } else {
            clip.pose(f, &rig, &opts).unwrap()
        };
        let head = at(&rig, &pose, "Head").1;
        let hips = at(&rig, &pose, "Hips").0;
        assert!(pose.root_translation.x == 0.0 && pose.root_translation.z == 0.0);
        let feet: Vec<f32> = ["LeftFoot", "RightFoot", "LeftToeBase", "RightToeBase"]
            .iter()
            .map(|n| at(&rig, &pose, n).1.y)
            .collect();
        let lowest = feet.iter().copied().fold(f32::INFINITY, f32::min);
        assert!(
            head.y > hips.y + 0.5 && feet.iter().all(|&y| y < hips.y - 0.5),
            "frame {f}"
        );
        assert!(
            lowest > -0.05 && lowest < 0.1,
            "frame {f}: feet at {feet:?}"
        );
        for side in ["Left", "Right"] {
            let shoulder = at(&rig, &pose, &format!("{side}Arm")).0;
            let hand = at(&rig, &pose, &format!("{side}Hand")).0;
            assert!(
                hand.y < shoulder.y - 0.3,
                "frame {f}: {side} hand not below the shoulder"
            );
        }
        let left = at(&rig, &pose, "LeftUpLeg").0;
        let right = at(&rig, &pose, "RightUpLeg").0;
        assert!(left.x > right.x, "frame {f}: left hip not at +X");
    }
    let keep = RetargetOptions {
        keep_horizontal_translation: true,
    };
    let a = clip.pose(0, &rig, &keep).unwrap().root_translation;
    let b = clip.pose(342, &rig, &keep).unwrap().root_translation;
    assert!(b.z - a.z > 1.0, "the walk moves forward (+Z): {a} -> {b}");
    assert!(matches!(
        clip.pose(343, &rig, &opts),
        Err(PoseError::FrameOutOfRange {
            frame: 343,
            count: 343
        })
    ));
}

#[test]
fn bvh_written_from_the_walk_reads_back() {
    let Some(dir) = cmu02() else { return };
    let asf = Asf::read(dir.join("02.asf")).unwrap();
    let amc = Amc::read(dir.join("02_01.amc"), &asf).unwrap();
    let path = std::env::temp_dir().join(format!("garnet_pose_{}_02_01.bvh", std::process::id()));
    save_bvh(&path, &asf, &amc, &BvhWriteOptions::default()).unwrap();
    let bvh = Bvh::read(&path, None).unwrap();
    assert!(
        (bvh.metres_per_unit - asf.metres_per_unit()).abs() < 1e-12,
        "unit detected"
    );
    assert_eq!(bvh.joints.len(), 31);
    assert_eq!(bvh.frame_count(), 343);
    let height = 1.7;
    let mut worst: f64 = 0.0;
    for f in 0..amc.frame_count() {
        let (root, ends) = asf.joint_positions(&asf.pose_of(&amc, f).unwrap());
        let (world, pos) = bvh.pose(Some(f)).unwrap();
        worst = worst.max((pos[0] - root).length());
        for (i, b) in asf.bones.iter().enumerate() {
            let j = bvh
                .joint_index(body::pose::cmu::rig_name_for_asf(&b.name).unwrap())
                .unwrap();
            worst = worst.max((pos[j] - ends[i].0).length());
        }
        let tips = bvh.end_sites(&world, &pos);
        assert_eq!(tips.len(), 7);
    }
    println!("BVH round trip: worst joint error {worst:e} m");
    assert!(worst < 1e-4 * height);
    // The BVH clip retargets like the ASF/AMC clip.
    let rig = a_pose_rig();
    let from_bvh = Clip::from_bvh(&path, None).unwrap();
    let from_amc = Clip::from_asf_amc(dir.join("02.asf"), dir.join("02_01.amc")).unwrap();
    assert!((from_bvh.frame_rate() - 120.0).abs() < 1e-3);
    for f in [0, 200] {
        let a = rig.posed_joints(&from_amc.pose(f, &rig, &RetargetOptions::default()).unwrap());
        let b = rig.posed_joints(&from_bvh.pose(f, &rig, &RetargetOptions::default()).unwrap());
        for ((ah, at), (bh, bt)) in a.iter().zip(&b) {
            assert!(
                (*ah - *bh).length() < 1e-3 && (*at - *bt).length() < 1e-3,
                "frame {f}"
            );
        }
    }
    std::fs::remove_file(&path).ok();
    // Writing is deterministic.
    assert_eq!(
        bvh_string(&asf, &amc, &BvhWriteOptions::default()).unwrap(),
        bvh_string(&asf, &amc, &BvhWriteOptions::default()).unwrap()
    );
}

#[test]
fn valid_fixtures_read() {
    let asf = Asf::read(fixture("mini.asf")).unwrap();
    let amc = Amc::read(fixture("mini.amc"), &asf).unwrap();
    assert_eq!((asf.bones.len(), amc.frame_count()), (4, 2));
    let clip = Clip::from_bvh(fixture("mini.bvh"), None).unwrap();
    assert_eq!(clip.frame_count(), 3);
    let bvh = Bvh::read(fixture("mini.bvh"), None).unwrap();
    assert!((bvh.metres_per_unit - 0.0254 / 0.45).abs() < 1e-12);
}

/// Asserts that reading `name` fails with an error naming the file and `line`.
fn rejected(name: &str, result: Result<(), PoseError>, line: usize, words: &str) {
    let err = result.expect_err(name);
    let text = err.to_string();
    assert!(text.contains(name), "{text} does not name {name}");
    assert!(
        text.contains(&format!(":{line}: ")),
        "{text}: expected line {line}"
    );
    assert!(text.contains(words), "{text} lacks '{words}'");
    match err {
        PoseError::Parse { path, line: l, .. } => assert!(path.ends_with(name) && l == line),
        other => panic!("{other}"),
    }
}

#[test]
fn malformed_fixtures_are_rejected_with_file_and_line() {
    let asf_err = |n: &str| Asf::read(fixture(n)).map(|_| ());
    rejected("truncated.asf", asf_err("truncated.asf"), 30, "truncated");
    rejected(
        "bad_length.asf",
        asf_err("bad_length.asf"),
        27,
        "non-numeric value '7.O'",
    );
    rejected(
        "undefined_bone.asf",
        asf_err("undefined_bone.asf"),
        56,
        "'lfoot' was never defined",
    );
    let asf = Asf::read(fixture("mini.asf")).unwrap();
    let amc_err = |n: &str| Amc::read(fixture(n), &asf).map(|_| ());
    rejected(
        "unknown_bone.amc",
        amc_err("unknown_bone.amc"),
        11,
        "unknown bone 'rfemur'",
    );
    rejected(
        "missing_value.amc",
        amc_err("missing_value.amc"),
        11,
        "2 values, expected 3",
    );
    rejected("truncated.amc", amc_err("truncated.amc"), 11, "truncated");
    rejected("nan_angle.amc", amc_err("nan_angle.amc"), 8, "non-finite");
    let bvh_err = |n: &str| Bvh::read(fixture(n), None).map(|_| ());
    rejected(
        "truncated_motion.bvh",
        bvh_err("truncated_motion.bvh"),
        26,
        "7 values, expected 12",
    );
    rejected(
        "wrong_channels.bvh",
        bvh_err("wrong_channels.bvh"),
        13,
        "wrong channel count",
    );
    let missing = Asf::read(fixture("no_such.asf")).unwrap_err();
    assert!(matches!(missing, PoseError::Io { .. }) && missing.to_string().contains("no_such.asf"));
}
