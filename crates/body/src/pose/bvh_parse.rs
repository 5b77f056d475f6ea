//! The BVH text parser behind [`Bvh::parse`](super::Bvh::parse).

use std::path::Path;

use glam::DVec3;

use super::bvh::{BvhChannel, BvhJoint};
use super::error::{parse_num, PoseError};

/// Joints, channel count, frame time and values of a BVH text.
type Parsed = (Vec<BvhJoint>, usize, f64, Vec<f64>);

/// Parses the HIERARCHY and MOTION sections; rotations are converted to radians.
pub(super) fn parse(text: &str, path: &Path) -> Result<Parsed, PoseError> {
    let lines: Vec<&str> = text.lines().collect();
    let last_line = lines.len().max(1);
    let motion = lines
        .iter()
        .position(|l| l.split_whitespace().next() == Some("MOTION"))
        .ok_or_else(|| PoseError::parse(path, last_line, "no MOTION section (truncated file?)"))?;
    let tokens: Vec<(usize, &str)> = lines[..motion]
        .iter()
        .enumerate()
        .flat_map(|(i, l)| l.split_whitespace().map(move |t| (i + 1, t)))
        .collect();
    let mut h = HierarchyParser {
        path,
        tokens: &tokens,
        at: 0,
        end_line: motion + 1,
        joints: Vec::new(),
        channels: 0,
    };
    h.expect("HIERARCHY")?;
    h.expect("ROOT")?;
    h.joint(None)?;
    if let Some(&(ln, t)) = tokens.get(h.at) {
        return Err(PoseError::parse(
            path,
            ln,
            format!("unexpected '{t}' after the root joint (only one ROOT is supported)"),
        ));
    }
    let (joints, channel_count) = (h.joints, h.channels);
    let (frame_time, values) = parse_motion(&lines, motion, path, &joints, channel_count)?;
    Ok((joints, channel_count, frame_time, values))
}

struct HierarchyParser<'a, 'b> {
    path: &'a Path,
    tokens: &'b [(usize, &'a str)],
    at: usize,
    end_line: usize,
    joints: Vec<BvhJoint>,
    channels: usize,
}

impl<'a> HierarchyParser<'a, '_> {
    fn next(&mut self, what: &str) -> Result<(usize, &'a str), PoseError> {
        let t = self.tokens.get(self.at).copied().ok_or_else(|| {
            PoseError::parse(
                self.path,
                self.end_line,
                format!("hierarchy ends where {what} was expected"),
            )
        })?;
        self.at += 1;
        Ok(t)
    }

    fn expect(&mut self, word: &str) -> Result<usize, PoseError> {
        let (ln, t) = self.next(&format!("'{word}'"))?;
        if t != word {
            return Err(PoseError::parse(
                self.path,
                ln,
                format!("expected '{word}', found '{t}'"),
            ));
        }
        Ok(ln)
    }

    fn offset(&mut self) -> Result<DVec3, PoseError> {
        self.expect("OFFSET")?;
        let mut v = [0.0; 3];
        for x in &mut v {
            let (ln, t) = self.next("an OFFSET value")?;
            *x = parse_num(t, self.path, ln, "OFFSET")?;
        }
        Ok(v.into())
    }

    fn joint(&mut self, parent: Option<usize>) -> Result<(), PoseError> {
        // A name runs to the end of its line or a '{' (`JOINT Bip01 L Thigh`).
        let (ln, first) = self.next("a joint name")?;
        let mut name = first.to_string();
        while let Some(&(l, t)) = self.tokens.get(self.at) {
            if l != ln || t == "{" {
                break;
            }
            name.push(' ');
            name.push_str(t);
            self.at += 1;
        }
        self.expect("{")?;
        let offset = self.offset()?;
        let index = self.joints.len();
        self.joints.push(BvhJoint {
            name,
            parent,
            offset,
            channels: Vec::new(),
            first_channel: self.channels,
            end_site: None,
        });
        loop {
            let (ln, t) = self.next("'}'")?;
            match t {
                "CHANNELS" => {
                    if !self.joints[index].channels.is_empty() {
                        return Err(PoseError::parse(
                            self.path,
                            ln,
                            "second CHANNELS line in one joint",
                        ));
                    }
                    let (_, n) = self.next("a channel count")?;
                    let n: usize = n.parse().ok().filter(|&n| n <= 6).ok_or_else(|| {
                        PoseError::parse(
                            self.path,
                            ln,
                            format!("CHANNELS: bad channel count '{n}' (0 to 6)"),
                        )
                    })?;
                    for k in 0..n {
                        let (cl, c) = self.next("a channel name")?;
                        let ch = BvhChannel::parse(c).ok_or_else(|| {
                            PoseError::parse(
                                self.path,
                                ln,
                                format!(
                                    "CHANNELS {n}: channel {} is '{c}' (line {cl}), not a channel name such as Zrotation (wrong channel count?)",
                                    k + 1
                                ),
                            )
                        })?;
                        self.joints[index].channels.push(ch);
                    }
                    self.joints[index].first_channel = self.channels;
                    self.channels += n;
                }
                "JOINT" => {
                    self.joint(Some(index))?;
                }
                "End" => {
                    self.expect("Site")?;
                    self.expect("{")?;
                    let e = self.offset()?;
                    self.expect("}")?;
                    if self.joints[index].end_site.is_some() {
                        return Err(PoseError::parse(
                            self.path,
                            ln,
                            "second End Site in one joint",
                        ));
                    }
                    self.joints[index].end_site = Some(e);
                }
                "}" => return Ok(()),
                other => {
                    return Err(PoseError::parse(
                        self.path,
                        ln,
                        format!("expected CHANNELS, JOINT, End Site or '}}', found '{other}'"),
                    ))
                }
            }
        }
    }
}

