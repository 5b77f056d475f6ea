//! Line charts (precision curves and the like) drawn with the crate's own text, so a
//! report needs no font files or plotting stack.

use crate::text::{draw_text, text_size};
use crate::Image;

/// One curve of a chart: its name in the legend, colour and points `(x, y)` in data units.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Line colour.
    pub color: [u8; 3],
    /// Points in data units, in drawing order.
    pub points: Vec<(f32, f32)>,
}

/// A line chart: axes from `x_range` and `y_range` (data units), `ticks` tick marks per
/// axis, labels, a title and a legend. `size`: image width and height in pixels.
#[derive(Clone, Debug)]
pub struct Chart {
    /// Title above the plot.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Horizontal data range.
    pub x_range: (f32, f32),
    /// Vertical data range.
    pub y_range: (f32, f32),
    /// Tick intervals per axis.
    pub ticks: u32,
    /// Image size in pixels.
    pub size: (u32, u32),
}

const INK: [u8; 3] = [40, 40, 40];
const GRID: [u8; 3] = [225, 225, 225];
const PAPER: [u8; 3] = [255, 255, 255];
/// Legend width beyond its longest name: the colour swatch, the gap and a margin (pixels).
const LEGEND_PAD: i64 = 30;

impl Chart {
    /// Draws `series` into a new image.
    pub fn draw(&self, series: &[Series]) -> Image {
        let (w, h) = self.size;
        let mut img = Image::new(w, h, PAPER);
        let (left, right, top, bottom) = (70i64, 20i64, 36i64, 50i64);
        let (pw, ph) = (
            (w as i64 - left - right).max(1),
            (h as i64 - top - bottom).max(1),
        );
        let to_px = |x: f32, y: f32| -> (f32, f32) {
            let (x0, x1) = self.x_range;
            let (y0, y1) = self.y_range;
            let u = (x - x0) / (x1 - x0).max(f32::EPSILON);
            let v = (y - y0) / (y1 - y0).max(f32::EPSILON);
            (
                left as f32 + u * pw as f32,
                (top + ph) as f32 - v * ph as f32,
            )
        };
        let ticks = self.ticks.max(1);
        for k in 0..=ticks {
            let t = k as f32 / ticks as f32;
            let x = left + (t * pw as f32) as i64;
            let y = top + ph - (t * ph as f32) as i64;
            img.fill_rect(x, top, 1, ph as u32, GRID);
            img.fill_rect(left, y, pw as u32, 1, GRID);
            let xv = self.x_range.0 + t * (self.x_range.1 - self.x_range.0);
            let yv = self.y_range.0 + t * (self.y_range.1 - self.y_range.0);
            let xs = format!("{xv:.4}")
                .trim_end_matches('0')
                .trim_end_matches('.')
                .to_string();
            let ys = format!("{yv:.4}")
                .trim_end_matches('0')
                .trim_end_matches('.')
                .to_string();
            let (tw, _) = text_size(&xs, 1);
            draw_text(&mut img, x - tw as i64 / 2, top + ph + 6, &xs, 1, INK);
            let (tw, _) = text_size(&ys, 1);
            draw_text(&mut img, left - 6 - tw as i64, y - 4, &ys, 1, INK);
        }
        img.fill_rect(left, top, 1, ph as u32, INK);
        img.fill_rect(left, top + ph, pw as u32, 1, INK);
        let (tw, _) = text_size(&self.title, 2);
        draw_text(&mut img, (w as i64 - tw as i64) / 2, 8, &self.title, 2, INK);
        let (tw, _) = text_size(&self.x_label, 1);
        draw_text(
            &mut img,
            left + (pw - tw as i64) / 2,
            h as i64 - 20,
            &self.x_label,
            1,
            INK,
        );
        draw_text(&mut img, 4, top - 14, &self.y_label, 1, INK);
        let mut ink = Vec::new();
        for s in series {
            for pair in s.points.windows(2) {
                let (a, b) = (to_px(pair[0].0, pair[0].1), to_px(pair[1].0, pair[1].1));
                ink.extend(line(&mut img, a, b, s.color));
            }
        }
        // The legend on a paper box as wide as its longest name, in the corner of the plot
        // its curves cross least (top right when none does).
        let name_w = series
            .iter()
            .map(|s| text_size(&s.name, 1).0 as i64)
            .max()
            .unwrap_or(0);
        let (box_w, box_h) = (name_w + LEGEND_PAD, 14 * series.len() as i64 + 6);
        let (x_right, x_left) = ((left + pw - box_w - 4).max(left + 2), left + 6);
        let (y_top, y_bottom) = (top + 6, (top + ph - box_h - 6).max(top + 6));
        let corners = [
            (x_right, y_top),
            (x_left, y_top),
            (x_right, y_bottom),
            (x_left, y_bottom),
        ];
        let crossed = |&(bx, by): &(i64, i64)| {
            ink.iter()
                .filter(|&&(x, y)| x >= bx && x < bx + box_w && y >= by && y < by + box_h)
                .count()
        };
        let (bx, by) = corners
            .iter()
            .copied()
            .min_by_key(crossed)
            .unwrap_or(corners[0]);
        if !series.is_empty() {
            img.fill_rect(bx, by, box_w as u32, box_h as u32, PAPER);
        }
        for (i, s) in series.iter().enumerate() {
            let (x, y) = (bx + 4, by + 4 + 14 * i as i64);
            img.fill_rect(x, y + 3, 16, 3, s.color);
            draw_text(&mut img, x + 22, y, &s.name, 1, INK);
        }
        img
    }
}

