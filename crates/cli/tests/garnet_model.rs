//! Integration tests of `garnet train`, `garnet eval` and `garnet drape` on a small
//! dataset of coarse T-shirts (generated once for all of them).

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::{fails, garnet, ok, s};
use dataset::batches::Order;

/// 3 bodies (train, val, test) x T-shirt in 2 poses: 6 samples of an 8 cm T-shirt, on
/// bodies skinned by linear blending.
const SPEC: &str = r#"
name = "model-cli"
seed = 4
shard_size = 2
[bodies]
count = 3
[[garments]]
kind = "tshirt"
edge = 0.08
poses_per_body = 2
[[poses.procedural]]
kind = "walk"
count = 4
[splits.bodies]
train = 1
val = 1
test = 1
[simulator]
morph_steps = 2
pose_steps = 3
max_settle_steps = 5
iterations = 2
max_penetration = 0.5
skinning = "lbs"
"#;

/// The dataset folder, generated on first use (kept in a folder that lives as long as the
/// test process).
fn dataset() -> &'static Path {
    static DIR: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &DIR.get_or_init(|| {
        let tmp = tempfile::tempdir().unwrap();
        let data = generate_in(tmp.path(), SPEC, &["--jobs", "2"]);
        (tmp, data)
    })
    .1
}

/// Writes `spec` to `dir/spec.toml` and runs `garnet dataset generate` on it into
/// `dir/data` with the `extra` flags; returns the data folder.
fn generate_in(dir: &Path, spec: &str, extra: &[&str]) -> PathBuf {
    let spec_path = dir.join("spec.toml");
    std::fs::write(&spec_path, spec).unwrap();
    let data = dir.join("data");
    let mut args = vec!["dataset", "generate", s(&spec_path), "--out", s(&data)];
    args.extend_from_slice(extra);
    ok(&args);
    data
}

