//! [`Sheet`]: many pictures in a captioned grid with an optional title.

use std::path::Path;

use crate::palette::{BACKGROUND, INK};
use crate::text::{draw_text, text_size, GLYPH_SIZE};
use crate::{Image, RenderError};

/// Scale of the 8x8 font on sheets (16-pixel characters).
const SCALE: u32 = 2;
/// Pixels per character side on sheets.
const CHAR: u32 = GLYPH_SIZE * SCALE;

/// Where captions go relative to their picture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CaptionPlace {
    /// Under the picture.
    #[default]
    Below,
    /// Over the picture.
    Above,
}

/// A grid of captioned pictures, filled row by row, `cols` per row.
///
/// Every cell is as large as the largest picture; smaller pictures are centred horizontally.
/// Captions and the title use the 8x8 font at 2x (16-pixel characters), are wrapped at word
/// boundaries to fit, and may hold `'\n'`.
#[derive(Clone, Debug)]
pub struct Sheet {
    cols: usize,
    title: Option<String>,
    cells: Vec<(Image, String)>,
    /// Caption placement (default below).
    pub captions: CaptionPlace,
    /// Background colour (sRGB).
    pub background: [u8; 3],
    /// Text colour (sRGB).
    pub ink: [u8; 3],
    /// Gap in pixels between cells and around the grid.
    pub gap: u32,
}

impl Sheet {
    /// An empty sheet with `cols` pictures per row (at least 1).
    pub fn new(cols: usize) -> Self {
        Self {
            cols: cols.max(1),
            title: None,
            cells: Vec::new(),
            captions: CaptionPlace::Below,
            background: BACKGROUND,
            ink: INK,
            gap: 8,
        }
    }

    /// Sets a title line drawn centred over the grid.
    pub fn with_title(mut self, title: impl Into<String>) -> Self {
        self.title = Some(title.into());
        self
    }

    /// Sets where captions go.
    pub fn with_captions(mut self, place: CaptionPlace) -> Self {
        self.captions = place;
        self
    }

    /// Appends a picture and its caption (may be empty).
    pub fn push(&mut self, image: Image, caption: impl Into<String>) -> &mut Self {
        self.cells.push((image, caption.into()));
        self
    }

    /// Number of pictures.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// True when no picture was pushed.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Draws the sheet: `rows = ceil(len / cols)` rows of cells, captions, title.
    pub fn compose(&self) -> Image {
        let gap = self.gap;
        let cols = self.cols.min(self.cells.len()).max(1) as u32;
        let rows = self.cells.len().div_ceil(self.cols) as u32;
        let cell_w = self.cells.iter().map(|c| c.0.width).max().unwrap_or(0);
        let cell_h = self.cells.iter().map(|c| c.0.height).max().unwrap_or(0);
        let grid_w = cols * cell_w + (cols + 1) * gap;
        // Captions wrap to the cell width; the title to the grid width (or its own width).
        let cap_chars = (cell_w / CHAR).max(1) as usize;
        let captions: Vec<Vec<String>> = self.cells.iter().map(|c| wrap(&c.1, cap_chars)).collect();
        let cap_lines = captions.iter().map(Vec::len).max().unwrap_or(0) as u32;
        let cap_h = if cap_lines > 0 {
            cap_lines * CHAR + 4
        } else {
            0
        };
        let title_lines = self
            .title
            .as_deref()
            .map(|t| {
                let fit = if self.cells.is_empty() {
                    usize::MAX
                } else {
                    (grid_w / CHAR).max(1) as usize
                };
                wrap(t, fit)
            })
            .unwrap_or_default();
        let title_w = title_lines
            .iter()
            .map(|l| text_size(l, SCALE).0)
            .max()
            .unwrap_or(0);
        let title_h = if title_lines.is_empty() {
            0
        } else {
            title_lines.len() as u32 * CHAR + gap
        };
        let width = grid_w.max(title_w + 2 * gap);
        let row_h = cell_h + cap_h;
        let height = gap + title_h + rows * (row_h + gap);
        let mut out = Image::new(width, height.max(1), self.background);
        for (i, line) in title_lines.iter().enumerate() {
            let w = text_size(line, SCALE).0;
            let x = (width - w) / 2;
            draw_text(
                &mut out,
                x as i64,
                (gap + i as u32 * CHAR) as i64,
                line,
                SCALE,
                self.ink,
            );
        }
        let left = (width - grid_w) / 2 + gap;
        for (k, ((image, _), lines)) in self.cells.iter().zip(&captions).enumerate() {
            let (c, r) = ((k % self.cols) as u32, (k / self.cols) as u32);
            let x0 = left + c * (cell_w + gap);
            let y0 = gap + title_h + r * (row_h + gap);
            let (img_y, cap_y) = match self.captions {
                CaptionPlace::Below => (y0, y0 + cell_h + 4),
                CaptionPlace::Above => (y0 + cap_h, y0),
            };
            out.blit(
                image,
                (x0 + (cell_w - image.width) / 2) as i64,
                img_y as i64,
            );
            for (j, line) in lines.iter().enumerate() {
                let w = text_size(line, SCALE).0;
                let x = x0 as i64 + (cell_w as i64 - w as i64) / 2;
                draw_text(
                    &mut out,
                    x,
                    (cap_y + j as u32 * CHAR) as i64,
                    line,
                    SCALE,
                    self.ink,
                );
            }
        }
        out
    }

