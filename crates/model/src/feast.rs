//! FeaStNet graph convolution (Verma, Boyer and Verbeek, CVPR 2018) over the garment's
//! 1-ring, with the translation-invariant soft assignment:
//!
//! ```text
//! q_m(x_i, x_j) = softmax_m( u_m . (x_j - x_i) + c_m )
//! y_i = b + sum_m (1/|N_i|) sum_{j in N_i} q_m(x_i, x_j) W_m x_j
//! ```
//!
//! with `N_i` the 1-ring of vertex i and i itself. The neighbourhoods come as a padded index
//! table `[N,K]` with per-entry weights `1/|N_i|` (0 on padding), see
//! [`crate::topology::GarmentTopology`].

use burn::module::Param;
use burn::nn::Linear;
use burn::prelude::*;

use crate::init::ParamInit;
use crate::tensors::gather_rows;

/// Largest span of a batch's assignment logits (over the heads of one vertex, plus the
/// span of the offsets) for which the factored assignment is used: its factors stay above
/// `exp(-2 * 30)`, far from f32 underflow.
pub const FACTORED_SPAN: f32 = 30.0;

/// One FeaStNet convolution `d_in -> d_out` with `heads` soft-assignment heads.
#[derive(Module, Debug)]
pub struct FeaStConv {
    /// The assignment directions `u_m` as a bias-free layer `[d_in, heads]`.
    pub u: Linear,
    /// The assignment offsets `c_m`: `[heads]`.
    pub c: Param<Tensor<1>>,
    /// The head weights `W_m` stacked as one layer `[d_in*heads, d_out]` (row
    /// `f*heads + m` multiplies feature f aggregated by head m) with the bias `b` `[d_out]`.
    pub w: Linear,
}

impl FeaStConv {
    pub(crate) fn new(
        d_in: usize,
        d_out: usize,
        heads: usize,
        init: &mut ParamInit,
        device: &Device,
    ) -> Self {
        FeaStConv {
            u: init.no_bias(d_in, heads, device),
            c: init.vector(heads, 0.1, device),
            w: init.hidden(heads * d_in, d_out, device),
        }
    }

    /// Number of heads M.
    pub fn heads(&self) -> usize {
        self.c.val().dims()[0]
    }

    /// The convolution (no activation).
    ///
    /// - `x`: `[B,N,d_in]` vertex features.
    /// - `ring`: `[N*K]` neighbour indices (row i: i itself, its 1-ring, padding).
    /// - `ring_weight`: `[1,N,K,1]`, `1/|N_i|` per real neighbour, 0 on padding.
    ///
    /// Returns `[B,N,d_out]`.
    pub fn forward(
        &self,
        x: Tensor<3>,
        ring: &Tensor<1, Int>,
        ring_weight: &Tensor<4>,
    ) -> Tensor<3> {
        let q = self.assignment(x.clone(), ring, ring_weight); // [B,N,K,M]
        self.w.forward(aggregate_tensors(x, ring, q))
    }

