//! Readers against hand-written fixtures (valid and broken) and write/read round trips.

use std::path::PathBuf;

use geom::adjacency::check_manifold;
use geom::io::{self, GlbMesh};
use geom::{Bvh, TriMesh};
use glam::Vec3;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// Reading `name` fails with a message naming the file and containing every `want` string.
fn assert_error(name: &str, want: &[&str]) {
    let err = io::read_mesh(fixture(name)).expect_err(name).to_string();
    assert!(
        err.contains(name),
        "{name}: message does not name the file: {err}"
    );
    for w in want {
        assert!(err.contains(w), "{name}: expected {w:?} in: {err}");
    }
}

#[test]
fn obj_with_quads_groups_and_all_face_forms() {
    let path = fixture("cube_quads.obj");
    let d = io::read_obj_data(&path).unwrap();
    let m = &d.mesh;
    assert_eq!((m.vertices.len(), m.faces.len()), (8, 12));
    assert_eq!(d.groups.len(), 2);
    assert_eq!(
        (d.groups[0].name.as_str(), d.groups[0].faces.clone()),
        ("sides", 0..8)
    );
    assert_eq!(
        (d.groups[1].name.as_str(), d.groups[1].faces.clone()),
        ("caps", 8..12)
    );
    let r = check_manifold(m.vertices.len(), &m.faces).unwrap();
    assert!(r.is_ok() && r.is_closed(), "{r}");
    assert_eq!(r.euler_characteristic(), 2);
    // Outward orientation: the centre is inside.
    let bvh = Bvh::from_mesh(m).unwrap();
    assert!(bvh.contains(Vec3::ZERO) && !bvh.contains(Vec3::ONE));
    assert!((m.surface_area() - 6.0).abs() < 1e-6);
}

