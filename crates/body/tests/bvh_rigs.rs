//! BVH files of other rigs: copies of a CMU-style walk that garnet writes itself, renamed
//! to the Mixamo, 3ds Max biped and generic conventions, turned to other axes, rescaled,
//! with six channels per joint and with another rest pose, must pose the body as the
//! original does; skeletons that cannot be placed are refused.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::OnceLock;

use body::pose::synthetic_clip::write_cmu_clip;
use body::pose::{
    save_bvh, Amc, Asf, Bvh, BvhRig, BvhWriteOptions, Clip, PoseError, RetargetOptions,
};
use body::rig::Rig;
use body::{BodyModel, Phenotype};
use glam::{DQuat, DVec3, EulerRot, Vec3};

const FRAMES: usize = 240;

fn rig() -> &'static Rig {
    static RIG: OnceLock<Rig> = OnceLock::new();
    RIG.get_or_init(|| {
        let model = BodyModel::load().expect("body assets");
        model.shape(&Phenotype::default()).expect("shape").rig
    })
}

/// The walk as a CMU-style BVH in a temporary folder.
fn walk_bvh() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let amc = write_cmu_clip(dir.path(), "cmu/02/02_01.amc", FRAMES).unwrap();
    let asf = Asf::read(dir.path().join("cmu/02/02.asf")).unwrap();
    let amc = Amc::read(amc, &asf).unwrap();
    let path = dir.path().join("walk.bvh");
    save_bvh(&path, &asf, &amc, &BvhWriteOptions::default()).unwrap();
    (dir, path)
}

/// How a copy differs from the original.
struct Copy {
    /// The copy's name of each CMU joint; `None` drops it (only joints that never turn).
    name: fn(&str) -> Option<String>,
    /// The copy's axes: the rotation from garnet's world to the file's.
    axes: DQuat,
    /// Metres per file unit.
    unit: f64,
    /// Position channels on every joint, repeating its OFFSET.
    six_channels: bool,
    /// Rest rotation of each joint's bone from the original's rest (original axes).
    rest: fn(&str) -> DQuat,
}

fn same(n: &str) -> Option<String> {
    Some(n.to_string())
}

fn no_rest(_: &str) -> DQuat {
    DQuat::IDENTITY
}

