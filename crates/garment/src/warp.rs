//! Warping a template onto any body: M = DQS(template, template joints, target joints,
//! weights), the GarNet paper's initial garment (and LBS for comparison).

use body::{Pose, RigidTransform, ShapedBody, Skinning};
use geom::TriMesh;

use crate::template::GarmentTemplate;
use crate::GarmentError;

/// Per-bone transforms `[B]` taking the template body's rest bones onto `target`'s
/// bones in `pose`: first rest to rest (shape change: each bone's frame and head move
/// to the target's), then the target's forward kinematics.
pub fn bone_transforms(template: &GarmentTemplate, target: &ShapedBody, pose: &Pose) -> Result<Vec<RigidTransform>, GarmentError> {
    let (from, to) = (&template.rig, &target.rig);
    if from.len() != to.len() || from.bones.iter().zip(&to.bones).any(|(a, b)| a.name != b.name) {
        return Err(GarmentError::Parameter("the target body's rig does not match the template's".into()));
    }
    if pose.rotations.len() != to.len() {
        return Err(GarmentError::Parameter(format!("pose has {} rotations, the rig {} bones", pose.rotations.len(), to.len())));
    }
    if !pose.root_translation.is_finite() || pose.rotations.iter().any(|q| !q.is_finite()) {
        return Err(GarmentError::Parameter("pose contains NaN or infinite values".into()));
    }
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

/// The template skinned onto `target` in `pose` (`[N]` vertices, the template's faces).
pub fn warp(template: &GarmentTemplate, target: &ShapedBody, pose: &Pose, method: Skinning) -> Result<TriMesh, GarmentError> {
    let transforms = bone_transforms(template, target, pose)?;
    Ok(TriMesh {
        vertices: template.weights.apply(&template.mesh.vertices, &transforms, method),
        faces: template.mesh.faces.clone(),
    })
}
