//! Integration tests of `garnet view`: a body mesh and an animated drape as self-contained
//! pages (three.js and the meshes inlined, nothing fetched), a `garnet eval --save-drapes`
//! folder as a heat map, and clean refusals of bad input. The browser check of the pages is
//! .ci/view/check.mjs, run by .ci/run.

mod common;

use std::path::{Path, PathBuf};

use common::{fails, ok, repo, s};

/// Decodes standard base64 (the page's data: URLs).
fn unbase64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let digits: Vec<u8> = text.bytes().filter(|&c| c != b'=').map(value).collect();
    let mut out = Vec::new();
    for chunk in digits.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &d)| n | (u32::from(d) << (18 - 6 * i)));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

/// The text between `start` and the next `end` after it.
fn between<'a>(text: &'a str, start: &str, end: &str) -> &'a str {
    let i = text.find(start).unwrap_or_else(|| panic!("no {start}")) + start.len();
    &text[i..i + text[i..].find(end).unwrap()]
}

/// Checks that `html` fetches nothing: no http(s) URL anywhere in the page, no `src` but
/// data: URLs, and every module of the import map a data: URL whose imports are names of the
/// import map (so nothing resolves to the network or the disk). Returns the modules' names.
fn assert_self_contained(html: &str) -> Vec<String> {
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "the page names a web address"
    );
    for part in html.split(" src=\"").skip(1) {
        assert!(
            part.starts_with("data:"),
            "src to {}",
            &part[..40.min(part.len())]
        );
    }
    assert!(!html.contains("fetch("), "the page fetches");
    let map: serde_json::Value =
        serde_json::from_str(between(html, "<script type=\"importmap\">", "</script>")).unwrap();
    let imports = map["imports"].as_object().unwrap();
    let names: Vec<String> = imports.keys().cloned().collect();
    for (name, url) in imports {
        let b64 = url
            .as_str()
            .unwrap()
            .strip_prefix("data:text/javascript;base64,")
            .unwrap_or_else(|| panic!("{name} is not an inline module"));
        let code = String::from_utf8(unbase64(b64)).unwrap();
        assert!(code.contains("three.js"), "{name}");
        assert!(
            !code.contains("import(") && !code.contains("importScripts("),
            "{name}"
        );
        // Static imports and re-exports: `import{..}from"x"`, `export{..}from"x"`,
        // `import*as X from"x"` (minified or not).
        for quote in ["from\"", "from '", "from \""] {
            let mut parts = code.split(quote);
            let mut before = parts.next().unwrap();
            for part in parts {
                let head = before.trim_end();
                let tail: String = head
                    .chars()
                    .rev()
                    .take(60)
                    .collect::<Vec<_>>()
                    .into_iter()
                    .rev()
                    .collect();
                if head.ends_with('}') || tail.contains("import*as") || tail.contains("import * as")
                {
                    let spec: String = part
                        .chars()
                        .take_while(|&c| c != '"' && c != '\'')
                        .collect();
                    assert!(
                        names.contains(&spec),
                        "{name} imports {spec:?}, not a module of the page"
                    );
                }
                before = part;
            }
        }
    }
    for name in [
        "three",
        "three/addons/controls/OrbitControls.js",
        "three/addons/loaders/GLTFLoader.js",
    ] {
        assert!(names.iter().any(|n| n == name), "no {name}");
    }
    // The viewer imports only the import map's names too.
    let viewer = between(html, "<script type=\"module\">", "</script>");
    for part in viewer.split(" from '").skip(1) {
        let spec = &part[..part.find('\'').unwrap()];
        assert!(names.iter().any(|n| n == spec), "the viewer imports {spec}");
    }
    names
}

/// The scenes' data of a page.
fn page_data(html: &str) -> serde_json::Value {
    let json = between(
        html,
        "<script type=\"application/json\" id=\"garnet-data\">",
        "</script>",
    );
    serde_json::from_str(&json.replace("<\\/", "</")).unwrap()
}

/// The JSON chunk of GLB bytes.
fn glb_json(bytes: &[u8]) -> serde_json::Value {
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + n]).unwrap()
}

fn view(files: &[&Path], out: &Path, extra: &[&str]) -> String {
    let mut args = vec!["view"];
    args.extend(files.iter().map(|f| s(f)));
    args.extend(["--out", s(out)]);
    args.extend_from_slice(extra);
    ok(&args);
    std::fs::read_to_string(out).unwrap()
}

