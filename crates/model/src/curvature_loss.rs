//! L_curv, the curvature term of GarNet++ (Gundogdu et al., 2020), which sharpens folds: it
//! compares how the prediction and its label spread about each vertex, along the label's
//! principal axes of that spread.
//!
//! For vertex i with neighbourhood N_i (i and its 1-ring, weights `w_ik = 1/|N_i|`):
//!
//! ```text
//! C_i = sum_k w_ik (x_k - xbar_i)(x_k - xbar_i)^T          (the local covariance, m^2)
//! R_ij(C) = e_ij^T C e_ij                                  (its Rayleigh quotient on e_ij)
//! L_curv = 1/(3N) sum_i sum_j | sqrt R_ij(C^P_i) - sqrt R_ij(C^G_i) |
//! ```
//!
//! with `e_ij` (j = 1..3) the unit eigenvectors of the label's `C^G_i`, so `R_ij(C^G_i)` are
//! its eigenvalues. The axis of least spread is the label's surface normal there: its
//! `sqrt R` is how far the neighbourhood bends out of its plane, which a fold makes
//! centimetres and a flat patch nothing. GarNet++ compares the quotients themselves (square
//! metres); garnet compares their square roots, standard deviations in the loss's unit
//! (centimetres, like L_vertex's distance and the tilt L_norm), whose gradient stays bounded
//! (it is the gradient of a weighted norm) and whose scale does not grow with the square of
//! the neighbourhood's size.
//!
//! The label's axes are worked out on the CPU (faer's symmetric eigendecomposition of a 3x3
//! matrix per vertex) and enter as constants: the gradient flows through the prediction only.

use burn::prelude::*;
use faer::{Mat, Side};
use glam::Vec3;

use crate::error::{ModelError, Result};
use crate::feast_rows::HostRing;
use crate::tensors::{gather_rows, vec_tensor};
use crate::topology::TopologyTensors;

/// Added to a variance before its square root (square metres): keeps the gradient finite
/// where a neighbourhood has no spread along an axis; changes a 1 mm deviation by 5e-7 m.
const VAR_EPS: f64 = 1e-12;

/// The labels' principal axes and their spread along them, from one eigendecomposition.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelAxes {
    /// `[B*N*9]` unit axes, row-major as `[B,N,3,3]` (row j of vertex i's block is its j-th
    /// axis `e_ij`).
    pub axes: Vec<f32>,
    /// `[B*N*3]` the label's standard deviation along each axis, `sqrt(lambda_ij + eps)`
    /// (metres), as `[B,N,1,3]`.
    pub spread: Vec<f32>,
}

/// The principal axes of every label's neighbourhoods and the label's spread along them.
/// `targets` `[B][N]` metres; `ring` the template's neighbourhoods. Fails when a target has
/// not N vertices or a neighbourhood's covariance has no eigendecomposition (a non-finite
/// label).
pub fn principal_axes(targets: &[Vec<Vec3>], ring: &HostRing) -> Result<LabelAxes> {
    let k = ring.k;
    let n = ring.ring.len() / k.max(1);
    let mut axes = Vec::with_capacity(targets.len() * n * 9);
    let mut spread = Vec::with_capacity(targets.len() * n * 3);
    for target in targets {
        if target.len() != n {
            return Err(ModelError::InvalidInput(format!(
                "L_curv: a label has {} vertices, the garment {n}",
                target.len()
            )));
        }
        for i in 0..n {
            let row = &ring.ring[i * k..(i + 1) * k];
            let w = &ring.weight[i * k..(i + 1) * k];
            let mean: glam::DVec3 = row
                .iter()
                .zip(w)
                .map(|(&j, &wj)| target[j as usize].as_dvec3() * wj as f64)
                .sum();
            let mut c = [[0.0f64; 3]; 3];
            for (&j, &wj) in row.iter().zip(w) {
                let d = target[j as usize].as_dvec3() - mean;
                let d = [d.x, d.y, d.z];
                for (a, ca) in c.iter_mut().enumerate() {
                    for (b, cab) in ca.iter_mut().enumerate() {
                        *cab += wj as f64 * d[a] * d[b];
                    }
                }
            }
            let cov = Mat::<f64>::from_fn(3, 3, |a, b| c[a][b]);
            let eig = cov.self_adjoint_eigen(Side::Lower).map_err(|e| {
                ModelError::InvalidInput(format!(
                    "L_curv: no principal axes at label vertex {i} ({e:?})"
                ))
            })?;
            let (u, lambda) = (eig.U(), eig.S().column_vector());
            for j in 0..3 {
                for a in 0..3 {
                    axes.push(u[(a, j)] as f32);
                }
                spread.push((lambda[j].max(0.0) + VAR_EPS).sqrt() as f32);
            }
        }
    }
    Ok(LabelAxes { axes, spread })
}

/// The standard deviations `[B,N,1,3]` of each neighbourhood of `v` `[B,N,3]` (metres)
/// along `axes` `[B,N,3,3]` (rows unit axes): `sqrt(R_ij + eps)`.
fn spread_along(v: Tensor<3>, axes: Tensor<4>, topo: &TopologyTensors) -> Tensor<4> {
    let [b, n, _] = v.dims();
    let k = topo.ring_width;
    let x = gather_rows(v, &topo.ring).reshape([b, n, k, 3]);
    let w = topo.ring_weight.clone();
    let mean = (x.clone() * w.clone()).sum_dim(2);
    let centred = x - mean;
    let along = centred.matmul(axes.swap_dims(2, 3)); // [B,N,K,3]
    ((along.square() * w).sum_dim(2) + VAR_EPS).sqrt()
}