/// The text of `copy` of `bvh`: rotations written `Zrotation Xrotation Yrotation`.
fn write_copy(bvh: &Bvh, copy: &Copy) -> String {
    let n = bvh.joints.len();
    let names: Vec<Option<String>> = bvh.joints.iter().map(|j| (copy.name)(&j.name)).collect();
    let rest: Vec<DQuat> = bvh.joints.iter().map(|j| (copy.rest)(&j.name)).collect();
    let parent = |mut j: usize| loop {
        match bvh.joints[j].parent {
            Some(p) if names[p].is_some() => return Some(p),
            Some(p) => j = p,
            None => return None,
        }
    };
    let (_, rest_pos) = bvh.pose(None).unwrap();
    let m = copy.axes;
    let u = bvh.metres_per_unit / copy.unit;
    let offset = |j: usize| match parent(j) {
        Some(p) => m * rest[p] * (rest_pos[j] - rest_pos[p]) / copy.unit,
        None => m * rest_pos[j] / copy.unit,
    };
    let mut out = String::from("HIERARCHY\n");
    fn v3(out: &mut String, v: DVec3) {
        let _ = write!(out, "{:.7} {:.7} {:.7}", v.x, v.y, v.z);
    }
    let mut order = Vec::new();
    fn joint(
        j: usize,
        depth: usize,
        out: &mut String,
        order: &mut Vec<usize>,
        ctx: &dyn Fn(usize) -> (String, DVec3, Option<DVec3>, Vec<usize>, bool),
    ) {
        let (name, offset, end, kids, six) = ctx(j);
        let tabs = "\t".repeat(depth);
        let word = if depth == 0 { "ROOT" } else { "JOINT" };
        let _ = write!(out, "{tabs}{word} {name}\n{tabs}{{\n{tabs}\tOFFSET ");
        v3(out, offset);
        let pos = if six {
            "6 Xposition Yposition Zposition"
        } else {
            "3"
        };
        let _ = writeln!(
            out,
            "\n{tabs}\tCHANNELS {pos} Zrotation Xrotation Yrotation"
        );
        order.push(j);
        if let Some(e) = end {
            let _ = write!(out, "{tabs}\tEnd Site\n{tabs}\t{{\n{tabs}\t\tOFFSET ");
            v3(out, e);
            let _ = writeln!(out, "\n{tabs}\t}}");
        }
        for k in kids {
            joint(k, depth + 1, out, order, ctx);
        }
        let _ = writeln!(out, "{tabs}}}");
    }
    let ctx = |j: usize| {
        let kids: Vec<usize> = (0..n)
            .filter(|&k| names[k].is_some() && parent(k) == Some(j))
            .collect();
        let end = bvh.joints[j].end_site.map(|e| m * rest[j] * e * u);
        let six = copy.six_channels || bvh.joints[j].parent.is_none();
        (names[j].clone().unwrap(), offset(j), end, kids, six)
    };
    let root = (0..n)
        .find(|&j| names[j].is_some() && parent(j).is_none())
        .unwrap();
    joint(root, 0, &mut out, &mut order, &ctx);
    let _ = write!(
        out,
        "MOTION\nFrames: {}\nFrame Time: {:.8}\n",
        bvh.frame_count(),
        1.0 / 120.0
    );
    for f in 0..bvh.frame_count() {
        let (world, pos) = bvh.pose(Some(f)).unwrap();
        let w = |j: usize| m * world[j] * rest[j].inverse() * m.inverse();
        for &j in &order {
            if j == root {
                v3(&mut out, m * pos[j] / copy.unit);
                out.push(' ');
            } else if copy.six_channels {
                v3(&mut out, offset(j));
                out.push(' ');
            }
            let local = parent(j).map_or(w(j), |p| w(p).inverse() * w(j));
            let (z, x, y) = local.to_euler(EulerRot::ZXY);
            let _ = write!(
                out,
                "{:.7} {:.7} {:.7} ",
                z.to_degrees(),
                x.to_degrees(),
                y.to_degrees()
            );
        }
        out.push('\n');
    }
    out
}

fn mixamo(n: &str) -> Option<String> {
    let m = match n {
        "LHipJoint" | "RHipJoint" | "Neck1" => return None,
        "LowerBack" => "Spine",
        "Spine" => "Spine1",
        "Spine1" => "Spine2",
        "LeftFingerBase" => "LeftHandIndex1",
        "LeftHandFinger1" => "LeftHandIndex2",
        "LThumb" => "LeftHandThumb1",
        "RightFingerBase" => "RightHandIndex1",
        "RightHandFinger1" => "RightHandIndex2",
        "RThumb" => "RightHandThumb1",
        other => other,
    };
    Some(format!("mixamorig:{m}"))
}

fn biped(n: &str) -> Option<String> {
    let side = |s: &str| s.replacen("Left", "L ", 1).replacen("Right", "R ", 1);
    let m = match n {
        "LHipJoint" | "RHipJoint" => return None,
        "Hips" => "Pelvis".into(),
        "LowerBack" => "Spine".into(),
        "Spine" => "Spine1".into(),
        "Spine1" => "Spine2".into(),
        "LThumb" => "L Finger0".into(),
        "RThumb" => "R Finger0".into(),
        other => side(other)
            .replace("UpLeg", "Thigh")
            .replace("ToeBase", "Toe0")
            .replace("Leg", "Calf")
            .replace("Shoulder", "Clavicle")
            .replace("ForeArm", "Forearm")
            .replace("Arm", "UpperArm")
            .replace("FingerBase", "Finger1")
            .replace("HandFinger1", "Finger11"),
    };
    Some(format!("Bip01 {m}"))
}

