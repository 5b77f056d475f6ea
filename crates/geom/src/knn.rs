//! k nearest neighbours among a point set (squared Euclidean distance), on kiddo's
//! `ImmutableKdTree`, parallel over queries; plus a brute-force reference.

use std::num::NonZeroUsize;

use glam::Vec3;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;

use crate::error::{GeomError, Result};

/// Leaf bucket size of the k-d tree.
const BUCKET: usize = 32;

/// Results of a k-nearest-neighbour query for Q points, row-major.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KnnResult {
    /// Neighbours per query, K.
    pub k: usize,
    /// `[Q*K]`: row `q` holds the indices of the K points nearest to query `q`, nearest first.
    pub indices: Vec<u32>,
    /// `[Q*K]`: the matching squared distances (square metres), ascending in each row.
    pub sq_distances: Vec<f32>,
}

impl KnnResult {
    /// Number of queries Q.
    pub fn num_queries(&self) -> usize {
        self.indices.len().checked_div(self.k).unwrap_or(0)
    }

    /// Neighbour indices of query `q` (`[K]`); empty if `q` is out of range.
    pub fn row(&self, q: usize) -> &[u32] {
        self.indices
            .get(q * self.k..(q + 1) * self.k)
            .unwrap_or(&[])
    }

    /// Squared distances of query `q` (`[K]`); empty if `q` is out of range.
    pub fn sq_row(&self, q: usize) -> &[f32] {
        self.sq_distances
            .get(q * self.k..(q + 1) * self.k)
            .unwrap_or(&[])
    }
}

/// A k-d tree over a fixed point set `[P]`, built once, queried many times.
pub struct KnnIndex {
    tree: ImmutableKdTree<f32, u32, 3, BUCKET>,
    len: usize,
}

impl std::fmt::Debug for KnnIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KnnIndex").field("len", &self.len).finish()
    }
}

fn check_points(what: &str, pts: &[Vec3]) -> Result<()> {
    if let Some(i) = pts.iter().position(|p| !p.is_finite()) {
        return Err(GeomError::InvalidInput(format!(
            "{what} {i} is not finite: {}",
            pts[i]
        )));
    }
    Ok(())
}

fn check_k(k: usize, n: usize) -> Result<NonZeroUsize> {
    let nz = NonZeroUsize::new(k)
        .ok_or_else(|| GeomError::InvalidInput("k must be at least 1".into()))?;
    if k > n {
        return Err(GeomError::InvalidInput(format!(
            "k = {k} exceeds the {n} points"
        )));
    }
    Ok(nz)
}

impl KnnIndex {
    /// Builds the tree over `points` (`[P]`, metres). Fails on non-finite coordinates or more
    /// than `u32::MAX` points; an empty set is allowed (every query then fails).
    pub fn new(points: &[Vec3]) -> Result<KnnIndex> {
        check_points("point", points)?;
        if points.len() > u32::MAX as usize {
            return Err(GeomError::InvalidInput(
                "too many points for u32 indices".into(),
            ));
        }
        let arr: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
        Ok(KnnIndex {
            tree: ImmutableKdTree::new_from_slice(&arr),
            len: points.len(),
        })
    }

    /// Number of indexed points P.
    pub fn len(&self) -> usize {
        self.len
    }

    /// `true` when no point is indexed.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The `k` nearest indexed points of each of `queries` (`[Q]`), in parallel: `[Q*K]`
    /// indices and squared distances, nearest first. Ties are broken by the tree (any of the
    /// equidistant points may come first). Fails when `k` is 0 or above P, or a query is not
    /// finite.
    pub fn query(&self, queries: &[Vec3], k: usize) -> Result<KnnResult> {
        let kk = check_k(k, self.len)?;
        check_points("query", queries)?;
        let mut indices = vec![0u32; queries.len() * k];
        let mut sq = vec![0f32; queries.len() * k];
        indices
            .par_chunks_mut(k)
            .zip(sq.par_chunks_mut(k))
            .zip(queries.par_iter())
            .for_each(|((ir, dr), q)| {
                let found = self.tree.nearest_n::<SquaredEuclidean>(&q.to_array(), kk);
                for (j, nb) in found.iter().take(k).enumerate() {
                    ir[j] = nb.item;
                    dr[j] = nb.distance;
                }
            });
        Ok(KnnResult {
            k,
            indices,
            sq_distances: sq,
        })
    }

