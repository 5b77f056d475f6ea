//! The body model on the real assets (fetched on first use), posed by clips garnet writes.

use body::shape_sampler::{stature_and_bmi, ShapeDistribution};
use body::{BodyModel, Phenotype, Pose, Skinning};
use glam::{Quat, Vec3};
use std::sync::OnceLock;

fn model() -> &'static BodyModel {
    static MODEL: OnceLock<BodyModel> = OnceLock::new();
    MODEL.get_or_init(|| BodyModel::load().expect("body assets"))
}

#[test]
fn default_phenotype_is_1626_mm_tall_closed_and_manifold() {
    let body = model().shape(&Phenotype::default()).unwrap();
    assert!(
        (body.height() - 1.626).abs() < 0.001,
        "height {}",
        body.height()
    );
    let mesh = &body.mesh;
    assert_eq!(mesh.vertices.len(), 13380);
    assert_eq!(mesh.faces.len(), 2 * 13378);
    let report = geom::adjacency::check_manifold(mesh.vertices.len(), &mesh.faces).unwrap();
    assert!(report.is_ok() && report.is_closed(), "{report:?}");
    assert_eq!(report.euler_characteristic(), 2);
    assert!(
        body.volume() > 0.03,
        "outward orientation gives a positive volume"
    );
}

#[test]
fn weights_sum_to_one_with_at_most_eight_influences() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let w = &body.weights;
    assert_eq!(w.len(), 13380);
    for v in 0..w.len() {
        let row: Vec<_> = w.row(v).collect();
        assert!(
            !row.is_empty() && row.len() <= 8,
            "vertex {v}: {} influences",
            row.len()
        );
        let s: f32 = row.iter().map(|(_, w)| w).sum();
        assert!((s - 1.0).abs() < 1e-5, "vertex {v}: sum {s}");
    }
}

#[test]
fn identity_pose_reproduces_the_rest_mesh() {
    let body = model()
        .shape(&Phenotype {
            gender: 0.0,
            weight: 0.8,
            ..Default::default()
        })
        .unwrap();
    let pose = Pose::identity(body.rig.len());
    for method in [Skinning::Lbs, Skinning::Dqs] {
        let posed = body.posed(&pose, method).unwrap();
        let err = posed
            .vertices
            .iter()
            .zip(&body.mesh.vertices)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        assert!(err < 1e-6, "{method:?}: {err}");
    }
}

#[test]
fn lbs_and_dqs_agree_away_from_joints_for_one_bone_rotation() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let elbow = body.rig.index("LeftForeArm").unwrap();
    let mut pose = Pose::identity(body.rig.len());
    pose.rotations[elbow] = Quat::from_rotation_x(1.2);
    let lbs = body.posed(&pose, Skinning::Lbs).unwrap();
    let dqs = body.posed(&pose, Skinning::Dqs).unwrap();
    // Vertices bound rigidly to one bone move identically under both methods...
    let mut rigid = 0;
    for v in 0..lbs.vertices.len() {
        let row: Vec<_> = body.weights.row(v).collect();
        if row.len() == 1 {
            rigid += 1;
            assert!(
                (lbs.vertices[v] - dqs.vertices[v]).length() < 1e-5,
                "vertex {v}"
            );
        }
    }
    assert!(rigid > 1000);
    // ... and the forearm really moved while the other side stayed.
    let hand = body.rig.index("LeftHand").unwrap();
    let joints = body.rig.posed_joints(&pose);
    assert!((joints[hand].0 - body.rig.bones[hand].head).length() > 0.1);
    let right = body.rig.index("RightHand").unwrap();
    assert!((joints[right].0 - body.rig.bones[right].head).length() < 1e-6);
}

#[test]
fn tpose_puts_the_arms_horizontal() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let joints = body.rig.posed_joints(&model().tpose());
    for name in ["LeftArm", "LeftForeArm", "RightArm", "RightForeArm"] {
        let (h, t) = joints[body.rig.index(name).unwrap()];
        let d = (t - h).normalize();
        assert!(d.x.abs() > 0.99, "{name} direction {d}");
    }
    let l = joints[body.rig.index("LeftForeArm").unwrap()].1;
    assert!(l.x > 0.5, "left hand at +X, found {l}");
}

