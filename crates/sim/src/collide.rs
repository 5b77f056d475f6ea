//! Collision against a moving, closed body mesh.
//!
//! The collider keeps the body at two times: `prev`, where it was at the start of the next
//! step, and `cur`, where it will be at the end ([`BodyCollider::move_to`]), with a BVH over
//! each (refitted, never rebuilt). A step of [`crate::ClothSim`] finds the cloth vertices
//! touching the body at `prev` (closest point within thickness + margin), carries them with
//! the motion of their body point, constrains them to stay outside the tangent plane at
//! `cur` during the solve, and afterwards projects every vertex inside or closer than the
//! thickness back out; the step then commits `cur` as the new `prev`.
//!
//! Inside/outside of a point near the surface is decided by the angle-weighted pseudo-normal
//! of the closest feature (face, edge or vertex; Baerentzen & Aanaes 2005), which is exact for
//! closed meshes; far points use the BVH's ray-voting winding test.

use std::sync::atomic::{AtomicU64, Ordering};

use geom::adjacency::{Csr, EdgeTopology, NO_EDGE};
use geom::{Bvh, ClosestHit, TriMesh};
use glam::Vec3;
use rayon::prelude::*;

use crate::error::{check_finite, Result, SimError};

/// No face: a search hint for "none known".
pub(crate) const NO_FACE: u32 = u32::MAX;

/// The next body state's number (shared by every collider, so no two states ever share
/// one).
static NEXT_STATE: AtomicU64 = AtomicU64::new(0);

fn new_state() -> u64 {
    NEXT_STATE.fetch_add(1, Ordering::Relaxed)
}

/// Directions [`BodyCollider::exit_point`] tries.
const EXIT_DIRECTIONS: usize = 32;

/// A closed body mesh moving over time, for cloth collision.
#[derive(Clone, Debug)]
pub struct BodyCollider {
    faces: Vec<[u32; 3]>,
    prev: Vec<Vec3>,
    cur: Vec<Vec3>,
    bvh_prev: Bvh,
    bvh_cur: Bvh,
    thickness: f32,
    /// `[F]` for each face, the edge index of `(v0,v1)`, `(v1,v2)`, `(v2,v0)`.
    face_edges: Vec<[u32; 3]>,
    /// `[E]` the (one or two) faces of each edge.
    edge_faces: Vec<[u32; 2]>,
    /// `[F]` unit face normals at `cur`.
    face_normals: Vec<Vec3>,
    /// `[N]` rows: the faces at each vertex, ascending (the order in which a pass over every
    /// face would add up the vertex's pseudo-normal).
    vertex_faces: Csr,
    /// `[N]` area-weighted smooth vertex normals at `cur` (contact planes).
    vertex_normals: Vec<Vec3>,
    /// Largest vertex displacement from `prev` to `cur`, metres.
    max_disp: f32,
    /// Numbers of the body states at `prev` and `cur`: equal numbers, equal bodies.
    prev_state: u64,
    cur_state: u64,
}

/// A cloth point's relation to the body at `cur`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfaceHit {
    /// The face holding the closest point.
    pub face: u32,
    /// Closest point on the body.
    pub point: Vec3,
    /// Barycentric weights of `point` in `face`.
    pub bary: [f32; 3],
    /// Signed distance (negative inside), metres.
    pub signed: f32,
    /// Unit direction from the surface toward outside at the query point: along
    /// `query - point` (flipped when inside), or the pseudo-normal when the point is on the
    /// surface.
    pub out: Vec3,
}

impl SurfaceHit {
    /// The closest point as the BVH search gave it.
    pub(crate) fn closest(&self) -> ClosestHit {
        ClosestHit {
            face: self.face,
            point: self.point,
            bary: self.bary,
            distance: self.signed.abs(),
        }
    }
}

