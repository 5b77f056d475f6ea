//! Tests of the render calls on small scenes built in place.

use super::*;
use crate::palette::{heat_colors, heat_legend, JEANS_INDIGO, SKIN, SWEATER_RED, TSHIRT_BLUE};
use crate::test_util::{cuboid, icosphere};
use crate::{CaptionPlace, Sheet};

/// Options that leave only the meshes on the background (no floor shadow).
fn plain() -> RenderOptions {
    RenderOptions {
        floor: false,
        ..RenderOptions::default()
    }
}

/// Inclusive bounding box (x0, y0, x1, y1) of the pixels not equal to `bg`.
fn covered_box(im: &Image, bg: [u8; 3]) -> Option<(u32, u32, u32, u32)> {
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for y in 0..im.height {
        for x in 0..im.width {
            if im.pixel(x, y) != bg {
                b = Some(match b {
                    None => (x, y, x, y),
                    Some((a, c, d, e)) => (a.min(x), c.min(y), d.max(x), e.max(y)),
                });
            }
        }
    }
    b
}

/// A quad in the plane z = `z`, from (x0, y0) to (x1, y1), facing +Z.
fn quad(x0: f32, y0: f32, x1: f32, y1: f32, z: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let v = vec![
        Vec3::new(x0, y0, z),
        Vec3::new(x1, y0, z),
        Vec3::new(x1, y1, z),
        Vec3::new(x0, y1, z),
    ];
    (v, vec![[0, 1, 2], [0, 2, 3]])
}

#[test]
fn sphere_covers_pi_r_squared() {
    let (v, f) = icosphere(Vec3::new(0.1, 1.0, -0.2), 0.5, 4);
    let opts = RenderOptions {
        framing: Framing::Fixed {
            center: Vec3::new(0.1, 1.0, -0.2),
            pixels_per_metre: 150.0,
        },
        ..plain()
    };
    for view in [View::Front, View::Side, View::Yaw(0.7)] {
        let im = render_view(&[RenderMesh::new(&v, &f, SKIN)], view, (200, 200), &opts).unwrap();
        let covered = im.count_not(opts.background) as f32;
        let expected = std::f32::consts::PI * 75.0 * 75.0;
        let rel = (covered - expected).abs() / expected;
        assert!(rel < 0.03, "{view:?}: {covered} px vs {expected}");
    }
}

#[test]
fn auto_framing_fits_with_margin() {
    let (v, f) = icosphere(Vec3::new(3.0, -2.0, 5.0), 0.25, 3);
    let im = render_view(
        &[RenderMesh::new(&v, &f, SKIN)],
        View::Front,
        (120, 100),
        &plain(),
    )
    .unwrap();
    let (x0, y0, x1, y1) = covered_box(&im, plain().background).unwrap();
    // Height 100 px minus 5 px margins: the sphere spans about 90 px, centred.
    assert!(
        (y0 as i32 - 5).abs() <= 1 && (y1 as i32 - 94).abs() <= 1,
        "{y0} {y1}"
    );
    assert!(((x0 + x1) as i32 - 119).abs() <= 2, "{x0} {x1}");
}

#[test]
fn nearer_mesh_occludes_farther() {
    let (va, fa) = quad(-0.5, -0.5, 0.5, 0.5, 0.0);
    let (vb, fb) = quad(-0.2, -0.2, 0.2, 0.2, 0.1);
    let red = [200, 30, 30];
    let blue = [30, 30, 200];
    let scene = |order_blue_first: bool| {
        let a = RenderMesh::new(&va, &fa, red).with_shading(Shading::Unlit);
        let b = RenderMesh::new(&vb, &fb, blue).with_shading(Shading::Unlit);
        if order_blue_first {
            vec![b, a]
        } else {
            vec![a, b]
        }
    };
    for order in [false, true] {
        let meshes = scene(order);
        let front = render_view(&meshes, View::Front, (100, 100), &plain()).unwrap();
        assert_eq!(front.pixel(50, 50), blue);
        assert_eq!(front.pixel(50, 15), red);
        // From the back the big quad hides the small one (its inside is unlit too).
        let back = render_view(&meshes, View::Back, (100, 100), &plain()).unwrap();
        assert_eq!(back.pixel(50, 50), red);
    }
}

