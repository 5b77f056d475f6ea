//! The body stream: a PointNet over the body vertices (paper section 3.2 and 3.4).
//!
//! ```text
//! B [B,V,3] -> STN 3x3 -> x' [B,V,3] -> MLP1 -> f1 [B,V,c1] -> feature STN c1 x c1 -> f1'
//! [f1'; x'] [B,V,c1+3] -> MLP2 -> point-wise body features [B,V,Cb] -> max -> global [B,Cb]
//! ```
//!
//! LeakyReLU(0.1) everywhere; the concatenation of `x'` before MLP2 is the paper's skip "from
//! the output of the first STN to the input of the second MLP block".

use burn::nn::Linear;
use burn::prelude::*;

use rayon::prelude::*;

use crate::config::GarNetConfig;
use crate::error::Result;
use crate::init::ParamInit;
use crate::layers::{lrelu, maximum, PointMlp};
use crate::local::LocalIndices;
use crate::stn::Stn;
use crate::tensors::{read_f32, read_i64, untracked_on_flex, vec_tensor};

/// PointNet body stream.
#[derive(Module, Debug)]
pub struct BodyStream {
    /// Input transform (3x3).
    pub input_stn: Stn,
    /// First MLP block `3 -> body_mlp1`.
    pub mlp1: PointMlp,
    /// Feature transform (c1 x c1, c1 = last width of `body_mlp1`).
    pub feature_stn: Stn,
    /// Second MLP block `c1 + 3 -> body_mlp2`.
    pub mlp2: PointMlp,
}

/// Outputs of the body stream.
#[derive(Clone, Debug)]
pub struct BodyFeatures {
    /// Point-wise body features `[B,V,Cb]`.
    pub points: Tensor<3>,
    /// Global body feature `[B,Cb]` (max over the V points).
    pub global: Tensor<2>,
}

impl BodyStream {
    pub(crate) fn new(cfg: &GarNetConfig, init: &mut ParamInit, device: &Device) -> Self {
        let input_stn = Stn::new(3, &cfg.stn_mlp, &cfg.stn_fc, init, device);
        let mlp1 = PointMlp::new(3, &cfg.body_mlp1, init, device);
        let c1 = mlp1.d_out();
        let feature_stn = Stn::new(c1, &cfg.stn_mlp, &cfg.stn_fc, init, device);
        let mlp2 = PointMlp::new(c1 + 3, &cfg.body_mlp2, init, device);
        BodyStream {
            input_stn,
            mlp1,
            feature_stn,
            mlp2,
        }
    }

    /// `body` `[B,V,3]` (metres) -> point-wise `[B,V,Cb]` and global `[B,Cb]` features.
    pub fn forward(&self, body: Tensor<3>) -> BodyFeatures {
        let x = self.input_stn.forward(body);
        let f1 = self.feature_stn.forward(self.mlp1.rows(vec![x.clone()]));
        let (points, global) = self.mlp2.rows_and_pooled(vec![f1, x]);
        BodyFeatures { points, global }
    }
}

/// GarNet-Local's local body features: the body downsampled 10x (point-wise features
/// average-pooled over 16 body neighbours of each kept point), a shared layer to a narrower
/// width, then for each garment vertex the max over its 15 nearest kept points.
#[derive(Module, Debug)]
pub struct LocalPool {
    /// Shared layer `Cb -> local_width` (LeakyReLU) on the downsampled points.
    pub proj: Linear,
}

impl LocalPool {
    pub(crate) fn new(cfg: &GarNetConfig, init: &mut ParamInit, device: &Device) -> Self {
        LocalPool {
            proj: init.hidden(cfg.body_feature_width(), cfg.local_width, device),
        }
    }