impl BodyCollider {
    /// A collider for `body` (vertices `[N]` metres, faces `[F]`), which must be closed (every
    /// edge shared by exactly two faces) and consistently oriented outward; it starts at rest
    /// at `body.vertices`. `thickness`: distance in metres cloth is kept outside the surface
    /// (a step uses the larger of this and [`crate::ClothParams::thickness`]).
    pub fn new(body: &TriMesh, thickness: f32) -> Result<Self> {
        body.validate()?;
        if body.faces.is_empty() {
            return Err(SimError::InvalidMesh("body mesh has no faces".into()));
        }
        if !(thickness.is_finite() && thickness >= 0.0) {
            return Err(SimError::InvalidInput(format!(
                "thickness must be non-negative and finite, got {thickness}"
            )));
        }
        let topo = EdgeTopology::new(body.vertices.len(), &body.faces)?;
        let mut edge_faces = Vec::with_capacity(topo.edges.len());
        for e in 0..topo.edges.len() {
            match topo.faces_of(e) {
                &[f, g] => edge_faces.push([f, g]),
                other => {
                    return Err(SimError::InvalidMesh(format!(
                        "body mesh is not closed: edge {:?} has {} faces (need 2)",
                        topo.edges[e],
                        other.len()
                    )))
                }
            }
        }
        if topo.face_edges.iter().any(|f| f.contains(&NO_EDGE)) {
            return Err(SimError::InvalidMesh(
                "body mesh has a degenerate face (repeated vertex)".into(),
            ));
        }
        let bvh = Bvh::from_mesh(body)?;
        let vertex_faces = geom::adjacency::vertex_faces(body.vertices.len(), &body.faces)?;
        let mut c = BodyCollider {
            faces: body.faces.clone(),
            prev: body.vertices.clone(),
            cur: body.vertices.clone(),
            bvh_prev: bvh.clone(),
            bvh_cur: bvh,
            thickness,
            face_edges: topo.face_edges,
            edge_faces,
            face_normals: Vec::new(),
            vertex_faces,
            vertex_normals: Vec::new(),
            max_disp: 0.0,
            prev_state: 0,
            cur_state: 0,
        };
        c.prev_state = new_state();
        c.cur_state = c.prev_state;
        c.update_normals();
        Ok(c)
    }

