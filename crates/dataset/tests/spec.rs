//! Spec parsing and validation: every error names the file and the field.

use std::path::{Path, PathBuf};

use dataset::poses::PoseLibrary;
use dataset::{LoadedSpec, Plan};

const GOOD: &str = r#"
format = 2
name = "t"
seed = 5
[bodies]
count = 10
[[garments]]
kind = "tshirt"
edge = 0.03
poses_per_body = 2
[[poses.procedural]]
kind = "walk"
count = 8
[splits.bodies]
train = 8
test = 2
"#;

fn parse(text: &str) -> Result<LoadedSpec, String> {
    LoadedSpec::parse(text, Path::new("specs/x.toml")).map_err(|e| e.to_string())
}

/// Parses `GOOD` with `from` replaced by `to` and returns the error.
fn error_of(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "{from}");
    parse(&GOOD.replacen(from, to, 1)).expect_err("should be rejected")
}

fn assert_names(err: &str, field: &str) {
    assert!(
        err.starts_with("specs/x.toml: ") && err.contains(field),
        "expected the file and `{field}` in: {err}"
    );
}

#[test]
fn a_good_spec_parses_and_hashes_by_meaning() {
    let a = parse(GOOD).unwrap();
    assert_eq!(a.spec.shard_size, 32);
    assert_eq!(a.spec.garments[0].poses_per_body, 2);
    let b = parse(&format!(
        "# a comment\n{}",
        GOOD.replace("seed = 5", "seed   =   5")
    ))
    .unwrap();
    assert_eq!(a.hash, b.hash);
    assert_ne!(
        a.hash,
        parse(&GOOD.replace("seed = 5", "seed = 6")).unwrap().hash
    );
}

#[test]
fn field_errors_name_the_file_and_field() {
    let cases = [
        ("edge = 0.03", "edge = 0.5", "garments[0].edge"),
        ("kind = \"tshirt\"", "kind = \"hat\"", "garments[0].kind"),
        (
            "poses_per_body = 2",
            "poses_per_body = 0",
            "garments[0].poses_per_body",
        ),
        ("count = 10", "count = 0", "bodies.count"),
        (
            "kind = \"walk\"",
            "kind = \"run\"",
            "poses.procedural[0].kind",
        ),
        ("test = 2", "test = 3", "splits.bodies"),
        ("test = 2", "test = 0.2", "splits.bodies"),
        ("seed = 5", "seed = 5\nshard_size = 0", "shard_size"),
        (
            "poses_per_body = 2",
            "poses_per_body = 2\ncut = { sleeves = 0.2 }",
            "garments[0].cut.sleeves",
        ),
        (
            "poses_per_body = 2",
            "poses_per_body = 2\ncut_ranges = { ease = [0.05, 0.02] }",
            "garments[0].cut_ranges.ease",
        ),
        (
            "count = 10",
            "count = 10\n[bodies.distribution]\nfemale_share = 1.5",
            "bodies.distribution.female_share",
        ),
        (
            "count = 10",
            "count = 10\n[bodies.distribution]\nfemale = 0.5",
            "bodies.distribution.female",
        ),
        (
            "test = 2",
            "test = 2\n[simulator]\niterations = 0",
            "simulator.iterations",
        ),
        (
            "test = 2",
            "test = 2\n[simulator]\nskinning = \"xyz\"",
            "simulator.skinning",
        ),
        (
            "test = 2",
            "test = 2\n[splits.unseen_poses]\nseen_fraction = 0.5\nheld_out = [\"val\"]",
            "splits.unseen_poses.held_out",
        ),
        (
            "test = 2",
            "test = 2\n[splits.unseen_poses]\nseen_fraction = 1.5\nheld_out = [\"test\"]",
            "splits.unseen_poses.seen_fraction",
        ),
        (
            "[[poses.procedural]]",
            "[[poses.amc]]\nclips = [\"a.amc\"]\nevery = 2\nrandom = 3\n[[poses.procedural]]",
            "poses.amc[0].every",
        ),
        (
            "[[poses.procedural]]",
            "[[poses.bvh]]\nclips = [\"a.amc\"]\nevery = 2\n[[poses.procedural]]",
            "poses.bvh[0].clips[0]",
        ),
    ];
    for (from, to, field) in cases {
        assert_names(&error_of(from, to), field);
    }
}

