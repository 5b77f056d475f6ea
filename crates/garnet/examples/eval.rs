//! Evaluate shipped models on a dataset's test split as the paper does (Table 1, Table 2,
//! precision curves, E_dist by motion), with the library alone.
//!
//! ```sh
//! cargo run --release --example eval -- DATASET_DIR [MODEL.garnet ...] [--out DIR]
//! ```
//!
//! With no model given, the three shipped GarNet-Local models; the report goes to
//! `out/example-eval` unless `--out` names another folder.

use std::path::PathBuf;

use garnet::{evaluate, shipped_models, Device, EvalOptions};

fn main() -> anyhow::Result<()> {
    // Process-wide malloc tuning for the networks' large temporaries (see model::alloc).
    garnet::model::tune_allocator();
    let mut args = std::env::args().skip(1);
    let (mut data, mut models, mut out) = (None, Vec::new(), PathBuf::from("out/example-eval"));
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => {
                out = args
                    .next()
                    .map(PathBuf::from)
                    .ok_or_else(|| anyhow::anyhow!("--out needs a folder"))?
            }
            _ if data.is_none() => data = Some(PathBuf::from(a)),
            _ => models.push(PathBuf::from(a)),
        }
    }
    let data = data
        .ok_or_else(|| anyhow::anyhow!("usage: eval DATASET_DIR [MODEL.garnet ...] [--out DIR]"))?;
    if models.is_empty() {
        models = shipped_models()?;
    }
    let report = evaluate(
        &data,
        "test",
        &models,
        &EvalOptions::default(),
        &Device::flex(),
    )?;
    for (garment, method, samples, e_dist, e_norm, _) in report.table1() {
        println!("{garment:8} {method:32} {samples:4} drapes  E_dist {e_dist:.3} cm  E_norm {e_norm:.2} deg");
    }
    report.write(&out)?;
    println!("wrote {}", out.display());
    Ok(())
}