#[test]
fn posing_rejects_a_wrong_bone_count_and_nan() {
    let body = model().shape(&Phenotype::default()).unwrap();
    assert!(body.posed(&Pose::identity(3), Skinning::Dqs).is_err());
    let mut pose = Pose::identity(body.rig.len());
    pose.root_translation = Vec3::new(f32::NAN, 0.0, 0.0);
    let err = body.posed(&pose, Skinning::Dqs).unwrap_err().to_string();
    assert!(err.contains("NaN"), "{err}");
    assert!(model()
        .shape(&Phenotype {
            age: f32::NAN,
            ..Default::default()
        })
        .is_err());
}

#[test]
fn random_shapes_are_realistic_adults_and_reproducible() {
    let dist = ShapeDistribution::default();
    let mut statures = Vec::new();
    for seed in 0..12 {
        let s = dist.sample(model(), seed).unwrap();
        assert!(
            (1.45..=2.0).contains(&s.stature),
            "seed {seed}: stature {}",
            s.stature
        );
        assert!((16.0..=40.0).contains(&s.bmi), "seed {seed}: BMI {}", s.bmi);
        assert!(
            (s.stature - s.target_stature).abs() < 0.01,
            "seed {seed}: {s:?}"
        );
        // BMI is met, or the model's heaviest shape fell short of a high target.
        let saturated = s.phenotype.weight >= 1.0 && s.bmi < s.target_bmi;
        assert!(
            (s.bmi - s.target_bmi).abs() < 0.5 || saturated,
            "seed {seed}: {s:?}"
        );
        let body = model().shape(&s.phenotype).unwrap();
        let (h, b) = stature_and_bmi(&body);
        assert!((h - s.stature).abs() < 1e-6 && (b - s.bmi).abs() < 1e-4);
        statures.push(s.stature);
    }
    assert_eq!(
        dist.sample(model(), 3).unwrap(),
        dist.sample(model(), 3).unwrap()
    );
    let spread =
        statures.iter().cloned().fold(0.0, f32::max) - statures.iter().cloned().fold(9.0, f32::min);
    assert!(spread > 0.08, "shapes vary: spread {spread}");
}

/// A CMU-style walk that garnet writes itself (`body::pose::synthetic_clip`): 240 frames.
fn walk_clip() -> body::pose::Clip {
    let dir = tempfile::tempdir().unwrap();
    let amc =
        body::pose::synthetic_clip::write_cmu_clip(dir.path(), "cmu/02/02_01.amc", 240).unwrap();
    body::pose::Clip::from_asf_amc(dir.path().join("cmu/02/02.asf"), amc).unwrap()
}

#[test]
fn walk_frames_stand_upright_with_feet_on_the_floor_and_arms_at_the_sides() {
    let clip = walk_clip();
    let body = model()
        .shape(&Phenotype {
            gender: 0.0,
            age: 0.7,
            ..Default::default()
        })
        .unwrap();
    let rig = &body.rig;
    let at = |joints: &[(Vec3, Vec3)], name: &str| joints[rig.index(name).unwrap()].0;
    for frame in [40, 80, 120, 160, 200] {
        let pose = clip.pose(frame, rig, &Default::default()).unwrap();
        let joints = rig.posed_joints(&pose);
        let (head, hips) = (at(&joints, "Head"), at(&joints, "Hips"));
        let feet = [at(&joints, "LeftFoot"), at(&joints, "RightFoot")];
        assert!(
            head.y > hips.y + 0.4 && feet.iter().all(|f| f.y < hips.y - 0.6),
            "frame {frame} upright"
        );
        let up = (head - hips).normalize();
        assert!(up.y > 0.9, "frame {frame}: trunk leans {up}");
        let mesh = body.posed(&pose, Skinning::Dqs).unwrap();
        let floor = mesh
            .vertices
            .iter()
            .map(|p| p.y)
            .fold(f32::INFINITY, f32::min);
        assert!(
            (-0.02..0.08).contains(&floor),
            "frame {frame}: lowest point at {floor} m"
        );
        // Each foot (ankle or toes: heels lift at toe-off) near the lowest point.
        for side in ["Left", "Right"] {
            let toe = joints[rig.index(&format!("{side}ToeBase")).unwrap()];
            let low = at(&joints, &format!("{side}Foot"))
                .y
                .min(toe.0.y)
                .min(toe.1.y);
            assert!(
                low - floor < 0.15,
                "frame {frame}: {side} foot {low} m, floor {floor} m"
            );
        }
        for (hand, shoulder) in [("LeftHand", "LeftArm"), ("RightHand", "RightArm")] {
            let (h, s) = (at(&joints, hand), at(&joints, shoulder));
            assert!(
                h.y < s.y - 0.35,
                "frame {frame}: {hand} not below the shoulder"
            );
            let off = (h - hips).with_y(0.0).length();
            assert!(
                off < 0.4,
                "frame {frame}: {hand} {off} m away from the side, hips {hips}, hand {h}"
            );
        }
    }
}

