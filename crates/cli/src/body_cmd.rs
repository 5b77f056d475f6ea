//! `garnet body`: a body of a given shape and pose as a mesh, a picture, or a sheet of
//! random shapes in several poses.

use std::path::{Path, PathBuf};

use anyhow::Context;
use body::pose::{save_bvh, Amc, Asf, BvhWriteOptions};
use body::{BodyModel, Skinning};
use clap::{Args, ValueEnum};
use glam::Vec3;
use rayon::prelude::*;
use render::{palette, Framing, RenderMesh, RenderOptions, Sheet, View};

use crate::output::{create_parent, write_mesh, write_png};
use crate::pose_args::{KindArg, PoseArgs};
use crate::shape_args::ShapeArgs;

/// Arguments of `garnet body`.
#[derive(Args, Debug, Clone)]
pub struct BodyArgs {
    #[command(flatten)]
    pub shape: ShapeArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    /// Skinning method.
    #[arg(long, value_enum, default_value_t = SkinningArg::Dqs)]
    pub skinning: SkinningArg,
    /// Mesh output (.obj, .ply or .glb).
    #[arg(long, default_value = "out/body.glb")]
    pub out: PathBuf,
    /// Also write a picture (front and side views).
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,
    /// Instead: a sheet of five random shapes in five poses each (needs the CMU clips).
    #[arg(long, value_name = "FILE.png")]
    pub sheet: Option<PathBuf>,
    /// Folder of the CMU clips for --sheet, with 01/ and 02/ inside (default:
    /// $GARNET_MOCAP/cmu).
    #[arg(long, value_name = "DIR")]
    pub mocap: Option<PathBuf>,
}

/// Skinning method on the command line.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum SkinningArg {
    Dqs,
    Lbs,
}

impl From<SkinningArg> for Skinning {
    fn from(s: SkinningArg) -> Self {
        match s {
            SkinningArg::Dqs => Skinning::Dqs,
            SkinningArg::Lbs => Skinning::Lbs,
        }
    }
}

pub fn run(args: &BodyArgs) -> anyhow::Result<()> {
    let model = BodyModel::load()?;
    if let Some(sheet) = &args.sheet {
        let mocap = crate::pose_args::cmu_folder(args.mocap.as_deref(), "body --sheet")?;
        return write_sheet(&model, sheet, &mocap, args.skinning.into());
    }
    let phenotype = args.shape.phenotype(&model)?;
    let body = model.shape(&phenotype)?;
    let (pose, what) = args.pose.pose(&model, &body)?;
    let mesh = body.posed(&pose, args.skinning.into())?;
    eprintln!(
        "body: {:.1} cm tall at rest, pose: {what}",
        body.height() * 100.0
    );
    write_mesh(&args.out, &mesh)?;
    if let Some(png) = &args.png {
        write_png(png, &[(&mesh, palette::SKIN)], (480, 720))?;
    }
    Ok(())
}

/// The five pose sources of the sheet, as pose arguments for shape `seed`.
fn sheet_poses(mocap: &Path, bvh: &Path, seed: u64) -> [(PoseArgs, &'static str); 5] {
    let amc = |clip: &str, frame| PoseArgs {
        pose_amc: Some(mocap.join(clip)),
        frame,
        ..PoseArgs::default()
    };
    let procedural = |kind| PoseArgs {
        pose_procedural: Some(seed),
        pose_kind: kind,
        ..PoseArgs::default()
    };
    [
        (amc("02/02_01.amc", 90 + 10 * seed as usize), "AMC walk"),
        (amc("01/01_02.amc", 1500 + 300 * seed as usize), "AMC climb"),
        (
            PoseArgs {
                pose_bvh: Some(bvh.to_path_buf()),
                frame: 400 + 120 * seed as usize,
                ..PoseArgs::default()
            },
            "BVH punch",
        ),
        (procedural(KindArg::Walk), "proc. walk"),
        (procedural(KindArg::Yoga), "proc. yoga"),
    ]
}

/// Five random shapes (seeds 1-5) in five poses each, front and side, one PNG.
fn write_sheet(
    model: &BodyModel,
    path: &Path,
    mocap: &Path,
    skinning: Skinning,
) -> anyhow::Result<()> {
    // The BVH column reads a BVH file that garnet writes from a CMU clip.
    let tmp = tempfile::tempdir()?;
    let bvh = tmp.path().join("02_05.bvh");
    let asf = Asf::read(mocap.join("02/02.asf"))
        .context("--mocap must hold the CMU subjects 01 and 02")?;
    let amc = Amc::read(mocap.join("02/02_05.amc"), &asf)?;
    save_bvh(&bvh, &asf, &amc, &BvhWriteOptions::default())?;

    let cells: Vec<(u64, usize)> = (1..=5).flat_map(|s| (0..5).map(move |p| (s, p))).collect();
    let options = RenderOptions {
        framing: Framing::Bounds {
            min: Vec3::new(-0.9, -0.05, -0.9),
            max: Vec3::new(0.9, 2.05, 0.9),
        },
        ..RenderOptions::default()
    };
    let images = cells
        .par_iter()
        .map(|&(seed, p)| -> anyhow::Result<(render::Image, String)> {
            let shape = ShapeArgs {
                random_shape: Some(seed),
                ..ShapeArgs::defaults()
            };
            let body = model.shape(&shape.phenotype(model)?)?;
            let (pose_args, label) = &sheet_poses(mocap, &bvh, seed)[p];
            let (pose, what) = pose_args.pose(model, &body)?;
            let mesh = body.posed(&pose, skinning)?;
            let scene = [RenderMesh::new(&mesh.vertices, &mesh.faces, palette::SKIN)];
            let image = render::render_views_with(
                &scene,
                &[View::Front, View::Side],
                (220, 330),
                &options,
            )?;
            let detail = what.rsplit(' ').next().unwrap_or("");
            Ok((
                image,
                format!("{seed}: {:.0} cm, {label} #{detail}", body.height() * 100.0),
            ))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut sheet = Sheet::new(5)
        .with_title("garnet body: 5 random adult shapes x 5 pose sources (front | side)");
    for (image, caption) in images {
        sheet.push(image, caption);
    }
    create_parent(path)?;
    sheet
        .save_png(path)
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
