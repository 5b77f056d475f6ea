//! End-to-end tests on small synthetic data: shapes of the three variants, input checks,
//! checkpoints, the training loop and overfitting one sample.

use std::time::Instant;

use burn::prelude::*;
use glam::Vec3;
use model::synthetic::{synthetic_sample, tube_garment};
use model::trainer::epoch_checkpoint_name;
use model::*;

const N_BODY: usize = 240;

/// A tiny network of `variant` for a ~`n_garment`-vertex tube over a 240-point ellipsoid.
fn setup(variant: Variant, n_garment: usize) -> ModelSetup {
    let (body, _) = model::synthetic::ellipsoid_body(N_BODY);
    ModelSetup::new(GarNetConfig::tiny(variant), tube_garment(n_garment), &body).unwrap()
}

/// `count` samples: bodies scaled 1.0, 1.03, ..., targets with different phases.
fn samples(setup: &ModelSetup, count: usize) -> Vec<Sample> {
    (0..count)
        .map(|i| {
            synthetic_sample(
                N_BODY,
                &setup.template,
                1.0 + 0.03 * i as f32,
                0.7 * i as f32,
            )
            .unwrap()
        })
        .collect()
}

fn bits(v: &[Vec<Vec3>]) -> Vec<u32> {
    v.iter()
        .flatten()
        .flat_map(|p| p.to_array())
        .map(f32::to_bits)
        .collect()
}

#[test]
fn every_variant_outputs_b_n_3() {
    let device = Device::flex();
    for variant in Variant::ALL {
        let s = setup(variant, 80);
        let n = s.template.num_vertices();
        let model = s.config.init(&device).unwrap();
        let topo = GarmentTopology::from_mesh(&s.template).unwrap();
        let batch = Batch::new(&samples(&s, 2), &topo, &s.input_spec(), &device).unwrap();
        assert_eq!(batch.inputs.local.is_some(), variant == Variant::Local);
        let out = model
            .forward(
                &batch.inputs,
                batch.warped.clone(),
                &topo.to_device(&device),
            )
            .unwrap();
        assert_eq!(out.dims(), [2, n, 3], "{variant:?}");
        let v = model::tensors::read_f32(out).unwrap();
        assert!(v.iter().all(|x| x.is_finite()));
        // The untrained network starts near M (small initial translations).
        let m: Vec<f32> = s
            .template
            .vertices
            .iter()
            .flat_map(|p| p.to_array())
            .collect();
        let max_move = v[..n * 3]
            .iter()
            .zip(&m)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(
            max_move < 0.05,
            "{variant:?} moves M by {max_move} m before training"
        );
    }
}

#[test]
fn local_variant_needs_its_tables() {
    let device = Device::flex();
    let s = setup(Variant::Local, 60);
    let model = s.config.init(&device).unwrap();
    let topo = GarmentTopology::from_mesh(&s.template).unwrap();
    let batch = Batch::new(&samples(&s, 1), &topo, &s.input_spec(), &device).unwrap();
    let mut inputs = batch.inputs.clone();
    inputs.local = None;
    let err = model
        .forward(&inputs, batch.warped, &topo.to_device(&device))
        .unwrap_err();
    assert!(err.to_string().contains("local tables"), "{err}");
}

/// Saves `model` with `setup`, the default loss and a fresh training state, no optimiser.
fn save_without_optimizer(path: &std::path::Path, model: &GarNet, setup: &ModelSetup) {
    save_checkpoint(
        path,
        model,
        None,
        setup,
        &LossConfig::new(),
        &TrainState::default(),
        None,
    )
    .unwrap();
}

/// The checkpoint at `path` with its safetensors header's metadata changed by `edit` (the
/// header is JSON after its 8-byte length).
fn edit_metadata(
    path: &std::path::Path,
    edit: impl FnOnce(&mut serde_json::Map<String, serde_json::Value>),
) {
    let bytes = std::fs::read(path).unwrap();
    let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    let mut header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
    edit(header["__metadata__"].as_object_mut().unwrap());
    let mut head = serde_json::to_vec(&header).unwrap();
    head.resize(head.len().div_ceil(8) * 8, b' ');
    let mut out = (head.len() as u64).to_le_bytes().to_vec();
    out.extend(head);
    out.extend_from_slice(&bytes[8 + n..]);
    std::fs::write(path, out).unwrap();
}

