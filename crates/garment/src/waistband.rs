//! The waistband of a garment worn on the hips: the band of cloth along its top opening,
//! which a simulator makes elastic and cuts to a smaller girth so that it holds the garment
//! up.

use crate::{GarmentError, GarmentKind, GarmentTemplate};

/// `[N]` whether each vertex of `template` (in its rest pose) lies in the waistband: at most
/// `width` metres below the mean height of the waist opening. `None` for a garment without
/// one (tops, imported garments). The jeans' waist is cut by a horizontal plane, so its
/// opening is level and the band is the strip of cloth below it.
pub fn waistband(
    template: &GarmentTemplate,
    width: f32,
) -> Result<Option<Vec<bool>>, GarmentError> {
    if template.kind != GarmentKind::Jeans {
        return Ok(None);
    }
    let v = &template.mesh.vertices;
    let loops = geom::adjacency::boundary_loops(v.len(), &template.mesh.faces)?;
    let mean_height =
        |l: &Vec<u32>| l.iter().map(|&i| v[i as usize].y).sum::<f32>() / l.len() as f32;
    let top = loops
        .iter()
        .filter(|l| !l.is_empty())
        .map(mean_height)
        .fold(f32::NEG_INFINITY, f32::max);
    if !top.is_finite() {
        return Err(GarmentError::rejected(
            "jeans template",
            "has no opening to put a waistband on",
        ));
    }
    Ok(Some(v.iter().map(|p| p.y >= top - width).collect()))
}
