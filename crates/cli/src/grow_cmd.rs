//! `garnet grow`: a trained checkpoint with wider layers (new features whose weights into the
//! trained ones start at zero) and extra residual blocks of mesh convolutions that start as
//! the identity, so it drapes as before and `garnet train --resume` trains the larger
//! network on from there.

use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;

/// Arguments of `garnet grow`.
#[derive(Args, Debug, Clone)]
pub struct GrowArgs {
    /// Checkpoint to grow (GarNet-Global or -Local; GarNet-Naive's fusion can be widened).
    #[arg(long, value_name = "CKPT")]
    pub model: PathBuf,
    /// Residual blocks to add after the network's blocks.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub extra_blocks: usize,
    /// Widen the mesh convolutions to this many features (at least the network's own).
    #[arg(long, value_name = "C")]
    pub conv_width: Option<usize>,
    /// Widen the fusion network's hidden layers to these widths, as many as it has, none
    /// narrower than its own (e.g. `256,128,64` for the default `128,64,32`).
    #[arg(long, value_name = "W,W,W", value_delimiter = ',')]
    pub fusion: Option<Vec<usize>>,
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
    let plan = model::GrowPlan {
        extra_blocks: args.extra_blocks,
        conv_width: args.conv_width,
        fusion: args.fusion.clone(),
    };
    let params = model::grow_checkpoint(&args.model, &args.out, &plan, &command)
        .with_context(|| format!("growing {}", args.model.display()))?;
    let mut what = Vec::new();
    if let Some(c) = args.conv_width {
        what.push(format!("convolutions {c} features wide"));
    }
    if let Some(f) = &args.fusion {
        what.push(format!("fusion widths {f:?}"));
    }
    if args.extra_blocks > 0 {
        what.push(format!("{} more blocks", args.extra_blocks));
    }
    eprintln!(
        "wrote {}: {} with {} ({params} parameters), draping as before",
        args.out.display(),
        args.model.display(),
        what.join(", ")
    );
    Ok(())
}
