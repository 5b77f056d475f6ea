//! A compact half-edge mesh with the three local operators of isotropic remeshing: edge split,
//! edge flip and half-edge collapse.
//!
//! Half-edges come in pairs: half-edge `h` and its opposite `h ^ 1` form edge `h >> 1`. A
//! half-edge stores the vertex it points to, the next and previous half-edge around its face
//! (or around its hole for boundary half-edges, whose face is [`NONE`]) and its face. Every
//! vertex keeps one outgoing half-edge, the boundary one when the vertex is on a boundary, so
//! boundary tests are O(1). Removed elements are only flagged; [`HeMesh::compact`] drops them.
//!
//! The operators keep the mesh an oriented 2-manifold provided the caller checks the
//! preconditions documented on each (the remeshing passes in `ops.rs` do).

use glam::Vec3;

use crate::adjacency::EdgeTopology;

/// "No element": the face of a boundary half-edge, the loop of an interior vertex.
pub(crate) const NONE: u32 = u32::MAX;

/// What remeshing must respect at a vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct VTag {
    /// The input boundary loop the vertex lies on, [`NONE`] for an interior vertex.
    pub lp: u32,
    /// Arc length (metres) along that loop from its first vertex, in the direction the loop's
    /// faces traverse it; f64 so that wrap-around differences on long loops stay exact.
    pub s: f64,
    /// Never moved, never removed (a boundary corner, or any boundary vertex when the boundary
    /// is fixed).
    pub locked: bool,
}

impl VTag {
    /// An unconstrained interior vertex.
    pub const INTERIOR: VTag = VTag {
        lp: NONE,
        s: 0.0,
        locked: false,
    };
}

/// The half-edge mesh. See the module documentation for the layout.
#[derive(Clone, Debug, Default)]
pub(crate) struct HeMesh {
    /// `[V]` positions (metres).
    pub pos: Vec<Vec3>,
    /// `[V]` constraints.
    pub tag: Vec<VTag>,
    /// `[V]` one outgoing half-edge (the boundary one on a boundary); [`NONE`] once removed.
    pub vout: Vec<u32>,
    /// `[V]` removed flags.
    pub vdel: Vec<bool>,
    /// `[2E]` target vertex.
    pub to: Vec<u32>,
    /// `[2E]` next half-edge around the face (or hole).
    pub next: Vec<u32>,
    /// `[2E]` previous half-edge around the face (or hole).
    pub prev: Vec<u32>,
    /// `[2E]` face, [`NONE`] for a boundary half-edge.
    pub hface: Vec<u32>,
    /// `[E]` removed flags.
    pub edel: Vec<bool>,
    /// `[F]` one half-edge of each face.
    pub fhe: Vec<u32>,
    /// `[F]` removed flags.
    pub fdel: Vec<bool>,
}

/// Outgoing half-edges of a vertex, rotating with `next(opposite(h))`.
pub(crate) struct Outgoing<'a> {
    m: &'a HeMesh,
    start: u32,
    cur: u32,
}

impl Iterator for Outgoing<'_> {
    type Item = u32;
    #[inline]
    fn next(&mut self) -> Option<u32> {
        if self.cur == NONE {
            return None;
        }
        let h = self.cur;
        let n = self.m.next[(h ^ 1) as usize];
        self.cur = if n == self.start { NONE } else { n };
        Some(h)
    }
}

