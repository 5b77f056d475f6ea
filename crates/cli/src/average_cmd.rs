//! `garnet average`: the element-wise mean of the networks of several checkpoints of one
//! run (stochastic weight averaging), written as one checkpoint that drapes, evaluates,
//! exports and resumes like any other.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::Args;

/// Arguments of `garnet average`.
#[derive(Args, Debug, Clone)]
pub struct AverageArgs {
    /// Checkpoints to average (two or more, of one architecture, garment and loss), say the
    /// snapshots of a run's last epochs at a low constant learning rate.
    #[arg(long, value_name = "CKPT", num_args = 2.., required = true)]
    pub models: Vec<PathBuf>,
    /// Weights of the networks, one per checkpoint in the order given, summing to 1 (say
    /// `0.25,0.25,0.5`); negative weights extrapolate (`-1,2`: twice the step from the first
    /// network to the second). Without it, the plain mean.
    #[arg(
        long,
        value_name = "W,W,...",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub weights: Option<Vec<f64>>,
    /// Checkpoint to write (`.garnet`), without optimiser state.
    #[arg(long, value_name = "FILE.garnet")]
    pub out: PathBuf,
}

/// Runs `garnet average`.
pub fn run(args: &AverageArgs) -> anyhow::Result<()> {
    if args.out.extension().and_then(|e| e.to_str()) != Some("garnet") {
        bail!("{}: the checkpoint must end in .garnet", args.out.display());
    }
    let inputs: Vec<&Path> = args.models.iter().map(PathBuf::as_path).collect();
    let command = crate::output::command_line();
    let report = model::average_checkpoints(
        &inputs,
        args.weights.as_deref(),
        &args.out,
        &command,
        crate::train_drapes::training_drapes,
    )
    .with_context(|| format!("averaging into {}", args.out.display()))?;
    let what = match &args.weights {
        Some(w) => format!("the combination with weights {w:?}"),
        None => "the mean".to_string(),
    };
    eprintln!(
        "wrote {}: {what} of {} networks ({} parameters each) of epochs {:?}",
        args.out.display(),
        inputs.len(),
        report.parameters,
        report.epochs
    );
    Ok(())
}
