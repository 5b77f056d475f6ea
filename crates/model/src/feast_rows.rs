//! FeaStNet convolutions as plain loops on the CPU, for drapes and evaluation (untracked
//! tensors on flex); training and the GPU backends keep burn's ops ([`FeaStConv::forward`]).
//!
//! A convolution of `[x; M]` (features and vertex positions) with the factored assignment
//! runs in one pass: the assignment factors per vertex, then tiles of [`TILE`] garment
//! rows, each aggregated over the 1-ring into a buffer that stays in cache and multiplied
//! by the head weights there (`gemm`), then the block's residual and activation. On flex
//! every step was a tensor of its own, allocated zeroed and copied once more for alignment:
//! the concatenation, the `[N,K,M]` assignment (gathers, products, sums, a division) and a
//! 16 MB `[N,d_in*M]` aggregate for a 10k-vertex garment, written and read again by the
//! product (`perf`; docs/findings.md, "Speed").

use std::mem::MaybeUninit;

use rayon::prelude::*;

use crate::error::Result;
use crate::feast::{FeaStConv, FACTORED_SPAN};
use crate::init::LEAKY_SLOPE;
use crate::tensors::read_f32;

/// Garment rows per tile: the aggregate of 256 rows of 51 features and 8 heads is 418 KB,
/// within a core's L2 cache, and the head weights (packed by `gemm` once per tile) serve
/// 256 rows.
pub const TILE: usize = 256;

/// The garment's padded 1-ring on the host (see [`crate::topology::GarmentTopology`]):
/// `[N*K]` neighbour indices and `[N*K]` weights `1/|N_i|` (0 on padding).
#[derive(Clone, Debug)]
pub struct HostRing {
    /// Neighbour indices, row i: i itself, its 1-ring, padding.
    pub ring: Vec<u32>,
    /// Weights of the same entries.
    pub weight: Vec<f32>,
    /// Row width K.
    pub k: usize,
}

/// What is applied to a convolution's output `y` before it is returned (row-major, the
/// output's shape).
#[derive(Clone, Copy, Debug)]
pub enum Epilogue<'a> {
    /// `lrelu(y)`.
    Lrelu,
    /// `lrelu(r + y)`.
    ResidualLrelu(&'a [f32]),
}

impl Epilogue<'_> {
    fn apply(&self, start: usize, y: &mut [f32]) {
        let lrelu = |v: f32| if v >= 0.0 { v } else { LEAKY_SLOPE as f32 * v };
        match self {
            Epilogue::Lrelu => y.iter_mut().for_each(|v| *v = lrelu(*v)),
            Epilogue::ResidualLrelu(r) => {
                for (v, &r) in y.iter_mut().zip(&r[start..]) {
                    *v = lrelu(r + *v);
                }
            }
        }
    }
}