impl HeMesh {
    /// Builds the half-edge mesh of `faces` (`[F]`) over `pos` (`[V]`) with constraints `tag`
    /// (`[V]`). The caller guarantees a manifold, consistently oriented mesh without
    /// degenerate faces or unreferenced vertices, and `topo` built from the same faces.
    pub fn build(pos: Vec<Vec3>, tag: Vec<VTag>, faces: &[[u32; 3]], topo: &EdgeTopology) -> Self {
        let (nv, ne) = (pos.len(), topo.edges.len());
        let mut m = HeMesh {
            pos,
            tag,
            vout: vec![NONE; nv],
            vdel: vec![false; nv],
            to: vec![NONE; 2 * ne],
            next: vec![NONE; 2 * ne],
            prev: vec![NONE; 2 * ne],
            hface: vec![NONE; 2 * ne],
            edel: vec![false; ne],
            fhe: Vec::with_capacity(faces.len()),
            fdel: vec![false; faces.len()],
        };
        for (e, &[a, b]) in topo.edges.iter().enumerate() {
            m.to[2 * e] = b;
            m.to[2 * e + 1] = a;
        }
        for (fi, f) in faces.iter().enumerate() {
            let mut hs = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                let h = 2 * topo.face_edges[fi][k] + u32::from(a > b);
                hs[k] = h;
                m.hface[h as usize] = fi as u32;
                if m.vout[a as usize] == NONE {
                    m.vout[a as usize] = h;
                }
            }
            for k in 0..3 {
                m.link(hs[k], hs[(k + 1) % 3]);
            }
            m.fhe.push(hs[0]);
        }
        // Boundary half-edges: each boundary vertex has exactly one outgoing one.
        let mut bout = vec![NONE; nv];
        for h in 0..2 * ne as u32 {
            if m.hface[h as usize] == NONE {
                bout[m.from(h) as usize] = h;
            }
        }
        for h in 0..2 * ne as u32 {
            if m.hface[h as usize] == NONE {
                let n = bout[m.to[h as usize] as usize];
                m.link(h, n);
            }
        }
        for (v, &b) in bout.iter().enumerate() {
            if b != NONE {
                m.vout[v] = b;
            }
        }
        m
    }

    /// Number of vertex slots (removed ones included).
    #[inline]
    pub fn n_vertices(&self) -> usize {
        self.pos.len()
    }

    /// Number of edge slots (removed ones included).
    #[inline]
    pub fn n_edges(&self) -> usize {
        self.edel.len()
    }

    #[inline]
    fn link(&mut self, a: u32, b: u32) {
        self.next[a as usize] = b;
        self.prev[b as usize] = a;
    }

    /// Source vertex of `h`.
    #[inline]
    pub fn from(&self, h: u32) -> u32 {
        self.to[(h ^ 1) as usize]
    }

    /// Vertex opposite half-edge `h` in its face (meaningless for a boundary half-edge).
    #[inline]
    pub fn opposite_vertex(&self, h: u32) -> u32 {
        self.to[self.next[h as usize] as usize]
    }

    /// Whether `h` has no face.
    #[inline]
    pub fn is_boundary_he(&self, h: u32) -> bool {
        self.hface[h as usize] == NONE
    }

    /// Whether edge `e` has only one face.
    #[inline]
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.is_boundary_he(2 * e) || self.is_boundary_he(2 * e + 1)
    }

    /// Whether vertex `v` lies on a boundary.
    #[inline]
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        let h = self.vout[v as usize];
        h != NONE && self.is_boundary_he(h)
    }

    /// Outgoing half-edges of `v` (none for a removed vertex).
    #[inline]
    pub fn outgoing(&self, v: u32) -> Outgoing<'_> {
        let h = self.vout[v as usize];
        Outgoing {
            m: self,
            start: h,
            cur: h,
        }
    }

    /// Number of edges at `v`.
    #[inline]
    pub fn valence(&self, v: u32) -> u32 {
        self.outgoing(v).count() as u32
    }

    /// The half-edge from `a` to `b`, if the edge exists.
    pub fn find_halfedge(&self, a: u32, b: u32) -> Option<u32> {
        self.outgoing(a).find(|&h| self.to[h as usize] == b)
    }

    /// The three vertices of face `f`, in its orientation.
    #[inline]
    pub fn face_vertices(&self, f: u32) -> [u32; 3] {
        let h = self.fhe[f as usize];
        [
            self.from(h),
            self.to[h as usize],
            self.to[self.next[h as usize] as usize],
        ]
    }

    /// Points `vout[v]` at its boundary half-edge if it has one.
    fn adjust_outgoing(&mut self, v: u32) {
        if let Some(h) = self.outgoing(v).find(|&h| self.is_boundary_he(h)) {
            self.vout[v as usize] = h;
        }
    }

    fn new_edge(&mut self, a: u32, b: u32) -> u32 {
        let h = self.to.len() as u32;
        self.to.extend_from_slice(&[b, a]);
        self.next.extend_from_slice(&[NONE, NONE]);
        self.prev.extend_from_slice(&[NONE, NONE]);
        self.hface.extend_from_slice(&[NONE, NONE]);
        self.edel.push(false);
        h
    }

    fn new_face(&mut self, h: u32) -> u32 {
        self.fhe.push(h);
        self.fdel.push(false);
        (self.fhe.len() - 1) as u32
    }

    /// Splits the triangle whose half-edges run `h1 (a->m), h2 (m->b), hn (b->c), hp (c->a)`
    /// (a quadrilateral after an edge split) with the diagonal m-c: `(a, m, c)` keeps the face
    /// of `h1`, `(m, b, c)` gets a new face.
    fn split_face(&mut self, h1: u32, h2: u32) {
        let hn = self.next[h2 as usize];
        let hp = self.prev[h1 as usize];
        let f = self.hface[h1 as usize];
        let (m, c) = (self.to[h1 as usize], self.to[hn as usize]);
        let x = self.new_edge(m, c); // x: m -> c, x ^ 1: c -> m
        let y = x ^ 1;
        self.link(h1, x);
        self.link(x, hp);
        self.hface[x as usize] = f;
        self.fhe[f as usize] = h1;
        let g = self.new_face(h2);
        self.link(h2, hn);
        self.link(hn, y);
        self.link(y, h2);
        for h in [h2, hn, y] {
            self.hface[h as usize] = g;
        }
    }

    /// Splits edge `e` at `p` with a new vertex tagged `tag`, triangulating its one or two
    /// faces from the new vertex; returns the new vertex. Always valid.
    pub fn split_edge(&mut self, e: u32, p: Vec3, tag: VTag) -> u32 {
        let (h, o) = (2 * e, 2 * e + 1);
        let (a, b) = (self.to[o as usize], self.to[h as usize]);
        let m = self.pos.len() as u32;
        self.pos.push(p);
        self.tag.push(tag);
        self.vdel.push(false);
        self.vout.push(NONE);
        // h: a -> m, h2: m -> b, o2: b -> m, o: m -> a.
        let h2 = self.new_edge(m, b);
        let o2 = h2 ^ 1;
        let (hn, op) = (self.next[h as usize], self.prev[o as usize]);
        self.to[h as usize] = m;
        self.hface[h2 as usize] = self.hface[h as usize];
        self.hface[o2 as usize] = self.hface[o as usize];
        self.link(h, h2);
        self.link(h2, hn);
        self.link(op, o2);
        self.link(o2, o);
        if self.vout[b as usize] == o {
            self.vout[b as usize] = o2;
        }
        self.vout[m as usize] = if self.is_boundary_he(o) { o } else { h2 };
        if !self.is_boundary_he(h) {
            self.split_face(h, h2);
        }
        if !self.is_boundary_he(o) {
            self.split_face(o2, o);
        }
        let _ = a;
        m
    }

    /// Flips interior edge `e` between faces `(a, b, c)` and `(b, a, d)` to the diagonal c-d.
    /// The caller checks that `e` is interior, that c-d is not an edge already and that a and
    /// b keep at least three edges (two for a boundary vertex).
    pub fn flip(&mut self, e: u32) {
        let (h, o) = (2 * e, 2 * e + 1);
        let (hn, hp) = (self.next[h as usize], self.prev[h as usize]);
        let (on, op) = (self.next[o as usize], self.prev[o as usize]);
        let (fh, fo) = (self.hface[h as usize], self.hface[o as usize]);
        let (a, b) = (self.to[o as usize], self.to[h as usize]);
        let (c, d) = (self.to[hn as usize], self.to[on as usize]);
        // o: c -> d in (c, d, b) = o, op, hn; h: d -> c in (d, c, a) = h, hp, on.
        self.to[o as usize] = d;
        self.to[h as usize] = c;
        self.link(o, op);
        self.link(op, hn);
        self.link(hn, o);
        self.link(h, hp);
        self.link(hp, on);
        self.link(on, h);
        self.hface[hn as usize] = fo;
        self.hface[on as usize] = fh;
        self.fhe[fo as usize] = o;
        self.fhe[fh as usize] = h;
        if self.vout[a as usize] == h {
            self.vout[a as usize] = on;
        }
        if self.vout[b as usize] == o {
            self.vout[b as usize] = hn;
        }
        let _ = (c, d);
    }

    /// Collapses half-edge `h` (v0 -> v1): v0 is removed and its edges move to v1, whose
    /// position is left as it is. The faces on either side of the edge disappear. The caller
    /// checks the link condition and the valences of the opposite vertices.
    pub fn collapse(&mut self, h: u32) {
        let o = h ^ 1;
        let (v0, v1) = (self.to[o as usize], self.to[h as usize]);
        let (hn, hp) = (self.next[h as usize], self.prev[h as usize]);
        let (on, op) = (self.next[o as usize], self.prev[o as usize]);
        let (fh, fo) = (self.hface[h as usize], self.hface[o as usize]);
        // Every half-edge into v0 now points at v1 (rotation reads only `next`).
        let start = self.vout[v0 as usize];
        let mut x = start;
        loop {
            self.to[(x ^ 1) as usize] = v1;
            x = self.next[(x ^ 1) as usize];
            if x == start {
                break;
            }
        }
        self.link(hp, hn);
        self.link(op, on);
        if fh != NONE {
            self.fhe[fh as usize] = hn;
        }
        if fo != NONE {
            self.fhe[fo as usize] = on;
        }
        if self.vout[v1 as usize] == o {
            self.vout[v1 as usize] = hn;
        }
        self.edel[(h >> 1) as usize] = true;
        self.vdel[v0 as usize] = true;
        self.vout[v0 as usize] = NONE;
        if fh != NONE {
            self.remove_loop(hn);
        }
        if fo != NONE {
            self.remove_loop(on);
        }
        self.adjust_outgoing(v1);
    }

    /// Removes the two-sided face of `h0` (v1 -> vl) and `h1 = next(h0)` (vl -> v1) left by a
    /// collapse: `h1` takes the place of `opposite(h0)`, whose edge is removed.
    fn remove_loop(&mut self, h0: u32) {
        let h1 = self.next[h0 as usize];
        let o0 = h0 ^ 1;
        let (v1, vl) = (self.from(h0), self.to[h0 as usize]);
        let f = self.hface[h0 as usize];
        let g = self.hface[o0 as usize];
        let (o0n, o0p) = (self.next[o0 as usize], self.prev[o0 as usize]);
        self.link(o0p, h1);
        self.link(h1, o0n);
        self.hface[h1 as usize] = g;
        if g != NONE && self.fhe[g as usize] == o0 {
            self.fhe[g as usize] = h1;
        }
        if self.vout[vl as usize] == o0 {
            self.vout[vl as usize] = h1;
        }
        if self.vout[v1 as usize] == h0 {
            self.vout[v1 as usize] = h1 ^ 1;
        }
        self.adjust_outgoing(vl);
        self.adjust_outgoing(v1);
        self.fdel[f as usize] = true;
        self.edel[(h0 >> 1) as usize] = true;
    }

    /// Drops removed elements, keeping the order of the rest (so results stay deterministic).
    pub fn compact(&mut self) {
        let vmap = renumber(&self.vdel);
        let emap = renumber(&self.edel);
        let fmap = renumber(&self.fdel);
        let hmap = |h: u32| -> u32 {
            if h == NONE {
                NONE
            } else {
                2 * emap[(h >> 1) as usize] + (h & 1)
            }
        };
        let keep_v: Vec<usize> = (0..self.vdel.len()).filter(|&v| !self.vdel[v]).collect();
        let keep_h: Vec<usize> = (0..self.to.len()).filter(|&h| !self.edel[h >> 1]).collect();
        let keep_f: Vec<usize> = (0..self.fdel.len()).filter(|&f| !self.fdel[f]).collect();
        self.pos = keep_v.iter().map(|&v| self.pos[v]).collect();
        self.tag = keep_v.iter().map(|&v| self.tag[v]).collect();
        self.vout = keep_v.iter().map(|&v| hmap(self.vout[v])).collect();
        self.vdel = vec![false; keep_v.len()];
        self.to = keep_h.iter().map(|&h| vmap[self.to[h] as usize]).collect();
        self.next = keep_h.iter().map(|&h| hmap(self.next[h])).collect();
        self.prev = keep_h.iter().map(|&h| hmap(self.prev[h])).collect();
        self.hface = keep_h
            .iter()
            .map(|&h| match self.hface[h] {
                NONE => NONE,
                f => fmap[f as usize],
            })
            .collect();
        self.edel = vec![false; keep_h.len() / 2];
        self.fhe = keep_f.iter().map(|&f| hmap(self.fhe[f])).collect();
        self.fdel = vec![false; keep_f.len()];
    }

    /// Live faces `[F]` as vertex triples (valid indices only after [`HeMesh::compact`]).
    pub fn faces(&self) -> Vec<[u32; 3]> {
        (0..self.fhe.len() as u32)
            .filter(|&f| !self.fdel[f as usize])
            .map(|f| self.face_vertices(f))
            .collect()
    }

    /// Checks every structural invariant; `Err` names the first broken one. For tests.
    #[cfg(test)]
    pub fn check(&self) -> Result<(), String> {
        let nh = self.to.len() as u32;
        for h in 0..nh {
            if self.edel[(h >> 1) as usize] {
                continue;
            }
            let (n, p) = (self.next[h as usize], self.prev[h as usize]);
            if n >= nh || p >= nh || self.edel[(n >> 1) as usize] || self.edel[(p >> 1) as usize] {
                return Err(format!("half-edge {h}: dangling next/prev"));
            }
            if self.prev[n as usize] != h || self.next[p as usize] != h {
                return Err(format!("half-edge {h}: next/prev disagree"));
            }
            if self.from(n) != self.to[h as usize] {
                return Err(format!("half-edge {h}: next does not start at its end"));
            }
            if self.hface[n as usize] != self.hface[h as usize] {
                return Err(format!("half-edge {h}: next in another face"));
            }
            let f = self.hface[h as usize];
            if f != NONE {
                if self.fdel[f as usize] {
                    return Err(format!("half-edge {h}: removed face {f}"));
                }
                if self.next[self.next[n as usize] as usize] != h {
                    return Err(format!("half-edge {h}: face {f} is not a triangle"));
                }
            }
            let v = self.to[h as usize];
            if self.vdel[v as usize] {
                return Err(format!("half-edge {h}: points at removed vertex {v}"));
            }
            if self.hface[h as usize] == NONE && self.hface[(h ^ 1) as usize] == NONE {
                return Err(format!("edge {}: no face", h >> 1));
            }
        }
        for f in 0..self.fhe.len() {
            if !self.fdel[f] && self.hface[self.fhe[f] as usize] != f as u32 {
                return Err(format!("face {f}: half-edge in another face"));
            }
        }
        for v in 0..self.pos.len() as u32 {
            if self.vdel[v as usize] {
                continue;
            }
            let h = self.vout[v as usize];
            if h == NONE || self.edel[(h >> 1) as usize] || self.from(h) != v {
                return Err(format!("vertex {v}: bad outgoing half-edge"));
            }
            let out: Vec<u32> = self.outgoing(v).take(10_000).collect();
            if out.iter().any(|&x| self.from(x) != v) {
                return Err(format!("vertex {v}: rotation leaves the vertex"));
            }
            let nb = out.iter().filter(|&&x| self.is_boundary_he(x)).count();
            if nb > 1 || (nb == 1 && !self.is_boundary_he(h)) {
                return Err(format!(
                    "vertex {v}: {nb} boundary half-edges, vout not one"
                ));
            }
        }
        Ok(())
    }
}

