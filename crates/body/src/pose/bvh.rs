//! Biovision hierarchy files (BVH), read in the file's own axes and joint names
//! ([`BvhRig`](super::BvhRig) places them on garnet's rig).
//!
//! The rest pose is the skeleton of the OFFSETs with every rotation zero. A joint's
//! rotation channels compose in the order the CHANNELS line lists them (intrinsic, left
//! to right). A joint's position channels give its position relative to its parent when
//! their values lie nearer its OFFSET than zero on average (along the OFFSET: the files
//! that repeat the OFFSET in six channels per joint, a root whose OFFSET is its rest
//! position); otherwise they add to the OFFSET. A joint's world rotation rotates the
//! positions of its children.

use std::path::{Path, PathBuf};

use glam::{DQuat, DVec3};

use super::error::{read_text, PoseError};
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
    /// Parses `Xposition` ... `Zrotation` (either case).
    pub(super) fn parse(s: &str) -> Option<BvhChannel> {
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
    /// Whether each joint's position channels replace its OFFSET, `[joints]`.
    absolute: Vec<bool>,
}

/// Rest height of a standing adult's joints (toes to top of head), metres, used to detect
/// the length unit of a BVH file.
const TYPICAL_JOINT_HEIGHT_M: f64 = 1.6;

/// Candidate metres-per-unit of BVH files: metres, centimetres, millimetres, inches and
/// the CMU ASF unit (1/0.45 inch).
const UNIT_CANDIDATES: [f64; 5] = [1.0, 0.01, 0.001, 0.0254, 0.0254 / 0.45];

impl Bvh {
    /// Reads a BVH file. `metres_per_unit`: the file's length unit in metres, or `None` to
    /// pick the one (m, cm, mm, inch, CMU unit) that makes the rest skeleton about 1.6 m
    /// tall along its up axis (feet to head, when the joint names place them; else Y).
    pub fn read(path: impl AsRef<Path>, metres_per_unit: Option<f64>) -> Result<Bvh, PoseError> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, path, metres_per_unit)
    }

    /// Parses BVH text; `path` is used in error messages. See [`Bvh::read`].
    pub fn parse(text: &str, path: &Path, metres_per_unit: Option<f64>) -> Result<Bvh, PoseError> {
        let (joints, channel_count, frame_time, values) = super::bvh_parse::parse(text, path)?;
        let metres_per_unit = match metres_per_unit {
            Some(s) if s.is_finite() && s > 0.0 => s,
            Some(s) => {
                return Err(PoseError::Invalid(format!(
                    "BVH unit {s} m is not positive"
                )))
            }
            None => detect_unit(&joints),
        };
        let absolute = absolute_positions(&joints, &values, channel_count);
        Ok(Bvh {
            path: path.to_path_buf(),
            absolute,
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

    /// Local rotation and position-channel translation (file unit) of joint `j` in a
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
            let base = if f.is_some() && self.absolute[j] {
                DVec3::ZERO
            } else {
                joint.offset
            };
            let local_pos = (base + t) * s;
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

/// Whether each joint's position channels replace its OFFSET (see the module
/// documentation): the mean over frames of `values . OFFSET` exceeds `|OFFSET|^2 / 2`.
fn absolute_positions(joints: &[BvhJoint], values: &[f64], channel_count: usize) -> Vec<bool> {
    let frames = values.len() / channel_count.max(1);
    joints
        .iter()
        .map(|j| {
            let o = j.offset;
            if frames == 0 || o.length_squared() == 0.0 {
                return false;
            }
            let mut along = 0.0;
            for row in values.chunks_exact(channel_count) {
                for (k, c) in j.channels.iter().enumerate() {
                    if let BvhChannel::Position(a) = c {
                        along += a.unit().dot(o) * row[j.first_channel + k];
                    }
                }
            }
            along / frames as f64 > 0.5 * o.length_squared()
        })
        .collect()
}

/// Metres per unit that makes the rest skeleton's extent along its up axis closest (in
/// ratio) to a standing adult's.
fn detect_unit(joints: &[BvhJoint]) -> f64 {
    let pos = super::bvh_rig::rest_positions(joints);
    let (bones, _) = super::bvh_rig::assign(joints);
    let up = super::bvh_rig::rest_up(&bones, &pos).unwrap_or(DVec3::Y);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (j, p) in joints.iter().zip(&pos) {
        for q in std::iter::once(*p).chain(j.end_site.map(|e| *p + e)) {
            lo = lo.min(q.dot(up));
            hi = hi.max(q.dot(up));
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
