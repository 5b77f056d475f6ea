//! Garment templates on the real body model: topology, fit, weights, warping, storage
//! and import checks.

use std::sync::OnceLock;

use body::{BodyModel, Phenotype, Pose, Skinning};
use garment::import::{import_garment, ImportLimits};
use garment::waistband::waistband;
use garment::warp::warp;
use garment::{build_template, CutParams, GarmentKind, GarmentTemplate};
use geom::bvh::Bvh;
use geom::TriMesh;
use glam::{Quat, Vec3};

/// Coarse edges keep the tests fast; the 1 cm resolution is tested once.
const EDGE: f32 = 0.025;

fn model() -> &'static BodyModel {
    static MODEL: OnceLock<BodyModel> = OnceLock::new();
    MODEL.get_or_init(|| BodyModel::load().expect("body assets"))
}

fn templates() -> &'static [GarmentTemplate] {
    static T: OnceLock<Vec<GarmentTemplate>> = OnceLock::new();
    T.get_or_init(|| {
        ["tshirt", "sweater", "jeans"]
            .iter()
            .map(|k| {
                let kind = GarmentKind::parse(k).unwrap();
                build_template(model(), &kind, &CutParams::default_for(&kind), EDGE).unwrap()
            })
            .collect()
    })
}

#[test]
fn templates_are_manifold_with_their_openings_only() {
    for t in templates() {
        let m = &t.mesh;
        let report = geom::adjacency::check_manifold(m.vertices.len(), &m.faces).unwrap();
        assert!(report.is_ok(), "{}: {report}", t.kind.name());
        let loops = geom::adjacency::boundary_loops(m.vertices.len(), &m.faces).unwrap();
        assert_eq!(Some(loops.len()), t.kind.openings(), "{}", t.kind.name());
        assert_eq!(t.uvs.len(), m.faces.len());
        assert!(t
            .uvs
            .iter()
            .flatten()
            .flatten()
            .all(|u| (0.0..=1.0).contains(u)));
    }
}

#[test]
fn templates_sit_outside_the_body_with_ease() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let bvh = Bvh::from_mesh(&body.mesh).unwrap();
    for t in templates() {
        let inside = t.mesh.vertices.iter().filter(|p| bvh.contains(**p)).count();
        assert_eq!(inside, 0, "{}: vertices inside the body", t.kind.name());
        let gaps: Vec<f32> = t
            .mesh
            .vertices
            .iter()
            .map(|p| bvh.closest_point(*p).unwrap().distance)
            .collect();
        let mean = gaps.iter().sum::<f32>() / gaps.len() as f32;
        assert!(
            (0.008..0.06).contains(&mean),
            "{}: mean gap {mean} m",
            t.kind.name()
        );
        let min = gaps.iter().cloned().fold(f32::INFINITY, f32::min);
        assert!(
            min > 0.003,
            "{}: closest vertex {min} m from the skin",
            t.kind.name()
        );
    }
}

#[test]
fn weights_sum_to_one() {
    for t in templates() {
        for v in 0..t.weights.len() {
            let s: f32 = t.weights.row(v).map(|(_, w)| w).sum();
            assert!((s - 1.0).abs() < 1e-5, "{} vertex {v}: {s}", t.kind.name());
        }
    }
}

#[test]
fn tshirt_at_one_centimetre_has_about_ten_thousand_vertices() {
    let kind = GarmentKind::Tshirt;
    let t = build_template(model(), &kind, &CutParams::default_for(&kind), 0.01).unwrap();
    let n = t.mesh.vertices.len();
    assert!((8_000..=12_000).contains(&n), "{n} vertices");
}

#[test]
fn warping_onto_the_template_body_at_rest_is_the_identity() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let rest = Pose::identity(body.rig.len());
    for t in templates() {
        for method in [Skinning::Dqs, Skinning::Lbs] {
            let m = warp(t, &body, &rest, method).unwrap();
            let err = m
                .vertices
                .iter()
                .zip(&t.mesh.vertices)
                .map(|(a, b)| (*a - *b).length())
                .fold(0.0, f32::max);
            assert!(err < 1e-5, "{} {method:?}: {err} m", t.kind.name());
        }
    }
}

