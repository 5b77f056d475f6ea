//! A whole motion draped frame by frame ([`drape_motion`]): every frame is draped as
//! [`crate::drape()`] drapes one pose (in parallel), optionally smoothed in time, then pushed
//! out of its body. [`coherence`] measures how much a garment jitters against its body.

use std::str::FromStr;

use anyhow::{bail, Context};
use body::pose::{PoseKind, ProceduralPoseGenerator};
use body::self_contact::sample_valid_pose;
use body::{Pose, ShapedBody};
use geom::TriMesh;
use glam::Vec3;
use rayon::prelude::*;

use crate::drape::{drape, push_out_gap, DrapeOptions, GarmentModel, PUSH_OUT_WITHIN};

/// Frames `start..end` (end exclusive) every `step`, as `A..B` or `A..B:STEP` on the command
/// line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    /// First frame.
    pub start: usize,
    /// One past the last frame.
    pub end: usize,
    /// Frames between two draped frames (at least 1).
    pub step: usize,
}

impl FrameRange {
    /// The frames, in order.
    pub fn frames(&self) -> impl Iterator<Item = usize> {
        (self.start..self.end).step_by(self.step)
    }

    /// This range with its end cut to `count` frames (a clip's length); fails, naming the
    /// clip's length, when nothing is left.
    pub fn within(self, count: usize) -> anyhow::Result<FrameRange> {
        let end = self.end.min(count);
        if self.start >= end {
            bail!(
                "frames {}..{} hold no frame of a clip of {count} frames",
                self.start,
                self.end
            );
        }
        Ok(FrameRange { end, ..self })
    }
}

impl FromStr for FrameRange {
    type Err = anyhow::Error;

    /// Parses `A..B` or `A..B:STEP` (`B` exclusive, `B > A`, `STEP >= 1`).
    fn from_str(s: &str) -> anyhow::Result<Self> {
        let bad =
            || format!("frames {s:?}: expected A..B or A..B:STEP (B after A, STEP at least 1)");
        let (range, step) = match s.split_once(':') {
            Some((r, st)) => (r, st.parse::<usize>().with_context(bad)?),
            None => (s, 1),
        };
        let (a, b) = range.split_once("..").with_context(bad)?;
        let (start, end) = (
            a.parse::<usize>().with_context(bad)?,
            b.parse::<usize>().with_context(bad)?,
        );
        if end <= start || step == 0 {
            bail!(bad());
        }
        Ok(FrameRange { start, end, step })
    }
}

/// Options of [`drape_motion`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionOptions {
    /// Each frame as [`crate::drape()`] drapes it (the push-out comes after the smoothing).
    pub drape: DrapeOptions,
    /// Smooth each garment in time (see [`smooth_tracks`]); `None`: as the networks drape it.
    pub smooth_within: Option<f32>,
}

impl Default for MotionOptions {
    /// Limb clearance and the push-out, no smoothing.
    fn default() -> Self {
        MotionOptions {
            drape: DrapeOptions::default(),
            smooth_within: None,
        }
    }
}

/// One garment along a motion.
pub struct GarmentTrack {
    /// The garment kind's name.
    pub kind: String,
    /// Its triangles `[F]`.
    pub faces: Vec<[u32; 3]>,
    /// Its vertices in each frame `[T][N]`, metres.
    pub frames: Vec<Vec<Vec3>>,
}

/// A draped motion: the body and each model's garment in every frame.
pub struct Motion {
    /// The body's triangles `[F]`.
    pub body_faces: Vec<[u32; 3]>,
    /// The posed body in each frame `[T][V]`, metres.
    pub body: Vec<Vec<Vec3>>,
    /// One track per model, in the models' order.
    pub garments: Vec<GarmentTrack>,
    /// The networks' time, summed over frames and models, ms.
    pub network_ms: f64,
}