/// A 2-pixel-wide line from `a` to `b` (pixels), clipped to the image; returns the pixels
/// it was drawn through (one per step, before clipping).
fn line(img: &mut Image, a: (f32, f32), b: (f32, f32), color: [u8; 3]) -> Vec<(i64, i64)> {
    let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).max(1);
    (0..=steps)
        .map(|k| {
            let t = k as f32 / steps as f32;
            let (x, y) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
            let p = (x.round() as i64, y.round() as i64);
            img.fill_rect(p.0, p.1, 2, 2, color);
            p
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chart of the unit square, `w` x `h` pixels.
    fn unit_chart(w: u32, h: u32) -> Chart {
        Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            ticks: 4,
            size: (w, h),
        }
    }

    #[test]
    fn a_rising_line_is_drawn_from_lower_left_to_upper_right() {
        let chart = unit_chart(300, 200);
        let red = [255, 0, 0];
        let img = chart.draw(&[Series {
            name: "s".into(),
            color: red,
            points: vec![(0.0, 0.0), (1.0, 1.0)],
        }]);
        // Plot area: x 70..280, y 36..150. The line passes its centre, not the area above
        // the diagonal (the legend's red swatch is in the top left corner).
        assert_eq!(img.pixel(175, 93), red);
        assert_ne!(img.pixel(150, 70), red);
        assert!(img.count_not(PAPER) > 500);
    }

    /// Regression: the legend sat in the top right corner whatever the curves did, and hid
    /// the precision curves' top (they rise to the right). It goes where no curve runs.
    #[test]
    fn the_legend_keeps_off_the_curves() {
        let chart = unit_chart(400, 300);
        let red = [255, 0, 0];
        let curve = |points: Vec<(f32, f32)>| {
            chart.draw(&[Series {
                name: "a fairly long series name".into(),
                color: red,
                points,
            }])
        };
        // Plot area: x 70..380, y 36..250. Red pixels covered by the paper box are lost.
        let red_pixels = |img: &Image| {
            (0..400)
                .flat_map(|x| (0..300).map(move |y| (x, y)))
                .filter(|&(x, y)| img.pixel(x, y) == red)
                .count()
        };
        // A precision-like curve: up steeply, then on to 0.9 at the right edge, through the
        // top right corner.
        let rising = curve(vec![(0.0, 0.0), (0.3, 0.6), (1.0, 0.9)]);
        // Along the bottom: the legend stays top right.
        let flat = curve(vec![(0.0, 0.02), (1.0, 0.02)]);
        for img in [&rising, &flat] {
            assert!(red_pixels(img) > 2 * 300, "{}", red_pixels(img));
        }
        // The rising curve is drawn where the legend used to be (x 375: y 0.893, row 59),
        // and the legend's text is in the top left instead.
        assert_eq!(rising.pixel(375, 59), red, "curve under the legend");
        let ink = |img: &Image, xs: std::ops::Range<u32>| {
            (42..62).any(|y| xs.clone().any(|x| img.pixel(x, y) == INK))
        };
        assert!(ink(&rising, 72..200) && !ink(&rising, 330..380));
        assert!(ink(&flat, 330..380) && !ink(&flat, 72..100));
    }

    /// Regression: names were drawn from a fixed 150 px before the right edge, so
    /// "tshirt GarNet-global" ran off the plot.
    #[test]
    fn a_long_legend_name_stays_inside_the_plot() {
        let chart = unit_chart(400, 200);
        let name = "sweater GarNet-global and more";
        let img = chart.draw(&[Series {
            name: name.into(),
            color: [0, 0, 255],
            points: vec![],
        }]);
        let (tw, th) = text_size(name, 1);
        // The plot's right edge is x = 380; the text ends left of it.
        let right = 380i64;
        let ink_beyond = (right..400)
            .flat_map(|x| (36..36 + 20 + th as i64).map(move |y| (x, y)))
            .filter(|&(x, y)| img.pixel(x as u32, y as u32) == INK)
            .count();
        assert_eq!(ink_beyond, 0);
        // And it is drawn: ink of the text width lies in the legend row.
        let ink_row = (0..400)
            .filter(|&x| (46..46 + th as i64).any(|y| img.pixel(x, y as u32) == INK))
            .count();
        assert!(ink_row as u32 > tw / 3, "{ink_row} of {tw}");
    }
}