    /// The nearest indexed point to `q`: `(index, squared distance)`; `None` for an empty
    /// index or a non-finite query.
    pub fn nearest(&self, q: Vec3) -> Option<(u32, f32)> {
        if self.len == 0 || !q.is_finite() {
            return None;
        }
        let nb = self.tree.nearest_one::<SquaredEuclidean>(&q.to_array());
        Some((nb.item, nb.distance))
    }
}

/// k nearest neighbours of `queries` (`[Q]`) among `points` (`[P]`): builds a [`KnnIndex`]
/// and queries it. Returns `[Q*K]` indices and squared distances, row-major, nearest first.
pub fn knn(points: &[Vec3], queries: &[Vec3], k: usize) -> Result<KnnResult> {
    KnnIndex::new(points)?.query(queries, k)
}

/// Reference k nearest neighbours by checking every point (O(Q P log P)), same output layout
/// as [`knn`]; ties broken by lower index.
pub fn knn_brute(points: &[Vec3], queries: &[Vec3], k: usize) -> Result<KnnResult> {
    check_k(k, points.len())?;
    check_points("point", points)?;
    check_points("query", queries)?;
    let mut indices = Vec::with_capacity(queries.len() * k);
    let mut sq = Vec::with_capacity(queries.len() * k);
    let mut all: Vec<(f32, u32)> = Vec::with_capacity(points.len());
    for q in queries {
        all.clear();
        all.extend(
            points
                .iter()
                .enumerate()
                .map(|(i, p)| (p.distance_squared(*q), i as u32)),
        );
        all.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for &(d, i) in &all[..k] {
            indices.push(i);
            sq.push(d);
        }
    }
    Ok(KnnResult {
        k,
        indices,
        sq_distances: sq,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::tests::Rng;

    #[test]
    fn matches_brute_force() {
        let mut rng = Rng(3);
        let pts: Vec<Vec3> = (0..2000).map(|_| rng.vec3(1.0)).collect();
        let qs: Vec<Vec3> = (0..300).map(|_| rng.vec3(1.2)).collect();
        for k in [1, 7, 16] {
            let a = knn(&pts, &qs, k).unwrap();
            let b = knn_brute(&pts, &qs, k).unwrap();
            assert_eq!(a.num_queries(), 300);
            for (q, qp) in qs.iter().enumerate() {
                for j in 0..k {
                    assert!(
                        (a.sq_row(q)[j] - b.sq_row(q)[j]).abs() <= 1e-6 * (1.0 + b.sq_row(q)[j])
                    );
                    let i = a.row(q)[j] as usize;
                    assert!((pts[i].distance_squared(*qp) - a.sq_row(q)[j]).abs() < 1e-6);
                }
            }
            // Random continuous data has no ties: indices agree too.
            assert_eq!(a.indices, b.indices);
        }
    }

    #[test]
    fn duplicates_and_planes() {
        // Many identical points and a flat axis-aligned grid (hard cases for k-d trees).
        let mut pts = vec![Vec3::splat(0.5); 500];
        for i in 0..40 {
            for j in 0..40 {
                pts.push(Vec3::new(i as f32 * 0.01, 0.0, j as f32 * 0.01));
            }
        }
        let idx = KnnIndex::new(&pts).unwrap();
        let r = idx
            .query(&[Vec3::splat(0.5), Vec3::new(0.101, 0.0, 0.2)], 10)
            .unwrap();
        assert!(r.sq_row(0).iter().all(|&d| d == 0.0));
        assert!(r.row(0).iter().all(|&i| i < 500));
        let b = knn_brute(&pts, &[Vec3::new(0.101, 0.0, 0.2)], 10).unwrap();
        for j in 0..10 {
            assert!((r.sq_row(1)[j] - b.sq_distances[j]).abs() < 1e-9);
        }
        assert_eq!(idx.nearest(Vec3::new(0.0, 0.1, 0.0)).unwrap().0, 500);
    }

    #[test]
    fn bad_input() {
        let pts = vec![Vec3::ZERO, Vec3::X];
        assert!(knn(&pts, &[Vec3::Y], 0).is_err());
        assert!(knn(&pts, &[Vec3::Y], 3).is_err());
        assert!(knn(&pts, &[Vec3::NAN], 1).is_err());
        assert!(knn(&[Vec3::INFINITY], &[Vec3::Y], 1).is_err());
        assert!(knn_brute(&pts, &[Vec3::Y], 3).is_err());
        let empty = KnnIndex::new(&[]).unwrap();
        assert!(empty.is_empty() && empty.nearest(Vec3::ZERO).is_none());
        assert!(empty.query(&[Vec3::ZERO], 1).is_err());
        assert_eq!(knn(&pts, &[], 2).unwrap().num_queries(), 0);
    }
}
