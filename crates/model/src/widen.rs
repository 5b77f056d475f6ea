//! Widening a trained network: more features in the garment stream's mesh convolutions
//! ([`GarNetConfig::conv_width`]) and wider fusion layers ([`GarNetConfig::fusion`]), without
//! changing what it drapes (function-preserving widening, as Net2Net's "wider" operation but
//! with zero outgoing weights instead of copied units).
//!
//! Every widened layer keeps its trained weights. A new feature (a new output column) gets
//! the initial values a fresh network of the wider config draws, so it starts as a real,
//! varied feature; every weight from a new feature into a trained one (a new input row of a
//! trained output column) is zero, so no trained feature, and not the output, sees the new
//! ones until training moves those weights. Their gradients are not zero (the new features
//! are), so `garnet train --resume` grows them from the first step.

use burn::module::Param;
use burn::nn::Linear;
use burn::prelude::*;

use crate::config::GarNetConfig;
use crate::error::{ModelError, Result};
use crate::feast::FeaStConv;
use crate::fusion::Fusion;
use crate::garment_stream::{ExtraBlock, GarmentStream, ResBlock};
use crate::garnet::GarNet;
use crate::layers::CondLinear;
use crate::tensors::{read_f32, vec_tensor};

/// `0..n`: a layer side that keeps its positions.
fn same(n: usize) -> Vec<usize> {
    (0..n).collect()
}

/// Positions `0..n` with those from `at` on moved up by `by`: a layer side that gets `by`
/// new entries inserted before position `at`.
fn shifted(n: usize, at: usize, by: usize) -> Vec<usize> {
    (0..n).map(|i| if i < at { i } else { i + by }).collect()
}

/// The trained layer `old` `[R,C]` placed inside the wider `fresh` `[R',C']`: `old`'s entry
/// `(i, j)` goes to `(rows[i], cols[j])` and its bias `j` to `cols[j]`; the rows of `fresh`
/// that no trained row lands on are zero in the trained columns `cols`; everything else
/// (the new columns) keeps `fresh`'s initial values.
fn embed(old: &Linear, fresh: Linear, rows: &[usize], cols: &[usize]) -> Result<Linear> {
    let [r0, c0] = old.weight.val().dims();
    let [r1, c1] = fresh.weight.val().dims();
    if rows.len() != r0 || cols.len() != c0 || rows.iter().any(|&r| r >= r1) {
        return Err(ModelError::InvalidInput(format!(
            "cannot place a [{r0},{c0}] layer in a [{r1},{c1}] one"
        )));
    }
    if cols.iter().any(|&c| c >= c1) || old.bias.is_some() != fresh.bias.is_some() {
        return Err(ModelError::InvalidInput(format!(
            "cannot place a [{r0},{c0}] layer in a [{r1},{c1}] one with the same bias"
        )));
    }
    let device = fresh.weight.val().device();
    let trained = read_f32(old.weight.val())?;
    let mut w = read_f32(fresh.weight.val())?;
    let mut kept_row = vec![false; r1];
    rows.iter().for_each(|&r| kept_row[r] = true);
    for r in (0..r1).filter(|&r| !kept_row[r]) {
        cols.iter().for_each(|&c| w[r * c1 + c] = 0.0);
    }
    for (i, &r) in rows.iter().enumerate() {
        for (j, &c) in cols.iter().enumerate() {
            w[r * c1 + c] = trained[i * c0 + j];
        }
    }
    let bias = match (&old.bias, fresh.bias) {
        (Some(old_b), Some(fresh_b)) => {
            let trained = read_f32(old_b.val())?;
            let mut b = read_f32(fresh_b.val())?;
            cols.iter().zip(trained).for_each(|(&c, v)| b[c] = v);
            Some(Param::from_tensor(vec_tensor(b, [c1], &device)))
        }
        _ => None,
    };
    Ok(Linear {
        weight: Param::from_tensor(vec_tensor(w, [r1, c1], &device)),
        bias,
    })
}