    /// The soft assignments times the neighbourhood weights, `w_ij q_m(x_i, x_j)`:
    /// `[B,N,K,M]`.
    ///
    /// With `a = x u` (`[B,N,M]`), `q_ijm = exp(a_jm + c_m - a_im) / sum_m' (...)`. The
    /// exponential factors per vertex, `exp(a_jm + c_m - a_im) = E_jm F_im`, so it is
    /// computed on `[B,N,M]` tensors (each shifted by its own per-vertex maximum over the heads,
    /// which cancels in the normalisation) and only the product and the normalisation run per
    /// neighbour: the same values as a softmax over the logits, without its `[B,N,K,M]`
    /// broadcasts (3-4x faster on flex). An assignment can only lose precision when one
    /// vertex's logits span more than ~80 (then the factors underflow, and their gradients
    /// overflow): when a batch's logits span more than [`FACTORED_SPAN`], the assignment is
    /// computed as a plain softmax over the `[B,N,K,M]` logits instead.
    pub fn assignment(
        &self,
        x: Tensor<3>,
        ring: &Tensor<1, Int>,
        ring_weight: &Tensor<4>,
    ) -> Tensor<4> {
        let [b, n, _] = x.dims();
        let k = ring_weight.dims()[2];
        let m = self.heads();
        let a = self.u.forward(x); // [B,N,M]
        let c = self.c.val();
        let span = (a.clone().max_dim(2) - a.clone().min_dim(2)).max().detach()
            + (c.clone().max() - c.clone().min()).detach();
        let span = crate::tensors::read_scalar(span).unwrap_or(f32::INFINITY);
        if span.is_nan() || span >= FACTORED_SPAN {
            let a_j = gather_rows(a.clone(), ring).reshape([b, n, k, m]);
            let logits = a_j - a.unsqueeze_dim::<4>(2) + c.reshape([1, 1, 1, m]);
            return burn::tensor::activation::softmax(logits, 3) * ring_weight.clone();
        }
        let ac = a.clone() + c.reshape([1, 1, m]);
        let e = (ac.clone() - ac.max_dim(2).detach()).exp(); // E_j, in (0, 1]
        let na = a.neg();
        let f = (na.clone() - na.max_dim(2).detach()).exp(); // F_i, in (0, 1]
        let e_j = gather_rows(e, ring).reshape([b, n, k, m]);
        let num = e_j * f.unsqueeze_dim::<4>(2); // [B,N,K,M]
        let den = num.clone().sum_dim(3) + f32::MIN_POSITIVE as f64; // [B,N,K,1]
        num * (ring_weight.clone() / den)
    }
}

