//! `garnet grow`: a trained checkpoint with extra residual blocks of mesh convolutions that
//! start as the identity, so it drapes as before and `garnet train --resume` trains the
//! deeper network on from there.

use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;

/// Arguments of `garnet grow`.
#[derive(Args, Debug, Clone)]
pub struct GrowArgs {
    /// Checkpoint to grow (GarNet-Global or -Local).
    #[arg(long, value_name = "CKPT")]
    pub model: PathBuf,
    /// Residual blocks to add after the network's blocks.
    #[arg(long, value_name = "N")]
    pub extra_blocks: usize,
    /// Checkpoint to write (`.garnet`), without optimiser state; put it in a run folder as
    /// `last.garnet` to train it on with `garnet train --resume`.
    #[arg(long, value_name = "FILE.garnet")]
    pub out: PathBuf,
}

/// Runs `garnet grow`.
pub fn run(args: &GrowArgs) -> anyhow::Result<()> {
    if args.out.extension().and_then(|e| e.to_str()) != Some("garnet") {
        bail!("{}: the checkpoint must end in .garnet", args.out.display());
    }
    let command = crate::output::command_line();
    let params = model::grow_checkpoint(&args.model, &args.out, args.extra_blocks, &command)
        .with_context(|| format!("growing {}", args.model.display()))?;
    eprintln!(
        "wrote {}: {} with {} more blocks ({params} parameters), draping as before",
        args.out.display(),
        args.model.display(),
        args.extra_blocks
    );
    Ok(())
}
