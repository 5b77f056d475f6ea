//! Acclaim motion files (AMC): per-frame values of an [`Asf`] skeleton's degrees of freedom.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::asf::{Asf, Dof};
use super::error::{parse_num, read_text, PoseError};

/// A parsed AMC clip. Every frame is one row of values laid out as
/// [`Asf::value_layout`] says: angles in radians, translations in the ASF length unit.
#[derive(Clone, Debug, PartialEq)]
pub struct Amc {
    /// The file it was read from.
    pub path: PathBuf,
    /// The frame numbers written in the file, `[F]`.
    pub frame_numbers: Vec<i64>,
    values: Vec<f64>,
    stride: usize,
    offsets: Vec<usize>,
    root_len: usize,
}

impl Amc {
    /// Reads an AMC file recorded for `asf`.
    pub fn read(path: impl AsRef<Path>, asf: &Asf) -> Result<Amc, PoseError> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, path, asf)
    }

    /// Parses AMC text for `asf`; `path` is used in error messages.
    pub fn parse(text: &str, path: &Path, asf: &Asf) -> Result<Amc, PoseError> {
        let (offsets, stride) = asf.value_layout();
        let root_len = asf.root.order.len();
        let names: HashMap<&str, usize> = asf
            .bones
            .iter()
            .enumerate()
            .map(|(i, b)| (b.name.as_str(), i))
            .collect();
        let deg = std::f64::consts::PI / 180.0;
        let mut angle_scale = if asf.units.degrees { deg } else { 1.0 };
        let mut fully_specified = false;
        let mut frame_numbers = Vec::new();
        let mut values: Vec<f64> = Vec::new();
        // Which of root (index 0) and bones (1 + i) the current frame has seen.
        let mut seen = vec![false; asf.bones.len() + 1];
        let mut frame_line = 0;
        let mut last_line = 0;
        let check_frame = |seen: &[bool], line: usize, at_end: bool, fully: bool, number: i64| {
            if !fully {
                return Ok(());
            }
            let missing: Vec<&str> = std::iter::once((root_len, "root"))
                .chain(asf.bones.iter().map(|b| (b.dofs.len(), b.name.as_str())))
                .zip(seen)
                .filter(|((n, _), s)| *n > 0 && !**s)
                .map(|((_, name), _)| name)
                .collect();
            if missing.is_empty() {
                return Ok(());
            }
            let msg = if at_end {
                format!(
                    "file ends in the middle of frame {number}: no values for {} (truncated file?)",
                    missing.join(", ")
                )
            } else {
                format!("frame {number} has no values for {}", missing.join(", "))
            };
            Err(PoseError::parse(path, line, msg))
        };
        for (i, raw) in text.lines().enumerate() {
            let ln = i + 1;
            last_line = ln;
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            if line.starts_with(':') {
                match line.to_ascii_uppercase().as_str() {
                    ":FULLY-SPECIFIED" => fully_specified = true,
                    ":DEGREES" => angle_scale = deg,
                    ":RADIANS" => angle_scale = 1.0,
                    _ => {}
                }
                continue;
            }
            let mut toks = line.split_whitespace();
            let first = toks.next().unwrap_or("");
            if first.bytes().all(|c| c.is_ascii_digit()) {
                if toks.next().is_some() {
                    return Err(PoseError::parse(
                        path,
                        ln,
                        "frame number followed by other values",
                    ));
                }
                if let Some(&n) = frame_numbers.last() {
                    check_frame(&seen, frame_line, false, fully_specified, n)?;
                }
                let n: i64 = first.parse().map_err(|_| {
                    PoseError::parse(path, ln, format!("bad frame number '{first}'"))
                })?;
                frame_numbers.push(n);
                values.resize(values.len() + stride, 0.0);
                seen.iter_mut().for_each(|s| *s = false);
                frame_line = ln;
                continue;
            }
            if frame_numbers.is_empty() {
                return Err(PoseError::parse(
                    path,
                    ln,
                    format!("values for '{first}' before the first frame number"),
                ));
            }
            let (slot, start, dofs): (usize, usize, &[Dof]) = if first == "root" {
                (0, 0, &asf.root.order)
            } else {
                let b = *names.get(first).ok_or_else(|| {
                    PoseError::parse(
                        path,
                        ln,
                        format!("unknown bone '{first}' (not in {})", asf.path.display()),
                    )
                })?;
                (b + 1, offsets[b], &asf.bones[b].dofs)
            };
            if seen[slot] {
                return Err(PoseError::parse(
                    path,
                    ln,
                    format!("'{first}' given twice in one frame"),
                ));
            }
            seen[slot] = true;
            let row = values.len() - stride + start;
            let mut count = 0;
            for (k, tok) in toks.enumerate() {
                count = k + 1;
                if k >= dofs.len() {
                    continue;
                }
                let v = parse_num(tok, path, ln, first)?;
                let scale = if dofs[k].rotation_axis().is_some() {
                    angle_scale
                } else {
                    1.0
                };
                values[row + k] = v * scale;
            }
            if count != dofs.len() {
                return Err(PoseError::parse(
                    path,
                    ln,
                    format!("'{first}' has {count} values, expected {}", dofs.len()),
                ));
            }
        }
        match frame_numbers.last() {
            Some(&n) => check_frame(&seen, last_line, true, fully_specified, n)?,
            None => {
                return Err(PoseError::parse(
                    path,
                    last_line.max(1),
                    "no frames (empty or truncated file?)",
                ))
            }
        }
        Ok(Amc {
            path: path.to_path_buf(),
            frame_numbers,
            values,
            stride,
            offsets,
            root_len,
        })
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.frame_numbers.len()
    }

    /// All values of frame `f` (`[stride]`, see [`Asf::value_layout`]). Panics if `f` is
    /// out of range (callers check [`Amc::frame_count`]).
    pub fn frame(&self, f: usize) -> &[f64] {
        &self.values[f * self.stride..(f + 1) * self.stride]
    }

    /// The root's values of frame `f`, in the ASF `:root order`.
    pub fn root(&self, f: usize) -> &[f64] {
        &self.frame(f)[..self.root_len]
    }

    /// The values of ASF bone `bone` in frame `f`, in the order of its `dof` line.
    pub fn bone(&self, f: usize, bone: usize) -> &[f64] {
        let start = self.offsets[bone];
        let end = self.offsets.get(bone + 1).copied().unwrap_or(self.stride);
        &self.frame(f)[start..end]
    }

    /// Whether this clip's value layout fits `asf` (same number of values per frame and
    /// per bone).
    pub fn fits(&self, asf: &Asf) -> bool {
        let (offsets, stride) = asf.value_layout();
        offsets == self.offsets && stride == self.stride && asf.root.order.len() == self.root_len
    }
}
