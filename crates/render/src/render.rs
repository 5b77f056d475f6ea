//! The render calls: options, per-view pipeline and the resolve from samples to pixels.

use glam::Vec3;
use rayon::prelude::*;

use crate::camera::{fit_cameras, Camera, Framing, View};
use crate::mesh::{vertex_normals, RenderMesh};
use crate::occlusion::{ambient_occlusion, silhouette};
use crate::palette::BACKGROUND;
use crate::raster::{rasterize, setup_scene, Tri, VisBuffer, NO_TRI};
use crate::shading::{to_linear, to_srgb, Lights, BACK_FACE_DIM};
use crate::{Image, RenderError, Shading};

/// Largest panel side in samples (output pixels times the supersampling factor).
const MAX_SAMPLES_SIDE: u32 = 16384;
/// Largest panel area in samples (8 bytes each: 512 MiB of buffers per view at most).
const MAX_SAMPLES: u64 = 1 << 26;
/// Ambient-occlusion window half size, metres.
const AO_RADIUS_M: f32 = 0.035;
/// Depth second difference (metres) at which the ambient occlusion is full.
const AO_RANGE_M: f32 = 0.015;
/// Occluders more than this far (metres) in front of a surface cast no ambient occlusion.
const AO_FAR_M: f32 = 0.08;
/// Darkest ambient-occlusion factor is `1 - AO_STRENGTH`.
const AO_STRENGTH: f32 = 0.55;
/// A depth step larger than this (metres) draws a silhouette line.
const OUTLINE_GAP_M: f32 = 0.012;
/// Darkening of silhouette lines (0 none, 1 black).
const OUTLINE_STRENGTH: f32 = 0.5;
/// Darkness of the contact shadow at its centre.
const FLOOR_SHADOW: f32 = 0.3;

/// Settings of a render call. `RenderOptions::default()` gives good pictures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Samples per pixel side for anti-aliasing (1 = none, 2 = 4 samples per pixel, the
    /// default; at most 8). Cost grows with its square.
    pub supersample: u32,
    /// Background colour (sRGB).
    pub background: [u8; 3],
    /// Free border on each side, as a fraction of the panel's smaller side (default 0.05).
    pub margin: f32,
    /// How the scene is placed in the panels (default [`Framing::Auto`]).
    pub framing: Framing,
    /// Draw a soft contact shadow on the floor under the scene's lowest point (default on).
    pub floor: bool,
    /// Darken silhouettes and depth steps (default on).
    pub outline: bool,
    /// Screen-space ambient occlusion darkening creases and folds (default on).
    pub ambient_occlusion: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            supersample: 2,
            background: BACKGROUND,
            margin: 0.05,
            framing: Framing::Auto,
            floor: true,
            outline: true,
            ambient_occlusion: true,
        }
    }
}

/// Renders `meshes` from `view` into a picture of `size = (width, height)` pixels.
///
/// `meshes`: the scene (see [`RenderMesh`]). Errors: a face index out of range, a colour
/// slice of the wrong length, or a zero or too large size.
pub fn render_view(
    meshes: &[RenderMesh],
    view: View,
    size: (u32, u32),
    options: &RenderOptions,
) -> Result<Image, RenderError> {
    Ok(render_panels(meshes, &[view], size, options)?.remove(0))
}

/// Renders `meshes` from every view in `views`, each into a `size = (width, height)` panel,
/// with default options, and puts the panels side by side (left to right in `views` order):
/// the picture is `views.len() * width` by `height` pixels. All views share one scale and
/// one vertical placement, so front and side views line up.
pub fn render_views(
    meshes: &[RenderMesh],
    views: &[View],
    size: (u32, u32),
) -> Result<Image, RenderError> {
    render_views_with(meshes, views, size, &RenderOptions::default())
}

/// [`render_views`] with explicit options.
pub fn render_views_with(
    meshes: &[RenderMesh],
    views: &[View],
    size: (u32, u32),
    options: &RenderOptions,
) -> Result<Image, RenderError> {
    let panels = render_panels(meshes, views, size, options)?;
    Ok(Image::hstack(&panels, options.background))
}

