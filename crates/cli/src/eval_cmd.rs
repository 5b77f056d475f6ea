//! `garnet eval`: trained models on a dataset split, as the paper reports them
//! ([`garnet::eval`]): results.md (printed too), results.json and two precision charts; with
//! `--html`, results.html too ([`crate::view_cmd::write_eval_page`]).

use std::path::PathBuf;

use clap::Args;
use garnet::EvalOptions;

use crate::drape_filter_args::DrapeFilterArgs;
use crate::model_device::DeviceArg;

/// Arguments of `garnet eval`.
#[derive(Args, Debug, Clone)]
pub struct EvalArgs {
    /// Dataset folder.
    #[arg(long, value_name = "DIR")]
    pub data: PathBuf,
    /// Split to evaluate on.
    #[arg(long, default_value = "test")]
    pub split: String,
    /// Trained model files (any garments and variants).
    #[arg(long = "model", value_name = "CKPT", required = true, num_args = 1..)]
    pub models: Vec<PathBuf>,
    /// Output folder: results.md, results.json, precision_dist.png, precision_norm.png (and
    /// drapes.png with `--pictures`).
    #[arg(long, default_value = "out/eval")]
    pub out: PathBuf,
    /// Evaluate at most this many samples per garment.
    #[arg(long, value_name = "N")]
    pub max_samples: Option<usize>,
    /// Which drapes to evaluate on (default: every one; the report says which).
    #[command(flatten)]
    pub drapes: DrapeFilterArgs,
    /// Where the networks run.
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    pub device: DeviceArg,
    /// Also report each network's drapes after `garnet drape`'s push-out (vertices inside
    /// the body or nearer its skin than 4 mm moved out to 4 mm), as rows "GarNet-X, pushed
    /// out" (the paper's Table 1 has the network's raw output only).
    #[arg(long)]
    pub push_out: bool,
    /// Also a row per garment of the surface-anchored M: the template placed on each posed
    /// body by its surface anchors (where the fitted-start simulator starts, and the M of a
    /// network with `base = "anchored"`); a baseline beside DQS.
    #[arg(long)]
    pub fitted: bool,
    /// Also write every evaluated drape (the network's, the simulator's, the warped M and
    /// the body, PLY in metres) and a table of each drape's errors, `samples.csv`, into
    /// `DIR/MODEL/` for each model file `MODEL.garnet` (`DIR/PARENT-MODEL/` where file names
    /// repeat).
    #[arg(long, value_name = "DIR")]
    pub save_drapes: Option<PathBuf>,
    /// Also write the report as a self-contained HTML page, `results.html` in the output
    /// folder: the tables, the precision charts and, with `--save-drapes`, each model's worst
    /// three drapes in 3D, coloured by each vertex's distance to the simulator's drape.
    #[arg(long)]
    pub html: bool,
    /// The row name of each model in the tables, in the order of `--model` (one per model),
    /// in place of its method name: e.g. the loss terms of an ablation's rows.
    #[arg(long = "label", value_name = "NAME", num_args = 1..)]
    pub labels: Vec<String>,
    /// Also draw, per garment, one drape (the first model's drape of median E_dist) by the
    /// simulator and by every model, on the body, into `drapes.png` in the output folder.
    #[arg(long)]
    pub pictures: bool,
}

/// Runs `garnet eval`.
pub fn run(args: &EvalArgs) -> anyhow::Result<()> {
    let opts = EvalOptions {
        filter: args.drapes.filter()?,
        max_samples: args.max_samples,
        push_out: args.push_out,
        fitted: args.fitted,
        save_drapes: args.save_drapes.clone(),
        labels: args.labels.clone(),
        pictures: args.pictures,
    };
    let report = garnet::evaluate(
        &args.data,
        &args.split,
        &args.models,
        &opts,
        &args.device.device()?,
    )?;
    report.write(&args.out)?;
    print!("{}", report.markdown());
    if args.html {
        let saved = args
            .save_drapes
            .as_ref()
            .map(|root| garnet::eval::save::save_folders(root, &args.models));
        crate::view_cmd::write_eval_page(&args.out, saved.as_deref())?;
    }
    eprintln!("wrote {}", args.out.display());
    Ok(())
}