fn generic_left_right(n: &str) -> Option<String> {
    let m = match n {
        "LHipJoint" | "RHipJoint" => return None,
        "LowerBack" => "Spine".into(),
        "Spine" => "Spine1".into(),
        "Spine1" => "Chest".into(),
        "LThumb" => "LeftThumb".into(),
        "RThumb" => "RightThumb".into(),
        other => other
            .replace("UpLeg", "Thigh")
            .replace("Leg", "Shin")
            .replace("ToeBase", "Toe")
            .replace("ForeArm", "Forearm")
            .replace("FingerBase", "Index1")
            .replace("HandFinger1", "Index2")
            .replace("Arm", "UpperArm"),
    };
    Some(m)
}

fn generic_suffix(n: &str) -> Option<String> {
    let (side, rest) = if let Some(r) = n.strip_prefix("Left") {
        ("_L", r)
    } else if let Some(r) = n.strip_prefix("Right") {
        ("_R", r)
    } else {
        ("", n)
    };
    let base = match rest {
        "LHipJoint" | "RHipJoint" | "Neck1" => return None,
        "LThumb" => return Some("thumb_L".into()),
        "RThumb" => return Some("thumb_R".into()),
        "Hips" => "pelvis",
        "LowerBack" => "abdomen",
        "Spine" => "spine",
        "Spine1" => "chest",
        "Neck" => "neck",
        "Head" => "head",
        "UpLeg" => "thigh",
        "Leg" => "shin",
        "Foot" => "foot",
        "ToeBase" => "toe",
        "Shoulder" => "clavicle",
        "Arm" => "upperarm",
        "ForeArm" => "lowerarm",
        "Hand" => "hand",
        "FingerBase" => "index1",
        "HandFinger1" => "index2",
        other => panic!("{other}"),
    };
    Some(format!("{base}{side}"))
}

/// The left arm's bones 40 degrees lower in the rest pose (an A-pose), the right's too.
fn a_pose(n: &str) -> DQuat {
    let arm = ["Arm", "ForeArm", "Hand", "FingerBase", "HandFinger1"];
    let a = 40f64.to_radians();
    match n {
        "LThumb" => DQuat::from_rotation_z(-a),
        "RThumb" => DQuat::from_rotation_z(a),
        _ if arm.iter().any(|b| n == format!("Left{b}")) => DQuat::from_rotation_z(-a),
        _ if arm.iter().any(|b| n == format!("Right{b}")) => DQuat::from_rotation_z(a),
        _ => DQuat::IDENTITY,
    }
}

/// Garnet's Y-up, +Z-facing world to a Z-up file facing -Y (Blender, 3ds Max).
fn z_up() -> DQuat {
    DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2)
}

fn posed(clip: &Clip, f: usize) -> Vec<(Vec3, Vec3)> {
    let opts = RetargetOptions {
        keep_horizontal_translation: true,
    };
    let rig = rig();
    rig.posed_joints(&clip.pose(f, rig, &opts).unwrap())
}

/// Largest distance (metres) between the posed joints of two clips over several frames,
/// and the bone where it is.
fn worst_joint_error(a: &Clip, b: &Clip) -> (f32, &'static str) {
    let mut worst = (0.0, "");
    for f in [0, 37, 90, 151, 203, FRAMES - 1] {
        for (i, ((ah, at), (bh, bt))) in posed(a, f).iter().zip(&posed(b, f)).enumerate() {
            let e = ah.distance(*bh).max(at.distance(*bt));
            if e > worst.0 {
                worst = (e, body::pose::cmu::CMU_BONES[i].name);
            }
        }
    }
    worst
}

