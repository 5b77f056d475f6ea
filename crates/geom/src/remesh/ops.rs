//! The topological passes of one remeshing iteration: split long edges, collapse short ones,
//! flip edges toward regular valence. Each checks the preconditions of the half-edge operator
//! it calls, so the mesh stays an oriented manifold with the same boundary loops.

use glam::Vec3;

use super::halfedge::{HeMesh, VTag, NONE};
use super::project::Projector;
use super::{BoundaryMode, RemeshOptions, RemeshStats};

/// Cosine of the largest change of a face normal a collapse or flip may cause (45 degrees).
const MAX_NORMAL_CHANGE_COS: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// The working state of a remeshing run.
pub(crate) struct Remesher<'a> {
    /// The mesh being remeshed.
    pub m: HeMesh,
    /// The input surface and boundary.
    pub proj: &'a Projector,
    /// The options of the run.
    pub opts: RemeshOptions,
    /// Edges shorter than this are collapsed (4/5 L, metres).
    pub low: f32,
    /// Edges longer than this are split (4/3 L, metres).
    pub high: f32,
    /// Working vertices on each input loop.
    pub loop_len: Vec<u32>,
    /// What the passes did.
    pub stats: RemeshStats,
    mark: Vec<u32>,
    stamp: u32,
}

/// Whether a face normal changing from `old` to `new` (both unnormalised) is acceptable: the
/// face keeps an area and turns by less than 45 degrees.
#[inline]
fn normal_ok(old: Vec3, new: Vec3) -> bool {
    let (lo, ln) = (old.length(), new.length());
    ln > 0.0 && new.dot(old) > MAX_NORMAL_CHANGE_COS * lo * ln
}

/// Target valence: 6 inside, 4 on a boundary.
#[inline]
fn target_valence(boundary: bool) -> i32 {
    if boundary {
        4
    } else {
        6
    }
}

impl<'a> Remesher<'a> {
    /// A run over `m` with its input `proj`; `loop_len` counts the vertices of each loop.
    pub fn new(m: HeMesh, proj: &'a Projector, opts: RemeshOptions, loop_len: Vec<u32>) -> Self {
        let l = opts.target_edge_length;
        Remesher {
            m,
            proj,
            opts,
            low: 0.8 * l,
            high: 4.0 / 3.0 * l,
            loop_len,
            stats: RemeshStats::default(),
            mark: Vec::new(),
            stamp: 0,
        }
    }

    #[inline]
    fn len2(&self, h: u32) -> f32 {
        let m = &self.m;
        m.pos[m.from(h) as usize].distance_squared(m.pos[m.to[h as usize] as usize])
    }

    /// Splits every edge longer than `high` at its midpoint (boundary edges at the arc-length
    /// midpoint on their input loop, unless the boundary is fixed), re-examining each half
    /// until none is long. Returns the number of splits.
    pub fn split_long_edges(&mut self) -> usize {
        let high2 = self.high * self.high;
        let fixed = self.opts.boundary == BoundaryMode::Fixed;
        let mut count = 0;
        let mut e = 0u32;
        while (e as usize) < self.m.n_edges() {
            if self.m.edel[e as usize] || self.len2(2 * e) <= high2 {
                e += 1;
                continue;
            }
            if self.m.is_boundary_edge(e) {
                if fixed {
                    e += 1;
                    continue;
                }
                // hb runs along the hole, so its faces traverse the edge from b to a.
                let hb = if self.m.is_boundary_he(2 * e) {
                    2 * e
                } else {
                    2 * e + 1
                };
                let (a, b) = (self.m.from(hb), self.m.to[hb as usize]);
                let (ta, tb) = (self.m.tag[a as usize], self.m.tag[b as usize]);
                let line = &self.proj.loops[ta.lp as usize];
                let s = line.wrap(tb.s + 0.5 * line.wrap(ta.s - tb.s));
                let tag = VTag {
                    lp: ta.lp,
                    s,
                    locked: false,
                };
                self.m.split_edge(e, line.point(s), tag);
                self.loop_len[ta.lp as usize] += 1;
            } else {
                let p = 0.5
                    * (self.m.pos[self.m.from(2 * e) as usize]
                        + self.m.pos[self.m.to[2 * e as usize] as usize]);
                self.m.split_edge(e, p, VTag::INTERIOR);
            }
            count += 1;
            // Stay on `e`: its remaining half may still be too long.
        }
        self.stats.splits += count;
        count
    }

