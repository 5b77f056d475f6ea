//! [`Image`]: an 8-bit RGB picture, its PNG encoding and atomic saving.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::RenderError;

/// An 8-bit sRGB picture, row-major from the top-left corner.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, `width * height * 3` bytes (R, G, B per pixel, rows top to bottom).
    pub rgb: Vec<u8>,
}

impl Image {
    /// A `width x height` picture filled with `color` (sRGB).
    pub fn new(width: u32, height: u32, color: [u8; 3]) -> Self {
        let n = width as usize * height as usize;
        let mut rgb = Vec::with_capacity(n * 3);
        for _ in 0..n {
            rgb.extend_from_slice(&color);
        }
        Self { width, height, rgb }
    }

    /// Wraps an RGB buffer of `width * height * 3` bytes.
    pub fn from_rgb(width: u32, height: u32, rgb: Vec<u8>) -> Result<Self, RenderError> {
        let expected = width as usize * height as usize * 3;
        if rgb.len() != expected {
            return Err(RenderError::BufferSize {
                got: rgb.len(),
                expected,
            });
        }
        Ok(Self { width, height, rgb })
    }

    /// The colour at column `x`, row `y` (from the top); panics outside the picture.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside the image"
        );
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Sets the colour at column `x`, row `y`; does nothing outside the picture.
    pub fn set_pixel(&mut self, x: u32, y: u32, color: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y as usize * self.width as usize + x as usize);
            self.rgb[i..i + 3].copy_from_slice(&color);
        }
    }

    /// Fills the rectangle at (`x`, `y`) of `w x h` pixels (clipped to the picture).
    pub fn fill_rect(&mut self, x: i64, y: i64, w: u32, h: u32, color: [u8; 3]) {
        let x0 = x.clamp(0, self.width as i64) as u32;
        let y0 = y.clamp(0, self.height as i64) as u32;
        let x1 = (x + w as i64).clamp(0, self.width as i64) as u32;
        let y1 = (y + h as i64).clamp(0, self.height as i64) as u32;
        for yy in y0..y1 {
            for xx in x0..x1 {
                self.set_pixel(xx, yy, color);
            }
        }
    }

    /// Copies `src` with its top-left corner at (`x`, `y`), clipped to this picture.
    pub fn blit(&mut self, src: &Image, x: i64, y: i64) {
        for sy in 0..src.height {
            let dy = y + sy as i64;
            if dy < 0 || dy >= self.height as i64 {
                continue;
            }
            let sx0 = (-x).max(0) as u32;
            let sx1 = (self.width as i64 - x).clamp(0, src.width as i64) as u32;
            if sx0 >= sx1 {
                continue;
            }
            let s = 3 * (sy as usize * src.width as usize + sx0 as usize);
            let d = 3 * (dy as usize * self.width as usize + (x + sx0 as i64) as usize);
            let n = 3 * (sx1 - sx0) as usize;
            self.rgb[d..d + n].copy_from_slice(&src.rgb[s..s + n]);
        }
    }

    /// Pictures side by side, tops aligned; shorter ones are padded below with `background`.
    pub fn hstack(images: &[Image], background: [u8; 3]) -> Image {
        let width = images.iter().map(|i| i.width).sum();
        let height = images.iter().map(|i| i.height).max().unwrap_or(0);
        let mut out = Image::new(width, height, background);
        let mut x = 0i64;
        for im in images {
            out.blit(im, x, 0);
            x += im.width as i64;
        }
        out
    }

    /// Number of pixels whose colour differs from `color`.
    pub fn count_not(&self, color: [u8; 3]) -> usize {
        self.rgb.chunks_exact(3).filter(|p| *p != color).count()
    }

    /// The picture as PNG bytes (8-bit RGB).
    pub fn encode_png(&self) -> Result<Vec<u8>, RenderError> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut writer = enc.write_header()?;
            writer.write_image_data(&self.rgb)?;
            writer.finish()?;
        }
        Ok(out)
    }

    /// Decodes PNG bytes of any colour type and bit depth into 8-bit RGB (alpha is dropped,
    /// grey is expanded, 16-bit samples are truncated to their high byte).
    pub fn decode_png(bytes: &[u8]) -> Result<Image, RenderError> {
        let err = |e: png::DecodingError| RenderError::PngDecode(e.to_string());
        let mut dec = png::Decoder::new(bytes);
        dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = dec.read_info().map_err(err)?;
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).map_err(err)?;
        let (w, h) = (info.width, info.height);
        let n = w as usize * h as usize;
        let channels = match info.color_type {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => {
                return Err(RenderError::PngDecode(
                    "indexed colour was not expanded".into(),
                ))
            }
        };
        let mut rgb = Vec::with_capacity(n * 3);
        for y in 0..h as usize {
            let row = &buf[y * info.line_size..];
            for x in 0..w as usize {
                let p = &row[x * channels..];
                if channels < 3 {
                    rgb.extend_from_slice(&[p[0]; 3]);
                } else {
                    rgb.extend_from_slice(&p[..3]);
                }
            }
        }
        Image::from_rgb(w, h, rgb)
    }

    /// Writes the picture as a PNG file, atomically: the bytes go to a temporary file in the
    /// same directory, which is then renamed over `path` (removed again on any error).
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        let bytes = self.encode_png()?;
        write_atomic(path.as_ref(), &bytes)
    }

    /// Reads a PNG file (see [`Image::decode_png`] for the colour types accepted).
    pub fn from_png(path: impl AsRef<Path>) -> Result<Image, RenderError> {
        let path = path.as_ref();
        let bytes = fs::read(path).map_err(|source| RenderError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Image::decode_png(&bytes)
    }
}

/// Writes `bytes` to `path` through a temporary sibling file and a rename.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), RenderError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let io_err = |p: &Path, source| RenderError::Io {
        path: p.display().to_string(),
        source,
    };
    let name = path
        .file_name()
        .ok_or_else(|| io_err(path, std::io::Error::other("no file name")))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(
        ".{}.{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp: PathBuf = path.with_file_name(tmp_name);
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = fs::remove_file(&tmp);
        io_err(path, e)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Image {
        let mut im = Image::new(7, 5, [10, 20, 30]);
        for y in 0..5 {
            for x in 0..7 {
                im.set_pixel(x, y, [(x * 30) as u8, (y * 50) as u8, ((x + y) * 7) as u8]);
            }
        }
        im
    }

    #[test]
    fn png_round_trip_is_identical() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let im = sample();
        im.save_png(&path).unwrap();
        assert_eq!(Image::from_png(&path).unwrap(), im);
        // Only the final file remains: no temporary left behind.
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn failed_save_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        // Renaming a file over a non-empty directory fails.
        let target = dir.path().join("taken");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("x"), b"x").unwrap();
        assert!(sample().save_png(&target).is_err());
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
        assert!(Image::from_png(dir.path().join("missing.png")).is_err());
    }

    #[test]
    fn blit_clips_and_hstack_pads() {
        let a = Image::new(2, 2, [1, 1, 1]);
        let b = Image::new(3, 1, [2, 2, 2]);
        let s = Image::hstack(&[a.clone(), b], [9, 9, 9]);
        assert_eq!((s.width, s.height), (5, 2));
        assert_eq!(s.pixel(4, 1), [9, 9, 9]);
        assert_eq!(s.pixel(2, 0), [2, 2, 2]);
        let mut c = Image::new(3, 3, [0; 3]);
        c.blit(&a, -1, 2);
        assert_eq!(c.count_not([0; 3]), 1);
        assert_eq!(c.pixel(0, 2), [1, 1, 1]);
    }
}
