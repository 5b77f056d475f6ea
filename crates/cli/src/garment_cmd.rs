//! `garnet garment`: make, import and warp garment templates.

use std::path::{Path, PathBuf};

use anyhow::Context;
use body::BodyModel;
use clap::{Args, Subcommand, ValueEnum};
use garment::import::{import_garment, ImportLimits};
use garment::warp::{warp, warp_fitted, SurfaceAnchors};
use garment::{build_template, CutParams, GarmentKind, GarmentTemplate};
use render::palette;

use crate::body_cmd::SkinningArg;
use crate::output::{create_parent, write_mesh, write_png};
use crate::pose_args::PoseArgs;
use crate::shape_args::ShapeArgs;

/// Garment templates.
#[derive(Subcommand, Debug)]
pub enum GarmentCmd {
    /// Build a T-shirt, sweater or jeans template on the template body.
    Make(MakeArgs),
    /// Make a template from your own garment mesh (OBJ, PLY or GLB, metres, fitted on
    /// the rest-pose template body).
    Import {
        /// The garment mesh.
        file: PathBuf,
        /// Name stored in the template (default: the file name).
        #[arg(long)]
        name: Option<String>,
        /// Template file to write, a .garment name.
        #[arg(
            long,
            value_name = "FILE.garment",
            default_value = "out/custom.garment"
        )]
        out: PathBuf,
        /// Also write a picture of it on the template body.
        #[arg(long, value_name = "FILE.png")]
        png: Option<PathBuf>,
    },
    /// Warp a template onto a body of any shape and pose (DQS, or LBS).
    Warp(WarpArgs),
    /// Picture sheet: the three templates on the template body, and each warped onto
    /// three random shapes in three poses (walk, arms raised, sitting).
    Sheet {
        /// The PNG to write.
        #[arg(long, default_value = "docs/garments.png")]
        out: PathBuf,
        /// Template edge length, metres.
        #[arg(long, default_value_t = 0.01)]
        edge: f32,
        /// Folder of the CMU clips (the walk comes from 02/02_01.amc; default:
        /// $GARNET_MOCAP/cmu).
        #[arg(long, value_name = "DIR")]
        mocap: Option<PathBuf>,
    },
}

/// Garment kinds on the command line.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum KindArg {
    Tshirt,
    Sweater,
    Jeans,
}

/// Arguments of `garnet garment make`.
#[derive(Args, Debug)]
pub struct MakeArgs {
    /// Which garment.
    pub kind: KindArg,
    /// Target edge length, metres (0.01 gives the paper's ~10k-vertex T-shirt).
    #[arg(long, default_value_t = 0.01)]
    pub edge: f32,
    /// Tops: neck base to hem, metres.
    #[arg(long)]
    pub body_length: Option<f32>,
    /// Tops: shoulder joint to cuff along the arm, metres.
    #[arg(long)]
    pub sleeve_length: Option<f32>,
    /// Mean gap to the skin, metres.
    #[arg(long)]
    pub ease: Option<f32>,
    /// Tops: drop of the front neckline, metres.
    #[arg(long)]
    pub neckline_depth: Option<f32>,
    /// Jeans: waistband above the hip joint, metres.
    #[arg(long)]
    pub waist_height: Option<f32>,
    /// Jeans: hip joint to hem along the leg, metres.
    #[arg(long)]
    pub leg_length: Option<f32>,
    /// Extra ease at the sleeve cuffs or trouser hems, metres, growing from a quarter of the
    /// way along the limb: straight sleeves and legs.
    #[arg(long)]
    pub flare: Option<f32>,
    /// How much the cloth spans the body's hollows (armpits, gluteal cleft) instead of
    /// following them, 0 to 1 (a fraction of the default bridging smoothing).
    #[arg(long)]
    pub bridge: Option<f32>,
    /// Jeans: extra ease over the thighs and knees, metres (most 40% of the way down the
    /// leg, none at the hips and from 75% on).
    #[arg(long)]
    pub thigh: Option<f32>,
    /// Template file to write, a .garment name (default out/KIND.garment).
    #[arg(long, value_name = "FILE.garment")]
    pub out: Option<PathBuf>,
    /// Also write the garment mesh (.obj, .ply, .glb).
    #[arg(long, value_name = "FILE")]
    pub mesh: Option<PathBuf>,
    /// Also write a picture of it on the template body.
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,
}

/// Arguments of `garnet garment warp`.
#[derive(Args, Debug)]
pub struct WarpArgs {
    /// The template file.
    #[arg(long)]
    pub template: PathBuf,
    #[command(flatten)]
    pub shape: ShapeArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    /// Skinning method.
    #[arg(long, value_enum, default_value_t = SkinningArg::Dqs)]
    pub skinning: SkinningArg,
    /// The paper's M: skin the template with the joints only, without first carrying
    /// it over the body's change of shape (girth) by its surface anchors.
    #[arg(long)]
    pub joints_only: bool,
    /// The warped garment mesh (.obj, .ply, .glb).
    #[arg(long, default_value = "out/warped.obj")]
    pub out: PathBuf,
    /// Also write the posed body mesh.
    #[arg(long, value_name = "FILE")]
    pub body_out: Option<PathBuf>,
    /// Also write a picture of the garment on the body.
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,
}

impl From<KindArg> for GarmentKind {
    fn from(k: KindArg) -> Self {
        match k {
            KindArg::Tshirt => GarmentKind::Tshirt,
            KindArg::Sweater => GarmentKind::Sweater,
            KindArg::Jeans => GarmentKind::Jeans,
        }
    }
}