/// A convolution `C0+3 -> C0` placed in a fresh `C1+3 -> C1` one: its input is `[x; M]`,
/// so the 3 position rows move up by `C1 - C0`; the head weights' rows are
/// `feature * heads + head`.
fn embed_conv(old: FeaStConv, fresh: FeaStConv, c0: usize, c1: usize) -> Result<FeaStConv> {
    let heads = old.heads();
    let features = shifted(c0 + 3, c0, c1 - c0);
    let w_rows: Vec<usize> = features
        .iter()
        .flat_map(|&f| (0..heads).map(move |m| f * heads + m))
        .collect();
    Ok(FeaStConv {
        u: embed(&old.u, fresh.u, &features, &same(heads))?,
        w: embed(&old.w, fresh.w, &w_rows, &same(c0))?,
        c: old.c,
    })
}

/// The garment stream with its convolutions `c0 -> c1` features wide.
fn widen_garment(
    old: GarmentStream,
    fresh: GarmentStream,
    point_width: usize,
    c0: usize,
    c1: usize,
) -> Result<GarmentStream> {
    let conv_in = match (old.conv_in, fresh.conv_in) {
        (Some(o), Some(f)) => Some(embed(&o, f, &same(point_width), &same(c0))?),
        (None, None) => None,
        _ => {
            return Err(ModelError::InvalidInput(format!(
                "a convolution width of {c1} would change whether a layer maps the \
                 {point_width} point-wise features into the convolutions; choose another width"
            )))
        }
    };
    let mut blocks = Vec::with_capacity(old.blocks.len());
    for (o, f) in old.blocks.into_iter().zip(fresh.blocks) {
        let convs = o
            .convs
            .into_iter()
            .zip(f.convs)
            .map(|(o, f)| embed_conv(o, f, c0, c1))
            .collect::<Result<_>>()?;
        blocks.push(ResBlock { convs });
    }
    let extra = old
        .extra
        .into_iter()
        .zip(fresh.extra)
        .map(|(o, f)| {
            Ok(ExtraBlock {
                conv: embed_conv(o.conv, f.conv, c0, c1)?,
            })
        })
        .collect::<Result<_>>()?;
    let g = old.global.weight.val().dims()[1];
    let global_in = old.global.weight.val().dims()[0];
    Ok(GarmentStream {
        stn: old.stn,
        mlp: old.mlp,
        conv_in,
        blocks,
        extra,
        global: embed(&old.global, fresh.global, &same(global_in), &same(g))?,
    })
}

/// The fusion network with hidden widths `widths` (each at least the trained one), its
/// per-vertex input placed by `input_rows`.
fn widen_fusion(old: Fusion, fresh: Fusion, input_rows: &[usize]) -> Result<Fusion> {
    let width = |l: &Linear| l.weight.val().dims()[1];
    let f0 = width(&old.first.point);
    let d_global = old.first.cond.weight.val().dims()[0];
    let first = CondLinear {
        point: embed(&old.first.point, fresh.first.point, input_rows, &same(f0))?,
        cond: embed(
            &old.first.cond,
            fresh.first.cond,
            &same(d_global),
            &same(f0),
        )?,
    };
    let mut hidden = Vec::with_capacity(old.hidden.len());
    let mut d_in = f0;
    for (o, f) in old.hidden.iter().zip(fresh.hidden) {
        let d_out = width(o);
        hidden.push(embed(o, f, &same(d_in), &same(d_out))?);
        d_in = d_out;
    }
    let out = embed(&old.out, fresh.out, &same(d_in), &same(3))?;
    Ok(Fusion { first, hidden, out })
}