/// The default body with phenotype `weight` (0..1, 0.5 average).
fn body_of_weight(weight: f32) -> body::ShapedBody {
    model()
        .shape(&Phenotype {
            weight,
            ..Default::default()
        })
        .unwrap()
}

#[test]
fn self_contact_flags_an_arm_through_the_torso_but_not_the_rest_pose() {
    use body::self_contact::SelfContact;
    let body = body_of_weight(0.9);
    let contact = SelfContact::new(&body);
    assert_eq!(contact.count_intersections(&body.mesh), 0, "rest pose");
    // Swing the left arm (and everything below it) across the chest.
    let pose = left_arm_along(&body, Vec3::new(-1.0, -0.1, 0.05));
    let posed = body.posed(&pose, Skinning::Dqs).unwrap();
    assert!(contact.count_intersections(&posed) > 20);
}

/// A pose of `body` with the left arm (and everything below it) pointing along `dir`.
fn left_arm_along(body: &body::ShapedBody, dir: Vec3) -> Pose {
    let rig = &body.rig;
    let mut world = vec![Quat::IDENTITY; rig.len()];
    rig.swing_limb(&mut world, rig.index("LeftArm").unwrap(), dir);
    Pose::from_world_rotations(rig, &world, Vec3::ZERO)
}

#[test]
fn clearance_leaves_the_rest_pose_alone_and_lifts_an_arm_out_of_the_chest() {
    use body::clearance::{clear_limbs, ClearanceOptions};
    let body = body_of_weight(1.0);
    let opts = ClearanceOptions::default();
    let rest = Pose::identity(body.rig.len());
    let (same, report) = clear_limbs(&body, &rest, &opts).unwrap();
    assert_eq!(same, rest);
    assert_eq!(report.largest_turn_deg(), 0.0);

    // A heavy body's left arm hanging straight down and a little inward sinks into the
    // chest (the left arm is on +X).
    let sunk = left_arm_along(&body, Vec3::new(-0.15, -1.0, 0.0));
    let (cleared, report) = clear_limbs(&body, &sunk, &opts).unwrap();
    assert!(
        report.buried_before[0] > report.buried_rest[0] + opts.tolerance,
        "the test pose must bury the upper arm: {report:?}"
    );
    assert!(
        report.buried_after[0] <= report.buried_rest[0] + opts.tolerance,
        "{report:?}"
    );
    assert!(report.turned[0] > 0.0, "{report:?}");
    let hand = body.rig.index("LeftHand").unwrap();
    let before = body.rig.posed_joints(&sunk)[hand].0;
    let after = body.rig.posed_joints(&cleared)[hand].0;
    assert!(
        after.x > before.x + 0.02,
        "hand moved out: {before} -> {after}"
    );
    // The right side was not touched.
    let right = body.rig.index("RightArm").unwrap();
    assert!(cleared.rotations[right].angle_between(sunk.rotations[right]) < 1e-5);
}

