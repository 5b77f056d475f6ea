//! `garnet dataset show`: samples as a picture, each a row of the body, M and G side by
//! side: chosen by index, or drawn at random from the stored samples.

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
    /// Sample indices (repeat the flag or separate by commas).
    #[arg(long, value_delimiter = ',', required_unless_present = "random")]
    pub index: Vec<u64>,
    /// Instead: this many stored samples drawn at random (by --seed).
    #[arg(long, value_name = "N", conflicts_with = "index")]
    pub random: Option<usize>,
    /// Seed of --random.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
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

/// The indices `args` asks for: as given, or `--random N` distinct stored samples.
fn chosen(data: &Dataset, args: &ShowArgs) -> anyhow::Result<Vec<u64>> {
    let Some(n) = args.random else {
        return Ok(args.index.clone());
    };
    let stored = data.select(None, None)?;
    let picks = dataset::rng::SplitMix64::new(args.seed).choose(stored.len(), n.min(stored.len()));
    Ok(picks.into_iter().map(|i| stored[i]).collect())
}

pub fn show(args: &ShowArgs) -> anyhow::Result<()> {
    let data = Dataset::open(&args.dir)?;
    let indices = chosen(&data, args)?;
    if indices.is_empty() {
        anyhow::bail!("{}: no samples to show", args.dir.display());
    }
    let body_faces = data.body_faces()?;
    // One sample a row, or two for a larger set.
    let columns = if indices.len() > 3 { 6 } else { 3 };
    let mut sheet = Sheet::new(columns).with_title(format!(
        "{}: {} sample(s), each as body, M (DQS warp), G (draped)",
        args.dir.display(),
        indices.len()
    ));
    for &index in &indices {
        let sample = data.sample(index)?;
        let r = &sample.record;
        let template = data.template(&r.template)?;
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
        let what = format!(
            "#{} {} body {} ({:.0} cm, BMI {:.0}) {} [{}]",
            r.index,
            r.garment,
            r.body,
            r.stature_m * 100.0,
            r.bmi,
            r.pose,
            r.split
        );
        let panels: [(Vec<RenderMesh>, String); 3] = [
            (vec![body], what),
            (
                vec![body, RenderMesh::new(&a.warped, faces, color)],
                "M: warped (DQS)".into(),
            ),
            (
                vec![body, RenderMesh::new(&a.draped, faces, color)],
                "G: draped".into(),
            ),
        ];
        for (scene, caption) in panels {
            let image = render::render_views_with(&scene, &[View::Front], (240, 360), &options)?;
            sheet.push(image, caption);
        }
    }
    create_parent(&args.png)?;
    sheet
        .save_png(&args.png)
        .with_context(|| format!("writing {}", args.png.display()))?;
    eprintln!("wrote {}", args.png.display());
    Ok(())
}