#[test]
fn train_resume_eval_and_drape() {
    let data = dataset();
    let tmp = tempfile::tempdir().unwrap();
    let local = tmp.path().join("local");
    let args = |epochs: &str| {
        owned(&train_args(
            data,
            "local",
            epochs,
            &local,
            &["--batch", "2"],
        ))
    };
    let mut first = args("2");
    first.push("--mirror".into());
    let log = ok(&as_str(&first));
    assert!(
        log.contains("epoch 2")
            && log.contains("val E_dist")
            && log.contains("mirroring every other training sample"),
        "{log}"
    );
    let metrics = local.join("metrics.csv");
    let rows = |p: &Path| std::fs::read_to_string(p).unwrap().lines().count();
    assert_eq!(rows(&metrics), 3, "header and two epochs");
    for f in ["best.garnet", "last.garnet"] {
        assert!(local.join(f).is_file(), "{f}");
    }
    // Resume to three epochs with L_vertex as the mean distance: one more row.
    let mut resume = args("3");
    resume.extend(["--resume", "--vertex-power", "1", "--vertex-weight", "2"].map(String::from));
    let log = ok(&as_str(&resume));
    // The resumed run keeps mirroring without being told again.
    assert!(
        log.contains("resuming") && log.contains("mirroring every other training sample"),
        "{log}"
    );
    assert!(
        log.contains("L_vertex from here on: weight 2, distances to the power 1 (the checkpoint's: weight 1, power 2)"),
        "{log}"
    );
    assert_eq!(rows(&metrics), 4);
    let powers: Vec<String> = std::fs::read_to_string(&metrics)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().to_string())
        .collect();
    assert_eq!(powers, ["2", "2", "1"]);
    let resumed = model::load_checkpoint(&local.join("last.garnet")).unwrap();
    assert_eq!((resumed.loss.vertex, resumed.loss.vertex_power), (2.0, 1.0));

    // Naive with clipped gradients and a cosine schedule over two epochs.
    let naive = tmp.path().join("naive");
    let log = ok(&train_args(
        data,
        "naive",
        "2",
        &naive,
        &["--grad-clip", "100", "--cosine-to", "1e-4"],
    ));
    assert!(
        log.contains("cosine to 0.0001 at epoch 2, from epoch 0")
            && log.contains("gradients clipped to norm 100")
            && log.contains("lr 1.00e-3")
            && log.contains("lr 5.50e-4"),
        "{log}"
    );
    let csv = std::fs::read_to_string(naive.join("metrics.csv")).unwrap();
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .ends_with(",train_grad_norm,vertex_power"));

    // The same cosine step by step: a single epoch already ends below its start rate.
    let per_step = tmp.path().join("per-step");
    let per_step_args = ["--batch", "1", "--cosine-to", "1e-4", "--cosine-per-step"];
    let log = ok(&train_args(data, "naive", "1", &per_step, &per_step_args));
    assert!(
        log.contains("cosine to 0.0001 at epoch 1, from epoch 0, step by step"),
        "{log}"
    );
    let csv = std::fs::read_to_string(per_step.join("metrics.csv")).unwrap();
    let lr: f64 = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(2)
        .unwrap()
        .parse()
        .unwrap();
    assert!(lr > 1e-4 && lr < 1e-3, "{csv}");
    let err = fails(&train_args(
        data,
        "naive",
        "1",
        &per_step,
        &["--cosine-per-step"],
    ));
    assert!(err.contains("--cosine-to"), "{err}");

    // Table 1 / Table 2 / precision curves.
    let eval = tmp.path().join("eval");
    let best = local.join("best.garnet");
    let report = ok(&[
        "eval",
        "--data",
        s(data),
        "--split",
        "test",
        "--model",
        s(&best),
        s(&naive.join("best.garnet")),
        "--out",
        s(&eval),
        "--push-out",
        "--save-drapes",
        s(&eval.join("drapes")),
    ]);
    for row in [
        "GarNet-local",
        "| tshirt | GarNet-local, pushed out |",
        "GarNet-naive",
        "| tshirt | DQS |",
        "simulator / network",
        "## E_dist by motion",
        "| tshirt | GarNet-local | procedural walk |",
    ] {
        assert!(report.contains(row), "{row} missing:\n{report}");
    }
    for f in [
        "results.md",
        "results.json",
        "precision_dist.png",
        "precision_norm.png",
    ] {
        assert!(eval.join(f).is_file(), "{f}");
    }
    check_saved_drapes(&eval.join("drapes").join("local-best"), &report);

    // Export: the network without the optimiser state, and its model card.
    let shipped = tmp.path().join("models").join("tshirt-local.garnet");
    let export = |out: &Path, flags: &[&str]| {
        let mut args = vec![
            "export",
            "--model",
            s(&best),
            "--data",
            s(data),
            "--out",
            s(out),
        ];
        args.extend_from_slice(flags);
        garnet(&args)
    };
    assert!(export(&shipped, &["--max-strain=1000"]).status.success());
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert!(
        size(&shipped) * 2 < size(&best),
        "{} vs {} bytes",
        size(&shipped),
        size(&best)
    );
    let card = std::fs::read_to_string(shipped.with_extension("md")).unwrap();
    for needle in [
        "GarNet-local for the tshirt",
        "garnet train --data",
        "--variant local",
        "| GarNet-local |",
        "| DQS warp (the input M) |",
        "best validation E_dist",
        "every other training sample mirrored left-right",
        "learning rate by epoch (from the run's metrics.csv): 1.0e-3 (epochs 1-3)",
        // The best checkpoint is epoch 2's, before the resumed run changed the loss.
        "- loss: L_vertex (mean of squared distances) + 1 L_pen",
        "L_vertex averaged, by epoch (from the run's metrics.csv): squared distances \
         (epochs 1-2), distances (epoch 3)",
        // The drapes it was trained on (from the run's log), those the export's filter
        // passes, and its metrics on the test drapes that pass it.
        "2 training samples of this garment, 2 of them drapes with strain p99 at most 1000%",
        "samples trained on per epoch (from the run's metrics.csv): 2 (epochs 1-3)",
        "| GarNet-local, drapes with strain p99 at most 1000% |",
        "| DQS warp, drapes with strain p99 at most 1000% |",
        "--max-strain 1000`.",
    ] {
        assert!(card.contains(needle), "{needle} missing:\n{card}");
    }
    // A bad filter is refused before anything is written.
    let bad_out = tmp.path().join("bad.garnet");
    let refused = export(&bad_out, &["--max-slide=-1"]);
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && err.contains("--max-slide"),
        "{err}"
    );
    assert!(!bad_out.exists());
    let refused = export(&tmp.path().join("model.bin"), &["--at-rest"]);
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("model.bin") && err.contains(".garnet"),
        "{err}"
    );
    // Trained on another dataset of the same bodies (as standard-x3 is of standard; here a
    // folder with this one's manifest, all export reads of it): the card counts that
    // dataset's training drapes and reports the metrics on --data's test split.
    let twin_data = tmp.path().join("twin-data");
    std::fs::create_dir_all(&twin_data).unwrap();
    let manifest = std::fs::read_to_string(data.join("manifest.json")).unwrap();
    std::fs::write(twin_data.join("manifest.json"), &manifest).unwrap();
    let export_twin =
        |out: &Path, split: &str| export(out, &["--train-data", s(&twin_data), "--split", split]);
    let twin = tmp.path().join("twin.garnet");
    assert!(export_twin(&twin, "test").status.success());
    let card = std::fs::read_to_string(twin.with_extension("md")).unwrap();
    for needle in [
        format!("(`{}`, spec", twin_data.display()),
        format!("split of 'model-cli', `{}`", data.display()),
        format!("--train-data {} --out", twin_data.display()),
    ] {
        assert!(card.contains(&needle), "{needle} missing:\n{card}");
    }
    // Figures on bodies it trained on, or a dataset of other bodies, are refused before
    // anything is written.
    let refused = export_twin(&bad_out, "train");
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        err.contains("training bodies are in the 'train' split"),
        "{err}"
    );
    std::fs::write(
        twin_data.join("manifest.json"),
        manifest.replacen("\"seed\": 4,", "\"seed\": 5,", 1),
    )
    .unwrap();
    let refused = export_twin(&bad_out, "test");
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("draw their bodies differently"), "{err}");
    assert!(!bad_out.exists());

    // Draping needs only the (exported) model file.
    let out = tmp.path().join("draped.obj");
    let png = tmp.path().join("draped.png");
    let drape = |out: &Path, flags: &[&str]| {
        let mut args = vec![
            "drape",
            "--model",
            s(&shipped),
            "--random-shape",
            "2",
            "--pose-procedural",
            "3",
            "--out",
            s(out),
        ];
        args.extend_from_slice(flags);
        ok(&args)
    };
    let body_out = tmp.path().join("body.obj");
    let log = drape(&out, &["--png", s(&png), "--body-out", s(&body_out)]);
    assert!(
        log.contains("network") && log.contains("pushed out of the body"),
        "{log}"
    );
    // By default the vertices the network leaves inside the body are pushed out; --raw
    // writes the network's output as it is.
    let raw_out = tmp.path().join("raw.obj");
    let raw_log = drape(&raw_out, &["--raw"]);
    assert!(!raw_log.contains("pushed out"), "{raw_log}");
    let body = geom::Bvh::from_mesh(&geom::io::read_mesh(&body_out).unwrap()).unwrap();
    let inside = |p: &Path| {
        let v = geom::io::read_mesh(p).unwrap().vertices;
        body.contains_points(&v).iter().filter(|&&i| i).count()
    };
    let (pushed, raw) = (inside(&out), inside(&raw_out));
    assert!(
        raw > 0 && pushed < raw,
        "inside the body: {pushed} pushed out, {raw} raw"
    );
    let draped = geom::io::read_mesh(&out).unwrap();
    let template_vertices = std::fs::read_dir(data.join("templates"))
        .unwrap()
        .map(|e| garment::GarmentTemplate::load(&e.unwrap().path()).unwrap())
        .next()
        .unwrap()
        .mesh
        .vertices
        .len();
    assert_eq!(draped.vertices.len(), template_vertices);
    assert!(png.is_file());
}

