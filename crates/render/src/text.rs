//! Bitmap text with the public-domain 8x8 font of the `font8x8` crate.

use font8x8::legacy::{BASIC_LEGACY, LATIN_LEGACY};

use crate::Image;

/// Side of one glyph cell in font pixels (multiply by the scale for image pixels).
pub const GLYPH_SIZE: u32 = 8;

/// The 8 rows of `c` (bit 0 is the leftmost pixel); `?` for characters the font lacks.
fn glyph(c: char) -> [u8; 8] {
    let u = c as u32;
    match u {
        0x20..=0x7e => BASIC_LEGACY[u as usize],
        0xa0..=0xff => LATIN_LEGACY[(u - 0xa0) as usize],
        _ => BASIC_LEGACY[b'?' as usize],
    }
}

/// Size in pixels (width, height) of `text` drawn at `scale`: 8 * scale per character and per
/// line (lines split at `'\n'`).
pub fn text_size(text: &str, scale: u32) -> (u32, u32) {
    let lines = text.split('\n');
    let (mut w, mut h) = (0u32, 0u32);
    for line in lines {
        w = w.max(line.chars().count() as u32 * GLYPH_SIZE * scale);
        h += GLYPH_SIZE * scale;
    }
    (w, h)
}

/// Draws `text` with its top-left corner at (`x`, `y`) pixels, each font pixel a
/// `scale x scale` square of `color` (sRGB); `'\n'` starts a new line. Clipped to the image.
pub fn draw_text(image: &mut Image, x: i64, y: i64, text: &str, scale: u32, color: [u8; 3]) {
    let s = scale.max(1);
    let cell = (GLYPH_SIZE * s) as i64;
    for (row, line) in text.split('\n').enumerate() {
        let top = y + row as i64 * cell;
        for (col, c) in line.chars().enumerate() {
            let left = x + col as i64 * cell;
            for (gy, bits) in glyph(c).iter().enumerate() {
                for gx in 0..8 {
                    if bits >> gx & 1 == 1 {
                        image.fill_rect(
                            left + gx * s as i64,
                            top + gy as i64 * s as i64,
                            s,
                            s,
                            color,
                        );
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_draws_pixels_inside_its_box() {
        let mut im = Image::new(100, 40, [255; 3]);
        draw_text(&mut im, 2, 3, "Hi 7\u{b0}", 2, [0; 3]);
        let (w, h) = text_size("Hi 7\u{b0}", 2);
        assert_eq!((w, h), (80, 16));
        let mut inside = 0;
        for y in 0..im.height {
            for x in 0..im.width {
                if im.pixel(x, y) != [255; 3] {
                    assert!((2..2 + w).contains(&x) && (3..3 + h).contains(&y));
                    inside += 1;
                }
            }
        }
        assert!(inside > 100);
        // Drawing off the image is clipped, not a panic.
        draw_text(&mut im, -50, 35, "clipped\nlines", 3, [0; 3]);
    }
}
