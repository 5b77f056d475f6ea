//! Building a template: cut the body region, inflate it into cloth, remesh it to the
//! target edge length, and give it weights and UVs.

use body::{BodyModel, Phenotype};
use geom::bvh::Bvh;
use geom::remesh::{isotropic_remesh, RemeshOptions};

use crate::cut::{THIGH_PEAK, THIGH_SPAN};
use crate::inflate::{inflate, push_out, InflateOptions};
use crate::region::garment_region;
use crate::template::GarmentTemplate;
use crate::weights::weights_from_correspondence;
use crate::{CutParams, GarmentError, GarmentKind};

/// Smallest and largest target edge length accepted, metres.
pub const EDGE_RANGE: (f32, f32) = (0.004, 0.08);

/// Where along a sleeve or trouser leg (as a fraction of its cut length) the flare starts.
pub const FLARE_FROM: f32 = 0.25;

/// Builds the template of `kind` with `cut`, remeshed to edges of about `edge` metres
/// (1 cm gives about 10k vertices for the T-shirt), on the template body (the default
/// phenotype in rest pose).
pub fn build_template(
    model: &BodyModel,
    kind: &GarmentKind,
    cut: &CutParams,
    edge: f32,
) -> Result<GarmentTemplate, GarmentError> {
    cut.validate()?;
    if !(EDGE_RANGE.0..=EDGE_RANGE.1).contains(&edge) {
        return Err(GarmentError::Parameter(format!(
            "edge length {edge} m is outside [{}, {}] m",
            EDGE_RANGE.0, EDGE_RANGE.1
        )));
    }
    let body = model.shape(&Phenotype::default())?;
    let bvh = Bvh::from_mesh(&body.mesh)?;
    let mut region = garment_region(&body, kind, cut)?;
    let opts = InflateOptions::new(cut.ease, cut.bridge);
    let thigh = if *kind == GarmentKind::Jeans {
        cut.thigh
    } else {
        0.0
    };
    let extra: Vec<f32> = region
        .along_limb
        .iter()
        .map(|&t| {
            let flare = cut.flare * ((t - FLARE_FROM) / (1.0 - FLARE_FROM)).clamp(0.0, 1.0);
            flare + thigh * (1.0 - (t - THIGH_PEAK).abs() / THIGH_SPAN).max(0.0)
        })
        .collect();
    inflate(&mut region.mesh, &extra, &bvh, &opts)?;
    let remeshed = isotropic_remesh(&region.mesh, &RemeshOptions::new(edge))?;
    let mut mesh = remeshed.mesh;
    push_out(&mut mesh.vertices, &bvh, opts.min_gap);
    let weights = weights_from_correspondence(
        &body,
        &region.mesh.faces,
        &region.body_vertex,
        &remeshed.source_face,
        &remeshed.source_bary,
    )?;
    GarmentTemplate::assemble(kind.clone(), Some(*cut), edge, mesh, weights, body)
}
