//! Shared fixtures of the generation tests: a fast spec (very coarse garments, a few
//! simulator steps) and one reference dataset generated once per test binary.

#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

use body::BodyModel;
use dataset::{GenerateOptions, GenerateReport, LoadedSpec};

/// 3 bodies (2 train, 1 test) x (T-shirt in 2 poses + jeans in 1, cut per body), 8 cm
/// edges, 10 simulator steps: 9 samples in 5 shards of 2.
pub const FAST: &str = r#"
format = 2
name = "fast"
seed = 3
shard_size = 2
[bodies]
count = 3
[[garments]]
kind = "tshirt"
edge = 0.08
poses_per_body = 2
[[garments]]
kind = "jeans"
edge = 0.08
poses_per_body = 1
cut_ranges = { leg_length = [0.5, 0.8] }
[[poses.procedural]]
kind = "any"
count = 6
[splits.bodies]
train = 2
test = 1
[simulator]
morph_steps = 2
pose_steps = 3
max_settle_steps = 5
iterations = 2
max_penetration = 0.5
"#;

/// The body model (loaded once).
pub fn model() -> &'static BodyModel {
    static MODEL: OnceLock<BodyModel> = OnceLock::new();
    MODEL.get_or_init(|| BodyModel::load().expect("body assets (set GARNET_HOME)"))
}

/// `text` as a spec file named `name`.
pub fn spec(text: &str) -> LoadedSpec {
    LoadedSpec::parse(text, Path::new("fast.toml")).unwrap()
}

/// Options with `jobs` threads and no mocap.
pub fn options(jobs: usize) -> GenerateOptions<'static> {
    let mut o = GenerateOptions::new(None);
    o.jobs = jobs;
    o
}

/// Generates `text` into `out` with `opts`.
pub fn generate(text: &str, out: &Path, opts: &GenerateOptions<'_>) -> GenerateReport {
    dataset::generate(model(), &spec(text), out, opts).unwrap_or_else(|e| panic!("{e}"))
}

/// The reference dataset of [`FAST`], generated once with 2 jobs.
pub fn reference() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let r = generate(FAST, dir.path(), &options(2));
        assert!(r.complete && r.made == 9, "{r:?}");
        dir
    })
    .path()
}

/// The shard files of dataset folder `dir`: name -> bytes.
pub fn shards(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir.join("shards"))
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

/// Asserts `dir` holds exactly the reference's shards, byte for byte.
pub fn assert_same_shards(dir: &Path) {
    let (a, b) = (shards(reference()), shards(dir));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "shard files differ"
    );
    for (name, bytes) in &a {
        assert!(bytes == &b[name], "{name} differs from the reference");
    }
}
