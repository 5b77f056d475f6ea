//! The region of the template body a garment covers, cut by its cut parameters.
//!
//! Vertices are classified by their heaviest bone's body segment (torso, upper arm,
//! forearm, thigh, shin). Tops keep the torso between the hem plane and the neckline and
//! each arm up to the sleeve length measured along the arm's bones; jeans keep the torso
//! below the waistband and each leg up to the leg length along the leg's bones. Faces
//! with all three vertices kept form the region; small enclosed gaps are filled so that
//! the only openings are the garment's own.

use body::self_contact::vertex_segments;
use body::ShapedBody;
use geom::TriMesh;
use glam::Vec3;

use crate::{CutParams, GarmentError, GarmentKind};

/// A part of a body mesh: its faces re-indexed onto its own vertices.
#[derive(Clone, Debug)]
pub struct Region {
    /// The region as a mesh (vertices copied from the body, metres).
    pub mesh: TriMesh,
    /// `[n]` body vertex index of every region vertex.
    pub body_vertex: Vec<u32>,
    /// `[n]` how far along its sleeve or trouser leg each region vertex lies, as a fraction
    /// of the cut's sleeve or leg length (0 on the torso, 1 at the opening).
    pub along_limb: Vec<f32>,
}

/// A bone as its head and tail, metres.
type BoneLine = (Vec3, Vec3);

/// Enclosed gaps smaller than this many faces are filled.
const MAX_GAP_FACES: usize = 400;

/// Distance of `p` along a two-bone limb chain from the first bone's head (metres):
/// along the first bone for points of the upper segment, then along the second.
fn along_chain(p: Vec3, upper: (Vec3, Vec3), lower: (Vec3, Vec3), on_lower: bool) -> f32 {
    let (h0, t0) = upper;
    let len0 = (t0 - h0).length();
    if on_lower {
        let (h1, t1) = lower;
        len0 + (p - h1).dot((t1 - h1).normalize())
    } else {
        (p - h0).dot((t0 - h0) / len0)
    }
}

/// For every body vertex (`[V]`): `None` where the garment does not cover it, else how far
/// along the sleeve or trouser leg it lies as a fraction of the cut's sleeve or leg length
/// (0 on the torso, 1 at the opening).
fn coverage(
    body: &ShapedBody,
    kind: &GarmentKind,
    cut: &CutParams,
) -> Result<Vec<Option<f32>>, GarmentError> {
    let rig = &body.rig;
    let bone = |name: &str| -> Result<BoneLine, GarmentError> {
        let b = rig
            .index(name)
            .ok_or_else(|| GarmentError::Parameter(format!("the rig has no bone {name}")))?;
        Ok((rig.bones[b].head, rig.bones[b].tail))
    };
    let seg = vertex_segments(body);
    let is_hand: Vec<bool> = rig
        .bones
        .iter()
        .map(|b| b.name.contains("Hand") || b.name.contains("Finger") || b.name.contains("Thumb"))
        .collect();
    let v = &body.mesh.vertices;
    // The fraction along the limb of a vertex on limb segment `s` within `length`.
    let along = |p: Vec3, s: u8, chains: &[(BoneLine, BoneLine, u8, u8)], length: f32| {
        chains.iter().find_map(|&(up, low, su, sl)| {
            let d = along_chain(p, up, low, s == sl);
            ((s == su || s == sl) && d <= length).then(|| (d / length).max(0.0))
        })
    };
    let keep: Vec<Option<f32>> = match kind {
        GarmentKind::Tshirt | GarmentKind::Sweater => {
            let neck = bone("Neck")?.0;
            let hem = neck.y - cut.body_length;
            let crotch = bone("LeftUpLeg")?.0.y - 0.08;
            if hem < crotch {
                return Err(GarmentError::Parameter(format!(
                    "body_length {} m reaches below the crotch of the template body",
                    cut.body_length
                )));
            }
            let arms = [
                (bone("LeftArm")?, bone("LeftForeArm")?, 1u8, 2u8),
                (bone("RightArm")?, bone("RightForeArm")?, 3, 4),
            ];
            (0..v.len())
                .map(|i| {
                    let (p, s) = (v[i], seg[i]);
                    let front = ((p.z - neck.z) / 0.05).clamp(0.0, 1.0);
                    let below_neckline = p.y < neck.y + 0.01 - cut.neckline_depth * front;
                    match s {
                        0 | 5 | 7 => (p.y >= hem && below_neckline).then_some(0.0),
                        _ if is_hand[body.weights.heaviest(i)] || p.y < hem => None,
                        _ => along(p, s, &arms, cut.sleeve_length),
                    }
                })
                .collect()
        }
        GarmentKind::Jeans => {
            let waist = bone("Hips")?.0.y + cut.waist_height;
            let legs = [
                (bone("LeftUpLeg")?, bone("LeftLeg")?, 5u8, 6u8),
                (bone("RightUpLeg")?, bone("RightLeg")?, 7, 8),
            ];
            (0..v.len())
                .map(|i| {
                    let (p, s) = (v[i], seg[i]);
                    match s {
                        0 => (p.y <= waist).then_some(0.0),
                        _ if (1..=4).contains(&s) || p.y > waist => None,
                        _ => along(p, s, &legs, cut.leg_length),
                    }
                })
                .collect()
        }
        GarmentKind::Custom(name) => {
            return Err(GarmentError::Parameter(format!(
                "'{name}' is imported, not cut from the body"
            )));
        }
    };
    Ok(keep)
}