impl FeaStConv {
    /// [`FeaStConv::forward`] of `[x; pos]` followed by `epilogue`, as plain loops:
    /// `x` `[B*N, C]` features and `pos` `[B*N, 3]` vertex positions (row-major, B samples
    /// of N vertices), `ring` the garment's 1-ring -> `[B*N, d_out]`. `None` where a
    /// sample's assignment logits span [`FACTORED_SPAN`] or more (or are not finite): the
    /// caller then takes the tensor path, which has the plain softmax for that case. The
    /// same values as the tensor path within rounding (tested).
    pub fn forward_rows(
        &self,
        x: &[f32],
        pos: &[f32],
        n: usize,
        ring: &HostRing,
        epilogue: Epilogue,
    ) -> Result<Option<Vec<f32>>> {
        let m = self.heads();
        let [d_in, d_out] = self.w.weight.dims();
        let d_in = d_in / m.max(1);
        let rows = pos.len() / 3;
        let c = d_in.saturating_sub(3);
        if m == 0 || d_in < 3 || x.len() != rows * c || n == 0 || rows % n != 0 {
            return Ok(None);
        }
        let u = read_f32(self.u.weight.val())?; // [d_in, M]
        let offsets = read_f32(self.c.val())?; // [M]
        let weight = read_f32(self.w.weight.val())?; // [d_in*M, d_out]
        let bias = match &self.w.bias {
            Some(b) => read_f32(b.val())?,
            None => vec![0.0; d_out],
        };
        let mut xin = vec![0.0f32; rows * d_in];
        xin.par_chunks_mut(d_in)
            .zip(pos.par_chunks(3))
            .enumerate()
            .for_each(|(r, (row, p))| {
                row[..c].copy_from_slice(&x[r * c..][..c]);
                row[c..].copy_from_slice(p);
            });
        let Some((e, f)) = factors(&xin, d_in, &u, &offsets) else {
            return Ok(None);
        };
        let input = Aggregation {
            xs: &xin,
            e: &e,
            f: &f,
            ring,
            n,
            d_in,
            m,
        };
        let width = d_in * m;
        let fused = fma_available();
        let mut out = vec![0.0f32; rows * d_out];
        if d_out == 0 {
            return Ok(Some(out));
        }
        out.par_chunks_mut(TILE * d_out)
            .enumerate()
            .for_each(|(tile, dst)| {
                let tile_rows = dst.len() / d_out;
                let mut agg: Vec<f32> = Vec::with_capacity(tile_rows * width);
                let mut scratch = Scratch::default();
                for (i, row) in agg.spare_capacity_mut()[..tile_rows * width]
                    .chunks_exact_mut(width)
                    .enumerate()
                {
                    input.write_row_fast(tile * TILE + i, row, &mut scratch, fused);
                }
                // SAFETY: `write_row_fast` initialised every element of every row.
                unsafe { agg.set_len(tile_rows * width) };
                for row in dst.chunks_exact_mut(d_out) {
                    row.copy_from_slice(&bias);
                }
                add_product(dst, &agg, &weight, width);
                epilogue.apply(tile * TILE * d_out, dst);
            });
        Ok(Some(out))
    }
}

/// The assignment's per-vertex factors of [`FeaStConv::assignment`] for the inputs `xin`
/// `[R, d_in]`: with `a = xin u` (`u` `[d_in, M]`) and offsets `c` `[M]`,
/// `E = exp(a + c - max_m(a + c))` and `F = exp(-a - max_m(-a))`, each `[R, M]`; `None`
/// when the logits span [`FACTORED_SPAN`] or more, or are not finite.
fn factors(xin: &[f32], d_in: usize, u: &[f32], c: &[f32]) -> Option<(Vec<f32>, Vec<f32>)> {
    let m = c.len();
    let mut a = vec![0.0f32; xin.len() / d_in * m];
    a.par_chunks_mut(TILE * m)
        .zip(xin.par_chunks(TILE * d_in))
        .for_each(|(a, x)| add_product(a, x, u, d_in));
    let spread = |v: &[f32]| {
        let (lo, hi) = v
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &x| {
                (l.min(x), h.max(x))
            });
        hi - lo
    };
    let span = a.chunks_exact(m).map(spread).fold(0.0f32, f32::max) + spread(c);
    if span.is_nan() || span >= FACTORED_SPAN || a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut e = vec![0.0f32; a.len()];
    let mut f = vec![0.0f32; a.len()];
    for ((a, e), f) in a
        .chunks_exact(m)
        .zip(e.chunks_exact_mut(m))
        .zip(f.chunks_exact_mut(m))
    {
        let top = a
            .iter()
            .zip(c)
            .map(|(a, c)| a + c)
            .fold(f32::NEG_INFINITY, f32::max);
        let bottom = a.iter().fold(f32::INFINITY, |l, &v| l.min(v));
        for h in 0..m {
            e[h] = (a[h] + c[h] - top).exp();
            f[h] = (bottom - a[h]).exp();
        }
    }
    Some((e, f))
}

