//! The shipped models: all nine load in the current format and drape; a copy with damaged
//! weights is refused, naming the file.

use garnet::body::{BodyModel, Phenotype, Pose};
use garnet::{drape, shipped_models_dir, Device, DrapeOptions, GarmentModel};

const SHIPPED: [&str; 9] = [
    "tshirt-local",
    "tshirt-global",
    "tshirt-naive",
    "sweater-local",
    "sweater-global",
    "sweater-naive",
    "jeans-local",
    "jeans-global",
    "jeans-naive",
];

#[test]
fn the_nine_models_load_and_drape_a_body() {
    let device = Device::flex();
    let bodies = BodyModel::load().unwrap();
    let target = bodies.shape(&Phenotype::default()).unwrap();
    let pose = Pose::identity(target.rig.len());
    for name in SHIPPED {
        let path = shipped_models_dir().join(format!("{name}.garnet"));
        let model = GarmentModel::load(&path, &device).unwrap();
        let (garment, variant) = name.split_once('-').unwrap();
        assert_eq!(model.template().kind.name(), garment, "{name}");
        assert!(
            model
                .method_name()
                .starts_with(&format!("GarNet-{variant}")),
            "{name}"
        );
        let card = std::fs::read_to_string(path.with_extension("md")).unwrap();
        assert!(
            card.contains(&format!("recipes/{name}.toml")),
            "{name}'s card"
        );
        let out = drape(&[model], &target, &pose, DrapeOptions::default()).unwrap();
        let g = &out.garments[0];
        assert!(g.mesh.vertices.iter().all(|v| v.is_finite()), "{name}");
        assert!(!g.mesh.faces.is_empty(), "{name}");
    }
}

#[test]
fn a_model_with_damaged_weights_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = std::fs::read(shipped_models_dir().join("jeans-naive.garnet")).unwrap();
    // A byte in the middle of the network's weights, far from the header.
    let k = bytes.len() / 2;
    bytes[k] ^= 0x01;
    let damaged = dir.path().join("damaged-jeans.garnet");
    std::fs::write(&damaged, &bytes).unwrap();
    let err = GarmentModel::load(&damaged, &Device::flex())
        .err()
        .expect("refused");
    let msg = format!("{err:#}");
    assert!(
        msg.contains("damaged-jeans.garnet") && msg.contains("damaged"),
        "{msg}"
    );
}

#[test]
fn a_model_knows_its_body_skinning_and_draping_with_none_is_refused() {
    let device = Device::flex();
    let path = shipped_models_dir().join("tshirt-naive.garnet");
    let model = GarmentModel::load(&path, &device).unwrap();
    assert_eq!(model.body_skinning().unwrap(), garnet::body::Skinning::Lbs);
    let bodies = BodyModel::load().unwrap();
    let target = bodies.shape(&Phenotype::default()).unwrap();
    let pose = Pose::identity(target.rig.len());
    let err = drape(&[], &target, &pose, DrapeOptions::default()).unwrap_err();
    assert!(err.to_string().contains("no model"), "{err}");
}

/// A body the caller posed (mesh and bone placements) drapes as the same body and pose
/// given by shape and pose; wrong counts and NaN are refused.
#[test]
fn a_body_posed_by_the_caller_drapes_as_its_shape_and_pose() {
    use garnet::body::pose::{PoseKind, ProceduralPoseGenerator};
    use garnet::{drape_posed, PosedBody};
    let device = Device::flex();
    let model =
        GarmentModel::load(&shipped_models_dir().join("jeans-local.garnet"), &device).unwrap();
    let bodies = BodyModel::load().unwrap();
    let target = bodies.shape(&Phenotype::default()).unwrap();
    let mut walks = ProceduralPoseGenerator::new(5, PoseKind::Walk);
    let pose = garnet::body::self_contact::sample_valid_pose(&target, &mut walks, 200).unwrap();
    let opts = DrapeOptions {
        clear_limbs: false,
        push_out: true,
    };
    let models = [model];
    let by_pose = drape(&models, &target, &pose, opts).unwrap();
    let posed = PosedBody::from_pose(&target, &pose, models[0].body_skinning().unwrap()).unwrap();
    let by_mesh = drape_posed(&models, &posed, true).unwrap();
    let worst = by_pose.garments[0]
        .mesh
        .vertices
        .iter()
        .zip(&by_mesh[0].mesh.vertices)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-4, "{worst} m");
    let mut short = posed.clone();
    short.vertices.pop();
    assert!(drape_posed(&models, &short, true)
        .unwrap_err()
        .to_string()
        .contains("vertices"));
    let mut few = posed.clone();
    few.joints.pop();
    assert!(drape_posed(&models, &few, true)
        .unwrap_err()
        .to_string()
        .contains("joints"));
    let mut nan = posed;
    nan.joints[3].0.x = f32::NAN;
    assert!(drape_posed(&models, &nan, true)
        .unwrap_err()
        .to_string()
        .contains("joint 3"));
}

/// A network whose base is anchored gets M placed on the posed body by the template's
/// surface anchors, not skinned by DQS, and is named for it.
#[test]
fn an_anchored_network_gets_its_m_placed_by_the_surface_anchors() {
    use garnet::model::{load_checkpoint, save_checkpoint, Base};
    let device = Device::flex();
    let shipped = shipped_models_dir().join("jeans-naive.garnet");
    let ck = load_checkpoint(&shipped).unwrap();
    let mut setup = ck.setup.clone();
    setup.config.base = Base::Anchored;
    let dir = tempfile::tempdir().unwrap();
    let anchored_path = dir.path().join("jeans-anchored.garnet");
    let net = ck.model(&device).unwrap();
    save_checkpoint(
        &anchored_path,
        &net,
        None,
        &setup,
        &ck.loss,
        &ck.state,
        ck.recipe.as_ref(),
    )
    .unwrap();
    let dqs = GarmentModel::load(&shipped, &device).unwrap();
    let anchored = GarmentModel::load(&anchored_path, &device).unwrap();
    assert!(
        anchored.method_name().ends_with(" +anchored"),
        "{}",
        anchored.method_name()
    );
    assert!(!dqs.method_name().contains("anchored"));
    let bodies = BodyModel::load().unwrap();
    // A heavier body than the template's: the anchors carry the garment over its girth.
    let heavy = Phenotype {
        weight: 0.8,
        ..Phenotype::default()
    };
    let target = bodies.shape(&heavy).unwrap();
    let mut walks =
        garnet::body::pose::ProceduralPoseGenerator::new(2, garnet::body::pose::PoseKind::Walk);
    let pose = garnet::body::self_contact::sample_valid_pose(&target, &mut walks, 200).unwrap();
    let opts = DrapeOptions {
        clear_limbs: false,
        push_out: false,
    };
    let anchors = garnet::base_anchors(Base::Anchored, anchored.template(), &bodies)
        .unwrap()
        .unwrap();
    let a = drape(&[anchored], &target, &pose, opts).unwrap();
    let d = drape(&[dqs], &target, &pose, opts).unwrap();
    assert_eq!(a.garments[0].warped, anchors.place(&a.body));
    let apart = a.garments[0]
        .warped
        .iter()
        .zip(&d.garments[0].warped)
        .map(|(p, q)| p.distance(*q))
        .sum::<f32>()
        / a.garments[0].warped.len() as f32;
    assert!(apart > 1e-3, "M moved {apart} m");
    assert_ne!(a.garments[0].mesh.vertices, d.garments[0].mesh.vertices);
}