/// Drapes `models` on `target` in each of `poses` (a motion's frames, in order), the frames
/// in parallel; `on_frame` is called once a frame is draped (for a progress bar). With
/// smoothing, each garment's offsets from its warped template M are smoothed in time before
/// the push-out. Fails as [`crate::drape()`] does, naming the frame.
pub fn drape_motion(
    models: &[GarmentModel],
    target: &ShapedBody,
    poses: &[Pose],
    opts: MotionOptions,
    on_frame: &(dyn Fn() + Sync),
) -> anyhow::Result<Motion> {
    if poses.is_empty() {
        bail!("a motion needs at least one frame");
    }
    let raw = DrapeOptions {
        push_out: false,
        ..opts.drape
    };
    let frames = poses
        .par_iter()
        .enumerate()
        .map(|(k, pose)| {
            let d = drape(models, target, pose, raw).with_context(|| format!("frame {k}"))?;
            on_frame();
            Ok(d)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let network_ms = frames
        .iter()
        .flat_map(|f| &f.garments)
        .map(|g| g.timings.network_ms)
        .sum();
    let mut garments: Vec<GarmentTrack> = (0..models.len())
        .map(|i| GarmentTrack {
            kind: frames[0].garments[i].kind.clone(),
            faces: frames[0].garments[i].mesh.faces.clone(),
            frames: frames
                .iter()
                .map(|f| f.garments[i].mesh.vertices.clone())
                .collect(),
        })
        .collect();
    if let Some(within) = opts.smooth_within {
        for (i, track) in garments.iter_mut().enumerate() {
            let warped: Vec<Vec<Vec3>> = frames
                .iter()
                .map(|f| f.garments[i].warped.clone())
                .collect();
            track.frames = smooth_tracks(&track.frames, &warped, within);
        }
    }
    let body: Vec<Vec<Vec3>> = frames.iter().map(|f| f.body.vertices.clone()).collect();
    let body_faces = frames[0].body.faces.clone();
    if opts.drape.push_out {
        let pushed = (0..body.len())
            .into_par_iter()
            .map(|k| {
                let mesh = TriMesh::new(body[k].clone(), body_faces.clone());
                let collider = sim::BodyCollider::new(&mesh, push_out_gap())
                    .with_context(|| format!("frame {k}: the body's collider"))?;
                Ok(garments
                    .iter()
                    .map(|track| {
                        let mut v = track.frames[k].clone();
                        collider.push_out(&mut v, PUSH_OUT_WITHIN, push_out_gap());
                        v
                    })
                    .collect::<Vec<_>>())
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        for (k, frame) in pushed.into_iter().enumerate() {
            for (track, v) in garments.iter_mut().zip(frame) {
                track.frames[k] = v;
            }
        }
    }
    Ok(Motion {
        body_faces,
        body,
        garments,
        network_ms,
    })
}

/// Smooths a garment's frames `[T][N]` in time: its offsets from `warped` (the template
/// skinned to each frame's body, `[T][N]`) are filtered with the binomial kernel
/// (1, 4, 6, 4, 1) / 16 (edges clamped), so the garment keeps following the body while the
/// network's frame-to-frame jitter is damped; in each frame the change is scaled down where
/// needed so that its mean vertex shift stays within `within` metres (E_dist from the
/// unsmoothed frame at most `within`).
pub fn smooth_tracks(frames: &[Vec<Vec3>], warped: &[Vec<Vec3>], within: f32) -> Vec<Vec<Vec3>> {
    const KERNEL: [f32; 5] = [1.0, 4.0, 6.0, 4.0, 1.0];
    let t = frames.len();
    let offsets: Vec<Vec<Vec3>> = frames
        .iter()
        .zip(warped)
        .map(|(g, m)| g.iter().zip(m).map(|(a, b)| *a - *b).collect())
        .collect();
    (0..t)
        .map(|k| {
            let n = frames[k].len();
            let mut change = vec![Vec3::ZERO; n];
            for (j, w) in KERNEL.iter().enumerate() {
                let f = (k + j).saturating_sub(2).min(t - 1);
                for (c, (o, o0)) in change.iter_mut().zip(offsets[f].iter().zip(&offsets[k])) {
                    *c += (*o - *o0) * (w / 16.0);
                }
            }
            let shift = change.iter().map(|c| c.length()).sum::<f32>() / n.max(1) as f32;
            let scale = if shift > within { within / shift } else { 1.0 };
            frames[k]
                .iter()
                .zip(&change)
                .map(|(g, c)| *g + *c * scale)
                .collect()
        })
        .collect()
}

/// How much a sequence of frames `[T][N]` jitters: the mean over interior frames and
/// vertices of the second difference `|x(t+1) - 2 x(t) + x(t-1)|`, metres per frame squared
/// (0 for fewer than 3 frames).
pub fn coherence(frames: &[Vec<Vec3>]) -> f32 {
    if frames.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0f64;
    let mut count = 0usize;
    for w in frames.windows(3) {
        for ((a, b), c) in w[0].iter().zip(&w[1]).zip(&w[2]) {
            sum += (*c - 2.0 * *b + *a).length() as f64;
            count += 1;
        }
    }
    (sum / count.max(1) as f64) as f32
}

/// A smooth procedural motion of `frames` frames on `target`: valid procedural poses of
/// `kind` drawn from `seed` as keys every `key_every` frames, every bone slerped (the root
/// translation lerped) between them.
pub fn procedural_motion(
    target: &ShapedBody,
    seed: u64,
    kind: PoseKind,
    frames: usize,
    key_every: usize,
) -> anyhow::Result<Vec<Pose>> {
    let key_every = key_every.max(1);
    let mut generator = ProceduralPoseGenerator::new(seed, kind);
    let keys = (0..=frames.div_ceil(key_every))
        .map(|_| sample_valid_pose(target, &mut generator, 200))
        .collect::<Result<Vec<_>, _>>()
        .with_context(|| format!("procedural motion, seed {seed}"))?;
    Ok((0..frames)
        .map(|f| {
            let (k, t) = (f / key_every, (f % key_every) as f32 / key_every as f32);
            // Smoothstep: each key is held for an instant, so the motion has no kinks there.
            keys[k].slerp(&keys[k + 1], t * t * (3.0 - 2.0 * t))
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_parse_and_clip() {
        let r: FrameRange = "10..20:3".parse().unwrap();
        assert_eq!(r.frames().collect::<Vec<_>>(), vec![10, 13, 16, 19]);
        assert_eq!("0..4".parse::<FrameRange>().unwrap().step, 1);
        for bad in ["4..4", "5..3", "0..9:0", "a..3", "3", "0..x:1"] {
            assert!(bad.parse::<FrameRange>().is_err(), "{bad}");
        }
        assert_eq!(r.within(15).unwrap().frames().last(), Some(13));
        assert!(r.within(10).is_err());
    }

    /// Jittered frames over a steady motion: the smoothing lowers the jitter and moves no
    /// frame more than its bound on average.
    #[test]
    fn smoothing_damps_jitter_within_its_bound() {
        let n = 50;
        let warped: Vec<Vec<Vec3>> = (0..40)
            .map(|t| {
                (0..n)
                    .map(|j| Vec3::new(j as f32 * 0.01, 0.002 * t as f32, 0.0))
                    .collect()
            })
            .collect();
        let jitter = |t: usize, j: usize| 0.001 * (((t * 7 + j * 3) % 5) as f32 - 2.0);
        let frames: Vec<Vec<Vec3>> = warped
            .iter()
            .enumerate()
            .map(|(t, w)| {
                w.iter()
                    .enumerate()
                    .map(|(j, v)| *v + Vec3::Z * jitter(t, j))
                    .collect()
            })
            .collect();
        let free = smooth_tracks(&frames, &warped, 0.01);
        assert!(coherence(&free) < 0.6 * coherence(&frames));
        let within = 0.0002;
        let bound = smooth_tracks(&frames, &warped, within);
        assert!(coherence(&bound) < coherence(&frames));
        for (a, b) in bound.iter().zip(&frames) {
            let shift = a.iter().zip(b).map(|(p, q)| p.distance(*q)).sum::<f32>() / n as f32;
            assert!(shift <= within * 1.0001, "{shift}");
        }
        // A steady motion has no second difference.
        assert!(coherence(&warped) < 1e-6);
        assert_eq!(coherence(&warped[..2]), 0.0);
    }
}
