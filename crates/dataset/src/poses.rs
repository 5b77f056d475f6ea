//! The motion clips of a spec, loaded from the mocap root, and turning a pool pose into a
//! [`Pose`] of a given body.

use std::path::{Path, PathBuf};

use body::pose::{Clip, ProceduralPoseGenerator, RetargetOptions};
use body::self_contact::sample_valid_pose;
use body::{Pose, ShapedBody};
use serde::{Deserialize, Serialize};

use crate::error::{DatasetError, Result};
use crate::hash::sha256_file;
use crate::pool::{clip_list, ClipFormat, PoseRef};
use crate::rng::{derive, Stream};
use crate::spec::Spec;
use crate::spec_check::parse_kind;

/// Procedural draws tried per pose before it counts as failed (self-intersecting bodies
/// are redrawn).
pub const MAX_POSE_TRIES: usize = 200;

/// A mocap file a dataset read, and its checksum.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct MocapFile {
    /// Path relative to the mocap root.
    pub path: String,
    /// Hex sha256 of the file.
    pub sha256: String,
}

/// The clips of a spec, loaded.
pub struct PoseLibrary {
    clips: Vec<Clip>,
    /// Every file read (clips and skeletons, each once), with checksums.
    pub files: Vec<MocapFile>,
}

impl PoseLibrary {
    /// Loads every clip `spec` names from under the mocap folder `root`. Errors name the
    /// missing or malformed file; a spec without clips needs no root (`None`).
    pub fn load(spec: &Spec, root: Option<&Path>) -> Result<Self> {
        let refs = clip_list(spec);
        let root = match root {
            _ if refs.is_empty() => Path::new(""),
            Some(root) if root.is_dir() => root,
            Some(root) => {
                return Err(DatasetError::Invalid(format!(
                    "the mocap folder {} is not a folder: give the folder the spec's clip \
                     paths are relative to with --mocap DIR or GARNET_MOCAP",
                    root.display()
                )))
            }
            None => {
                return Err(DatasetError::Invalid(format!(
                    "the spec names {} mocap clips (such as {}) but no mocap folder was \
                     given: give the folder their paths are relative to with --mocap DIR or \
                     GARNET_MOCAP",
                    refs.len(),
                    refs[0].path
                )))
            }
        };
        let mut files: Vec<MocapFile> = Vec::new();
        let mut note = |rel: &str| -> Result<PathBuf> {
            let path = root.join(rel);
            if !files.iter().any(|f| f.path == rel) {
                files.push(MocapFile {
                    path: rel.to_string(),
                    sha256: sha256_file(&path)?,
                });
            }
            Ok(path)
        };
        let mut clips = Vec::with_capacity(refs.len());
        for r in &refs {
            let path = note(&r.path)?;
            let clip = match r.format {
                ClipFormat::Amc => {
                    let asf = note(r.asf.as_deref().expect("AMC clips have a skeleton"))?;
                    Clip::from_asf_amc(&asf, &path)
                }
                ClipFormat::Bvh => Clip::from_bvh(&path, r.bvh_unit),
            }
            .map_err(|e| DatasetError::Body(e.into()))?;
            if clip.frame_count() == 0 {
                return Err(DatasetError::corrupt(&path, "the clip has no frames"));
            }
            clips.push(clip);
        }
        Ok(Self { clips, files })
    }

    /// `[clips]`: frame counts, in [`clip_list`] order.
    pub fn frame_counts(&self) -> Vec<usize> {
        self.clips.iter().map(Clip::frame_count).collect()
    }

    /// Pose `pose` of the pool on `body`: a clip frame retargeted onto its rig, or a
    /// procedural draw redrawn until the posed body does not intersect itself. An error
    /// (as text) means this sample cannot be made.
    pub fn pose(
        &self,
        spec: &Spec,
        pose: PoseRef,
        body: &ShapedBody,
    ) -> std::result::Result<Pose, String> {
        match pose {
            PoseRef::Clip { clip, frame } => self.clips[clip]
                .pose(frame as usize, &body.rig, &RetargetOptions::default())
                .map_err(|e| format!("pose: {e}")),
            PoseRef::Procedural { source, draw } => {
                let src = &spec.poses.procedural[source];
                let kind = parse_kind(&src.kind).expect("validated kind");
                let seed = derive(spec.seed, Stream::Procedural, &[source as u64, draw as u64]);
                let mut generator = ProceduralPoseGenerator::new(seed, kind);
                sample_valid_pose(body, &mut generator, MAX_POSE_TRIES)
                    .map_err(|e| format!("procedural pose: {e}"))
            }
        }
    }
}