/// `model` (built from `config`) widened to `conv_width` mesh-convolution features and the
/// fusion hidden widths `fusion` (as many as `config.fusion`, none narrower), draping as
/// before, and the wider config. New values come from a fresh network of the wider config
/// (its seed). Refused: narrower widths, another fusion depth, no change at all, a wider
/// convolution on GarNet-Naive, or a width equal to the point-wise garment width where
/// there was none (or the other way round), which would add or drop a layer.
pub fn widen_network(
    model: GarNet,
    config: &GarNetConfig,
    conv_width: usize,
    fusion: &[usize],
    device: &Device,
) -> Result<(GarNet, GarNetConfig)> {
    let (c0, c1) = (config.conv_width, conv_width);
    let narrower = fusion.iter().zip(&config.fusion).any(|(n, o)| n < o);
    if fusion.len() != config.fusion.len() || narrower || c1 < c0 {
        return Err(ModelError::InvalidInput(format!(
            "a network can only be widened: convolutions {c0} -> {c1}, fusion {:?} -> \
             {fusion:?}",
            config.fusion
        )));
    }
    if c1 == c0 && fusion == config.fusion.as_slice() {
        return Err(ModelError::InvalidInput(
            "the widths given are the network's own: nothing to widen".into(),
        ));
    }
    if c1 != c0 && !config.variant.has_mesh_conv() {
        return Err(ModelError::InvalidInput(
            "GarNet-Naive has no mesh convolutions to widen".into(),
        ));
    }
    let wider = config
        .clone()
        .with_conv_width(c1)
        .with_fusion(fusion.to_vec());
    let fresh = wider.init(device)?;
    let p = config.garment_point_width();
    let (c0_in, extra_in) = if config.variant.has_mesh_conv() {
        (c0, c1 - c0)
    } else {
        (0, 0)
    };
    let local = if config.variant.has_local() {
        config.local_width
    } else {
        0
    };
    let input_rows = shifted(p + c0_in + local, p + c0_in, extra_in);
    let garment = widen_garment(model.garment, fresh.garment, p, c0, c1)?;
    let fusion = widen_fusion(model.fusion, fresh.fusion, &input_rows)?;
    Ok((
        GarNet {
            garment,
            fusion,
            ..model
        },
        wider,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Variant;
    use crate::init::ParamInit;

    /// The plain reference of [`embed`]: each entry of the wider layer written out.
    #[test]
    fn embed_keeps_trained_entries_zeroes_new_rows_into_them_and_keeps_new_columns() {
        let device = Device::flex();
        let mut init = ParamInit::new(3);
        let old = init.hidden(2, 2, &device);
        let fresh = init.hidden(3, 4, &device);
        let (o, f) = (
            read_f32(old.weight.val()).unwrap(),
            read_f32(fresh.weight.val()).unwrap(),
        );
        let ob = read_f32(old.bias.clone().unwrap().val()).unwrap();
        let fb = read_f32(fresh.bias.clone().unwrap().val()).unwrap();
        // Trained rows 0, 1 go to rows 0, 2; trained columns 0, 1 to columns 1, 3.
        let got = embed(&old, fresh, &[0, 2], &[1, 3]).unwrap();
        let w = read_f32(got.weight.val()).unwrap();
        let expected = vec![
            f[0], o[0], f[2], o[1], //
            f[4], 0.0, f[6], 0.0, //
            f[8], o[2], f[10], o[3],
        ];
        assert_eq!(w, expected);
        let b = read_f32(got.bias.unwrap().val()).unwrap();
        assert_eq!(b, vec![fb[0], ob[0], fb[2], ob[1]]);
    }

    #[test]
    fn narrower_unchanged_naive_and_layer_changing_widths_are_refused() {
        let device = Device::flex();
        let cfg = GarNetConfig::tiny(Variant::Global);
        let net = || cfg.init(&device).unwrap();
        let fusion = cfg.fusion.clone();
        for (conv, fus) in [
            (cfg.conv_width - 1, fusion.clone()),
            (cfg.conv_width, vec![64, 32]),
            (cfg.conv_width, vec![64, 16, 16]),
            (cfg.conv_width, fusion.clone()),
            // The point-wise garment width: no layer into the convolutions any more.
            (cfg.garment_point_width(), fusion.clone()),
        ] {
            assert!(widen_network(net(), &cfg, conv, &fus, &device).is_err());
        }
        let naive = GarNetConfig::tiny(Variant::Naive);
        let n = naive.init(&device).unwrap();
        assert!(widen_network(n, &naive, naive.conv_width + 8, &naive.fusion, &device).is_err());
        let n = naive.init(&device).unwrap();
        let (_, wide) = widen_network(n, &naive, naive.conv_width, &[80, 32, 16], &device).unwrap();
        assert_eq!(wide.fusion, vec![80, 32, 16]);
    }

    #[test]
    fn widened_network_has_the_parameters_of_its_config() {
        let device = Device::flex();
        let cfg = GarNetConfig::tiny(Variant::Local).with_extra_blocks(1);
        let (wide, wide_cfg) =
            widen_network(cfg.init(&device).unwrap(), &cfg, 24, &[80, 48, 16], &device).unwrap();
        assert_eq!((wide_cfg.conv_width, wide_cfg.extra_blocks), (24, 1));
        assert_eq!(
            wide.num_params(),
            wide_cfg.init(&device).unwrap().num_params()
        );
    }
}