#[test]
fn depth_bias_lets_a_garment_win() {
    let (skin_v, skin_f) = quad(-0.5, -0.5, 0.5, 0.5, 0.0);
    // The "garment" lies 1 mm behind the skin (a chord of a curved surface would).
    let (cloth_v, cloth_f) = quad(-0.3, -0.3, 0.3, 0.3, -0.001);
    let cloth = [30, 30, 200];
    let skin = RenderMesh::new(&skin_v, &skin_f, SKIN).with_shading(Shading::Unlit);
    let garment = RenderMesh::new(&cloth_v, &cloth_f, cloth).with_shading(Shading::Unlit);
    let no_bias = render_view(&[skin, garment], View::Front, (64, 64), &plain()).unwrap();
    assert_eq!(no_bias.pixel(32, 32), SKIN);
    let biased = render_view(
        &[skin, garment.with_depth_bias(0.003)],
        View::Front,
        (64, 64),
        &plain(),
    )
    .unwrap();
    assert_eq!(biased.pixel(32, 32), cloth);
}

#[test]
fn box_aspect_in_front_and_side_views() {
    // 0.2 m wide (x), 1.0 m tall (y), 0.5 m deep (z).
    let (v, f) = cuboid(Vec3::new(-0.1, 0.0, -0.25), Vec3::new(0.1, 1.0, 0.25));
    let opts = RenderOptions {
        margin: 0.1,
        ..plain()
    };
    let panels = render_panels(
        &[RenderMesh::new(&v, &f, TSHIRT_BLUE)],
        &[View::Front, View::Side],
        (200, 200),
        &opts,
    )
    .unwrap();
    let front = covered_box(&panels[0], opts.background).unwrap();
    let side = covered_box(&panels[1], opts.background).unwrap();
    let size = |b: (u32, u32, u32, u32)| ((b.2 - b.0 + 1) as f32, (b.3 - b.1 + 1) as f32);
    let (fw, fh) = size(front);
    let (sw, sh) = size(side);
    // Height 1 m fills 160 px; widths 0.2 m and 0.5 m at the same scale.
    assert!(
        (fh - 160.0).abs() <= 2.0 && (sh - 160.0).abs() <= 2.0,
        "{fh} {sh}"
    );
    assert!((fw - 32.0).abs() <= 2.0, "{fw}");
    assert!((sw - 80.0).abs() <= 2.0, "{sw}");
    // Front and side line up: same top and bottom rows.
    assert_eq!((front.1, front.3), (side.1, side.3));
    // Side by side in one picture.
    let both = render_views_with(
        &[RenderMesh::new(&v, &f, TSHIRT_BLUE)],
        &[View::Front, View::Side],
        (200, 200),
        &opts,
    )
    .unwrap();
    assert_eq!((both.width, both.height), (400, 200));
    let mut right = Image::new(200, 200, [0; 3]);
    right.blit(&both, -200, 0);
    assert_eq!(right, panels[1]);
}

#[test]
fn views_face_the_expected_way() {
    // A small marker on the +X side: visible on screen right from the front, centred from
    // the side, on screen left from the back.
    let (bv, bf) = cuboid(Vec3::new(-0.3, 0.0, -0.1), Vec3::new(0.3, 0.2, 0.1));
    let (mv, mf) = cuboid(Vec3::new(0.25, 0.18, -0.05), Vec3::new(0.3, 0.3, 0.05));
    let marker = [250, 0, 0];
    let meshes = [
        RenderMesh::new(&bv, &bf, [90; 3]).with_shading(Shading::Unlit),
        RenderMesh::new(&mv, &mf, marker).with_shading(Shading::Unlit),
    ];
    let opts = RenderOptions {
        outline: false,
        ..plain()
    };
    let find = |view| {
        let im = render_view(&meshes, view, (120, 120), &opts).unwrap();
        let xs: Vec<u32> = (0..120)
            .flat_map(|y| (0..120).map(move |x| (x, y)))
            .filter(|&(x, y)| im.pixel(x, y) == marker)
            .map(|(x, _)| x)
            .collect();
        xs.iter().sum::<u32>() as f32 / xs.len() as f32
    };
    assert!(find(View::Front) > 90.0);
    assert!((find(View::Side) - 60.0).abs() < 10.0);
    assert!(find(View::Back) < 30.0);
}