/// Renders one `size = (width, height)` picture per view, all at one scale (as
/// [`render_views`] but as separate pictures, e.g. for a captioned [`crate::Sheet`]).
/// Views render in parallel. An empty `views` gives an empty list.
pub fn render_panels(
    meshes: &[RenderMesh],
    views: &[View],
    size: (u32, u32),
    options: &RenderOptions,
) -> Result<Vec<Image>, RenderError> {
    let ss = options.supersample.clamp(1, 8);
    let size_err = |reason| RenderError::Size {
        width: size.0,
        height: size.1,
        reason,
    };
    if size.0 == 0 || size.1 == 0 {
        return Err(size_err("zero width or height"));
    }
    if size.0.saturating_mul(ss) > MAX_SAMPLES_SIDE || size.1.saturating_mul(ss) > MAX_SAMPLES_SIDE
    {
        return Err(size_err(
            "a side times the supersampling factor exceeds 16384",
        ));
    }
    if (size.0 * ss) as u64 * (size.1 * ss) as u64 > MAX_SAMPLES {
        return Err(size_err(
            "width x height x supersample^2 exceeds 2^26 samples",
        ));
    }
    if let Framing::Fixed {
        pixels_per_metre, ..
    } = options.framing
    {
        if !(pixels_per_metre.is_finite() && pixels_per_metre > 0.0) {
            return Err(size_err(
                "Framing::Fixed needs a positive finite pixels_per_metre",
            ));
        }
    }
    for (i, m) in meshes.iter().enumerate() {
        m.validate(i)?;
    }
    let normals: Vec<Vec<Vec3>> = meshes
        .par_iter()
        .map(|m| vertex_normals(m.vertices, m.faces))
        .collect();
    let cams = fit_cameras(meshes, views, size, ss, options.margin, options.framing);
    Ok(cams
        .par_iter()
        .map(|cam| render_camera(meshes, &normals, cam, ss, options))
        .collect())
}

/// Everything the resolve step reads for one view.
struct Frame<'a> {
    meshes: &'a [RenderMesh<'a>],
    normals: &'a [Vec<Vec3>],
    tris: Vec<Tri>,
    offsets: Vec<usize>,
    vb: VisBuffer,
    ao: Option<Vec<f32>>,
    lights: Lights,
    cam: &'a Camera,
    background: Vec3,
    outline_reach: u32,
    outline: bool,
}

fn render_camera(
    meshes: &[RenderMesh],
    normals: &[Vec<Vec3>],
    cam: &Camera,
    ss: u32,
    options: &RenderOptions,
) -> Image {
    let (tris, offsets) = setup_scene(meshes, cam);
    let vb = rasterize(&tris, cam.width, cam.height);
    let ao = options.ambient_occlusion.then(|| {
        let radius = (AO_RADIUS_M * cam.scale).clamp(1.0, 96.0);
        ambient_occlusion(&vb, ss, radius, AO_RANGE_M, AO_FAR_M, AO_STRENGTH)
    });
    let frame = Frame {
        meshes,
        normals,
        tris,
        offsets,
        vb,
        ao,
        lights: Lights::for_camera(cam),
        cam,
        background: to_linear(options.background),
        outline_reach: ss.div_ceil(2),
        outline: options.outline,
    };
    let (w, h) = (cam.width / ss, cam.height / ss);
    let mut image = Image::new(w, h, options.background);
    let floor = if options.floor {
        FloorShadow::new(cam)
    } else {
        None
    };
    image
        .rgb
        .par_chunks_mut(3 * w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as u32;
            for x in 0..w {
                let mut bg = frame.background;
                if let Some(f) = &floor {
                    bg *= f.factor((x as f32 + 0.5) * ss as f32, (y as f32 + 0.5) * ss as f32);
                }
                let ao = frame.ao.as_ref().map_or(1.0, |a| a[(y * w + x) as usize]);
                let mut sum = Vec3::ZERO;
                for sy in y * ss..(y + 1) * ss {
                    for sx in x * ss..(x + 1) * ss {
                        sum += frame.sample(sx, sy, ao).unwrap_or(bg);
                    }
                }
                let c = to_srgb(sum / (ss * ss) as f32);
                row[3 * x as usize..3 * x as usize + 3].copy_from_slice(&c);
            }
        });
    image
}

