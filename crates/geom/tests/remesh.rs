//! Isotropic remeshing: topology kept, boundaries kept, quality reached, sources usable.

use std::f32::consts::TAU;
use std::time::Instant;

use geom::adjacency::{boundary_loops, check_manifold};
use geom::remesh::{
    isotropic_remesh, mesh_quality, BoundaryMode, MeshQuality, RemeshOptions, Remeshed,
};
use geom::{Bvh, TriMesh};
use glam::Vec3;

/// Deterministic uniform numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// An open tube around +Y: `n` vertices around, `rows` rings from y = 0 to `height`, radius
/// `radius(theta, y)`, optional tangential jitter (fraction of the spacing); outward faces.
fn tube(
    n: usize,
    rows: usize,
    height: f32,
    jitter: f32,
    radius: impl Fn(f32, f32) -> f32,
) -> TriMesh {
    let mut rng = Rng(99);
    let mut vertices = Vec::with_capacity(n * rows);
    for j in 0..rows {
        for i in 0..n {
            let inner = j > 0 && j + 1 < rows;
            let (dt, dy) = if inner {
                (jitter * (rng.next() - 0.5), jitter * (rng.next() - 0.5))
            } else {
                (0.0, 0.0)
            };
            let t = TAU * (i as f32 + dt) / n as f32;
            let y = height * (j as f32 + dy) / (rows - 1) as f32;
            let r = radius(t, y);
            vertices.push(Vec3::new(r * t.cos(), y, -r * t.sin()));
        }
    }
    let id = |i: usize, j: usize| (j * n + i % n) as u32;
    let mut faces = Vec::new();
    for j in 0..rows - 1 {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1));
            if (i + j) % 2 == 0 {
                faces.extend([[a, b, d], [a, d, c]]);
            } else {
                faces.extend([[a, b, c], [b, d, c]]);
            }
        }
    }
    let mut m = TriMesh::new(vertices, faces);
    // Outward: the first face's normal points away from the axis.
    let [p, q, r] = m.faces[0].map(|v| m.vertices[v as usize]);
    if (q - p).cross(r - p).dot(Vec3::new(p.x, 0.0, p.z)) < 0.0 {
        m.flip_faces();
    }
    m
}

/// A unit grid sheet (spacing 0.025, 1 m square) without the faces of the central square
/// `|x|, |z| < 0.2`.
fn grid_with_hole() -> TriMesh {
    let mut g = TriMesh::grid(41, 41, 0.025);
    let v = g.vertices.clone();
    g.faces.retain(|f| {
        let c = f.iter().map(|&i| v[i as usize]).sum::<Vec3>() / 3.0;
        c.x.abs() > 0.2 || c.z.abs() > 0.2
    });
    g
}

/// A unit icosphere (level 4) without the faces near four points: genus 0, four loops.
fn sphere_with_four_holes() -> TriMesh {
    let mut s = TriMesh::icosphere(4, 1.0);
    let centres = [Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::NEG_X];
    let v = s.vertices.clone();
    s.faces.retain(|f| {
        let c = (f.iter().map(|&i| v[i as usize]).sum::<Vec3>() / 3.0).normalize();
        centres.iter().all(|k| c.dot(*k) < 0.9)
    });
    s
}

fn perimeter(m: &TriMesh, l: &[u32]) -> f32 {
    (0..l.len())
        .map(|i| m.vertices[l[i] as usize].distance(m.vertices[l[(i + 1) % l.len()] as usize]))
        .sum()
}

/// Sorted perimeters of the boundary loops.
fn perimeters(m: &TriMesh) -> Vec<f32> {
    let mut p: Vec<f32> = boundary_loops(m.vertices.len(), &m.faces)
        .unwrap()
        .iter()
        .map(|l| perimeter(m, l))
        .collect();
    p.sort_by(f32::total_cmp);
    p
}

