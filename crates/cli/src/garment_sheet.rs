//! `garnet garment sheet`: the three templates, on the template body and warped onto
//! random shapes in several poses (surface anchors for the shape, then DQS), in one
//! picture.

use std::path::Path;

use anyhow::Context;
use body::pose::{Clip, KeyPose, RetargetOptions};
use body::{BodyModel, Pose, ShapedBody, Skinning};
use garment::warp::{warp_fitted, SurfaceAnchors};
use garment::{build_template, CutParams, GarmentKind};
use glam::Vec3;
use rayon::prelude::*;
use render::{palette, Framing, RenderMesh, RenderOptions, Sheet, View};

use crate::garment_cmd::garment_color;
use crate::output::create_parent;
use crate::shape_args::ShapeArgs;

/// Seeds of the random shapes shown.
const SHAPES: [u64; 3] = [11, 12, 13];
/// Names of the poses shown.
const POSES: [&str; 3] = ["walk", "arms raised", "sitting"];

/// Pose `which` of [`POSES`] for `body`.
fn sheet_pose(which: usize, body: &ShapedBody, walk: &Clip) -> anyhow::Result<Pose> {
    Ok(match which {
        0 => walk.pose(120, &body.rig, &RetargetOptions::default())?,
        1 => KeyPose::ArmsRaised.pose().to_pose(&body.rig),
        _ => KeyPose::Chair.pose().to_pose(&body.rig),
    })
}

pub fn write_sheet(model: &BodyModel, out: &Path, edge: f32, mocap: &Path) -> anyhow::Result<()> {
    let walk = Clip::from_asf_amc(mocap.join("02/02.asf"), mocap.join("02/02_01.amc"))
        .context("--mocap must hold the CMU subject 02")?;
    let kinds = [
        GarmentKind::Tshirt,
        GarmentKind::Sweater,
        GarmentKind::Jeans,
    ];
    let templates = kinds
        .par_iter()
        .map(|k| build_template(model, k, &CutParams::default_for(k), edge))
        .collect::<Result<Vec<_>, _>>()?;
    let bodies = SHAPES
        .iter()
        .map(|&seed| {
            let shape = ShapeArgs {
                random_shape: Some(seed),
                ..ShapeArgs::defaults()
            };
            Ok(model.shape(&shape.phenotype(model)?)?)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let template_body = model.shape(&templates[0].body_phenotype)?;
    let anchors = templates
        .iter()
        .map(|t| SurfaceAnchors::new(&t.mesh, &template_body.mesh))
        .collect::<Result<Vec<_>, _>>()?;
    let options = RenderOptions {
        framing: Framing::Bounds {
            min: Vec3::new(-0.9, -0.05, -0.9),
            max: Vec3::new(0.9, 2.05, 0.9),
        },
        ..RenderOptions::default()
    };
    // Cells: per garment, the template, then shapes x poses.
    let cells: Vec<(usize, Option<(usize, usize)>)> = (0..3)
        .flat_map(|g| {
            std::iter::once((g, None))
                .chain((0..3).flat_map(move |s| (0..3).map(move |p| (g, Some((s, p))))))
        })
        .collect();
    let images = cells
        .par_iter()
        .map(|&(g, case)| -> anyhow::Result<(render::Image, String)> {
            let t = &templates[g];
            let (body, garment, caption) = match case {
                None => (
                    template_body.mesh.clone(),
                    t.mesh.clone(),
                    format!("{} template", t.kind.name()),
                ),
                Some((s, p)) => {
                    let body = &bodies[s];
                    let pose = sheet_pose(p, body, &walk)?;
                    let caption = format!(
                        "shape {} ({:.0} cm), {}",
                        SHAPES[s],
                        body.height() * 100.0,
                        POSES[p]
                    );
                    (
                        body.posed(&pose, Skinning::Dqs)?,
                        warp_fitted(t, &anchors[g], body, &pose, Skinning::Dqs)?,
                        caption,
                    )
                }
            };
            let scene = [
                RenderMesh::new(&body.vertices, &body.faces, palette::SKIN),
                RenderMesh::new(&garment.vertices, &garment.faces, garment_color(&t.kind)),
            ];
            Ok((
                render::render_views_with(&scene, &[View::Front], (200, 300), &options)?,
                caption,
            ))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut sheet = Sheet::new(10).with_title(format!(
        "garnet garments: templates ({} cm edges), warped (anchors + DQS) onto random shapes",
        edge * 100.0
    ));
    for (image, caption) in images {
        sheet.push(image, caption);
    }
    create_parent(out)?;
    sheet
        .save_png(out)
        .with_context(|| format!("writing {}", out.display()))?;
    eprintln!("wrote {}", out.display());
    Ok(())
}
