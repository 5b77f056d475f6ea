//! Views, framing and the orthographic camera shared by all views of one call.

use glam::Vec3;

use crate::mesh::{finite, RenderMesh};

/// Where the camera looks from. All views are orthographic with Y up on screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// Camera on +Z looking towards -Z: the body's front, its left (+X) on screen right.
    Front,
    /// Camera on +X looking towards -X: the body's left side, its front (+Z) on screen left.
    Side,
    /// Camera on -Z looking towards +Z: the body's back.
    Back,
    /// Camera turned about +Y by this many radians from [`View::Front`]
    /// (`Yaw(π/2)` is [`View::Side`], `Yaw(π)` is [`View::Back`]).
    Yaw(f32),
}

impl View {
    /// The yaw of the camera about +Y in radians (Front 0, Side π/2, Back π).
    pub fn yaw(self) -> f32 {
        match self {
            View::Front => 0.0,
            View::Side => std::f32::consts::FRAC_PI_2,
            View::Back => std::f32::consts::PI,
            View::Yaw(a) => a,
        }
    }

    /// Unit vector from the scene towards the camera (world frame).
    pub fn toward_camera(self) -> Vec3 {
        match self {
            View::Front => Vec3::Z,
            View::Side => Vec3::X,
            View::Back => Vec3::NEG_Z,
            View::Yaw(a) => Vec3::new(a.sin(), 0.0, a.cos()),
        }
    }

    /// A short lower-case name for captions: "front", "side", "back" or "yaw 30°".
    pub fn name(self) -> String {
        match self {
            View::Front => "front".into(),
            View::Side => "side".into(),
            View::Back => "back".into(),
            View::Yaw(a) => format!("yaw {:.0}\u{b0}", a.to_degrees()),
        }
    }
}

/// How the scene is placed in the picture.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Framing {
    /// Fit the bounding box of the scene's finite vertices, with the options' margin.
    #[default]
    Auto,
    /// Fit this world box (metres) instead of the scene's: give the same box to several calls
    /// so their pictures share one scale (e.g. a prediction next to its ground truth).
    Bounds {
        /// Lower corner, metres.
        min: Vec3,
        /// Upper corner, metres.
        max: Vec3,
    },
    /// Put `center` (metres) at the middle of every panel at `pixels_per_metre` (output
    /// pixels, before supersampling): fixed framing for animations.
    Fixed {
        /// World point shown at the panel centre, metres.
        center: Vec3,
        /// Output pixels per metre.
        pixels_per_metre: f32,
    },
}

/// An orthographic camera in sample units (output pixels times the supersampling factor).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Camera {
    /// Screen right, world frame.
    pub right: Vec3,
    /// Screen up (+Y), world frame.
    pub up: Vec3,
    /// Towards the camera, world frame; depth grows towards the camera.
    pub toward: Vec3,
    /// Samples per metre.
    pub scale: f32,
    /// World coordinates along `right` and `up` that map to the panel centre.
    pub center: (f32, f32),
    /// Panel size in samples.
    pub width: u32,
    /// Panel height in samples.
    pub height: u32,
    /// Floor: lowest scene Y (metres) and the horizontal extent (along `right`, metres) of
    /// the scene's lowest part, for the contact shadow; `None` for an empty scene.
    pub floor: Option<(f32, f32, f32)>,
}

impl Camera {
    /// Projects a world point to (x right, y down) samples and a depth in metres towards the
    /// camera.
    #[inline]
    pub fn project(&self, p: Vec3) -> Vec3 {
        Vec3::new(
            (p.dot(self.right) - self.center.0) * self.scale + 0.5 * self.width as f32,
            0.5 * self.height as f32 - (p.dot(self.up) - self.center.1) * self.scale,
            p.dot(self.toward),
        )
    }
}

/// Axis-aligned box of the scene's finite vertices, or `None` if there are none.
fn scene_bounds(meshes: &[RenderMesh]) -> Option<(Vec3, Vec3)> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for m in meshes {
        for &v in m.vertices.iter().filter(|v| finite(**v)) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    (lo.x <= hi.x).then_some((lo, hi))
}

fn basis(view: View) -> (Vec3, Vec3, Vec3) {
    let toward = view.toward_camera();
    let right = Vec3::Y.cross(toward).normalize_or(Vec3::X);
    (right, Vec3::Y, toward)
}

/// Extent along `axis` of the scene's finite vertices (or of a box's corners).
fn extent_along(meshes: &[RenderMesh], bounds: Option<(Vec3, Vec3)>, axis: Vec3) -> (f32, f32) {
    let mut lo = f32::INFINITY;
    let mut hi = f32::NEG_INFINITY;
    let mut add = |v: Vec3| {
        let d = v.dot(axis);
        lo = lo.min(d);
        hi = hi.max(d);
    };
    match bounds {
        Some((a, b)) => {
            for i in 0..8 {
                add(Vec3::new(
                    if i & 1 == 0 { a.x } else { b.x },
                    if i & 2 == 0 { a.y } else { b.y },
                    if i & 4 == 0 { a.z } else { b.z },
                ));
            }
        }
        None => meshes
            .iter()
            .flat_map(|m| m.vertices.iter())
            .filter(|v| finite(**v))
            .for_each(|&v| add(v)),
    }
    (lo, hi)
}