    /// Where the vertex left by collapsing `h` (v0 -> v1) goes: the midpoint of two interior
    /// vertices, the arc-length midpoint on the loop of two free boundary vertices, else v1
    /// itself (a boundary vertex absorbing an interior one, or a locked corner). Returns the
    /// position and, on a loop, the arc length.
    fn collapse_target(&self, h: u32) -> (Vec3, Option<f64>) {
        let m = &self.m;
        let (v0, v1) = (m.from(h), m.to[h as usize]);
        let (b0, b1) = (m.is_boundary_vertex(v0), m.is_boundary_vertex(v1));
        let p1 = m.pos[v1 as usize];
        if !b0 && !b1 {
            return (0.5 * (m.pos[v0 as usize] + p1), None);
        }
        let t1 = m.tag[v1 as usize];
        if !b0 || !b1 || t1.locked {
            // (A boundary v0 into an interior v1 is refused by `collapse_ok`.)
            return (p1, Some(t1.s).filter(|_| b1));
        }
        // Both on the loop, along a boundary edge (checked by the caller).
        let hb = if m.is_boundary_he(h) { h } else { h ^ 1 };
        let (a, b) = (m.from(hb), m.to[hb as usize]);
        let line = &self.proj.loops[t1.lp as usize];
        let (sa, sb) = (m.tag[a as usize].s, m.tag[b as usize].s);
        let s = line.wrap(sb + 0.5 * line.wrap(sa - sb));
        (line.point(s), Some(s))
    }