    /// Sets where the body's vertices (`[N]`, metres, same topology as at construction) will be
    /// at the END of the next step; the body moves linearly from its current place during that
    /// step. Calling it again before a step replaces the target. Refits the BVH. Fails on a
    /// length mismatch or a non-finite coordinate, leaving the collider unchanged. The same
    /// target again (a body holding still while the cloth settles) costs one comparison:
    /// nothing is refitted or recomputed.
    pub fn move_to(&mut self, vertices: &[Vec3]) -> Result<()> {
        if vertices.len() != self.cur.len() {
            return Err(SimError::InvalidInput(format!(
                "body has {} vertices, move_to got {}",
                self.cur.len(),
                vertices.len()
            )));
        }
        if vertices == self.cur.as_slice() {
            return Ok(());
        }
        check_finite("body vertices", vertices)?;
        self.bvh_cur.refit(vertices)?;
        self.cur.copy_from_slice(vertices);
        self.cur_state = new_state();
        self.max_disp = self
            .prev
            .iter()
            .zip(&self.cur)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f32::max);
        self.update_normals();
        Ok(())
    }

    /// The collider's own thickness, metres.
    pub fn thickness(&self) -> f32 {
        self.thickness
    }

    /// The body's vertices `[N]` at the end of the next step (metres).
    pub fn vertices(&self) -> &[Vec3] {
        &self.cur
    }

    /// The body's faces `[F]`.
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The BVH of the body where it is now (the target of the pending motion).
    pub fn bvh(&self) -> &Bvh {
        &self.bvh_cur
    }

    /// Largest body vertex displacement of the pending motion (metres).
    pub fn max_displacement(&self) -> f32 {
        self.max_disp
    }

    /// Depth of each point of `points` (`[P]`, metres) inside the body at its current
    /// (target) position: the distance to the surface for points inside (winding test), 0 for
    /// points outside or non-finite: `[P]` metres.
    pub fn penetration_depths(&self, points: &[Vec3]) -> Vec<f32> {
        points
            .par_iter()
            .map(|&p| {
                if p.is_finite() && self.bvh_cur.contains(p) {
                    self.bvh_cur.closest_point(p).map_or(0.0, |h| h.distance)
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// Moves every point of `points` (`[P]` metres) that is inside the body, or outside but
    /// closer than `gap` metres to its surface, to `gap` outside its closest surface point
    /// (along the surface's outward direction there); only points within `within` metres of
    /// the surface are looked at (deeper ones are left). Returns how many moved. For a
    /// predicted garment: cloth rests on the skin, never in it.
    pub fn push_out(&self, points: &mut [Vec3], within: f32, gap: f32) -> usize {
        points
            .par_iter_mut()
            .map(|p| match self.surface_within(*p, within, NO_FACE) {
                Some(h) if h.signed < gap => {
                    *p = h.point + h.out * gap;
                    1
                }
                _ => 0,
            })
            .sum()
    }

    /// How far the body's skin under the cloth is stretched: for every body edge of a face
    /// whose surface lies within `within` metres of one of `points` (`[P]` metres, the
    /// cloth), its length at the current position over its length in `rest` (`[N]` metres,
    /// the same body in its rest pose), minus 1; `[E']`, one value per such edge, in no set
    /// order. Cloth held to the skin by friction must stretch as much, or slide.
    pub fn skin_stretch_under(
        &self,
        rest: &[Vec3],
        points: &[Vec3],
        within: f32,
    ) -> Result<Vec<f32>> {
        if rest.len() != self.cur.len() {
            return Err(SimError::InvalidInput(format!(
                "rest body has {} vertices, the collider's body {}",
                rest.len(),
                self.cur.len()
            )));
        }
        check_finite("rest body", rest)?;
        let touched: Vec<u32> = points
            .par_iter()
            .filter_map(|&p| self.bvh_cur.closest_point_within(p, within).map(|h| h.face))
            .collect();
        let mut seen = vec![false; self.edge_faces.len()];
        let mut stretch = Vec::new();
        for f in touched {
            let face = self.faces[f as usize];
            for (k, &e) in self.face_edges[f as usize].iter().enumerate() {
                if !std::mem::replace(&mut seen[e as usize], true) {
                    let (a, b) = (face[k] as usize, face[(k + 1) % 3] as usize);
                    let l0 = rest[a].distance(rest[b]);
                    if l0 > 0.0 {
                        stretch.push(self.cur[a].distance(self.cur[b]) / l0 - 1.0);
                    }
                }
            }
        }
        Ok(stretch)
    }

    /// Makes the current (target) position the start of the next step.
    pub(crate) fn commit(&mut self) {
        if self.prev != self.cur {
            self.prev.copy_from_slice(&self.cur);
            // Same length and finite: refit cannot fail.
            let _ = self.bvh_prev.refit(&self.cur);
        }
        self.prev_state = self.cur_state;
        self.max_disp = 0.0;
    }

    /// The number of the body state at the start of the next step: a closest point found at
    /// the end of a step with [`BodyCollider::cur_state`] `s` holds at the start of the next
    /// while this is `s`.
    pub(crate) fn prev_state(&self) -> u64 {
        self.prev_state
    }

    /// The number of the body state at the end of the next step.
    pub(crate) fn cur_state(&self) -> u64 {
        self.cur_state
    }

    /// Closest point at the start of the step within `r` metres of `p`; `hint`: a face
    /// likely close to `p` ([`NO_FACE`] for none), which makes the search cheaper and does
    /// not change its result ([`BodyCollider::search_radius`]).
    #[inline]
    pub(crate) fn closest_prev(&self, p: Vec3, r: f32, hint: u32) -> Option<ClosestHit> {
        let r = self.search_radius(&self.prev, p, r, hint);
        self.bvh_prev.closest_point_within(p, r)
    }

    /// `r` lowered to the distance from `p` to face `hint` of the body at `vertices`, when
    /// that is a face: the closest point is no farther than that. A BVH search visits its
    /// nodes in an order set by `p` alone and keeps the first closest face it meets, which
    /// no smaller bound prunes, so the result is the same, found with fewer visits.
    #[inline]
    fn search_radius(&self, vertices: &[Vec3], p: Vec3, r: f32, hint: u32) -> f32 {
        let Some(f) = self.faces.get(hint as usize) else {
            return r;
        };
        let [a, b, c] = f.map(|k| vertices[k as usize]);
        let (q, _) = geom::tri::closest_point_on_triangle(p, a, b, c);
        // A hair beyond the face, so that rounding (the search compares squares) cannot
        // leave the face itself outside the bound.
        r.min(q.distance(p) * (1.0 + 1e-5) + 1e-9)
    }

    /// Displacement from `prev` to `cur` of the body point at `face` / `bary`.
    #[inline]
    pub(crate) fn displacement(&self, face: u32, bary: [f32; 3]) -> Vec3 {
        let f = self.faces[face as usize];
        (0..3)
            .map(|k| (self.cur[f[k] as usize] - self.prev[f[k] as usize]) * bary[k])
            .sum()
    }

    /// Point and smooth unit normal at the end of the step of the body point at
    /// `face` / `bary`.
    #[inline]
    pub(crate) fn plane_cur(&self, face: u32, bary: [f32; 3]) -> (Vec3, Vec3) {
        let f = self.faces[face as usize];
        let mut p = Vec3::ZERO;
        let mut n = Vec3::ZERO;
        for k in 0..3 {
            p += self.cur[f[k] as usize] * bary[k];
            n += self.vertex_normals[f[k] as usize] * bary[k];
        }
        let n = n
            .try_normalize()
            .unwrap_or(self.face_normals[face as usize]);
        (p, n)
    }

    /// The pseudo-normal of the feature of `face` holding the point with weights `bary`.
    fn pseudo_normal(&self, face: u32, bary: [f32; 3]) -> Vec3 {
        const EPS: f32 = 1e-5;
        let f = self.faces[face as usize];
        let zeros = bary.iter().filter(|&&w| w < EPS).count();
        if zeros >= 2 {
            let k = (0..3)
                .max_by(|&a, &b| bary[a].total_cmp(&bary[b]))
                .unwrap_or(0);
            self.vertex_pseudo_normal(f[k] as usize)
        } else if zeros == 1 {
            let k = (0..3).find(|&k| bary[k] < EPS).unwrap_or(0);
            // The edge opposite corner k runs (k+1) -> (k+2): slot (k+1) % 3.
            let [g, h] = self.edge_faces[self.face_edges[face as usize][(k + 1) % 3] as usize];
            (self.face_normals[g as usize] + self.face_normals[h as usize]).normalize_or_zero()
        } else {
            self.face_normals[face as usize]
        }
    }

    /// The closest point at the end of the step within `r` metres of `p`, with its signed
    /// distance and outward direction; `hint` as for [`BodyCollider::closest_prev`].
    pub(crate) fn surface_within(&self, p: Vec3, r: f32, hint: u32) -> Option<SurfaceHit> {
        let r = self.search_radius(&self.cur, p, r, hint);
        let h = self.bvh_cur.closest_point_within(p, r)?;
        Some(self.classify(p, h))
    }

    /// The closest point at the end of the step, unbounded (for points known to be inside).
    pub(crate) fn surface_any(&self, p: Vec3) -> Option<SurfaceHit> {
        let h = self.bvh_cur.closest_point(p)?;
        Some(self.classify(p, h))
    }

    fn classify(&self, p: Vec3, h: ClosestHit) -> SurfaceHit {
        let pn = self.pseudo_normal(h.face, h.bary);
        let d = p - h.point;
        let inside = d.dot(pn) < 0.0;
        let out = if h.distance > 1e-7 {
            let u = d / h.distance;
            if inside {
                -u
            } else {
                u
            }
        } else {
            pn
        };
        SurfaceHit {
            face: h.face,
            point: h.point,
            bary: h.bary,
            signed: if inside { -h.distance } else { h.distance },
            out,
        }
    }

    /// Whether `p` is inside the body at the end of the step (winding test; slow, for points
    /// far from the surface).
    pub(crate) fn contains_cur(&self, p: Vec3) -> bool {
        self.bvh_cur.contains(p)
    }

    /// The nearest way out of the body at the end of the step from `p`, for a point the
    /// closest surface cannot lead out (inside one body part and under the surface of
    /// another, or under a fold of skin): along each of [`EXIT_DIRECTIONS`] directions the
    /// point where no body part encloses the ray any more ([`Bvh::ray_exit`]), `margin`
    /// metres beyond it, kept if the winding test finds it outside; the shortest of those.
    /// `(target, direction)`, or `None` when no direction leads out.
    pub(crate) fn exit_point(&self, p: Vec3, margin: f32) -> Option<(Vec3, Vec3)> {
        let n = EXIT_DIRECTIONS as f32;
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let mut best: Option<(f32, Vec3)> = None;
        for k in 0..EXIT_DIRECTIONS {
            // Fibonacci sphere: directions spread evenly over all of space.
            let y = 1.0 - (2 * k + 1) as f32 / n;
            let r = (1.0 - y * y).sqrt();
            let a = golden * k as f32;
            let dir = Vec3::new(r * a.cos(), y, r * a.sin());
            let Some(t) = self.bvh_cur.ray_exit(p, dir) else {
                continue;
            };
            if best.is_some_and(|(b, _)| b <= t) {
                continue;
            }
            if !self.bvh_cur.contains(p + dir * (t + margin)) {
                best = Some((t, dir));
            }
        }
        best.map(|(t, dir)| (p + dir * (t + margin), dir))
    }

    /// The face and smooth vertex normals at `cur`. The edge and vertex pseudo-normals are
    /// worked out where a query needs one: a step asks for a few hundred of them, and a
    /// pass over every face for all of them was about 4% of a dataset drape.
    fn update_normals(&mut self) {
        self.face_normals = geom::normals::face_normals(&self.cur, &self.faces);
        self.vertex_normals = geom::normals::vertex_normals(&self.cur, &self.faces);
    }

    /// The angle-weighted pseudo-normal of vertex `v` at `cur` (unit, or zero where its
    /// corners are degenerate): each face's normal weighted by its angle at `v`, added up in
    /// face order.
    fn vertex_pseudo_normal(&self, v: usize) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for &fi in self.vertex_faces.row(v) {
            let fi = fi as usize;
            let f = self.faces[fi];
            // No face repeats a vertex (`new` refuses degenerate faces): one corner at `v`.
            let k = f.iter().position(|&w| w as usize == v).unwrap_or(0);
            let a = self.cur[f[k] as usize];
            let b = self.cur[f[(k + 1) % 3] as usize];
            let c = self.cur[f[(k + 2) % 3] as usize];
            let angle = (b - a).angle_between(c - a);
            if angle.is_finite() {
                sum += self.face_normals[fi] * angle;
            }
        }
        sum.normalize_or_zero()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depths_and_signs_on_a_sphere() {
        let s = TriMesh::icosphere(3, 1.0);
        let c = BodyCollider::new(&s, 0.01).unwrap();
        let pts = [
            Vec3::ZERO,
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 1.5, 0.0),
        ];
        let d = c.penetration_depths(&pts);
        assert!(d[0] > 0.95 && d[0] <= 1.0, "{d:?}");
        assert!(d[1] > 0.45 && d[1] <= 0.5, "{d:?}");
        assert_eq!(d[2], 0.0);
        // Signs from pseudo-normals near vertices, edges and faces of the sphere.
        for (i, &v) in s.vertices.iter().enumerate().step_by(7) {
            for t in [0.995f32, 1.005] {
                let p = v * t + Vec3::splat(1e-4 * (i % 3) as f32);
                let h = c.surface_within(p, 0.1, NO_FACE).unwrap();
                assert_eq!(h.signed < 0.0, c.bvh_cur.contains(p), "{p} {}", h.signed);
                assert!(h.out.dot(v) > 0.9);
            }
        }
    }

    #[test]
    fn pseudo_normals_on_demand_match_a_pass_over_every_face() {
        let mut s = TriMesh::icosphere(3, 0.3);
        for (i, v) in s.vertices.iter_mut().enumerate() {
            *v *= 1.0 + 0.05 * ((i * 37 % 11) as f32 / 10.0 - 0.5);
        }
        let mut c = BodyCollider::new(&s, 0.004).unwrap();
        let moved: Vec<Vec3> = s.vertices.iter().map(|v| *v * 1.1).collect();
        c.move_to(&moved).unwrap();
        // The plain way: every face adds its angle-weighted normal to its three corners.
        let mut plain = vec![Vec3::ZERO; moved.len()];
        for (fi, f) in s.faces.iter().enumerate() {
            let n = c.face_normals[fi];
            for k in 0..3 {
                let a = moved[f[k] as usize];
                let b = moved[f[(k + 1) % 3] as usize];
                let cc = moved[f[(k + 2) % 3] as usize];
                let angle = (b - a).angle_between(cc - a);
                if angle.is_finite() {
                    plain[f[k] as usize] += n * angle;
                }
            }
        }
        for (v, p) in plain.iter().enumerate() {
            assert_eq!(
                c.vertex_pseudo_normal(v),
                p.normalize_or_zero(),
                "vertex {v}"
            );
            assert!(c.vertex_pseudo_normal(v).dot(moved[v]) > 0.0, "vertex {v}");
        }
    }

    #[test]
    fn search_hints_never_change_the_closest_point() {
        let s = TriMesh::icosphere(3, 0.3);
        let c = BodyCollider::new(&s, 0.004).unwrap();
        let faces = s.faces.len() as u32;
        for k in 0..400u32 {
            // Points from 0.9 to 1.1 of the radius, spread over the sphere.
            let t = k as f32 * 0.618;
            let dir = Vec3::new(t.cos(), (k as f32 / 200.0) - 1.0, t.sin()).normalize();
            let p = dir * 0.3 * (0.9 + 0.2 * (k % 7) as f32 / 6.0);
            let plain = c.closest_prev(p, 0.02, NO_FACE);
            // The closest face itself (the bound must not drop it by rounding), a
            // neighbour-ish face and a far one.
            let own = plain.map_or(NO_FACE, |h| h.face);
            for hint in [own, (own.wrapping_add(1)) % faces, (k * 37) % faces] {
                assert_eq!(
                    c.closest_prev(p, 0.02, hint),
                    plain,
                    "point {k} hint {hint}"
                );
                let a = c.surface_within(p, 0.02, hint).map(|h| (h.face, h.signed));
                let b = c
                    .surface_within(p, 0.02, NO_FACE)
                    .map(|h| (h.face, h.signed));
                assert_eq!(a, b, "point {k} hint {hint}");
            }
        }
    }

    #[test]
    fn push_out_puts_points_inside_or_too_close_at_the_gap() {
        let s = TriMesh::icosphere(3, 1.0);
        let c = BodyCollider::new(&s, 0.005).unwrap();
        // Off the centre of a face along its normal: inside, on the surface, closer than
        // the gap, outside it, and deeper than `within`.
        let [a, b, cc] = s.faces[7].map(|k| s.vertices[k as usize]);
        let (centre, n) = ((a + b + cc) / 3.0, (b - a).cross(cc - a).normalize());
        let mut pts = [-0.03f32, 0.0, 0.001, 0.01, -0.4].map(|t| centre + n * t);
        let before = pts;
        assert_eq!(c.push_out(&mut pts, 0.05, 0.002), 3);
        for p in &pts[..3] {
            assert!((*p - (centre + n * 0.002)).length() < 1e-5, "{p}");
        }
        assert_eq!(pts[3..], before[3..]);
    }

    #[test]
    fn skin_stretch_under_cloth_matches_a_brute_force_search() {
        let rest = TriMesh::icosphere(2, 1.0);
        let mut c = BodyCollider::new(&rest, 0.005).unwrap();
        // Uniform growth by 10%: every touched edge is stretched by 10%.
        let grown: Vec<Vec3> = rest.vertices.iter().map(|v| *v * 1.1).collect();
        c.move_to(&grown).unwrap();
        let near = |t: f32| -> Vec<Vec3> {
            grown
                .iter()
                .step_by(5)
                .map(|v| *v * t)
                .chain([Vec3::X * 3.0])
                .collect()
        };
        let s = c
            .skin_stretch_under(&rest.vertices, &near(1.004), 0.01)
            .unwrap();
        assert!(
            !s.is_empty() && s.iter().all(|x| (x - 0.1).abs() < 1e-5),
            "{s:?}"
        );
        assert!(c
            .skin_stretch_under(&rest.vertices, &[Vec3::X * 3.0], 0.01)
            .unwrap()
            .is_empty());
        assert!(c
            .skin_stretch_under(&rest.vertices[1..], &near(1.0), 0.01)
            .is_err());
        // The +x half stretched sideways only: the same edges, with the same values, as
        // testing every face against every point.
        let skewed: Vec<Vec3> = rest
            .vertices
            .iter()
            .map(|v| {
                if v.x > 0.0 {
                    *v * Vec3::new(1.0, 1.3, 1.0)
                } else {
                    *v
                }
            })
            .collect();
        c.move_to(&skewed).unwrap();
        // Off face centres (off vertices, faces tie for the closest).
        let pts: Vec<Vec3> = rest
            .faces
            .iter()
            .step_by(3)
            .map(|f| {
                let [a, b, cc] = f.map(|k| skewed[k as usize]);
                (a + b + cc) / 3.0 + (b - a).cross(cc - a).normalize() * 0.006
            })
            .collect();
        let mut fast = c.skin_stretch_under(&rest.vertices, &pts, 0.01).unwrap();
        let mut edges = std::collections::BTreeSet::new();
        for p in &pts {
            let (f, d) = rest
                .faces
                .iter()
                .enumerate()
                .map(|(i, f)| {
                    let [a, b, cc] = f.map(|k| skewed[k as usize]);
                    (
                        i,
                        geom::tri::closest_point_on_triangle(*p, a, b, cc)
                            .0
                            .distance(*p),
                    )
                })
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .unwrap();
            if d <= 0.01 {
                let face = rest.faces[f];
                for k in 0..3 {
                    let (a, b) = (face[k], face[(k + 1) % 3]);
                    edges.insert((a.min(b), a.max(b)));
                }
            }
        }
        let mut plain: Vec<f32> = edges
            .iter()
            .map(|&(a, b)| {
                let (a, b) = (a as usize, b as usize);
                skewed[a].distance(skewed[b]) / rest.vertices[a].distance(rest.vertices[b]) - 1.0
            })
            .collect();
        fast.sort_by(f32::total_cmp);
        plain.sort_by(f32::total_cmp);
        assert_eq!(fast.len(), plain.len());
        assert!(fast.iter().zip(&plain).all(|(a, b)| (a - b).abs() < 1e-6));
        assert!(plain.last().unwrap() > &0.1);
    }

    #[test]
    fn rejects_open_or_bad_meshes() {
        let g = TriMesh::grid(3, 3, 0.1);
        assert!(BodyCollider::new(&g, 0.01).is_err());
        let s = TriMesh::icosphere(1, 1.0);
        assert!(BodyCollider::new(&s, f32::NAN).is_err());
        let mut c = BodyCollider::new(&s, 0.01).unwrap();
        assert!(c.move_to(&s.vertices[..3]).is_err());
        let mut bad = s.vertices.clone();
        bad[4].x = f32::NAN;
        let e = c.move_to(&bad).unwrap_err().to_string();
        assert!(e.contains("vertex 4"), "{e}");
        let moved: Vec<Vec3> = s.vertices.iter().map(|v| *v + Vec3::X * 0.1).collect();
        c.move_to(&moved).unwrap();
        assert!((c.max_displacement() - 0.1).abs() < 1e-6);
        // The same target again changes nothing.
        c.move_to(&moved).unwrap();
        assert!((c.max_displacement() - 0.1).abs() < 1e-6);
        assert_eq!(c.vertices(), moved.as_slice());
        let d = c.displacement(0, [0.2, 0.3, 0.5]);
        assert!((d - Vec3::X * 0.1).length() < 1e-6);
        c.commit();
        assert_eq!(c.max_displacement(), 0.0);
    }
}