#[test]
fn copies_in_other_conventions_pose_the_body_as_the_original() {
    let (dir, path) = walk_bvh();
    let original = Bvh::read(&path, None).unwrap();
    let reference = Clip::from_bvh(&path, None).unwrap();
    let copies: [(&str, Copy, f64); 7] = [
        (
            "z_up_cm",
            Copy {
                name: same,
                axes: z_up(),
                unit: 0.01,
                six_channels: false,
                rest: no_rest,
            },
            0.01,
        ),
        (
            "inches_facing_x",
            Copy {
                name: same,
                axes: DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2),
                unit: 0.0254,
                six_channels: false,
                rest: no_rest,
            },
            0.0254,
        ),
        (
            "mixamo",
            Copy {
                name: mixamo,
                axes: DQuat::IDENTITY,
                unit: 0.01,
                six_channels: false,
                rest: no_rest,
            },
            0.01,
        ),
        (
            "biped",
            Copy {
                name: biped,
                axes: z_up(),
                unit: 0.0254,
                six_channels: false,
                rest: no_rest,
            },
            0.0254,
        ),
        (
            "left_right_six_channels",
            Copy {
                name: generic_left_right,
                axes: DQuat::IDENTITY,
                unit: 0.01,
                six_channels: true,
                rest: no_rest,
            },
            0.01,
        ),
        (
            "suffix_a_pose",
            Copy {
                name: generic_suffix,
                axes: DQuat::from_rotation_y(std::f64::consts::PI),
                unit: 1.0,
                six_channels: false,
                rest: a_pose,
            },
            1.0,
        ),
        (
            "mixamo_six_channels_z_up",
            Copy {
                name: mixamo,
                axes: z_up(),
                unit: 0.01,
                six_channels: true,
                rest: a_pose,
            },
            0.01,
        ),
    ];
    for (name, copy, unit) in copies {
        let p = dir.path().join(format!("{name}.bvh"));
        std::fs::write(&p, write_copy(&original, &copy)).unwrap();
        let bvh = Bvh::read(&p, None).unwrap();
        assert_eq!(bvh.metres_per_unit, unit, "{name}: unit");
        let rig = BvhRig::new(&bvh).unwrap();
        let up = copy.axes * DVec3::Y;
        assert!(rig.up.distance(up) < 1e-9, "{name}: up {} vs {up}", rig.up);
        assert!(
            rig.forward.distance(copy.axes * DVec3::Z) < 1e-9,
            "{name}: forward"
        );
        let clip = Clip::from_bvh(&p, None).unwrap();
        let (worst, bone) = worst_joint_error(&reference, &clip);
        eprintln!(
            "{name}: worst joint error {:.2} mm ({bone})",
            worst * 1000.0
        );
        assert!(worst < 0.01, "{name}: joints {worst} m from the original's");
    }
}

/// Posed head and tail of a rig bone.
fn at(pose: &body::rig::Pose, name: &str) -> (Vec3, Vec3) {
    let rig = rig();
    rig.posed_joints(pose)[rig.index(name).unwrap()]
}