#[test]
fn train_and_eval_leave_out_drapes_not_at_rest_or_overstretched() {
    let data = dataset();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("filtered");
    let train = |extra: &[&str]| owned(&train_args(data, "naive", "1", &out, extra));
    let log = ok(&as_str(&train(&["--max-strain", "1000"])));
    assert!(
        log.contains("training on drapes with strain p99 at most 1000% only: left out 0"),
        "{log}"
    );
    // Evaluation says which drapes it used.
    let model = out.join("last.garnet");
    let eval = |extra: &[&str]| {
        let mut a = vec!["eval", "--data", s(data), "--model", s(&model), "--out"];
        a.push(s(tmp.path()));
        a.extend_from_slice(extra);
        owned(&a)
    };
    ok(&as_str(&eval(&["--max-strain", "1000"])));
    let md = std::fs::read_to_string(tmp.path().join("results.md")).unwrap();
    assert!(
        md.contains("Only drapes with strain p99 at most 1000%") && md.contains("| tshirt |"),
        "{md}"
    );
    let err = fails(&as_str(&eval(&["--at-rest"])));
    assert!(
        err.contains("no 'tshirt' sample of split 'test' is one of the drapes at rest"),
        "{err}"
    );
    // Five settling steps: no drape of this dataset is at rest, and every one is strained.
    let err = fails(&as_str(&train(&["--at-rest"])));
    assert!(
        err.contains("none of the 2 samples") && err.contains("--at-rest"),
        "{err}"
    );
    let err = fails(&as_str(&train(&["--max-strain", "0"])));
    assert!(err.contains("strain p99 at most 0%"), "{err}");
    let err = fails(&as_str(&train(&["--max-strain=-1"])));
    assert!(err.contains("--max-strain"), "{err}");
    // Every garment settles onto the body a little: none slid 0 cm, all under 10 m.
    let err = fails(&as_str(&train(&["--max-slide", "0"])));
    assert!(
        err.contains("whose garment slid at most 0 cm") && err.contains("--max-slide"),
        "{err}"
    );
    ok(&as_str(&eval(&["--max-slide", "1000"])));
    let err = fails(&as_str(&train(&["--max-slide=-1"])));
    assert!(err.contains("--max-slide"), "{err}");
    let err = fails(&as_str(&train(&["--vertex-power", "3"])));
    assert!(
        err.contains("the power of L_vertex's distances must be in [1, 2], got 3"),
        "{err}"
    );
}