#[test]
fn a_body_and_an_animated_drape_make_self_contained_pages() {
    let tmp = tempfile::tempdir().unwrap();
    let body = tmp.path().join("body.obj");
    ok(&["body", "--out", s(&body)]);
    let html = view(&[&body], &tmp.path().join("body.html"), &[]);
    assert_self_contained(&html);
    let data = page_data(&html);
    let mesh = &data["scenes"][0]["meshes"][0];
    assert_eq!(mesh["name"], "body.obj");
    let glb = unbase64(mesh["glb"].as_str().unwrap());
    assert_eq!(&glb[..4], b"glTF");
    let prims = geom::io::parse_glb(&glb, Path::new("body.glb")).unwrap();
    let read = geom::io::read_mesh(&body).unwrap();
    assert_eq!(prims[0].mesh.vertices.len(), read.vertices.len());

    let anim = tmp.path().join("x.glb");
    let model = repo().join("models/tshirt-local.garnet");
    ok(&[
        "drape",
        "--frames",
        "0..6",
        "--pose-procedural",
        "1",
        "--model",
        s(&model),
        "--out",
        s(&anim),
    ]);
    let out = tmp.path().join("pages/anim.html");
    let html = view(&[&anim, &body], &out, &["--title", "a <walk>"]);
    assert_self_contained(&html);
    assert!(html.contains("<title>a &lt;walk&gt;</title>"));
    let data = page_data(&html);
    let meshes = data["scenes"][0]["meshes"].as_array().unwrap();
    assert_eq!(meshes.len(), 2);
    // The animated GLB is inlined as written: its morph-target animation plays in the page.
    let inlined = unbase64(meshes[0]["glb"].as_str().unwrap());
    assert_eq!(inlined, std::fs::read(&anim).unwrap());
    let doc = glb_json(&inlined);
    assert_eq!(doc["animations"].as_array().unwrap().len(), 1);
    assert!(html.contains("AnimationMixer") && html.contains("id=\"garnet-frame\""));
}

/// A fake `garnet eval --save-drapes` folder: sample 3 and 8 of a sphere garment on a body.
fn saved_drapes(dir: &Path) -> PathBuf {
    let model = dir.join("tshirt");
    std::fs::create_dir_all(&model).unwrap();
    let sim = geom::TriMesh::icosphere(2, 0.3);
    for (index, shift) in [(3u64, 0.01f32), (8, 0.05)] {
        let mut net = sim.clone();
        for (i, v) in net.vertices.iter_mut().enumerate() {
            v.y += shift * (i % 3) as f32;
        }
        let write = |what: &str, m: &geom::TriMesh| {
            geom::io::write_mesh(model.join(format!("{index:06}-{what}.ply")), m).unwrap()
        };
        write("net", &net);
        write("sim", &sim);
        write("dqs", &sim);
        write("body", &geom::TriMesh::icosphere(1, 0.2));
    }
    std::fs::write(
        model.join("samples.csv"),
        "index,pose,e_dist_cm,e_norm_deg,dqs_e_dist_cm\n3,\"walk, 1\",1.0000,2.000,3.0000\n8,walk-2,5.0000,6.000,7.0000\n",
    )
    .unwrap();
    model
}

#[test]
fn a_saved_drape_shows_as_a_heat_map_with_its_scale() {
    let tmp = tempfile::tempdir().unwrap();
    let model = saved_drapes(tmp.path());
    let out = tmp.path().join("worst.html");
    let log = ok(&["view", s(&model), "--out", s(&out)]);
    assert!(log.contains("wrote"), "{log}");
    let html = std::fs::read_to_string(&out).unwrap();
    assert_self_contained(&html);
    // The worst sample by default: 8, whose largest distance is 10 cm.
    assert!(html.contains("tshirt sample 8"));
    let data = page_data(&html);
    let scene = &data["scenes"][0];
    assert_eq!(scene["legend"]["unit"], "cm");
    assert_eq!(scene["legend"]["low"], 0.0);
    assert!((scene["legend"]["high"].as_f64().unwrap() - 10.0).abs() < 1e-3);
    let names: Vec<&str> = scene["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 4, "{names:?}");
    let net = &scene["meshes"][1];
    assert!(net["name"].as_str().unwrap().contains("network"));
    let doc = glb_json(&unbase64(net["glb"].as_str().unwrap()));
    assert!(doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"].is_number());
    assert_eq!(scene["meshes"][2]["visible"], false);

    // A chosen sample and scale.
    let html = view(&[&model], &out, &["--sample", "3", "--max-cm", "2"]);
    let data = page_data(&html);
    assert!(html.contains("tshirt sample 3"));
    assert_eq!(data["scenes"][0]["legend"]["high"], 2.0);
    let err = fails(&["view", s(&model), "--sample", "5", "--out", s(&out)]);
    assert!(
        err.contains("no sample 5") && err.contains("samples.csv"),
        "{err}"
    );
}

#[test]
fn bad_input_is_refused_with_the_file_and_the_problem() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("page.html");
    let missing = tmp.path().join("missing.obj");
    let err = fails(&["view", s(&missing), "--out", s(&out)]);
    assert!(err.contains("missing.obj: no such file"), "{err}");
    let text = tmp.path().join("notes.txt");
    std::fs::write(&text, "not a mesh\n").unwrap();
    let err = fails(&["view", s(&text), "--out", s(&out)]);
    assert!(err.contains("notes.txt: not a mesh file"), "{err}");
    let fake = tmp.path().join("fake.glb");
    std::fs::write(&fake, "not a mesh either").unwrap();
    let err = fails(&["view", s(&fake), "--out", s(&out)]);
    assert!(err.contains("fake.glb: not a readable GLB"), "{err}");
    let ply = tmp.path().join("fake.ply");
    std::fs::write(&ply, "ply\nformat ascii 1.0\nelement vertex 2\n").unwrap();
    let err = fails(&["view", s(&ply), "--out", s(&out)]);
    assert!(err.contains("fake.ply"), "{err}");
    let err = fails(&["view", s(tmp.path()), "--out", s(&out)]);
    assert!(
        err.contains("not a folder of garnet eval --save-drapes"),
        "{err}"
    );
    let err = fails(&["view", s(&missing), "--out", s(&out), "--max-cm=-1"]);
    assert!(err.contains("--max-cm"), "{err}");
    assert!(!out.exists());
}
