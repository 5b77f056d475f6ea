//! The pose pool: every pose a dataset may use, grouped into motions (one per clip and one
//! per procedural source), and which of them the unseen-pose split leaves to the ordinary
//! splits.

use std::path::Path;

use crate::error::{DatasetError, Result};
use crate::rng::{derive, SplitMix64, Stream};
use crate::spec::{ClipSource, Spec};

/// The file format of a clip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipFormat {
    /// CMU ASF/AMC.
    Amc,
    /// BVH.
    Bvh,
}

/// One clip file named by the spec.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipRef {
    /// File format.
    pub format: ClipFormat,
    /// Index of its source in `poses.amc` or `poses.bvh`.
    pub source: usize,
    /// Path relative to the mocap root.
    pub path: String,
    /// AMC: the skeleton, relative to the mocap root.
    pub asf: Option<String>,
    /// BVH: metres per file unit (`None`: the reader's guess).
    pub bvh_unit: Option<f64>,
}

/// The clips of `spec` in order: AMC sources, then BVH sources, each clip in file order.
pub fn clip_list(spec: &Spec) -> Vec<ClipRef> {
    let amc = spec.poses.amc.iter().map(|s| (ClipFormat::Amc, s));
    let bvh = spec.poses.bvh.iter().map(|s| (ClipFormat::Bvh, s));
    let mut out = Vec::new();
    let mut counts = [0usize; 2];
    for (format, s) in amc.chain(bvh) {
        let source = counts[format as usize];
        counts[format as usize] += 1;
        for clip in &s.clips {
            out.push(ClipRef {
                format,
                source,
                path: clip.clone(),
                asf: match format {
                    ClipFormat::Amc => Some(s.asf.clone().unwrap_or_else(|| default_asf(clip))),
                    ClipFormat::Bvh => None,
                },
                bvh_unit: s.bvh_unit,
            });
        }
    }
    out
}

/// The skeleton beside an AMC clip: `02/02_01.amc` -> `02/02.asf`.
pub fn default_asf(clip: &str) -> String {
    let p = Path::new(clip);
    let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let subject = stem.split('_').next().unwrap_or(stem);
    p.with_file_name(format!("{subject}.asf"))
        .to_string_lossy()
        .into_owned()
}

/// One pose of the pool.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PoseRef {
    /// Frame `frame` of clip `clip` (index into [`clip_list`]).
    Clip {
        /// Clip index.
        clip: usize,
        /// 0-based frame.
        frame: u32,
    },
    /// Draw `draw` of procedural source `source` (index in `poses.procedural`).
    Procedural {
        /// Source index.
        source: usize,
        /// Draw index within the source.
        draw: u32,
    },
}

/// A motion: a clip or a procedural source, and its poses' range in the pool.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// The clip path or `procedural[i]:KIND`.
    pub name: String,
    /// Its poses: `pool.poses[range]`.
    pub range: std::ops::Range<usize>,
}

/// All poses of a dataset.
#[derive(Clone, Debug, PartialEq)]
pub struct PosePool {
    /// The clips poses refer to.
    pub clips: Vec<ClipRef>,
    /// Every pose, motion after motion.
    pub poses: Vec<PoseRef>,
    /// The motions.
    pub motions: Vec<Motion>,
    /// `[poses]`: open to the ordinary splits (always true without unseen-pose splits).
    pub seen: Vec<bool>,
}

/// Frames taken from a clip of `count` frames by `src` (`clip` is its index in the clip
/// list, for the random draw); `field` names the source in errors.
fn clip_frames(
    src: &ClipSource,
    count: usize,
    seed: u64,
    clip: usize,
) -> std::result::Result<Vec<u32>, String> {
    let end = src.end.map_or(count, |e| (e as usize).min(count));
    let start = src.start as usize;
    if start >= end {
        return Err(format!(
            "start = {start} leaves no frame of a clip of {count} frames"
        ));
    }
    if let Some(k) = src.every {
        return Ok((start..end).step_by(k as usize).map(|f| f as u32).collect());
    }
    let n = src.random.unwrap_or(1) as usize;
    if n > end - start {
        return Err(format!(
            "random = {n} frames, but the clip has only {} in range",
            end - start
        ));
    }
    let mut rng = SplitMix64::new(derive(seed, Stream::Frames, &[clip as u64]));
    let mut frames: Vec<u32> = rng
        .choose(end - start, n)
        .into_iter()
        .map(|f| (f + start) as u32)
        .collect();
    frames.sort_unstable();
    Ok(frames)
}

