//! `garnet bench model`: GarNet's forward time per drape (batch 1) for each variant at
//! given garment sizes on the 13,380-vertex body, and a training step, each with its ratio
//! to the DQS warp of the 1 cm T-shirt measured in the same run.

use body::BodyModel;
use burn::prelude::Device;
use model::bench::{bench_forward, bench_train_step};
use model::{GarNetConfig, Variant};

use crate::bench_cmd::TshirtCase;

/// Body vertices the networks see (the body model's mesh).
const BODY_VERTICES: usize = 13380;

/// Runs the benchmark and prints a Markdown table.
pub fn bench_model(runs: usize, sizes: &[usize]) -> anyhow::Result<()> {
    let body_model = BodyModel::load()?;
    let reference = TshirtCase::new(&body_model, 0.01, 5)?;
    let warp_ms = reference.warp.as_secs_f64() * 1e3;
    let device = Device::flex();
    println!(
        "garnet bench model: flex CPU backend, {} threads; body {BODY_VERTICES} vertices; \
         reference: DQS warp of the {}-vertex T-shirt",
        rayon::current_num_threads(),
        reference.template.mesh.vertices.len()
    );
    println!("| measure | variant | garment vertices | parameters | median (min..max) ms | CPU ms | ratio to DQS warp |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    println!(
        "| DQS warp (reference) | | {} | | {warp_ms:.2} | | 1 |",
        reference.template.mesh.vertices.len()
    );
    for &n in sizes {
        for variant in Variant::ALL {
            let b = bench_forward(&GarNetConfig::new(variant), n, BODY_VERTICES, runs, &device)?;
            let t = &b.drape;
            println!(
                "| drape (forward, batch 1) | {} | {} | {} | {:.1} ({:.1}..{:.1}) | {:.1} | {:.0} |",
                b.variant,
                b.n_garment,
                b.params,
                t.median_ms,
                t.min_ms,
                t.max_ms,
                t.cpu_ms.unwrap_or(f64::NAN),
                t.median_ms / warp_ms
            );
        }
    }
    for &n in sizes {
        for variant in Variant::ALL {
            let b = bench_train_step(
                &GarNetConfig::new(variant),
                n,
                BODY_VERTICES,
                1,
                runs.clamp(1, 3),
                &device,
            )?;
            let t = &b.step;
            println!(
                "| training step (batch 1) | {} | {} | | {:.1} ({:.1}..{:.1}) | {:.1} | {:.0} |",
                b.variant,
                b.n_garment,
                t.median_ms,
                t.min_ms,
                t.max_ms,
                t.cpu_ms.unwrap_or(f64::NAN),
                t.median_ms / warp_ms
            );
        }
    }
    Ok(())
}
