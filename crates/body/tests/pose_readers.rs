//! Pose readers on clips garnet writes itself (a CMU-style skeleton walking, see
//! `body::pose::synthetic_clip`) and on the hand-made malformed fixtures.

use std::path::{Path, PathBuf};
use std::time::Instant;

use body::pose::synthetic::a_pose_rig;
use body::pose::synthetic_clip::{cmu_asf_text, walk_amc_text, write_cmu_clip, WALK_SPEED};
use body::pose::{
    bvh_string, save_bvh, Amc, Asf, Bvh, BvhWriteOptions, Clip, PoseError, RetargetOptions,
};
use body::rig::{Pose, Rig};

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Frames of the walk clip: 2 s at 120 Hz.
const FRAMES: usize = 240;

/// A folder holding the walk `cmu/02/02_01.amc` and its skeleton `cmu/02/02.asf`; returns
/// the folder (kept alive by the guard) and the skeleton and clip paths.
fn walk() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let amc = write_cmu_clip(dir.path(), "cmu/02/02_01.amc", FRAMES).unwrap();
    let asf = dir.path().join("cmu/02/02.asf");
    (dir, asf, amc)
}

fn fixture(name: &str) -> PathBuf {
    crate_dir().join("tests/fixtures").join(name)
}

#[test]
fn cmu_style_walk_parses() {
    let (_dir, asf_path, amc_path) = walk();
    let asf = Asf::read(&asf_path).unwrap();
    assert_eq!(asf.bones.len(), 30);
    assert_eq!(asf.order().len(), 30);
    let femur = &asf.bones[asf.bone_index("lfemur").unwrap()];
    assert!((femur.length * asf.metres_per_unit() - 0.4289).abs() < 1e-3);
    let tibia = asf.bone_index("ltibia").unwrap();
    assert_eq!(asf.bones[tibia].parent, asf.bone_index("lfemur"));
    assert_eq!(asf.bones[asf.bone_index("lhipjoint").unwrap()].parent, None);
    let amc = Amc::read(&amc_path, &asf).unwrap();
    assert_eq!(amc.frame_count(), FRAMES);
    assert_eq!(amc.frame_numbers[FRAMES - 1], FRAMES as i64);
    assert!(amc.fits(&asf));
    // Values read back as written: the root's forward translation (file units) and the
    // left hip's flexion (degrees in the file, radians once read).
    let text = walk_amc_text(FRAMES, 1);
    let lines: Vec<&str> = text.lines().collect();
    let root: Vec<f64> = lines[4]
        .split_whitespace()
        .skip(1)
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(amc
        .root(0)
        .iter()
        .zip(&root)
        .all(|(a, b)| (a - b).abs() < 1e-9));
    let femur_line = lines.iter().find(|l| l.starts_with("lfemur ")).unwrap();
    let rx: f64 = femur_line
        .split_whitespace()
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let lfemur = asf.bone_index("lfemur").unwrap();
    assert!((amc.bone(0, lfemur)[0] - rx.to_radians()).abs() < 1e-9);
}

#[test]
fn long_amc_reads_fast() {
    let asf = Asf::parse(&cmu_asf_text(), Path::new("cmu.asf")).unwrap();
    let long = walk_amc_text(4000, 0);
    let t = Instant::now();
    let amc = Amc::parse(&long, Path::new("long.amc"), &asf).unwrap();
    let took = t.elapsed();
    assert_eq!(amc.frame_count(), 4000);
    assert!(took.as_secs_f64() < 2.0, "4000 frames parsed in {took:?}");
}

/// Posed head/tail of a rig bone.
fn at(rig: &Rig, pose: &Pose, name: &str) -> (glam::Vec3, glam::Vec3) {
    rig.posed_joints(pose)[rig.index(name).unwrap()]
}

#[test]
fn retargeted_walk_stands_upright() {
    let (_dir, asf, amc) = walk();
    let clip = Clip::from_asf_amc(&asf, &amc).unwrap();
    assert_eq!(clip.frame_count(), FRAMES);
    assert_eq!(clip.frame_rate(), 120.0);
    let rig = a_pose_rig();
    let opts = RetargetOptions::default();
    let last = FRAMES - 1;
    for f in [0, 60, 120, 180, last] {
        let pose = clip.pose(f, &rig, &opts).unwrap();
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
    let b = clip.pose(last, &rig, &keep).unwrap().root_translation;
    let walked = WALK_SPEED as f32 * last as f32 / 120.0;
    assert!(
        b.z - a.z > 0.5 * walked,
        "the walk moves forward (+Z): {a} -> {b}"
    );
    assert!(matches!(
        clip.pose(FRAMES, &rig, &opts),
        Err(PoseError::FrameOutOfRange { frame, count }) if frame == FRAMES && count == FRAMES
    ));
}

#[test]
fn bvh_written_from_the_walk_reads_back() {
    let (dir, asf_path, amc_path) = walk();
    let asf = Asf::read(&asf_path).unwrap();
    let amc = Amc::read(&amc_path, &asf).unwrap();
    let path = dir.path().join("02_01.bvh");
    save_bvh(&path, &asf, &amc, &BvhWriteOptions::default()).unwrap();
    let bvh = Bvh::read(&path, None).unwrap();
    assert!(
        (bvh.metres_per_unit - asf.metres_per_unit()).abs() < 1e-12,
        "unit detected"
    );
    assert_eq!(bvh.joints.len(), 31);
    assert_eq!(bvh.frame_count(), FRAMES);
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
    assert!(worst < 1e-4 * height, "worst joint error {worst:e} m");
    // The BVH clip retargets like the ASF/AMC clip.
    let rig = a_pose_rig();
    let from_bvh = Clip::from_bvh(&path, None).unwrap();
    let from_amc = Clip::from_asf_amc(&asf_path, &amc_path).unwrap();
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
    let bvh = Bvh::read(fixture("mini.bvh"), None).unwrap();
    assert_eq!(bvh.frame_count(), 3);
    assert!((bvh.metres_per_unit - 0.0254 / 0.45).abs() < 1e-12);
    // A hip and a leg are no body to pose.
    let err = Clip::from_bvh(fixture("mini.bvh"), None).unwrap_err();
    assert!(matches!(err, PoseError::Skeleton { .. }), "{err}");
    assert!(err.to_string().contains("mini.bvh") && err.to_string().contains("no joint for"));
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