#[test]
fn vertex_and_face_colours() {
    let (v, f) = quad(-0.5, -0.5, 0.5, 0.5, 0.0);
    let vc = heat_colors(&[0.0, 1.0, 1.0, 0.0], 0.0, 1.0);
    let m = RenderMesh::new(&v, &f, SKIN)
        .with_vertex_colors(&vc)
        .with_shading(Shading::Unlit);
    let opts = RenderOptions {
        outline: false,
        ..plain()
    };
    let im = render_view(&[m], View::Front, (64, 64), &opts).unwrap();
    // Left edge low (blue), right edge high (red).
    let (l, r) = (im.pixel(5, 32), im.pixel(58, 32));
    assert!(l[2] > l[0] && r[0] > r[2], "{l:?} {r:?}");
    let fc = [[10, 200, 10], [200, 10, 200]];
    let m = RenderMesh::new(&v, &f, SKIN)
        .with_face_colors(&fc)
        .with_shading(Shading::Unlit);
    let im = render_view(&[m], View::Front, (64, 64), &opts).unwrap();
    // Face 0 is the lower-right triangle.
    assert_eq!(im.pixel(50, 50), fc[0]);
    assert_eq!(im.pixel(12, 12), fc[1]);
}

#[test]
fn bad_input_is_an_error_or_skipped() {
    let (v, f) = icosphere(Vec3::ZERO, 0.5, 1);
    let opts = RenderOptions::default();
    // Out-of-range index: an error, not a panic.
    let bad = [[0, 1, 999]];
    let err = render_view(
        &[
            RenderMesh::new(&v, &f, SKIN),
            RenderMesh::new(&v, &bad, SKIN),
        ],
        View::Front,
        (32, 32),
        &opts,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            RenderError::FaceIndex {
                mesh: 1,
                face: 0,
                index: 999,
                ..
            }
        ),
        "{err}"
    );
    assert!(render_view(&[], View::Front, (0, 10), &opts).is_err());
    assert!(render_view(&[], View::Front, (10, 100_000), &opts).is_err());
    let fixed = RenderOptions {
        framing: Framing::Fixed {
            center: Vec3::ZERO,
            pixels_per_metre: f32::NAN,
        },
        ..opts
    };
    assert!(render_view(&[], View::Front, (8, 8), &fixed).is_err());
    let short = [[0u8; 3]; 2];
    assert!(render_view(
        &[RenderMesh::new(&v, &f, SKIN).with_vertex_colors(&short)],
        View::Front,
        (8, 8),
        &opts
    )
    .is_err());

    // Empty scenes and empty meshes render the background.
    let empty = render_views(&[], &[View::Front, View::Side], (16, 16)).unwrap();
    assert_eq!((empty.width, empty.height), (32, 16));
    assert_eq!(empty.count_not(opts.background), 0);
    let none: [[u32; 3]; 0] = [];
    assert!(render_view(
        &[RenderMesh::new(&[], &none, SKIN)],
        View::Back,
        (8, 8),
        &opts
    )
    .is_ok());
    assert!(render_panels(&[], &[], (8, 8), &opts).unwrap().is_empty());

    // Degenerate faces, NaN and infinite vertices are skipped; the rest still draws.
    let mut v2 = v.clone();
    v2.push(Vec3::NAN);
    v2.push(Vec3::new(f32::INFINITY, 0.0, 0.0));
    v2.push(Vec3::new(1e30, -1e30, 0.0));
    let n = v.len() as u32;
    let mut f2 = f.clone();
    f2.extend([
        [0, 0, 0],
        [0, 1, 1],
        [0, n, 1],
        [n + 1, 2, 3],
        [n + 2, 4, 5],
        [n, n + 1, n + 2],
    ]);
    // (Auto framing would include the huge finite vertex; fix the framing instead.)
    let fixed = RenderOptions {
        framing: Framing::Fixed {
            center: Vec3::ZERO,
            pixels_per_metre: 50.0,
        },
        ..plain()
    };
    let im = render_view(
        &[RenderMesh::new(&v2, &f2, SKIN)],
        View::Front,
        (64, 64),
        &fixed,
    )
    .unwrap();
    let expected = std::f32::consts::PI * 25.0 * 25.0;
    assert!((im.count_not(plain().background) as f32 - expected).abs() < 0.1 * expected);
    render_view(
        &[RenderMesh::new(&v2, &f2, SKIN)],
        View::Front,
        (64, 64),
        &opts,
    )
    .unwrap();
    // Collinear and single-point scenes.
    let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
    render_views(
        &[RenderMesh::new(&line, &[[0, 1, 2]], SKIN)],
        &[View::Front, View::Side],
        (16, 16),
    )
    .unwrap();
    let point = [Vec3::ONE; 3];
    render_views(
        &[RenderMesh::new(&point, &[[0, 1, 2]], SKIN)],
        &[View::Yaw(0.3)],
        (16, 16),
    )
    .unwrap();
    let nans = [Vec3::NAN; 3];
    render_views(
        &[RenderMesh::new(&nans, &[[0, 1, 2]], SKIN)],
        &[View::Front],
        (16, 16),
    )
    .unwrap();
    // A non-finite yaw draws nothing but does not panic.
    render_views(
        &[RenderMesh::new(&v, &f, SKIN)],
        &[View::Yaw(f32::NAN)],
        (16, 16),
    )
    .unwrap();
    assert!(render_view(&[], View::Front, (8192, 8192), &opts).is_err());
}

