//! Top-down BVH construction with a binned surface-area heuristic.

use glam::Vec3;

use super::{Node, MAX_LEAF};

const BINS: usize = 16;
/// Above this many faces a node is always split, even when the SAH prefers a leaf.
const FORCE_SPLIT: usize = 16;

#[derive(Clone, Copy)]
struct Aabb {
    min: Vec3,
    max: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, o: &Aabb) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }

    fn grow_point(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Half the surface area (the constant factor does not matter to the SAH).
    fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// Builds nodes (boxes left empty, filled by the refit) and the face order. Vertices and
/// indices are already validated.
pub(super) fn build(vertices: &[Vec3], faces: &[[u32; 3]]) -> (Vec<Node>, Vec<u32>) {
    let nf = faces.len();
    if nf == 0 {
        return (Vec::new(), Vec::new());
    }
    let boxes: Vec<Aabb> = faces
        .iter()
        .map(|f| {
            let mut b = Aabb::EMPTY;
            for &v in f {
                b.grow_point(vertices[v as usize]);
            }
            b
        })
        .collect();
    let centroids: Vec<Vec3> = boxes.iter().map(|b| 0.5 * (b.min + b.max)).collect();
    let mut order: Vec<u32> = (0..nf as u32).collect();
    let mut nodes = Vec::with_capacity(2 * nf / MAX_LEAF + 1);
    nodes.push(Node::default());
    let mut stack = vec![(0usize, 0usize, nf)];
    while let Some((ni, start, end)) = stack.pop() {
        let count = end - start;
        let mut bounds = Aabb::EMPTY;
        let mut cbounds = Aabb::EMPTY;
        for &f in &order[start..end] {
            bounds.grow(&boxes[f as usize]);
            cbounds.grow_point(centroids[f as usize]);
        }
        if count <= MAX_LEAF {
            nodes[ni] = Node {
                start: start as u32,
                count: count as u32,
                ..Default::default()
            };
            continue;
        }
        let mid = match best_split(&order[start..end], &boxes, &centroids, &cbounds) {
            Some(s) if s.cost < count as f32 * bounds.half_area() || count > FORCE_SPLIT => {
                let slice = &mut order[start..end];
                let mut left = 0;
                for i in 0..slice.len() {
                    if s.bin(centroids[slice[i] as usize]) < s.bin_index {
                        slice.swap(i, left);
                        left += 1;
                    }
                }
                if left == 0 || left == count {
                    start + count / 2
                } else {
                    start + left
                }
            }
            Some(_) => {
                nodes[ni] = Node {
                    start: start as u32,
                    count: count as u32,
                    ..Default::default()
                };
                continue;
            }
            // All centroids coincide: any split is as good as another.
            None => start + count / 2,
        };
        let left = nodes.len();
        nodes.push(Node::default());
        nodes.push(Node::default());
        nodes[ni] = Node {
            start: left as u32,
            count: 0,
            ..Default::default()
        };
        stack.push((left + 1, mid, end));
        stack.push((left, start, mid));
    }
    (nodes, order)
}

/// A candidate split: faces whose centroid falls in a bin below `bin_index` go left.
#[derive(Clone, Copy)]
struct Split {
    axis: usize,
    lo: f32,
    scale: f32,
    bin_index: usize,
    /// `half_area(left) * n_left + half_area(right) * n_right`.
    cost: f32,
}

impl Split {
    #[inline]
    fn bin(&self, c: Vec3) -> usize {
        (((c[self.axis] - self.lo) * self.scale) as usize).min(BINS - 1)
    }
}

/// The cheapest binned SAH split over the three axes; `None` if the centroids all coincide.
fn best_split(faces: &[u32], boxes: &[Aabb], centroids: &[Vec3], cb: &Aabb) -> Option<Split> {
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        let (lo, hi) = (cb.min[axis], cb.max[axis]);
        let extent = hi - lo;
        if extent <= 0.0 || !extent.is_finite() {
            continue;
        }
        let scale = BINS as f32 / extent;
        let mut bin_box = [Aabb::EMPTY; BINS];
        let mut bin_n = [0usize; BINS];
        let probe = Split {
            axis,
            lo,
            scale,
            bin_index: 0,
            cost: 0.0,
        };
        for &f in faces {
            let b = probe.bin(centroids[f as usize]);
            bin_box[b].grow(&boxes[f as usize]);
            bin_n[b] += 1;
        }
        // Sweep from the right: cost of the right side for every split.
        let mut right_cost = [0f32; BINS];
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for i in (1..BINS).rev() {
            acc.grow(&bin_box[i]);
            n += bin_n[i];
            right_cost[i] = if n > 0 {
                acc.half_area() * n as f32
            } else {
                0.0
            };
        }
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for i in 1..BINS {
            acc.grow(&bin_box[i - 1]);
            n += bin_n[i - 1];
            if n == 0 || n == faces.len() {
                continue;
            }
            let cost = acc.half_area() * n as f32 + right_cost[i];
            if best.is_none_or(|b| cost < b.cost) {
                best = Some(Split {
                    bin_index: i,
                    cost,
                    ..probe
                });
            }
        }
    }
    best
}