/// Whether pose `j` of a motion is seen, for a share `f` of them evenly spread.
pub fn is_seen(j: usize, f: f64) -> bool {
    ((j + 1) as f64 * f).floor() > (j as f64 * f).floor()
}

impl PosePool {
    /// The pool of `spec` (read from `file`), given each clip's frame count
    /// (`frame_counts[i]` for clip `i` of [`clip_list`]).
    pub fn new(spec: &Spec, file: &Path, frame_counts: &[usize]) -> Result<Self> {
        let clips = clip_list(spec);
        assert_eq!(clips.len(), frame_counts.len(), "a frame count per clip");
        let (mut poses, mut motions) = (Vec::new(), Vec::new());
        for (i, (clip, &count)) in clips.iter().zip(frame_counts).enumerate() {
            let (src, what) = match clip.format {
                ClipFormat::Amc => (&spec.poses.amc[clip.source], "amc"),
                ClipFormat::Bvh => (&spec.poses.bvh[clip.source], "bvh"),
            };
            let frames = clip_frames(src, count, spec.seed, i).map_err(|m| {
                DatasetError::spec(
                    file,
                    format!("poses.{what}[{}]", clip.source),
                    format!("{}: {m}", clip.path),
                )
            })?;
            let start = poses.len();
            poses.extend(
                frames
                    .into_iter()
                    .map(|frame| PoseRef::Clip { clip: i, frame }),
            );
            motions.push(Motion {
                name: clip.path.clone(),
                range: start..poses.len(),
            });
        }
        for (source, p) in spec.poses.procedural.iter().enumerate() {
            let start = poses.len();
            poses.extend((0..p.count).map(|draw| PoseRef::Procedural { source, draw }));
            motions.push(Motion {
                name: format!("procedural[{source}]:{}", p.kind.to_ascii_lowercase()),
                range: start..poses.len(),
            });
        }
        let mut seen = vec![true; poses.len()];
        if let Some(u) = &spec.splits.unseen_poses {
            for m in &motions {
                for (j, i) in m.range.clone().enumerate() {
                    seen[i] = is_seen(j, u.seen_fraction);
                }
            }
        }
        Ok(Self {
            clips,
            poses,
            motions,
            seen,
        })
    }

    /// A stable text id of pose `i`: `PATH#FRAME` or `procedural[S]:KIND#DRAW`.
    pub fn pose_id(&self, i: usize) -> String {
        match self.poses[i] {
            PoseRef::Clip { clip, frame } => format!("{}#{frame}", self.clips[clip].path),
            PoseRef::Procedural { draw, .. } => {
                let m = self
                    .motions
                    .iter()
                    .find(|m| m.range.contains(&i))
                    .expect("every pose is in a motion");
                format!("{}#{draw}", m.name)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn even_spread_of_seen_poses() {
        let seen: Vec<bool> = (0..8).map(|j| is_seen(j, 0.5)).collect();
        assert_eq!(seen.iter().filter(|&&s| s).count(), 4);
        assert!(seen.windows(2).all(|w| w[0] != w[1]));
        assert_eq!((0..100).filter(|&j| is_seen(j, 0.25)).count(), 25);
        assert_eq!(default_asf("cmu/02/02_01.amc"), "cmu/02/02.asf");
    }

    #[test]
    fn frames_every_and_random() {
        let src = ClipSource {
            clips: vec!["a.amc".into()],
            asf: None,
            every: Some(30),
            random: None,
            start: 10,
            end: Some(100),
            bvh_unit: None,
        };
        assert_eq!(clip_frames(&src, 500, 1, 0).unwrap(), vec![10, 40, 70]);
        assert_eq!(clip_frames(&src, 50, 1, 0).unwrap(), vec![10, 40]);
        let random = ClipSource {
            every: None,
            random: Some(5),
            ..src.clone()
        };
        let f = clip_frames(&random, 500, 1, 0).unwrap();
        assert_eq!(f, clip_frames(&random, 500, 1, 0).unwrap());
        assert_ne!(f, clip_frames(&random, 500, 1, 1).unwrap());
        assert!(f.len() == 5 && f.windows(2).all(|w| w[0] < w[1]));
        assert!(f.iter().all(|x| (10..100).contains(x)));
        assert!(clip_frames(&random, 12, 1, 0).is_err());
        assert!(clip_frames(&src, 5, 1, 0).is_err());
    }
}
