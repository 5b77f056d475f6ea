//! Triangle setup and a watertight z-buffer rasteriser writing a visibility buffer.
//!
//! Screen positions are snapped to a fixed-point grid (8 fractional bits per sample) and
//! coverage is decided with exact integer edge functions and a tie rule, so two triangles
//! sharing an edge never both cover, nor both miss, a sample on it. The rasteriser stores, per
//! sample, the depth (metres towards the camera) and the id of the nearest triangle; shading
//! happens later, once per visible sample.

use glam::Vec3;
use rayon::prelude::*;

use crate::camera::Camera;
use crate::mesh::RenderMesh;

/// Fractional bits of the fixed-point screen grid.
const SUB_BITS: u32 = 8;
const ONE: i64 = 1 << SUB_BITS;
const HALF: i64 = ONE / 2;
/// Vertices farther than this many samples from the panel are refused (keeps products in i64).
const MAX_COORD: f32 = (1 << 22) as f32;
/// Sample rows per rasterisation band (the unit of parallel work).
const BAND_ROWS: u32 = 16;
/// Id of a sample no triangle covers.
pub(crate) const NO_TRI: u32 = u32::MAX;

/// One triangle ready for rasterising and for barycentric look-ups when shading.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tri {
    /// Vertex indices into its mesh, ordered so that the screen-space area is positive.
    pub v: [u32; 3],
    /// Fixed-point screen x of the three vertices (samples << SUB_BITS).
    pub x: [i32; 3],
    /// Fixed-point screen y (down) of the three vertices.
    pub y: [i32; 3],
    /// Depth of the three vertices, metres towards the camera, depth bias included.
    pub z: [f32; 3],
    /// 1 / (twice the fixed-point area).
    pub inv_area: f32,
    /// Inclusive sample bounds `[x0, y0, x1, y1]`; `x0 > x1` marks a skipped triangle.
    pub bbox: [u32; 4],
    /// True when the face's outside (CCW side) faces the camera.
    pub front: bool,
}

impl Tri {
    const SKIPPED: Tri = Tri {
        v: [0; 3],
        x: [0; 3],
        y: [0; 3],
        z: [0.0; 3],
        inv_area: 0.0,
        bbox: [1, 0, 0, 0],
        front: false,
    };

    fn is_skipped(&self) -> bool {
        self.bbox[0] > self.bbox[2]
    }

    /// Barycentric weights of vertices `v[0..3]` at the centre of sample `(sx, sy)`.
    #[inline]
    pub fn barycentric(&self, sx: u32, sy: u32) -> [f32; 3] {
        let px = sx as i64 * ONE + HALF;
        let py = sy as i64 * ONE + HALF;
        let e = |a: usize, b: usize| edge(self.x[a], self.y[a], self.x[b], self.y[b], px, py);
        let w1 = (e(2, 0) as f32 * self.inv_area).clamp(0.0, 1.0);
        let w2 = (e(0, 1) as f32 * self.inv_area).clamp(0.0, 1.0 - w1);
        [1.0 - w1 - w2, w1, w2]
    }
}

/// Twice the signed area of (a, b, p) in fixed-point units; positive when p is on the left of
/// a->b in y-down coordinates with the orientation chosen in [`setup`].
#[inline]
fn edge(ax: i32, ay: i32, bx: i32, by: i32, px: i64, py: i64) -> i64 {
    (bx as i64 - ax as i64) * (py - ay as i64) - (by as i64 - ay as i64) * (px - ax as i64)
}

/// Tie rule: exactly one of the two triangles sharing edge a->b / b->a owns samples on it.
#[inline]
fn owns(ax: i32, ay: i32, bx: i32, by: i32) -> bool {
    by < ay || (by == ay && bx > ax)
}

