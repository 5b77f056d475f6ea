//! Chains of per-point dense layers as plain loops on the CPU, for drapes and evaluation
//! (untracked tensors on flex); training and the GPU backends keep burn's ops.
//!
//! A chain runs tile by tile: [`TILE`] rows of its inputs are gathered into a buffer, each
//! layer's product (`gemm` on this thread), bias and LeakyReLU is worked out on it while it
//! stays in cache, and the tile's last output is written out, or only folded into a running
//! maximum over the rows (the max pooling of PointNet). Tiles run in parallel. On flex each
//! layer was a tensor written to memory, allocated zeroed and copied once more, and the bias,
//! the activation, a concatenation and the max pooling each passed over it again: the
//! fusion MLP took about 21 ms at 10k garment vertices where its products take 7-14 ms,
//! and the garment stream's global layer 15 ms where its product takes 3-5 ms
//! (docs/findings.md, "Speed").

use burn::nn::Linear;
use burn::prelude::*;
use rayon::prelude::*;

use crate::error::Result;
use crate::feast_rows::{add_product, TILE};
use crate::init::LEAKY_SLOPE;
use crate::tensors::{read_f32, untracked_on_flex, vec_tensor};

/// One per-point layer on the host: `y = x W + b (+ the sample's bias)`, then LeakyReLU when
/// `lrelu` is set.
#[derive(Clone, Debug)]
pub struct HostLayer {
    /// `W` `[d_in, d_out]`, row-major.
    weight: Vec<f32>,
    /// `b` `[d_out]`, or per sample `[B, d_out]`.
    bias: Vec<f32>,
    d_in: usize,
    d_out: usize,
    lrelu: bool,
}

impl HostLayer {
    /// `linear` read back (a missing bias as zeros), followed by LeakyReLU when `lrelu`.
    pub fn read(linear: &Linear, lrelu: bool) -> Result<HostLayer> {
        let [d_in, d_out] = linear.weight.dims();
        let bias = match &linear.bias {
            Some(b) => read_f32(b.val())?,
            None => vec![0.0; d_out],
        };
        Ok(HostLayer {
            weight: read_f32(linear.weight.val())?,
            bias,
            d_in,
            d_out,
            lrelu,
        })
    }

    /// The same layer with a bias of its own for each sample: `per_sample` `[B, d_out]`
    /// added to the layer's bias (`CondLinear`'s `W_c c`).
    pub fn with_sample_bias(mut self, per_sample: &[f32]) -> HostLayer {
        self.bias = per_sample
            .chunks_exact(self.d_out.max(1))
            .flat_map(|row| row.iter().zip(&self.bias).map(|(a, b)| a + b))
            .collect();
        self
    }

    /// The bias row of sample `sample`.
    fn bias_of(&self, sample: usize) -> &[f32] {
        match self.bias.len() == self.d_out {
            true => &self.bias,
            false => &self.bias[sample * self.d_out..][..self.d_out],
        }
    }

    /// `dst` `[R, d_out] = lrelu?(src [R, d_in] W + b)` for rows of sample `sample`.
    fn apply(&self, src: &[f32], sample: usize, dst: &mut Vec<f32>) {
        let rows = src.len() / self.d_in.max(1);
        dst.clear();
        let bias = self.bias_of(sample);
        for _ in 0..rows {
            dst.extend_from_slice(bias);
        }
        add_product(dst, src, &self.weight, self.d_in);
        if self.lrelu {
            let slope = LEAKY_SLOPE as f32;
            dst.iter_mut()
                .for_each(|v| *v = if *v >= 0.0 { *v } else { slope * *v });
        }
    }
}

/// What a chain gives back.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChainOutput {
    /// The last layer's output of every row `[B*N, d_last]`, when asked for.
    pub rows: Option<Vec<f32>>,
    /// Its maximum over each sample's rows `[B, d_last]`, when asked for.
    pub max: Option<Vec<f32>>,
}