/// Horizontal extent (along `right`) of the vertices within `band` metres of `floor_y`.
fn foot_extent(meshes: &[RenderMesh], right: Vec3, floor_y: f32, band: f32) -> (f32, f32) {
    let mut lo = f32::INFINITY;
    let mut hi = f32::NEG_INFINITY;
    for m in meshes {
        for &v in m
            .vertices
            .iter()
            .filter(|v| finite(**v) && v.y <= floor_y + band)
        {
            let d = v.dot(right);
            lo = lo.min(d);
            hi = hi.max(d);
        }
    }
    (lo, hi)
}

/// Cameras for `views`, one per view, all at one scale, for panels of `size` output pixels
/// rendered at `supersample` samples per pixel side. `margin` is a fraction of the panel's
/// smaller side kept free on every edge.
pub(crate) fn fit_cameras(
    meshes: &[RenderMesh],
    views: &[View],
    size: (u32, u32),
    supersample: u32,
    margin: f32,
    framing: Framing,
) -> Vec<Camera> {
    let scene = scene_bounds(meshes);
    let ss = supersample as f32;
    let (w, h) = (size.0 as f32, size.1 as f32);
    let pad = margin.clamp(0.0, 0.45) * w.min(h);
    let (avail_w, avail_h) = ((w - 2.0 * pad).max(1.0), (h - 2.0 * pad).max(1.0));
    let fit_box = match framing {
        Framing::Bounds { min, max } => Some((min.min(max), min.max(max))),
        _ => None,
    };
    let bases: Vec<_> = views.iter().map(|&v| basis(v)).collect();
    // Per view horizontal extent; vertical extent is along Y for every view.
    let extents: Vec<(f32, f32)> = bases
        .iter()
        .map(|&(r, _, _)| extent_along(meshes, fit_box, r))
        .collect();
    let (ylo, yhi) = extent_along(meshes, fit_box, Vec3::Y);
    let (scale, cy) = match framing {
        Framing::Fixed {
            center,
            pixels_per_metre,
        } => (pixels_per_metre, center.y),
        _ => {
            let mut s = if yhi > ylo {
                avail_h / (yhi - ylo)
            } else {
                f32::INFINITY
            };
            for &(lo, hi) in &extents {
                if hi > lo {
                    s = s.min(avail_w / (hi - lo));
                }
            }
            if !s.is_finite() {
                // A single point or an empty scene: one metre fills the panel.
                s = avail_w.min(avail_h);
            }
            let cy = if yhi >= ylo { 0.5 * (ylo + yhi) } else { 0.0 };
            (s, cy)
        }
    };
    bases
        .iter()
        .zip(&extents)
        .map(|(&(right, up, toward), &(lo, hi))| {
            let cx = match framing {
                Framing::Fixed { center, .. } => center.dot(right),
                _ if hi >= lo => 0.5 * (lo + hi),
                _ => 0.0,
            };
            let floor = scene.map(|(slo, shi)| {
                let band = 0.08 * (shi.y - slo.y).max(1e-6);
                let (a, b) = foot_extent(meshes, right, slo.y, band);
                (slo.y, a, b)
            });
            Camera {
                right,
                up,
                toward,
                scale: scale * ss,
                center: (cx, cy),
                width: size.0 * supersample,
                height: size.1 * supersample,
                floor,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_views_match_their_yaw() {
        for v in [View::Front, View::Side, View::Back] {
            let d = View::Yaw(v.yaw()).toward_camera() - v.toward_camera();
            assert!(d.length() < 1e-6, "{v:?}");
        }
        let (right, _, _) = basis(View::Front);
        assert!((right - Vec3::X).length() < 1e-6);
        // Side view: the body's front (+Z) is on screen left.
        let (right, _, _) = basis(View::Side);
        assert!((right - Vec3::NEG_Z).length() < 1e-6);
    }

    #[test]
    fn views_share_scale_and_height() {
        let v = [Vec3::new(-0.5, 0.0, -0.1), Vec3::new(0.5, 2.0, 0.1)];
        let f: [[u32; 3]; 0] = [];
        let m = [RenderMesh::new(&v, &f, [0; 3])];
        let cams = fit_cameras(
            &m,
            &[View::Front, View::Side],
            (100, 100),
            2,
            0.0,
            Framing::Auto,
        );
        assert_eq!(cams[0].scale, cams[1].scale);
        // Height 2 m fills 200 samples.
        assert!((cams[0].scale - 100.0).abs() < 1e-3);
        let top = cams[1].project(Vec3::new(0.0, 2.0, 0.0));
        assert!(top.y.abs() < 1e-3);
    }
}