/// Regression (session 26): a run on a dataset still being generated kept comparing its
/// best validation E_dist with a figure measured before the validation split had grown.
#[test]
fn best_starts_afresh_when_the_validation_split_grows() {
    let tmp = tempfile::tempdir().unwrap();
    // One sample a shard: shards 0-1 train, 2-3 test, 4-5 validation.
    let spec = SPEC.replace("shard_size = 2", "shard_size = 1");
    let generate = |shards: &str| generate_in(tmp.path(), &spec, &["--shard", shards]);
    let data = generate("0-4");
    let run = tmp.path().join("run");
    let log = ok(&train_args(&data, "naive", "1", &run, &[]));
    assert!(log.contains("(1 validation)"), "{log}");
    generate("5");
    let log = ok(&train_args(&data, "naive", "2", &run, &["--resume"]));
    assert!(
        log.contains("(2 validation)")
            && log.contains("was measured on another validation set")
            && log.contains("validates on 'model-cli:tshirt:2'"),
        "{log}"
    );
    // Resumed again on the same drapes, it keeps its best.
    let log = ok(&train_args(&data, "naive", "3", &run, &["--resume"]));
    assert!(!log.contains("another validation set"), "{log}");
}

#[test]
fn drape_and_eval_refuse_what_does_not_fit() {
    let data = dataset();
    let tmp = tempfile::tempdir().unwrap();
    // A garment template is not a model.
    let template = std::fs::read_dir(data.join("templates"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let err = fails(&[
        "drape",
        "--model",
        s(&template),
        "--out",
        s(&tmp.path().join("x.obj")),
    ]);
    assert!(err.contains(s(&template)), "{err}");
    // No such garment in the dataset.
    let err = fails(&[
        "train",
        "--data",
        s(data),
        "--garment",
        "jeans",
        "--epochs",
        "1",
    ]);
    assert!(err.contains("jeans") && err.contains("tshirt"), "{err}");
    // A missing model file.
    let err = fails(&["eval", "--data", s(data), "--model", "nope.garnet"]);
    assert!(err.contains("nope.garnet"), "{err}");
    // Bodies posed another way than the network learned from: a network that learned from
    // DQS bodies on this dataset (LBS bodies), or draped in one run with one trained on it.
    let naive = tmp.path().join("naive");
    ok(&train_args(data, "naive", "1", &naive, &[]));
    let trained = naive.join("best.garnet");
    let dqs = tmp.path().join("dqs-naive.garnet");
    let ck = model::load_checkpoint(&trained).unwrap();
    let setup = ck.setup.clone().with_body_skinning("dqs").unwrap();
    let network = ck.model(&burn::prelude::Device::flex()).unwrap();
    model::save_checkpoint(&dqs, &network, None, &setup, &ck.loss, &ck.state).unwrap();
    let err = fails(&["eval", "--data", s(data), "--model", s(&dqs)]);
    assert!(
        err.contains("dqs-naive.garnet")
            && err.contains("posed with dqs")
            && err.contains("with lbs"),
        "{err}"
    );
    let err = fails(&[
        "drape",
        "--model",
        s(&trained),
        "--model",
        s(&dqs),
        "--out",
        s(&tmp.path().join("x.obj")),
    ]);
    assert!(err.contains("separate runs"), "{err}");
    assert!(!tmp.path().join("x-tshirt.obj").exists());
}

/// `eval --save-drapes`: each row of `samples.csv` has its four meshes, and its errors are
/// the paper's metrics of the saved network and simulator drapes; `report` is Table 1's
/// markdown, whose GarNet-local E_dist is their mean.
fn check_saved_drapes(dir: &Path, report: &str) {
    let csv = std::fs::read_to_string(dir.join("samples.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("index,pose,e_dist_cm,e_norm_deg,dqs_e_dist_cm")
    );
    let mut dists = Vec::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let mesh = |what: &str| {
            geom::io::read_mesh(dir.join(format!("{:06}-{what}.ply", f[0].parse::<u64>().unwrap())))
                .unwrap()
        };
        let (net, sim, dqs) = (mesh("net"), mesh("sim"), mesh("dqs"));
        assert_eq!(mesh("body").faces.len(), 26756);
        let e = geom::metrics::mesh_errors(&sim.vertices, &net.vertices, &sim.faces).unwrap();
        let d = geom::metrics::mesh_errors(&sim.vertices, &dqs.vertices, &sim.faces).unwrap();
        let col = |i: usize| f[i].parse::<f32>().unwrap();
        assert!((col(2) - e.e_dist_cm).abs() < 1e-3, "{line}: {e:?}");
        assert!((col(3) - e.e_norm_deg).abs() < 1e-2, "{line}: {e:?}");
        assert!((col(4) - d.e_dist_cm).abs() < 1e-3, "{line}: {d:?}");
        assert!(f[1].contains("walk"), "{line}");
        dists.push(col(2));
    }
    assert_eq!(dists.len(), 2, "{csv}");
    let mean = dists.iter().sum::<f32>() / 2.0;
    let table: f32 = report
        .lines()
        .find_map(|l| l.strip_prefix("| tshirt | GarNet-local | 2 | "))
        .and_then(|rest| rest.split(" |").next())
        .unwrap_or_else(|| panic!("no GarNet-local row of 2 samples:\n{report}"))
        .parse()
        .unwrap();
    assert!((table - mean).abs() < 2e-3, "{table} against {mean}");
}

#[test]
fn train_takes_the_network_widths_from_a_config_file() {
    let data = dataset();
    let tmp = tempfile::tempdir().unwrap();
    // The run's header: "training GarNet-naive[ +extensions] (N parameters) on ...".
    let params = |log: &str| -> usize {
        let after = log
            .split("training GarNet-naive")
            .nth(1)
            .expect("the run's header");
        let count = after.split('(').nth(1).expect("a parameter count");
        count.split(' ').next().unwrap().parse().unwrap()
    };
    let run = |name: &str, extra: &[&str]| {
        let out = tmp.path().join(name);
        let mut a = train_args(data, "naive", "1", &out, extra);
        a.extend_from_slice(&["--max-samples", "2"]);
        owned(&a)
    };
    let default = params(&ok(&as_str(&run("default", &[]))));
    let config = tmp.path().join("narrow.json");
    std::fs::write(
        &config,
        r#"{"fusion": [16, 8], "variant": "Local", "body_contact": true, "rest_input": true}"#,
    )
    .unwrap();
    let log = ok(&as_str(&run("narrow", &["--config", s(&config)])));
    // The file's fusion widths and extra inputs, the command line's variant: fewer
    // parameters than the default Naive, still a Naive network, named with its extensions.
    assert!(
        log.contains("training GarNet-naive +contact +rest ("),
        "{log}"
    );
    assert!(params(&log) < default, "{log}");
    let naive = tmp.path().join("narrow/best.garnet");
    ok(&[
        "eval",
        "--data",
        s(data),
        "--model",
        s(&naive),
        "--max-samples",
        "1",
        "--out",
        s(&tmp.path().join("eval")),
    ]);
    let table = std::fs::read_to_string(tmp.path().join("eval/results.md")).unwrap();
    assert!(table.contains("| GarNet-naive +contact +rest |"), "{table}");
    // The model carries the body's faces, so a drape computes the contact features itself.
    let out = ok(&[
        "drape",
        "--model",
        s(&naive),
        "--random-shape",
        "2",
        "--pose-procedural",
        "3",
        "--out",
        s(&tmp.path().join("d.glb")),
    ]);
    assert!(out.contains("GarNet-naive +contact +rest"), "{out}");
    let draped = geom::io::read_mesh(tmp.path().join("d.glb")).unwrap();
    assert!(draped.vertices.iter().all(|v| v.is_finite()));
    // An unknown field or a wrong type names the file and the field.
    std::fs::write(&config, r#"{"fusion_widths": [16]}"#).unwrap();
    let err = fails(&as_str(&run("bad", &["--config", s(&config)])));
    assert!(
        err.contains("narrow.json") && err.contains("fusion_widths") && err.contains("fusion"),
        "{err}"
    );
    std::fs::write(&config, r#"{"fusion": 16}"#).unwrap();
    let err = fails(&as_str(&run("bad", &["--config", s(&config)])));
    assert!(err.contains("narrow.json") && err.contains("type"), "{err}");
    std::fs::write(&config, r#"{"fusion": []}"#).unwrap();
    let err = fails(&as_str(&run("bad", &["--config", s(&config)])));
    assert!(
        err.contains("narrow.json") && err.contains("fusion"),
        "{err}"
    );
}

/// `garnet average` of two epochs' checkpoints kept by `train --keep-epochs`: a checkpoint
/// that exports with a card naming the averaged epochs; checkpoints of another variant are
/// refused.
#[test]
fn average_writes_a_checkpoint_that_exports() {
    let data = dataset();
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("naive");
    ok(&train_args(data, "naive", "2", &run, &["--keep-epochs"]));
    let snapshots: Vec<PathBuf> = (1..=2)
        .map(|e| run.join(format!("epoch-{e}.garnet")))
        .collect();
    for (e, snap) in snapshots.iter().enumerate() {
        assert_eq!(model::load_checkpoint(snap).unwrap().state.epoch, e + 1);
    }
    let mean = tmp.path().join("mean.garnet");
    let log = ok(&[
        "average",
        "--models",
        s(&snapshots[0]),
        s(&snapshots[1]),
        "--out",
        s(&mean),
    ]);
    assert!(log.contains("the mean of 2 networks"), "{log}");
    // Three networks of one variant: each row names its file (Tables 1 and 2 and the one
    // motion of the split); the DQS row stays one.
    let eval = tmp.path().join("eval");
    let mut args = vec!["eval", "--data", s(data), "--model"];
    args.extend([s(&snapshots[0]), s(&snapshots[1]), s(&mean)]);
    args.extend(["--out", s(&eval)]);
    let md = ok(&args);
    for model in [&snapshots[0], &snapshots[1], &mean] {
        let row = format!("| tshirt | GarNet-naive ({}) |", model.display());
        assert_eq!(md.matches(&row).count(), 3, "{row}\n{md}");
    }
    assert_eq!(md.matches("| tshirt | DQS |").count(), 1, "{md}");
    // The export's filter only adds the card's rows on the test drapes it passes: the
    // mean (no metrics.csv beside it) trained on every drape, as its record says (a
    // regression: the card said it trained only on the drapes the export's filter passes).
    let card = exported_card(
        &mean,
        data,
        &tmp.path().join("models").join("tshirt-naive.garnet"),
        &["--max-strain", "1000"],
    );
    for needle in [
        "- weights: the mean of the networks of epochs 1-2 (`garnet average`)",
        "; then garnet average --models",
        "2 training samples of this garment, trained on every one of them; validation",
        "- progress: the networks averaged are of epochs 1-2; the file records the last one's \
         progress: 2 epochs",
        "| GarNet-naive, drapes with strain p99 at most 1000% |",
    ] {
        assert!(card.contains(needle), "{needle} missing:\n{card}");
    }

    let local = one_epoch_checkpoint(data, "local", &tmp.path().join("local"));
    let err = fails(&[
        "average",
        "--models",
        s(&snapshots[0]),
        s(&local),
        "--out",
        s(&mean),
    ]);
    assert!(
        err.contains("not averageable") && err.contains("last.garnet"),
        "{err}"
    );
    let err = fails(&["average", "--models", s(&snapshots[0]), "--out", s(&mean)]);
    assert!(err.contains("--models"), "{err}");

    // Weights: a weighted combination (here an extrapolation) that the card spells out;
    // weights that do not sum to 1 are refused and write nothing.
    let combined = tmp.path().join("combined.garnet");
    let pair = [s(&snapshots[0]), s(&snapshots[1])];
    let log = ok(&[
        "average",
        "--models",
        pair[0],
        pair[1],
        "--weights",
        "-0.5,1.5",
        "--out",
        s(&combined),
    ]);
    assert!(
        log.contains("the combination with weights [-0.5, 1.5]"),
        "{log}"
    );
    let card = exported_card(
        &combined,
        data,
        &tmp.path().join("models").join("tshirt-naive-x.garnet"),
        &[],
    );
    assert!(
        card.contains("the combination -0.5 x epoch 1 + 1.5 x epoch 2 of networks"),
        "{card}"
    );
    let bad = tmp.path().join("bad.garnet");
    let err = fails(&[
        "average",
        "--models",
        pair[0],
        pair[1],
        "--weights",
        "0.5,0.6",
        "--out",
        s(&bad),
    ]);
    assert!(err.contains("sum to"), "{err}");
    assert!(!bad.exists());
}

/// Exports `model` as `out` with `data`'s test metrics and the drape filter flags `filter`,
/// and returns the model card written beside it.
fn exported_card(model: &Path, data: &Path, out: &Path, filter: &[&str]) -> String {
    let mut args = vec![
        "export",
        "--model",
        s(model),
        "--data",
        s(data),
        "--out",
        s(out),
    ];
    args.extend_from_slice(filter);
    ok(&args);
    std::fs::read_to_string(out.with_extension("md")).unwrap()
}

/// `garnet grow`: the grown and the widened checkpoints evaluate as their parent, and `garnet
/// train --resume` trains the grown one on; narrowing and Naive's convolutions are refused.
#[test]
fn grow_keeps_the_drapes_and_trains_on() {
    let data = dataset();
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("global");
    let grown = one_epoch_checkpoint(data, "global", &run);
    let parent = tmp.path().join("parent.garnet");
    std::fs::copy(&grown, &parent).unwrap();
    let log = ok(&[
        "grow",
        "--model",
        s(&parent),
        "--extra-blocks",
        "2",
        "--out",
        s(&grown),
    ]);
    assert!(log.contains("with 2 more blocks"), "{log}");
    let e_dist = |model: &Path| {
        let out = tmp.path().join("eval");
        let report = ok(&[
            "eval",
            "--data",
            s(data),
            "--split",
            "test",
            "--model",
            s(model),
            "--out",
            s(&out),
        ]);
        let row = report
            .lines()
            .find(|l| l.starts_with("| tshirt | GarNet-global"))
            .unwrap_or_else(|| panic!("no GarNet row:\n{report}"))
            .to_string();
        row.split('|').nth(4).unwrap().trim().to_string()
    };
    assert_eq!(e_dist(&parent), e_dist(&grown));
    // Wider convolutions and fusion drape as before too (up to the rounding of longer sums).
    let wide = tmp.path().join("wide.garnet");
    let narrow = tmp.path().join("narrow.garnet");
    let grow_wide = |conv: &'static str, out: &Path| {
        let out = s(out).to_string();
        let args = [
            "grow",
            "--model",
            s(&parent),
            "--conv-width",
            conv,
            "--fusion",
        ];
        let mut v = owned(&args);
        v.extend(["160,64,32".to_string(), "--out".to_string(), out]);
        v
    };
    let args = grow_wide("48", &wide);
    let log = ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        log.contains("convolutions 48 features wide, fusion widths [160, 64, 32]"),
        "{log}"
    );
    assert_eq!(e_dist(&parent), e_dist(&wide));
    let args = grow_wide("16", &narrow);
    let err = fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(err.contains("can only be widened"), "{err}");
    let log = ok(&train_args(data, "global", "2", &run, &["--resume"]));
    assert!(
        log.contains("GarNet-global +2 blocks") && log.contains("epoch 2"),
        "{log}"
    );

    let naive = one_epoch_checkpoint(data, "naive", &tmp.path().join("naive"));
    let err = fails(&[
        "grow",
        "--model",
        s(&naive),
        "--extra-blocks",
        "1",
        "--out",
        s(&tmp.path().join("x.garnet")),
    ]);
    assert!(err.contains("Naive has no mesh convolutions"), "{err}");
}

/// A run stopped inside an epoch (here by a damaged shard at its second batch) resumes from
/// `mid-epoch.garnet` at that batch once the shard is whole again, and its epoch's row of
/// `metrics.csv` is that of a run that never stopped; with another shuffle it refuses.
#[test]
fn train_resumes_an_epoch_stopped_inside() {
    let tmp = tempfile::tempdir().unwrap();
    let one_a_shard = SPEC.replace("shard_size = 2", "shard_size = 1");
    let data = generate_in(tmp.path(), &one_a_shard, &["--jobs", "2"]);
    let set = dataset::Dataset::open(&data).unwrap();
    let train = set.select(Some("train"), Some("tshirt")).unwrap();
    let order = Order::Shuffled { seed: 0, epoch: 0 };
    let second = dataset::batches::epoch_order(&set, &train, order)[1];
    let shard = set.manifest().sample(second).unwrap().shard;
    let shard = data.join(format!("shards/shard-{shard:06}.safetensors"));
    let whole_bytes = std::fs::read(&shard).unwrap();

    let run = |out: &Path, extra: &[&str]| {
        let mut a = train_args(&data, "local", "1", out, &["--batch", "1"]);
        a.extend_from_slice(extra);
        owned(&a)
    };
    let whole = tmp.path().join("whole");
    ok(&as_str(&run(&whole, &[])));

    let stopped = tmp.path().join("stopped");
    let mut damaged = whole_bytes.clone();
    let n = damaged.len();
    damaged[n - 50] ^= 0x40;
    std::fs::write(&shard, &damaged).unwrap();
    let err = fails(&as_str(&run(&stopped, &["--checkpoint-minutes", "1e-6"])));
    assert!(err.contains("checksum"), "{err}");
    let mid = stopped.join("mid-epoch.garnet");
    assert!(mid.is_file() && !stopped.join("last.garnet").exists());
    std::fs::write(&shard, &whole_bytes).unwrap();

    let err = fails(&as_str(&run(&stopped, &["--resume", "--seed", "5"])));
    assert!(
        err.contains("inside epoch 1 after 1 batches of another training set")
            && err.contains("seed 0")
            && err.contains("seed 5"),
        "{err}"
    );
    let log = ok(&as_str(&run(&stopped, &["--resume"])));
    assert!(log.contains("inside epoch 1, after 1 batches"), "{log}");
    assert!(!mid.exists() && stopped.join("last.garnet").is_file());
    // The row without its wall time (the fourth column).
    let row = |dir: &Path| -> Vec<String> {
        let csv = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
        let last = csv.lines().last().unwrap().to_string();
        let mut cells: Vec<String> = last.split(',').map(String::from).collect();
        cells.remove(3);
        cells
    };
    assert_eq!(row(&stopped), row(&whole));

    // A run started afresh in the folder removes a stopped epoch left there, so that a later
    // --resume cannot go back to it.
    std::fs::copy(stopped.join("last.garnet"), &mid).unwrap();
    let log = ok(&as_str(&run(&stopped, &[])));
    assert!(log.contains("removed") && !mid.exists(), "{log}");
}

/// `garnet train` of `variant` on `data`'s T-shirts for one epoch into `run`: its
/// `last.garnet`.
fn one_epoch_checkpoint(data: &Path, variant: &str, run: &Path) -> PathBuf {
    ok(&train_args(data, variant, "1", run, &[]));
    run.join("last.garnet")
}

/// `garnet train` on `data`'s T-shirts with `variant` for `epochs` into `out`, then `extra`.
fn train_args<'a>(
    data: &'a Path,
    variant: &'a str,
    epochs: &'a str,
    out: &'a Path,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut a = vec![
        "train",
        "--data",
        s(data),
        "--garment",
        "tshirt",
        "--variant",
        variant,
        "--epochs",
        epochs,
        "--out",
        s(out),
    ];
    a.extend_from_slice(extra);
    a
}

fn owned(v: &[&str]) -> Vec<String> {
    v.iter().map(|a| a.to_string()).collect()
}

fn as_str(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// `garnet bench model` on a 300-vertex synthetic garment and the 5 cm T-shirt's drape, one
/// run each, then `extra`.
fn small_bench_model(extra: &[&str]) -> Vec<String> {
    let mut a = owned(&["bench", "model", "--runs", "1", "--sizes", "300"]);
    a.extend(owned(&["--edge", "0.05", "--simulator"]));
    a.extend(owned(extra));
    a
}

#[test]
fn bench_model_reports_every_variant_against_the_dqs_warp() {
    let out = ok(&as_str(&small_bench_model(&[])));
    assert!(out.contains("DQS warp (reference)"), "{out}");
    // A drape row and a training-step row each; GarNet-Local, with and without the
    // body-contact features, also on the simulator's drape, alone and with the push-out.
    for (variant, count) in [("| local |", 6), ("| global |", 2), ("| naive |", 2)] {
        let rows = out.lines().filter(|l| l.contains(variant)).count();
        assert_eq!(rows, count, "{variant}\n{out}");
    }
    assert!(out.contains("same drape: simulator to rest"), "{out}");
    for name in ["GarNet-local", "GarNet-local +contact"] {
        assert!(
            out.contains(&format!("same drape: {name} with the push-out")),
            "{out}"
        );
    }
    assert!(out.contains("with the push-out), "), "{out}");
    assert!(out.contains("faster than the simulator"), "{out}");
}

/// `--config` times networks of a file's widths and inputs: the same-drape rows compare
/// the paper's GarNet-Local with the file's (here deeper, with the body-contact and
/// template-vertex inputs), and the parameter counts are the file's.
#[test]
fn bench_model_times_the_networks_of_a_config_file() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("net.json");
    std::fs::write(
        &file,
        r#"{"convs_per_block": 2, "body_contact": true, "rest_input": true}"#,
    )
    .unwrap();
    let args = |config: &Path| small_bench_model(&["--config", s(config)]);
    let out = ok(&as_str(&args(&file)));
    assert!(out.contains("net.json"), "{out}");
    for name in ["GarNet-local", "GarNet-local +contact +rest"] {
        assert!(
            out.contains(&format!("same drape: {name} with the push-out")),
            "{out}"
        );
    }
    // Twice the mesh convolutions: more parameters than the defaults in the Local and
    // Global rows; Naive has none, and gains only the template vertices' 3 inputs to its
    // first 64-wide layer (the synthetic rows leave the body contact out).
    let params = |out: &str, variant: &str| -> usize {
        let row = out
            .lines()
            .find(|l| l.starts_with("| drape (forward") && l.contains(variant))
            .unwrap_or_else(|| panic!("no {variant} drape row:\n{out}"));
        row.split('|').nth(4).unwrap().trim().parse().unwrap()
    };
    let defaults = ok(&["bench", "model", "--runs", "1", "--sizes", "300"]);
    assert!(params(&out, "| local |") > params(&defaults, "| local |"));
    assert!(params(&out, "| global |") > params(&defaults, "| global |"));
    assert_eq!(
        params(&out, "| naive |"),
        params(&defaults, "| naive |") + 3 * 64
    );
    let bad = tmp.path().join("bad.json");
    std::fs::write(&bad, r#"{"conv_widht": 64}"#).unwrap();
    let err = fails(&as_str(&args(&bad)));
    assert!(
        err.contains("bad.json") && err.contains("conv_widht"),
        "{err}"
    );
}

/// A GPU backend this build lacks is refused before any work, naming the cargo feature.
#[test]
fn bench_model_on_a_backend_not_built_in_says_how_to_build_it() {
    let err = fails(&["bench", "model", "--device", "vulkan", "--runs", "1"]);
    assert!(err.contains("--features vulkan"), "{err}");
}

/// The main job (no command, run from any folder): the three shipped models drape a random
/// body in a random pose; meshes and a picture land in `out/` of the working directory.
#[test]
fn main_job_drapes_the_three_shipped_models() {
    let tmp = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_garnet"))
        .current_dir(tmp.path())
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "main job failed:\n{log}");
    for garment in ["tshirt", "sweater", "jeans"] {
        assert!(log.contains(&format!("{garment} (")), "{garment}:\n{log}");
        let mesh = tmp.path().join(format!("out/draped-{garment}.glb"));
        assert!(geom::io::read_mesh(&mesh).unwrap().vertices.len() > 100);
        let png = tmp.path().join(format!("out/drape-{garment}.png"));
        assert!(png.is_file(), "{}", png.display());
    }
    assert!(tmp.path().join("out/body.glb").is_file());
}
