//! Lighting in linear RGB and sRGB conversions.
//!
//! Lights are attached to the camera (a key light from the upper front-left, a fill light from
//! the right, a sky/ground ambient and a faint rim), so every view of a body is lit alike.

use std::sync::OnceLock;

use glam::Vec3;

use crate::camera::Camera;
use crate::mesh::Shading;

/// Linear value of every sRGB byte.
fn to_linear_table() -> &'static [f32; 256] {
    static T: OnceLock<[f32; 256]> = OnceLock::new();
    T.get_or_init(|| {
        std::array::from_fn(|i| {
            let c = i as f32 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
    })
}

/// Entries of the linear-to-sRGB table (uniform steps over [0, 1]).
const TO_SRGB_STEPS: usize = 4096;

fn to_srgb_table() -> &'static [u8; TO_SRGB_STEPS + 1] {
    static T: OnceLock<[u8; TO_SRGB_STEPS + 1]> = OnceLock::new();
    T.get_or_init(|| {
        std::array::from_fn(|i| {
            let l = i as f32 / TO_SRGB_STEPS as f32;
            let c = if l <= 0.003_130_8 {
                12.92 * l
            } else {
                1.055 * l.powf(1.0 / 2.4) - 0.055
            };
            (c * 255.0 + 0.5).clamp(0.0, 255.0) as u8
        })
    })
}

/// sRGB bytes to linear RGB in [0, 1].
#[inline]
pub(crate) fn to_linear(c: [u8; 3]) -> Vec3 {
    let t = to_linear_table();
    Vec3::new(t[c[0] as usize], t[c[1] as usize], t[c[2] as usize])
}

/// Linear RGB (clamped to [0, 1]) to sRGB bytes.
#[inline]
pub(crate) fn to_srgb(l: Vec3) -> [u8; 3] {
    let t = to_srgb_table();
    let q = |v: f32| t[(v.clamp(0.0, 1.0) * TO_SRGB_STEPS as f32 + 0.5) as usize];
    [q(l.x), q(l.y), q(l.z)]
}

/// Brightness factor applied to the inside (back faces) of open surfaces.
pub(crate) const BACK_FACE_DIM: f32 = 0.72;

/// The light rig of one camera, in world coordinates.
pub(crate) struct Lights {
    key: Vec3,
    fill: Vec3,
    half: Vec3,
    toward: Vec3,
}

impl Lights {
    /// Lights placed relative to `cam`: key from the upper front-left, fill from the right.
    pub fn for_camera(cam: &Camera) -> Self {
        let (r, u, t) = (cam.right, cam.up, cam.toward);
        let key = (-0.55 * r + 0.6 * u + 0.75 * t).normalize();
        let fill = (0.75 * r + 0.05 * u + 0.6 * t).normalize();
        Self {
            key,
            fill,
            half: (key + t).normalize(),
            toward: t,
        }
    }

    /// Shaded linear colour for unit normal `n` (facing the camera), linear base colour
    /// `base` and ambient-occlusion factor `ao` in [0, 1].
    #[inline]
    pub fn shade(&self, n: Vec3, base: Vec3, shading: Shading, ao: f32) -> Vec3 {
        match shading {
            Shading::Unlit => base,
            Shading::Soft => {
                let k = n.dot(self.key).max(0.0);
                base * ((0.72 + 0.3 * k) * (0.6 + 0.4 * ao))
            }
            Shading::Lit => {
                // Slightly wrapped Lambert softens the terminator on skin and cloth.
                let key = ((n.dot(self.key) + 0.15) / 1.15).max(0.0);
                let fill = n.dot(self.fill).max(0.0);
                let sky = 0.5 + 0.5 * n.y;
                let ambient = 0.1 + 0.12 * sky;
                let facing = n.dot(self.toward).clamp(0.0, 1.0);
                let rim = 0.1 * (1.0 - facing).powi(3);
                let spec = 0.05 * n.dot(self.half).max(0.0).powi(24);
                let light = (ambient + rim) * ao + (0.82 * key + 0.22 * fill) * (0.35 + 0.65 * ao);
                base * light + Vec3::splat(spec * ao)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_is_exact() {
        for i in 0..=255u8 {
            let c = [i, i, i];
            assert_eq!(to_srgb(to_linear(c)), c);
        }
    }
}
