//! Importing a user's garment mesh as a template: checks, then weights and UVs.

use body::{BodyModel, Phenotype};
use geom::bvh::Bvh;
use geom::TriMesh;
use rayon::prelude::*;

use crate::template::GarmentTemplate;
use crate::weights::transfer_weights;
use crate::{GarmentError, GarmentKind};

/// Limits of the checks an imported garment must pass.
#[derive(Clone, Copy, Debug)]
pub struct ImportLimits {
    /// Largest share of vertices allowed inside the template body.
    pub max_inside_share: f32,
    /// Largest mean distance from the garment's vertices to the body surface, metres.
    pub max_mean_gap: f32,
    /// Smallest and largest extent of the garment's bounding box, metres.
    pub extent: (f32, f32),
    /// Largest number of vertices.
    pub max_vertices: usize,
}

impl Default for ImportLimits {
    fn default() -> Self {
        Self {
            max_inside_share: 0.01,
            max_mean_gap: 0.10,
            extent: (0.1, 2.5),
            max_vertices: 200_000,
        }
    }
}

/// Checks `mesh` fits the template body (rest pose, default phenotype) as a garment and
/// makes a template of it named `name`: weights transferred from the body, UVs by body
/// part. Refuses, with the reason, a mesh with NaN or bad indices, a non-manifold or
/// inconsistently oriented mesh, an implausible size, one inside the body or far from it.
pub fn import_garment(
    mesh: TriMesh,
    name: &str,
    model: &BodyModel,
    limits: &ImportLimits,
) -> Result<GarmentTemplate, GarmentError> {
    let reject = |reason: String| GarmentError::rejected(format!("garment '{name}'"), reason);
    mesh.validate().map_err(|e| reject(e.to_string()))?;
    if mesh.faces.is_empty() || mesh.vertices.len() > limits.max_vertices {
        return Err(reject(format!(
            "has {} vertices and {} faces",
            mesh.vertices.len(),
            mesh.faces.len()
        )));
    }
    let (lo, hi) = mesh.bounds().expect("non-empty mesh");
    let extent = (hi - lo).max_element();
    if extent < limits.extent.0 || extent > limits.extent.1 {
        return Err(reject(format!(
            "is {:.0} cm across; a garment is {:.0} to {:.0} cm (is the mesh in metres?)",
            extent * 100.0,
            limits.extent.0 * 100.0,
            limits.extent.1 * 100.0
        )));
    }
    let report = geom::adjacency::check_manifold(mesh.vertices.len(), &mesh.faces)?;
    if !report.is_ok() {
        return Err(reject(format!(
            "is not a manifold, consistently oriented surface: {report}"
        )));
    }
    let body = model.shape(&Phenotype::default())?;
    let bvh = Bvh::from_mesh(&body.mesh)?;
    let inside = mesh
        .vertices
        .par_iter()
        .filter(|p| bvh.contains(**p))
        .count();
    let share = inside as f32 / mesh.vertices.len() as f32;
    if share > limits.max_inside_share {
        return Err(reject(format!(
            "has {:.1}% of its vertices inside the template body",
            share * 100.0
        )));
    }
    let mean_gap = mesh
        .vertices
        .par_iter()
        .map(|p| bvh.closest_point(*p).map_or(f32::INFINITY, |h| h.distance))
        .sum::<f32>()
        / mesh.vertices.len() as f32;
    if mean_gap > limits.max_mean_gap {
        return Err(reject(format!(
            "is far from the template body (mean gap {:.1} cm, at most {:.1} cm): fit it on the rest-pose template body",
            mean_gap * 100.0,
            limits.max_mean_gap * 100.0
        )));
    }
    let weights = transfer_weights(&mesh, &body, &bvh, 3)?;
    let edge_length = mesh.mean_edge_length();
    GarmentTemplate::assemble(
        GarmentKind::Custom(name.to_string()),
        None,
        edge_length,
        mesh,
        weights,
        body,
    )
}