/// Manifold, consistently oriented, no unreferenced vertex, same Euler characteristic and
/// loop count as `input`; returns the quality report.
fn check_topology(input: &TriMesh, out: &Remeshed) -> MeshQuality {
    let m = &out.mesh;
    m.validate().unwrap();
    let r = check_manifold(m.vertices.len(), &m.faces).unwrap();
    assert!(r.is_ok(), "{r}");
    assert_eq!(r.unreferenced_vertices, 0, "{r}");
    let r0 = check_manifold(input.vertices.len(), &input.faces).unwrap();
    assert_eq!(
        r.euler_characteristic(),
        r0.euler_characteristic() - r0.unreferenced_vertices as i64,
        "{r}"
    );
    let loops = |m: &TriMesh| boundary_loops(m.vertices.len(), &m.faces).unwrap().len();
    assert_eq!(loops(m), loops(input));
    assert_eq!(out.stats.boundary_loops, loops(input));
    assert_eq!(out.source_face.len(), m.vertices.len());
    assert_eq!(out.source_bary.len(), m.vertices.len());
    mesh_quality(m).unwrap()
}

/// Edge lengths mostly within [0.7 L, 1.4 L] and no thin triangles.
fn check_quality(q: &MeshQuality, l: f32, min_angle_p1: f32) {
    assert!(q.edge_p5 >= 0.7 * l && q.edge_p95 <= 1.4 * l, "L={l}: {q}");
    assert!((q.edge_mean / l - 1.0).abs() < 0.15, "L={l}: {q}");
    assert!(q.min_angle_p1 > min_angle_p1, "L={l}: {q}");
}