    /// Whether collapsing `h` (removing its source v0 into its target v1, which moves to `p`)
    /// keeps the mesh manifold with the same boundary loops, turns no face by more than 45
    /// degrees and creates no edge longer than `high`.
    fn collapse_ok(&mut self, h: u32, p: Vec3) -> bool {
        let m = &self.m;
        let o = h ^ 1;
        let (v0, v1) = (m.from(h), m.to[h as usize]);
        let t0 = m.tag[v0 as usize];
        if t0.locked {
            return false;
        }
        let edge_on_boundary = m.is_boundary_he(h) || m.is_boundary_he(o);
        if m.is_boundary_vertex(v0) {
            // A boundary vertex only slides along its loop, which keeps three vertices.
            if !edge_on_boundary || self.loop_len[t0.lp as usize] <= 3 {
                return false;
            }
        }
        // Opposite vertices keep at least two faces (one on a boundary).
        let vl = if m.is_boundary_he(h) {
            NONE
        } else {
            m.opposite_vertex(h)
        };
        let vr = if m.is_boundary_he(o) {
            NONE
        } else {
            m.opposite_vertex(o)
        };
        if vl == vr {
            return false;
        }
        for x in [vl, vr] {
            if x != NONE && m.valence(x) < if m.is_boundary_vertex(x) { 3 } else { 4 } {
                return false;
            }
        }
        // Link condition: the only common neighbours are the opposite vertices.
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.mark.iter_mut().for_each(|x| *x = 0);
            self.stamp = 1;
        }
        if self.mark.len() < m.n_vertices() {
            self.mark.resize(m.n_vertices(), 0);
        }
        for x in m.outgoing(v0) {
            self.mark[m.to[x as usize] as usize] = self.stamp;
        }
        let common = m
            .outgoing(v1)
            .filter(|&x| self.mark[m.to[x as usize] as usize] == self.stamp)
            .count();
        if common != usize::from(vl != NONE) + usize::from(vr != NONE) {
            return false;
        }
        // Geometry: short enough edges, no face turned over, around both ends.
        let high2 = self.high * self.high;
        let (fh, fo) = (m.hface[h as usize], m.hface[o as usize]);
        for (v, other) in [(v0, v1), (v1, v0)] {
            let pv = m.pos[v as usize];
            if v == v1 && pv == p {
                break;
            }
            for x in m.outgoing(v) {
                let w = m.to[x as usize];
                if w == other {
                    continue;
                }
                let pw = m.pos[w as usize];
                if p.distance_squared(pw) > high2 {
                    return false;
                }
                let f = m.hface[x as usize];
                if f != NONE && f != fh && f != fo {
                    let py = m.pos[m.opposite_vertex(x) as usize];
                    if !normal_ok((pw - pv).cross(py - pv), (pw - p).cross(py - p)) {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// Collapses edges shorter than `low` where [`Remesher::collapse_ok`] allows, trying both
    /// directions; repeats the sweep while it makes progress (at most `max_sweeps` times).
    /// Returns the number of collapses.
    pub fn collapse_short_edges(&mut self, max_sweeps: usize) -> usize {
        let low2 = self.low * self.low;
        let mut total = 0;
        for _ in 0..max_sweeps {
            let mut count = 0;
            for e in 0..self.m.n_edges() as u32 {
                if self.m.edel[e as usize] || self.len2(2 * e) >= low2 {
                    continue;
                }
                let Some((h, (p, s))) = [2 * e, 2 * e + 1].into_iter().find_map(|h| {
                    let t = self.collapse_target(h);
                    self.collapse_ok(h, t.0).then_some((h, t))
                }) else {
                    continue;
                };
                let (v0, v1) = (self.m.from(h), self.m.to[h as usize]);
                if self.m.is_boundary_vertex(v0) {
                    self.loop_len[self.m.tag[v0 as usize].lp as usize] -= 1;
                }
                self.m.collapse(h);
                self.m.pos[v1 as usize] = p;
                if let Some(s) = s {
                    self.m.tag[v1 as usize].s = s;
                }
                count += 1;
            }
            total += count;
            if count == 0 {
                break;
            }
        }
        self.stats.collapses += total;
        total
    }

    /// The diamond `[a, b, c, d]` of interior edge `e` (faces `(a, b, c)` and `(b, a, d)`)
    /// when flipping it to c-d is allowed topologically (c-d not an edge yet, a and b keep
    /// enough faces) and turns no face by more than 45 degrees; `None` otherwise.
    fn flippable(&self, e: u32) -> Option<[u32; 4]> {
        let m = &self.m;
        if m.edel[e as usize] || m.is_boundary_edge(e) {
            return None;
        }
        let (h, o) = (2 * e, 2 * e + 1);
        let vs = [
            m.from(h),
            m.to[h as usize],
            m.opposite_vertex(h),
            m.opposite_vertex(o),
        ];
        for v in &vs[..2] {
            if m.valence(*v) < if m.is_boundary_vertex(*v) { 3 } else { 4 } {
                return None;
            }
        }
        if m.find_halfedge(vs[2], vs[3]).is_some() {
            return None;
        }
        let [pa, pb, pc, pd] = vs.map(|v| m.pos[v as usize]);
        let (n1, n2) = ((pb - pa).cross(pc - pa), (pa - pb).cross(pd - pb));
        let (m1, m2) = ((pd - pc).cross(pb - pc), (pc - pd).cross(pa - pd));
        let ok = normal_ok(n1, m1) && normal_ok(n2, m1) && normal_ok(n1, m2) && normal_ok(n2, m2);
        ok.then_some(vs)
    }

    /// Flips interior edges where that brings the four vertices' valences closer to 6 (4 on a
    /// boundary) in total absolute deviation, if [`Remesher::flippable`] and, where the new
    /// edge touches the boundary, it is no longer than `high`. Returns the number of flips.
    pub fn equalize_valences(&mut self) -> usize {
        let mut count = 0;
        for e in 0..self.m.n_edges() as u32 {
            let m = &self.m;
            if m.edel[e as usize] || m.is_boundary_edge(e) {
                continue;
            }
            let (h, o) = (2 * e, 2 * e + 1);
            let vs = [
                m.from(h),
                m.to[h as usize],
                m.opposite_vertex(h),
                m.opposite_vertex(o),
            ];
            let bnd = vs.map(|v| m.is_boundary_vertex(v));
            let val = vs.map(|v| m.valence(v) as i32);
            let dev = |k: usize, delta: i32| (val[k] + delta - target_valence(bnd[k])).abs();
            let before: i32 = (0..4).map(|k| dev(k, 0)).sum();
            let after = dev(0, -1) + dev(1, -1) + dev(2, 1) + dev(3, 1);
            if after >= before || self.flippable(e).is_none() {
                continue;
            }
            // A new edge at the boundary must not be long: nothing smooths it out there.
            let (pc, pd) = (m.pos[vs[2] as usize], m.pos[vs[3] as usize]);
            if (bnd[2] || bnd[3]) && pc.distance_squared(pd) > self.high * self.high {
                continue;
            }
            self.m.flip(e);
            count += 1;
        }
        self.stats.flips += count;
        count
    }

    /// Flips the interior edges of triangles with an angle below `min_angle_deg` where that
    /// raises the smaller of the two triangles' smallest angles (the Delaunay criterion,
    /// restricted to bad triangles so valences stay regular elsewhere); repeats while it makes
    /// progress, at most `max_sweeps` times. Returns the number of flips.
    pub fn flip_slivers(&mut self, min_angle_deg: f32, max_sweeps: usize) -> usize {
        let mut total = 0;
        for _ in 0..max_sweeps {
            let mut count = 0;
            for e in 0..self.m.n_edges() as u32 {
                let Some(vs) = self.flippable(e) else {
                    continue;
                };
                let [pa, pb, pc, pd] = vs.map(|v| self.m.pos[v as usize]);
                let before = min_angle(pa, pb, pc).min(min_angle(pb, pa, pd));
                let after = min_angle(pc, pd, pb).min(min_angle(pd, pc, pa));
                if before < min_angle_deg && after > before + 1.0 {
                    self.m.flip(e);
                    count += 1;
                }
            }
            total += count;
            if count == 0 {
                break;
            }
        }
        self.stats.flips += total;
        total
    }
}

/// Smallest angle (degrees) of triangle `(a, b, c)`; 0 when degenerate.
fn min_angle(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let ang = |p: Vec3, q: Vec3, r: Vec3| {
        let (u, v) = (q - p, r - p);
        u.cross(v).length().atan2(u.dot(v))
    };
    ang(a, b, c)
        .min(ang(b, c, a))
        .min(ang(c, a, b))
        .to_degrees()
}
