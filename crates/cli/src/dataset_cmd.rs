//! `garnet dataset`: check a spec, generate (sharded, resumable), merge, inspect, show,
//! measure how repeatable the drapes are.

use std::path::{Path, PathBuf};

use anyhow::Context;
use body::BodyModel;
use clap::{Args, Subcommand};
use dataset::{Dataset, GenerateOptions, LoadedSpec, Plan, ShardSelection, Summary};
use indicatif::{ProgressBar, ProgressStyle};

use crate::log_lines::{LogLines, LOG_EVERY};

/// `garnet dataset` subcommands.
#[derive(Subcommand, Debug)]
pub enum DatasetCmd {
    /// Check a spec and show what it would make (no drapes).
    Plan(PlanArgs),
    /// Generate (or resume) a dataset: `garnet dataset generate SPEC --out DIR`.
    Generate(GenerateArgs),
    /// Merge the folders of `--shard i/n` runs into one dataset.
    Merge(MergeArgs),
    /// Counts per split and garment, simulator statistics, failures.
    Info(InfoArgs),
    /// A picture of one sample: the body, M (warped) and G (draped) side by side.
    Show(crate::dataset_show::ShowArgs),
    /// How repeatable the labels are: samples draped at the spec's cloth density and 0.1%
    /// above and below it, and the distances between the drapes.
    Spread(crate::dataset_spread::SpreadArgs),
}

/// Where the mocap clips are.
#[derive(Args, Debug)]
pub struct MocapArg {
    /// Folder that the spec's clip paths are relative to (default: $GARNET_MOCAP); needed
    /// when the spec names clips.
    #[arg(long, value_name = "DIR")]
    pub mocap: Option<PathBuf>,
}

impl MocapArg {
    /// `--mocap`, else `GARNET_MOCAP`, else none.
    pub fn root(&self) -> Option<PathBuf> {
        self.mocap
            .clone()
            .or_else(|| std::env::var_os("GARNET_MOCAP").map(PathBuf::from))
    }
}

/// The spec file and the overrides of its poses per body.
#[derive(Args, Debug)]
pub struct SpecArg {
    /// The spec file (TOML).
    pub spec: PathBuf,
    /// Samples per body of some garments instead of the spec's, e.g. tshirt=99 or
    /// tshirt=99,sweater=54 (the dataset folder records the spec with them).
    #[arg(long, value_name = "GARMENT=N[,GARMENT=N]")]
    pub poses: Option<String>,
}

impl SpecArg {
    /// The spec, its base and the `--poses` overrides resolved.
    pub fn load(&self) -> anyhow::Result<LoadedSpec> {
        let poses = match &self.poses {
            Some(text) => dataset::spec_load::parse_poses_override(text)?,
            None => Vec::new(),
        };
        Ok(LoadedSpec::load_with(&self.spec, &poses)?)
    }
}

/// Arguments of `garnet dataset plan`.
#[derive(Args, Debug)]
pub struct PlanArgs {
    #[command(flatten)]
    pub spec: SpecArg,
    #[command(flatten)]
    pub mocap: MocapArg,
}

/// Arguments of `garnet dataset generate`.
#[derive(Args, Debug)]
pub struct GenerateArgs {
    #[command(flatten)]
    pub spec: SpecArg,
    /// The dataset folder (created; an existing one of the same spec is resumed).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Samples drawn in parallel (default: one per core).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Make only shards s with s % n == i (for job arrays), or only the listed shards and
    /// inclusive ranges, e.g. 0-9,12; merge the folders after.
    #[arg(long, value_name = "i/n|a-b,c")]
    pub shard: Option<String>,
    /// Of those, make only the shards that hold a sample of these splits (comma-separated,
    /// e.g. test): the drapes an evaluation needs, without the rest of the dataset.
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub split: Vec<String>,
    /// Of those, make only the shards that hold a sample of these garments (comma-separated
    /// names, e.g. tshirt).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub garment: Vec<String>,
    /// Take the samples an earlier dataset of a smaller spec already made (same seed,
    /// garments, poses and simulator; only the body count, poses per body, splits, shard
    /// size and output.compact may differ) instead of simulating them again.
    #[arg(long, value_name = "DIR")]
    pub reuse: Option<PathBuf>,
    /// Stop after making this many samples (resume later by running again).
    #[arg(long, value_name = "N")]
    pub max_samples: Option<u64>,
    #[command(flatten)]
    pub mocap: MocapArg,
}

/// Arguments of `garnet dataset merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The merged dataset folder (new).
    pub out: PathBuf,
    /// The folders to merge.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
}

/// Arguments of `garnet dataset info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The dataset folder.
    pub dir: PathBuf,
    /// Also read every file and check its sha256.
    #[arg(long)]
    pub verify: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(cmd: &DatasetCmd) -> anyhow::Result<()> {
    match cmd {
        DatasetCmd::Plan(a) => plan(a),
        DatasetCmd::Generate(a) => generate(a),
        DatasetCmd::Merge(a) => merge(a),
        DatasetCmd::Info(a) => info(a),
        DatasetCmd::Show(a) => crate::dataset_show::show(a),
        DatasetCmd::Spread(a) => crate::dataset_spread::spread(a),
    }
}

/// Loads the spec and its plan (reading the clips).
fn load_plan(spec: &SpecArg, mocap: Option<&Path>) -> anyhow::Result<(LoadedSpec, Plan)> {
    let spec = spec.load()?;
    let library = dataset::poses::PoseLibrary::load(&spec.spec, mocap)?;
    let plan = Plan::new(&spec, &library.frame_counts())?;
    Ok((spec, plan))
}

