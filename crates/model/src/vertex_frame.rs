//! Each garment vertex's own frame: the rotation that carries the template's neighbourhood of
//! the vertex onto the warped garment M's (an input of networks with
//! [`crate::GarNetConfig::vertex_frames`]).
//!
//! M is the template skinned into the pose, so near each vertex it is the template turned by
//! the blend of the bones that move it. A network that predicts a vertex's translation in
//! the world (or the canonical frame, turned only about gravity) must learn a sleeve's
//! offset again for every arm orientation; in the vertex's frame the same fold is the same
//! output. The rotation is the best rigid fit of the vertex's 1-ring edges (and its normal)
//! from the template onto M: the rotation factor of the polar decomposition of
//! `H = sum_j e^M_j (e^R_j)^T + s^2 n^M (n^R)^T`, `s^2` the mean squared edge length.

use glam::{Mat3, Vec3};

use crate::error::{check_count, Result};

/// Newton iterations of the polar decomposition; each at least halves the distance to the
/// rotation once near it (quadratic convergence), 12 reach f32 precision from any `H` whose
/// singular values are within 1e4 of each other.
const POLAR_ITERATIONS: usize = 12;

/// The template's neighbourhoods, from which each sample's vertex frames are fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexFrames {
    rest: Vec<Vec3>,
    rest_normals: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
    ring: geom::adjacency::Csr,
}

impl VertexFrames {
    /// The frames of garment template `mesh` (metres). Fails on a face index out of range.
    pub fn new(mesh: &geom::TriMesh) -> Result<VertexFrames> {
        let ring = geom::adjacency::one_ring(mesh.num_vertices(), &mesh.faces)?;
        Ok(VertexFrames {
            rest: mesh.vertices.clone(),
            rest_normals: geom::normals::vertex_normals(&mesh.vertices, &mesh.faces),
            faces: mesh.faces.clone(),
            ring,
        })
    }

    /// Per vertex, the rotation `[N]` carrying the template's neighbourhood onto that of
    /// `warped` `[N]` (metres, any frame; the rotation is from the template's frame to
    /// `warped`'s). Fails when `warped` has another vertex count than the template.
    pub fn rotations(&self, warped: &[Vec3]) -> Result<Vec<Mat3>> {
        check_count("warped garment M", self.rest.len(), warped.len())?;
        let normals = geom::normals::vertex_normals(warped, &self.faces);
        Ok((0..warped.len())
            .map(|i| {
                let (mut h, mut squared, mut count) = (Mat3::ZERO, 0.0f32, 0usize);
                for &j in self.ring.row(i) {
                    let (em, er) = (
                        warped[j as usize] - warped[i],
                        self.rest[j as usize] - self.rest[i],
                    );
                    h += outer(em, er);
                    squared += er.length_squared();
                    count += 1;
                }
                let s2 = if count > 0 {
                    squared / count as f32
                } else {
                    1.0
                };
                h += outer(normals[i], self.rest_normals[i]) * s2;
                rotation_of(h).unwrap_or_else(|| arc(self.rest_normals[i], normals[i]))
            })
            .collect())
    }
}

/// `a b^T`.
fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The rotation factor of the polar decomposition of `h` (scaled Newton iteration,
/// `X <- (g X + (g X)^-T) / 2`); `None` when `h` is singular, not finite or a reflection.
fn rotation_of(h: Mat3) -> Option<Mat3> {
    let det = h.determinant();
    if !(det.is_finite() && det > 0.0) {
        return None;
    }
    let mut x = h * (1.0 / det.cbrt());
    for _ in 0..POLAR_ITERATIONS {
        let inv_t = x.inverse().transpose();
        let norm = |m: Mat3| m.to_cols_array().iter().map(|v| v * v).sum::<f32>().sqrt();
        let g = (norm(inv_t) / norm(x)).sqrt();
        x = (x * g + inv_t * (1.0 / g)) * 0.5;
    }
    let ok = x.to_cols_array().iter().all(|v| v.is_finite()) && x.determinant() > 0.5;
    ok.then_some(x)
}

/// The shortest-arc rotation from unit `a` to unit `b` (the identity for degenerate input).
fn arc(a: Vec3, b: Vec3) -> Mat3 {
    if a.is_normalized() && b.is_normalized() {
        Mat3::from_quat(glam::Quat::from_rotation_arc(a, b))
    } else {
        Mat3::IDENTITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::tube_garment;

    fn max_diff(a: Mat3, b: Mat3) -> f32 {
        (a - b)
            .to_cols_array()
            .iter()
            .fold(0.0f32, |m, v| m.max(v.abs()))
    }

    /// A turned and moved copy of the template gives that turn at every vertex.
    #[test]
    fn a_rigid_motion_gives_its_rotation_everywhere() {
        let mesh = tube_garment(200);
        let frames = VertexFrames::new(&mesh).unwrap();
        let turn = Mat3::from_quat(glam::Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 2.3));
        let moved: Vec<Vec3> = mesh
            .vertices
            .iter()
            .map(|&p| turn * p + Vec3::new(0.3, -2.0, 1.0))
            .collect();
        let r = frames.rotations(&moved).unwrap();
        assert_eq!(r.len(), mesh.num_vertices());
        let worst = r.iter().map(|&m| max_diff(m, turn)).fold(0.0f32, f32::max);
        assert!(worst < 1e-4, "{worst}");
    }

    /// Scaled and turned, the frame is still the turn; bent, each half follows its own part.
    #[test]
    fn scale_leaves_the_turn_and_bends_turn_each_part() {
        let mesh = tube_garment(200);
        let frames = VertexFrames::new(&mesh).unwrap();
        let turn = Mat3::from_rotation_y(0.7);
        let scaled: Vec<Vec3> = mesh.vertices.iter().map(|&p| turn * p * 1.3).collect();
        let r = frames.rotations(&scaled).unwrap();
        let worst = r.iter().map(|&m| max_diff(m, turn)).fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "{worst}");
        for m in &r {
            assert!((m.determinant() - 1.0).abs() < 1e-4);
            assert!(max_diff(*m * m.transpose(), Mat3::IDENTITY) < 1e-4);
        }
        // The upper half (y above the middle) turned 90 degrees about z about the middle.
        let mid = mesh.vertices.iter().map(|p| p.y).sum::<f32>() / mesh.num_vertices() as f32;
        let bend = Mat3::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let bent: Vec<Vec3> = mesh
            .vertices
            .iter()
            .map(|&p| match p.y > mid {
                true => bend * (p - Vec3::Y * mid) + Vec3::Y * mid,
                false => p,
            })
            .collect();
        let r = frames.rotations(&bent).unwrap();
        let far = |i: usize| (mesh.vertices[i].y - mid).abs() > 0.1;
        for (i, m) in r.iter().enumerate().filter(|&(i, _)| far(i)) {
            let want = if mesh.vertices[i].y > mid {
                bend
            } else {
                Mat3::IDENTITY
            };
            assert!(max_diff(*m, want) < 1e-3, "vertex {i}");
        }
        assert!(frames.rotations(&bent[1..]).is_err());
    }

    #[test]
    fn polar_factor_refuses_reflections_and_singular_matrices() {
        assert!(rotation_of(Mat3::from_diagonal(Vec3::new(1.0, 1.0, -1.0))).is_none());
        assert!(rotation_of(Mat3::ZERO).is_none());
        let r = rotation_of(Mat3::from_diagonal(Vec3::new(3.0, 0.01, 7.0))).unwrap();
        assert!(max_diff(r, Mat3::IDENTITY) < 1e-5);
    }
}