/// A file whose weights were damaged (one flipped bit), or of an older format, is refused
/// with an error naming it; the recipe a network was trained by comes back as it was saved.
#[test]
fn damaged_or_old_checkpoints_are_refused_and_recipes_round_trip() {
    let device = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("net.garnet");
    let s = setup(Variant::Naive, 60).with_body_skinning("lbs").unwrap();
    let model = s.config.init(&device).unwrap();
    let recipe = RecipeRecord {
        recipe: Recipe::parse(
            "format = 1\ngarment = \"tube\"\nvariant = \"naive\"\ndata = \"d\"\n\
             [schedule]\nepochs = 2\n",
        )
        .unwrap(),
        command: "garnet train --recipe r.toml".into(),
    };
    let state = TrainState::default();
    save_checkpoint(
        &path,
        &model,
        None,
        &s,
        &LossConfig::new(),
        &state,
        Some(&recipe),
    )
    .unwrap();
    let back = load_checkpoint(&path).unwrap();
    assert_eq!(back.recipe.as_ref(), Some(&recipe));
    assert_eq!(back.setup.body_skinning, "lbs");

    // One bit flipped in the middle of the weights.
    let mut bytes = std::fs::read(&path).unwrap();
    let mid = bytes.len() - 1000;
    bytes[mid] ^= 0x10;
    let damaged = dir.path().join("damaged.garnet");
    std::fs::write(&damaged, &bytes).unwrap();
    for err in [
        load_checkpoint(&damaged).unwrap_err().to_string(),
        Draper::load(&damaged, &device).unwrap_err().to_string(),
    ] {
        assert!(
            err.contains("damaged.garnet") && err.contains("checksum"),
            "{err}"
        );
    }

    // The format before this one.
    let old = dir.path().join("old.garnet");
    std::fs::copy(&path, &old).unwrap();
    edit_metadata(&old, |m| {
        m.insert("format".into(), "garnet-model-1".into());
    });
    let err = load_checkpoint(&old).unwrap_err().to_string();
    assert!(
        err.contains("old.garnet") && err.contains("garnet-model-2"),
        "{err}"
    );
}

/// A closed ellipsoid body with faces (an icosphere, 642 vertices) and its topology.
fn meshed_body() -> (Vec<Vec3>, BodyTopology) {
    use model::synthetic::{BODY_CENTRE, BODY_RADII};
    let sphere = geom::TriMesh::icosphere(3, 1.0);
    let body: Vec<Vec3> = sphere
        .vertices
        .iter()
        .map(|v| BODY_CENTRE + *v * BODY_RADII)
        .collect();
    let topology = BodyTopology::new(body.len(), sphere.faces).unwrap();
    (body, topology)
}

/// A network with body-contact features and the template-vertex input gets them from its
/// batches (the features of `model::contact` on the body and M; the template), through a
/// checkpoint and in a drape; it refuses to run without them, and a network without them
/// refuses them.
/// A drape (untracked tensors on flex) takes plain loops for the dense layers, the mesh
/// convolutions and the local max pooling; the same network on the autodiff device takes
/// burn's ops throughout. Both agree to within 1e-6 m for every variant, with both
/// extensions, on two samples of a garment of more than two tiles of vertices.
#[test]
fn drapes_on_the_host_match_the_tensor_ops() {
    let device = Device::flex();
    let (body, body_topo) = meshed_body();
    let template = tube_garment(600);
    let topo = GarmentTopology::from_mesh(&template).unwrap();
    assert!(template.num_vertices() > 2 * model::feast_rows::TILE);
    for variant in [Variant::Naive, Variant::Global, Variant::Local] {
        let cfg = GarNetConfig::tiny(variant)
            .with_body_contact(true)
            .with_rest_input(true);
        let setup = ModelSetup::new(cfg, template.clone(), &body)
            .unwrap()
            .with_body_faces(body_topo.faces.clone())
            .unwrap();
        let samples: Vec<Sample> = (0..2)
            .map(|i| {
                let warped =
                    model::synthetic::smooth_displacement(&template.vertices, 0.2 + 0.1 * i as f32);
                Sample::new(body.clone(), &body_topo, warped, None).unwrap()
            })
            .collect();
        let run = |device: &Device| {
            let model = setup.config.init(device).unwrap();
            let batch = Batch::new(&samples, &topo, &setup.input_spec(), device).unwrap();
            let pred = model.forward(&batch.inputs, batch.warped.clone(), &topo.to_device(device));
            model::tensors::read_points(pred.unwrap()).unwrap()
        };
        let (host, ops) = (run(&device), run(&device.clone().autodiff()));
        let worst = host
            .iter()
            .flatten()
            .zip(ops.iter().flatten())
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        assert!(worst < 1e-6, "{variant:?}: {worst} m");
    }
}

