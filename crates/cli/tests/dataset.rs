//! Integration tests of `garnet dataset`: plan, generate (sharded, interrupted, resumed),
//! merge, info (with checksum verification) and show, on a fast spec.

mod common;

use common::{fails, mocap_fixture, ok, repo, s};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Every clip the repository's specs name, as CMU-style walks garnet writes (120 frames
/// each), in the mocap folder `root`.
fn spec_mocap(root: &Path) -> PathBuf {
    let clips = [
        "cmu/01/01_01.amc",
        "cmu/01/01_08.amc",
        "cmu/01/01_14.amc",
        "cmu/02/02_01.amc",
        "cmu/02/02_02.amc",
        "cmu/02/02_03.amc",
        "cmu/02/02_04.amc",
        "cmu/02/02_05.amc",
        "cmu/02/02_06.amc",
        "cmu/02/02_07.amc",
        "cmu/02/02_09.amc",
    ];
    mocap_fixture(root, &clips.map(|c| (c, 120)))
}

/// 2 bodies x (T-shirt in 2 poses + jeans in 1): 6 samples of 8 cm garments in 3
/// shards, a few simulator steps each.
const FAST: &str = r#"
format = 2
name = "cli"
seed = 9
shard_size = 2
[bodies]
count = 2
[[garments]]
kind = "tshirt"
edge = 0.08
poses_per_body = 2
[[garments]]
kind = "jeans"
edge = 0.08
poses_per_body = 1
[[poses.procedural]]
kind = "walk"
count = 4
[splits.bodies]
train = 1
test = 1
[simulator]
morph_steps = 2
pose_steps = 3
max_settle_steps = 5
iterations = 2
max_penetration = 0.5
"#;

#[test]
fn plan_describes_specs_and_names_bad_fields() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("fast.toml");
    std::fs::write(&spec, FAST).unwrap();
    let out = ok(&["dataset", "plan", s(&spec)]);
    assert!(
        out.contains("6 samples in 3 shards of 2; 2 bodies"),
        "{out}"
    );
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, FAST.replace("edge = 0.08", "edge = 0.9")).unwrap();
    let err = fails(&["dataset", "plan", s(&bad)]);
    assert!(
        err.contains("bad.toml") && err.contains("garments[0].edge"),
        "{err}"
    );
    let mocap = spec_mocap(&dir.path().join("mocap"));
    for (name, samples) in [
        ("tiny", 12),
        ("standard-lbs", 6000),
        ("standard-x9-lbs", 54000),
        ("paper", 56400),
    ] {
        let spec = repo().join(format!("specs/{name}.toml"));
        let out = ok(&["dataset", "plan", s(&spec), "--mocap", s(&mocap)]);
        assert!(
            out.contains(&format!("{samples} samples in")),
            "{name}: {out}"
        );
    }
    let out = ok(&[
        "dataset",
        "plan",
        s(&repo().join("specs/paper.toml")),
        "--mocap",
        s(&mocap),
    ]);
    assert!(out.contains("split train: 500 bodies"), "{out}");
    // --poses replaces a garment's poses per body.
    let x9 = repo().join("specs/standard-x9-lbs.toml");
    let out = ok(&[
        "dataset",
        "plan",
        s(&x9),
        "--mocap",
        s(&mocap),
        "--poses",
        "tshirt=99,sweater=54",
    ]);
    assert!(out.contains("108000 samples in"), "{out}");
    assert!(out.contains("99 poses per body"), "{out}");
    for (poses, says) in [
        (
            "hat=3",
            "no garment 'hat' (the garments are tshirt, sweater, jeans)",
        ),
        ("tshirt", "GARMENT=N"),
    ] {
        let err = fails(&[
            "dataset",
            "plan",
            s(&x9),
            "--mocap",
            s(&mocap),
            "--poses",
            poses,
        ]);
        assert!(err.contains(says), "{poses}: {err}");
    }
    // A spec that names clips needs the mocap folder; the error says how to give it.
    let out = Command::new(env!("CARGO_BIN_EXE_garnet"))
        .args(["dataset", "plan", s(&x9)])
        .env_remove("GARNET_MOCAP")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--mocap DIR or GARNET_MOCAP"),
        "{err}"
    );
    // The smoke-test spec generates from the clips (its first sample).
    let tiny = dir.path().join("tiny");
    let out = ok(&[
        "dataset",
        "generate",
        s(&repo().join("specs/tiny.toml")),
        "--out",
        s(&tiny),
        "--mocap",
        s(&mocap),
        "--max-samples",
        "1",
    ]);
    assert!(out.contains("made 1 now"), "{out}");
    // A BVH clip (converted from a walk) as a pose source.
    let root = dir.path().join("bvh-mocap");
    std::fs::create_dir_all(&root).unwrap();
    let cmu = mocap.join("cmu/02");
    ok(&[
        "pose",
        "convert",
        "--asf",
        s(&cmu.join("02.asf")),
        "--amc",
        s(&cmu.join("02_01.amc")),
        "--out",
        s(&root.join("walk.bvh")),
    ]);
    let bvh = dir.path().join("bvh.toml");
    let text = FAST.replace(
        "[[poses.procedural]]",
        "[[poses.bvh]]\nclips = [\"walk.bvh\"]\nevery = 50\n[[poses.procedural]]",
    );
    std::fs::write(&bvh, text).unwrap();
    let out = ok(&["dataset", "plan", s(&bvh), "--mocap", s(&root)]);
    // Frames 0, 50 and 100 of the 120, and the 4 procedural poses.
    assert!(out.contains("pose pool: 7 poses in 2 motions"), "{out}");
    let err = fails(&[
        "dataset",
        "plan",
        s(&repo().join("specs/tiny.toml")),
        "--mocap",
        s(dir.path()),
    ]);
    assert!(err.contains("02_01.amc"), "{err}");
}