#[test]
fn rendered_png_round_trips() {
    let (v, f) = icosphere(Vec3::ZERO, 0.5, 2);
    let im = render_views(
        &[RenderMesh::new(&v, &f, SWEATER_RED)],
        &[View::Front, View::Side],
        (48, 40),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.png");
    im.save_png(&path).unwrap();
    assert_eq!(Image::from_png(&path).unwrap(), im);
}

#[test]
fn two_sided_open_surface_shows_its_inside() {
    // A single quad facing +Z seen from the back is still drawn (darker inside).
    let (v, f) = quad(-0.5, -0.5, 0.5, 0.5, 0.0);
    let m = [RenderMesh::new(&v, &f, [200, 200, 200])];
    let front = render_view(&m, View::Front, (32, 32), &plain()).unwrap();
    let back = render_view(&m, View::Back, (32, 32), &plain()).unwrap();
    let (a, b) = (front.pixel(16, 16), back.pixel(16, 16));
    assert_ne!(b, plain().background);
    assert!(b[0] < a[0], "{a:?} {b:?}");
}

/// A body-sized stretched UV sphere with about 27k triangles (`n` rings and segments).
fn body_like(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for i in 0..=n {
        let th = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..n {
            let ph = std::f32::consts::TAU * j as f32 / n as f32;
            let wobble = 1.0 + 0.15 * (5.0 * th).sin() * (3.0 * ph).cos();
            v.push(Vec3::new(
                0.2 * wobble * th.sin() * ph.cos(),
                0.85 - 0.85 * th.cos(),
                0.12 * wobble * th.sin() * ph.sin(),
            ));
        }
    }
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let a = i * n + j;
            let b = i * n + (j + 1) % n;
            let (c, d) = (a + n, b + n);
            f.push([a, c, d]);
            f.push([a, d, b]);
        }
    }
    (v, f)
}

/// Prints the time of a 27k-triangle mesh at 512x512 on one thread and on all threads.
/// Run with `cargo test --release -p render -- --ignored --nocapture timing`.
#[test]
#[ignore]
fn timing_27k_triangles_512() {
    let (v, f) = body_like(116);
    let mesh = [RenderMesh::new(&v, &f, SKIN)];
    let time = |threads: usize, opts: &RenderOptions| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            render_view(&mesh, View::Front, (512, 512), opts).unwrap();
            let runs = 10;
            let t = std::time::Instant::now();
            for _ in 0..runs {
                std::hint::black_box(render_view(&mesh, View::Front, (512, 512), opts).unwrap());
            }
            t.elapsed().as_secs_f64() * 1000.0 / runs as f64
        })
    };
    let full = RenderOptions::default();
    println!("{} triangles at 512x512, supersample 2", f.len());
    println!(
        "1 thread: {:.1} ms, all threads: {:.1} ms",
        time(1, &full),
        time(0, &full)
    );
    let bare = RenderOptions {
        ambient_occlusion: false,
        outline: false,
        floor: false,
        ..full
    };
    println!(
        "1 thread without AO/outline/floor: {:.1} ms",
        time(1, &bare)
    );
    let ss1 = RenderOptions {
        supersample: 1,
        ..bare
    };
    println!("1 thread, supersample 1, bare: {:.1} ms", time(1, &ss1));
    let ss3 = RenderOptions {
        supersample: 3,
        ..full
    };
    println!("1 thread, supersample 3: {:.1} ms", time(1, &ss3));
}

