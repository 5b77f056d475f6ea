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
format = 2
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
    // The export below adds the metrics on the drapes the recipe's filter keeps.
    let local_recipe = recipe(
        tmp.path(),
        "local",
        data,
        "local",
        2,
        "batch = 2",
        "[drapes]\nmax_strain_pct = 1000.0\n",
    );
    let log = ok_v(train(&local_recipe, &local, &[]));
    assert!(
        log.contains("epoch 2")
            && log.contains("val E_dist")
            && log.contains("by garnet train --recipe"),
        "{log}"
    );
    let metrics = local.join("metrics.csv");
    let rows = |p: &Path| std::fs::read_to_string(p).unwrap().lines().count();
    assert_eq!(rows(&metrics), 3, "header and two epochs");
    for f in ["best.garnet", "last.garnet"] {
        assert!(local.join(f).is_file(), "{f}");
    }
    // Resumed to three epochs by the same recipe: one more row; the checkpoint records the
    // recipe as run and its command.
    let log = ok_v(train(&local_recipe, &local, &["--resume", "--epochs", "3"]));
    assert!(log.contains("resuming"), "{log}");
    assert_eq!(rows(&metrics), 4);
    let resumed = model::load_checkpoint(&local.join("last.garnet")).unwrap();
    let record = resumed.recipe.expect("the recipe");
    assert_eq!(
        (record.recipe.schedule.epochs, record.recipe.schedule.batch),
        (3, 2)
    );
    assert!(
        record.command.ends_with("local.toml --epochs 3"),
        "{}",
        record.command
    );
    // Another recipe cannot resume the run.
    let other = recipe(tmp.path(), "other", data, "local", 4, "batch = 1", "");
    let err = fails_v(train(&other, &local, &["--resume"]));
    assert!(err.contains("trained by another recipe"), "{err}");

    // Naive with clipped gradients and a cosine schedule over two epochs.
    let naive = tmp.path().join("naive");
    let naive_recipe = recipe(
        tmp.path(),
        "naive",
        data,
        "naive",
        2,
        "grad_clip = 100.0\ncosine_to = 1e-4",
        "",
    );
    ok_v(train(&naive_recipe, &naive, &[]));
    let csv = std::fs::read_to_string(naive.join("metrics.csv")).unwrap();
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .ends_with(",train_grad_norm,train_cpu_s,train_curvature,val_curvature"));
    let lr = |csv: &str, row: usize| -> f64 {
        let line = csv.lines().nth(row).unwrap();
        line.split(',').nth(2).unwrap().parse().unwrap()
    };
    assert_eq!((lr(&csv, 1), lr(&csv, 2)), (1e-3, 5.5e-4), "{csv}");
    let ck = model::load_checkpoint(&naive.join("last.garnet")).unwrap();
    assert_eq!(ck.state.max_grad_norm, Some(100.0));

    // The same cosine step by step, after a warm-up epoch: the second epoch already ends
    // below its start rate.
    let per_step = tmp.path().join("per-step");
    let per_step_recipe = recipe(
        tmp.path(),
        "per-step",
        data,
        "naive",
        2,
        "batch = 1\nwarmup_epochs = 1\ncosine_to = 1e-4\nper_step = true",
        "",
    );
    ok_v(train(&per_step_recipe, &per_step, &[]));
    let csv = std::fs::read_to_string(per_step.join("metrics.csv")).unwrap();
    assert_eq!(lr(&csv, 1), 1e-3, "{csv}");
    assert!(lr(&csv, 2) > 1e-4 && lr(&csv, 2) < 1e-3, "{csv}");
    // A compute budget from the command line: 0.01 CPU minutes end a 1000-epoch recipe
    // long before its last epoch.
    let budget = tmp.path().join("budget");
    let budget_recipe = recipe(
        tmp.path(),
        "budget",
        data,
        "naive",
        1000,
        "cosine_to = 1e-4",
        "",
    );
    let log = ok_v(train(&budget_recipe, &budget, &["--minutes", "0.01"]));
    let csv = std::fs::read_to_string(budget.join("metrics.csv")).unwrap();
    let rows = csv.lines().count() - 1;
    let cpu: f64 = csv
        .lines()
        .last()
        .unwrap()
        .rsplit(',')
        .nth(2)
        .unwrap()
        .parse()
        .unwrap();
    assert!(rows >= 1 && rows < 1000 && cpu >= 0.6, "{csv}\n{log}");
    assert!(log.contains("CPU min in all"), "{log}");
    let bad = recipe(tmp.path(), "bad", data, "naive", 1, "per_step = true", "");
    let err = fails_v(train(&bad, &per_step, &[]));
    assert!(
        err.contains("bad.toml") && err.contains("per_step needs cosine_to"),
        "{err}"
    );

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
        "--fitted",
        "--save-drapes",
        s(&eval.join("drapes")),
    ]);
    for row in [
        "GarNet-local",
        "| tshirt | GarNet-local, pushed out |",
        "GarNet-naive",
        "| tshirt | DQS |",
        "| tshirt | surface-anchored M |",
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
    // Rows named by the caller, and the same drape drawn by both models beside the
    // simulator's.
    let named = tmp.path().join("eval-named");
    let naive_best = naive.join("best.garnet");
    let model_args = ["--model", s(&best), s(&naive_best)];
    let mut args = vec!["eval", "--data", s(data), "--out", s(&named), "--pictures"];
    args.extend(model_args);
    args.extend(["--label", "all four terms", "no L_bend"]);
    let report = ok(&args);
    for row in [
        "| tshirt | all four terms |",
        "| tshirt | no L_bend |",
        "drapes.png",
    ] {
        assert!(report.contains(row), "{row} missing:\n{report}");
    }
    let sheet = render::Image::from_png(named.join("drapes.png")).unwrap();
    assert!(
        sheet.width > 3 * 200 && sheet.height > 400,
        "{}x{}",
        sheet.width,
        sheet.height
    );
    let mut args = vec!["eval", "--data", s(data), "--out", s(&named)];
    args.extend(model_args);
    args.extend(["--label", "only one"]);
    let err = fails(&args);
    assert!(err.contains("1 labels for 2 models"), "{err}");

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
    assert!(export(&shipped, &[]).status.success());
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
        "trained from scratch by `garnet train --recipe",
        "local.toml",
        "variant = \"local\"",
        "| GarNet-local |",
        "| DQS warp (the input M) |",
        "best validation E_dist",
        "- loss: 1 L_vertex (squared) + 1 L_pen",
        // The drapes it was trained on, and its metrics on the test drapes that pass the
        // recipe's filter.
        "2 training samples of this garment, trained on the 2 of them that are drapes with strain p99 at most 1000%",
        "| GarNet-local, drapes with strain p99 at most 1000% |",
        "| DQS warp, drapes with strain p99 at most 1000% |",
    ] {
        assert!(card.contains(needle), "{needle} missing:\n{card}");
    }
    let bad_out = tmp.path().join("bad.garnet");
    let refused = export(&tmp.path().join("model.bin"), &[]);
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("model.bin") && err.contains(".garnet"),
        "{err}"
    );
    // Trained on another dataset of the same bodies (as standard-x9-lbs is of standard-lbs; here a
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
        format!("(`{}`)", twin_data.display()),
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
    let with_drapes = |name: &str, drapes: &str| {
        let file = recipe(
            tmp.path(),
            name,
            data,
            "naive",
            1,
            "",
            &format!("[drapes]\n{drapes}\n"),
        );
        train(&file, &out, &[])
    };
    let log = ok_v(with_drapes("strain", "max_strain_pct = 1000.0"));
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
    let json = std::fs::read_to_string(tmp.path().join("results.json")).unwrap();
    assert!(
        json.contains("\"name\": \"model-cli\"") && json.contains("\"spec_sha256\""),
        "{json}"
    );
    let err = fails(&as_str(&eval(&["--at-rest"])));
    assert!(
        err.contains("no 'tshirt' sample of split 'test' is one of the drapes at rest"),
        "{err}"
    );
    // Five settling steps: no drape of this dataset is at rest, and every one is strained.
    let err = fails_v(with_drapes("rest", "at_rest = true"));
    assert!(err.contains("none of the 2 samples"), "{err}");
    let err = fails_v(with_drapes("zero", "max_strain_pct = 0.0"));
    assert!(err.contains("strain p99 at most 0%"), "{err}");
    let err = fails_v(with_drapes("negative", "max_strain_pct = -1.0"));
    assert!(
        err.contains("negative.toml") && err.contains("max_strain_pct"),
        "{err}"
    );
    // Every garment settles onto the body a little: none slid 0 cm, all under 10 m.
    let err = fails_v(with_drapes("slide", "max_slide_cm = 0.0"));
    assert!(err.contains("whose garment slid at most 0 cm"), "{err}");
    ok(&as_str(&eval(&["--max-slide", "1000"])));
    let err = fails(&as_str(&eval(&["--max-slide=-1"])));
    assert!(err.contains("--max-slide"), "{err}");
    let err = fails_v(with_drapes("unknown", "mirror = true"));
    assert!(
        err.contains("unknown.toml") && err.contains("mirror"),
        "{err}"
    );
}

