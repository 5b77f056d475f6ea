//! Which body points the network sees, and GarNet-Local's neighbour tables (computed on the
//! CPU with k-d trees, kiddo through [`geom::KnnIndex`], and passed to the network as int
//! tensors).
//!
//! The bodies of a dataset share one topology (13380 vertices here, against SMPL's 6890 in the
//! paper), so the subsampling is a fixed list of body vertices ([`BodySampling`]), chosen once
//! by farthest-point sampling on a reference body and stored in the checkpoint: it stays
//! evenly spread over the surface in every shape and pose and costs nothing per sample.
//!
//! - The body stream sees the first `ceil(V / body_subsample)` vertices of that list (3345 of
//!   13380 by default; 6690 with `body_subsample = 2`, about the paper's point count).
//! - GarNet-Local keeps the first `ceil(P / body_downsample)` of those stream points (10x, as in
//!   the paper): a prefix of a farthest-point order is itself a farthest-point sample. Per
//!   sample, each kept point averages the features of its `pool_k` (16) nearest stream points
//!   and each garment vertex max-pools the features of its `knn_k` (15) nearest kept points
//!   (nearest to the warped garment M, the network's input).

use burn::prelude::*;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::{check_count, check_finite, ModelError, Result};
use crate::tensors::index_tensor;

/// A fixed subsampling of the body: body vertex indices in farthest-point order.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct BodySampling {
    /// Number of body vertices V the indices refer to.
    pub n_body: usize,
    /// `[P]` body vertex indices the body stream sees, in farthest-point order.
    pub stream: Vec<u32>,
    /// GarNet-Local: the first `n_centres` stream points are the kept (downsampled) points.
    pub n_centres: usize,
}

impl BodySampling {
    /// Farthest-point sampling of `ceil(V / subsample)` vertices of the reference `body`
    /// (`[V]`, metres), starting at vertex 0 (deterministic, O(V P)); the first
    /// `ceil(P / downsample)` are GarNet-Local's kept points.
    pub fn farthest_point(body: &[Vec3], subsample: usize, downsample: usize) -> Result<Self> {
        check_finite("reference body", body)?;
        if body.is_empty() || subsample == 0 || downsample == 0 {
            return Err(ModelError::InvalidInput(
                "body sampling needs a non-empty body and positive factors".into(),
            ));
        }
        let p = body.len().div_ceil(subsample);
        let mut stream = Vec::with_capacity(p);
        let mut dist = vec![f32::INFINITY; body.len()];
        let mut next = 0usize;
        for _ in 0..p {
            stream.push(next as u32);
            let c = body[next];
            let mut best = (0usize, -1.0f32);
            for (i, (q, d)) in body.iter().zip(dist.iter_mut()).enumerate() {
                let dd = q.distance_squared(c);
                if dd < *d {
                    *d = dd;
                }
                if *d > best.1 {
                    best = (i, *d);
                }
            }
            next = best.0;
        }
        Ok(BodySampling {
            n_body: body.len(),
            n_centres: p.div_ceil(downsample),
            stream,
        })
    }

    /// Number of stream points P.
    pub fn len(&self) -> usize {
        self.stream.len()
    }

    /// `true` when no point is kept.
    pub fn is_empty(&self) -> bool {
        self.stream.is_empty()
    }

    /// Fails unless the indices fit `n_body` and `n_centres <= P`.
    pub fn validate(&self) -> Result<()> {
        if self.stream.is_empty()
            || self.n_centres == 0
            || self.n_centres > self.stream.len()
            || self.stream.iter().any(|&i| i as usize >= self.n_body)
        {
            return Err(ModelError::InvalidInput(format!(
                "body sampling of {} stream points ({} kept) is inconsistent with {} body \
                 vertices",
                self.stream.len(),
                self.n_centres,
                self.n_body
            )));
        }
        Ok(())
    }

    /// The stream points `[P]` of `body` `[V]`; fails on a wrong vertex count.
    pub fn stream_points(&self, body: &[Vec3]) -> Result<Vec<Vec3>> {
        check_count("body vertices", self.n_body, body.len())?;
        Ok(self.stream.iter().map(|&i| body[i as usize]).collect())
    }

    /// The neighbour tables of one sample: `stream` `[P]` (the body's stream points, see
    /// [`BodySampling::stream_points`]) and `warped` M `[N]` (metres) ->
    /// (`[S*pool_k]` stream point indices averaged into each kept point, `[N*knn_k]` kept
    /// point indices max-pooled into each garment vertex), nearest first.
    pub fn tables(
        &self,
        stream: &[Vec3],
        warped: &[Vec3],
        pool_k: usize,
        knn_k: usize,
    ) -> Result<(Vec<u32>, Vec<u32>)> {
        check_count("body stream points", self.len(), stream.len())?;
        if pool_k > stream.len() || knn_k > self.n_centres {
            return Err(ModelError::InvalidInput(format!(
                "local pooling needs {pool_k} neighbours among {} body points and {knn_k} among \
                 {} kept points",
                stream.len(),
                self.n_centres
            )));
        }
        let index = geom::KnnIndex::new(stream)?;
        let centres = &stream[..self.n_centres];
        let pool = index.query(centres, pool_k)?.indices;
        let knn = geom::knn::knn(centres, warped, knn_k)?.indices;
        Ok((pool, knn))
    }
}