/// L_curv (module docs), metres: `pred` `[B,N,3]` metres, `targets` its labels on the host
/// (`[B][N]`), whose spread comes with their axes from [`principal_axes`].
pub fn curvature_loss(
    pred: Tensor<3>,
    targets: &[Vec<Vec3>],
    topo: &TopologyTensors,
) -> Result<Tensor<1>> {
    let [b, n, _] = pred.dims();
    let label = principal_axes(targets, &topo.host_ring)?;
    let device = pred.device();
    let axes = vec_tensor(label.axes, [b, n, 3, 3], &device);
    let sg = vec_tensor(label.spread, [b, n, 1, 3], &device);
    Ok((spread_along(pred, axes, topo) - sg).abs().mean())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tensors::{points_tensor, read_scalar};
    use crate::topology::GarmentTopology;

    /// A 5x5 grid, 1 cm apart, in the y = 0 plane, and the same grid folded: a round ridge
    /// along x, `h` high (along y) at the middle row and none at the edges.
    fn grids(h: f32) -> (geom::TriMesh, Vec<Vec3>) {
        let mesh = geom::TriMesh::grid(5, 5, 0.01);
        let folded = mesh
            .vertices
            .iter()
            .map(|p| *p + Vec3::Y * (h * (p.z / 0.04 * std::f32::consts::PI).cos()))
            .collect();
        (mesh, folded)
    }

    fn loss(pred: &[Vec3], target: &[Vec3], topo: &GarmentTopology) -> f32 {
        let device = Device::flex();
        let tt = topo.to_device(&device);
        let l = curvature_loss(points_tensor(&[pred], &device), &[target.to_vec()], &tt).unwrap();
        read_scalar(l).unwrap()
    }

    #[test]
    fn a_prediction_that_misses_a_fold_costs_and_a_moved_copy_does_not() {
        let (mesh, folded) = grids(0.01);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        // The fold moved 5 cm: the spread about each vertex is unchanged.
        let moved: Vec<Vec3> = folded
            .iter()
            .map(|p| *p + Vec3::new(0.05, -0.02, 0.03))
            .collect();
        assert!(loss(&moved, &folded, &topo) < 1e-5);
        // The flat grid against the folded label: the ridge's out-of-plane spread is missed.
        let flat = loss(&mesh.vertices, &folded, &topo);
        assert!(flat > 5e-4, "{flat}");
        // A deeper miss costs more, and a scaled fold (2 cm ridge) sits between.
        let (_, deep) = grids(0.02);
        assert!(loss(&mesh.vertices, &deep, &topo) > 1.5 * flat);
        assert!(loss(&deep, &folded, &topo) > 0.5 * flat);
    }

    #[test]
    fn the_vertex_spread_matches_a_hand_computed_value() {
        // A vertex of a flat fan of four neighbours at 1 cm (0, +-x, +-y) and its label lifted
        // at the centre by 1 cm: along z the label's deviations are (0.8, -0.2 x4) cm from
        // their mean 0.2: variance (0.64 + 4 * 0.04) / 5 = 0.16 cm^2, deviation 0.4 cm. The
        // flat prediction has none along z; in the plane both spread equally.
        let p = vec![
            Vec3::ZERO,
            Vec3::new(0.01, 0.0, 0.0),
            Vec3::new(0.0, 0.01, 0.0),
            Vec3::new(-0.01, 0.0, 0.0),
            Vec3::new(0.0, -0.01, 0.0),
        ];
        let mesh = geom::TriMesh::new(p.clone(), vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]]);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let mut label = p.clone();
        label[0].z = 0.01;
        let device = Device::flex();
        let tt = topo.to_device(&device);
        let LabelAxes { axes, spread: sg } =
            principal_axes(&[label.clone()], &tt.host_ring).unwrap();
        // Vertex 0's least-spread axis (faer sorts eigenvalues up: the first) is +-z.
        assert!((axes[2].abs() - 1.0).abs() < 1e-5, "{:?}", &axes[..9]);
        let along = |v: &[Vec3]| {
            let t = spread_along(
                points_tensor(&[v], &device),
                vec_tensor(axes.clone(), [1, 5, 3, 3], &device),
                &tt,
            );
            crate::tensors::read_f32(t).unwrap()
        };
        let sp = along(&p);
        // The label's spread from its eigenvalues is its spread measured along its axes.
        let measured = along(&label);
        assert!(
            sg.iter().zip(&measured).all(|(a, b)| (a - b).abs() < 1e-6),
            "{sg:?} {measured:?}"
        );
        assert!(
            sp[0] < 2e-6 && (sg[0] - 0.004).abs() < 1e-6,
            "{sp:?} {sg:?}"
        );
        assert!((sp[1] - sg[1]).abs() < 1e-6 && (sp[2] - sg[2]).abs() < 1e-6);
    }

    #[test]
    fn a_label_of_the_wrong_size_is_refused() {
        let (mesh, folded) = grids(0.01);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let tt = topo.to_device(&Device::flex());
        assert!(principal_axes(&[folded[..10].to_vec()], &tt.host_ring).is_err());
    }
}