#[test]
fn syntax_and_unknown_keys_name_the_line() {
    let e = error_of("edge = 0.03", "edgee = 0.03");
    assert_names(&e, "line 9 (`edgee = 0.03`)");
    assert!(e.contains("edgee"), "{e}");
    let e = error_of("seed = 5", "seed = ");
    assert_names(&e, "line 4");
    let e = parse("format = 2\nseed = 1").unwrap_err();
    assert!(e.contains("bodies"), "{e}");
    let missing = LoadedSpec::load(Path::new("/no/such/spec.toml")).unwrap_err();
    assert!(missing.to_string().contains("/no/such/spec.toml"));
}

#[test]
fn pose_pools_too_small_for_a_split_are_rejected() {
    let text = GOOD.replace("count = 8", "count = 3").replace(
        "test = 2",
        "test = 2\n[splits.unseen_poses]\nseen_fraction = 0.5\nheld_out = [\"test\"]",
    );
    let spec = parse(&text).unwrap();
    let e = Plan::new(&spec, &[]).unwrap_err().to_string();
    assert_names(&e, "garments[0].poses_per_body");
    assert!(e.contains("split 'train' can use only 1 of them"), "{e}");
}

fn repo_spec(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../specs")
        .join(name)
}

/// A mocap folder holding every clip `specs` name (CMU-style walks garnet writes, 120
/// frames each, their skeletons beside them), in a folder kept alive by the guard.
fn mocap_for(specs: &[&LoadedSpec]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for spec in specs {
        for source in &spec.spec.poses.amc {
            for clip in &source.clips {
                body::pose::synthetic_clip::write_cmu_clip(dir.path(), clip, 120).unwrap();
            }
        }
        assert!(spec.spec.poses.bvh.is_empty(), "{}", spec.path.display());
    }
    dir
}