#[test]
fn generate_resume_merge_info_show() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spec = d.join("fast.toml");
    std::fs::write(&spec, FAST).unwrap();
    let (a, b, whole) = (d.join("a"), d.join("b"), d.join("whole"));
    // Job 0 of 2, interrupted after one sample, then resumed.
    let out = ok(&[
        "dataset",
        "generate",
        s(&spec),
        "--out",
        s(&a),
        "--shard",
        "0/2",
        "--max-samples",
        "1",
    ]);
    assert!(
        out.contains("run the same command again to resume"),
        "{out}"
    );
    let out = ok(&[
        "dataset",
        "generate",
        s(&spec),
        "--out",
        s(&a),
        "--shard",
        "0/2",
        "--jobs",
        "2",
    ]);
    assert!(
        out.contains("1 of 4 selected samples were already made"),
        "{out}"
    );
    assert!(out.contains("the selected shards are finished"), "{out}");
    assert!(out.contains("(dataset merge)"), "{out}");
    ok(&[
        "dataset",
        "generate",
        s(&spec),
        "--out",
        s(&b),
        "--shard",
        "1/2",
        "--jobs",
        "1",
    ]);
    let merged = d.join("merged");
    let out = ok(&["dataset", "merge", s(&merged), s(&a), s(&b)]);
    assert!(
        out.contains("3 of 3 shards") && out.contains("complete"),
        "{out}"
    );
    // The same dataset made in one go.
    let out = ok(&["dataset", "generate", s(&spec), "--out", s(&whole)]);
    assert!(out.contains("the dataset is complete"), "{out}");
    for shard in 0..3 {
        let name = format!("shards/shard-{shard:06}.safetensors");
        let (x, y) = (
            std::fs::read(merged.join(&name)),
            std::fs::read(whole.join(&name)),
        );
        assert_eq!(x.unwrap(), y.unwrap(), "{name}");
    }
    // Only the test body's T-shirts: one shard, the same bytes as the whole dataset's.
    let test_only = d.join("test-only");
    let args = ["--split", "test", "--garment", "tshirt"];
    let out = ok(&[
        &["dataset", "generate", s(&spec), "--out", s(&test_only)][..],
        &args,
    ]
    .concat());
    assert!(
        out.contains("0 of 2 selected samples were already made")
            && out.contains("holding a sample of split test")
            && out.contains("the selected shards are finished"),
        "{out}"
    );
    let made: Vec<_> = std::fs::read_dir(test_only.join("shards"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(made.len(), 1, "{made:?}");
    let name = made[0].file_name().unwrap();
    assert_eq!(
        std::fs::read(&made[0]).unwrap(),
        std::fs::read(whole.join("shards").join(name)).unwrap()
    );
    let err = fails(&[
        "dataset",
        "generate",
        s(&spec),
        "--out",
        s(&test_only),
        "--split",
        "tset",
    ]);
    assert!(
        err.contains("no split 'tset' (the splits are test, train)"),
        "{err}"
    );
    let out = ok(&["dataset", "info", s(&merged), "--verify"]);
    assert!(
        out.contains("of 6 samples stored") && out.contains("tshirt ok/failed"),
        "{out}"
    );
    assert!(
        out.contains("drape time") && out.contains("verified: 3 shards"),
        "{out}"
    );
    let json = ok(&["dataset", "info", s(&merged), "--json"]);
    assert!(json.contains("\"total_samples\": 6"), "{json}");
    // Show: the body, M and G of a stored sample.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(merged.join("manifest.json")).unwrap())
            .unwrap();
    let k = manifest["samples"][0]["index"]
        .as_u64()
        .unwrap()
        .to_string();
    let png = d.join("show.png");
    ok(&[
        "dataset",
        "show",
        s(&merged),
        "--index",
        &k,
        "--png",
        s(&png),
    ]);
    let image = render::Image::from_png(&png).unwrap();
    assert!(image.width >= 700 && image.count_not(image.pixel(0, 0)) > 20_000);
    let err = fails(&[
        "dataset",
        "show",
        s(&merged),
        "--index",
        "99",
        "--png",
        s(&png),
    ]);
    assert!(err.contains("sample 99 is not stored"), "{err}");
    // Three random samples: three rows.
    ok(&[
        "dataset",
        "show",
        s(&merged),
        "--random",
        "3",
        "--png",
        s(&png),
    ]);
    let three = render::Image::from_png(&png).unwrap();
    assert!(
        three.height > 2 * image.height,
        "{} vs {}",
        three.height,
        image.height
    );
    // A damaged shard is named.
    let shard = merged.join("shards/shard-000002.safetensors");
    let mut bytes = std::fs::read(&shard).unwrap();
    let n = bytes.len();
    bytes[n - 8] ^= 1;
    std::fs::write(&shard, bytes).unwrap();
    let err = fails(&["dataset", "info", s(&merged), "--verify"]);
    assert!(
        err.contains("shard-000002.safetensors") && err.contains("checksum"),
        "{err}"
    );
    // A folder started with --poses resumes only with the same: its spec.toml is the
    // resolved spec.
    let fewer = d.join("fewer");
    let args = ["dataset", "generate", s(&spec), "--out", s(&fewer)];
    ok(&[&args[..], &["--poses", "tshirt=1", "--max-samples", "1"]].concat());
    let err = fails(&args);
    assert!(
        err.contains("garments[0].poses_per_body: 1 -> 2") && err.contains("--poses"),
        "{err}"
    );
    let recorded = fewer.join("spec.toml");
    let out = ok(&["dataset", "generate", s(&recorded), "--out", s(&fewer)]);
    assert!(
        out.contains("1 of 4 selected samples were already made"),
        "{out}"
    );
    // Another spec in the same folder is refused.
    std::fs::write(&spec, FAST.replace("seed = 9", "seed = 10")).unwrap();
    let err = fails(&["dataset", "generate", s(&spec), "--out", s(&whole)]);
    assert!(err.contains("another spec"), "{err}");
    let err = fails(&[
        "dataset",
        "generate",
        s(&spec),
        "--out",
        s(&whole),
        "--shard",
        "2/2",
    ]);
    assert!(err.contains("--shard"), "{err}");
}

#[test]
fn generate_a_grown_compact_spec_reusing_a_smaller_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (small_spec, grown_spec) = (d.join("small.toml"), d.join("grown.toml"));
    std::fs::write(&small_spec, FAST).unwrap();
    let grown = FAST
        .replace("count = 2\n[[garments]]", "count = 3\n[[garments]]")
        .replace("train = 1\ntest = 1", "train = 2\ntest = 1")
        + "[output]\ncompact = true\n";
    std::fs::write(&grown_spec, grown).unwrap();
    let (small, big) = (d.join("small"), d.join("big"));
    ok(&["dataset", "generate", s(&small_spec), "--out", s(&small)]);
    // Shards 0 and 3-4: the first two T-shirt samples, then the jeans (9 samples in all).
    let out = ok(&[
        "dataset",
        "generate",
        s(&grown_spec),
        "--out",
        s(&big),
        "--reuse",
        s(&small),
        "--shard",
        "0,3-4",
    ]);
    assert!(
        out.contains("4 of 5 selected samples were already made (4 taken from --reuse now)"),
        "{out}"
    );
    // The compact dataset's body and M are rebuilt for the picture.
    let png = d.join("show.png");
    ok(&["dataset", "show", s(&big), "--index", "0", "--png", s(&png)]);
    let image = render::Image::from_png(&png).unwrap();
    assert!(image.count_not(image.pixel(0, 0)) > 20_000);
    // A dataset of another seed is refused as a source.
    let other_spec = d.join("other.toml");
    std::fs::write(&other_spec, FAST.replace("seed = 9", "seed = 10")).unwrap();
    let err = fails(&[
        "dataset",
        "generate",
        s(&other_spec),
        "--out",
        s(&d.join("other")),
        "--reuse",
        s(&small),
    ]);
    assert!(err.contains("--reuse") && err.contains("seed"), "{err}");
}