/// `dst` `[R, n] += src [R, k] x weight [k, n]`, all row-major (n from `weight`'s length),
/// by `gemm` on this thread.
pub(crate) fn add_product(dst: &mut [f32], src: &[f32], weight: &[f32], k: usize) {
    let n = weight.len() / k.max(1);
    let rows = dst.len() / n.max(1);
    if rows == 0 || n == 0 || k == 0 || src.len() != rows * k || weight.len() != k * n {
        return;
    }
    // SAFETY: `dst` [rows, n], `src` [rows, k] and `weight` [k, n] hold exactly their shapes
    // (checked above), row-major.
    unsafe {
        gemm::gemm(
            rows,
            n,
            k,
            dst.as_mut_ptr(),
            1,
            n as isize,
            true,
            src.as_ptr(),
            1,
            k as isize,
            weight.as_ptr(),
            1,
            n as isize,
            1.0,
            1.0,
            false,
            false,
            false,
            gemm::Parallelism::None,
        );
    }
}

/// Whether this CPU runs AVX2 with fused multiply-adds (checked once, then cached by std).
fn fma_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `a + x q`, fused (one rounding) or plain. `f32::mul_add` is a slow library call where
/// the code is not compiled for a CPU with FMA, so only the AVX2 kernel fuses.
#[inline(always)]
fn madd<const FUSED: bool>(a: f32, x: f32, q: f32) -> f32 {
    if FUSED {
        x.mul_add(q, a)
    } else {
        a + x * q
    }
}

/// `dst` filled with zeros, as initialised values.
fn zeroed(dst: &mut [MaybeUninit<f32>]) -> &mut [f32] {
    for e in dst.iter_mut() {
        e.write(0.0);
    }
    // SAFETY: every element was initialised just above.
    unsafe { &mut *(dst as *mut [MaybeUninit<f32>] as *mut [f32]) }
}

/// A row's real neighbours, reused from row to row: the start of each one's inputs in
/// `xs`, and its assignment `[M]` per neighbour.
#[derive(Default)]
struct Scratch {
    starts: Vec<usize>,
    q: Vec<f32>,
}

/// The inputs of a convolution's aggregation: `xs` `[B*N, d_in]`, the assignment factors
/// `e` and `f` `[B*N, M]`, and the 1-ring.
struct Aggregation<'a> {
    xs: &'a [f32],
    e: &'a [f32],
    f: &'a [f32],
    ring: &'a HostRing,
    n: usize,
    d_in: usize,
    m: usize,
}

