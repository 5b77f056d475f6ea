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
fn models_that_learned_from_differently_posed_bodies_are_not_draped_together() {
    let device = Device::flex();
    let path = shipped_models_dir().join("tshirt-naive.garnet");
    let model = GarmentModel::load(&path, &device).unwrap();
    assert_eq!(model.body_skinning().unwrap(), garnet::body::Skinning::Lbs);
    let bodies = BodyModel::load().unwrap();
    let target = bodies.shape(&Phenotype::default()).unwrap();
    let pose = Pose::identity(target.rig.len());
    let err = drape(&[], &target, &pose, DrapeOptions::default())
        .err()
        .expect("no model");
    assert!(err.to_string().contains("no model"), "{err}");
}
