//! The GarNet paper's error metrics and precision curves.
//!
//! - `E_dist`: mean over vertices of `||G_gt - G_pred||` (metres; [`m_to_cm`] for reports).
//! - `E_norm`: mean over faces of the angle between ground-truth and predicted face normals
//!   (radians; [`rad_to_deg`] for reports).
//!
//! Means are accumulated in f64. Inputs must have matching lengths and indices in range,
//! otherwise an [`GeomError::InvalidInput`] is returned.

use glam::Vec3;

use crate::error::{GeomError, Result};

/// Metres to centimetres.
pub fn m_to_cm(m: f32) -> f32 {
    m * 100.0
}

/// Radians to degrees.
pub fn rad_to_deg(r: f32) -> f32 {
    r.to_degrees()
}

fn check_pair(gt: &[Vec3], pred: &[Vec3]) -> Result<()> {
    if gt.len() != pred.len() {
        return Err(GeomError::InvalidInput(format!(
            "{} ground-truth vertices but {} predicted",
            gt.len(),
            pred.len()
        )));
    }
    Ok(())
}

fn mean(v: &[f32]) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64) as f32
}

/// Per-vertex distances `[N]` (metres) between `gt` and `pred` (`[N]` each).
pub fn vertex_distances(gt: &[Vec3], pred: &[Vec3]) -> Result<Vec<f32>> {
    check_pair(gt, pred)?;
    Ok(gt.iter().zip(pred).map(|(a, b)| a.distance(*b)).collect())
}

/// `E_dist`: mean per-vertex distance (metres); 0 for empty inputs.
pub fn e_dist(gt: &[Vec3], pred: &[Vec3]) -> Result<f32> {
    Ok(mean(&vertex_distances(gt, pred)?))
}

/// Angle (radians, in [0, pi]) between two face normals given unnormalised, via
/// `atan2(|a x b|, a . b)` (accurate for small angles). 0 when both are zero (degenerate),
/// pi/2 when only one is.
fn angle_between(a: Vec3, b: Vec3) -> f32 {
    let (za, zb) = (a == Vec3::ZERO, b == Vec3::ZERO);
    match (za, zb) {
        (true, true) => 0.0,
        (true, false) | (false, true) => std::f32::consts::FRAC_PI_2,
        _ => a.cross(b).length().atan2(a.dot(b)),
    }
}

/// Per-face normal angles `[F]` (radians) between the faces `[F]` over `gt` and over `pred`
/// (`[N]` each, same topology). A face degenerate in both counts 0, in one only pi/2.
pub fn face_normal_angles(gt: &[Vec3], pred: &[Vec3], faces: &[[u32; 3]]) -> Result<Vec<f32>> {
    check_pair(gt, pred)?;
    crate::adjacency::check_indices(gt.len(), faces)
        .map_err(|e| GeomError::InvalidInput(e.to_string()))?;
    let cross = |v: &[Vec3], f: &[u32; 3]| {
        let [a, b, c] = f.map(|i| v[i as usize]);
        // Normalise by the edge scale so tiny faces do not underflow to a zero cross product.
        let s = (b - a).length().max((c - a).length());
        if s == 0.0 {
            Vec3::ZERO
        } else {
            ((b - a) / s).cross((c - a) / s)
        }
    };
    Ok(faces
        .iter()
        .map(|f| angle_between(cross(gt, f), cross(pred, f)))
        .collect())
}

/// `E_norm`: mean face-normal angle (radians); 0 for no faces.
pub fn e_norm(gt: &[Vec3], pred: &[Vec3], faces: &[[u32; 3]]) -> Result<f32> {
    Ok(mean(&face_normal_angles(gt, pred, faces)?))
}

/// Report-ready errors of one predicted mesh.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeshErrors {
    /// Mean vertex distance, centimetres.
    pub e_dist_cm: f32,
    /// Mean face-normal angle, degrees.
    pub e_norm_deg: f32,
}

/// `E_dist` in cm and `E_norm` in degrees of `pred` against `gt` (`[N]` each) over `faces`.
pub fn mesh_errors(gt: &[Vec3], pred: &[Vec3], faces: &[[u32; 3]]) -> Result<MeshErrors> {
    Ok(MeshErrors {
        e_dist_cm: m_to_cm(e_dist(gt, pred)?),
        e_norm_deg: rad_to_deg(e_norm(gt, pred, faces)?),
    })
}

