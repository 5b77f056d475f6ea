//! `garnet drape`: a body in, draped garments out, with trained GarNet models
//! ([`garnet::drape()`]). With no command, garnet drapes the three shipped models (`models/`)
//! on a random body in a random pose ([`DrapeArgs::main_job`]).

use std::path::{Path, PathBuf};

use body::BodyModel;
use clap::Args;
use garnet::{drape, DrapeOptions, FrameRange, GarmentModel};
use render::palette;

use crate::garment_cmd::garment_color;
use crate::model_device::DeviceArg;
use crate::output::{write_mesh, write_png};
use crate::pose_args::PoseArgs;
use crate::shape_args::ShapeArgs;

/// Arguments of `garnet drape`.
#[derive(Args, Debug, Clone)]
pub struct DrapeArgs {
    /// Trained model files (`.garnet`, from `garnet train`); one garment each.
    #[arg(long = "model", value_name = "CKPT", required = true, num_args = 1..)]
    pub models: Vec<PathBuf>,
    #[command(flatten)]
    pub shape: ShapeArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    /// Drape the pose as given: no limb clearance (the models were trained on cleared poses).
    #[arg(long)]
    pub keep_pose: bool,
    /// Output mesh of the draped garment (OBJ, PLY or GLB); with several models, the
    /// garment's kind is added to the name (`draped-tshirt.glb`). With --frames: an animated
    /// GLB of the body and every garment, or a PC2 point cache per garment (`.pc2`, its mesh
    /// as `.obj` beside it).
    #[arg(long, default_value = "out/draped.glb")]
    pub out: PathBuf,
    /// Also write the posed body mesh here (with --frames: its motion, `.glb` or `.pc2`).
    #[arg(long, value_name = "FILE")]
    pub body_out: Option<PathBuf>,
    /// Picture of the body wearing the garment; with several models, one per garment with
    /// its kind added to the name (`drape-tshirt.png`).
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,
    /// Where the networks run.
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    pub device: DeviceArg,
    /// Write the network's output as it is. By default garment vertices that it leaves
    /// inside the body, or nearer its skin than the simulator's cloth thickness (4 mm), are
    /// moved out to that distance from their closest skin point, as the simulator leaves
    /// cloth (only vertices within 6 cm of the skin are looked at).
    #[arg(long)]
    pub raw: bool,
    /// Drape a motion: these frames of the clip (--pose-bvh, --pose-amc) or of a procedural
    /// motion (--pose-procedural, keys every 30 frames), `A..B` or `A..B:STEP` (B exclusive),
    /// in parallel; the output is an animation.
    #[arg(long, value_name = "A..B[:STEP]", conflicts_with = "tpose")]
    pub frames: Option<FrameRange>,
    /// Frames a second of the animation (default: the clip's rate over the step; 30 for a
    /// procedural motion).
    #[arg(long, requires = "frames")]
    pub fps: Option<f32>,
    /// Smooth the garments in time (their offsets from the skinned template, filtered over
    /// five frames); each frame stays within 0.05 cm (mean vertex distance) of its unsmoothed
    /// drape.
    #[arg(long, requires = "frames")]
    pub smooth: bool,
}

impl DrapeArgs {
    /// The main job: the three shipped models on a random realistic adult (shape seed 1) in
    /// a procedural pose (seed 1), written to `out/draped-GARMENT.glb`, `out/body.glb` and
    /// pictures `out/drape-GARMENT.png`. Fails, naming the folder, when the models are missing.
    pub fn main_job() -> anyhow::Result<Self> {
        Ok(Self {
            models: garnet::shipped_models()?,
            shape: ShapeArgs {
                random_shape: Some(1),
                ..ShapeArgs::defaults()
            },
            pose: PoseArgs {
                pose_procedural: Some(1),
                ..PoseArgs::default()
            },
            keep_pose: false,
            out: "out/draped.glb".into(),
            body_out: Some("out/body.glb".into()),
            png: Some("out/drape.png".into()),
            device: DeviceArg::Cpu,
            raw: false,
            frames: None,
            fps: None,
            smooth: false,
        })
    }
}

/// Runs `garnet drape`.
pub fn run(args: &DrapeArgs) -> anyhow::Result<()> {
    if let Some(range) = args.frames {
        return crate::drape_motion::run(args, range);
    }
    let device = args.device.device()?;
    let body_model = BodyModel::load()?;
    let target = body_model.shape(&args.shape.phenotype(&body_model)?)?;
    let (pose, what) = args.pose.pose(&body_model, &target)?;
    let models = args
        .models
        .iter()
        .map(|path| GarmentModel::load(path, &device))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let opts = DrapeOptions {
        clear_limbs: !args.keep_pose,
        push_out: !args.raw,
    };
    let result = drape(&models, &target, &pose, opts)?;
    if let Some(ms) = result.collider_ms {
        eprintln!("body's collider for the push-out built in {ms:.1} ms, beside the networks");
    }
    let several = models.len() > 1;
    for (m, g) in models.iter().zip(&result.garments) {
        let t = g.timings;
        let pushed = match opts.push_out {
            true => format!(
                ", {} vertices pushed out of the body in {:.1} ms",
                g.pushed_out, t.push_out_ms
            ),
            false => String::new(),
        };
        eprintln!(
            "{} ({} vertices, {}) on a {:.1} cm body, {what}: warp {:.1} ms, network {:.1} ms{pushed}",
            g.kind,
            g.mesh.vertices.len(),
            m.method_name(),
            target.height() * 100.0,
            t.warp_ms,
            t.network_ms
        );
        let out = match several {
            true => with_kind(&args.out, &g.kind),
            false => args.out.clone(),
        };
        write_mesh(&out, &g.mesh)?;
    }
    if let Some(p) = &args.body_out {
        write_mesh(p, &result.body)?;
    }
    if let Some(png) = &args.png {
        // One picture per garment: two tops drawn over each other would hide both.
        for (m, g) in models.iter().zip(&result.garments) {
            let path = match several {
                true => with_kind(png, &g.kind),
                false => png.clone(),
            };
            let colour = garment_color(&m.template().kind);
            write_png(
                &path,
                &[(&result.body, palette::SKIN), (&g.mesh, colour)],
                (480, 720),
            )?;
        }
    }
    Ok(())
}

/// `path` with `-KIND` added to its file stem (`out/draped.glb` -> `out/draped-tshirt.glb`).
pub fn with_kind(path: &Path, kind: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("draped");
    match path.extension().and_then(|s| s.to_str()) {
        Some(ext) => path.with_file_name(format!("{stem}-{kind}.{ext}")),
        None => path.with_file_name(format!("{stem}-{kind}")),
    }
}