#[test]
fn warping_follows_shape_and_pose() {
    let target = model()
        .shape(&Phenotype {
            gender: 0.0,
            height: 0.9,
            weight: 0.8,
            ..Default::default()
        })
        .unwrap();
    let mut pose = Pose::identity(target.rig.len());
    let arm = target.rig.index("LeftArm").unwrap();
    pose.rotations[arm] = Quat::from_rotation_z(0.6);
    let tshirt = &templates()[0];
    let m = warp(tshirt, &target, &pose, Skinning::Dqs).unwrap();
    assert!(m.vertices.iter().all(|p| p.is_finite()));
    let top = |mesh: &TriMesh| mesh.vertices.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    assert!(
        top(&m) > top(&tshirt.mesh) + 0.05,
        "a taller body lifts the collar"
    );
    let mut nan = pose.clone();
    nan.rotations[0] = Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0);
    assert!(warp(tshirt, &target, &nan, Skinning::Dqs).is_err());
}

#[test]
fn template_files_round_trip_exactly_and_reject_corruption() {
    let dir = tempfile::tempdir().unwrap();
    for t in templates() {
        let path = dir.path().join(format!("{}.garment", t.kind.name()));
        t.save(&path).unwrap();
        assert_eq!(&GarmentTemplate::load(&path).unwrap(), t);
    }
    let path = dir.path().join("jeans.garment");
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let err = GarmentTemplate::load(&path).unwrap_err().to_string();
    assert!(err.contains("jeans.garment"), "{err}");
}

#[test]
fn import_accepts_a_fitted_mesh_and_refuses_bad_ones_with_reasons() {
    let limits = ImportLimits::default();
    let good = templates()[0].mesh.clone();
    let t = import_garment(good.clone(), "my-shirt", model(), &limits).unwrap();
    assert_eq!(t.kind, GarmentKind::Custom("my-shirt".into()));
    assert_eq!(t.weights.len(), good.vertices.len());

    let mut nan = good.clone();
    nan.vertices[5].x = f32::NAN;
    let err = import_garment(nan, "nan", model(), &limits)
        .unwrap_err()
        .to_string();
    assert!(err.contains("NaN") || err.contains("finite"), "{err}");

    let mut fan = good.clone();
    let [a, b, _] = fan.faces[0];
    let extra = fan.vertices.len() as u32;
    fan.vertices
        .push(fan.vertices[a as usize] + Vec3::new(0.0, 0.0, 0.02));
    fan.faces.push([a, b, extra]);
    let err = import_garment(fan, "fan", model(), &limits)
        .unwrap_err()
        .to_string();
    assert!(err.contains("manifold"), "{err}");

    let mut far = good.clone();
    far.vertices
        .iter_mut()
        .for_each(|p| *p += Vec3::new(1.0, 0.0, 0.0));
    let err = import_garment(far, "far", model(), &limits)
        .unwrap_err()
        .to_string();
    assert!(err.contains("far from"), "{err}");

    let mut inside = good;
    let c = inside.vertices.iter().sum::<Vec3>() / inside.vertices.len() as f32;
    inside
        .vertices
        .iter_mut()
        .for_each(|p| *p = c + (*p - c) * 0.5);
    let err = import_garment(inside, "inside", model(), &limits)
        .unwrap_err()
        .to_string();
    assert!(err.contains("inside"), "{err}");
}