/// Sets up every face of `mesh` for camera `cam`. The result has one entry per face (skipped
/// faces included, so a triangle's id is its mesh offset plus its face number).
fn setup_mesh(mesh: &RenderMesh, cam: &Camera, out: &mut [Tri]) {
    let projected: Vec<Vec3> = mesh.vertices.iter().map(|&p| cam.project(p)).collect();
    let bias = mesh.depth_bias;
    let (w, h) = (cam.width, cam.height);
    out.par_iter_mut()
        .zip(mesh.faces.par_iter())
        .for_each(|(t, f)| *t = setup(&projected, *f, bias, w, h));
}

fn setup(projected: &[Vec3], f: [u32; 3], bias: f32, width: u32, height: u32) -> Tri {
    let p = f.map(|i| projected[i as usize]);
    let ok = p
        .iter()
        .all(|q| q.is_finite() && q.x.abs() < MAX_COORD && q.y.abs() < MAX_COORD);
    if !ok {
        return Tri::SKIPPED;
    }
    let fx = |v: f32| (v * ONE as f32).round() as i32;
    let mut v = f;
    let mut x = p.map(|q| fx(q.x));
    let mut y = p.map(|q| fx(q.y));
    let mut z = p.map(|q| q.z + bias);
    let area = edge(x[0], y[0], x[1], y[1], x[2] as i64, y[2] as i64);
    if area == 0 {
        return Tri::SKIPPED;
    }
    // On a y-down screen a face seen from its outside (CCW) has negative area.
    let front = area < 0;
    if front {
        v.swap(1, 2);
        x.swap(1, 2);
        y.swap(1, 2);
        z.swap(1, 2);
    }
    // Inclusive range of sample centres (s * ONE + HALF) inside the fixed-point bounds.
    let lo = |a: i32| ((a as i64 - HALF + ONE - 1).div_euclid(ONE)).max(0);
    let hi = |a: i32, n: u32| ((a as i64 - HALF).div_euclid(ONE)).min(n as i64 - 1);
    let x0 = lo(*x.iter().min().unwrap());
    let x1 = hi(*x.iter().max().unwrap(), width);
    let y0 = lo(*y.iter().min().unwrap());
    let y1 = hi(*y.iter().max().unwrap(), height);
    if x0 > x1 || y0 > y1 {
        return Tri::SKIPPED;
    }
    Tri {
        v,
        x,
        y,
        z,
        inv_area: 1.0 / area.abs() as f32,
        bbox: [x0 as u32, y0 as u32, x1 as u32, y1 as u32],
        front,
    }
}

/// Depth and triangle id per sample, row-major, `width * height` entries each.
pub(crate) struct VisBuffer {
    /// Width in samples.
    pub width: u32,
    /// Height in samples.
    pub height: u32,
    /// Depth in metres towards the camera; `-inf` where nothing was drawn.
    pub depth: Vec<f32>,
    /// Global triangle id (mesh offset + face number) or [`NO_TRI`].
    pub id: Vec<u32>,
}

/// Triangles of all meshes for one camera, and where each mesh's faces start in that list.
pub(crate) fn setup_scene(meshes: &[RenderMesh], cam: &Camera) -> (Vec<Tri>, Vec<usize>) {
    let mut offsets = Vec::with_capacity(meshes.len() + 1);
    let mut total = 0;
    for m in meshes {
        offsets.push(total);
        total += m.faces.len();
    }
    offsets.push(total);
    let mut tris = vec![Tri::SKIPPED; total];
    for (i, m) in meshes.iter().enumerate() {
        setup_mesh(m, cam, &mut tris[offsets[i]..offsets[i + 1]]);
    }
    (tris, offsets)
}

