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
                let p = 0.5 * (self.m.pos[self.m.from(2 * e) as usize] + self.m.pos[self.m.to[2 * e as usize] as usize]);
                self.m.split_edge(e, p, VTag::INTERIOR);
            }
            count += 1;
            // Stay on `e`: its remaining half may still be too long.
        }
        self.stats.splits += count;
        count
    }

    /// Whether collapsing `h` (removing its source v0 into its target v1, which does not move)
    /// keeps the mesh manifold with the same boundary loops, flips no face and creates no
    /// edge longer than `high`.
    fn collapse_ok(&mut self, h: u32) -> bool {
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
        // Geometry: short enough edges, no face turned over.
        let (p0, p1) = (m.pos[v0 as usize], m.pos[v1 as usize]);
        let high2 = self.high * self.high;
        let (fh, fo) = (m.hface[h as usize], m.hface[o as usize]);
        for x in m.outgoing(v0) {
            let w = m.to[x as usize];
            if w == v1 {
                continue;
            }
            let pw = m.pos[w as usize];
            if p1.distance_squared(pw) > high2 {
                return false;
            }
            let f = m.hface[x as usize];
            if f != NONE && f != fh && f != fo {
                let py = m.pos[m.opposite_vertex(x) as usize];
                if !normal_ok((pw - p0).cross(py - p0), (pw - p1).cross(py - p1)) {
                    return false;
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
                let h = if self.collapse_ok(2 * e) {
                    2 * e
                } else if self.collapse_ok(2 * e + 1) {
                    2 * e + 1
                } else {
                    continue;
                };
                let v0 = self.m.from(h);
                if self.m.is_boundary_vertex(v0) {
                    self.loop_len[self.m.tag[v0 as usize].lp as usize] -= 1;
                }
                self.m.collapse(h);
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

    /// Flips interior edges where that brings the four vertices' valences closer to 6 (4 on a
    /// boundary) in total absolute deviation, unless the flip would duplicate an edge, leave a
    /// vertex with too few faces, or turn a face by more than 45 degrees. Returns the number
    /// of flips.
    pub fn equalize_valences(&mut self) -> usize {
        let mut count = 0;
        for e in 0..self.m.n_edges() as u32 {
            let m = &self.m;
            if m.edel[e as usize] || m.is_boundary_edge(e) {
                continue;
            }
            let (h, o) = (2 * e, 2 * e + 1);
            let (a, b) = (m.from(h), m.to[h as usize]);
            let (c, d) = (m.opposite_vertex(h), m.opposite_vertex(o));
            let vs = [a, b, c, d];
            let bnd = vs.map(|v| m.is_boundary_vertex(v));
            let val = vs.map(|v| m.valence(v) as i32);
            let dev = |k: usize, delta: i32| (val[k] + delta - target_valence(bnd[k])).abs();
            let before: i32 = (0..4).map(|k| dev(k, 0)).sum();
            let after = dev(0, -1) + dev(1, -1) + dev(2, 1) + dev(3, 1);
            if after >= before {
                continue;
            }
            if val[0] < if bnd[0] { 3 } else { 4 } || val[1] < if bnd[1] { 3 } else { 4 } {
                continue;
            }
            if m.find_halfedge(c, d).is_some() {
                continue;
            }
            let [pa, pb, pc, pd] = vs.map(|v| m.pos[v as usize]);
            let (n1, n2) = ((pb - pa).cross(pc - pa), (pa - pb).cross(pd - pb));
            let (m1, m2) = ((pd - pc).cross(pb - pc), (pc - pd).cross(pa - pd));
            if !(normal_ok(n1, m1) && normal_ok(n2, m1) && normal_ok(n1, m2) && normal_ok(n2, m2))
            {
                continue;
            }
            self.m.flip(e);
            count += 1;
        }
        self.stats.flips += count;
        count
    }
}