fn plan(args: &PlanArgs) -> anyhow::Result<()> {
    let (spec, plan) = load_plan(&args.spec, args.mocap.root().as_deref())?;
    println!(
        "spec {} ({}), hash {}",
        spec.path.display(),
        spec.spec.name,
        &spec.hash[..16]
    );
    println!(
        "{} samples in {} shards of {}; {} bodies",
        plan.total(),
        plan.shard_count(),
        plan.shard_size,
        plan.bodies
    );
    for (g, garment) in plan.garments.iter().enumerate() {
        println!(
            "  garment {}: {} ({} cm edges, {} poses per body, {} cut): samples {}..{}",
            garment.name,
            garment.kind.name(),
            garment.edge * 100.0,
            garment.poses_per_body,
            if garment.per_body() {
                "per-body"
            } else {
                "fixed"
            },
            plan.offsets[g],
            plan.offsets[g + 1]
        );
    }
    for (i, name) in plan.split_names.iter().enumerate() {
        println!(
            "  split {name}: {} bodies{}",
            plan.split_bodies(i).len(),
            if plan.held_out[i] {
                ", held-out poses only"
            } else {
                ""
            }
        );
    }
    let pool = &plan.pool;
    let seen = pool.seen.iter().filter(|&&s| s).count();
    println!(
        "  pose pool: {} poses in {} motions ({} open to ordinary splits)",
        pool.poses.len(),
        pool.motions.len(),
        seen
    );
    Ok(())
}

fn generate(args: &GenerateArgs) -> anyhow::Result<()> {
    let spec = args.spec.load()?;
    let model = BodyModel::load()?;
    let mut opts = GenerateOptions::new(args.mocap.root());
    if let Some(j) = args.jobs {
        anyhow::ensure!(j >= 1, "--jobs must be at least 1");
        opts.jobs = j;
    }
    if let Some(s) = &args.shard {
        opts.selection = ShardSelection::parse(s)?;
    }
    opts.only_splits.clone_from(&args.split);
    opts.only_garments.clone_from(&args.garment);
    opts.max_new_samples = args.max_samples;
    opts.reuse.clone_from(&args.reuse);
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:25}] {pos}/{len} {per_sec} ETA {eta} {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    let started = std::sync::atomic::AtomicBool::new(false);
    // Without a terminal (a log file) the bar is hidden: a line every few minutes instead.
    let log = std::sync::Mutex::new(LogLines::new(LOG_EVERY, "samples"));
    let progress = |p: &dataset::Progress| {
        if bar.is_hidden() {
            let mut log = log.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(line) = log.line(std::time::Instant::now(), p.done, p.total) {
                eprintln!("{line}; {} failed", p.failed);
            }
        }
        if !started.swap(true, std::sync::atomic::Ordering::SeqCst) {
            // The rate and ETA count from the first sample of this run.
            bar.set_length(p.total);
            bar.set_position(p.done);
            bar.reset_eta();
        } else {
            bar.set_position(p.done);
        }
        bar.set_message(format!("{} failed", p.failed));
    };
    opts.progress = Some(&progress);
    let scope: Vec<String> = [("split", &args.split), ("garment", &args.garment)]
        .iter()
        .filter(|(_, names)| !names.is_empty())
        .map(|(what, names)| format!("{what} {}", names.join(",")))
        .collect();
    let scope = match scope.is_empty() {
        true => String::new(),
        false => format!(" holding a sample of {}", scope.join(" and ")),
    };
    eprintln!(
        "generating {} into {} (shards {}{scope}, {} jobs)",
        args.spec.spec.display(),
        args.out.display(),
        opts.selection,
        opts.jobs
    );
    let report = dataset::generate(&model, &spec, &args.out, &opts)
        .with_context(|| format!("generating {}", args.out.display()))?;
    bar.finish_and_clear();
    eprintln!(
        "{} of {} selected samples were already made ({} taken from --reuse now); made {} now ({} failed) in {:.1} s; {} shards written{}",
        report.resumed,
        report.selected_samples,
        report.reused,
        report.made,
        report.failed,
        report.wall_s,
        report.shards_written,
        if report.stray_temps_removed > 0 {
            format!("; removed {} stray temporary files", report.stray_temps_removed)
        } else {
            String::new()
        }
    );
    let state = match (report.complete, report.finished) {
        (true, _) => "the dataset is complete",
        (false, true) => {
            "the selected shards are finished; the dataset's other shards are still to be made \
             (another --shard range) or merged in from the folders that hold them (dataset merge)"
        }
        (false, false) => "stopped before the end: run the same command again to resume",
    };
    println!("{}: {state}", args.out.display());
    Ok(())
}

fn merge(args: &MergeArgs) -> anyhow::Result<()> {
    let r = dataset::merge(&args.out, &args.inputs)?;
    println!(
        "{}: {} of {} shards, {} samples, {} failures{}",
        args.out.display(),
        r.shards,
        r.shard_count,
        r.samples,
        r.failures,
        if r.complete {
            ", complete".to_string()
        } else {
            format!(", missing shards {:?}", r.missing)
        }
    );
    Ok(())
}

fn info(args: &InfoArgs) -> anyhow::Result<()> {
    let data = Dataset::open(&args.dir)?;
    let summary = Summary::of(data.manifest());
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print!("{}", summary.report());
    }
    if args.verify {
        let problems = data.verify();
        for p in &problems {
            eprintln!("garnet: {p}");
        }
        anyhow::ensure!(
            problems.is_empty(),
            "{} damaged files in {}",
            problems.len(),
            args.dir.display()
        );
        println!(
            "verified: {} shards, {} templates and the body faces match their checksums",
            data.manifest().shards.len(),
            data.manifest().templates.len()
        );
    }
    Ok(())
}
