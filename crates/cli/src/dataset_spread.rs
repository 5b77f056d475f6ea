//! `garnet dataset spread`: how repeatable a spec's labels are. Samples of one split are
//! draped three times from scratch, at the spec's cloth density and 0.1% (`--step`) above
//! and below it; the distances between the drapes are printed per garment and written
//! as JSON (and the per-sample rows as CSV).

use std::path::{Path, PathBuf};

use anyhow::Context;
use body::BodyModel;
use clap::Args;
use dataset::spread::{DEFAULT_PER_GARMENT, DEFAULT_SPLIT, DEFAULT_STEP};
use dataset::SpreadOptions;
use indicatif::{ProgressBar, ProgressStyle};

use crate::dataset_cmd::{MocapArg, SpecArg};
use crate::log_lines::{LogLines, LOG_EVERY};
use crate::output::create_parent;

/// Arguments of `garnet dataset spread`.
#[derive(Args, Debug)]
pub struct SpreadArgs {
    #[command(flatten)]
    pub spec: SpecArg,
    /// The split whose samples are draped.
    #[arg(long, default_value = DEFAULT_SPLIT)]
    pub split: String,
    /// Samples per garment, spread evenly over the split's samples of that garment (all of
    /// them when it has fewer).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_PER_GARMENT)]
    pub per_garment: usize,
    /// Relative density step s: each sample is also draped at d (1 + s) and d (1 - s),
    /// in (0, 0.1).
    #[arg(long, value_name = "S", default_value_t = DEFAULT_STEP)]
    pub step: f32,
    /// Of the spec's garments, only these (comma-separated names, e.g. jeans).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub garment: Vec<String>,
    /// Drapes in parallel (default: one per core).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// A simulator settings file whose keys replace those of the spec's [simulator] table.
    #[arg(long, value_name = "FILE")]
    pub simulator: Option<PathBuf>,
    #[command(flatten)]
    pub mocap: MocapArg,
    /// The report (JSON): per-garment figures and per-sample rows.
    #[arg(long, value_name = "FILE.json")]
    pub out: PathBuf,
    /// Also the per-sample rows as CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
}

/// Writes `text` to `path` atomically (a temporary file, then renamed), creating its folder.
fn write_report(path: &Path, text: &str) -> anyhow::Result<()> {
    create_parent(path)?;
    geom::io::write_bytes_atomic(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

pub fn spread(args: &SpreadArgs) -> anyhow::Result<()> {
    let spec = args.spec.load()?;
    let mut opts = SpreadOptions::new(args.mocap.root());
    if let Some(j) = args.jobs {
        anyhow::ensure!(j >= 1, "--jobs must be at least 1");
        opts.jobs = j;
    }
    opts.split.clone_from(&args.split);
    opts.per_garment = args.per_garment;
    opts.step = args.step;
    opts.garments.clone_from(&args.garment);
    opts.simulator.clone_from(&args.simulator);
    let model = BodyModel::load()?;
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:25}] {pos}/{len} drapes {per_sec} ETA {eta} {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    // Without a terminal (a log file) the bar is hidden: a line every few minutes instead.
    let log = std::sync::Mutex::new(LogLines::new(LOG_EVERY, "drapes"));
    let progress = |p: &dataset::Progress| {
        if bar.is_hidden() {
            let mut log = log.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(line) = log.line(std::time::Instant::now(), p.done, p.total) {
                eprintln!("{line}; {} failed", p.failed);
            }
        }
        bar.set_length(p.total);
        bar.set_position(p.done);
        bar.set_message(format!("{} failed", p.failed));
    };
    opts.progress = Some(&progress);
    eprintln!(
        "draping {} samples per garment of split {} of {} three times (density step {}, {} jobs)",
        opts.per_garment,
        opts.split,
        args.spec.spec.display(),
        opts.step,
        opts.jobs
    );
    let report = dataset::spread(&model, &spec, &opts)?;
    bar.finish_and_clear();
    print!("{}", report.markdown());
    for g in &report.garments {
        for f in &g.failures {
            eprintln!(
                "failed: {} sample {} ({}): {}",
                g.garment, f.index, f.variant, f.message
            );
        }
    }
    write_report(&args.out, &(serde_json::to_string_pretty(&report)? + "\n"))?;
    if let Some(csv) = &args.csv {
        write_report(csv, &report.csv())?;
    }
    eprintln!(
        "{} drapes in {:.1} s ({:.1} a minute)",
        report.rows.len() * 3,
        report.wall_s,
        report.drapes_per_min
    );
    Ok(())
}