#[test]
fn fitted_warp_is_the_identity_at_rest_and_follows_girth() {
    use garment::warp::{warp_fitted, SurfaceAnchors};
    let template_body = model().shape(&Phenotype::default()).unwrap();
    let heavy = model()
        .shape(&Phenotype {
            gender: 0.0,
            weight: 1.0,
            muscle: 0.8,
            height: 0.8,
            ..Default::default()
        })
        .unwrap();
    let bvh = Bvh::from_mesh(&heavy.mesh).unwrap();
    for t in templates() {
        let anchors = SurfaceAnchors::new(&t.mesh, &template_body.mesh).unwrap();
        let rest = Pose::identity(template_body.rig.len());
        let same = warp_fitted(t, &anchors, &template_body, &rest, Skinning::Dqs).unwrap();
        let err = same
            .vertices
            .iter()
            .zip(&t.mesh.vertices)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        assert!(err < 1e-5, "{}: {err} m", t.kind.name());
        // On a heavier body the joint-only warp sinks into the flesh; the fitted one keeps the ease.
        let inside = |m: &TriMesh| m.vertices.iter().filter(|p| bvh.contains(**p)).count();
        let joints = inside(&warp(t, &heavy, &rest, Skinning::Dqs).unwrap());
        let fitted = inside(&warp_fitted(t, &anchors, &heavy, &rest, Skinning::Dqs).unwrap());
        assert!(
            fitted * 20 <= joints.max(20),
            "{}: {fitted} vs {joints} vertices inside",
            t.kind.name()
        );
    }
}

/// Each opening of `t` as (centroid, mean gap to the skin), metres.
fn openings(t: &GarmentTemplate, bvh: &Bvh) -> Vec<(Vec3, f32)> {
    let m = &t.mesh;
    geom::adjacency::boundary_loops(m.vertices.len(), &m.faces)
        .unwrap()
        .iter()
        .map(|l| {
            let n = l.len() as f32;
            let points = l.iter().map(|&i| m.vertices[i as usize]);
            let centroid = points.clone().sum::<Vec3>() / n;
            let gap = points
                .map(|p| bvh.closest_point(p).unwrap().distance)
                .sum::<f32>()
                / n;
            (centroid, gap)
        })
        .collect()
}

#[test]
fn flare_widens_the_sleeve_and_leg_openings_only() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let bvh = Bvh::from_mesh(&body.mesh).unwrap();
    let flare = 0.03;
    for kind in [
        GarmentKind::Tshirt,
        GarmentKind::Sweater,
        GarmentKind::Jeans,
    ] {
        let cut = CutParams::first_for(&kind);
        let plain = &build_template(model(), &kind, &cut, EDGE).unwrap();
        let flared = build_template(model(), &kind, &CutParams { flare, ..cut }, EDGE).unwrap();
        let before = openings(plain, &bvh);
        let mut widened = 0;
        for (centroid, gap) in openings(&flared, &bvh) {
            let (_, old) = before
                .iter()
                .min_by(|a, b| a.0.distance(centroid).total_cmp(&b.0.distance(centroid)))
                .unwrap();
            let grown = gap - old;
            // The body's openings (neck, hem, waist) keep their ease; the sleeves' cuffs
            // and the trouser hems gain at least half the flare (smoothing and the feet take
            // some).
            if centroid.x.abs() > 0.12 || (kind == GarmentKind::Jeans && centroid.y < 0.5) {
                assert!(
                    grown > 0.5 * flare,
                    "{}: an opening at {centroid} grew {grown} m",
                    kind.name()
                );
                widened += 1;
            } else {
                assert!(
                    grown.abs() < 0.005,
                    "{}: the opening at {centroid} moved {grown} m",
                    kind.name()
                );
            }
        }
        assert_eq!(widened, 2, "{}", kind.name());
    }
}

