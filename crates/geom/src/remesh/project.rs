//! Projection onto the input: the surface (through a BVH closest-point query) and its
//! boundary loops (closed polylines parametrised by arc length).

use glam::Vec3;

use crate::adjacency::EdgeTopology;
use crate::bvh::Bvh;
use crate::error::Result;

/// One input boundary loop as a closed polyline, walked in the direction its faces traverse it.
#[derive(Clone, Debug)]
pub(crate) struct Polyline {
    /// `[K]` input vertex indices.
    pub verts: Vec<u32>,
    /// `[K]` positions (metres).
    pub pts: Vec<Vec3>,
    /// `[K]` the input face holding segment `k` (`verts[k] -> verts[k + 1]`).
    pub faces: Vec<u32>,
    /// `[K + 1]` arc length (metres) at the start of each segment; the last is the perimeter.
    pub cum: Vec<f64>,
}

impl Polyline {
    /// Perimeter (metres).
    pub fn perimeter(&self) -> f64 {
        *self.cum.last().unwrap_or(&0.0)
    }

    /// `s` wrapped into `[0, perimeter)`.
    pub fn wrap(&self, s: f64) -> f64 {
        let p = self.perimeter();
        if p <= 0.0 {
            return 0.0;
        }
        let w = s.rem_euclid(p);
        if w >= p {
            0.0
        } else {
            w
        }
    }

    /// Segment index and parameter `t` in [0, 1] at arc length `s` (wrapped).
    pub fn locate(&self, s: f64) -> (usize, f32) {
        let s = self.wrap(s);
        let k = self.cum.partition_point(|&c| c <= s).saturating_sub(1);
        let k = k.min(self.verts.len() - 1);
        let len = self.cum[k + 1] - self.cum[k];
        let t = if len > 0.0 {
            ((s - self.cum[k]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (k, t as f32)
    }

    /// Point at arc length `s` (wrapped).
    pub fn point(&self, s: f64) -> Vec3 {
        let (k, t) = self.locate(s);
        let q = self.pts[(k + 1) % self.pts.len()];
        self.pts[k].lerp(q, t)
    }
}

/// The input surface and its boundary loops.
pub(crate) struct Projector {
    bvh: Bvh,
    faces: Vec<[u32; 3]>,
    /// The input boundary loops.
    pub loops: Vec<Polyline>,
}

impl Projector {
    /// Prepares projection onto `vertices` (`[N]`) / `faces` (`[F]`), whose boundary `loops`
    /// (vertex cycles from [`crate::adjacency::boundary_loops`]) and edge topology are given.
    pub fn new(
        vertices: &[Vec3],
        faces: &[[u32; 3]],
        topo: &EdgeTopology,
        loops: &[Vec<u32>],
    ) -> Result<Self> {
        // The face holding each boundary edge, keyed by the vertex the face leaves it from.
        let mut bface = vec![u32::MAX; vertices.len()];
        for (fi, f) in faces.iter().enumerate() {
            for k in 0..3 {
                if topo.faces_of(topo.face_edges[fi][k] as usize).len() == 1 {
                    bface[f[k] as usize] = fi as u32;
                }
            }
        }
        let loops = loops
            .iter()
            .map(|l| {
                let pts: Vec<Vec3> = l.iter().map(|&v| vertices[v as usize]).collect();
                let mut cum = Vec::with_capacity(l.len() + 1);
                cum.push(0.0f64);
                for k in 0..l.len() {
                    let d = pts[k].distance(pts[(k + 1) % l.len()]) as f64;
                    cum.push(cum[k] + d);
                }
                Polyline {
                    faces: l.iter().map(|&v| bface[v as usize]).collect(),
                    verts: l.clone(),
                    pts,
                    cum,
                }
            })
            .collect();
        Ok(Projector {
            bvh: Bvh::new(vertices, faces)?,
            faces: faces.to_vec(),
            loops,
        })
    }

    /// Closest points on the input surface to `points` (`[Q]`), in parallel: `[Q]` of
    /// `(point, face, barycentric weights)`; a query that finds nothing keeps its point and
    /// reports face 0 with weights `[1, 0, 0]` (cannot happen for a non-empty input).
    pub fn surface(&self, points: &[Vec3]) -> Vec<(Vec3, u32, [f32; 3])> {
        self.bvh
            .closest_points(points, f32::INFINITY)
            .into_iter()
            .zip(points)
            .map(|(h, &p)| match h {
                Some(h) => (h.point, h.face, h.bary),
                None => (p, 0, [1.0, 0.0, 0.0]),
            })
            .collect()
    }

    /// Input face and barycentric weights of the point at arc length `s` on loop `lp`.
    pub fn loop_source(&self, lp: u32, s: f64) -> (u32, [f32; 3]) {
        let l = &self.loops[lp as usize];
        let (k, t) = l.locate(s);
        let (a, b) = (l.verts[k], l.verts[(k + 1) % l.verts.len()]);
        let f = l.faces[k];
        let mut w = [0.0f32; 3];
        for (c, &v) in self.faces[f as usize].iter().enumerate() {
            if v == a {
                w[c] = 1.0 - t;
            } else if v == b {
                w[c] = t;
            }
        }
        (f, w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::adjacency::boundary_loops;
    use crate::TriMesh;

    #[test]
    fn grid_loop_arc_length() {
        let g = TriMesh::grid(3, 3, 1.0);
        let topo = EdgeTopology::new(9, &g.faces).unwrap();
        let loops = boundary_loops(9, &g.faces).unwrap();
        let p = Projector::new(&g.vertices, &g.faces, &topo, &loops).unwrap();
        let l = &p.loops[0];
        assert_eq!(l.perimeter(), 8.0);
        assert_eq!(l.point(0.0), l.pts[0]);
        assert_eq!(l.point(8.0), l.pts[0]);
        assert_eq!(l.point(-1.0), l.pts[7]);
        let mid = l.point(2.5);
        assert!((mid - l.pts[2].lerp(l.pts[3], 0.5)).length() < 1e-6);
        // The source reproduces the point.
        for s in [0.0, 0.3, 2.5, 7.9] {
            let (f, w) = p.loop_source(0, s);
            let q: Vec3 = (0..3)
                .map(|c| w[c] * g.vertices[g.faces[f as usize][c] as usize])
                .sum();
            assert!((q - l.point(s)).length() < 1e-6, "{s}");
        }
    }
}