/// Every source point reproduces its vertex (all vertices lie on the input).
fn check_sources(input: &TriMesh, out: &Remeshed, tol: f32) {
    let back = out.interpolate(&input.faces, &input.vertices).unwrap();
    for (i, (p, q)) in out.mesh.vertices.iter().zip(&back).enumerate() {
        assert!(p.distance(*q) < tol, "vertex {i}: {p} vs source {q}");
        let w = out.source_bary[i];
        assert!(w.iter().all(|&x| x >= -1e-6) && (w.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    }
}

#[test]
fn sphere_stays_closed_on_the_sphere() {
    let s = TriMesh::icosphere(4, 1.0);
    let l = 0.05;
    let t = Instant::now();
    let out = isotropic_remesh(&s, &RemeshOptions::new(l)).unwrap();
    let dt = t.elapsed();
    let q = check_topology(&s, &out);
    println!(
        "sphere L={l}: {:.3} s, {:?}\n  {q}",
        dt.as_secs_f64(),
        out.stats
    );
    println!("  valence {:?}", q.valence_histogram);
    assert!(q.boundary_valence_histogram.is_empty());
    check_quality(&q, l, 20.0);
    let worst = out
        .mesh
        .vertices
        .iter()
        .map(|v| (v.length() - 1.0).abs())
        .fold(0.0, f32::max);
    assert!(worst < 2e-3, "{worst}");
    check_sources(&s, &out, 1e-5);
    assert!(q.regular_fraction() > 0.6, "{q}");
    // The BVH projection against brute force: each source is the closest input point.
    for (i, v) in out.mesh.vertices.iter().enumerate().step_by(37) {
        let r = geom::bvh::closest_point_brute(&s.vertices, &s.faces, *v).unwrap();
        let f = s.faces[out.source_face[i] as usize];
        let w = out.source_bary[i];
        let q: Vec3 = (0..3).map(|c| w[c] * s.vertices[f[c] as usize]).sum();
        assert!((q.distance(*v) - r.distance).abs() < 1e-6);
    }
}

#[test]
fn open_cylinder_keeps_its_two_loops() {
    let (radius, height) = (0.3, 0.8);
    let c = tube(64, 17, height, 0.0, |_, _| radius);
    let l = 0.04;
    let out = isotropic_remesh(&c, &RemeshOptions::new(l)).unwrap();
    let q = check_topology(&c, &out);
    println!("cylinder L={l}: {:?}\n  {q}", out.stats);
    check_quality(&q, l, 20.0);
    let (p_in, p_out) = (perimeters(&c), perimeters(&out.mesh));
    assert_eq!(p_out.len(), 2);
    for (a, b) in p_in.iter().zip(&p_out) {
        assert!((a - b).abs() < 0.01 * a, "perimeter {a} -> {b}");
    }
    // Boundary vertices on the rims, about L apart; every vertex on the input surface.
    let loops = boundary_loops(out.mesh.vertices.len(), &out.mesh.faces).unwrap();
    for lp in &loops {
        let y0 = out.mesh.vertices[lp[0] as usize].y;
        assert!(y0.abs() < 1e-6 || (y0 - height).abs() < 1e-6);
        for &v in lp {
            let p = out.mesh.vertices[v as usize];
            assert!((p.y - y0).abs() < 1e-6, "{p}");
        }
        let spacing = perimeter(&out.mesh, lp) / lp.len() as f32;
        assert!((spacing / l - 1.0).abs() < 0.25, "{spacing}");
    }
    check_sources(&c, &out, 1e-5);
}

#[test]
fn grid_keeps_its_hole_and_corners() {
    let g = grid_with_hole();
    let l = 0.05;
    let out = isotropic_remesh(&g, &RemeshOptions::new(l)).unwrap();
    let q = check_topology(&g, &out);
    println!("grid with hole L={l}: {:?}\n  {q}", out.stats);
    check_quality(&q, l, 20.0);
    let m = &out.mesh;
    for f in &m.faces {
        let c = f.iter().map(|&i| m.vertices[i as usize]).sum::<Vec3>() / 3.0;
        assert!(
            c.x.abs() > 0.2 || c.z.abs() > 0.2,
            "face over the hole at {c}"
        );
    }
    // The eight corners (outer and hole) are kept exactly, the sheet stays flat.
    for h in [0.5f32, 0.2] {
        for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            let corner = Vec3::new(sx * h, 0.0, sz * h);
            assert!(
                m.vertices.iter().any(|v| v.distance(corner) < 1e-6),
                "corner {corner} lost"
            );
        }
    }
    assert!(m.vertices.iter().all(|v| v.y.abs() < 1e-6));
    let (p_in, p_out) = (perimeters(&g), perimeters(m));
    for (a, b) in p_in.iter().zip(&p_out) {
        assert!((a - b).abs() < 1e-4 * a, "perimeter {a} -> {b}");
    }
}

#[test]
fn genus_zero_with_four_loops_stays_so() {
    let s = sphere_with_four_holes();
    let out = isotropic_remesh(&s, &RemeshOptions::new(0.06)).unwrap();
    let q = check_topology(&s, &out);
    println!("sphere with 4 holes: {:?}\n  {q}", out.stats);
    let r = check_manifold(out.mesh.vertices.len(), &out.mesh.faces).unwrap();
    assert_eq!(r.euler_characteristic(), -2);
    let (p_in, p_out) = (perimeters(&s), perimeters(&out.mesh));
    for (a, b) in p_in.iter().zip(&p_out) {
        assert!((a - b).abs() < 0.02 * a, "perimeter {a} -> {b}");
    }
    check_sources(&s, &out, 1e-5);
}

#[test]
fn remeshing_is_deterministic() {
    let c = tube(40, 12, 0.5, 0.4, |t, y| 0.2 + 0.03 * (3.0 * t).sin() * y);
    let o = RemeshOptions::new(0.03);
    let a = isotropic_remesh(&c, &o).unwrap();
    let b = isotropic_remesh(&c, &o).unwrap();
    assert_eq!(a.mesh, b.mesh);
    assert_eq!(a.source_face, b.source_face);
    assert_eq!(a.source_bary, b.source_bary);
    assert_eq!(a.stats, b.stats);
}

#[test]
fn coarse_to_fine_and_fine_to_coarse() {
    // Coarse input (edges about 0.55 m) to L = 0.1: many splits, vertices on the faceted input.
    let coarse = TriMesh::icosphere(1, 1.0);
    let l = 0.1;
    let out = isotropic_remesh(&coarse, &RemeshOptions::new(l)).unwrap();
    let q = check_topology(&coarse, &out);
    println!("coarse to fine: {:?}\n  {q}", out.stats);
    check_quality(&q, l, 15.0);
    let bvh = Bvh::from_mesh(&coarse).unwrap();
    for v in &out.mesh.vertices {
        assert!(bvh.closest_point(*v).unwrap().distance < 1e-5);
    }
    check_sources(&coarse, &out, 1e-5);

    // Fine input (edges about 0.04 m) to L = 0.25.
    let fine = TriMesh::icosphere(5, 1.0);
    let l = 0.25;
    let out = isotropic_remesh(&fine, &RemeshOptions::new(l)).unwrap();
    let q = check_topology(&fine, &out);
    println!("fine to coarse: {:?}\n  {q}", out.stats);
    check_quality(&q, l, 20.0);
    assert!(out.mesh.vertices.len() < fine.vertices.len() / 20);

    // An open tube both ways too.
    for (n, l) in [(16usize, 0.03f32), (120, 0.08)] {
        let t = tube(n, n / 2, 0.5, 0.0, |_, _| 0.2);
        let out = isotropic_remesh(&t, &RemeshOptions::new(l)).unwrap();
        let q = check_topology(&t, &out);
        println!("tube n={n} L={l}: {:?}\n  {q}", out.stats);
        check_quality(&q, l, 15.0);
    }
}

#[test]
fn fixed_boundary_is_kept_exactly() {
    let g = grid_with_hole();
    let o = RemeshOptions {
        boundary: BoundaryMode::Fixed,
        ..RemeshOptions::new(0.04)
    };
    let out = isotropic_remesh(&g, &o).unwrap();
    check_topology(&g, &out);
    let key = |m: &TriMesh| {
        let mut v: Vec<[i64; 3]> = boundary_loops(m.vertices.len(), &m.faces)
            .unwrap()
            .concat()
            .iter()
            .map(|&i| {
                m.vertices[i as usize]
                    .to_array()
                    .map(|x| (x * 1e6).round() as i64)
            })
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(key(&g), key(&out.mesh));
    for mode in [BoundaryMode::Resample, BoundaryMode::Slide] {
        let o = RemeshOptions {
            boundary: mode,
            ..RemeshOptions::new(0.04)
        };
        let out = isotropic_remesh(&g, &o).unwrap();
        check_topology(&g, &out);
        assert_ne!(key(&g), key(&out.mesh), "{mode:?}");
    }
}

#[test]
fn options_and_bad_input() {
    let s = TriMesh::icosphere(2, 1.0);
    for l in [0.0, -1.0, f32::NAN, f32::INFINITY, 1e-5] {
        assert!(isotropic_remesh(&s, &RemeshOptions::new(l)).is_err(), "{l}");
    }
    assert!(isotropic_remesh(&TriMesh::default(), &RemeshOptions::new(0.1)).is_err());
    let mut bad = s.clone();
    bad.faces[0].swap(1, 2);
    let e = isotropic_remesh(&bad, &RemeshOptions::new(0.1)).unwrap_err();
    assert!(e.to_string().contains("inconsistently oriented"), "{e}");
    // Zero iterations: the input with its own sources; unreferenced vertices are dropped.
    let mut extra = s.clone();
    extra.vertices.push(Vec3::splat(5.0));
    let o = RemeshOptions {
        iterations: 0,
        ..RemeshOptions::new(0.1)
    };
    let out = isotropic_remesh(&extra, &o).unwrap();
    assert_eq!(out.mesh, s);
    check_sources(&s, &out, 1e-6);
    // Without projection vertices leave the sphere a little but the mesh is fine.
    let o = RemeshOptions {
        project: false,
        ..RemeshOptions::new(0.1)
    };
    let out = isotropic_remesh(&s, &o).unwrap();
    check_topology(&s, &out);
}

/// A torso-sized bumpy tube of about 27k jittered triangles remeshed to about 10k vertices.
/// Prints the time (not asserted: shared machines).
#[test]
fn performance_27k_triangles() {
    let t = tube(150, 90, 0.7, 0.5, |th, y| {
        0.15 + 0.02 * (2.0 * th).cos() + 0.01 * (9.0 * y).sin() * (3.0 * th).sin()
    });
    let l = 0.0087;
    let t0 = Instant::now();
    let out = isotropic_remesh(&t, &RemeshOptions::new(l)).unwrap();
    let dt = t0.elapsed().as_secs_f64();
    let q = check_topology(&t, &out);
    println!(
        "27k: {} input triangles -> {} vertices / {} triangles in {dt:.3} s \
         ({} threads available), {:?}\n  input: {}\n  output: {q}",
        t.faces.len(),
        out.mesh.vertices.len(),
        out.mesh.faces.len(),
        rayon::current_num_threads(),
        out.stats,
        mesh_quality(&t).unwrap(),
    );
    check_quality(&q, l, 20.0);
    check_sources(&t, &out, 1e-5);
}

/// Extreme and in-between target lengths on irregular open meshes: topology always kept.
#[test]
fn many_lengths_keep_topology() {
    let tube = tube(40, 20, 0.5, 0.6, |t, y| 0.15 + 0.04 * (2.0 * t).sin() * y);
    let holes = sphere_with_four_holes();
    for (m, lengths) in [
        (&tube, &[0.008f32, 0.02, 0.05, 0.1, 0.3, 1.0][..]),
        (&holes, &[0.03, 0.1, 0.3, 0.6, 2.0][..]),
    ] {
        for &l in lengths {
            let out = isotropic_remesh(m, &RemeshOptions::new(l)).unwrap();
            let q = check_topology(m, &out);
            println!("L={l}: {q}");
            check_sources(m, &out, 1e-5);
        }
    }
}

/// Jagged openings (a region cut along mesh edges) smoothed along their loops first, then
/// remeshed: the loops come out smooth.
#[test]
fn jagged_openings_smoothed_then_remeshed() {
    use geom::smooth::{SmoothOptions, Smoother};
    let s = sphere_with_four_holes();
    let max_turn = |m: &TriMesh| -> f32 {
        let mut worst = 0f32;
        for l in boundary_loops(m.vertices.len(), &m.faces).unwrap() {
            let k = l.len();
            for i in 0..k {
                let p = |j: usize| m.vertices[l[j % k] as usize];
                let (a, b) = (p(i + k - 1), p(i));
                let c = p(i + 1);
                worst = worst.max((b - a).angle_between(c - b).to_degrees());
            }
        }
        worst
    };
    let smoother = Smoother::new(s.vertices.len(), &s.faces).unwrap();
    let interior: Vec<bool> = (0..s.vertices.len())
        .map(|v| !smoother.is_boundary(v))
        .collect();
    let mut smoothed = s.clone();
    smoother
        .smooth(
            &mut smoothed.vertices,
            &SmoothOptions::taubin(20),
            Some(&interior),
        )
        .unwrap();
    let out = isotropic_remesh(&smoothed, &RemeshOptions::new(0.05)).unwrap();
    let q = check_topology(&s, &out);
    let (before, after) = (max_turn(&s), max_turn(&out.mesh));
    println!("jagged openings: turning {before:.1} -> {after:.1} degrees; {q}");
    assert!(before > 50.0 && after < 25.0, "{before} -> {after}");
    assert!(q.min_angle_p1 > 20.0, "{q}");
}
