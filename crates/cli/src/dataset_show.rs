//! `garnet dataset show`: one sample as a picture, the body, M and G side by side.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use dataset::Dataset;
use garment::GarmentKind;
use glam::Vec3;
use render::{palette, Framing, RenderMesh, RenderOptions, Sheet, View};

use crate::garment_cmd::garment_color;
use crate::output::create_parent;

/// Arguments of `garnet dataset show`.
#[derive(Args, Debug)]
pub struct ShowArgs {
    /// The dataset folder.
    pub dir: PathBuf,
    /// The sample index.
    #[arg(long)]
    pub index: u64,
    /// The picture to write.
    #[arg(long, value_name = "FILE.png")]
    pub png: PathBuf,
}

/// The bounds of all `points`, widened by 5 cm.
fn bounds(points: &[&[Vec3]]) -> (Vec3, Vec3) {
    let all = points.iter().flat_map(|p| p.iter().copied());
    let (lo, hi) = all.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    });
    (lo - Vec3::splat(0.05), hi + Vec3::splat(0.05))
}

pub fn show(args: &ShowArgs) -> anyhow::Result<()> {
    let data = Dataset::open(&args.dir)?;
    let sample = data.sample(args.index)?;
    let r = &sample.record;
    let template = data.template(&r.template)?;
    let body_faces = data.body_faces()?;
    let kind = data
        .manifest()
        .garments
        .iter()
        .find(|g| g.name == r.garment)
        .and_then(|g| GarmentKind::parse(&g.kind).ok())
        .unwrap_or(GarmentKind::Custom(r.garment.clone()));
    let a = &sample.arrays;
    let (min, max) = bounds(&[&a.body, &a.warped, &a.draped]);
    let options = RenderOptions {
        framing: Framing::Bounds { min, max },
        ..RenderOptions::default()
    };
    let body = RenderMesh::new(&a.body, &body_faces, palette::SKIN);
    let faces = &template.mesh.faces;
    let color = garment_color(&kind);
    let panels: [(Vec<RenderMesh>, &str); 3] = [
        (vec![body], "body"),
        (
            vec![body, RenderMesh::new(&a.warped, faces, color)],
            "M: warped (DQS)",
        ),
        (
            vec![body, RenderMesh::new(&a.draped, faces, color)],
            "G: draped",
        ),
    ];
    let mut sheet = Sheet::new(3).with_title(format!(
        "sample {}: {} on body {} ({:.1} cm, BMI {:.1}), {}, split {}",
        r.index,
        r.garment,
        r.body,
        r.stature_m * 100.0,
        r.bmi,
        r.pose,
        r.split
    ));
    for (scene, caption) in panels {
        let image = render::render_views_with(&scene, &[View::Front], (320, 480), &options)?;
        sheet.push(image, caption);
    }
    create_parent(&args.png)?;
    sheet
        .save_png(&args.png)
        .with_context(|| format!("writing {}", args.png.display()))?;
    eprintln!("wrote {}", args.png.display());
    Ok(())
}
