//! `garnet simulate --sheet`: thirty drapes (T-shirt, sweater and jeans on ten random
//! shapes in poses from CMU clips and the procedural generator), their statistics as
//! JSON and a Markdown table, and a picture sheet.

use std::path::Path;

use anyhow::Context;
use body::BodyModel;
use garment::{build_template, CutParams, GarmentKind};
use glam::Vec3;
use render::{palette, Framing, RenderMesh, RenderOptions, Sheet, View};
use serde::Serialize;
use sim::drape::{drape, DrapeOptions};
use sim::stats::DrapeStats;

use crate::garment_cmd::garment_color;
use crate::output::create_parent;
use crate::pose_args::{KindArg, PoseArgs};
use crate::shape_args::ShapeArgs;
use crate::simulate_cmd::write_json;

/// One drape of the sheet and how it went.
#[derive(Serialize)]
struct Case {
    garment: String,
    shape_seed: u64,
    pose: String,
    stature_cm: f32,
    stats: Option<DrapeStats>,
    failure: Option<String>,
}

/// Pose source `i` (0..10) of the sheet: CMU frames and procedural draws alternate.
fn case_pose(i: u64, mocap: &Path) -> PoseArgs {
    let amc = |clip: &str, frame| PoseArgs {
        pose_amc: Some(mocap.join(clip)),
        frame,
        ..PoseArgs::default()
    };
    let procedural = |kind| PoseArgs {
        pose_procedural: Some(100 + i),
        pose_kind: kind,
        ..PoseArgs::default()
    };
    match i {
        0 => amc("02/02_01.amc", 90),
        2 => amc("02/02_05.amc", 500),
        4 => amc("01/01_02.amc", 2100),
        6 => amc("02/02_01.amc", 200),
        8 => amc("02/02_09.amc", 300),
        1 => procedural(KindArg::Walk),
        3 | 9 => procedural(KindArg::Yoga),
        5 => procedural(KindArg::Dance),
        _ => procedural(KindArg::Any),
    }
}

/// How the sheet's garments are built.
pub struct SheetTemplates {
    /// Template edge length, metres.
    pub edge: f32,
    /// Cut settings `KIND:KEY=VALUE[,KEY=VALUE...]` ([`CutParams::apply`]); a kind not
    /// named keeps its default cut.
    pub cuts: Vec<String>,
}

impl SheetTemplates {
    /// The cut of `kind`: its default with the settings naming it. Errors on a setting for
    /// no garment of the sheet or a bad one, quoting it.
    fn cut(&self, kind: &GarmentKind) -> anyhow::Result<CutParams> {
        let mut cut = CutParams::default_for(kind);
        for setting in &self.cuts {
            let (name, settings) = setting.split_once(':').ok_or_else(|| {
                anyhow::anyhow!("--cut '{setting}': expected KIND:KEY=VALUE[,KEY=VALUE...]")
            })?;
            let named = GarmentKind::parse(name).with_context(|| format!("--cut '{setting}'"))?;
            if named == *kind {
                cut.apply(settings)
                    .with_context(|| format!("--cut '{setting}'"))?;
            }
        }
        Ok(cut)
    }
}

