//! Biovision hierarchy files (BVH) as the CMU conversions write them.
//!
//! The rest pose is the skeleton of the OFFSETs with every rotation zero. A joint's
//! rotation channels compose in the order the CHANNELS line lists them (intrinsic, left
//! to right); its position channels add to its OFFSET. A joint's world rotation rotates
//! the OFFSETs of its children.

use std::path::{Path, PathBuf};

use glam::{DQuat, DVec3};

use super::error::{parse_num, read_text, PoseError};
use super::euler::Axis;

/// One channel of a BVH joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhChannel {
    /// Translation along an axis (file length unit).
    Position(Axis),
    /// Rotation about an axis (degrees in the file, radians once read).
    Rotation(Axis),
}

impl BvhChannel {
    fn parse(s: &str) -> Option<BvhChannel> {
        let lower = s.to_ascii_lowercase();
        let axis = Axis::from_char(lower.chars().next()?)?;
        match &lower[1..] {
            "position" => Some(BvhChannel::Position(axis)),
            "rotation" => Some(BvhChannel::Rotation(axis)),
            _ => None,
        }
    }

    /// The name written in a CHANNELS line (`Zrotation`).
    pub fn name(self) -> &'static str {
        match self {
            BvhChannel::Position(Axis::X) => "Xposition",
            BvhChannel::Position(Axis::Y) => "Yposition",
            BvhChannel::Position(Axis::Z) => "Zposition",
            BvhChannel::Rotation(Axis::X) => "Xrotation",
            BvhChannel::Rotation(Axis::Y) => "Yrotation",
            BvhChannel::Rotation(Axis::Z) => "Zrotation",
        }
    }
}

/// One joint of a BVH hierarchy.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhJoint {
    /// The joint name (`LeftUpLeg`).
    pub name: String,
    /// Index of the parent joint; `None` for the root. Parents precede children.
    pub parent: Option<usize>,
    /// Rest position relative to the parent joint, file length unit.
    pub offset: DVec3,
    /// The joint's channels in file order.
    pub channels: Vec<BvhChannel>,
    /// Index of the joint's first channel in a frame's value row.
    pub first_channel: usize,
    /// The `End Site` offset, if the joint has one (file length unit).
    pub end_site: Option<DVec3>,
}

/// A parsed BVH clip.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    /// The file it was read from.
    pub path: PathBuf,
    /// Joints, parents first.
    pub joints: Vec<BvhJoint>,
    /// Seconds per frame.
    pub frame_time: f64,
    /// Metres per file length unit (given, or detected from the skeleton's height).
    pub metres_per_unit: f64,
    /// Values per frame (all joints' channels).
    pub channel_count: usize,
    values: Vec<f64>,
}

/// Rest height of a standing adult's joints (toes to top of head), metres, used to detect
/// the length unit of a BVH file.
const TYPICAL_JOINT_HEIGHT_M: f64 = 1.6;

/// Candidate metres-per-unit of BVH files: metres, centimetres, millimetres, inches and
/// the CMU ASF unit (1/0.45 inch).
const UNIT_CANDIDATES: [f64; 5] = [1.0, 0.01, 0.001, 0.0254, 0.0254 / 0.45];