    /// `points` `[B,V,Cb]` point-wise body features and the batch's neighbour tables ->
    /// `[B,N,local_width]` local body feature of every garment vertex.
    pub fn forward(&self, points: Tensor<3>, idx: &LocalIndices) -> Tensor<3> {
        let [b, v, c] = points.dims();
        let (s, p, n) = (idx.n_centres, idx.pool_k, idx.n_garment);
        // Average pooling of the Cb-wide point-wise features over each kept point's P body
        // neighbours (the paper's downsampling), then the shared layer on the S means only.
        let pooled = points
            .reshape([b * v, c])
            .select(0, idx.pool.clone())
            .reshape([b, s, p, c])
            .mean_dim(2)
            .reshape([b, s, c]);
        let local = lrelu(self.proj.forward(pooled));
        let l = local.dims()[2];
        // Max over the k nearest kept points, one [B*N, L] gather per neighbour rank (no
        // [B*N*k, L] intermediate), with `maximum` (exact, the gradient to one side).
        let table = local.reshape([b * s, l]);
        if idx.knn.is_empty() {
            // No neighbour (knn_k = 0, refused by GarNet::translations): no local feature.
            return Tensor::zeros([b, n, l], &table.device());
        }
        let pooled = if untracked_on_flex(&table) {
            max_pool_rows(&table, &idx.knn).unwrap_or_else(|_| max_pool_tensors(table, &idx.knn))
        } else {
            max_pool_tensors(table, &idx.knn)
        };
        pooled.reshape([b, n, l])
    }
}

/// The max pooling of [`LocalPool::forward`] with burn's ops: the kept-point table `[R,L]`
/// and `knn` columns (at least one) `[B*N]` of its rows -> `[B*N,L]`, the element-wise
/// maximum of each garment vertex's rows, one `[B*N,L]` gather per neighbour rank (no
/// `[B*N*k,L]` intermediate) with `maximum` (exact, the gradient to one side). Used whenever
/// gradients flow, and on the GPU backends.
fn max_pool_tensors(table: Tensor<2>, knn: &[Tensor<1, Int>]) -> Tensor<2> {
    knn.iter()
        .map(|col| table.clone().select(0, col.clone()))
        .reduce(|acc, t| maximum(t, acc))
        .expect("at least one neighbour column")
}