/// GarNet-Local's neighbour tables for a batch, as flat row indices into the batch-flattened
/// feature tables (sample b's rows start at `b*P` for the stream points, `b*S` for the kept
/// points).
#[derive(Clone, Debug)]
pub struct LocalIndices {
    /// Kept points per sample S.
    pub n_centres: usize,
    /// Stream points averaged per kept point (16).
    pub pool_k: usize,
    /// Garment vertices per sample N.
    pub n_garment: usize,
    /// Kept points max-pooled per garment vertex (15).
    pub knn_k: usize,
    /// `[B*S*pool_k]` rows of the `[B*P, C]` body feature table.
    pub pool: Tensor<1, Int>,
    /// `knn_k` tensors `[B*N]`: entry k holds, for every garment vertex, the row of its k-th
    /// nearest kept point in the `[B*S, C]` kept-point feature table (column-split so the max
    /// pooling gathers `[B*N, C]` slices instead of one `[B*N*knn_k, C]` tensor).
    pub knn: Vec<Tensor<1, Int>>,
}

impl LocalIndices {
    /// The tables of a batch: `streams[b]` `[P]` and `warped[b]` `[N]` (metres) for each
    /// sample b.
    pub fn build(
        sampling: &BodySampling,
        pool_k: usize,
        knn_k: usize,
        streams: &[&[Vec3]],
        warped: &[&[Vec3]],
        device: &Device,
    ) -> Result<Self> {
        if streams.len() != warped.len() || streams.is_empty() {
            return Err(ModelError::InvalidInput(
                "local tables need one body per warped garment and at least one sample".into(),
            ));
        }
        let p = sampling.len();
        let s = sampling.n_centres;
        let n = warped[0].len();
        let mut pool = Vec::with_capacity(streams.len() * s * pool_k);
        let mut knn = vec![Vec::with_capacity(streams.len() * n); knn_k];
        for (b, (stream, m)) in streams.iter().zip(warped).enumerate() {
            check_count("warped garment M", n, m.len())?;
            let (pt, kt) = sampling.tables(stream, m, pool_k, knn_k)?;
            pool.extend(pt.iter().map(|&i| (b * p) as i64 + i as i64));
            for row in kt.chunks_exact(knn_k) {
                for (col, &i) in knn.iter_mut().zip(row) {
                    col.push((b * s) as i64 + i as i64);
                }
            }
        }
        Ok(LocalIndices {
            n_centres: s,
            pool_k,
            n_garment: n,
            knn_k,
            pool: index_tensor(pool, device),
            knn: knn
                .into_iter()
                .map(|col| index_tensor(col, device))
                .collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::ellipsoid_body;

    #[test]
    fn farthest_point_sampling_covers_the_body_evenly() {
        let (body, _) = ellipsoid_body(600);
        let s = BodySampling::farthest_point(&body, 4, 5).unwrap();
        assert_eq!(s.len(), 150);
        assert_eq!(s.n_centres, 30);
        assert_eq!(s.stream[0], 0);
        let mut sorted = s.stream.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 150, "indices are distinct");
        s.validate().unwrap();
        // Farthest-point property: every body point is within the smallest separation of
        // the chosen points (the covering radius never exceeds the packing distance).
        let chosen = s.stream_points(&body).unwrap();
        let min_sep = (0..chosen.len())
            .flat_map(|i| (0..i).map(move |j| (i, j)))
            .map(|(i, j)| chosen[i].distance(chosen[j]))
            .fold(f32::MAX, f32::min);
        let cover = body
            .iter()
            .map(|p| {
                chosen
                    .iter()
                    .map(|c| p.distance(*c))
                    .fold(f32::MAX, f32::min)
            })
            .fold(0.0f32, f32::max);
        assert!(
            cover <= min_sep + 1e-6,
            "cover {cover} > separation {min_sep}"
        );
        // The kept prefix is itself a farthest-point sample.
        let kept = &chosen[..s.n_centres];
        let again = BodySampling::farthest_point(&body, 20, 1).unwrap();
        assert_eq!(again.stream[..], s.stream[..s.n_centres]);
        assert_eq!(kept.len(), 30);
    }

    #[test]
    fn tables_are_the_nearest_neighbours() {
        let (body, _) = ellipsoid_body(300);
        let s = BodySampling::farthest_point(&body, 2, 5).unwrap();
        let stream = s.stream_points(&body).unwrap();
        let garment = crate::synthetic::tube_garment(40).vertices;
        let (pool, knn) = s.tables(&stream, &garment, 4, 3).unwrap();
        let centres = &stream[..s.n_centres];
        let want_pool = geom::knn::knn_brute(&stream, centres, 4).unwrap();
        let want_knn = geom::knn::knn_brute(centres, &garment, 3).unwrap();
        // Compare distances (indices may differ only between equidistant points).
        for (q, c) in centres.iter().enumerate() {
            for (a, &i) in pool[q * 4..q * 4 + 4].iter().enumerate() {
                let d = stream[i as usize].distance_squared(*c);
                assert!((d - want_pool.sq_row(q)[a]).abs() < 1e-9);
            }
        }
        for (q, g) in garment.iter().enumerate() {
            for (a, &i) in knn[q * 3..q * 3 + 3].iter().enumerate() {
                let d = centres[i as usize].distance_squared(*g);
                assert!((d - want_knn.sq_row(q)[a]).abs() < 1e-9);
            }
        }
        assert!(s.tables(&stream, &garment, 4, s.n_centres + 1).is_err());
        assert!(s.stream_points(&body[..299]).is_err());
    }
}
