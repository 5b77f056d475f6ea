//! Synthetic bodies, garments and samples for tests and benchmarks (no dataset needed): an
//! ellipsoid "body" with any number of points and a cylindrical "garment" around it.

use glam::Vec3;

use crate::batch::Sample;
use crate::error::Result;

/// Radii (metres) of the synthetic ellipsoid body: a torso-like 0.18 x 0.8 x 0.12.
pub const BODY_RADII: Vec3 = Vec3::new(0.18, 0.8, 0.12);
/// Centre of the synthetic body (metres).
pub const BODY_CENTRE: Vec3 = Vec3::new(0.0, 0.9, 0.0);

/// An ellipsoid body of exactly `n` points (a Fibonacci lattice, evenly spread), radii
/// [`BODY_RADII`] around [`BODY_CENTRE`]: `([n]` points, `[n]` unit outward normals`)`.
pub fn ellipsoid_body(n: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let mut points = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(n);
    for i in 0..n {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let phi = golden * i as f32;
        let unit = Vec3::new(r * phi.cos(), y, r * phi.sin());
        points.push(BODY_CENTRE + unit * BODY_RADII);
        normals.push((unit / BODY_RADII).normalize());
    }
    (points, normals)
}

/// Mean distance (metres) from each point to its nearest other point: the synthetic body's
/// stand-in for the mean edge length.
pub fn mean_spacing(points: &[Vec3]) -> Result<f32> {
    let k = geom::knn::knn(points, points, 2)?;
    let sum: f64 = (0..points.len())
        .map(|q| k.sq_row(q).get(1).copied().unwrap_or(0.0).sqrt() as f64)
        .sum();
    Ok((sum / points.len().max(1) as f64) as f32)
}

/// A tube "garment" of about `target_vertices` vertices (`rows x cols`, 3:1 around:along)
/// wrapped on a cylinder of radius 0.25 m around the body axis from y = 0.7 to 1.4 m, open
/// along one seam; near-equilateral-sized quads split in two triangles.
pub fn tube_garment(target_vertices: usize) -> geom::TriMesh {
    let rows = ((target_vertices as f32 / 3.0).sqrt().round() as usize).max(2);
    let cols = (target_vertices / rows).max(3);
    let grid = geom::TriMesh::grid(cols, rows, 1.0);
    let radius = 0.25;
    let (y0, y1) = (0.7, 1.4);
    let vertices = (0..rows)
        .flat_map(|j| {
            (0..cols).map(move |i| {
                let theta = std::f32::consts::TAU * i as f32 / cols as f32;
                let y = y0 + (y1 - y0) * j as f32 / (rows - 1) as f32;
                Vec3::new(radius * theta.cos(), y, radius * theta.sin())
            })
        })
        .collect();
    geom::TriMesh::new(vertices, grid.faces)
}

/// A smooth synthetic "drape" of the garment `m` (metres): every vertex moves by a
/// displacement of a few centimetres that varies smoothly with position and `phase`.
pub fn smooth_displacement(m: &[Vec3], phase: f32) -> Vec<Vec3> {
    m.iter()
        .map(|p| {
            *p + Vec3::new(
                0.02 * (3.0 * p.y + phase).sin(),
                -0.03 + 0.01 * (5.0 * p.x + phase).cos(),
                0.02 * (4.0 * p.x + 2.0 * p.y).sin(),
            )
        })
        .collect()
}

/// A training sample: the ellipsoid body of `n_body` points scaled by `scale` around its
/// centre, the garment `template` as M and [`smooth_displacement`] of it (with `phase`) as
/// the target G.
pub fn synthetic_sample(
    n_body: usize,
    template: &geom::TriMesh,
    scale: f32,
    phase: f32,
) -> Result<Sample> {
    let (points, normals) = ellipsoid_body(n_body);
    let body: Vec<Vec3> = points
        .iter()
        .map(|p| BODY_CENTRE + (*p - BODY_CENTRE) * scale)
        .collect();
    let body_edge = mean_spacing(&body)?;
    let warped = template.vertices.clone();
    let target = smooth_displacement(&warped, phase);
    Ok(Sample {
        body,
        body_normals: normals,
        body_edge,
        warped,
        target: Some(target),
    })
}
