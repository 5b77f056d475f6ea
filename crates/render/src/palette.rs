//! Colours: a palette for bodies and garments, a heat-map ramp and a legend bar.

use glam::Vec3;

use crate::shading::{to_linear, to_srgb};
use crate::text::{draw_text, text_size};
use crate::Image;

/// A mid skin tone (sRGB).
pub const SKIN: [u8; 3] = [224, 180, 150];
/// A darker skin tone.
pub const SKIN_DARK: [u8; 3] = [150, 105, 80];
/// T-shirt blue.
pub const TSHIRT_BLUE: [u8; 3] = [60, 110, 190];
/// Sweater red.
pub const SWEATER_RED: [u8; 3] = [185, 50, 50];
/// Jeans indigo.
pub const JEANS_INDIGO: [u8; 3] = [55, 70, 125];
/// Olive green, a fourth garment colour.
pub const OLIVE: [u8; 3] = [115, 130, 60];
/// Mustard yellow, a fifth garment colour.
pub const MUSTARD: [u8; 3] = [215, 170, 60];
/// Neutral clay grey for shape-only pictures.
pub const CLAY: [u8; 3] = [190, 190, 185];
/// Default picture background (light grey).
pub const BACKGROUND: [u8; 3] = [242, 242, 240];
/// Text colour on the background.
pub const INK: [u8; 3] = [35, 35, 40];
/// Colour of NaN values on heat maps.
pub const MISSING: [u8; 3] = [128, 128, 128];

/// Distinct garment colours, in order, for scenes with several garments.
pub const GARMENTS: [[u8; 3]; 5] = [TSHIRT_BLUE, SWEATER_RED, JEANS_INDIGO, OLIVE, MUSTARD];

/// Distinct line colours, in order, for the curves of one chart. Sixteen: `garnet eval` of
/// the nine shipped models draws twelve curves (DQS once a garment), and with ten colours
/// two pairs of them were drawn alike.
pub const CURVES: [[u8; 3]; 16] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
    [0, 0, 0],
    [174, 199, 232],
    [152, 223, 138],
    [255, 187, 120],
    [120, 60, 160],
    [0, 100, 60],
];

/// Control points of the heat ramp, low to high: deep blue, blue, cyan, green, yellow,
/// orange, red, dark red (evenly spaced over [0, 1]).
const HEAT: [[u8; 3]; 8] = [
    [40, 30, 120],
    [40, 90, 210],
    [40, 180, 220],
    [80, 200, 110],
    [235, 225, 60],
    [245, 150, 40],
    [215, 50, 35],
    [125, 15, 25],
];

/// Heat-map colour (sRGB) of `value` in [0, 1]: blue (low) through green and yellow to red
/// (high). Values outside are clamped; NaN gives [`MISSING`]. Interpolated in linear RGB.
pub fn heat(value: f32) -> [u8; 3] {
    if value.is_nan() {
        return MISSING;
    }
    let t = value.clamp(0.0, 1.0) * (HEAT.len() - 1) as f32;
    let i = (t.floor() as usize).min(HEAT.len() - 2);
    let f = t - i as f32;
    to_srgb(to_linear(HEAT[i]).lerp(to_linear(HEAT[i + 1]), f))
}

/// Heat colours for `values` mapped linearly from [`lo`, `hi`] to [0, 1]; shape `[N]` in,
/// `[N]` out (e.g. per-vertex errors in cm to per-vertex colours).
pub fn heat_colors(values: &[f32], lo: f32, hi: f32) -> Vec<[u8; 3]> {
    let span = if hi > lo { hi - lo } else { 1.0 };
    values.iter().map(|&v| heat((v - lo) / span)).collect()
}

/// Blends two sRGB colours in linear light: `t = 0` gives `a`, `t = 1` gives `b`.
pub fn mix(a: [u8; 3], b: [u8; 3], t: f32) -> [u8; 3] {
    let (a, b): (Vec3, Vec3) = (to_linear(a), to_linear(b));
    to_srgb(a.lerp(b, t.clamp(0.0, 1.0)))
}

/// A horizontal legend for [`heat`]: a colour bar `width` pixels wide and 16 high with
/// `low` printed under its left end and `high` under its right end (2x font), on
/// [`BACKGROUND`]. Height is 16 + 4 + 16 pixels.
pub fn heat_legend(width: u32, low: &str, high: &str) -> Image {
    let bar = 16;
    let mut im = Image::new(width, bar + 4 + 16, BACKGROUND);
    for x in 0..width {
        let c = heat(x as f32 / (width.max(2) - 1) as f32);
        im.fill_rect(x as i64, 0, 1, bar, c);
    }
    draw_text(&mut im, 0, (bar + 4) as i64, low, 2, INK);
    let (w, _) = text_size(high, 2);
    draw_text(
        &mut im,
        width as i64 - w as i64,
        (bar + 4) as i64,
        high,
        2,
        INK,
    );
    im
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heat_ends_and_order() {
        assert_eq!(heat(0.0), HEAT[0]);
        assert_eq!(heat(1.0), HEAT[7]);
        assert_eq!(heat(-3.0), HEAT[0]);
        assert_eq!(heat(f32::NAN), MISSING);
        // Low values are blue-ish, high values red-ish.
        let lo = heat(0.1);
        let hi = heat(0.9);
        assert!(lo[2] > lo[0] && hi[0] > hi[2]);
        assert_eq!(heat_colors(&[0.0, 2.0], 0.0, 2.0), vec![HEAT[0], HEAT[7]]);
        assert_eq!(mix(SKIN, INK, 0.0), SKIN);
        let legend = heat_legend(200, "0 cm", "2 cm");
        assert_eq!(legend.width, 200);
    }

    /// Regression: twelve curves of one chart must not share a colour. Any two
    /// curve colours differ by at least 40 (of 255) in some channel.
    #[test]
    fn curve_colours_are_distinct() {
        for (i, a) in CURVES.iter().enumerate() {
            for b in &CURVES[i + 1..] {
                let gap = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
                assert!(gap >= 40, "{a:?} and {b:?} are too alike");
            }
        }
    }
}