#[test]
fn a_walk_read_from_a_z_up_copy_stands_upright_and_faces_z() {
    let (dir, path) = walk_bvh();
    let original = Bvh::read(&path, None).unwrap();
    let copy = Copy {
        name: biped,
        axes: z_up(),
        unit: 0.01,
        six_channels: false,
        rest: no_rest,
    };
    let p = dir.path().join("z_up.bvh");
    std::fs::write(&p, write_copy(&original, &copy)).unwrap();
    let clip = Clip::from_bvh(&p, None).unwrap();
    let keep = RetargetOptions {
        keep_horizontal_translation: true,
    };
    let rig = rig();
    for f in [0, 60, 120, 180, FRAMES - 1] {
        let pose = clip.pose(f, rig, &keep).unwrap();
        let head = at(&pose, "Head").1;
        let hips = at(&pose, "Hips").0;
        for side in ["Left", "Right"] {
            let (ankle, toe) = at(&pose, &format!("{side}Foot"));
            assert!(
                head.y > hips.y + 0.5 && ankle.y < hips.y - 0.5,
                "frame {f}: not upright"
            );
            assert!(
                ankle.y > -0.05 && ankle.y < 0.2,
                "frame {f}: {side} ankle at {ankle}"
            );
            assert!(
                toe.z > ankle.z + 0.05,
                "frame {f}: {side} toes not along +Z"
            );
        }
        assert!(
            at(&pose, "LeftUpLeg").0.x > at(&pose, "RightUpLeg").0.x,
            "frame {f}"
        );
    }
    let a = clip.pose(0, rig, &keep).unwrap().root_translation;
    let b = clip.pose(FRAMES - 1, rig, &keep).unwrap().root_translation;
    assert!(
        b.z - a.z > 1.0 && (b.x - a.x).abs() < 0.05,
        "walks along +Z: {a} -> {b}"
    );
}

fn refused(path: &std::path::Path) -> String {
    match Clip::from_bvh(path, None) {
        Err(e @ PoseError::Skeleton { .. }) => e.to_string(),
        Err(other) => panic!("not a skeleton error: {other}"),
        Ok(_) => panic!("{} accepted", path.display()),
    }
}

fn wingless(n: &str) -> Option<String> {
    Some(match n {
        "LeftArm" => "Wing1".into(),
        "LeftForeArm" => "Wing2".into(),
        "LeftHand" => "Wing3".into(),
        other => other.into(),
    })
}

#[test]
fn skeletons_that_cannot_be_placed_are_refused_naming_their_joints() {
    let (dir, path) = walk_bvh();
    let original = Bvh::read(&path, None).unwrap();
    let copy = Copy {
        name: wingless,
        axes: DQuat::IDENTITY,
        unit: 0.01,
        six_channels: false,
        rest: no_rest,
    };
    let p = dir.path().join("wingless.bvh");
    std::fs::write(&p, write_copy(&original, &copy)).unwrap();
    let msg = refused(&p);
    for words in [
        "wingless.bvh",
        "left upper arm",
        "left forearm",
        "left hand",
        "Wing1, Wing2, Wing3",
    ] {
        assert!(msg.contains(words), "{msg} lacks {words}");
    }
    assert!(!msg.contains("right upper arm"), "{msg}");
    let two = dir.path().join("two_joints.bvh");
    std::fs::write(
        &two,
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition \
         Zrotation Yrotation Xrotation\n JOINT LeftUpLeg\n {\n  OFFSET 10 0 0\n  CHANNELS 3 \
         Zrotation Yrotation Xrotation\n  End Site\n  {\n   OFFSET 0 -40 0\n  }\n }\n}\n\
         MOTION\nFrames: 1\nFrame Time: 0.01\n0 90 0 0 0 0 0 0 0\n",
    )
    .unwrap();
    assert_eq!(Bvh::read(&two, None).unwrap().joints.len(), 2);
    let msg = refused(&two);
    for words in [
        "two_joints.bvh",
        "(2 joints)",
        "spine",
        "head",
        "right thigh",
        "left shin",
    ] {
        assert!(msg.contains(words), "{msg} lacks {words}");
    }
    // A rest pose standing on its head is refused too.
    let upside_down = Copy {
        name: same,
        axes: DQuat::IDENTITY,
        unit: 0.01,
        six_channels: false,
        rest: legs_up,
    };
    let p = dir.path().join("legs_up.bvh");
    std::fs::write(&p, write_copy(&original, &upside_down)).unwrap();
    assert!(refused(&p).contains("does not stand"));
}

/// The legs pointing up in the rest pose.
fn legs_up(n: &str) -> DQuat {
    if n.ends_with("UpLeg") {
        DQuat::from_rotation_z(std::f64::consts::PI)
    } else {
        DQuat::IDENTITY
    }
}
