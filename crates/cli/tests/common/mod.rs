//! Helpers shared by the CLI integration tests: run the `garnet` binary, expect success
//! or a clean failure.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `garnet` with `args`.
pub fn garnet(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_garnet"))
        .args(args)
        .output()
        .expect("garnet runs")
}

/// Runs `garnet`, asserting success; stdout then stderr.
pub fn ok(args: &[&str]) -> String {
    let out = garnet(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "garnet {args:?} failed:\n{stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned() + &stderr
}

/// Runs `garnet`, asserting a failure without a panic; stderr.
pub fn fails(args: &[&str]) -> String {
    let out = garnet(args);
    assert!(!out.status.success(), "garnet {args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

/// A path as `&str`.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Writes CMU-style walks that garnet makes itself (`body::pose::synthetic_clip`) into the
/// mocap folder `root`: each `(clip, frames)`, a path such as `cmu/02/02_01.amc`, with its
/// subject's skeleton beside it (`cmu/02/02.asf`). Returns `root`.
pub fn mocap_fixture(root: &Path, clips: &[(&str, usize)]) -> PathBuf {
    for (clip, frames) in clips {
        body::pose::synthetic_clip::write_cmu_clip(root, clip, *frames).unwrap();
    }
    root.to_path_buf()
}

/// A walk of `frames` frames garnet writes itself (`root/cmu/02/02.asf` and `02_01.amc`),
/// converted by `garnet pose convert` to `root/walk.bvh`; returns (ASF, AMC, BVH).
pub fn walk_clip(root: &Path, frames: usize) -> (PathBuf, PathBuf, PathBuf) {
    let mocap = mocap_fixture(root, &[("cmu/02/02_01.amc", frames)]).join("cmu");
    let (asf, amc) = (mocap.join("02/02.asf"), mocap.join("02/02_01.amc"));
    let bvh = root.join("walk.bvh");
    ok(&[
        "pose",
        "convert",
        "--asf",
        s(&asf),
        "--amc",
        s(&amc),
        "--out",
        s(&bvh),
    ]);
    (asf, amc, bvh)
}