/// Precision curve: for each of `thresholds` (`[T]`, any order), the share in [0, 1] of
/// `values` (`[M]`) that are `<=` it. NaN values never count as under; with no values every
/// share is 0. O((M + T) log M).
pub fn precision_curve(values: &[f32], thresholds: &[f32]) -> Vec<f32> {
    let mut sorted: Vec<f32> = values.iter().copied().filter(|v| !v.is_nan()).collect();
    sorted.sort_unstable_by(f32::total_cmp);
    let n = values.len();
    thresholds
        .iter()
        .map(|&t| {
            if n == 0 {
                0.0
            } else {
                sorted.partition_point(|&v| v <= t) as f32 / n as f32
            }
        })
        .collect()
}

/// `count` evenly spaced thresholds from 0 to `max` inclusive (`[count]`), for precision
/// curves; empty when `count` is 0, `[max]` when 1.
pub fn linspace(max: f32, count: usize) -> Vec<f32> {
    match count {
        0 => Vec::new(),
        1 => vec![max],
        _ => (0..count)
            .map(|i| max * i as f32 / (count - 1) as f32)
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriMesh;

    #[test]
    fn distances_and_means() {
        let gt = vec![Vec3::ZERO, Vec3::X];
        let pred = vec![Vec3::new(0.0, 0.03, 0.04), Vec3::X];
        assert_eq!(vertex_distances(&gt, &pred).unwrap(), vec![0.05, 0.0]);
        assert!((e_dist(&gt, &pred).unwrap() - 0.025).abs() < 1e-7);
        assert!(e_dist(&gt, &pred[..1]).is_err());
        assert_eq!(e_dist(&[], &[]).unwrap(), 0.0);
        assert!((m_to_cm(0.025) - 2.5).abs() < 1e-6);
    }

    #[test]
    fn normal_angles() {
        let m = TriMesh::grid(3, 3, 0.1);
        assert!(e_norm(&m.vertices, &m.vertices, &m.faces).unwrap() < 1e-6);
        // Rotate the prediction 30 degrees about X: every face normal turns 30 degrees.
        let r = glam::Quat::from_rotation_x(30f32.to_radians());
        let pred: Vec<Vec3> = m.vertices.iter().map(|&v| r * v).collect();
        let e = rad_to_deg(e_norm(&m.vertices, &pred, &m.faces).unwrap());
        assert!((e - 30.0).abs() < 1e-3, "{e}");
        // Flipped faces: 180 degrees. Tiny faces still measure correctly.
        let flipped: Vec<Vec3> = m
            .vertices
            .iter()
            .map(|&v| Vec3::new(v.x, 0.0, -v.z))
            .collect();
        let a = face_normal_angles(&m.vertices, &flipped, &m.faces).unwrap();
        assert!(a.iter().all(|&x| (x - std::f32::consts::PI).abs() < 1e-5));
        let tiny: Vec<Vec3> = m.vertices.iter().map(|&v| v * 1e-20).collect();
        assert!(e_norm(&tiny, &m.vertices, &m.faces).unwrap() < 1e-5);
        // Degenerate prediction: pi/2.
        let collapsed = vec![Vec3::ZERO; m.vertices.len()];
        let a = face_normal_angles(&m.vertices, &collapsed, &m.faces).unwrap();
        assert!(a.iter().all(|&x| x == std::f32::consts::FRAC_PI_2));
        assert!(e_norm(&m.vertices, &m.vertices, &[[0, 1, 99]]).is_err());
        let me = mesh_errors(&m.vertices, &pred, &m.faces).unwrap();
        assert!((me.e_norm_deg - 30.0).abs() < 1e-3);
    }

    #[test]
    fn precision_curves() {
        let v = [0.5, 1.0, 2.0, f32::NAN];
        assert_eq!(
            precision_curve(&v, &[0.0, 0.5, 1.5, 10.0]),
            vec![0.0, 0.25, 0.5, 0.75]
        );
        assert_eq!(precision_curve(&[], &[1.0]), vec![0.0]);
        assert_eq!(linspace(2.0, 3), vec![0.0, 1.0, 2.0]);
        assert!(linspace(1.0, 0).is_empty());
    }
}