#[test]
fn extended_network_takes_its_inputs_and_only_it() {
    let device = Device::flex();
    let (body, body_topo) = meshed_body();
    let cfg = GarNetConfig::tiny(Variant::Local)
        .with_body_contact(true)
        .with_rest_input(true);
    let template = tube_garment(60);
    let setup = ModelSetup::new(cfg.clone(), template.clone(), &body).unwrap();
    assert!(setup.validate().is_err(), "no body faces");
    let setup = setup.with_body_faces(body_topo.faces.clone()).unwrap();
    let model = setup.config.init(&device).unwrap();
    assert!(model.body_contact && model.rest_input);
    let sample = Sample::new(
        body.clone(),
        &body_topo,
        template.vertices.clone(),
        Some(model::synthetic::smooth_displacement(
            &template.vertices,
            0.3,
        )),
    )
    .unwrap();
    let topo = GarmentTopology::from_mesh(&template).unwrap();
    let topo_t = topo.to_device(&device);
    let batch = Batch::new(&[sample], &topo, &setup.input_spec(), &device).unwrap();
    let contact = batch.inputs.contact.clone().expect("contact features");
    // M is the template, so the canonical frame is the identity.
    let normals = geom::normals::vertex_normals(&body, &body_topo.faces);
    let index = geom::KnnIndex::new(&body).unwrap();
    let want =
        model::contact::contact_features(&index, &body, &normals, &template.vertices).unwrap();
    let got = model::tensors::read_f32(contact.clone()).unwrap();
    assert_eq!(contact.dims(), [1, 60, model::contact::CONTACT_WIDTH]);
    let worst = got
        .iter()
        .zip(&want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(worst < 1e-3, "{worst}");
    let rest = model::tensors::read_points(batch.inputs.rest.clone().unwrap()).unwrap();
    assert_eq!(rest[0], template.vertices);
    let run =
        |m: &model::GarNet, inputs: &NetInputs| m.forward(inputs, batch.warped.clone(), &topo_t);
    let pred = model::tensors::read_points(run(&model, &batch.inputs).unwrap()).unwrap();
    // Each extra input left out (bit 0 contact, 1 template vertices).
    let without = |leave_out: u8| {
        let mut i = batch.inputs.clone();
        if leave_out & 1 != 0 {
            i.contact = None;
        }
        if leave_out & 2 != 0 {
            i.rest = None;
        }
        i
    };
    let wants = ["body-contact features", "template vertices"];
    let plain = cfg
        .with_body_contact(false)
        .with_rest_input(false)
        .init(&device)
        .unwrap();
    assert!(!plain.body_contact && !plain.rest_input);
    for (bit, what) in wants.iter().enumerate() {
        let err = run(&model, &without(1 << bit)).unwrap_err().to_string();
        assert!(err.contains(&format!("needs {what}")), "{err}");
        let err = run(&plain, &without(3 & !(1 << bit)))
            .unwrap_err()
            .to_string();
        assert!(err.contains(&format!("takes no {what}")), "{err}");
    }
    assert!(run(&plain, &without(3)).is_ok());
    // Through a checkpoint: the faces come back and a drape computes the same inputs.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.garnet");
    save_without_optimizer(&path, &model, &setup);
    let ck = load_checkpoint(&path).unwrap();
    assert_eq!(ck.setup.body_faces.as_ref(), Some(&body_topo.faces));
    let draper = Draper::load(&path, &device).unwrap();
    let draped = draper.drape(&body, &template.vertices).unwrap();
    let gap = draped
        .iter()
        .zip(&pred[0])
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f32::max);
    assert!(
        gap < 1e-5,
        "drape differs from the batch forward by {gap} m"
    );
}