impl Frame<'_> {
    /// Linear colour of sample (`sx`, `sy`) with its pixel's ambient-occlusion factor `ao`,
    /// or `None` where no triangle covers it.
    #[inline]
    fn sample(&self, sx: u32, sy: u32, ao: f32) -> Option<Vec3> {
        let i = (sy * self.vb.width + sx) as usize;
        let id = self.vb.id[i];
        if id == NO_TRI {
            return None;
        }
        let m = self.offsets.partition_point(|&o| o <= id as usize) - 1;
        let mesh = &self.meshes[m];
        let face = id as usize - self.offsets[m];
        let tri = &self.tris[id as usize];
        let b = tri.barycentric(sx, sy);
        let v = tri.v.map(|k| k as usize);
        let nrm = &self.normals[m];
        let toward = self.cam.toward;
        let mut n = b[0] * nrm[v[0]] + b[1] * nrm[v[1]] + b[2] * nrm[v[2]];
        if !tri.front {
            n = -n;
        }
        if n.length_squared() < 1e-12 {
            n = toward;
        }
        let mut n = n.normalize();
        // Smooth normals can lean away from the camera near silhouettes: straighten them.
        let facing = n.dot(toward);
        if facing < 0.0 {
            n = (n - toward * facing).normalize_or(toward);
        }
        let mut base = if let Some(fc) = mesh.face_colors {
            to_linear(fc[face])
        } else if let Some(vc) = mesh.vertex_colors {
            b[0] * to_linear(vc[v[0]]) + b[1] * to_linear(vc[v[1]]) + b[2] * to_linear(vc[v[2]])
        } else {
            to_linear(mesh.color)
        };
        if !tri.front && mesh.shading != Shading::Unlit {
            base *= BACK_FACE_DIM;
        }
        let mut c = self.lights.shade(n, base, mesh.shading, ao);
        if self.outline {
            let s = silhouette(&self.vb, sx, sy, self.outline_reach, OUTLINE_GAP_M);
            c *= 1.0 - OUTLINE_STRENGTH * s;
        }
        Some(c)
    }
}

/// A soft elliptical contact shadow centred on the floor line under the scene.
struct FloorShadow {
    cx: f32,
    cy: f32,
    inv_rx: f32,
    inv_ry: f32,
}

impl FloorShadow {
    fn new(cam: &Camera) -> Option<Self> {
        let (y, lo, hi) = cam.floor?;
        if lo > hi {
            return None;
        }
        let s = cam.scale;
        let cx = (0.5 * (lo + hi) - cam.center.0) * s + 0.5 * cam.width as f32;
        let cy = 0.5 * cam.height as f32 - (y - cam.center.1) * s;
        let rx = (0.5 * (hi - lo) * s * 1.25).max(4.0);
        let ry = (rx * 0.1).max(3.0);
        Some(Self {
            cx,
            cy,
            inv_rx: 1.0 / rx,
            inv_ry: 1.0 / ry,
        })
    }

    /// Background brightness factor at sample position (`x`, `y`).
    #[inline]
    fn factor(&self, x: f32, y: f32) -> f32 {
        let dx = (x - self.cx) * self.inv_rx;
        let dy = (y - self.cy) * self.inv_ry;
        let r2 = dx * dx + dy * dy;
        if r2 >= 1.0 {
            1.0
        } else {
            1.0 - FLOOR_SHADOW * (1.0 - r2) * (1.0 - r2)
        }
    }
}

#[cfg(test)]
#[path = "render_tests.rs"]
mod tests;