/// Runs `layers` in order on the rows of `parts`, each `[B*N, w]` row-major with its width
/// `w`, concatenated along the features (the first layer's `d_in` is the sum of the widths),
/// `n` rows per sample. Keeps every row's output when `keep_rows` and the per-sample maximum
/// over rows when `max`. `None` when the shapes do not fit together.
pub fn run_chain(
    parts: &[(&[f32], usize)],
    n: usize,
    layers: &[HostLayer],
    keep_rows: bool,
    max: bool,
) -> Option<ChainOutput> {
    let d_in: usize = parts.iter().map(|p| p.1).sum();
    let rows = parts.first().map(|p| p.0.len() / p.1.max(1))?;
    let fits = parts.iter().all(|(x, w)| *w > 0 && x.len() == rows * w)
        && layers.first().is_some_and(|l| l.d_in == d_in)
        && layers.windows(2).all(|p| p[0].d_out == p[1].d_in)
        && layers
            .iter()
            .all(|l| l.d_out > 0 && l.weight.len() == l.d_in * l.d_out)
        && n > 0
        && rows % n == 0;
    let samples = rows / n.max(1);
    let fits = fits
        && layers
            .iter()
            .all(|l| l.bias.len() == l.d_out || l.bias.len() == samples * l.d_out);
    if !fits {
        return None;
    }
    let d_last = layers.last().map_or(0, |l| l.d_out);
    let tiles = n.div_ceil(TILE);
    // One tile: rows [start, end) of sample `s` through every layer; its last output.
    let run_tile = |s: usize, t: usize| -> Vec<f32> {
        let start = s * n + t * TILE;
        let end = (start + TILE).min((s + 1) * n);
        let mut input = Vec::with_capacity((end - start) * d_in);
        for r in start..end {
            for (x, w) in parts {
                input.extend_from_slice(&x[r * w..][..*w]);
            }
        }
        let mut output = Vec::new();
        for layer in layers {
            layer.apply(&input, s, &mut output);
            std::mem::swap(&mut input, &mut output);
        }
        input
    };
    let column_max = |tile: &[f32]| -> Vec<f32> {
        tile.chunks_exact(d_last)
            .fold(vec![f32::NEG_INFINITY; d_last], |mut m, row| {
                m.iter_mut().zip(row).for_each(|(m, &v)| *m = m.max(v));
                m
            })
    };
    let merge = |mut a: Vec<f32>, b: Vec<f32>| {
        a.iter_mut().zip(&b).for_each(|(a, &b)| *a = a.max(b));
        a
    };
    let mut out = ChainOutput::default();
    if keep_rows {
        let mut all = vec![0.0f32; rows * d_last];
        let maxima: Vec<Vec<f32>> = all
            .par_chunks_mut(n * d_last)
            .enumerate()
            .flat_map(|(s, sample)| {
                sample
                    .par_chunks_mut(TILE * d_last)
                    .enumerate()
                    .map(move |(t, dst)| {
                        let tile = run_tile(s, t);
                        dst.copy_from_slice(&tile);
                        // Only when the pooling is asked for (empty otherwise).
                        if max {
                            column_max(&tile)
                        } else {
                            Vec::new()
                        }
                    })
            })
            .collect();
        if max {
            out.max = Some(per_sample_max(maxima, tiles, d_last, merge));
        }
        out.rows = Some(all);
    } else if max {
        let maxima: Vec<Vec<f32>> = (0..samples * tiles)
            .into_par_iter()
            .map(|i| column_max(&run_tile(i / tiles, i % tiles)))
            .collect();
        out.max = Some(per_sample_max(maxima, tiles, d_last, merge));
    }
    Some(out)
}

/// The tiles' column maxima (sample by sample, `tiles` each) merged into `[B, d]`.
fn per_sample_max(
    maxima: Vec<Vec<f32>>,
    tiles: usize,
    d: usize,
    merge: impl Fn(Vec<f32>, Vec<f32>) -> Vec<f32>,
) -> Vec<f32> {
    maxima
        .chunks(tiles.max(1))
        .flat_map(|sample| {
            sample
                .iter()
                .cloned()
                .reduce(&merge)
                .unwrap_or_else(|| vec![f32::NEG_INFINITY; d])
        })
        .collect()
}

