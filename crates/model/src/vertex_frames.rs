//! Per-vertex frames of a garment and the rotations that take the template's to M's (for
//! networks with [`crate::GarNetConfig::vertex_frames`]).
//!
//! A vertex's frame is its unit vertex normal `n`, the unit tangent `t` toward a fixed
//! neighbour (the edge to it with its normal part removed) and `n x t`. The rotation of
//! vertex i is `R_i = F_i(M) F_i(template)^T`: the template's frame turned onto M's. Where
//! either frame is degenerate (a zero normal, or the edge along the normal) the rotation is
//! the identity.

use glam::{Mat3, Vec3};

use crate::error::{check_count, ModelError, Result};

/// The fixed neighbour of every vertex and the template's frames, for one garment topology.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexFrames {
    /// `[F]` the garment's faces.
    faces: Vec<[u32; 3]>,
    /// `[N]` the neighbour whose edge gives each vertex's tangent (the next corner of the
    /// first face that holds it; the vertex itself when no face does).
    neighbour: Vec<u32>,
    /// `[N]` the template's frames (`None` where degenerate).
    rest: Vec<Option<Mat3>>,
}

impl VertexFrames {
    /// The frames of the template `rest` `[N]` (metres) with faces `faces` `[F]`; fails on
    /// an index out of range.
    pub fn new(rest: &[Vec3], faces: &[[u32; 3]]) -> Result<Self> {
        geom::adjacency::check_indices(rest.len(), faces)?;
        let mut neighbour: Vec<u32> = (0..rest.len() as u32).collect();
        let mut seen = vec![false; rest.len()];
        for f in faces {
            for c in 0..3 {
                let i = f[c] as usize;
                if !seen[i] {
                    seen[i] = true;
                    neighbour[i] = f[(c + 1) % 3];
                }
            }
        }
        let mut frames = VertexFrames {
            faces: faces.to_vec(),
            neighbour,
            rest: Vec::new(),
        };
        frames.rest = frames.frames(rest);
        Ok(frames)
    }

    /// The frames (columns `t`, `n`, `n x t`) of the garment posed as `posed` `[N]`.
    fn frames(&self, posed: &[Vec3]) -> Vec<Option<Mat3>> {
        let normals = geom::normals::vertex_normals(posed, &self.faces);
        posed
            .iter()
            .zip(&normals)
            .zip(&self.neighbour)
            .map(|((p, n), &j)| {
                let e = posed[j as usize] - *p;
                let t = (e - n.dot(e) * *n).try_normalize()?;
                let n = n.try_normalize()?;
                Some(Mat3::from_cols(t, n, n.cross(t)))
            })
            .collect()
    }

    /// The rotations `[N]` from the template's frames to those of `posed` `[N]` (metres), as
    /// row-major 3x3 blocks `[N*9]`. Fails on a wrong vertex count.
    pub fn rotations(&self, posed: &[Vec3]) -> Result<Vec<f32>> {
        check_count("garment vertices", self.rest.len(), posed.len())?;
        let mut out = Vec::with_capacity(posed.len() * 9);
        for (now, rest) in self.frames(posed).into_iter().zip(&self.rest) {
            let r = match (now, rest) {
                (Some(now), Some(rest)) => now * rest.transpose(),
                _ => Mat3::IDENTITY,
            };
            // glam is column-major: the transpose's columns are the rows.
            out.extend(r.transpose().to_cols_array());
        }
        if out.iter().any(|x| !x.is_finite()) {
            return Err(ModelError::InvalidInput(
                "a vertex rotation is not finite".into(),
            ));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::tube_garment;

    fn rotation(flat: &[f32], i: usize) -> Mat3 {
        Mat3::from_cols_array(flat[i * 9..(i + 1) * 9].try_into().unwrap()).transpose()
    }

    /// A rigidly turned garment gives every vertex that turn; the template itself gives the
    /// identity; a bent garment turns only the vertices that moved.
    #[test]
    fn rigid_turns_are_recovered_and_rest_is_the_identity() {
        let tube = tube_garment(120);
        let frames = VertexFrames::new(&tube.vertices, &tube.faces).unwrap();
        let same = frames.rotations(&tube.vertices).unwrap();
        for i in 0..tube.vertices.len() {
            assert!(rotation(&same, i).abs_diff_eq(Mat3::IDENTITY, 1e-5));
        }
        let turn = Mat3::from_axis_angle(Vec3::new(0.3, 1.0, -0.2).normalize(), 0.9);
        let moved: Vec<Vec3> = tube
            .vertices
            .iter()
            .map(|p| turn * *p + Vec3::new(0.1, -0.2, 0.3))
            .collect();
        let r = frames.rotations(&moved).unwrap();
        for i in 0..tube.vertices.len() {
            let got = rotation(&r, i);
            assert!(got.abs_diff_eq(turn, 1e-4), "vertex {i}: {got} vs {turn}");
            // Row-major layout: entry (k, j) at 3k + j.
            assert!((r[i * 9 + 1] - turn.col(1).x).abs() < 1e-4);
        }
        assert!(frames.rotations(&moved[1..]).is_err());
        assert!(VertexFrames::new(&tube.vertices[..10], &tube.faces).is_err());
    }
}