impl Aggregation<'_> {
    /// The assignment of row `row`'s real neighbours (weight not 0) into `scratch`:
    /// `q_jm = w_j E_jm F_im / (sum_m' E_jm' F_im' + MIN_POSITIVE)`, as
    /// [`FeaStConv::assignment`] computes it.
    #[inline(always)]
    fn assign(&self, row: usize, scratch: &mut Scratch) {
        let (n, k, m) = (self.n, self.ring.k, self.m);
        let (sample, i) = (row / n, row % n);
        scratch.starts.clear();
        scratch.q.clear();
        let f_i = &self.f[row * m..][..m];
        for (&j, &w) in self.ring.ring[i * k..][..k]
            .iter()
            .zip(&self.ring.weight[i * k..][..k])
        {
            if w == 0.0 {
                continue;
            }
            let col = sample * n + j as usize;
            let e_j = &self.e[col * m..][..m];
            let start = scratch.q.len();
            scratch.q.resize(start + m, 0.0);
            let q = &mut scratch.q[start..];
            let mut sum = 0.0f32;
            for ((q, e), f) in q.iter_mut().zip(e_j).zip(f_i) {
                *q = e * f;
                sum += *q;
            }
            let scale = w / (sum + f32::MIN_POSITIVE);
            q.iter_mut().for_each(|v| *v *= scale);
            scratch.starts.push(col * self.d_in);
        }
    }

    /// Writes row `row` (sample `row / N`, vertex `row % N`) of the aggregate into `dst`
    /// `[d_in*M]`: `dst[f*M + m] = sum_j q_jm x_j[f]` over the real neighbours in ring
    /// order. With 8 heads (the paper's) the features go in blocks of 8, whose 8-wide sums
    /// stay in registers over the neighbours.
    #[inline(always)]
    fn write_row<const FUSED: bool>(
        &self,
        row: usize,
        dst: &mut [MaybeUninit<f32>],
        scratch: &mut Scratch,
    ) {
        self.assign(row, scratch);
        let (d_in, m) = (self.d_in, self.m);
        let neighbours = scratch
            .starts
            .iter()
            .map(|&s| &self.xs[s..][..d_in])
            .zip(scratch.q.chunks_exact(m));
        if m != 8 {
            let dst = zeroed(dst);
            for (x_j, q_j) in neighbours {
                for (a, &xf) in dst.chunks_exact_mut(m).zip(x_j) {
                    for (a, &qm) in a.iter_mut().zip(q_j) {
                        *a = madd::<FUSED>(*a, xf, qm);
                    }
                }
            }
            return;
        }
        const BLOCK: usize = 8;
        let full = d_in / BLOCK * BLOCK;
        for (f0, out) in (0..full)
            .step_by(BLOCK)
            .zip(dst.chunks_exact_mut(BLOCK * 8))
        {
            let mut acc = [[0.0f32; 8]; BLOCK];
            for (x_j, q_j) in neighbours.clone() {
                let (Ok(q), Ok(x)) = (
                    <&[f32; 8]>::try_from(q_j),
                    <&[f32; BLOCK]>::try_from(&x_j[f0..f0 + BLOCK]),
                ) else {
                    continue;
                };
                for (a, &xf) in acc.iter_mut().zip(x) {
                    for (a, &qm) in a.iter_mut().zip(q) {
                        *a = madd::<FUSED>(*a, xf, qm);
                    }
                }
            }
            for (a, o) in acc.iter().zip(out.chunks_exact_mut(8)) {
                for (&v, o) in a.iter().zip(o) {
                    o.write(v);
                }
            }
        }
        let tail = zeroed(&mut dst[full * 8..]);
        for (x_j, q_j) in neighbours {
            for (a, &xf) in tail.chunks_exact_mut(8).zip(&x_j[full..]) {
                for (a, &qm) in a.iter_mut().zip(q_j) {
                    *a = madd::<FUSED>(*a, xf, qm);
                }
            }
        }
    }

    /// [`Aggregation::write_row`] compiled for AVX2 with FMA (8 lanes, fused) when `fused`
    /// (the CPU has them: [`fma_available`]), else the portable build (SSE2 on x86-64).
    #[inline(always)]
    fn write_row_fast(
        &self,
        row: usize,
        dst: &mut [MaybeUninit<f32>],
        scratch: &mut Scratch,
        fused: bool,
    ) {
        #[cfg(target_arch = "x86_64")]
        if fused {
            // SAFETY: `fused` is only true where the CPU has AVX2 and FMA.
            unsafe { self.write_row_avx2(row, dst, scratch) };
            return;
        }
        let _ = fused;
        self.write_row::<false>(row, dst, scratch);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn write_row_avx2(&self, row: usize, dst: &mut [MaybeUninit<f32>], scratch: &mut Scratch) {
        self.write_row::<true>(row, dst, scratch);
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::feast::aggregate_tensors;
    use crate::init::ParamInit;
    use crate::tensors::vec_tensor;
    use crate::topology::GarmentTopology;
    use burn::prelude::*;
    use rand::{Rng, SeedableRng};

    /// The largest absolute difference between two equally long value lists.
    pub(crate) fn largest_difference(a: &[f32], b: &[f32]) -> f32 {
        assert_eq!(a.len(), b.len());
        a.iter()
            .zip(b)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max)
    }

    fn random(len: usize, range: f32, rng: &mut rand::rngs::StdRng) -> Vec<f32> {
        (0..len).map(|_| rng.random_range(-range..range)).collect()
    }

    /// The plain loops against burn's ops (`FeaStConv::forward` of `[x; pos]`, then the
    /// epilogue as tensor ops) on a batch of two samples over several tiles and a partial
    /// one: 4 heads and 8 (the blocked path), features filling whole blocks of 8 and not,
    /// every epilogue; and both row kernels (portable, and the one this CPU runs) against
    /// the tensor aggregate.
    #[test]
    fn convolution_loops_match_the_tensor_ops() {
        let device = Device::flex();
        let mesh = geom::TriMesh::grid(30, 20, 0.1);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let tt = topo.to_device(&device);
        let (b, n) = (2, mesh.num_vertices());
        assert!(b * n > 2 * TILE && (b * n) % TILE != 0);
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        for (c, m) in [(9, 4), (9, 8), (5, 8)] {
            let d_out = c;
            let conv = FeaStConv::new(c + 3, d_out, m, &mut ParamInit::new(7), &device);
            let xs = random(b * n * c, 1.0, &mut rng);
            let ps = random(b * n * 3, 1.0, &mut rng);
            let x = vec_tensor(xs.clone(), [b, n, c], &device);
            let pos = vec_tensor(ps.clone(), [b, n, 3], &device);
            let xin = Tensor::cat(vec![x.clone(), pos], 2);
            let y = conv.forward(xin.clone(), &tt.ring, &tt.ring_weight);
            let lrelu = |t: Tensor<3>| burn::tensor::activation::leaky_relu(t, LEAKY_SLOPE);
            let cases = [
                (Epilogue::Lrelu, lrelu(y.clone())),
                (Epilogue::ResidualLrelu(&xs), lrelu(x.clone() + y.clone())),
            ];
            for (epilogue, want) in cases {
                let got = conv
                    .forward_rows(&xs, &ps, n, &tt.host_ring, epilogue)
                    .unwrap()
                    .expect("logits within the factored span");
                let want = read_f32(want).unwrap();
                let worst = largest_difference(&got, &want);
                assert!(worst < 1e-5, "C {c}, {m} heads, {epilogue:?}: {worst}");
                assert!(got.iter().any(|v| v.abs() > 0.05), "not all zero");
            }
            // The row kernels against the aggregate of burn's assignment.
            let q = conv.assignment(xin.clone(), &tt.ring, &tt.ring_weight);
            let agg = read_f32(aggregate_tensors(xin.clone(), &tt.ring, q)).unwrap();
            let xin = read_f32(xin).unwrap();
            let u = read_f32(conv.u.weight.val()).unwrap();
            let offsets = read_f32(conv.c.val()).unwrap();
            let (e, f) = factors(&xin, c + 3, &u, &offsets).unwrap();
            let input = Aggregation {
                xs: &xin,
                e: &e,
                f: &f,
                ring: &tt.host_ring,
                n,
                d_in: c + 3,
                m,
            };
            let width = (c + 3) * m;
            let mut scratch = Scratch::default();
            for row in 0..b * n {
                let want = &agg[row * width..][..width];
                for fused in [false, fma_available()] {
                    let mut got = vec![MaybeUninit::new(f32::NAN); width];
                    if fused {
                        input.write_row_fast(row, &mut got, &mut scratch, true);
                    } else {
                        input.write_row::<false>(row, &mut got, &mut scratch);
                    }
                    // SAFETY: every element was initialised (NaN, then the kernel's value).
                    let got: Vec<f32> = got.iter().map(|v| unsafe { v.assume_init() }).collect();
                    let worst = largest_difference(&got, want);
                    assert!(worst < 1e-5, "C {c}, {m} heads, row {row}: {worst}");
                }
            }
        }
    }

    /// Logits spanning the factored limit or more, and mismatched shapes, are left to the
    /// tensor path.
    #[test]
    fn wide_logits_and_bad_shapes_fall_back() {
        let device = Device::flex();
        let mesh = geom::TriMesh::grid(4, 4, 0.1);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let tt = topo.to_device(&device);
        let n = mesh.num_vertices();
        let conv = FeaStConv::new(6, 3, 8, &mut ParamInit::new(3), &device);
        let mut rng = rand::rngs::StdRng::seed_from_u64(9);
        let ps = random(n * 3, 1.0, &mut rng);
        let small = random(n * 3, 1.0, &mut rng);
        let run = |x: &[f32], p: &[f32]| {
            conv.forward_rows(x, p, n, &tt.host_ring, Epilogue::Lrelu)
                .unwrap()
        };
        assert!(run(&small, &ps).is_some());
        let huge: Vec<f32> = small.iter().map(|v| v * 1e4).collect();
        assert!(run(&huge, &ps).is_none());
        assert!(run(&small[3..], &ps).is_none());
    }
}