/// The per-head aggregation `a_i[f, m] = sum_k q_ikm x_{ring(i,k)}[f]` with burn's ops:
/// `x` `[B,N,d_in]`, `ring` `[N*K]`, `q` `[B,N,K,M]` -> `[B,N,d_in*M]` (entry `f*M + m`), as
/// `[d_in,K] x [K,M]` per vertex (this orientation runs ~2.5x faster on flex than
/// `[M,K] x [K,d_in]`). Drapes and evaluation on the CPU take the plain loops of
/// [`crate::feast_rows`] instead.
pub(crate) fn aggregate_tensors(x: Tensor<3>, ring: &Tensor<1, Int>, q: Tensor<4>) -> Tensor<3> {
    let [b, n, d_in] = x.dims();
    let [_, _, k, m] = q.dims();
    let x_j = gather_rows(x, ring).reshape([b * n, k, d_in]);
    let q = q.reshape([b * n, k, m]);
    x_j.swap_dims(1, 2).matmul(q).reshape([b, n, d_in * m]) // [B*N,d_in,M]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tensors::{read_f32, vec_tensor};
    use crate::topology::GarmentTopology;
    use rand::{Rng, SeedableRng};

    /// FeaStNet written as loops over vertices, neighbours and heads, in f64, with the
    /// layer's own parameters: `x` `[B][N][d_in]` -> `[B][N][d_out]`.
    fn reference(
        conv: &FeaStConv,
        mesh: &geom::TriMesh,
        x: &[Vec<Vec<f64>>],
    ) -> Vec<Vec<Vec<f64>>> {
        let u = read_f32(conv.u.weight.val()).unwrap(); // [d_in, M]
        let c = read_f32(conv.c.val()).unwrap(); // [M]
        let w = read_f32(conv.w.weight.val()).unwrap(); // [d_in*M, d_out]
        let bias = read_f32(conv.w.bias.as_ref().unwrap().val()).unwrap();
        let m = c.len();
        let d_out = bias.len();
        let d_in = u.len() / m;
        let rings = geom::adjacency::one_ring(mesh.num_vertices(), &mesh.faces).unwrap();
        x.iter()
            .map(|xb| {
                (0..xb.len())
                    .map(|i| {
                        let mut nbhd = vec![i];
                        nbhd.extend(rings.row(i).iter().map(|&j| j as usize));
                        let mut y: Vec<f64> = bias.iter().map(|&v| v as f64).collect();
                        for &j in &nbhd {
                            let logits: Vec<f64> = (0..m)
                                .map(|h| {
                                    (0..d_in)
                                        .map(|f| u[f * m + h] as f64 * (xb[j][f] - xb[i][f]))
                                        .sum::<f64>()
                                        + c[h] as f64
                                })
                                .collect();
                            let mx = logits.iter().cloned().fold(f64::MIN, f64::max);
                            let z: f64 = logits.iter().map(|l| (l - mx).exp()).sum();
                            for h in 0..m {
                                let q = (logits[h] - mx).exp() / z / nbhd.len() as f64;
                                for (o, yo) in y.iter_mut().enumerate() {
                                    let wx: f64 = (0..d_in)
                                        .map(|f| w[(f * m + h) * d_out + o] as f64 * xb[j][f])
                                        .sum();
                                    *yo += q * wx;
                                }
                            }
                        }
                        y
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn feast_conv_matches_a_plain_loop() {
        let device = Device::flex();
        // A 5x4 grid: vertex degrees 2 to 6, so rows are padded differently.
        let mesh = geom::TriMesh::grid(5, 4, 0.1);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let tt = topo.to_device(&device);
        let (b, n, d_in, d_out, heads) = (2, mesh.num_vertices(), 5, 4, 3);
        let mut init = ParamInit::new(11);
        let mut conv = FeaStConv::new(d_in, d_out, heads, &mut init, &device);
        conv.c = init.vector(heads, 1.0, &device);
        // Features within +-2 take the factored assignment, within +-80 (logits spanning more
        // than FACTORED_SPAN) the plain softmax: both must match the loops.
        for (range, factored) in [(2.0, true), (80.0, false)] {
            let mut rng = rand::rngs::StdRng::seed_from_u64(3);
            let x: Vec<Vec<Vec<f64>>> = (0..b)
                .map(|_| {
                    (0..n)
                        .map(|_| (0..d_in).map(|_| rng.random_range(-range..range)).collect())
                        .collect()
                })
                .collect();
            let flat: Vec<f32> = x.iter().flatten().flatten().map(|&v| v as f32).collect();
            let x_t = vec_tensor(flat, [b, n, d_in], &device);
            let a = read_f32(conv.u.forward(x_t.clone())).unwrap();
            let span = a
                .chunks_exact(heads)
                .map(|r| {
                    r.iter().fold(f32::MIN, |m, v| m.max(*v))
                        - r.iter().fold(f32::MAX, |m, v| m.min(*v))
                })
                .fold(0.0f32, f32::max);
            assert_eq!(span + 2.0 < FACTORED_SPAN, factored, "logit span {span}");
            let y = conv.forward(x_t, &tt.ring, &tt.ring_weight);
            assert_eq!(y.dims(), [b, n, d_out]);
            let got = read_f32(y).unwrap();
            let want: Vec<f64> = reference(&conv, &mesh, &x)
                .into_iter()
                .flatten()
                .flatten()
                .collect();
            let worst = got
                .iter()
                .zip(&want)
                .map(|(g, w)| ((*g as f64 - w) / (1.0 + w.abs())).abs())
                .fold(0.0, f64::max);
            assert!(worst < 5e-5, "range {range}: largest difference {worst}");
        }
    }

    #[test]
    fn assignments_are_a_softmax_even_with_large_logits() {
        let device = Device::flex();
        let mesh = geom::TriMesh::grid(3, 3, 1.0);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let tt = topo.to_device(&device);
        let mut init = ParamInit::new(5);
        let conv = FeaStConv::new(3, 2, 4, &mut init, &device);
        // Features of size ~30 give logits spanning tens: a plain exp would overflow.
        let x: Vec<f32> = (0..9 * 3)
            .map(|i| ((i * 37) % 11) as f32 * 6.0 - 30.0)
            .collect();
        let q = conv.assignment(vec_tensor(x, [1, 9, 3], &device), &tt.ring, &tt.ring_weight);
        let q = read_f32(q).unwrap();
        let k = topo.ring_width;
        for (row, w) in q.chunks_exact(4).zip(&topo.ring_weight) {
            let s: f32 = row.iter().sum();
            assert!(row.iter().all(|v| v.is_finite() && *v >= 0.0));
            assert!((s - w).abs() < 1e-5, "heads sum to {s}, expected {w}");
        }
        assert_eq!(q.len(), 9 * k * 4);
    }
}
