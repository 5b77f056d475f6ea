//! Warping a template onto any body: M = DQS(template, template joints, target joints,
//! weights), the GarNet paper's initial garment (and LBS for comparison).

use body::{Pose, RigidTransform, ShapedBody, Skinning};
use geom::TriMesh;

use crate::template::GarmentTemplate;
use crate::GarmentError;

/// Per-bone transforms `[B]` taking the template body's rest bones onto `target`'s
/// bones in `pose`: first rest to rest (shape change: each bone's frame and head move
/// to the target's), then the target's forward kinematics.
pub fn bone_transforms(
    template: &GarmentTemplate,
    target: &ShapedBody,
    pose: &Pose,
) -> Result<Vec<RigidTransform>, GarmentError> {
    check_target(template, target, pose)?;
    let (from, to) = (&template.rig, &target.rig);
    let posed = to.skinning_transforms(pose);
    Ok(from
        .bones
        .iter()
        .zip(&to.bones)
        .zip(&posed)
        .map(|((a, b), s)| {
            let rest_rotation = b.frame * a.frame.inverse();
            let rest_translation = b.head - rest_rotation * a.head;
            RigidTransform {
                rotation: (s.rotation * rest_rotation).normalize(),
                translation: s.rotation * rest_translation + s.translation,
            }
        })
        .collect())
}

/// Checks that `target`'s rig is the template's and that `pose` fits it and is finite.
fn check_target(
    template: &GarmentTemplate,
    target: &ShapedBody,
    pose: &Pose,
) -> Result<(), GarmentError> {
    let (from, to) = (&template.rig, &target.rig);
    if from.len() != to.len()
        || from
            .bones
            .iter()
            .zip(&to.bones)
            .any(|(a, b)| a.name != b.name)
    {
        return Err(GarmentError::Parameter(
            "the target body's rig does not match the template's".into(),
        ));
    }
    if pose.rotations.len() != to.len() {
        return Err(GarmentError::Parameter(format!(
            "pose has {} rotations, the rig {} bones",
            pose.rotations.len(),
            to.len()
        )));
    }
    if !pose.root_translation.is_finite() || pose.rotations.iter().any(|q| !q.is_finite()) {
        return Err(GarmentError::Parameter(
            "pose contains NaN or infinite values".into(),
        ));
    }
    Ok(())
}

/// The template skinned onto `target` in `pose` (`[N]` vertices, the template's faces).
pub fn warp(
    template: &GarmentTemplate,
    target: &ShapedBody,
    pose: &Pose,
    method: Skinning,
) -> Result<TriMesh, GarmentError> {
    let transforms = bone_transforms(template, target, pose)?;
    Ok(TriMesh {
        vertices: template
            .weights
            .apply(&template.mesh.vertices, &transforms, method),
        faces: template.mesh.faces.clone(),
    })
}

/// Where each garment vertex sits relative to the template body's surface: its closest
/// body face, the barycentric point on it, and its offset in that point's local frame
/// (tangent, bitangent, smooth normal). Placing a garment by its anchors on another
/// body shape carries it over girth and proportion changes with the same ease, which
/// joint-driven skinning alone cannot do.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceAnchors {
    face: Vec<u32>,
    bary: Vec<[f32; 3]>,
    local: Vec<glam::Vec3>,
}

/// Local frame `[tangent, bitangent, normal]` and origin at a barycentric point of a body
/// face, with the normal interpolated from vertex normals `normals`.
fn surface_frame(
    body: &TriMesh,
    normals: &[glam::Vec3],
    face: u32,
    bary: [f32; 3],
) -> (glam::Vec3, glam::Mat3) {
    let f = body.faces[face as usize].map(|i| i as usize);
    let p = f.map(|i| body.vertices[i]);
    let origin = p[0] * bary[0] + p[1] * bary[1] + p[2] * bary[2];
    let n = (normals[f[0]] * bary[0] + normals[f[1]] * bary[1] + normals[f[2]] * bary[2])
        .normalize_or(glam::Vec3::Y);
    let e = p[1] - p[0];
    let t = (e - n * n.dot(e)).normalize_or(n.any_orthonormal_vector());
    (origin, glam::Mat3::from_cols(t, n.cross(t), n))
}

impl SurfaceAnchors {
    /// Anchors of `garment` (rest pose) on `template_body` (the body it is fitted on,
    /// same pose), by closest points.
    pub fn new(garment: &TriMesh, template_body: &TriMesh) -> Result<Self, GarmentError> {
        use rayon::prelude::*;
        let bvh = geom::bvh::Bvh::from_mesh(template_body)?;
        let normals = geom::normals::vertex_normals(&template_body.vertices, &template_body.faces);
        let anchored: Vec<(u32, [f32; 3], glam::Vec3)> = garment
            .vertices
            .par_iter()
            .map(|&g| {
                let hit = bvh.closest_point(g).expect("non-empty body");
                let (origin, frame) = surface_frame(template_body, &normals, hit.face, hit.bary);
                (hit.face, hit.bary, frame.transpose() * (g - origin))
            })
            .collect();
        Ok(Self {
            face: anchored.iter().map(|a| a.0).collect(),
            bary: anchored.iter().map(|a| a.1).collect(),
            local: anchored.iter().map(|a| a.2).collect(),
        })
    }

    /// The garment's vertices `[N]` placed on `body`, a mesh with the template body's
    /// topology (another shape, or the same shape posed).
    pub fn place(&self, body: &TriMesh) -> Vec<glam::Vec3> {
        let normals = geom::normals::vertex_normals(&body.vertices, &body.faces);
        self.face
            .iter()
            .zip(&self.bary)
            .zip(&self.local)
            .map(|((&f, &b), &l)| {
                let (origin, frame) = surface_frame(body, &normals, f, b);
                origin + frame * l
            })
            .collect()
    }
}

/// The template carried onto `target`'s rest shape by its surface anchors, then skinned
/// into `pose` with the target's own joints. Unlike [`warp`] (the paper's M, driven by
/// joints only) it follows girth and proportion changes of the body.
pub fn warp_fitted(
    template: &GarmentTemplate,
    anchors: &SurfaceAnchors,
    target: &ShapedBody,
    pose: &Pose,
    method: Skinning,
) -> Result<TriMesh, GarmentError> {
    check_target(template, target, pose)?;
    if anchors.face.len() != template.mesh.vertices.len()
        || anchors
            .face
            .iter()
            .any(|&f| f as usize >= target.mesh.faces.len())
    {
        return Err(GarmentError::Parameter(
            "surface anchors do not belong to this template and body".into(),
        ));
    }
    let rest = anchors.place(&target.mesh);
    let transforms = target.rig.skinning_transforms(pose);
    Ok(TriMesh {
        vertices: template.weights.apply(&rest, &transforms, method),
        faces: template.mesh.faces.clone(),
    })
}