impl Bvh {
    /// Reads a BVH file. `metres_per_unit`: the file's length unit in metres, or `None` to
    /// pick the one (m, cm, mm, inch, CMU unit) that makes the skeleton about 1.6 m tall.
    pub fn read(path: impl AsRef<Path>, metres_per_unit: Option<f64>) -> Result<Bvh, PoseError> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, path, metres_per_unit)
    }

    /// Parses BVH text; `path` is used in error messages. See [`Bvh::read`].
    pub fn parse(text: &str, path: &Path, metres_per_unit: Option<f64>) -> Result<Bvh, PoseError> {
        let lines: Vec<&str> = text.lines().collect();
        let last_line = lines.len().max(1);
        let motion = lines
            .iter()
            .position(|l| l.split_whitespace().next() == Some("MOTION"))
            .ok_or_else(|| {
                PoseError::parse(path, last_line, "no MOTION section (truncated file?)")
            })?;
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
        let metres_per_unit = match metres_per_unit {
            Some(s) if s.is_finite() && s > 0.0 => s,
            Some(s) => {
                return Err(PoseError::Invalid(format!(
                    "BVH unit {s} m is not positive"
                )))
            }
            None => detect_unit(&joints),
        };
        Ok(Bvh {
            path: path.to_path_buf(),
            joints,
            frame_time,
            metres_per_unit,
            channel_count,
            values,
        })
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.values.len() / self.channel_count.max(1)
    }

    /// Frames per second (`1 / frame_time`).
    pub fn frame_rate(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// Index of the joint called `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The channel values of frame `f` (`[channel_count]`, rotations in radians); panics
    /// if `f` is out of range.
    pub fn frame(&self, f: usize) -> &[f64] {
        &self.values[f * self.channel_count..(f + 1) * self.channel_count]
    }

    /// Local rotation and translation (file unit, added to the OFFSET) of joint `j` in a
    /// value row.
    fn local(&self, j: usize, row: &[f64]) -> (DQuat, DVec3) {
        let joint = &self.joints[j];
        let mut q = DQuat::IDENTITY;
        let mut t = DVec3::ZERO;
        for (k, c) in joint.channels.iter().enumerate() {
            let v = row[joint.first_channel + k];
            match c {
                BvhChannel::Rotation(a) => q *= a.rotation(v),
                BvhChannel::Position(a) => t += a.unit() * v,
            }
        }
        (q, t)
    }

    /// World rotations `[joints]` (relative to the rest, whose rotations are zero) and
    /// world joint positions `[joints]` in metres, of frame `f`; `None` gives the rest.
    pub fn pose(&self, f: Option<usize>) -> Result<(Vec<DQuat>, Vec<DVec3>), PoseError> {
        let zeros;
        let row = match f {
            Some(f) if f >= self.frame_count() => {
                return Err(PoseError::FrameOutOfRange {
                    frame: f,
                    count: self.frame_count(),
                })
            }
            Some(f) => self.frame(f),
            None => {
                zeros = vec![0.0; self.channel_count];
                &zeros
            }
        };
        let s = self.metres_per_unit;
        let mut world = Vec::with_capacity(self.joints.len());
        let mut pos: Vec<DVec3> = Vec::with_capacity(self.joints.len());
        for (j, joint) in self.joints.iter().enumerate() {
            let (q, t) = self.local(j, row);
            let local_pos = (joint.offset + t) * s;
            match joint.parent {
                None => {
                    world.push(q.normalize());
                    pos.push(local_pos);
                }
                Some(p) => {
                    world.push((world[p] * q).normalize());
                    pos.push(pos[p] + world[p] * local_pos);
                }
            }
        }
        Ok((world, pos))
    }

    /// Positions `[end sites]` in metres of every End Site for the given world rotations
    /// and joint positions (from [`Bvh::pose`]), in joint order.
    pub fn end_sites(&self, world: &[DQuat], pos: &[DVec3]) -> Vec<DVec3> {
        self.joints
            .iter()
            .enumerate()
            .filter_map(|(j, joint)| {
                joint
                    .end_site
                    .map(|e| pos[j] + world[j] * (e * self.metres_per_unit))
            })
            .collect()
    }
}

/// Metres per unit that makes the rest skeleton closest (in ratio) to a standing adult.
fn detect_unit(joints: &[BvhJoint]) -> f64 {
    let mut pos: Vec<DVec3> = Vec::with_capacity(joints.len());
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for j in joints {
        let p = j.parent.map_or(DVec3::ZERO, |p| pos[p]) + j.offset;
        pos.push(p);
        for q in std::iter::once(p).chain(j.end_site.map(|e| p + e)) {
            lo = lo.min(q.y);
            hi = hi.max(q.y);
        }
    }
    let height = hi - lo;
    if height.is_nan() || height <= 0.0 {
        return 1.0;
    }
    let score = |s: f64| (height * s / TYPICAL_JOINT_HEIGHT_M).ln().abs();
    UNIT_CANDIDATES
        .into_iter()
        .min_by(|a, b| score(*a).total_cmp(&score(*b)))
        .unwrap_or(1.0)
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
        let (_, name) = self.next("a joint name")?;
        let name = name.to_string();
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