/// Colour of a garment in pictures.
pub fn garment_color(kind: &GarmentKind) -> [u8; 3] {
    match kind {
        GarmentKind::Tshirt => palette::TSHIRT_BLUE,
        GarmentKind::Sweater => palette::SWEATER_RED,
        GarmentKind::Jeans => palette::JEANS_INDIGO,
        GarmentKind::Custom(_) => palette::OLIVE,
    }
}

pub fn run(cmd: &GarmentCmd) -> anyhow::Result<()> {
    let model = BodyModel::load()?;
    match cmd {
        GarmentCmd::Make(args) => make(&model, args),
        GarmentCmd::Import {
            file,
            name,
            out,
            png,
        } => {
            check_template_path(out, "")?;
            let mesh = geom::io::read_mesh(file)?;
            let name = name
                .clone()
                .unwrap_or_else(|| crate::pose_args::file_name(file));
            let template = import_garment(mesh, &name, &model, &ImportLimits::default())?;
            save(&template, out)?;
            picture_on_template_body(&model, &template, png.as_deref())
        }
        GarmentCmd::Sheet { out, edge, mocap } => {
            let mocap = crate::pose_args::cmu_folder(mocap.as_deref(), "garment sheet")?;
            crate::garment_sheet::write_sheet(&model, out, *edge, &mocap)
        }
        GarmentCmd::Warp(args) => {
            let template = GarmentTemplate::load(&args.template)?;
            let body = model.shape(&args.shape.phenotype(&model)?)?;
            let (pose, what) = args.pose.pose(&model, &body)?;
            let warped = if args.joints_only {
                warp(&template, &body, &pose, args.skinning.into())?
            } else {
                let template_body = model.shape(&template.body_phenotype)?;
                let anchors = SurfaceAnchors::new(&template.mesh, &template_body.mesh)?;
                warp_fitted(&template, &anchors, &body, &pose, args.skinning.into())?
            };
            eprintln!(
                "{} warped onto a {:.1} cm body, pose: {what}",
                template.kind.name(),
                body.height() * 100.0
            );
            write_mesh(&args.out, &warped)?;
            let posed = body.posed(&pose, args.skinning.into())?;
            if let Some(path) = &args.body_out {
                write_mesh(path, &posed)?;
            }
            if let Some(png) = &args.png {
                write_png(
                    png,
                    &[
                        (&posed, palette::SKIN),
                        (&warped, garment_color(&template.kind)),
                    ],
                    (480, 720),
                )?;
            }
            Ok(())
        }
    }
}

fn make(model: &BodyModel, args: &MakeArgs) -> anyhow::Result<()> {
    let kind: GarmentKind = args.kind.into();
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("out/{}.garment", kind.name())));
    check_template_path(
        &out,
        " (the mesh alone is written with --mesh FILE.obj|ply|glb)",
    )?;
    let d = CutParams::default_for(&kind);
    let cut = CutParams {
        body_length: args.body_length.unwrap_or(d.body_length),
        sleeve_length: args.sleeve_length.unwrap_or(d.sleeve_length),
        ease: args.ease.unwrap_or(d.ease),
        neckline_depth: args.neckline_depth.unwrap_or(d.neckline_depth),
        waist_height: args.waist_height.unwrap_or(d.waist_height),
        leg_length: args.leg_length.unwrap_or(d.leg_length),
        flare: args.flare.unwrap_or(d.flare),
        bridge: args.bridge.unwrap_or(d.bridge),
        thigh: args.thigh.unwrap_or(d.thigh),
    };
    let t0 = std::time::Instant::now();
    let template = build_template(model, &kind, &cut, args.edge)?;
    eprintln!(
        "{}: {} vertices, {} faces, built in {:.2} s",
        kind.name(),
        template.mesh.vertices.len(),
        template.mesh.faces.len(),
        t0.elapsed().as_secs_f32()
    );
    save(&template, &out)?;
    if let Some(path) = &args.mesh {
        write_mesh(path, &template.mesh)?;
    }
    picture_on_template_body(model, &template, args.png.as_deref())
}

/// Errors unless `out` is a `.garment` file name: a template is never written under a
/// mesh's name. `hint` ends the message.
fn check_template_path(out: &Path, hint: &str) -> anyhow::Result<()> {
    let ext = out.extension().and_then(|e| e.to_str());
    if ext.is_some_and(|e| e.eq_ignore_ascii_case("garment")) {
        return Ok(());
    }
    let mesh = matches!(
        ext.map(str::to_ascii_lowercase).as_deref(),
        Some("obj" | "ply" | "glb")
    );
    if mesh && !hint.is_empty() {
        anyhow::bail!(
            "--out {}: --out writes the template, under a .garment name; to write the mesh, \
             use --mesh {}",
            out.display(),
            out.display()
        );
    }
    anyhow::bail!(
        "--out {}: --out writes the template, under a .garment name{hint}",
        out.display()
    )
}

fn save(template: &GarmentTemplate, out: &Path) -> anyhow::Result<()> {
    create_parent(out)?;
    template
        .save(out)
        .with_context(|| format!("writing {}", out.display()))?;
    eprintln!("wrote {}", out.display());
    Ok(())
}

fn picture_on_template_body(
    model: &BodyModel,
    template: &GarmentTemplate,
    png: Option<&Path>,
) -> anyhow::Result<()> {
    let Some(png) = png else { return Ok(()) };
    let body = model.shape(&template.body_phenotype)?;
    write_png(
        png,
        &[
            (&body.mesh, palette::SKIN),
            (&template.mesh, garment_color(&template.kind)),
        ],
        (480, 720),
    )
}