/// Regression: a run on a dataset still being generated kept comparing its
/// best validation E_dist with a figure measured before the validation split had grown.
#[test]
fn best_starts_afresh_when_the_validation_split_grows() {
    let tmp = tempfile::tempdir().unwrap();
    // One sample a shard: shards 0-1 train, 2-3 test, 4-5 validation.
    let spec = SPEC.replace("shard_size = 2", "shard_size = 1");
    let generate = |shards: &str| generate_in(tmp.path(), &spec, &["--shard", shards]);
    let data = generate("0-4");
    let run = tmp.path().join("run");
    let file = recipe(tmp.path(), "naive", &data, "naive", 1, "", "");
    let log = ok_v(train(&file, &run, &[]));
    assert!(log.contains("(1 validation)"), "{log}");
    generate("5");
    let log = ok_v(train(&file, &run, &["--resume", "--epochs", "2"]));
    assert!(
        log.contains("(2 validation)")
            && log.contains("was measured on another validation set")
            && log.contains("validates on 'model-cli:tshirt:2'"),
        "{log}"
    );
    // Resumed again on the same drapes, it keeps its best.
    let log = ok_v(train(&file, &run, &["--resume", "--epochs", "3"]));
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
    let jeans = recipe(tmp.path(), "jeans", data, "naive", 1, "", "");
    std::fs::write(
        &jeans,
        std::fs::read_to_string(&jeans)
            .unwrap()
            .replace("\"tshirt\"", "\"jeans\""),
    )
    .unwrap();
    let err = fails_v(train(&jeans, &tmp.path().join("j"), &[]));
    assert!(err.contains("jeans") && err.contains("tshirt"), "{err}");
    // A missing recipe.
    let err = fails(&["train", "--recipe", "no-such-recipe.toml"]);
    assert!(err.contains("no-such-recipe.toml"), "{err}");
    // A missing model file.
    let err = fails(&["eval", "--data", s(data), "--model", "nope.garnet"]);
    assert!(err.contains("nope.garnet"), "{err}");
    // Bodies posed another way than the network learned from: a network that learned from
    // DQS bodies on this dataset (LBS bodies), or draped in one run with one trained on it.
    let naive = tmp.path().join("naive");
    ok_v(train(
        &recipe(tmp.path(), "naive", data, "naive", 1, "", ""),
        &naive,
        &[],
    ));
    let trained = naive.join("best.garnet");
    let dqs = tmp.path().join("dqs-naive.garnet");
    let ck = model::load_checkpoint(&trained).unwrap();
    let setup = ck.setup.clone().with_body_skinning("dqs").unwrap();
    let network = ck.model(&burn::prelude::Device::flex()).unwrap();
    model::save_checkpoint(&dqs, &network, None, &setup, &ck.loss, &ck.state, None).unwrap();
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
fn train_takes_the_network_widths_from_its_recipe() {
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
    let run = |name: &str, network: &str| {
        let file = recipe(tmp.path(), name, data, "naive", 1, "", network);
        train(&file, &tmp.path().join(name), &["--max-samples", "2"])
    };
    let default = params(&ok_v(run("default", "")));
    // Narrow, with the contact and rest inputs, and M placed by the surface anchors.
    let narrow = "[network]\nfusion = [16, 8]\nbody_contact = true\nrest_input = true\n\
                  base = \"anchored\"\n";
    let log = ok_v(run("narrow", narrow));
    // The recipe's fusion widths and extra inputs: fewer parameters than the default
    // Naive, named with its extensions.
    assert!(
        log.contains("training GarNet-naive +contact +rest +anchored ("),
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
    assert!(
        table.contains("| GarNet-naive +contact +rest +anchored |"),
        "{table}"
    );
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
    assert!(
        out.contains("GarNet-naive +contact +rest +anchored"),
        "{out}"
    );
    let draped = geom::io::read_mesh(tmp.path().join("d.glb")).unwrap();
    assert!(draped.vertices.iter().all(|v| v.is_finite()));
    // An unknown field, a wrong type or an empty width list names the file and the field.
    let err = fails_v(run("unknown", "[network]\nfusion_widths = [16]\n"));
    assert!(
        err.contains("unknown.toml") && err.contains("fusion_widths"),
        "{err}"
    );
    let err = fails_v(run("type", "[network]\nfusion = 16\n"));
    assert!(err.contains("type.toml") && err.contains("fusion"), "{err}");
    let err = fails_v(run("base", "[network]\nbase = \"smpl\"\n"));
    assert!(
        err.contains("base.toml") && err.contains("dqs or anchored"),
        "{err}"
    );
    let err = fails_v(run("empty", "[network]\nfusion = []\n"));
    assert!(
        err.contains("empty.toml") && err.contains("fusion"),
        "{err}"
    );
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
    let train_samples = set.select(Some("train"), Some("tshirt")).unwrap();
    let order = Order::Shuffled { seed: 0, epoch: 0 };
    let second = dataset::batches::epoch_order(&set, &train_samples, order)[1];
    let shard = set.manifest().sample(second).unwrap().shard;
    let shard = data.join(format!("shards/shard-{shard:06}.safetensors"));
    let whole_bytes = std::fs::read(&shard).unwrap();

    let every_step = recipe(
        tmp.path(),
        "local",
        &data,
        "local",
        1,
        "batch = 1\ncheckpoint_minutes = 1e-6",
        "",
    );
    let run = |out: &Path, extra: &[&str]| train(&every_step, out, extra);
    let whole = tmp.path().join("whole");
    ok_v(run(&whole, &[]));

    let stopped = tmp.path().join("stopped");
    let mut damaged = whole_bytes.clone();
    let n = damaged.len();
    damaged[n - 50] ^= 0x40;
    std::fs::write(&shard, &damaged).unwrap();
    let err = fails_v(run(&stopped, &[]));
    assert!(err.contains("checksum"), "{err}");
    let mid = stopped.join("mid-epoch.garnet");
    assert!(mid.is_file() && !stopped.join("last.garnet").exists());
    std::fs::write(&shard, &whole_bytes).unwrap();

    // Another shuffle is another recipe: the stopped run cannot go on with it.
    let err = fails_v(run(&stopped, &["--resume", "--seed", "5"]));
    assert!(err.contains("trained by another recipe"), "{err}");
    let log = ok_v(run(&stopped, &["--resume"]));
    assert!(log.contains("inside epoch 1, after 1 batches"), "{log}");
    assert!(!mid.exists() && stopped.join("last.garnet").is_file());
    // The row without its wall time (the fourth column) and CPU time (the last).
    let row = |dir: &Path| -> Vec<String> {
        let csv = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
        let last = csv.lines().last().unwrap().to_string();
        let mut cells: Vec<String> = last.split(',').map(String::from).collect();
        cells.remove(3);
        cells.pop();
        cells
    };
    assert_eq!(row(&stopped), row(&whole));

    // A run started afresh in the folder removes a stopped epoch left there, so that a later
    // --resume cannot go back to it.
    std::fs::copy(stopped.join("last.garnet"), &mid).unwrap();
    let log = ok_v(run(&stopped, &[]));
    assert!(log.contains("removed") && !mid.exists(), "{log}");
}

/// Writes `dir/NAME.toml`: a recipe of `variant` on `data`'s T-shirts for `epochs` epochs,
/// with the `schedule` lines in its `[schedule]` and the `sections` after it; returns its
/// path.
fn recipe(
    dir: &Path,
    name: &str,
    data: &Path,
    variant: &str,
    epochs: usize,
    schedule: &str,
    sections: &str,
) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    let text = format!(
        "format = 1\ngarment = \"tshirt\"\nvariant = \"{variant}\"\ndata = {data:?}\n\n\
         [schedule]\nepochs = {epochs}\n{schedule}\n\n{sections}"
    );
    std::fs::write(&path, text).unwrap();
    path
}

/// `garnet train --recipe RECIPE --out OUT` and `extra`.
fn train(recipe: &Path, out: &Path, extra: &[&str]) -> Vec<String> {
    let mut a = vec!["train", "--recipe", s(recipe), "--out", s(out)];
    a.extend_from_slice(extra);
    owned(&a)
}

/// [`ok`] of an owned command line.
fn ok_v(v: Vec<String>) -> String {
    ok(&as_str(&v))
}

/// [`fails`] of an owned command line.
fn fails_v(v: Vec<String>) -> String {
    fails(&as_str(&v))
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

/// `--recipe` times networks of a recipe's widths and inputs: the same-drape rows compare
/// the paper's GarNet-Local with the recipe's (here wider, with the body-contact and
/// template-vertex inputs, M placed by the surface anchors), and the parameter counts are
/// the recipe's.
#[test]
fn bench_model_times_the_networks_of_a_recipe() {
    let tmp = tempfile::tempdir().unwrap();
    let network = "[network]\nconv_width = 48\nbody_contact = true\nrest_input = true\n\
                   base = \"anchored\"\n";
    let file = recipe(tmp.path(), "net", Path::new("d"), "local", 1, "", network);
    let args = |config: &Path| small_bench_model(&["--recipe", s(config)]);
    let out = ok(&as_str(&args(&file)));
    assert!(out.contains("net.toml"), "{out}");
    for name in ["GarNet-local", "GarNet-local +contact +rest +anchored"] {
        assert!(
            out.contains(&format!("same drape: {name} with the push-out")),
            "{out}"
        );
    }
    // Wider mesh convolutions: more parameters than the defaults in the Local and Global
    // rows; Naive has none, and gains only the template vertices' 3 inputs to its first
    // 64-wide layer (the synthetic rows leave the body contact out).
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
    let bad = recipe(
        tmp.path(),
        "bad",
        Path::new("d"),
        "local",
        1,
        "",
        "[network]\nconv_widht = 64\n",
    );
    let err = fails(&as_str(&args(&bad)));
    assert!(
        err.contains("bad.toml") && err.contains("conv_widht"),
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

/// Regression of the library facade: `garnet drape` of the three shipped models on the main
/// job's body and pose gives the vertices it gave before the drape moved into the library
/// and the models into their current format (`tests/fixtures/drape-main-job-*.glb`, written
/// by the earlier build), to within the differences of the CPUs' matrix kernels.
#[test]
fn drape_gives_the_vertices_it_gave_before() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = common::repo().join("models");
    let models = ["tshirt", "sweater", "jeans"].map(|g| dir.join(format!("{g}-local.garnet")));
    let out = tmp.path().join("drape.glb");
    let mut args = vec!["drape", "--model"];
    args.extend(models.iter().map(|m| s(m)));
    args.extend([
        "--random-shape",
        "1",
        "--pose-procedural",
        "1",
        "--out",
        s(&out),
    ]);
    ok(&args);
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    for garment in ["tshirt", "sweater", "jeans"] {
        let name = format!("drape-main-job-{garment}.glb");
        let before = geom::io::read_mesh(fixtures.join(&name)).unwrap();
        let now = geom::io::read_mesh(tmp.path().join(format!("drape-{garment}.glb"))).unwrap();
        assert_eq!(now.faces, before.faces, "{name}");
        let worst = now
            .vertices
            .iter()
            .zip(&before.vertices)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "{name}: a vertex moved {worst} m");
    }
}

/// `garnet train` takes a recipe and a handful of overrides: at most ten options.
#[test]
fn train_takes_a_recipe_and_few_options() {
    let help = ok(&["train", "--help"]);
    let options = help
        .lines()
        .filter(|l| l.starts_with("  -") || l.starts_with("      --"))
        .count();
    assert!(options <= 10, "{options} options:\n{help}");
    assert!(help.contains("--recipe"), "{help}");
    // Every shipped recipe parses and names its garment and variant in its file name.
    let files = |dir: &str| {
        std::fs::read_dir(common::repo().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file())
            .collect::<Vec<_>>()
    };
    for path in files("recipes") {
        let recipe = model::Recipe::load(&path).unwrap();
        let name = format!("{}-{}.toml", recipe.garment, recipe.variant);
        assert_eq!(path.file_name().unwrap().to_str().unwrap(), name);
    }
    // The design benchmark's recipes all train for the same compute budget.
    let bench = files("recipes/bench");
    assert!(!bench.is_empty());
    for path in bench {
        let recipe = model::Recipe::load(&path).unwrap();
        assert_eq!(recipe.schedule.minutes, Some(30.0), "{}", path.display());
    }
}
