//! `garnet simulate`: drape a garment template on a body of any shape and pose with the
//! cloth simulator.

use std::path::{Path, PathBuf};

use anyhow::Context;
use body::clearance::ClearanceOptions;
use body::BodyModel;
use clap::Args;
use garment::GarmentTemplate;
use render::palette;
use sim::drape::{drape, DrapeOptions};

use crate::body_cmd::SkinningArg;
use crate::garment_cmd::garment_color;
use crate::output::{create_parent, write_mesh, write_png, write_strain_png};
use crate::pose_args::PoseArgs;
use crate::shape_args::ShapeArgs;

/// Arguments of `garnet simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// The garment template (from `garnet garment make` or `import`).
    #[arg(long)]
    pub template: Option<PathBuf>,
    #[command(flatten)]
    pub shape: ShapeArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    /// How the body is skinned during the animation [default: lbs, or the --simulator
    /// file's].
    #[arg(long, value_enum)]
    pub skinning: Option<SkinningArg>,
    /// The draped garment (.obj, .ply, .glb).
    #[arg(long, default_value = "out/draped.obj")]
    pub out: PathBuf,
    /// Also write the posed body.
    #[arg(long, value_name = "FILE")]
    pub body_out: Option<PathBuf>,
    /// Write the drape's statistics as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub stats: Option<PathBuf>,
    /// Also write a picture of the draped garment on the body.
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,
    /// Also write a strain map: the garment coloured by how far its edges are stretched
    /// (blue 0%, red 10% or more), front, side and back.
    #[arg(long, value_name = "FILE.png")]
    pub strain_png: Option<PathBuf>,
    /// Write the animation as meshes into this folder (garment_NNNN.obj, body_NNNN.obj).
    #[arg(long, value_name = "DIR")]
    pub frames: Option<PathBuf>,
    /// With --frames: keep every Nth step.
    #[arg(long, default_value_t = 5)]
    pub frames_every: u32,
    /// Simulator settings: a TOML file with the keys of a dataset spec's `[simulator]`
    /// table (`friction = 0.2`, `stretch_stiffness = 5000.0`, `dt = 0.01`, ...), at its top
    /// level or under a `[simulator]` header, so a dataset spec drapes as its dataset did.
    /// Keys it leaves out keep the simulator's defaults, as in a dataset.
    #[arg(long, value_name = "FILE.toml")]
    pub simulator: Option<PathBuf>,
    /// Most settling steps after the animation [default: 400, or the --simulator file's].
    #[arg(long)]
    pub max_settle_steps: Option<u32>,
    /// A drape leaving a garment vertex deeper than this inside the body fails, mm
    /// [default: 1, or the --simulator file's].
    #[arg(long)]
    pub max_penetration_mm: Option<f32>,
    /// Drape the pose exactly as given: no limb clearance (by default a limb that sinks
    /// into the body, as a heavy arm into the chest, is first turned out of it).
    #[arg(long)]
    pub keep_pose: bool,
    /// Instead: 30 drapes (T-shirt, sweater, jeans x 10 random shapes and poses) into a
    /// picture sheet, with their statistics beside it (.json, .md).
    #[arg(long, value_name = "FILE.png")]
    pub sheet: Option<PathBuf>,
    /// With --sheet: template edge length, metres.
    #[arg(long, default_value_t = 0.01)]
    pub edge: f32,
    /// With --sheet: a garment's cut as `KIND:KEY=VALUE[,KEY=VALUE...]` with the parameters
    /// of `garnet garment make` (e.g. `tshirt:flare=0.03,bridge=0`); repeatable. Garments
    /// it does not name keep their default cut.
    #[arg(long = "cut", value_name = "KIND:SETTINGS")]
    pub cuts: Vec<String>,
    /// With --sheet: folder of the CMU clips, with 01/ and 02/ inside (default:
    /// $GARNET_MOCAP/cmu).
    #[arg(long, value_name = "DIR")]
    pub mocap: Option<PathBuf>,
}

pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let model = BodyModel::load()?;
    let opts = drape_options(args)?;
    if let Some(sheet) = &args.sheet {
        let templates = crate::simulate_sheet::SheetTemplates {
            edge: args.edge,
            cuts: args.cuts.clone(),
        };
        let mocap = args.mocap.as_deref();
        return crate::simulate_sheet::write_sheet(&model, sheet, mocap, &templates, &opts);
    }
    let path = args
        .template
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("--template is required (or --sheet)"))?;
    let template = GarmentTemplate::load(path)?;
    let template_body = model.shape(&template.body_phenotype)?;
    let target = model.shape(&args.shape.phenotype(&model)?)?;
    let (pose, what) = args.pose.pose(&model, &target)?;
    if let Some(dir) = &args.frames {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut frame_error: Option<anyhow::Error> = None;
    let mut record = |step: u32, garment: &[glam::Vec3], body: &[glam::Vec3]| {
        let Some(dir) = &args.frames else { return };
        if step % args.frames_every.max(1) != 0 || frame_error.is_some() {
            return;
        }
        let write = |name: &str, v: &[glam::Vec3], faces: &[[u32; 3]]| -> anyhow::Result<()> {
            let mesh = geom::TriMesh {
                vertices: v.to_vec(),
                faces: faces.to_vec(),
            };
            Ok(geom::io::write_mesh(
                dir.join(format!("{name}_{step:04}.obj")),
                &mesh,
            )?)
        };
        if let Err(e) = write("garment", garment, &template.mesh.faces)
            .and_then(|_| write("body", body, &target.mesh.faces))
        {
            frame_error = Some(e);
        }
    };
    let result = drape(
        &template,
        &template_body,
        &target,
        &pose,
        &opts,
        &mut record,
    )
    .with_context(|| format!("draping {} ({what})", template.kind.name()))?;
    if let Some(e) = frame_error {
        return Err(e.context("writing the animation frames"));
    }
    eprintln!(
        "{} on a {:.1} cm body, {what}: {}",
        template.kind.name(),
        target.height() * 100.0,
        result.stats.summary()
    );
    write_mesh(&args.out, &result.garment)?;
    if let Some(p) = &args.body_out {
        write_mesh(p, &result.body)?;
    }
    if let Some(p) = &args.stats {
        write_json(p, &result.stats)?;
    }
    if let Some(png) = &args.png {
        write_png(
            png,
            &[
                (&result.body, palette::SKIN),
                (&result.garment, garment_color(&template.kind)),
            ],
            (480, 720),
        )?;
    }
    if let Some(png) = &args.strain_png {
        write_strain_png(
            png,
            &result.body,
            &result.garment,
            &result.vertex_strain,
            (480, 720),
        )?;
    }
    Ok(())
}

/// The drape options of `args`: the defaults, then the `--simulator` file's settings, then
/// the flags.
fn drape_options(args: &SimulateArgs) -> anyhow::Result<DrapeOptions> {
    let mut opts = dataset::simulator::load_drape_options_or_default(args.simulator.as_deref())?;
    if let Some(skinning) = args.skinning {
        opts.skinning = skinning.into();
    }
    opts.clearance = (!args.keep_pose).then(ClearanceOptions::default);
    if let Some(steps) = args.max_settle_steps {
        opts.max_settle_steps = steps;
    }
    if let Some(mm) = args.max_penetration_mm {
        anyhow::ensure!(
            mm.is_finite() && mm >= 0.0,
            "--max-penetration-mm must be a non-negative number of millimetres, got {mm}"
        );
        opts.max_penetration = mm * 1e-3;
    }
    Ok(opts)
}

/// Writes `value` as pretty JSON to `path` (atomically).
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    create_parent(path)?;
    let text = serde_json::to_string_pretty(value)?;
    geom::io::write_bytes_atomic(path, text.as_bytes())?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