/// Rasterises `tris` into a fresh visibility buffer of `width x height` samples.
pub(crate) fn rasterize(tris: &[Tri], width: u32, height: u32) -> VisBuffer {
    let n = width as usize * height as usize;
    let mut depth = vec![f32::NEG_INFINITY; n];
    let mut id = vec![NO_TRI; n];
    let bands = height.div_ceil(BAND_ROWS) as usize;
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (i, t) in tris.iter().enumerate() {
        if t.is_skipped() {
            continue;
        }
        for bin in &mut bins[(t.bbox[1] / BAND_ROWS) as usize..=(t.bbox[3] / BAND_ROWS) as usize] {
            bin.push(i as u32);
        }
    }
    let chunk = (BAND_ROWS * width) as usize;
    depth
        .par_chunks_mut(chunk)
        .zip(id.par_chunks_mut(chunk))
        .zip(bins.par_iter())
        .enumerate()
        .for_each(|(band, ((d, ids), bin))| {
            raster_band(tris, bin, band as u32 * BAND_ROWS, width, d, ids);
        });
    VisBuffer {
        width,
        height,
        depth,
        id,
    }
}

/// Draws the triangles listed in `bin` into one band of rows starting at sample row `y_start`.
fn raster_band(
    tris: &[Tri],
    bin: &[u32],
    y_start: u32,
    width: u32,
    depth: &mut [f32],
    ids: &mut [u32],
) {
    let rows = (depth.len() / width as usize) as u32;
    for &ti in bin {
        let t = &tris[ti as usize];
        let [x0, y0, x1, y1] = t.bbox;
        let ys = y0.max(y_start);
        let ye = y1.min(y_start + rows - 1);
        let (x, y) = (t.x, t.y);
        let px = x0 as i64 * ONE + HALF;
        let py = ys as i64 * ONE + HALF;
        // Edge k is opposite vertex k; its value is vertex k's unnormalised weight.
        let pairs = [(1, 2), (2, 0), (0, 1)];
        let mut row = [0i64; 3];
        let mut dx = [0i64; 3];
        let mut dy = [0i64; 3];
        for (k, &(a, b)) in pairs.iter().enumerate() {
            let bias = if owns(x[a], y[a], x[b], y[b]) { 0 } else { -1 };
            row[k] = edge(x[a], y[a], x[b], y[b], px, py) + bias;
            dx[k] = -(y[b] as i64 - y[a] as i64) * ONE;
            dy[k] = (x[b] as i64 - x[a] as i64) * ONE;
        }
        let (z0, dz1, dz2) = (t.z[0], t.z[1] - t.z[0], t.z[2] - t.z[0]);
        let inv = t.inv_area;
        for sy in ys..=ye {
            let [mut w0, mut w1, mut w2] = row;
            let base = ((sy - y_start) * width) as usize;
            for sx in x0..=x1 {
                if (w0 | w1 | w2) >= 0 {
                    let z = z0 + (w1 as f32 * inv) * dz1 + (w2 as f32 * inv) * dz2;
                    let i = base + sx as usize;
                    if z > depth[i] {
                        depth[i] = z;
                        ids[i] = ti;
                    }
                }
                w0 += dx[0];
                w1 += dx[1];
                w2 += dx[2];
            }
            for k in 0..3 {
                row[k] += dy[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{fit_cameras, Framing, View};

    /// A square of two triangles sharing a diagonal covers every sample exactly once.
    #[test]
    fn shared_edges_are_watertight() {
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.37, 0.61, 0.0),
        ];
        // A fan around an interior vertex: many shared edges at odd angles.
        let f = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let m = [RenderMesh::new(&v, &f, [0; 3])];
        let cam = fit_cameras(&m, &[View::Front], (37, 37), 1, 0.0, Framing::Auto)[0];
        let (tris, _) = setup_scene(&m, &cam);
        let mut count = vec![0u32; 37 * 37];
        for (i, _) in tris.iter().enumerate() {
            let vb = rasterize(&tris[i..=i], 37, 37);
            for (c, id) in count.iter_mut().zip(&vb.id) {
                *c += (*id != NO_TRI) as u32;
            }
        }
        assert!(count.iter().all(|&c| c == 1), "{count:?}");
    }
}
