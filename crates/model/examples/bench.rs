//! Times GarNet on the CPU (`flex`): forward per drape of each variant at ~3k and ~10k garment
//! vertices on a 13380-point body, and a training step.
//!
//! `cargo run --release -p model --example bench [runs] [garment sizes, comma-separated]`

use burn::prelude::Device;
use model::bench::{bench_forward, bench_train_step};
use model::{GarNetConfig, Variant};

fn main() -> model::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let runs: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    let sizes: Vec<usize> = args
        .get(2)
        .map(|s| s.split(',').filter_map(|x| x.parse().ok()).collect())
        .unwrap_or_else(|| vec![3000, 10000]);
    let n_body = 13380;
    println!(
        "flex CPU backend, {} threads available",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    let device = Device::flex();
    println!("variant  N      V      params    drape median (min..max) ms, CPU ms per drape");
    for &n in &sizes {
        for variant in Variant::ALL {
            let b = bench_forward(&GarNetConfig::new(variant), n, n_body, runs, &device)?;
            println!(
                "{:<8} {:<6} {:<6} {:<9} {:.1} ({:.1}..{:.1}), cpu {:.1}",
                b.variant,
                b.n_garment,
                b.n_body,
                b.params,
                b.drape.median_ms,
                b.drape.min_ms,
                b.drape.max_ms,
                b.drape.cpu_ms.unwrap_or(f64::NAN)
            );
        }
    }
    println!("variant  N      V      batch  train step median (min..max) ms, CPU ms per step");
    for &n in &sizes {
        for variant in Variant::ALL {
            let b = bench_train_step(
                &GarNetConfig::new(variant),
                n,
                n_body,
                1,
                runs.min(3),
                &device,
            )?;
            println!(
                "{:<8} {:<6} {:<6} {:<6} {:.1} ({:.1}..{:.1}), cpu {:.1}",
                b.variant,
                b.n_garment,
                b.n_body,
                b.batch_size,
                b.step.median_ms,
                b.step.min_ms,
                b.step.max_ms,
                b.step.cpu_ms.unwrap_or(f64::NAN)
            );
        }
    }
    Ok(())
}