/// Writes a check picture to /tmp/render_check.png (run with `--ignored`).
#[test]
#[ignore]
fn write_check_picture() {
    let (sv, sf) = icosphere(Vec3::new(-0.3, 0.3, 0.0), 0.3, 4);
    let (bv, bf) = cuboid(Vec3::new(0.1, 0.0, -0.2), Vec3::new(0.5, 0.9, 0.2));
    let (gv, gf) = body_like(116);
    let gv: Vec<Vec3> = gv.iter().map(|p| *p + Vec3::new(0.0, 0.0, 0.0)).collect();
    // An open "garment": the middle band of the body-like mesh pushed out by 1 cm.
    let n = 116u32;
    let band: Vec<[u32; 3]> = gf
        .iter()
        .copied()
        .filter(|t| t.iter().all(|&i| (i / n) > 30 && (i / n) < 70))
        .collect();
    let cloth_v: Vec<Vec3> = gv
        .iter()
        .map(|p| Vec3::new(p.x * 1.08, p.y, p.z * 1.1))
        .collect();
    let err: Vec<f32> = gv
        .iter()
        .map(|p| (p.y - 0.4).abs() * 2.0 + p.x.abs())
        .collect();
    let heat = heat_colors(&err, 0.0, 1.0);
    let scene = [
        RenderMesh::new(&sv, &sf, SKIN),
        RenderMesh::new(&bv, &bf, JEANS_INDIGO),
    ];
    let body = [
        RenderMesh::new(&gv, &gf, SKIN),
        RenderMesh::new(&cloth_v, &band, TSHIRT_BLUE).with_depth_bias(0.003),
    ];
    let views = [View::Front, View::Side, View::Back, View::Yaw(0.6)];
    let mut sheet = Sheet::new(4).with_title("render check: sphere + box, body-like + open band");
    for (p, v) in render_panels(&scene, &views, (256, 256), &RenderOptions::default())
        .unwrap()
        .into_iter()
        .zip(views)
    {
        sheet.push(p, v.name());
    }
    for (p, v) in render_panels(&body, &views, (256, 256), &RenderOptions::default())
        .unwrap()
        .into_iter()
        .zip(views)
    {
        sheet.push(p, v.name());
    }
    let hm = [RenderMesh::new(&gv, &gf, SKIN)
        .with_vertex_colors(&heat)
        .with_shading(Shading::Soft)];
    sheet.push(
        render_view(&hm, View::Front, (256, 256), &RenderOptions::default()).unwrap(),
        "heat, soft",
    );
    let hm = [RenderMesh::new(&gv, &gf, SKIN)
        .with_vertex_colors(&heat)
        .with_shading(Shading::Unlit)];
    sheet.push(
        render_view(&hm, View::Front, (256, 256), &RenderOptions::default()).unwrap(),
        "heat, unlit",
    );
    let mut legend = Image::new(256, 256, crate::palette::BACKGROUND);
    legend.blit(&heat_legend(220, "0 cm", "2 cm"), 18, 110);
    sheet.push(legend, "legend");
    let no_aa = RenderOptions {
        supersample: 1,
        ambient_occlusion: false,
        outline: false,
        floor: false,
        ..RenderOptions::default()
    };
    sheet.push(
        render_view(&body, View::Front, (256, 256), &no_aa).unwrap(),
        "no AA/AO/outline",
    );
    // An open curtain with folds in front of a sphere: folds, two-sided shading, AO.
    let (cv, cf) = curtain(80);
    let (sv2, sf2) = icosphere(Vec3::new(0.0, 0.5, -0.3), 0.25, 4);
    let folds = [
        RenderMesh::new(&sv2, &sf2, SKIN),
        RenderMesh::new(&cv, &cf, SWEATER_RED),
    ];
    for v in [View::Front, View::Side, View::Back, View::Yaw(-0.8)] {
        sheet.push(
            render_view(&folds, v, (256, 256), &RenderOptions::default()).unwrap(),
            format!("curtain {}", v.name()),
        );
    }
    let sheet = sheet.with_captions(CaptionPlace::Below);
    sheet.save_png("/tmp/render_check.png").unwrap();
}

/// An open 1 m x 1 m sheet hanging in the XY plane with vertical folds whose depth grows
/// downwards, `n x n` quads.
fn curtain(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (j as f32 / n as f32 - 0.5, 1.0 - i as f32 / n as f32);
            let amp = 0.01 + 0.05 * (1.0 - y);
            v.push(Vec3::new(x, y, amp * (x * 28.0).sin()));
        }
    }
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
            f.push([a, c, d]);
            f.push([a, d, b]);
        }
    }
    (v, f)
}
