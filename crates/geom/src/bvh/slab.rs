//! Rays and segments against the tree's boxes: the slab test and the walk over the leaves a
//! ray passes through, shared by the inside tests and the segment queries.

use glam::{Vec3, Vec3A};

use super::{Bvh, Node};

/// A ray `o + t d`, `t in [0, t_max]`, set up for slab tests against many boxes.
pub(super) struct Slabs {
    o: Vec3A,
    d: Vec3A,
    inv: Vec3A,
    t_max: f32,
    /// Every component of `d` has a finite, non-zero reciprocal, so the SIMD test applies.
    general: bool,
}

impl Slabs {
    /// The ray from `o` along `d` (any length; `t` counts in units of `d`) up to `t_max`.
    pub(super) fn new(o: Vec3, d: Vec3, t_max: f32) -> Slabs {
        let inv = d.recip();
        Slabs {
            o: o.into(),
            d: d.into(),
            inv: inv.into(),
            t_max,
            general: inv.is_finite() && d.cmpne(Vec3::ZERO).all(),
        }
    }

    /// Whether the ray meets the box of `n`.
    ///
    /// Four lanes at once (`minps`/`maxps`) where the plain test spent its time in the NaN
    /// handling of `f32::min`/`max`, one axis at a time. It gives the same answer as
    /// [`Slabs::hits_scalar`] for finite boxes: the same products, and the order of the
    /// minima and maxima does not change them.
    #[inline]
    pub(super) fn hits(&self, n: &Node) -> bool {
        if !self.general {
            return self.hits_scalar(n);
        }
        let a = (Vec3A::from(n.min) - self.o) * self.inv;
        let b = (Vec3A::from(n.max) - self.o) * self.inv;
        let t0 = a.min(b).max_element().max(0.0);
        let t1 = a.max(b).min_element().min(self.t_max);
        t0 <= t1
    }

    /// The plain slab test, one axis at a time (also the reference for [`Slabs::hits`]);
    /// an axis the ray does not move along keeps it only when its origin lies in the slab.
    pub(super) fn hits_scalar(&self, n: &Node) -> bool {
        let (o, d, inv) = (self.o, self.d, self.inv);
        let (mut t0, mut t1) = (0.0f32, self.t_max);
        for k in 0..3 {
            if d[k] == 0.0 {
                if o[k] < n.min[k] || o[k] > n.max[k] {
                    return false;
                }
                continue;
            }
            let a = (n.min[k] - o[k]) * inv[k];
            let b = (n.max[k] - o[k]) * inv[k];
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
            if t0 > t1 {
                return false;
            }
        }
        true
    }
}

impl Bvh {
    /// Calls `f(face)` for every face in a leaf whose box the ray meets, depth first; stops
    /// when `f` returns `false`.
    pub(super) fn for_each_face_on_ray(&self, ray: &Slabs, mut f: impl FnMut(u32) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(ni) = stack.pop() {
            let n = &self.nodes[ni as usize];
            if !ray.hits(n) {
                continue;
            }
            if n.is_leaf() {
                for &fi in self.leaf_faces(n) {
                    if !f(fi) {
                        return;
                    }
                }
            } else {
                stack.push(n.start);
                stack.push(n.start + 1);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::tests::Rng;

    #[test]
    fn simd_slab_test_matches_the_scalar_one() {
        let mut rng = Rng(17);
        let mut agree = [0usize; 2];
        for i in 0..20000 {
            let c = rng.vec3(1.0);
            let h = rng.vec3(0.5).abs();
            let n = Node {
                min: c - h,
                max: c + h,
                start: 0,
                count: 1,
            };
            let mut d = rng.vec3(1.0);
            // Axis-parallel rays and rays that start inside the box or on its faces.
            if i % 7 == 0 {
                d.y = 0.0;
            }
            let o = match i % 5 {
                0 => c,
                1 => Vec3::new(n.min.x, c.y, c.z),
                _ => rng.vec3(2.0),
            };
            let t_max = if i % 3 == 0 { f32::INFINITY } else { 1.5 };
            let ray = Slabs::new(o, d, t_max);
            let hit = ray.hits(&n);
            assert_eq!(hit, ray.hits_scalar(&n), "o {o} d {d} box {n:?}");
            agree[hit as usize] += 1;
        }
        // Both answers occur often enough for the comparison to mean something.
        assert!(agree[0] > 2000 && agree[1] > 2000, "{agree:?}");
    }
}
