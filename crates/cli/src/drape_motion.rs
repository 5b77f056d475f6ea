//! `garnet drape --frames A..B[:STEP]`: a whole motion draped frame by frame
//! ([`garnet::drape_motion`]) and written as an animation: an animated GLB (the body and the
//! garments, morph-target animation), or PC2 point caches with their meshes as OBJ.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use body::pose::{Clip, RetargetOptions};
use body::{BodyModel, Pose, ShapedBody};
use garnet::motion::{coherence, procedural_motion, FrameRange, Motion};
use garnet::{DrapeOptions, GarmentModel, MotionOptions};
use geom::io::{write_animated_glb, write_pc2, AnimatedMesh};
use geom::TriMesh;
use indicatif::{ProgressBar, ProgressStyle};
use render::palette;

use crate::drape_cmd::{with_kind, DrapeArgs};
use crate::garment_cmd::garment_color;
use crate::output::{create_parent, write_mesh};
use crate::pose_args::{default_asf, file_name, PoseArgs};

/// How far the smoothing may move a frame's vertices on average, metres: 0.045 cm, so that
/// with the push-out after it each frame stays within 0.05 cm of its unsmoothed drape.
pub const SMOOTH_WITHIN: f32 = 0.00045;

/// Frames a second of a procedural motion.
const PROCEDURAL_FPS: f64 = 30.0;

/// A procedural motion's frames between two key poses.
const PROCEDURAL_KEY_EVERY: usize = 30;

/// The poses of `range` of the clip or procedural motion `pose` names, retargeted to
/// `target`; the clip's frame rate; and a description.
pub fn motion_poses(
    pose: &PoseArgs,
    target: &ShapedBody,
    range: FrameRange,
) -> anyhow::Result<(Vec<Pose>, f64, String)> {
    let opts = RetargetOptions::default();
    let clip = if let Some(amc) = &pose.pose_amc {
        let asf = match &pose.asf {
            Some(a) => a.clone(),
            None => default_asf(amc)?,
        };
        Some((Clip::from_asf_amc(&asf, amc)?, file_name(amc)))
    } else if let Some(bvh) = &pose.pose_bvh {
        Some((Clip::from_bvh(bvh, None)?, file_name(bvh)))
    } else {
        None
    };
    if let Some((clip, name)) = clip {
        let range = range
            .within(clip.frame_count())
            .with_context(|| name.clone())?;
        let poses = range
            .frames()
            .map(|f| clip.pose(f, &target.rig, &opts))
            .collect::<Result<Vec<_>, _>>()?;
        let what = format!(
            "{name} frames {}..{}:{}",
            range.start, range.end, range.step
        );
        return Ok((poses, clip.frame_rate(), what));
    }
    let Some(seed) = pose.pose_procedural else {
        bail!("--frames needs a motion: a clip (--pose-bvh, --pose-amc) or --pose-procedural");
    };
    let all = procedural_motion(
        target,
        seed,
        pose.pose_kind.into(),
        range.end,
        PROCEDURAL_KEY_EVERY,
    )?;
    let poses = range.frames().map(|f| all[f].clone()).collect();
    let what = format!("procedural {:?} motion {seed}", pose.pose_kind).to_lowercase();
    Ok((poses, PROCEDURAL_FPS, what))
}

/// Runs `garnet drape --frames`.
pub fn run(args: &DrapeArgs, range: FrameRange) -> anyhow::Result<()> {
    let device = args.device.device()?;
    let body_model = BodyModel::load()?;
    let target = body_model.shape(&args.shape.phenotype(&body_model)?)?;
    let (poses, clip_fps, what) = motion_poses(&args.pose, &target, range)?;
    let fps = match args.fps {
        Some(f) if !(f.is_finite() && f > 0.0) => bail!("--fps must be > 0, got {f}"),
        Some(f) => f,
        None => (clip_fps / range.step as f64) as f32,
    };
    let models = args
        .models
        .iter()
        .map(|path| GarmentModel::load(path, &device))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let bar = ProgressBar::new(poses.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("draping [{bar:30}] {pos}/{len} frames {per_sec} eta {eta}")?
            .progress_chars("=> "),
    );
    let opts = MotionOptions {
        drape: DrapeOptions {
            clear_limbs: !args.keep_pose,
            push_out: !args.raw,
        },
        smooth_within: args.smooth.then_some(SMOOTH_WITHIN),
    };
    let motion = garnet::drape_motion(&models, &target, &poses, opts, &|| bar.inc(1))?;
    bar.finish_and_clear();
    report(&motion, &what, fps);
    write_motion(args, &models, &motion, fps)
}

