//! Spec parsing and validation: every error names the file and the field.

use std::path::{Path, PathBuf};

use dataset::{LoadedSpec, Plan};

const GOOD: &str = r#"
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

/// Regression: a new optional field of the spec changed the canonical JSON (as `null`) and
/// so the hash of every spec, and datasets made before could no longer be resumed. The hash
/// of a spec that does not use a field added later must stay what it was.
#[test]
fn hashes_of_older_specs_do_not_change() {
    let a = parse(GOOD).unwrap();
    assert!(
        a.hash.starts_with("508d84f9f8baa99f"),
        "the hash of a spec written before changed: {}",
        a.hash
    );
    let stepped = parse(&format!("{GOOD}[simulator]\nbody_step = 0.004\n")).unwrap();
    assert_ne!(stepped.hash, a.hash);
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
    assert_names(&e, "line 8 (`edgee = 0.03`)");
    assert!(e.contains("edgee"), "{e}");
    let e = error_of("seed = 5", "seed = ");
    assert_names(&e, "line 3");
    let e = parse("seed = 1").unwrap_err();
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

#[test]
fn the_repository_specs_are_valid() {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(repo_spec(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 16, "{paths:?}");
    for path in &paths {
        let name = path.file_name().unwrap().to_string_lossy();
        let spec = LoadedSpec::load(path).unwrap_or_else(|e| panic!("{e}"));
        let kinds: Vec<&str> = spec.spec.garments.iter().map(|g| g.kind.as_str()).collect();
        assert!(!kinds.is_empty(), "{name}");
        if name.starts_with("standard") || name == "paper.toml" {
            assert_eq!(kinds, ["tshirt", "sweater", "jeans"], "{name}");
        }
    }
    let paper = LoadedSpec::load(&repo_spec("paper.toml")).unwrap();
    assert_eq!(paper.spec.bodies.count, 600);
    assert!(paper.spec.garments.iter().all(|g| g.edge == 0.01));
}
