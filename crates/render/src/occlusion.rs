//! Screen-space fake ambient occlusion and silhouette detection.
//!
//! Ambient occlusion looks, for every output pixel, at pairs of opposite taps around the
//! pixel's centre sample in the depth buffer. Half the sum of the two taps' depth differences is
//! a second difference: zero on any plane (tilted surfaces are not darkened), positive in a
//! crease or under a fold. A tap far in front of the centre (another body part, centimetres
//! away) or on the background tells nothing about the local surface, so its pair is skipped;
//! that keeps dark halos off surfaces behind an occluder.

use rayon::prelude::*;

use crate::raster::{VisBuffer, NO_TRI};

/// Number of opposite tap pairs.
const PAIRS: usize = 8;

/// Tap offsets (in samples) of the pairs, on a golden-angle spiral out to `radius` samples,
/// and the ratio `radius / r` of each (second differences of a crease grow with `r`).
fn taps(radius: f32) -> Vec<(i32, i32, f32)> {
    (0..PAIRS)
        .map(|k| {
            let r = radius * ((k as f32 + 0.5) / PAIRS as f32).sqrt();
            let a = k as f32 * 2.399_963;
            let (dx, dy) = ((r * a.cos()).round() as i32, (r * a.sin()).round() as i32);
            let len = ((dx * dx + dy * dy) as f32).sqrt().max(1.0);
            (dx, dy, radius / len)
        })
        .filter(|&(dx, dy, _)| dx != 0 || dy != 0)
        .collect()
}

/// Per output pixel brightness factors in `[1 - strength, 1]`, shape `[height / ss][width /
/// ss]` of `vb` (`ss` samples per pixel side), for lit surfaces.
///
/// `radius`: tap radius in samples; `range`: second difference in metres at which the
/// darkening is full; taps more than `far` metres in front of the centre are ignored.
pub(crate) fn ambient_occlusion(
    vb: &VisBuffer,
    ss: u32,
    radius: f32,
    range: f32,
    far: f32,
    strength: f32,
) -> Vec<f32> {
    let (w, h) = (vb.width as i32, vb.height as i32);
    let (pw, ph) = ((vb.width / ss) as usize, (vb.height / ss) as usize);
    let taps = taps(radius.max(1.0));
    let depth_at = |x: i32, y: i32| -> Option<f32> {
        if x < 0 || y < 0 || x >= w || y >= h {
            return None;
        }
        let i = (y * w + x) as usize;
        (vb.id[i] != NO_TRI).then(|| vb.depth[i])
    };
    let mut out = vec![1f32; pw * ph];
    out.par_chunks_mut(pw).enumerate().for_each(|(py, row)| {
        for (px, o) in row.iter_mut().enumerate() {
            let (cx, cy) = (
                (px as u32 * ss + ss / 2) as i32,
                (py as u32 * ss + ss / 2) as i32,
            );
            let Some(d) = depth_at(cx, cy) else { continue };
            let mut sum = 0.0;
            for &(dx, dy, scale) in &taps {
                let (Some(a), Some(b)) = (depth_at(cx + dx, cy + dy), depth_at(cx - dx, cy - dy))
                else {
                    continue;
                };
                let (da, db) = (a - d, b - d);
                if da > far || db > far {
                    continue;
                }
                let t = (0.5 * (da + db) * scale / range).clamp(0.0, 1.0);
                sum += t * t * (3.0 - 2.0 * t);
            }
            *o = 1.0 - strength * (sum / taps.len() as f32).min(1.0);
        }
    });
    out
}

/// Silhouette strength of sample `(x, y)` in `[0, 1]`: 1 where a neighbour within `reach`
/// samples is background or lies more than `gap` metres behind this sample (this sample is on
/// the near side of a depth discontinuity), 0 inside smooth surfaces and on background.
#[inline]
pub(crate) fn silhouette(vb: &VisBuffer, x: u32, y: u32, reach: u32, gap: f32) -> f32 {
    let (w, h) = (vb.width, vb.height);
    let i = (y * w + x) as usize;
    if vb.id[i] == NO_TRI {
        return 0.0;
    }
    let d = vb.depth[i];
    let mut hit = 0.0f32;
    for r in 1..=reach {
        let weight = if r == reach && reach > 1 { 0.5 } else { 1.0 };
        let nbrs = [
            (x.checked_sub(r), Some(y)),
            ((x + r < w).then_some(x + r), Some(y)),
            (Some(x), y.checked_sub(r)),
            (Some(x), (y + r < h).then_some(y + r)),
        ];
        for (nx, ny) in nbrs {
            let (Some(nx), Some(ny)) = (nx, ny) else {
                continue;
            };
            let j = (ny * w + nx) as usize;
            if vb.id[j] == NO_TRI || d - vb.depth[j] > gap {
                hit = hit.max(weight);
            }
        }
    }
    hit
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pit_is_darkened_and_a_plane_is_not() {
        let (w, h) = (40u32, 40u32);
        let mut vb = VisBuffer {
            width: w,
            height: h,
            depth: vec![0.0; (w * h) as usize],
            id: vec![0; (w * h) as usize],
        };
        // A tilted plane is not darkened.
        for y in 0..h {
            for x in 0..w {
                vb.depth[(y * w + x) as usize] = 0.01 * x as f32 - 0.003 * y as f32;
            }
        }
        let tilted = ambient_occlusion(&vb, 1, 5.0, 0.01, 0.1, 0.5);
        assert!(tilted.iter().all(|&a| (a - 1.0).abs() < 1e-6));
        vb.depth.fill(0.0);
        // A 6x6 pit 2 cm deep in the middle.
        for y in 17..23 {
            for x in 17..23 {
                vb.depth[(y * w + x) as usize] = -0.02;
            }
        }
        let ao = ambient_occlusion(&vb, 1, 5.0, 0.01, 0.1, 0.5);
        assert!(ao[(20 * w + 20) as usize] < 0.8);
        assert!((ao[(2 * w + 2) as usize] - 1.0).abs() < 1e-6);
        // A far occluder (1 m in front) casts nothing: no halo around it.
        let ao = {
            vb.depth.fill(0.0);
            for y in 0..h {
                for x in 20..w {
                    vb.depth[(y * w + x) as usize] = 1.0;
                }
            }
            ambient_occlusion(&vb, 1, 5.0, 0.01, 0.1, 0.5)
        };
        assert!(ao.iter().all(|&a| (a - 1.0).abs() < 1e-6));
        vb.depth.fill(0.0);
        for y in 17..23 {
            for x in 17..23 {
                vb.depth[(y * w + x) as usize] = -0.02;
            }
        }
        // The pit's rim on the near side is a silhouette, the plane far away is not.
        assert!(silhouette(&vb, 16, 20, 1, 0.005) > 0.0);
        assert_eq!(silhouette(&vb, 5, 5, 1, 0.005), 0.0);
    }
}