/// New indices for the kept (`!removed`) slots, [`NONE`] for removed ones.
fn renumber(removed: &[bool]) -> Vec<u32> {
    let mut next = 0u32;
    removed
        .iter()
        .map(|&r| {
            if r {
                NONE
            } else {
                next += 1;
                next - 1
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::adjacency::{boundary_loops, check_manifold};
    use crate::TriMesh;

    fn he(m: &TriMesh) -> HeMesh {
        let topo = EdgeTopology::new(m.vertices.len(), &m.faces).unwrap();
        let tags = vec![VTag::INTERIOR; m.vertices.len()];
        let h = HeMesh::build(m.vertices.clone(), tags, &m.faces, &topo);
        h.check().unwrap();
        h
    }

    fn assert_ok(h: &mut HeMesh, chi: i64, loops: usize) {
        h.check().unwrap();
        h.compact();
        h.check().unwrap();
        let faces = h.faces();
        let r = check_manifold(h.pos.len(), &faces).unwrap();
        assert!(r.is_ok(), "{r}");
        assert_eq!(r.unreferenced_vertices, 0, "{r}");
        assert_eq!(r.euler_characteristic(), chi, "{r}");
        assert_eq!(boundary_loops(h.pos.len(), &faces).unwrap().len(), loops);
    }

    #[test]
    fn build_round_trips() {
        for m in [TriMesh::icosphere(1, 1.0), TriMesh::grid(4, 3, 1.0)] {
            let mut h = he(&m);
            assert_eq!(h.faces(), m.faces);
            let loops = usize::from(m.faces.len() == 12);
            assert_ok(&mut h, if loops == 1 { 1 } else { 2 }, loops);
            assert_eq!(h.valence(0), if loops == 1 { 2 } else { 5 });
        }
    }

    /// Runs many splits, flips and collapses (preconditions checked crudely here) and checks
    /// every invariant after each.
    #[test]
    fn random_operations_keep_invariants() {
        for (m, chi, loops) in [
            (TriMesh::icosphere(2, 1.0), 2, 0),
            (TriMesh::grid(7, 6, 0.1), 1, 1),
        ] {
            let mut h = he(&m);
            let mut seed = 12345u64;
            let mut rnd = |n: usize| {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (seed >> 33) as usize % n
            };
            let mut done = [0usize; 3];
            for _ in 0..3000 {
                let e = rnd(h.n_edges()) as u32;
                if h.edel[e as usize] {
                    continue;
                }
                let (a, b) = (h.from(2 * e), h.to[2 * e as usize]);
                match rnd(3) {
                    0 if h.n_vertices() < 400 => {
                        let p = (h.pos[a as usize] + h.pos[b as usize]) * 0.5;
                        h.split_edge(e, p, VTag::INTERIOR);
                        done[0] += 1;
                    }
                    1 if !h.is_boundary_edge(e) => {
                        let (c, d) = (h.opposite_vertex(2 * e), h.opposite_vertex(2 * e + 1));
                        let min_ab = |v: u32| if h.is_boundary_vertex(v) { 3 } else { 4 };
                        if h.find_halfedge(c, d).is_none()
                            && h.valence(a) >= min_ab(a)
                            && h.valence(b) >= min_ab(b)
                        {
                            h.flip(e);
                            done[1] += 1;
                        }
                    }
                    2 if topo_collapse_ok(&h, 2 * e) => {
                        h.collapse(2 * e);
                        done[2] += 1;
                    }
                    _ => {}
                }
                h.check().unwrap();
            }
            assert!(done.iter().all(|&d| d > 50), "{done:?}");
            assert_ok(&mut h, chi, loops);
        }
    }

    /// Link condition, boundary rules and opposite valences (as the remesher checks them).
    fn topo_collapse_ok(h: &HeMesh, hh: u32) -> bool {
        let (v0, v1) = (h.from(hh), h.to[hh as usize]);
        let eb = h.is_boundary_edge(hh >> 1);
        if h.is_boundary_vertex(v0) && (!eb || !h.is_boundary_vertex(v1)) {
            return false;
        }
        let mut opp = Vec::new();
        for x in [hh, hh ^ 1] {
            if !h.is_boundary_he(x) {
                let w = h.opposite_vertex(x);
                let min = if h.is_boundary_vertex(w) { 3 } else { 4 };
                if h.valence(w) < min {
                    return false;
                }
                opp.push(w);
            }
        }
        if eb {
            // The hole must keep three edges.
            let hb = if h.is_boundary_he(hh) { hh } else { hh ^ 1 };
            let n = h.next[hb as usize];
            if h.next[h.next[n as usize] as usize] == hb {
                return false;
            }
        }
        let n0: Vec<u32> = h.outgoing(v0).map(|x| h.to[x as usize]).collect();
        let common = h
            .outgoing(v1)
            .filter(|&x| n0.contains(&h.to[x as usize]))
            .count();
        common == opp.len()
    }

    #[test]
    fn split_flip_collapse_by_hand() {
        // Two triangles (0, 1, 2), (2, 1, 3): split the shared edge, flip, collapse back.
        let m = TriMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)],
            vec![[0, 1, 2], [2, 1, 3]],
        );
        let mut h = he(&m);
        let e = (0..h.n_edges() as u32)
            .find(|&e| !h.is_boundary_edge(e))
            .unwrap();
        let v = h.split_edge(e, Vec3::new(0.5, 0.5, 0.0), VTag::INTERIOR);
        h.check().unwrap();
        assert_eq!(h.faces().len(), 4);
        assert_eq!(h.valence(v), 4);
        assert!(!h.is_boundary_vertex(v));
        // Split a boundary edge: the new vertex is on the boundary.
        let eb = (h.find_halfedge(0, 1).unwrap()) >> 1;
        let w = h.split_edge(eb, Vec3::new(0.5, 0.0, 0.0), VTag::INTERIOR);
        h.check().unwrap();
        assert!(h.is_boundary_vertex(w));
        assert_eq!(h.valence(w), 3);
        // Collapse it back into vertex 0.
        let hw = h.find_halfedge(w, 0).unwrap();
        h.collapse(hw);
        h.check().unwrap();
        assert_eq!(h.faces().len(), 4);
        let mut h2 = h.clone();
        assert_ok(&mut h2, 1, 1);
    }
}