/// Runs the thirty drapes with `templates`, writes `png`, and the statistics beside it
/// (`.json`, `.md`). `mocap` is `--mocap` (see [`crate::pose_args::cmu_folder`]), needed
/// once the cuts are checked.
pub fn write_sheet(
    model: &BodyModel,
    png: &Path,
    mocap: Option<&Path>,
    templates: &SheetTemplates,
    opts: &DrapeOptions,
) -> anyhow::Result<()> {
    let edge = templates.edge;
    let kinds = [
        GarmentKind::Tshirt,
        GarmentKind::Sweater,
        GarmentKind::Jeans,
    ];
    let options = RenderOptions {
        framing: Framing::Bounds {
            min: Vec3::new(-0.9, -0.05, -0.9),
            max: Vec3::new(0.9, 2.05, 0.9),
        },
        ..RenderOptions::default()
    };
    let cuts = kinds
        .iter()
        .map(|k| templates.cut(k))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mocap = &crate::pose_args::cmu_folder(mocap, "simulate --sheet")?;
    let cut_note: String = templates.cuts.iter().map(|c| format!(", {c}")).collect();
    let mut sheet = Sheet::new(10).with_title(format!(
        "garnet simulate: 30 drapes, templates with {} cm edges{cut_note}",
        edge * 100.0
    ));
    let mut cases = Vec::new();
    for (kind, cut) in kinds.iter().zip(&cuts) {
        let template = build_template(model, kind, cut, edge)?;
        let template_body = model.shape(&template.body_phenotype)?;
        for i in 0..10u64 {
            let shape = ShapeArgs {
                random_shape: Some(100 + i),
                ..ShapeArgs::defaults()
            };
            let target = model.shape(&shape.phenotype(model)?)?;
            let (pose, what) = case_pose(i, mocap)
                .pose(model, &target)
                .with_context(|| format!("pose {i}"))?;
            let result = drape(
                &template,
                &template_body,
                &target,
                &pose,
                opts,
                &mut |_, _, _| {},
            );
            let mut case = Case {
                garment: kind.name().into(),
                shape_seed: 100 + i,
                pose: what.clone(),
                stature_cm: target.height() * 100.0,
                stats: None,
                failure: None,
            };
            let image = match &result {
                Ok(d) => {
                    eprintln!(
                        "{} / shape {} / {what}: {}",
                        kind.name(),
                        100 + i,
                        d.stats.summary()
                    );
                    case.stats = Some(d.stats.clone());
                    let scene = [
                        RenderMesh::new(&d.body.vertices, &d.body.faces, palette::SKIN),
                        RenderMesh::new(&d.garment.vertices, &d.garment.faces, garment_color(kind)),
                    ];
                    render::render_views_with(&scene, &[View::Front], (200, 300), &options)?
                }
                Err(e) => {
                    eprintln!("{} / shape {} / {what}: FAILED: {e}", kind.name(), 100 + i);
                    case.failure = Some(e.to_string());
                    let body = target.posed(&pose, opts.skinning)?;
                    let scene = [RenderMesh::new(&body.vertices, &body.faces, palette::SKIN)];
                    render::render_views_with(&scene, &[View::Front], (200, 300), &options)?
                }
            };
            let caption = match &case.stats {
                Some(s) => format!(
                    "{} {}: {:.1}s {}",
                    kind.name(),
                    100 + i,
                    s.wall_time_s,
                    short(&what)
                ),
                None => format!("{} {}: FAILED", kind.name(), 100 + i),
            };
            sheet.push(image, caption);
            cases.push(case);
        }
    }
    create_parent(png)?;
    sheet
        .save_png(png)
        .with_context(|| format!("writing {}", png.display()))?;
    eprintln!("wrote {}", png.display());
    write_json(&png.with_extension("json"), &cases)?;
    let table = markdown(&cases);
    geom::io::write_bytes_atomic(png.with_extension("md"), table.as_bytes())?;
    println!("{table}");
    Ok(())
}

/// The last word of a pose description (clip frame or seed).
fn short(what: &str) -> String {
    what.split_whitespace()
        .take(2)
        .collect::<Vec<_>>()
        .join(" ")
}

/// A Markdown table of the cases and a summary line.
fn markdown(cases: &[Case]) -> String {
    let mut out = String::from(
        "| garment | shape | pose | time (s) | steps | at rest | max pen. (mm) | strain p99 (%) | elastic p99 (%) | skin stretch p90 (%) | slid (cm) | limbs turned (deg) | walked out |\n|---|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for c in cases {
        match &c.stats {
            Some(s) => {
                // The waistband's stretch; none for a garment without elastic.
                let elastic = match s.elastic_strain_p99 {
                    0.0 => "-".to_string(),
                    e => format!("{:.1}", e * 100.0),
                };
                out += &format!(
                    concat!(
                        "| {} | {} | {} | {:.2} | {} | {} | {:.2} | {:.2} | {} | {:.1} | {:.1} | ",
                        "{:.0} | {} |\n"
                    ),
                    c.garment,
                    c.shape_seed,
                    c.pose,
                    s.wall_time_s,
                    s.animation_steps + s.settle_steps,
                    if s.converged { "yes" } else { "no" },
                    s.max_penetration_m * 1e3,
                    s.strain_p99 * 100.0,
                    elastic,
                    s.skin_stretch_p90 * 100.0,
                    s.slid_m * 100.0,
                    s.limb_turn_deg,
                    s.walked_out
                )
            }
            None => {
                out += &format!(
                    "| {} | {} | {} | failed: {} | | | | | | | | | |\n",
                    c.garment,
                    c.shape_seed,
                    c.pose,
                    c.failure.as_deref().unwrap_or("")
                )
            }
        }
    }
    let ok: Vec<&DrapeStats> = cases.iter().filter_map(|c| c.stats.as_ref()).collect();
    let worst = |f: fn(&DrapeStats) -> f32| ok.iter().map(|s| f(s)).fold(0.0, f32::max);
    out += &format!(
        "\n{} of {} drapes succeeded, {} at rest, {} of them with strain p99 under 2%; worst max penetration {:.2} mm, worst strain p99 {:.2}%, mean time {:.2} s\n",
        ok.len(),
        cases.len(),
        ok.iter().filter(|s| s.converged).count(),
        ok.iter()
            .filter(|s| s.converged && s.strain_p99 < 0.02)
            .count(),
        worst(|s| s.max_penetration_m) * 1e3,
        worst(|s| s.strain_p99) * 100.0,
        ok.iter().map(|s| s.wall_time_s).sum::<f64>() / ok.len().max(1) as f64
    );
    out
}
