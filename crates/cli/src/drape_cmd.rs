//! `garnet drape`: a body in, draped garments out, with trained GarNet models. Each model
//! file carries its garment template, so nothing else is needed: the template is warped
//! onto the posed body by DQS (the network's input M) and the network predicts the drape.
//! With no command, garnet drapes the three shipped models (`models/`) on a random body in a
//! random pose ([`DrapeArgs::main_job`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, Context};
use body::clearance::{clear_limbs, ClearanceOptions};
use body::{BodyModel, Skinning};
use clap::Args;
use garment::warp::warp;
use garment::GarmentTemplate;
use geom::TriMesh;
use model::Draper;
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
    /// garment's kind is added to the name (`draped-tshirt.glb`).
    #[arg(long, default_value = "out/draped.glb")]
    pub out: PathBuf,
    /// Also write the posed body mesh here.
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
}

/// How far from the skin `garnet drape` looks for garment vertices to push out, metres: on
/// `standard`'s test split 6 cm left 0.17-0.36% of the vertices inside the body, 3 cm
/// 0.74-1.87% (session 14).
pub const PUSH_OUT_WITHIN: f32 = 0.06;

/// The gap `garnet drape` leaves between the skin and a garment vertex it pushes out: the
/// simulator's cloth thickness, metres.
pub fn push_out_gap() -> f32 {
    sim::ClothParams::default().thickness
}

/// Runs `networks` while another thread builds the collider of `body` for the push-out
/// (`None` for none): a forward pass of the flex backend keeps only about one of two cores
/// busy, so the build (18 ms for the 13,380-vertex body) mostly hides behind it. Returns
/// what `networks` returned, and the collider with its build time in ms.
pub fn beside_push_out_collider<T: Send>(
    body: Option<&TriMesh>,
    networks: impl FnOnce() -> T,
) -> (T, anyhow::Result<Option<(sim::BodyCollider, f64)>>) {
    std::thread::scope(|scope| {
        let building = body.map(|b| {
            scope.spawn(move || {
                let start = Instant::now();
                sim::BodyCollider::new(b, push_out_gap())
                    .map(|c| (c, start.elapsed().as_secs_f64() * 1e3))
            })
        });
        let out = networks();
        let collider = building
            .map(|h| {
                h.join()
                    .map_err(|_| anyhow!("building the body's collider failed"))?
                    .map_err(anyhow::Error::from)
            })
            .transpose();
        (out, collider)
    })
}

/// The shipped GarNet-Local models (in [`shipped_models_dir`]): T-shirt, sweater, jeans.
pub const SHIPPED_MODELS: [&str; 3] = [
    "tshirt-local.garnet",
    "sweater-local.garnet",
    "jeans-local.garnet",
];