    /// Composes the sheet and writes it as a PNG atomically (see [`Image::save_png`]).
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        self.compose().save_png(path)
    }
}

/// Splits `text` into lines of at most `max` characters: at `'\n'`, then between words, and
/// inside words longer than a line. An empty text gives no lines.
fn wrap(text: &str, max: usize) -> Vec<String> {
    let mut out = Vec::new();
    if text.is_empty() {
        return out;
    }
    for para in text.split('\n') {
        let mut line = String::new();
        let mut len = 0;
        for word in para.split(' ').filter(|w| !w.is_empty()) {
            let mut chars: Vec<char> = word.chars().collect();
            let need = if len == 0 {
                chars.len()
            } else {
                len + 1 + chars.len()
            };
            if need <= max {
                if len > 0 {
                    line.push(' ');
                    len += 1;
                }
                line.extend(&chars);
                len += chars.len();
                continue;
            }
            if len > 0 {
                out.push(std::mem::take(&mut line));
            }
            while chars.len() > max {
                out.push(chars.drain(..max).collect());
            }
            len = chars.len();
            line.extend(chars);
        }
        out.push(line);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_splits_words_and_long_words() {
        assert_eq!(wrap("ab cd ef", 5), vec!["ab cd", "ef"]);
        assert_eq!(wrap("abcdefgh", 3), vec!["abc", "def", "gh"]);
        assert_eq!(wrap("a\nb", 10), vec!["a", "b"]);
        assert!(wrap("", 4).is_empty());
    }

    #[test]
    fn sheet_layout_and_labels() {
        let mut s = Sheet::new(2).with_title("Title");
        for i in 0..3 {
            s.push(Image::new(40 + 10 * i, 30, [200, 0, 0]), format!("c {i}"));
        }
        let im = s.compose();
        // 2 columns of 60 px cells, 8 px gaps; 2 rows of 30 px + one caption line.
        assert_eq!(im.width, 2 * 60 + 3 * 8);
        assert_eq!(im.height, 8 + (16 + 8) + 2 * (30 + 16 + 4 + 8));
        // Captions and title are drawn in ink.
        let ink = im.rgb.chunks_exact(3).filter(|p| *p == INK).count();
        assert!(ink > 200, "{ink}");
        // Title alone, no cells.
        let t = Sheet::new(3).with_title("only a title").compose();
        assert!(t.count_not(BACKGROUND) > 0);
        // Captions above also draw.
        let mut a = Sheet::new(1).with_captions(CaptionPlace::Above);
        a.push(Image::new(64, 8, [0, 0, 200]), "top");
        let a = a.compose();
        assert!(a.rgb.chunks_exact(3).any(|p| p == INK));
    }
}