/// Parses the MOTION section starting at line index `motion`; returns the frame time and
/// the values (rotations converted to radians).
fn parse_motion(
    lines: &[&str],
    motion: usize,
    path: &Path,
    joints: &[BvhJoint],
    channel_count: usize,
) -> Result<(f64, Vec<f64>), PoseError> {
    let last_line = lines.len().max(1);
    let mut is_rotation = vec![false; channel_count];
    for j in joints {
        for (k, c) in j.channels.iter().enumerate() {
            is_rotation[j.first_channel + k] = matches!(c, BvhChannel::Rotation(_));
        }
    }
    let mut i = motion + 1;
    let mut header = |key: &str| -> Result<(usize, String), PoseError> {
        while i < lines.len() && lines[i].trim().is_empty() {
            i += 1;
        }
        let line = lines.get(i).ok_or_else(|| {
            PoseError::parse(
                path,
                last_line,
                format!("file ends before '{key}' (truncated file?)"),
            )
        })?;
        let rest = line.trim().strip_prefix(key).ok_or_else(|| {
            PoseError::parse(
                path,
                i + 1,
                format!("expected '{key}', found '{}'", line.trim()),
            )
        })?;
        i += 1;
        Ok((i, rest.trim().to_string()))
    };
    let (ln, n) = header("Frames:")?;
    let frames: usize = n
        .parse()
        .map_err(|_| PoseError::parse(path, ln, format!("Frames: bad count '{n}'")))?;
    let (ln, t) = header("Frame Time:")?;
    let frame_time = parse_num(&t, path, ln, "Frame Time")?;
    if frame_time <= 0.0 {
        return Err(PoseError::parse(path, ln, "Frame Time must be positive"));
    }
    let deg = std::f64::consts::PI / 180.0;
    let mut values = Vec::with_capacity(frames * channel_count);
    let mut read = 0;
    for (k, line) in lines.iter().enumerate().skip(i) {
        let ln = k + 1;
        if line.trim().is_empty() {
            continue;
        }
        if read == frames {
            return Err(PoseError::parse(
                path,
                ln,
                format!("more frames than the {frames} declared"),
            ));
        }
        let start = values.len();
        for tok in line.split_whitespace() {
            let v = parse_num(tok, path, ln, "frame value")?;
            let c = values.len() - start;
            values.push(if c < channel_count && is_rotation[c] {
                v * deg
            } else {
                v
            });
        }
        let found = values.len() - start;
        if found != channel_count {
            return Err(PoseError::parse(
                path,
                ln,
                format!("frame {read} has {found} values, expected {channel_count}"),
            ));
        }
        read += 1;
    }
    if read < frames {
        return Err(PoseError::parse(
            path,
            last_line,
            format!("file ends after {read} of {frames} frames (truncated file?)"),
        ));
    }
    Ok((frame_time, values))
}