#[test]
fn ply_ascii_and_binary() {
    let a = io::read_mesh(fixture("tri_ascii.ply")).unwrap();
    assert_eq!(a.faces, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(a.vertices[2], Vec3::new(1.0, 1.0, 0.0));
    let b = io::read_mesh(fixture("quad_binary.ply")).unwrap();
    assert_eq!(b, a);
}

#[test]
fn glb_fixture() {
    let m = io::read_mesh(fixture("triangle.glb")).unwrap();
    assert_eq!(m.faces, vec![[0, 1, 2]]);
    assert_eq!(m.vertices[1], Vec3::X);
    let prims = io::read_glb(fixture("triangle.glb")).unwrap();
    assert_eq!(prims[0].name.as_deref(), Some("tri"));
    assert_eq!(prims[0].base_color, None);
}

#[test]
fn broken_text_files_name_file_and_line() {
    assert_error("truncated_face.obj", &[":6:", "at least 3"]);
    assert_error("bad_coordinate.obj", &[":4:", "\"1o5\"", "not a number"]);
    assert_error("index_out_of_range.obj", &[":5:", "out of range"]);
    assert_error("lying_count.ply", &[":14:", "end of file"]);
    assert_error("bad_token.ply", &[":11:", "\"zero\""]);
}

#[test]
fn broken_binary_files_name_file_and_offset() {
    assert_error("truncated_binary.ply", &["byte ", "end of data"]);
    assert_error("bad_magic.glb", &["byte 0", "magic"]);
    assert_error("truncated_chunk.glb", &["byte ", "runs past the end"]);
}

#[test]
fn missing_file_and_unknown_extension() {
    let e = io::read_mesh(fixture("nope.obj")).unwrap_err().to_string();
    assert!(e.contains("nope.obj"), "{e}");
    let e = io::read_mesh(fixture("cube_quads.stl"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cube_quads.stl") && e.contains("extension"),
        "{e}"
    );
}

#[test]
fn round_trips_through_a_tempdir() {
    let dir = tempfile::tempdir().unwrap();
    let mut body = TriMesh::icosphere(3, 0.3);
    for (i, v) in body.vertices.iter_mut().enumerate() {
        *v *= 1.0 + 0.01 * ((i * 7919 % 97) as f32 / 97.0); // exact f32 values must survive
    }
    let sheet = TriMesh::grid(11, 7, 0.013);
    for ext in ["obj", "ply", "glb"] {
        for m in [&body, &sheet] {
            let p = dir.path().join(format!("mesh.{ext}"));
            io::write_mesh(&p, m).unwrap();
            assert_eq!(&io::read_mesh(&p).unwrap(), m, "{ext}");
        }
    }
    // Several meshes with colours in one GLB.
    let p = dir.path().join("scene.glb");
    io::write_glb(
        &p,
        &[
            GlbMesh {
                mesh: &body,
                name: "body",
                color: [0.8, 0.6, 0.5, 1.0],
            },
            GlbMesh {
                mesh: &sheet,
                name: "shirt",
                color: [0.1, 0.3, 0.9, 1.0],
            },
        ],
    )
    .unwrap();
    let prims = io::read_glb(&p).unwrap();
    assert_eq!(prims.len(), 2);
    assert_eq!((&prims[0].mesh, &prims[1].mesh), (&body, &sheet));
    assert_eq!(prims[1].base_color, Some([0.1, 0.3, 0.9, 1.0]));
    let merged = io::read_mesh(&p).unwrap();
    assert_eq!(merged.faces.len(), body.faces.len() + sheet.faces.len());
    // Only the final files remain: no temporaries.
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["mesh.glb", "mesh.obj", "mesh.ply", "scene.glb"]);
}

#[test]
fn writers_reject_invalid_meshes_without_touching_the_target() {
    let dir = tempfile::tempdir().unwrap();
    let mut bad = TriMesh::icosphere(0, 1.0);
    bad.faces.push([0, 1, 40]);
    for ext in ["obj", "ply", "glb"] {
        let p = dir.path().join(format!("bad.{ext}"));
        assert!(io::write_mesh(&p, &bad).is_err());
        assert!(!p.exists());
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Every prefix and many single-byte corruptions of valid files must give `Ok` or `Err`,
/// never a panic (the test fails by panicking).
#[test]
fn corrupted_inputs_never_panic() {
    let p = std::path::Path::new("fuzz");
    let sphere = TriMesh::icosphere(1, 1.0);
    let glb = io::encode_glb(&[GlbMesh {
        mesh: &sphere,
        name: "s",
        color: io::DEFAULT_COLOR,
    }])
    .unwrap();
    let ply = io::encode_ply(&sphere).unwrap();
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("obj", std::fs::read(fixture("cube_quads.obj")).unwrap()),
        ("ply", std::fs::read(fixture("tri_ascii.ply")).unwrap()),
        ("ply", std::fs::read(fixture("quad_binary.ply")).unwrap()),
        ("ply", ply),
        ("glb", std::fs::read(fixture("triangle.glb")).unwrap()),
        ("glb", glb),
    ];
    let parse = |kind: &str, b: &[u8]| match kind {
        "obj" => io::parse_obj(&String::from_utf8_lossy(b), p).map(|_| ()),
        "ply" => io::parse_ply(b, p).map(|_| ()),
        _ => io::parse_glb(b, p).map(|_| ()),
    };
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    // GEOM_FUZZ_ITERS raises the number of corruptions per file for a longer local run.
    let iters: usize = std::env::var("GEOM_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(600);
    for (kind, bytes) in &files {
        let step = (bytes.len() / 300).max(1);
        for cut in (0..bytes.len()).step_by(step) {
            let _ = parse(kind, &bytes[..cut]);
        }
        for _ in 0..iters {
            let mut b = bytes.clone();
            for _ in 0..1 + next() % 3 {
                let i = (next() % b.len() as u64) as usize;
                b[i] = match next() % 4 {
                    0 => 0xff,
                    1 => 0,
                    2 => b"9-/ \n.e"[(next() % 7) as usize],
                    _ => next() as u8,
                };
            }
            let _ = parse(kind, &b);
        }
    }
}
