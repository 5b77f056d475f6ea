//! `garnet export`: a training checkpoint as a model to ship, with its model card beside it
//! ([`garnet::export`]).

use std::path::PathBuf;

use clap::Args;
use garnet::export::{export, ExportJob};

use crate::model_device::DeviceArg;

/// Arguments of `garnet export`.
#[derive(Args, Debug, Clone)]
pub struct ExportArgs {
    /// Training checkpoint (`best.garnet` or `last.garnet` of `garnet train`).
    #[arg(long, value_name = "CKPT")]
    pub model: PathBuf,
    /// The dataset whose `--split` gives the card's metrics: the one the model was trained
    /// on, unless `--train-data` names another.
    #[arg(long, value_name = "DIR")]
    pub data: PathBuf,
    /// The dataset the model was trained on, when it is not `--data`: a larger dataset of
    /// the same bodies, so the card can report the metrics on `--data`'s test split. Its
    /// training bodies must not be in that split.
    #[arg(long, value_name = "DIR")]
    pub train_data: Option<PathBuf>,
    /// Split for the card's metrics.
    #[arg(long, default_value = "test")]
    pub split: String,
    /// Evaluate at most this many samples.
    #[arg(long, value_name = "N")]
    pub max_samples: Option<usize>,
    /// Model file to write (`.garnet`); the card goes beside it with the extension `.md`.
    /// The card adds the metrics on the drapes the recipe's `[drapes]` keeps.
    #[arg(long, value_name = "FILE.garnet")]
    pub out: PathBuf,
}

/// Runs `garnet export`.
pub fn run(args: &ExportArgs) -> anyhow::Result<()> {
    let job = ExportJob {
        model: args.model.clone(),
        data: args.data.clone(),
        train_data: args.train_data.clone(),
        split: args.split.clone(),
        max_samples: args.max_samples,
        out: args.out.clone(),
    };
    let card = export(&job, &DeviceArg::Cpu.device()?)?;
    eprintln!(
        "wrote {} ({:.1} MB) and {}",
        args.out.display(),
        std::fs::metadata(&args.out)?.len() as f64 / 1e6,
        card.display()
    );
    Ok(())
}
