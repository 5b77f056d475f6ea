//! The geometric passes of one remeshing iteration: tangential relaxation, projection back
//! onto the input, and the final input face / barycentric coordinates of every vertex.

use glam::Vec3;

use super::halfedge::NONE;
use super::ops::Remesher;
use super::{BoundaryMode, Relaxation};

impl Remesher<'_> {
    /// Moves every free interior vertex to the (uniform or area-weighted) centroid of its
    /// neighbours, projected onto its tangent plane, and, when the boundary slides, every free
    /// boundary vertex to the arc-length midpoint of its two loop neighbours (a 1-D Laplacian
    /// along the input loop, so it stays on the loop and keeps its order). All vertices move at
    /// once (Jacobi), so the result does not depend on vertex order.
    pub fn relax(&mut self) {
        let m = &self.m;
        let n = m.n_vertices();
        // Area-weighted normals, and vertex areas (a third of each incident face).
        let mut normal = vec![Vec3::ZERO; n];
        let mut area = vec![0f32; n];
        for f in 0..m.fhe.len() as u32 {
            if m.fdel[f as usize] {
                continue;
            }
            let vs = m.face_vertices(f);
            let [a, b, c] = vs.map(|v| m.pos[v as usize]);
            let cr = (b - a).cross(c - a);
            let third = cr.length() / 6.0;
            for v in vs {
                normal[v as usize] += cr;
                area[v as usize] += third;
            }
        }
        let weighted = self.opts.relaxation == Relaxation::AreaWeighted;
        let slide = self.opts.boundary == BoundaryMode::Slide;
        let mut new_pos = m.pos.clone();
        let mut new_s: Vec<(u32, f64)> = Vec::new();
        for v in 0..n as u32 {
            let tag = m.tag[v as usize];
            if m.vdel[v as usize] || tag.locked {
                continue;
            }
            if m.is_boundary_vertex(v) {
                if slide {
                    let hb = m.vout[v as usize];
                    // Along the loop's faces: `prev -> v -> next`.
                    let prev = m.to[hb as usize];
                    let next = m.from(m.prev[hb as usize]);
                    let line = &self.proj.loops[tag.lp as usize];
                    let ahead = line.wrap(m.tag[next as usize].s - tag.s);
                    let behind = line.wrap(tag.s - m.tag[prev as usize].s);
                    new_s.push((v, line.wrap(tag.s + 0.5 * (ahead - behind))));
                }
                continue;
            }
            let mut sum = Vec3::ZERO;
            let mut wsum = 0f32;
            for x in m.outgoing(v) {
                let w = m.to[x as usize];
                let wt = if weighted { area[w as usize] } else { 1.0 };
                sum += wt * m.pos[w as usize];
                wsum += wt;
            }
            if wsum <= 0.0 {
                continue;
            }
            let p = m.pos[v as usize];
            let mut d = sum / wsum - p;
            let nrm = normal[v as usize].normalize_or_zero();
            d -= nrm * nrm.dot(d);
            new_pos[v as usize] = p + d;
        }
        self.m.pos = new_pos;
        for (v, s) in new_s {
            let tag = &mut self.m.tag[v as usize];
            tag.s = s;
            self.m.pos[v as usize] = self.proj.loops[tag.lp as usize].point(s);
        }
    }

    /// Live interior vertices (boundary ones always lie on their input loop).
    fn interior_vertices(&self) -> Vec<u32> {
        (0..self.m.n_vertices() as u32)
            .filter(|&v| !self.m.vdel[v as usize] && self.m.tag[v as usize].lp == NONE)
            .collect()
    }

    /// Moves every interior vertex to its closest point on the input surface.
    pub fn project(&mut self) {
        let idx = self.interior_vertices();
        let pts: Vec<Vec3> = idx.iter().map(|&v| self.m.pos[v as usize]).collect();
        for (&v, (p, _, _)) in idx.iter().zip(self.proj.surface(&pts)) {
            self.m.pos[v as usize] = p;
        }
    }

    /// For every vertex slot: the input face and barycentric weights of its source point: the
    /// closest input point for an interior vertex, its place on the loop for a boundary one.
    /// `([V], [V])`; removed slots get face 0 with weights `[1, 0, 0]`.
    pub fn sources(&self) -> (Vec<u32>, Vec<[f32; 3]>) {
        let n = self.m.n_vertices();
        let mut face = vec![0u32; n];
        let mut bary = vec![[1.0f32, 0.0, 0.0]; n];
        let idx = self.interior_vertices();
        let pts: Vec<Vec3> = idx.iter().map(|&v| self.m.pos[v as usize]).collect();
        for (&v, (_, f, w)) in idx.iter().zip(self.proj.surface(&pts)) {
            face[v as usize] = f;
            bary[v as usize] = w;
        }
        for v in 0..n {
            let t = self.m.tag[v];
            if !self.m.vdel[v] && t.lp != NONE {
                (face[v], bary[v]) = self.proj.loop_source(t.lp, t.s);
            }
        }
        (face, bary)
    }
}