/// The region of `body` covered by a garment: covered faces, enclosed gaps filled.
/// Errors if the result does not have the kind's number of openings.
pub fn garment_region(
    body: &ShapedBody,
    kind: &GarmentKind,
    cut: &CutParams,
) -> Result<Region, GarmentError> {
    let cover = coverage(body, kind, cut)?;
    let faces = &body.mesh.faces;
    let mut in_region: Vec<bool> = faces
        .iter()
        .map(|f| f.iter().all(|&i| cover[i as usize].is_some()))
        .collect();
    fill_small_gaps(faces, body.mesh.vertices.len(), &mut in_region)?;
    let region = extract(&body.mesh, &in_region, &cover);
    let loops = geom::adjacency::boundary_loops(region.mesh.vertices.len(), &region.mesh.faces)?;
    if let Some(expected) = kind.openings() {
        if loops.len() != expected {
            return Err(GarmentError::rejected(
                format!("{} region", kind.name()),
                format!(
                    "has {} openings, expected {expected}: adjust the cut parameters",
                    loops.len()
                ),
            ));
        }
    }
    Ok(region)
}

/// Adds to the region every connected group of excluded faces smaller than
/// [`MAX_GAP_FACES`] (holes left where the covered set is not convex).
fn fill_small_gaps(
    faces: &[[u32; 3]],
    n: usize,
    in_region: &mut [bool],
) -> Result<(), GarmentError> {
    let topo = geom::adjacency::EdgeTopology::new(n, faces)?;
    let mut seen = vec![false; faces.len()];
    for start in 0..faces.len() {
        if in_region[start] || seen[start] {
            continue;
        }
        let mut group = vec![start];
        seen[start] = true;
        let mut k = 0;
        while k < group.len() {
            let f = group[k];
            k += 1;
            for &e in &topo.face_edges[f] {
                for &g in topo.faces_of(e as usize) {
                    let g = g as usize;
                    if !in_region[g] && !seen[g] {
                        seen[g] = true;
                        group.push(g);
                    }
                }
            }
        }
        if group.len() < MAX_GAP_FACES {
            for f in group {
                in_region[f] = true;
            }
        }
    }
    Ok(())
}

/// The sub-mesh of `mesh` made of the faces flagged in `in_region`, compacted; each vertex
/// takes its fraction along the limb from `cover` (0 where uncovered: filled gaps).
fn extract(mesh: &TriMesh, in_region: &[bool], cover: &[Option<f32>]) -> Region {
    let mut map = vec![u32::MAX; mesh.vertices.len()];
    let mut body_vertex = Vec::new();
    let mut faces = Vec::new();
    for (f, _) in mesh.faces.iter().zip(in_region).filter(|(_, keep)| **keep) {
        faces.push(f.map(|i| {
            if map[i as usize] == u32::MAX {
                map[i as usize] = body_vertex.len() as u32;
                body_vertex.push(i);
            }
            map[i as usize]
        }));
    }
    let vertices = body_vertex
        .iter()
        .map(|&i| mesh.vertices[i as usize])
        .collect();
    Region {
        mesh: TriMesh { vertices, faces },
        along_limb: body_vertex
            .iter()
            .map(|&i| cover[i as usize].unwrap_or(0.0))
            .collect(),
        body_vertex,
    }
}