#[test]
fn the_repository_specs_are_valid_and_plan() {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(repo_spec(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!((4..=6).contains(&paths.len()), "{paths:?}");
    let specs: Vec<LoadedSpec> = paths
        .iter()
        .map(|p| LoadedSpec::load(p).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    let mocap = mocap_for(&specs.iter().collect::<Vec<_>>());
    for spec in &specs {
        let name = spec.path.file_name().unwrap().to_string_lossy();
        let kinds: Vec<&str> = spec.spec.garments.iter().map(|g| g.kind.as_str()).collect();
        assert_eq!(kinds, ["tshirt", "sweater", "jeans"], "{name}");
        let library = PoseLibrary::load(&spec.spec, Some(mocap.path())).unwrap();
        let plan = Plan::new(spec, &library.frame_counts()).unwrap_or_else(|e| panic!("{e}"));
        assert!(plan.total() > 0, "{name}");
        // The resolved spec, as a dataset folder keeps it, reads back as the same spec.
        let again = LoadedSpec::parse(&spec.resolved_toml(), Path::new("again.toml")).unwrap();
        assert_eq!(again.spec, spec.spec, "{name}");
        assert_eq!(again.hash, spec.hash, "{name}");
    }
    let paper = LoadedSpec::load(&repo_spec("paper.toml")).unwrap();
    assert_eq!(paper.spec.bodies.count, 600);
    assert!(paper.spec.garments.iter().all(|g| g.edge == 0.01));
}

/// The benchmark spells out every setting it relies on, so that it makes the same drapes
/// whatever the defaults become: each simulator setting, each garment's whole cut (the first
/// cut), the shape distribution.
#[test]
fn the_benchmarks_name_every_setting() {
    for file in ["standard-lbs.toml", "standard-fitted.toml"] {
        check_names_every_setting(file);
    }
    // standard-lbs was written before `start` and `static_friction` existed, so it names
    // neither (its hash stays the same): it relies on their defaults staying the animated
    // path and the creeping friction.
    let lbs = LoadedSpec::load(&repo_spec("standard-lbs.toml"))
        .unwrap()
        .spec;
    assert_eq!(
        (&lbs.simulator.start, lbs.simulator.static_friction),
        (&None, None)
    );
    let opts = lbs.simulator.drape_options().unwrap();
    assert_eq!(opts.start, sim::drape::Start::Animate);
    assert!(!opts.cloth.static_friction);
    let fitted = LoadedSpec::load(&repo_spec("standard-fitted.toml"))
        .unwrap()
        .spec;
    assert_eq!(fitted.simulator.start.as_deref(), Some("fitted"));
    assert_eq!(fitted.simulator.static_friction, Some(true));
}

/// Every simulator setting (but `start` and `static_friction`, see above), the whole cut
/// of each garment and the whole shape distribution are written out in `file`.
fn check_names_every_setting(file: &str) {
    let text = std::fs::read_to_string(repo_spec(file)).unwrap();
    let table: toml::Table = toml::from_str(&text).unwrap();
    let spec = LoadedSpec::load(&repo_spec(file)).unwrap().spec;
    let simulator = serde_json::to_value(&spec.simulator).unwrap();
    for (key, value) in simulator.as_object().unwrap() {
        assert!(!value.is_null(), "{file}: [simulator] names no {key}");
    }
    assert_eq!(spec.simulator.skinning.as_deref(), Some("lbs"));
    assert_eq!(spec.simulator.waistband, Some(false));
    for g in &spec.garments {
        let kind = garment::GarmentKind::parse(&g.kind).unwrap();
        let first = garment::CutParams::first_for(&kind);
        assert_eq!(
            g.cut.len(),
            first.named().len(),
            "{}: the whole cut",
            g.kind
        );
        for (name, value) in first.named() {
            assert_eq!(g.cut[name], value, "{}.cut.{name}", g.kind);
        }
    }
    let distribution = table["bodies"]["distribution"].as_table().unwrap();
    let all = toml::Table::try_from(body::shape_sampler::ShapeDistribution::default()).unwrap();
    assert_eq!(
        distribution.keys().collect::<Vec<_>>(),
        all.keys().collect::<Vec<_>>()
    );
    assert_eq!(spec.shard_size, 1);
    assert!(spec.output.compact && !spec.output.fitted);
}

/// standard-x9-lbs is standard-lbs with 32 samples a shard and nine times the poses per
/// body (36, 27, 27): what its own full copy said.
#[test]
fn the_x9_spec_is_the_benchmark_with_nine_times_the_poses() {
    let x9 = LoadedSpec::load(&repo_spec("standard-x9-lbs.toml")).unwrap();
    let mut want = LoadedSpec::load(&repo_spec("standard-lbs.toml"))
        .unwrap()
        .spec;
    want.name = "standard-x9-lbs".into();
    want.shard_size = 32;
    for (g, n) in want.garments.iter_mut().zip([36, 27, 27]) {
        g.poses_per_body = n;
    }
    assert_eq!(x9.spec, want);
    // The same through --poses: the benchmark's garments at the x9 counts.
    let overridden =
        LoadedSpec::load_with(&repo_spec("standard-x9-lbs.toml"), &[("tshirt".into(), 99)])
            .unwrap();
    assert_eq!(overridden.spec.garments[0].poses_per_body, 99);
    assert_eq!(overridden.spec.garments[1..], x9.spec.garments[1..]);
    assert_ne!(overridden.hash, x9.hash);
}

#[test]
fn bases_resolve_relative_to_the_spec_and_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.toml"), GOOD).unwrap();
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let over = sub.join("over.toml");
    let write = |text: &str| std::fs::write(&over, text).unwrap();
    write("format = 2\nbase = \"../base.toml\"\nseed = 6\n[poses_per_body]\ntshirt = 5\n");
    let spec = LoadedSpec::load(&over).unwrap();
    let mut want = parse(GOOD).unwrap().spec;
    want.seed = 6;
    want.garments[0].poses_per_body = 5;
    assert_eq!(spec.spec, want);
    write("format = 2\nbase = \"../base.toml\"\n[poses_per_body]\nhat = 5\n");
    let e = LoadedSpec::load(&over).unwrap_err().to_string();
    assert!(
        e.contains("over.toml: poses_per_body.hat: no garment 'hat'"),
        "{e}"
    );
    write("format = 2\nbase = \"over.toml\"\n");
    let e = LoadedSpec::load(&over).unwrap_err().to_string();
    assert!(e.contains("cycle"), "{e}");
    write("format = 2\nbase = \"missing.toml\"\n");
    let e = LoadedSpec::load(&over).unwrap_err().to_string();
    assert!(e.contains("missing.toml"), "{e}");
    let e = LoadedSpec::load_with(&dir.path().join("base.toml"), &[("jeans".into(), 2)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--poses jeans=2: no garment 'jeans' (the garments are tshirt)"),
        "{e}"
    );
}

#[test]
fn specs_without_the_current_format_are_refused() {
    let e = parse(&GOOD.replace("format = 2\n", "")).unwrap_err();
    assert_names(&e, "format");
    assert!(e.contains("add `format = 2`"), "{e}");
    let e = parse(&GOOD.replace("format = 2", "format = 1")).unwrap_err();
    assert!(e.contains("format 1 is no longer read"), "{e}");
}
