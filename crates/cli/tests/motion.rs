//! Integration tests of `garnet drape --frames`: a clip the project writes itself (a CMU-style
//! walk, converted to BVH by `garnet pose convert`) and a procedural motion, draped into an
//! animated GLB and PC2 point caches.

mod common;

use std::path::{Path, PathBuf};

use common::{fails, ok, repo, s};

/// A 48-frame CMU-style walk as BVH in `dir`.
fn walk_bvh(dir: &Path) -> PathBuf {
    common::walk_clip(dir, 48).2
}

fn tshirt() -> PathBuf {
    repo().join("models/tshirt-local.garnet")
}

/// The JSON chunk of a GLB file.
fn glb_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + n]).unwrap()
}

#[test]
fn a_clip_drapes_into_an_animated_glb_and_point_caches() {
    let tmp = tempfile::tempdir().unwrap();
    let bvh = walk_bvh(tmp.path());
    let glb = tmp.path().join("walk.glb");
    let model = tshirt();
    let drape = |out: &Path, extra: &[&str]| {
        let mut a = vec!["drape", "--model", s(&model), "--pose-bvh", s(&bvh)];
        a.extend(["--random-shape", "2", "--out", s(out)]);
        a.extend_from_slice(extra);
        ok(&a)
    };
    let log = drape(&glb, &["--frames", "0..48:4"]);
    assert!(
        log.contains("12 frames of walk.bvh") && log.contains("30.0 fps"),
        "{log}"
    );
    assert!(log.contains("mean vertex acceleration"), "{log}");
    let doc = glb_json(&glb);
    let names: Vec<&str> = doc["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["tshirt", "body"]);
    for m in doc["meshes"].as_array().unwrap() {
        assert_eq!(m["primitives"][0]["targets"].as_array().unwrap().len(), 11);
    }
    let anim = &doc["animations"][0];
    assert_eq!(anim["channels"].as_array().unwrap().len(), 2);
    let input = &doc["accessors"][anim["samplers"][0]["input"].as_u64().unwrap() as usize];
    assert_eq!(input["count"], 12);

    // Point caches, as the network drapes them and smoothed.
    let raw = tmp.path().join("raw.pc2");
    let smooth = tmp.path().join("smooth.pc2");
    drape(&raw, &["--frames", "0..48:4", "--fps", "24"]);
    drape(&smooth, &["--frames", "0..48:4", "--smooth"]);
    let (a, b) = (
        geom::io::read_pc2(&raw).unwrap(),
        geom::io::read_pc2(&smooth).unwrap(),
    );
    let mesh = geom::io::read_mesh(raw.with_extension("obj")).unwrap();
    assert_eq!(a.frames.len(), 12);
    assert!(a.frames.iter().all(|f| f.len() == mesh.vertices.len()));
    assert_eq!(mesh.vertices, a.frames[0]);
    for (k, (fa, fb)) in a.frames.iter().zip(&b.frames).enumerate() {
        let e = geom::metrics::e_dist(fa, fb).unwrap();
        assert!(e <= 0.05, "frame {k}: the smoothing moved it {e} cm");
    }
    assert!(garnet::motion::coherence(&b.frames) <= garnet::motion::coherence(&a.frames));
}

#[test]
fn a_procedural_motion_drapes_and_bad_requests_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("dance.pc2");
    let body = tmp.path().join("body.pc2");
    let model = tshirt();
    let log = ok(&[
        "drape",
        "--model",
        s(&model),
        "--pose-procedural",
        "3",
        "--pose-kind",
        "dance",
        "--frames",
        "0..8",
        "--out",
        s(&out),
        "--body-out",
        s(&body),
    ]);
    assert!(
        log.contains("8 frames of procedural dance motion 3"),
        "{log}"
    );
    assert_eq!(geom::io::read_pc2(&out).unwrap().frames.len(), 8);
    assert_eq!(geom::io::read_pc2(&body).unwrap().frames[0].len(), 13380);
    let bvh = walk_bvh(tmp.path());
    let run = |extra: &[&str]| {
        let mut a = vec!["drape", "--model", s(&model), "--out"];
        a.push(s(&out));
        a.extend_from_slice(extra);
        fails(&a)
    };
    let err = run(&["--pose-bvh", s(&bvh), "--frames", "5..3"]);
    assert!(err.contains("5..3"), "{err}");
    let err = run(&["--frames", "0..4"]);
    assert!(err.contains("--frames needs a motion"), "{err}");
    let err = run(&["--pose-bvh", s(&bvh), "--frames", "100..120"]);
    assert!(
        err.contains("walk.bvh") && err.contains("48 frames"),
        "{err}"
    );
    let obj = tmp.path().join("x.obj");
    let err = fails(&[
        "drape",
        "--model",
        s(&model),
        "--pose-bvh",
        s(&bvh),
        "--frames",
        "0..2",
        "--out",
        s(&obj),
    ]);
    assert!(err.contains("x.obj") && err.contains(".pc2"), "{err}");
    let err = run(&["--pose-bvh", s(&bvh), "--frames", "0..2", "--fps", "0"]);
    assert!(err.contains("--fps"), "{err}");
}