/// 2 bodies x (T-shirt in 2 poses + jeans in 1) of coarse 5 cm garments in procedural
/// poses (no mocap), a short settling: what `dataset spread` drapes in a few seconds.
const SPREAD: &str = r#"
format = 2
name = "spread"
seed = 4
[bodies]
count = 2
[[garments]]
kind = "tshirt"
edge = 0.05
poses_per_body = 2
[[garments]]
kind = "jeans"
edge = 0.05
poses_per_body = 1
[[poses.procedural]]
kind = "walk"
count = 3
[splits.bodies]
train = 1
test = 1
[simulator]
max_settle_steps = 30
max_penetration = 0.05
"#;

#[test]
fn spread_drapes_each_garment_three_times_and_reports_distances() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spec = d.join("spread.toml");
    std::fs::write(&spec, SPREAD).unwrap();
    let settings = d.join("sim.toml");
    std::fs::write(&settings, "max_settle_steps = 20\n").unwrap();
    let (json, csv) = (d.join("out/report.json"), d.join("out/rows.csv"));
    let out = ok(&[
        "dataset",
        "spread",
        s(&spec),
        "--per-garment",
        "1",
        "--jobs",
        "2",
        "--simulator",
        s(&settings),
        "--out",
        s(&json),
        "--csv",
        s(&csv),
    ]);
    assert!(
        out.contains("| garment |") && out.contains("| jeans |"),
        "{out}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["split"], "test");
    assert_eq!(report["spec_name"], "spread");
    assert_eq!(report["spec_hash"].as_str().unwrap().len(), 64);
    // The file's key over the spec's, the spec's other keys kept.
    assert_eq!(report["simulator"]["max_settle_steps"], 20);
    assert!((report["simulator"]["max_penetration"].as_f64().unwrap() - 0.05).abs() < 1e-6);
    let densities = report["densities_kg_m2"].as_array().unwrap();
    let d0 = densities[0].as_f64().unwrap();
    assert!(
        (densities[1].as_f64().unwrap() / d0 - 1.001).abs() < 1e-5,
        "{densities:?}"
    );
    assert!(
        (densities[2].as_f64().unwrap() / d0 - 0.999).abs() < 1e-5,
        "{densities:?}"
    );
    let garments = report["garments"].as_array().unwrap();
    let names: Vec<&str> = garments
        .iter()
        .map(|g| g["garment"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["tshirt", "jeans"]);
    for g in garments {
        assert_eq!(
            (g["samples"].as_u64(), g["drapes"].as_u64()),
            (Some(1), Some(3)),
            "{g}"
        );
        assert_eq!(g["failed"], 0, "{g}");
        for key in [
            "e_dist_up_cm",
            "e_dist_down_cm",
            "e_dist_cm",
            "e_norm_up_deg",
            "e_norm_deg",
        ] {
            let v = g[key].as_f64().unwrap_or(f64::NAN);
            assert!(v.is_finite() && v >= 0.0, "{key}: {g}");
        }
        assert!(g["median_settle_steps"].as_f64().unwrap() <= 20.0, "{g}");
    }
    let rows = report["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for r in rows {
        assert_eq!(r["drapes"].as_array().unwrap().len(), 3, "{r}");
    }
    let csv = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(
        csv.starts_with("index,garment,body,pose,e_dist_up_cm"),
        "{csv}"
    );
    // No temporary file is left beside the reports.
    let names: Vec<String> = std::fs::read_dir(d.join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
    // --garment measures only the garments it names.
    ok(&[
        "dataset",
        "spread",
        s(&spec),
        "--per-garment",
        "1",
        "--garment",
        "jeans",
        "--simulator",
        s(&settings),
        "--out",
        s(&json),
    ]);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let garments = report["garments"].as_array().unwrap();
    assert_eq!(garments.len(), 1);
    assert_eq!(garments[0]["garment"], "jeans");
    assert_eq!(report["rows"].as_array().unwrap().len(), 1);
}

#[test]
fn spread_refuses_an_unknown_split_and_bad_counts() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("spread.toml");
    std::fs::write(&spec, SPREAD).unwrap();
    let json = dir.path().join("report.json");
    let args = ["dataset", "spread", s(&spec), "--out", s(&json)];
    for (extra, says) in [
        (
            &["--split", "tset"][..],
            "no split 'tset' (the splits are test, train)",
        ),
        (&["--per-garment", "0"][..], "--per-garment"),
        (&["--step", "0.2"][..], "(0, 0.1)"),
        (
            &["--garment", "jeans,skirt"][..],
            "no garment 'skirt' (the garments are tshirt, jeans)",
        ),
    ] {
        let err = fails(&[&args[..], extra].concat());
        assert!(
            err.contains(says) && err.contains("spread.toml"),
            "{extra:?}: {err}"
        );
    }
    assert!(!json.exists());
    // A spec that names clips needs the mocap folder.
    let clips = dir.path().join("clips.toml");
    let text = SPREAD.replace(
        "[[poses.procedural]]",
        "[[poses.amc]]\nclips = [\"cmu/02/02_01.amc\"]\nevery = 50\n[[poses.procedural]]",
    );
    std::fs::write(&clips, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_garnet"))
        .args(["dataset", "spread", s(&clips), "--out", s(&json)])
        .env_remove("GARNET_MOCAP")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("clips.toml") && err.contains("--mocap DIR"),
        "{err}"
    );
}