#[test]
fn drape_refuses_wrong_vertex_counts_and_non_finite_input() {
    let device = Device::flex();
    let s = setup(Variant::Local, 60);
    let n = s.template.num_vertices();
    let model = s.config.init(&device).unwrap();
    let draper = Draper::new(model, s.clone(), &device).unwrap();
    let sample = &samples(&s, 1)[0];
    let ok = draper.drape(&sample.body, &sample.warped).unwrap();
    assert_eq!(ok.len(), n);

    let err = draper
        .drape(&sample.body, &sample.warped[..n - 1])
        .unwrap_err();
    assert!(
        matches!(err, ModelError::VertexCount { expected, got, .. } if expected == n && got == n - 1)
    );
    assert!(
        err.to_string()
            .contains(&format!("expected {n} vertices, got {}", n - 1)),
        "{err}"
    );

    let err = draper.drape(&sample.body[1..], &sample.warped).unwrap_err();
    assert!(err.to_string().starts_with("body vertices"), "{err}");
    assert!(
        err.to_string()
            .contains(&format!("expected {N_BODY} vertices")),
        "{err}"
    );

    let mut body = sample.body.clone();
    body[17].y = f32::NAN;
    let err = draper.drape(&body, &sample.warped).unwrap_err();
    assert!(
        matches!(err, ModelError::NonFinite { index: 17, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("vertex 17 is not finite"), "{err}");

    let mut warped = sample.warped.clone();
    warped[3].x = f32::INFINITY;
    let err = draper.drape(&sample.body, &warped).unwrap_err();
    assert!(
        err.to_string().starts_with("warped garment M: vertex 3"),
        "{err}"
    );
}

/// Draping is unchanged by a turn about gravity and a horizontal move: the network works in
/// the canonical frame fitted to M, so a turned and moved input gives the same drape, turned
/// and moved (up to rounding), for every variant.
#[test]
fn drape_follows_a_turn_about_gravity_and_a_move() {
    let device = Device::flex();
    for variant in Variant::ALL {
        let s = setup(variant, 60);
        let model = s.config.init(&device).unwrap();
        let draper = Draper::new(model, s.clone(), &device).unwrap();
        let sample = &samples(&s, 2)[1];
        let plain = draper.drape(&sample.body, &sample.warped).unwrap();
        let frame = CanonicalFrame {
            rotation: glam::Quat::from_rotation_y(2.3),
            offset: Vec3::new(1.5, 0.0, -0.8),
        };
        let turn = |pts: &[Vec3]| -> Vec<Vec3> { pts.iter().map(|&p| frame.to_world(p)).collect() };
        let turned = draper
            .drape(&turn(&sample.body), &turn(&sample.warped))
            .unwrap();
        let worst = turn(&plain)
            .iter()
            .zip(&turned)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0f32, f32::max);
        assert!(
            worst < 1e-4,
            "{variant:?}: turned drape differs by {worst} m"
        );
    }
}

#[test]
fn batch_refuses_mismatched_samples() {
    let device = Device::flex();
    let s = setup(Variant::Global, 60);
    let topo = GarmentTopology::from_mesh(&s.template).unwrap();
    let spec = s.input_spec();
    let mut bad = samples(&s, 2);
    bad[1].warped.pop();
    assert!(Batch::new(&bad, &topo, &spec, &device).is_err());
    let mut bad = samples(&s, 2);
    bad[0].target.as_mut().unwrap()[0].z = f32::NAN;
    assert!(Batch::new(&bad, &topo, &spec, &device).is_err());
    assert!(Batch::new(&[], &topo, &spec, &device).is_err());
    // Without targets a batch is an inference batch: the loss refuses it.
    let mut no_target = samples(&s, 1);
    no_target[0].target = None;
    let b = Batch::new(&no_target, &topo, &spec, &device).unwrap();
    assert!(b.target.is_none());
    let pred = b.warped.clone();
    assert!(garnet_loss(pred, &b, &topo.to_device(&device), &LossConfig::new()).is_err());
}

#[test]
fn checkpoints_round_trip_exactly_and_resume_training() {
    let device = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    // The checkpoint also carries an opaque garment file, byte for byte, and the skinning
    // of the bodies it learned from.
    let s = setup(Variant::Local, 60)
        .with_garment_file((0..=255u8).cycle().take(1000).collect())
        .with_body_skinning("lbs")
        .unwrap();
    let data = samples(&s, 3);
    let mut trainer = Trainer::new(s.clone(), LossConfig::new(), 1e-3, &device).unwrap();
    for _ in 0..3 {
        trainer.step(&data[..2]).unwrap();
    }
    let path = dir.path().join("model.garnet");
    trainer.save(&path).unwrap();

    // Inference: bit-identical outputs after reload.
    let pairs: Vec<(&[Vec3], &[Vec3])> =
        data.iter().map(|d| (&d.body[..], &d.warped[..])).collect();
    let before = trainer.draper().unwrap().drape_batch(&pairs).unwrap();
    let loaded = Draper::load(&path, &device).unwrap();
    assert_eq!(loaded.setup(), trainer.setup());
    let after = loaded.drape_batch(&pairs).unwrap();
    assert_eq!(bits(&before), bits(&after));

    let ck = load_checkpoint(&path).unwrap();
    assert_eq!(ck.setup.body_skinning, "lbs");
    assert_eq!(ck.state.step, 3);
    assert!(ck.has_optimizer());
    assert_eq!(ck.loss, LossConfig::new());

    // Training: the resumed trainer (Adam moments included) takes the same next step.
    let mut resumed = Trainer::resume(&path, None, &device).unwrap();
    assert_eq!(resumed.state(), trainer.state());
    let a = trainer.step(&data[1..]).unwrap();
    let b = resumed.step(&data[1..]).unwrap();
    assert_eq!(a, b);
    let a = trainer.draper().unwrap().drape_batch(&pairs).unwrap();
    let b = resumed.draper().unwrap().drape_batch(&pairs).unwrap();
    assert_eq!(bits(&a), bits(&b));
    // A fresh Adam (no moments) would have stepped differently.
    let mut fresh = Trainer::resume(&path, None, &device).unwrap();
    let fresh_model = ck.model(&device.clone().autodiff()).unwrap();
    let mut optim = model::adam();
    let topo = GarmentTopology::from_mesh(&s.template).unwrap();
    let batch = fresh.train_batch(&data[1..]).unwrap();
    let mut m = fresh_model;
    train_step(
        &mut m,
        &mut optim,
        &batch,
        &topo.to_device(&device.clone().autodiff()),
        &LossConfig::new(),
        1e-3,
        None,
    )
    .unwrap();
    fresh.step(&data[1..]).unwrap();
    let with_moments = fresh.draper().unwrap().drape_batch(&pairs).unwrap();
    let without = Draper::new(m, s.clone(), &device)
        .unwrap()
        .drape_batch(&pairs)
        .unwrap();
    assert_ne!(bits(&with_moments), bits(&without));
}

#[test]
fn corrupt_or_foreign_checkpoints_are_clear_errors() {
    let device = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.garnet");
    std::fs::write(&junk, b"not a checkpoint").unwrap();
    let err = Draper::load(&junk, &device).unwrap_err();
    assert!(err.to_string().contains("junk.garnet"), "{err}");
    let missing = dir.path().join("missing.garnet");
    assert!(load_checkpoint(&missing).is_err());
    // A checkpoint whose weights belong to another architecture.
    let s = setup(Variant::Global, 60);
    let path = dir.path().join("g.garnet");
    let model = s.config.init(&device).unwrap();
    save_without_optimizer(&path, &model, &s);
    let mut ck = load_checkpoint(&path).unwrap();
    assert!(!ck.has_optimizer());
    ck.setup.config = ck.setup.config.clone().with_conv_width(24);
    assert!(ck.model(&device).is_err());
    // A skinning the body model does not have.
    assert!(setup(Variant::Global, 60)
        .with_body_skinning("cubic")
        .is_err());
    // A network saved with a setup of another variant.
    let local = setup(Variant::Local, 60);
    assert!(save_checkpoint(
        &path,
        &model,
        None,
        &local,
        &LossConfig::new(),
        &TrainState::default(),
        None,
    )
    .is_err());
}

/// A tiny Naive network's trainer and three samples to train it on.
fn naive_trainer_on_three(device: &Device) -> (Trainer, Vec<Sample>) {
    let s = setup(Variant::Naive, 60);
    let data = samples(&s, 3);
    (
        Trainer::new(s, LossConfig::new(), 1e-3, device).unwrap(),
        data,
    )
}

/// `data` as batches of one sample.
fn batches_of_one(data: &[Sample]) -> Vec<Result<Vec<Sample>, String>> {
    data.chunks(1).map(|c| Ok(c.to_vec())).collect()
}

#[test]
fn a_per_step_schedule_changes_the_rate_inside_each_epoch() {
    let device = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    let (mut trainer, data) = naive_trainer_on_three(&device);
    let train = || batches_of_one(&data);
    let schedule = CosineSchedule::new(1e-3, 1e-5, 0, 2).unwrap().per_step(3);
    trainer.set_schedule(Some(schedule));
    let reports = trainer
        .fit(
            2,
            |_, _| train(),
            None::<fn() -> Vec<_>>,
            dir.path(),
            |_| {},
        )
        .unwrap();
    // Each report carries its epoch's last rate: step 2 of 3, not the epoch's first.
    assert!((reports[0].lr - schedule.lr_of_step(0, 2)).abs() < 1e-15);
    assert!(reports[0].lr < schedule.lr(0) && reports[0].lr > schedule.lr(1));
    assert!((reports[1].lr - schedule.lr_of_step(1, 2)).abs() < 1e-15);
    assert!(reports[1].lr < schedule.lr(1));
    // The checkpoint keeps the plan, so resuming with it continues step by step.
    let (last, _, _) = Trainer::output_paths(dir.path());
    assert_eq!(
        load_checkpoint(&last).unwrap().state.schedule,
        Some(schedule)
    );
}

#[test]
fn a_compute_budget_ends_the_run_sets_its_rate_and_extends_on_resume() {
    let device = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    let (mut trainer, data) = naive_trainer_on_three(&device);
    let train = || batches_of_one(&data);
    let no_valid = None::<fn() -> Vec<_>>;
    // 0.3 CPU seconds: a fraction of what 1000 epochs take, at least a step.
    let budget = TimeBudget::new(0.005, 0.0, 1e-3, 1e-5).unwrap();
    trainer.set_budget(Some(budget));
    let reports = trainer
        .fit(1000, |_, _| train(), no_valid, dir.path(), |_| {})
        .unwrap();
    let state = trainer.state().clone();
    assert!(
        trainer.budget_spent() && state.train_cpu_s >= 0.3,
        "{state:?}"
    );
    assert!(
        state.epoch < 1000 && state.epoch == reports.len(),
        "{state:?}"
    );
    // The last step ran just under the budget's end: near the cosine's end rate.
    assert!(state.lr < 1e-4, "{state:?}");
    assert_eq!(reports.last().unwrap().train_cpu_s, state.train_cpu_s);
    // Resumed with the same budget there is nothing left to do; with twice it goes on.
    let (last, _, metrics) = Trainer::output_paths(dir.path());
    let mut again = Trainer::resume(&last, None, &device).unwrap();
    assert_eq!(again.state().budget, Some(budget));
    let none = again
        .fit(1000, |_, _| train(), no_valid, dir.path(), |_| {})
        .unwrap();
    assert!(none.is_empty());
    again.set_budget(Some(TimeBudget::new(0.01, 0.0, 1e-3, 1e-5).unwrap()));
    let more = again
        .fit(1000, |_, _| train(), no_valid, dir.path(), |_| {})
        .unwrap();
    assert!(!more.is_empty() && again.state().train_cpu_s >= 0.6);
    assert!(again.state().step > state.step);
    let csv = std::fs::read_to_string(metrics).unwrap();
    let cpu: f64 = csv
        .lines()
        .last()
        .unwrap()
        .rsplit(',')
        .nth(2)
        .unwrap()
        .parse()
        .unwrap();
    assert!((cpu - again.state().train_cpu_s).abs() < 0.06, "{cpu}");
}

#[test]
fn trainer_writes_checkpoints_and_metrics_and_resumes() {
    let device = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    let s = setup(Variant::Global, 60);
    let data = samples(&s, 4);
    let train = || {
        data[..3]
            .chunks(2)
            .map(|c| Ok::<_, String>(c.to_vec()))
            .collect::<Vec<_>>()
    };
    let valid = || vec![Ok::<_, String>(data[3..].to_vec())];
    let mut trainer = Trainer::new(s.clone(), LossConfig::new(), 1e-3, &device).unwrap();
    let schedule = CosineSchedule::new(1e-3, 1e-4, 0, 3).unwrap();
    trainer.set_schedule(Some(schedule));
    trainer.set_max_grad_norm(Some(50.0)).unwrap();
    assert!(trainer.set_max_grad_norm(Some(-1.0)).is_err());
    let mut seen = Vec::new();
    let reports = trainer
        .fit(
            2,
            |_, _| train(),
            Some(valid),
            dir.path(),
            |r| seen.push(r.epoch),
        )
        .unwrap();
    assert_eq!(seen, vec![1, 2]);
    assert_eq!(reports[0].train_samples, 3);
    assert!(reports[0].is_best);
    let v = reports[1].validation.unwrap();
    assert_eq!(v.samples, 1);
    assert!(v.e_dist_cm > 0.0 && v.e_norm_deg >= 0.0);
    let (last, best, metrics) = Trainer::output_paths(dir.path());
    assert!(last.exists() && best.exists());
    let text = std::fs::read_to_string(&metrics).unwrap();
    assert_eq!(text.lines().count(), 3);
    assert_eq!(trainer.state().step, 4);
    // The schedule sets each epoch's rate; every step reports its gradient norm, and the
    // log the epoch's mean.
    assert_eq!(reports[0].lr, 1e-3);
    assert!((reports[1].lr - schedule.lr(1)).abs() < 1e-15);
    assert!(reports.iter().all(|r| r.grad_norm > 0.0));
    assert!(text.lines().nth(1).unwrap().contains(&format!(
        ",{},{:.1},",
        reports[0].grad_norm, reports[0].train_cpu_s
    )));

    // The resumed run keeps the clipping and the schedule (a new plan of the same rates
    // and end keeps the old start).
    let mut resumed = Trainer::resume(&last, None, &device).unwrap();
    assert_eq!(resumed.state().epoch, 2);
    assert_eq!(resumed.state().max_grad_norm, Some(50.0));
    resumed.set_schedule(Some(CosineSchedule::new(1e-3, 1e-4, 2, 3).unwrap()));
    assert_eq!(resumed.state().schedule, Some(schedule));
    let more = resumed
        .fit(3, |_, _| train(), Some(valid), dir.path(), |_| {})
        .unwrap();
    assert_eq!(more.len(), 1);
    assert_eq!(more[0].epoch, 3);
    assert!((more[0].lr - schedule.lr(2)).abs() < 1e-15);
    let text = std::fs::read_to_string(&metrics).unwrap();
    assert_eq!(text.lines().count(), 4);
    assert_eq!(load_checkpoint(&last).unwrap().state.epoch, 3);

    // A data source error stops the epoch with that error.
    let err = resumed
        .run_epoch(
            vec![Err::<Vec<Sample>, _>("shard 7 unreadable".to_string())],
            None::<Vec<Result<Vec<Sample>, String>>>,
            dir.path(),
        )
        .unwrap_err();
    assert!(err.to_string().contains("shard 7 unreadable"));
}

/// Clipping the gradients to a tiny norm changes the steps after the first (Adam's first
/// step does not see the gradient's scale) and reports the norm before clipping.
#[test]
fn gradient_clipping_changes_training() {
    let device = Device::flex();
    let s = setup(Variant::Naive, 60);
    let data = samples(&s, 2);
    let pairs: Vec<(&[Vec3], &[Vec3])> =
        data.iter().map(|d| (&d.body[..], &d.warped[..])).collect();
    let run = |clip: Option<f32>| {
        let mut t = Trainer::new(s.clone(), LossConfig::new(), 1e-3, &device).unwrap();
        t.set_max_grad_norm(clip).unwrap();
        let norms: Vec<f32> = (0..3)
            .map(|i| t.step(&data[i % 2..i % 2 + 1]).unwrap().grad_norm)
            .collect();
        (norms, t.draper().unwrap().drape_batch(&pairs).unwrap())
    };
    let (free_norms, free) = run(None);
    let (clipped_norms, clipped) = run(Some(1e-3));
    assert_eq!(free_norms[0], clipped_norms[0]);
    assert!(free_norms[0] > 1e-3);
    assert_ne!(bits(&free), bits(&clipped));
}

/// GarNet-Local with small widths fits one synthetic sample (a smooth ~3 cm drape of a
/// 120-vertex tube) to a mean vertex error under 1 mm with the full loss and Adam (learning
/// rate 1e-3, lowered to 3e-4 and 1e-4 late: near the optimum the L1 bending term dominates
/// the loss and keeps Adam oscillating at a constant step).
#[test]
fn tiny_model_overfits_one_sample_below_one_millimetre() {
    let device = Device::flex();
    let mut s = setup(Variant::Local, 120);
    s.config = s
        .config
        .clone()
        .with_fusion(vec![128, 64, 32])
        .with_garment_mlp(vec![64, 64]);
    let sample = samples(&s, 1);
    let start_error =
        geom::metrics::e_dist(sample[0].target.as_ref().unwrap(), &sample[0].warped).unwrap();
    assert!(
        start_error > 0.02,
        "the target must be a real drape: {start_error}"
    );
    let mut trainer = Trainer::new(s, LossConfig::new(), 1e-3, &device).unwrap();
    let start = Instant::now();
    let target = sample[0].target.as_ref().unwrap();
    let error = |t: &Trainer| {
        let pred = t
            .draper()
            .unwrap()
            .drape(&sample[0].body, &sample[0].warped)
            .unwrap();
        geom::metrics::e_dist(target, &pred).unwrap()
    };
    let mut steps = 0;
    let mut e = error(&trainer);
    // Train until the drape after the last step is within 0.5 mm, checked every 25 steps.
    while steps < 4000 && e >= 5e-4 {
        trainer.step(&sample).unwrap();
        steps += 1;
        match steps {
            1500 => trainer.set_lr(3e-4),
            2500 => trainer.set_lr(1e-4),
            _ => {}
        }
        if steps % 25 == 0 {
            e = error(&trainer);
        }
    }
    e = error(&trainer);
    println!(
        "overfit: {steps} steps, {:.1} s, E_dist {:.3} mm",
        start.elapsed().as_secs_f64(),
        e * 1e3
    );
    assert!(e < 1e-3, "E_dist {e} m after {steps} steps");
}

/// Regression: a run resumed on another dataset kept the best validation
/// E_dist of the old one, so it never wrote `best.garnet`. A checkpoint now names the set
/// its best was measured on, and a run validating on another set starts its best afresh.
#[test]
fn best_starts_afresh_on_another_validation_set() {
    let device = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    let s = setup(Variant::Naive, 40);
    let data = samples(&s, 3);
    let train = || vec![Ok::<_, String>(data[..2].to_vec())];
    let valid = || vec![Ok::<_, String>(data[2..].to_vec())];
    let mut trainer = Trainer::new(s, LossConfig::new(), 1e-3, &device).unwrap();
    assert_eq!(trainer.set_validation_set("set-a:tube"), None);
    trainer
        .fit(1, |_, _| train(), Some(valid), dir.path(), |_| {})
        .unwrap();
    let (last, best, _) = Trainer::output_paths(dir.path());
    let state = load_checkpoint(&best).unwrap().state;
    assert_eq!(state.validation.as_deref(), Some("set-a:tube"));
    let first_best = state.best_e_dist_cm.unwrap();

    // The same set keeps the figure; another one clears it.
    let mut same = Trainer::resume(&last, None, &device).unwrap();
    assert_eq!(same.set_validation_set("set-a:tube"), None);
    assert_eq!(same.state().best_e_dist_cm, Some(first_best));
    let mut other = Trainer::resume(&last, None, &device).unwrap();
    assert_eq!(other.set_validation_set("set-b:tube"), Some(first_best));
    assert_eq!(other.state().best_e_dist_cm, None);

    // A best far below anything reachable, carried in from the other set, would block
    // every later best; cleared, the next epoch writes best.garnet.
    let carried = load_checkpoint(&last).unwrap();
    let mut state = carried.state.clone();
    state.best_e_dist_cm = Some(1e-6);
    let model = carried.model(&device).unwrap();
    save_checkpoint(
        &last,
        &model,
        None,
        &carried.setup,
        &carried.loss,
        &state,
        None,
    )
    .unwrap();
    std::fs::remove_file(&best).unwrap();
    let mut resumed = Trainer::resume(&last, None, &device).unwrap();
    assert_eq!(resumed.set_validation_set("set-b:tube"), Some(1e-6));
    let reports = resumed
        .fit(2, |_, _| train(), Some(valid), dir.path(), |_| {})
        .unwrap();
    assert!(reports[0].is_best && best.is_file());
    let state = load_checkpoint(&best).unwrap().state;
    assert_eq!(state.validation.as_deref(), Some("set-b:tube"));
    assert_eq!(state.epoch, 2);
}

/// `set_keep_epochs` writes every epoch's checkpoint beside `last.garnet`; a run branched
/// from one of them (copied to another folder's `last.garnet`) takes the trunk's next steps
/// bit for bit, and a run without the option keeps none.
#[test]
fn kept_epochs_are_checkpoints_to_branch_from() {
    let device = Device::flex();
    let trunk = tempfile::tempdir().unwrap();
    let (mut trainer, data) = global_trainer_on_two_samples(&device);
    let train = || vec![Ok::<_, String>(data.clone())];
    trainer.set_keep_epochs(true);
    trainer
        .fit(2, |_, _| train(), NO_VALIDATION, trunk.path(), |_| {})
        .unwrap();
    let params = |path: &std::path::Path| {
        let epoch = load_checkpoint(path).unwrap().state.epoch;
        (epoch, checkpoint_params(path, &device))
    };
    let (last, _, _) = Trainer::output_paths(trunk.path());
    let kept: Vec<_> = (1..=2)
        .map(|e| params(&trunk.path().join(epoch_checkpoint_name(e))))
        .collect();
    assert_eq!(kept[0].0, 1);
    assert_eq!(kept[1], params(&last));
    assert_ne!(kept[0].1, kept[1].1);

    let branch = tempfile::tempdir().unwrap();
    let (branch_last, _, _) = Trainer::output_paths(branch.path());
    std::fs::copy(trunk.path().join(epoch_checkpoint_name(1)), &branch_last).unwrap();
    let mut resumed = Trainer::resume(&branch_last, None, &device).unwrap();
    resumed
        .fit(2, |_, _| train(), NO_VALIDATION, branch.path(), |_| {})
        .unwrap();
    assert_eq!(params(&branch_last), kept[1]);
    assert!(!branch.path().join(epoch_checkpoint_name(2)).exists());
}

/// An epoch stopped inside (here by a data error after two of its four batches) resumes from
/// its mid-epoch checkpoint at the next batch, and ends with the network, optimiser and
/// epoch report of a run that never stopped; the checkpoint is gone once the epoch ends. A
/// run on another training set or order refuses to go on with that epoch.
#[test]
fn an_epoch_stopped_inside_resumes_where_it_stopped() {
    let device = Device::flex();
    let s = setup(Variant::Global, 40);
    let data = samples(&s, 4);
    let batches = |skip: usize| -> SampleBatches {
        data.chunks(1).skip(skip).map(|c| Ok(c.to_vec())).collect()
    };
    let fresh = || {
        let mut t = Trainer::new(s.clone(), LossConfig::new(), 1e-3, &device).unwrap();
        t.set_training_set("set-a");
        t
    };
    let whole = tempfile::tempdir().unwrap();
    let reports = fresh()
        .fit(
            2,
            |_, skip| batches(skip),
            NO_VALIDATION,
            whole.path(),
            |_| {},
        )
        .unwrap();

    let dir = tempfile::tempdir().unwrap();
    assert_eq!(Trainer::resume_point(dir.path()).unwrap(), None);
    let mut stopped = fresh();
    stopped.set_checkpoint_every(Some(std::time::Duration::ZERO));
    let err = stopped
        .fit(
            2,
            |epoch, skip| match epoch {
                0 => batches(skip),
                _ => {
                    let mut b = batches(skip);
                    b.insert(2, Err("the data source stopped".into()));
                    b
                }
            },
            NO_VALIDATION,
            dir.path(),
            |_| {},
        )
        .unwrap_err();
    assert!(err.to_string().contains("the data source stopped"));
    let mid = dir.path().join(model::trainer::MID_EPOCH_CHECKPOINT);
    assert_eq!(
        Trainer::resume_point(dir.path()).unwrap(),
        Some(mid.clone())
    );
    let state = load_checkpoint(&mid).unwrap().state;
    assert_eq!((state.epoch, state.step), (1, 6));
    assert_eq!(state.partial.as_ref().map(|p| p.batches), Some(2));
    // The stopped trainer itself goes on from there too.
    assert_eq!(stopped.state().partial, state.partial);
    let same_trainer = tempfile::tempdir().unwrap();
    stopped
        .fit(
            2,
            |_, skip| batches(skip),
            NO_VALIDATION,
            same_trainer.path(),
            |_| {},
        )
        .unwrap();
    let (whole_last, _, _) = Trainer::output_paths(whole.path());
    assert_eq!(
        checkpoint_params(&same_trainer.path().join("last.garnet"), &device),
        checkpoint_params(&whole_last, &device)
    );
    let mut elsewhere = Trainer::resume(&mid, None, &device).unwrap();
    elsewhere.set_training_set("set-b");
    let refused = elsewhere
        .fit(
            2,
            |_, skip| batches(skip),
            NO_VALIDATION,
            dir.path(),
            |_| {},
        )
        .unwrap_err()
        .to_string();
    assert!(
        refused.contains("epoch 2 after 2 batches") && refused.contains("set-a"),
        "{refused}"
    );

    let mut resumed = Trainer::resume(&mid, None, &device).unwrap();
    resumed.set_training_set("set-a");
    let mut skipped = Vec::new();
    let rest = resumed
        .fit(
            2,
            |_, skip| {
                skipped.push(skip);
                batches(skip)
            },
            NO_VALIDATION,
            dir.path(),
            |_| {},
        )
        .unwrap();
    assert_eq!(skipped, vec![2]);
    assert_eq!(rest[0].train, reports[1].train);
    assert_eq!(rest[0].grad_norm, reports[1].grad_norm);
    assert_eq!(rest[0].train_samples, 4);
    assert!(!mid.exists());
    let (last, _, _) = Trainer::output_paths(dir.path());
    assert_eq!(
        Trainer::resume_point(dir.path()).unwrap(),
        Some(last.clone())
    );
    assert_eq!(
        checkpoint_params(&last, &device),
        checkpoint_params(&whole_last, &device)
    );
    let state = load_checkpoint(&last).unwrap().state;
    assert_eq!((state.step, &state.partial), (8, &None));
    // The same state, but for the CPU time each run took.
    let whole = load_checkpoint(&whole_last).unwrap().state;
    let untimed = |s: TrainState| TrainState {
        train_cpu_s: 0.0,
        ..s
    };
    assert_eq!(untimed(state), untimed(whole));
    // Adam's moments too: one more epoch from each gives the same network.
    for path in [&last, &whole_last] {
        let mut t = Trainer::resume(path, None, &device).unwrap();
        t.set_training_set("set-a");
        t.fit(
            3,
            |_, skip| batches(skip),
            NO_VALIDATION,
            path.parent().unwrap(),
            |_| {},
        )
        .unwrap();
    }
    assert_eq!(
        checkpoint_params(&last, &device),
        checkpoint_params(&whole_last, &device)
    );
}

/// No validation data, for [`Trainer::fit`].
const NO_VALIDATION: Option<fn() -> SampleBatches> = None;

/// Batches of samples as [`Trainer::fit`] takes them.
type SampleBatches = Vec<Result<Vec<Sample>, String>>;

/// A fresh GarNet-Global trainer (Adam at 1e-3) on a 40-vertex tube, and two samples of it.
fn global_trainer_on_two_samples(device: &Device) -> (Trainer, Vec<Sample>) {
    let s = setup(Variant::Global, 40);
    let data = samples(&s, 2);
    (
        Trainer::new(s, LossConfig::new(), 1e-3, device).unwrap(),
        data,
    )
}

/// Collects the values of every float parameter of a module, in visiting order.
struct ParamValues(Vec<Vec<f32>>);

impl burn::module::ModuleVisitor for ParamValues {
    fn visit_float<const D: usize>(&mut self, param: &burn::module::Param<Tensor<D>>) {
        self.0.push(model::tensors::read_f32(param.val()).unwrap());
    }
}

/// The values of the network parameters of the checkpoint at `path`.
fn checkpoint_params(path: &std::path::Path, device: &Device) -> Vec<Vec<f32>> {
    let model = load_checkpoint(path).unwrap().model(device).unwrap();
    let mut values = ParamValues(Vec::new());
    model.visit(&mut values);
    values.0
}