/// [`max_pool_tensors`] as plain loops (in parallel over the garment vertices) for an
/// untracked CPU table `[R,L]` and `knn` columns `[B*N]` of row indices:
/// `[B*N,L]`, row r the element-wise maximum of the rows `knn[0][r]`, `knn[1][r]`, ...,
/// compared as `maximum` does (a later row wins only where it is greater), so the values are
/// bit for bit those of the tensor path. Written by hand because flex's `max_pair` is a
/// masked select, ~10% of a 10k-vertex drape with the gathers (`perf`, docs/model.md
/// "Speed").
fn max_pool_rows(table: &Tensor<2>, knn: &[Tensor<1, Int>]) -> Result<Tensor<2>> {
    let l = table.dims()[1];
    let values = read_f32(table.clone())?;
    let columns = knn
        .iter()
        .map(|c| read_i64(c.clone()))
        .collect::<Result<Vec<_>>>()?;
    let rows = columns.first().map_or(0, Vec::len);
    let mut out = vec![0.0f32; rows * l];
    if out.is_empty() {
        return Ok(vec_tensor(out, [rows, l], &table.device()));
    }
    out.par_chunks_mut(l).enumerate().for_each(|(r, dst)| {
        for (c, column) in columns.iter().enumerate() {
            let src = &values[column[r] as usize * l..][..l];
            if c == 0 {
                dst.copy_from_slice(src);
            } else {
                // A select, not a conditional store: it compiles to vector compares and
                // blends (the `if v > *a { *a = v }` form was branchy scalar code).
                for (a, &v) in dst.iter_mut().zip(src) {
                    *a = if v > *a { v } else { *a };
                }
            }
        }
    });
    Ok(vec_tensor(out, [rows, l], &table.device()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::local::BodySampling;
    use crate::synthetic::{ellipsoid_body, tube_garment};
    use rand::{Rng, SeedableRng};

    /// The loops of `max_pool_rows` (drapes, evaluation) give the values of the tensor path
    /// (training) bit for bit, ties and repeated rows included.
    #[test]
    fn max_pool_loops_match_the_tensor_path() {
        let device = Device::flex();
        let (rows, l, n) = (9, 6, 40);
        let mut rng = rand::rngs::StdRng::seed_from_u64(4);
        // Values on a coarse grid, so that many compared pairs tie.
        let table: Vec<f32> = (0..rows * l)
            .map(|_| rng.random_range(-4..4) as f32 * 0.5)
            .collect();
        let table = vec_tensor(table, [rows, l], &device);
        let knn: Vec<Tensor<1, Int>> = (0..5)
            .map(|_| {
                let col: Vec<i64> = (0..n).map(|_| rng.random_range(0..rows as i64)).collect();
                crate::tensors::index_tensor(col, &device)
            })
            .collect();
        let loops = read_f32(max_pool_rows(&table, &knn).unwrap()).unwrap();
        let tensors = read_f32(max_pool_tensors(table, &knn)).unwrap();
        assert_eq!(loops.len(), n * l);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&loops), bits(&tensors));
    }

    /// Local pooling against loops over the tables, for a batch of two different bodies.
    #[test]
    fn local_pool_matches_a_plain_loop() {
        let device = Device::flex();
        let cfg = GarNetConfig::tiny(crate::Variant::Local);
        let mut init = ParamInit::new(9);
        let pool = LocalPool::new(&cfg, &mut init, &device);
        let (body, _) = ellipsoid_body(200);
        let sampling = BodySampling::farthest_point(&body, 2, 4).unwrap();
        let garment = tube_garment(30).vertices;
        let streams: Vec<Vec<glam::Vec3>> = [1.0f32, 1.2]
            .iter()
            .map(|s| {
                sampling
                    .stream_points(&body)
                    .unwrap()
                    .iter()
                    .map(|p| *p * *s)
                    .collect()
            })
            .collect();
        let refs: Vec<&[glam::Vec3]> = streams.iter().map(Vec::as_slice).collect();
        let (pk, kk) = (cfg.pool_neighbours, cfg.local_neighbours);
        let idx =
            LocalIndices::build(&sampling, pk, kk, &refs, &[&garment, &garment], &device).unwrap();
        let (b, p, c) = (2, sampling.len(), cfg.body_feature_width());
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        let feats: Vec<f32> = (0..b * p * c)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let got = pool.forward(vec_tensor(feats.clone(), [b, p, c], &device), &idx);
        let n = garment.len();
        let l = cfg.local_width;
        assert_eq!(got.dims(), [b, n, l]);
        let got = read_f32(got).unwrap();
        let w = read_f32(pool.proj.weight.val()).unwrap();
        let bias = read_f32(pool.proj.bias.as_ref().unwrap().val()).unwrap();
        for (bi, stream) in refs.iter().enumerate() {
            let (pt, kt) = sampling.tables(stream, &garment, pk, kk).unwrap();
            let s = sampling.n_centres;
            let kept: Vec<Vec<f64>> = (0..s)
                .map(|ci| {
                    let mean: Vec<f64> = (0..c)
                        .map(|f| {
                            pt[ci * pk..(ci + 1) * pk]
                                .iter()
                                .map(|&j| feats[(bi * p + j as usize) * c + f] as f64)
                                .sum::<f64>()
                                / pk as f64
                        })
                        .collect();
                    (0..l)
                        .map(|o| {
                            let z = bias[o] as f64
                                + (0..c).map(|f| mean[f] * w[f * l + o] as f64).sum::<f64>();
                            if z > 0.0 {
                                z
                            } else {
                                0.1 * z
                            }
                        })
                        .collect()
                })
                .collect();
            for v in 0..n {
                for o in 0..l {
                    let want = kt[v * kk..(v + 1) * kk]
                        .iter()
                        .map(|&ci| kept[ci as usize][o])
                        .fold(f64::MIN, f64::max);
                    let g = got[(bi * n + v) * l + o] as f64;
                    assert!(
                        (g - want).abs() < 1e-5,
                        "sample {bi} vertex {v}: {g} vs {want}"
                    );
                }
            }
        }
    }
}
