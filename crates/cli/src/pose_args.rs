//! Command-line arguments that choose a pose, and turning them into a [`Pose`].

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use body::pose::{Clip, PoseKind, ProceduralPoseGenerator, RetargetOptions};
use body::self_contact::sample_valid_pose;
use body::{BodyModel, Pose, ShapedBody};
use clap::{Args, ValueEnum};

/// The folder of the CMU clips (with `01/` and `02/` inside) that a picture sheet poses its
/// bodies with: `mocap` (`--mocap DIR`), else `$GARNET_MOCAP/cmu`; an error saying how to
/// give it when neither is there. `what` names the command in the error.
pub fn cmu_folder(mocap: Option<&Path>, what: &str) -> anyhow::Result<PathBuf> {
    if let Some(dir) = mocap {
        return Ok(dir.to_path_buf());
    }
    match std::env::var_os("GARNET_MOCAP") {
        Some(root) => Ok(PathBuf::from(root).join("cmu")),
        None => bail!(
            "{what} poses its bodies with CMU clips: give their folder (holding 01/ and 02/) \
             with --mocap DIR, or set GARNET_MOCAP to the folder holding cmu/"
        ),
    }
}

/// Body pose: rest A-pose by default.
#[derive(Args, Debug, Clone, Default)]
pub struct PoseArgs {
    /// The T-pose (arms horizontal).
    #[arg(long, conflicts_with_all = ["pose_amc", "pose_bvh", "pose_procedural"])]
    pub tpose: bool,
    /// A frame of a CMU AMC clip (with --frame); the skeleton is --asf, or SUBJECT.asf
    /// beside the clip.
    #[arg(long, value_name = "FILE.amc", conflicts_with_all = ["pose_bvh", "pose_procedural"])]
    pub pose_amc: Option<PathBuf>,
    /// The ASF skeleton of --pose-amc.
    #[arg(long, value_name = "FILE.asf", requires = "pose_amc")]
    pub asf: Option<PathBuf>,
    /// A frame of a CMU-style BVH clip (with --frame).
    #[arg(long, value_name = "FILE.bvh", conflicts_with = "pose_procedural")]
    pub pose_bvh: Option<PathBuf>,
    /// Frame index (0-based) of the clip.
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// A procedural pose drawn from this seed (self-intersecting draws are rejected).
    #[arg(long, value_name = "SEED")]
    pub pose_procedural: Option<u64>,
    /// Kind of procedural pose.
    #[arg(long, value_enum, default_value_t = KindArg::Any)]
    pub pose_kind: KindArg,
}

/// Procedural pose kinds on the command line.
#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum KindArg {
    Walk,
    Yoga,
    Dance,
    #[default]
    Any,
}

impl From<KindArg> for PoseKind {
    fn from(k: KindArg) -> Self {
        match k {
            KindArg::Walk => PoseKind::Walk,
            KindArg::Yoga => PoseKind::Yoga,
            KindArg::Dance => PoseKind::Dance,
            KindArg::Any => PoseKind::Any,
        }
    }
}

/// The ASF skeleton beside an AMC clip: `DIR/02_01.amc` -> `DIR/02.asf`.
pub fn default_asf(amc: &Path) -> anyhow::Result<PathBuf> {
    let stem = amc.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let subject = stem.split('_').next().unwrap_or(stem);
    let asf = amc.with_file_name(format!("{subject}.asf"));
    if !asf.is_file() {
        bail!(
            "{}: no skeleton {} beside the clip; give it with --asf",
            amc.display(),
            asf.display()
        );
    }
    Ok(asf)
}

impl PoseArgs {
    /// The pose these arguments describe, for `body`, and a short description.
    pub fn pose(&self, model: &BodyModel, body: &ShapedBody) -> anyhow::Result<(Pose, String)> {
        let opts = RetargetOptions::default();
        if self.tpose {
            return Ok((model.tpose(), "T-pose".into()));
        }
        if let Some(amc) = &self.pose_amc {
            let asf = match &self.asf {
                Some(a) => a.clone(),
                None => default_asf(amc)?,
            };
            let clip = Clip::from_asf_amc(&asf, amc)?;
            let pose = clip.pose(self.frame, &body.rig, &opts)?;
            return Ok((pose, format!("{} frame {}", file_name(amc), self.frame)));
        }
        if let Some(bvh) = &self.pose_bvh {
            let clip = Clip::from_bvh(bvh, None)?;
            let pose = clip.pose(self.frame, &body.rig, &opts)?;
            return Ok((pose, format!("{} frame {}", file_name(bvh), self.frame)));
        }
        if let Some(seed) = self.pose_procedural {
            let mut generator = ProceduralPoseGenerator::new(seed, self.pose_kind.into());
            let pose = sample_valid_pose(body, &mut generator, 200)
                .with_context(|| format!("procedural pose, seed {seed}"))?;
            return Ok((
                pose,
                format!("procedural {:?} {seed}", self.pose_kind).to_lowercase(),
            ));
        }
        Ok((Pose::identity(body.rig.len()), "rest A-pose".into()))
    }
}

/// The file name of `path` for captions.
pub fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