/// Prints the motion's frame count, network time and each garment's jitter against the
/// body's.
fn report(motion: &Motion, what: &str, fps: f32) {
    let frames = motion.body.len();
    let body = coherence(&motion.body);
    eprintln!(
        "{frames} frames of {what} at {fps:.1} fps: networks {:.1} ms a frame",
        motion.network_ms / frames as f64
    );
    for g in &motion.garments {
        let a = coherence(&g.frames);
        eprintln!(
            "{}: mean vertex acceleration {:.3} mm/frame^2, the body's {:.3} ({:.2}x)",
            g.kind,
            a * 1e3,
            body * 1e3,
            a / body.max(1e-12)
        );
    }
}

/// Writes the motion by the extension of `--out` (and `--body-out`): `.glb` (one animated
/// file with the body and every garment), `.pc2` (a point cache per garment, its mesh as
/// `.obj` beside it); `--png` pictures the first frame.
fn write_motion(
    args: &DrapeArgs,
    models: &[GarmentModel],
    motion: &Motion,
    fps: f32,
) -> anyhow::Result<()> {
    let several = motion.garments.len() > 1;
    let ext = extension(&args.out);
    match ext.as_str() {
        "glb" => {
            let mut meshes: Vec<AnimatedMesh> = motion
                .garments
                .iter()
                .zip(models)
                .map(|(g, m)| AnimatedMesh {
                    name: &g.kind,
                    faces: &g.faces,
                    frames: &g.frames,
                    color: rgba(garment_color(&m.template().kind)),
                    normals: true,
                })
                .collect();
            meshes.push(AnimatedMesh {
                name: "body",
                faces: &motion.body_faces,
                frames: &motion.body,
                color: rgba(palette::SKIN),
                normals: false,
            });
            write_animation(&args.out, &meshes, fps)?;
        }
        "pc2" => {
            for g in &motion.garments {
                let out = if several {
                    with_kind(&args.out, &g.kind)
                } else {
                    args.out.clone()
                };
                write_cache(&out, &g.faces, &g.frames)?;
            }
        }
        _ => bail!(
            "{}: a motion is written as .glb (animated) or .pc2 (point cache), not .{ext}",
            args.out.display()
        ),
    }
    if let Some(p) = &args.body_out {
        match extension(p).as_str() {
            "glb" => write_animation(
                p,
                &[AnimatedMesh {
                    name: "body",
                    faces: &motion.body_faces,
                    frames: &motion.body,
                    color: rgba(palette::SKIN),
                    normals: false,
                }],
                fps,
            )?,
            "pc2" => write_cache(p, &motion.body_faces, &motion.body)?,
            e => bail!(
                "{}: the body's motion is written as .glb or .pc2, not .{e}",
                p.display()
            ),
        }
    }
    if let Some(png) = &args.png {
        let body = TriMesh::new(motion.body[0].clone(), motion.body_faces.clone());
        for (g, m) in motion.garments.iter().zip(models) {
            let path = if several {
                with_kind(png, &g.kind)
            } else {
                png.clone()
            };
            let mesh = TriMesh::new(g.frames[0].clone(), g.faces.clone());
            let colour = garment_color(&m.template().kind);
            crate::output::write_png(
                &path,
                &[(&body, palette::SKIN), (&mesh, colour)],
                (480, 720),
            )?;
        }
    }
    Ok(())
}

/// The lower-case extension of `path` (empty for none).
fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or_default()
        .to_ascii_lowercase()
}

/// An sRGB-ish 8-bit colour as glTF's linear RGBA base colour.
fn rgba(c: [u8; 3]) -> [f32; 4] {
    let lin = |v: u8| (v as f32 / 255.0).powf(2.2);
    [lin(c[0]), lin(c[1]), lin(c[2]), 1.0]
}

/// Writes an animated GLB and says so.
fn write_animation(path: &Path, meshes: &[AnimatedMesh], fps: f32) -> anyhow::Result<()> {
    create_parent(path)?;
    write_animated_glb(path, meshes, fps).with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// Writes `frames` as a PC2 point cache at `path` and its first frame with `faces` as an
/// OBJ beside it (the mesh the cache deforms).
fn write_cache(path: &Path, faces: &[[u32; 3]], frames: &[Vec<glam::Vec3>]) -> anyhow::Result<()> {
    create_parent(path)?;
    write_pc2(path, frames).with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {} ({} frames)", path.display(), frames.len());
    let obj: PathBuf = path.with_extension("obj");
    write_mesh(&obj, &TriMesh::new(frames[0].clone(), faces.to_vec()))
}