/// The clearance measures the body skinned as its options say, whatever the drape's
/// skinning: its counts are those of that body.
#[test]
fn clearance_measures_the_body_as_it_is_skinned() {
    use body::clearance::{buried_vertices, clear_limbs, ClearanceOptions, PROBE};
    use body::self_contact::vertex_segments;
    let body = body_of_weight(1.0);
    let sunk = left_arm_along(&body, Vec3::new(-0.15, -1.0, 0.0));
    let opts = ClearanceOptions {
        probe: PROBE,
        ..Default::default()
    };
    let segments = vertex_segments(&body);
    let direct = |skinning| {
        let buried = buried_vertices(&body.posed(&sunk, skinning).unwrap()).unwrap();
        let mut count = [0usize; 8];
        for (v, _) in buried.iter().enumerate().filter(|(_, &b)| b) {
            if let Some(s) = (segments[v] as usize).checked_sub(1) {
                count[s] += 1;
            }
        }
        count
    };
    let (lbs, dqs) = (direct(Skinning::Lbs), direct(Skinning::Dqs));
    assert_ne!(lbs, dqs, "the test pose must bury the limbs differently");
    for (skinning, want) in [(Skinning::Lbs, lbs), (Skinning::Dqs, dqs)] {
        let (_, report) =
            clear_limbs(&body, &sunk, &ClearanceOptions { skinning, ..opts }).unwrap();
        assert_eq!(report.buried_before, want, "{skinning:?}");
    }
}

/// One AMC frame of the CMU-style skeleton (`body::pose::synthetic_clip::cmu_asf_text`):
/// swordplay, the left arm pressed across the chest (the angles of CMU clip 02_07's frame
/// 480, rounded to 0.1 degree).
const ARM_ACROSS_THE_CHEST: &str = "\
:FULLY-SPECIFIED
:DEGREES
1
root 10.9 17.5 -1.9 22.4 -24.3 -7.6
lowerback 20.4 0.5 -1.1
upperback 10.9 0.2 -2.0
thorax 0.4 0.0 -1.6
lowerneck -10.7 7.8 3.4
upperneck -14.2 9.5 -9.9
head -2.1 4.8 -3.6
rclavicle 0 0
rhumerus 19.7 56.2 -92.4
rradius 34.3
rwrist -37.1
rhand -37.6 3.2
rfingers 7.1
rthumb -10.7 -26.5
lclavicle 0 0
lhumerus 28.7 1.3 94.5
lradius 24.2
lwrist 40.9
lhand -35.9 27.2
lfingers 7.1
lthumb -9.0 57.0
rfemur -16.5 3.3 22.3
rtibia 18.2
rfoot -17.1 -16.9
rtoes -13.0
lfemur -48.5 13.3 -20.6
ltibia 38.9
lfoot -5.9 5.5
ltoes 3.9
";

/// Regression (the left arm pressed across the chest; T-shirts draped in it were left
/// 10-21 mm inside the body): the default clearance probe (8 mm) keeps a gap for the
/// cloth, so the arm turns further out than a 2 mm probe turns it.
#[test]
fn clearance_leaves_a_gap_for_the_cloth_under_an_arm_across_the_chest() {
    use body::clearance::{clear_limbs, ClearanceOptions, PROBE};
    let dir = tempfile::tempdir().unwrap();
    let (asf, amc) = (dir.path().join("s.asf"), dir.path().join("a.amc"));
    std::fs::write(&asf, body::pose::synthetic_clip::cmu_asf_text()).unwrap();
    std::fs::write(&amc, ARM_ACROSS_THE_CHEST).unwrap();
    let clip = body::pose::Clip::from_asf_amc(&asf, &amc).unwrap();
    let m = model();
    let shape = body::shape_sampler::ShapeDistribution::default()
        .sample(m, 100)
        .unwrap();
    let body = m.shape(&shape.phenotype).unwrap();
    let pose = clip.pose(0, &body.rig, &Default::default()).unwrap();
    let wide = ClearanceOptions::default();
    let narrow = ClearanceOptions {
        probe: PROBE,
        ..wide
    };
    let (_, with_gap) = clear_limbs(&body, &pose, &wide).unwrap();
    let (_, without) = clear_limbs(&body, &pose, &narrow).unwrap();
    assert!(
        with_gap.buried_before[0] > with_gap.buried_rest[0] + wide.tolerance,
        "the pose must press the left upper arm into the body: {with_gap:?}"
    );
    assert!(
        with_gap.buried_after[0] < with_gap.buried_before[0],
        "{with_gap:?}"
    );
    assert!(
        with_gap.turned[0] > without.turned[0],
        "8 mm probe turned the arm {} deg, 2 mm {} deg",
        with_gap.turned[0].to_degrees(),
        without.turned[0].to_degrees()
    );
}