#[test]
fn thigh_room_loosens_the_jeans_thighs_only() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let bvh = Bvh::from_mesh(&body.mesh).unwrap();
    let kind = GarmentKind::Jeans;
    let cut = CutParams::first_for(&kind);
    let thigh = 0.03;
    let plain = build_template(model(), &kind, &cut, EDGE).unwrap();
    let roomy = build_template(model(), &kind, &CutParams { thigh, ..cut }, EDGE).unwrap();
    // Mean gap to the skin of the vertices within 3 cm of the height where the room is
    // largest (the leg hangs nearly straight down in the rest pose).
    let hip = body.rig.bones[body.rig.index("LeftUpLeg").unwrap()].head;
    let peak = hip.y - garment::cut::THIGH_PEAK * cut.leg_length;
    let thigh_gap = |t: &GarmentTemplate| {
        let gaps: Vec<f32> = (t.mesh.vertices.iter())
            .filter(|p| (p.y - peak).abs() < 0.03)
            .map(|&p| bvh.closest_point(p).unwrap().distance)
            .collect();
        gaps.iter().sum::<f32>() / gaps.len() as f32
    };
    let grown = thigh_gap(&roomy) - thigh_gap(&plain);
    // Smoothing spreads the room and takes some of it (measured: 1.9 cm of 3).
    assert!(
        grown > 0.5 * thigh && grown < 1.2 * thigh,
        "the thighs grew {grown} m"
    );
    // The waist and the hems keep their ease.
    let before = openings(&plain, &bvh);
    for (c1, g1) in openings(&roomy, &bvh) {
        let (c0, g0) = before
            .iter()
            .min_by(|a, b| a.0.distance(c1).total_cmp(&b.0.distance(c1)))
            .unwrap();
        assert!(
            c0.distance(c1) < 0.02 && (g1 - g0).abs() < 0.005,
            "{c0} {g0} -> {c1} {g1}"
        );
    }
    // Tops have no thighs: the setting changes nothing.
    let tshirt = CutParams::first_for(&GarmentKind::Tshirt);
    let a = build_template(model(), &GarmentKind::Tshirt, &tshirt, EDGE).unwrap();
    let b = build_template(
        model(),
        &GarmentKind::Tshirt,
        &CutParams { thigh, ..tshirt },
        EDGE,
    )
    .unwrap();
    assert_eq!(a.mesh, b.mesh);
}

#[test]
fn a_cut_without_bridging_follows_the_hollows_with_more_cloth() {
    let body = model().shape(&Phenotype::default()).unwrap();
    let bvh = Bvh::from_mesh(&body.mesh).unwrap();
    let area = |m: &TriMesh| {
        geom::normals::face_areas(&m.vertices, &m.faces)
            .iter()
            .sum::<f32>()
    };
    let kind = GarmentKind::Tshirt;
    let cut = CutParams::first_for(&kind);
    let spanning = build_template(model(), &kind, &cut, EDGE).unwrap();
    let cut = CutParams { bridge: 0.0, ..cut };
    let following = build_template(model(), &kind, &cut, EDGE).unwrap();
    let (a0, a1) = (area(&spanning.mesh), area(&following.mesh));
    // Measured: 10% more cloth.
    assert!(a1 > 1.05 * a0, "area {a1} m^2 against {a0} m^2");
    let inside = following
        .mesh
        .vertices
        .iter()
        .filter(|p| bvh.contains(**p))
        .count();
    assert_eq!(inside, 0);
}

#[test]
fn the_jeans_waistband_is_the_strip_under_the_waist_and_tops_have_none() {
    let jeans = &templates()[2];
    let band = waistband(jeans, 0.04).unwrap().unwrap();
    let v = &jeans.mesh.vertices;
    let top = v.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    let n = band.iter().filter(|&&b| b).count();
    assert!(n > 0 && n < v.len() / 5, "{n} of {} vertices", v.len());
    for (p, &b) in v.iter().zip(&band) {
        // The opening is level within an edge or so.
        if p.y > top - 0.02 {
            assert!(b, "a vertex 2 cm under the top is in the band");
        }
        if p.y < top - 0.04 - 2.0 * EDGE {
            assert!(!b, "a vertex far under the band is in it");
        }
    }
    for top in &templates()[..2] {
        assert_eq!(waistband(top, 0.04).unwrap(), None);
    }
}