/// [`run_chain`] on tensors: `parts` `[B,N,w]` (untracked, on flex) through the layers that
/// `layers` reads back (only called when this path is taken) -> the rows `[B,N,d]`
/// when `keep_rows` and the per-sample maximum `[B,d]` when `max`, as tensors on the same
/// device. `None` (the caller takes burn's ops) for tracked tensors, another backend or
/// shapes that do not fit.
pub fn chain_tensors(
    parts: &[Tensor<3>],
    layers: impl FnOnce() -> Result<Vec<HostLayer>>,
    keep_rows: bool,
    max: bool,
) -> Option<(Option<Tensor<3>>, Option<Tensor<2>>)> {
    let first = parts.first()?;
    if !parts.iter().all(untracked_on_flex) {
        return None;
    }
    let layers = layers().ok()?;
    let [b, n, _] = first.dims();
    if parts.iter().any(|p| p.dims()[..2] != [b, n]) {
        return None;
    }
    let values: Vec<(Vec<f32>, usize)> = parts
        .iter()
        .map(|p| read_f32(p.clone()).ok().map(|v| (v, p.dims()[2])))
        .collect::<Option<_>>()?;
    let slices: Vec<(&[f32], usize)> = values.iter().map(|(v, w)| (v.as_slice(), *w)).collect();
    let out = run_chain(&slices, n, &layers, keep_rows, max)?;
    let d = layers.last()?.d_out;
    let device = first.device();
    Some((
        out.rows.map(|r| vec_tensor(r, [b, n, d], &device)),
        out.max.map(|m| vec_tensor(m, [b, d], &device)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::feast_rows::tests::largest_difference;
    use crate::init::ParamInit;
    use crate::layers::{lrelu, max_points};
    use rand::{Rng, SeedableRng};

    /// Chains against burn's ops (each layer's product, bias, the per-sample bias and the
    /// activation, then the max pooling) on two samples of 300 rows (a whole tile and a
    /// partial one each) from two input parts: the rows, the pooling, and both at once.
    #[test]
    fn chains_match_the_tensor_ops() {
        let device = Device::flex();
        let mut init = ParamInit::new(3);
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let (b, n, widths) = (2, 300, [5, 3]);
        assert!(n > TILE && n % TILE != 0);
        let parts: Vec<Tensor<3>> = widths
            .iter()
            .map(|&w| {
                let v = (0..b * n * w)
                    .map(|_| rng.random_range(-1.0..1.0))
                    .collect();
                vec_tensor(v, [b, n, w], &device)
            })
            .collect();
        let first = init.hidden(8, 20, &device);
        let second = init.hidden(20, 7, &device);
        let last = init.scaled(7, 3, 0.5, &device);
        let per_sample: Vec<f32> = (0..b * 20).map(|_| rng.random_range(-1.0..1.0)).collect();
        let sample_bias = vec_tensor(per_sample.clone(), [b, 20], &device).unsqueeze_dim(1);
        let x = Tensor::cat(parts.clone(), 2);
        let h = lrelu(first.forward(x) + sample_bias);
        let want_rows = last.forward(lrelu(second.forward(h)));
        let want_max = read_f32(max_points(want_rows.clone())).unwrap();
        let want_rows = read_f32(want_rows).unwrap();
        let layers = || {
            Ok(vec![
                HostLayer::read(&first, true)?.with_sample_bias(&per_sample),
                HostLayer::read(&second, true)?,
                HostLayer::read(&last, false)?,
            ])
        };
        for (keep_rows, max) in [(true, false), (false, true), (true, true)] {
            let (rows, pooled) = chain_tensors(&parts, layers, keep_rows, max).unwrap();
            assert_eq!((rows.is_some(), pooled.is_some()), (keep_rows, max));
            if let Some(rows) = rows {
                assert_eq!(rows.dims(), [b, n, 3]);
                let got = read_f32(rows).unwrap();
                let worst = largest_difference(&got, &want_rows);
                assert!(worst < 1e-5, "rows: {worst}");
                assert!(got.iter().any(|v| v.abs() > 0.05), "not all zero");
            }
            if let Some(pooled) = pooled {
                assert_eq!(pooled.dims(), [b, 3]);
                let worst = largest_difference(&read_f32(pooled).unwrap(), &want_max);
                assert!(worst < 1e-5, "max: {worst}");
            }
        }
    }

    /// Tracked tensors, inputs whose width is not the first layer's, layers that do not
    /// chain, or a per-sample bias for another batch size all leave it to burn's ops.
    #[test]
    fn tracked_tensors_and_misfits_fall_back() {
        let device = Device::flex();
        let mut init = ParamInit::new(4);
        let a = init.hidden(4, 6, &device);
        let b = init.hidden(6, 2, &device);
        let x = Tensor::<3>::ones([2, 10, 4], &device);
        let host = |l: &Linear| HostLayer::read(l, true);
        assert!(chain_tensors(
            std::slice::from_ref(&x),
            || Ok(vec![host(&a)?, host(&b)?]),
            true,
            true
        )
        .is_some());
        let tracked = Tensor::<3>::ones([2, 10, 4], &device.clone().autodiff()).require_grad();
        assert!(chain_tensors(&[tracked], || Ok(vec![host(&a)?]), true, true).is_none());
        let narrow = Tensor::<3>::ones([2, 10, 3], &device);
        assert!(chain_tensors(&[narrow], || Ok(vec![host(&a)?]), true, true).is_none());
        assert!(
            chain_tensors(std::slice::from_ref(&x), || Ok(vec![host(&b)?]), true, true).is_none()
        );
        assert!(chain_tensors(
            std::slice::from_ref(&x),
            || Ok(vec![host(&a)?, host(&a)?]),
            true,
            true
        )
        .is_none());
        let three_samples = host(&a).unwrap().with_sample_bias(&[0.5; 18]);
        assert!(chain_tensors(&[x], || Ok(vec![three_samples]), true, true).is_none());
    }
}