/// Where the shipped models are: `models/` in the working directory when it holds them,
/// else the `models/` folder of the repository this binary was built from.
pub fn shipped_models_dir() -> PathBuf {
    let local = PathBuf::from("models");
    if local.join(SHIPPED_MODELS[0]).is_file() {
        return local;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

impl DrapeArgs {
    /// The main job: the three shipped models on a random realistic adult (shape seed 1) in
    /// a procedural pose (seed 1), written to `out/draped-GARMENT.glb`, `out/body.glb` and
    /// pictures `out/drape-GARMENT.png`. Fails, naming the folder, when the models are missing.
    pub fn main_job() -> anyhow::Result<Self> {
        let dir = shipped_models_dir();
        let models: Vec<PathBuf> = SHIPPED_MODELS.iter().map(|m| dir.join(m)).collect();
        if let Some(missing) = models.iter().find(|m| !m.is_file()) {
            return Err(anyhow!(
                "{}: shipped model missing (the main job drapes {}; train and export them as \
                 README \"GarNet\" shows)",
                missing.display(),
                SHIPPED_MODELS.join(", ")
            ));
        }
        Ok(Self {
            models,
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
        })
    }
}

/// The garment template a checkpoint carries.
pub fn checkpoint_template(draper: &Draper, path: &Path) -> anyhow::Result<GarmentTemplate> {
    let bytes = draper.setup().garment_file.as_ref().ok_or_else(|| {
        anyhow!(
            "{}: the model carries no garment template (train it with `garnet train`)",
            path.display()
        )
    })?;
    Ok(GarmentTemplate::from_bytes(bytes, path)?)
}

/// Runs `garnet drape`.
pub fn run(args: &DrapeArgs) -> anyhow::Result<()> {
    let device = args.device.device()?;
    let body_model = BodyModel::load()?;
    let target = body_model.shape(&args.shape.phenotype(&body_model)?)?;
    let (pose, what) = args.pose.pose(&body_model, &target)?;
    let pose = if args.keep_pose {
        pose
    } else {
        clear_limbs(&target, &pose, &ClearanceOptions::default())?.0
    };
    let drapers = args
        .models
        .iter()
        .map(|path| {
            Draper::load(path, &device).with_context(|| format!("loading {}", path.display()))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let body = target.posed(&pose, body_skinning(&args.models, &drapers)?)?;
    // The networks first (the body's collider is built beside them), then the push-out.
    let (predicted, collider) = beside_push_out_collider((!args.raw).then_some(&body), || {
        args.models
            .iter()
            .zip(&drapers)
            .map(|(path, draper)| {
                let template = checkpoint_template(draper, path)?;
                let start = Instant::now();
                let m = warp(&template, &target, &pose, Skinning::Dqs)?;
                let warp_ms = start.elapsed().as_secs_f64() * 1e3;
                let start = Instant::now();
                let draped = draper
                    .drape(&body.vertices, &m.vertices)
                    .with_context(|| format!("{}: draping", path.display()))?;
                Ok((
                    template,
                    draped,
                    warp_ms,
                    start.elapsed().as_secs_f64() * 1e3,
                ))
            })
            .collect::<anyhow::Result<Vec<_>>>()
    });
    let collider = collider?;
    if let Some((_, ms)) = &collider {
        eprintln!("body's collider for the push-out built in {ms:.1} ms, beside the networks");
    }
    let mut scene: Vec<(String, TriMesh, [u8; 3])> = Vec::new();
    let several = args.models.len() > 1;
    for (draper, (template, mut draped, warp_ms, net_ms)) in drapers.iter().zip(predicted?) {
        let start = Instant::now();
        let pushed = collider.as_ref().map_or(String::new(), |(c, _)| {
            let n = c.push_out(&mut draped, PUSH_OUT_WITHIN, push_out_gap());
            format!(
                ", {n} vertices pushed out of the body in {:.1} ms",
                start.elapsed().as_secs_f64() * 1e3
            )
        });
        eprintln!(
            "{} ({} vertices, {}) on a {:.1} cm body, {what}: warp {warp_ms:.1} ms, \
             network {net_ms:.1} ms{pushed}",
            template.kind.name(),
            draped.len(),
            draper.setup().config.method_name(),
            target.height() * 100.0
        );
        let mesh = TriMesh {
            vertices: draped,
            faces: template.mesh.faces.clone(),
        };
        let kind = template.kind.name();
        let out = if several {
            with_kind(&args.out, kind)
        } else {
            args.out.clone()
        };
        write_mesh(&out, &mesh)?;
        scene.push((kind.to_string(), mesh, garment_color(&template.kind)));
    }
    if let Some(p) = &args.body_out {
        write_mesh(p, &body)?;
    }
    if let Some(png) = &args.png {
        // One picture per garment: two tops drawn over each other would hide both.
        for (kind, mesh, color) in &scene {
            let path = if several {
                with_kind(png, kind)
            } else {
                png.clone()
            };
            write_png(&path, &[(&body, palette::SKIN), (mesh, *color)], (480, 720))?;
        }
    }
    Ok(())
}

/// How the body must be posed for the models at `paths` (`drapers`, loaded from them): the
/// skinning of the bodies they learned from, which they must share.
fn body_skinning(paths: &[PathBuf], drapers: &[Draper]) -> anyhow::Result<Skinning> {
    let names: Vec<&str> = drapers
        .iter()
        .map(|d| d.setup().body_skinning.as_str())
        .collect();
    if let Some(k) = names.iter().position(|n| *n != names[0]) {
        anyhow::bail!(
            "{} learned from bodies posed with {}, {} with {}: drape them in separate runs",
            paths[0].display(),
            names[0],
            paths[k].display(),
            names[k]
        );
    }
    let name = names.first().copied().unwrap_or("dqs");
    Skinning::from_name(name).with_context(|| format!("unknown body skinning '{name}'"))
}

/// `path` with `-KIND` added to its file stem (`out/draped.glb` -> `out/draped-tshirt.glb`).
fn with_kind(path: &Path, kind: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("draped");
    match path.extension().and_then(|s| s.to_str()) {
        Some(ext) => path.with_file_name(format!("{stem}-{kind}.{ext}")),
        None => path.with_file_name(format!("{stem}-{kind}")),
    }
}
