//! `garnet export`: a training checkpoint as a model to ship: the network with its garment
//! template and body sampling, without the optimiser state (a third of the checkpoint's
//! size), and a model card beside it (`NAME.md`): what the model drapes, how it was trained
//! (dataset, command, progress, loss weights) and its test metrics against the DQS warp,
//! measured by the same code as `garnet eval`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use burn::module::Module;
use clap::Args;
use model::{load_checkpoint, save_checkpoint, Checkpoint};

use dataset::{Dataset, DrapeFilter};

use crate::drape_filter_args::{filter_flags, parse_filter_flags, DrapeFilterArgs};
use crate::eval_cmd::{EvalData, EvalOutputs, ModelEvaluation};
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
    /// the same bodies (as `standard-x3` is of `standard`), so the card can report the
    /// metrics on `--data`'s test split. Its training bodies must not be in that split.
    #[arg(long, value_name = "DIR")]
    pub train_data: Option<PathBuf>,
    /// Split for the card's metrics.
    #[arg(long, default_value = "test")]
    pub split: String,
    /// Evaluate at most this many samples.
    #[arg(long, value_name = "N")]
    pub max_samples: Option<usize>,
    /// Model file to write (`.garnet`); the card goes beside it with the extension `.md`.
    #[arg(long, value_name = "FILE.garnet")]
    pub out: PathBuf,
    /// A filter of drapes (`garnet train`'s flags): the card counts the training drapes that
    /// pass it and adds the metrics on the test drapes that pass it. What the model trained
    /// on each epoch comes from its run's `metrics.csv` beside `--model` where there is one,
    /// else from the training drapes the checkpoint records (see `garnet average`).
    #[command(flatten)]
    pub drapes: DrapeFilterArgs,
}

/// Runs `garnet export`.
pub fn run(args: &ExportArgs) -> anyhow::Result<()> {
    if args.out.extension().and_then(|e| e.to_str()) != Some("garnet") {
        bail!("{}: the model file must end in .garnet", args.out.display());
    }
    let filter = args.drapes.filter()?;
    let ck = load_checkpoint(&args.model)
        .with_context(|| format!("loading {}", args.model.display()))?;
    let data = EvalData::open(&args.data)?;
    let train_data = args
        .train_data
        .as_deref()
        .map(|d| Dataset::open(d).with_context(|| format!("--train-data {}", d.display())))
        .transpose()?;
    let train = train_data.as_ref().unwrap_or(data.dataset());
    let seen = train
        .manifest()
        .shared_bodies("train", data.dataset().manifest(), &args.split)?;
    if !seen.is_empty() {
        bail!(
            "{}: {} of its training bodies are in the '{}' split of {} (bodies {:?}...): the \
             card's figures must be on bodies the model never saw",
            train.dir().display(),
            seen.len(),
            args.split,
            args.data.display(),
            &seen[..seen.len().min(5)]
        );
    }
    let device = DeviceArg::Cpu.device()?;
    let network = ck.model(&device)?;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    save_checkpoint(&args.out, &network, None, &ck.setup, &ck.loss, &ck.state)?;
    let eval = data.evaluate(
        &args.out,
        &args.split,
        None,
        args.max_samples,
        EvalOutputs::default(),
        &device,
    )?;
    let filtered = filter
        .map(|f| {
            data.evaluate(
                &args.out,
                &args.split,
                Some(&f),
                args.max_samples,
                EvalOutputs::default(),
                &device,
            )
            .map(|e| (f, e))
        })
        .transpose()?;
    let card = model_card(
        &args.model,
        &args.out,
        &ck,
        network.num_params(),
        train,
        data.dataset(),
        &args.split,
        &eval,
        filtered.as_ref(),
    )?;
    let card_path = args.out.with_extension("md");
    geom::io::write_bytes_atomic(&card_path, card.as_bytes())?;
    eprintln!(
        "wrote {} ({:.1} MB) and {}",
        args.out.display(),
        std::fs::metadata(&args.out)?.len() as f64 / 1e6,
        card_path.display()
    );
    Ok(())
}

/// The model card (Markdown) of the exported model at `path`, trained on `train` and
/// evaluated (`eval`) on `data`'s `split`; `filtered`: the filter of the drapes it was
/// trained on and its evaluation on the test drapes that pass it.
#[allow(clippy::too_many_arguments)]
fn model_card(
    source: &Path,
    path: &Path,
    ck: &Checkpoint,
    params: usize,
    train: &Dataset,
    data: &Dataset,
    split: &str,
    eval: &ModelEvaluation,
    filtered: Option<&(DrapeFilter, ModelEvaluation)>,
) -> anyhow::Result<String> {
    let setup = &ck.setup;
    let cfg = &setup.config;
    let state = &ck.state;
    let loss = &ck.loss;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("model");
    let size_mb = std::fs::metadata(path)?.len() as f64 / 1e6;
    let train_indices = train.select(Some("train"), Some(&eval.garment))?;
    let passing = |f: &DrapeFilter| {
        let mut kept = train_indices.clone();
        train.retain_drapes(&mut kept, f);
        kept.len()
    };
    // What the run trained on, from its log where there is one: a model fine-tuned from
    // another on other drapes has its own count per epoch, whatever the export's filter.
    // Else from the checkpoint's record: the export's filter only chooses the card's rows.
    let metrics_csv = source
        .parent()
        .map(|d| d.join(model::trainer::METRICS_LOG))
        .and_then(|m| std::fs::read_to_string(m).ok());
    let mut trained_on = format!("{} training samples of this garment", train_indices.len());
    match metrics_csv.as_deref().and_then(training_samples_history) {
        Some(history) => {
            if let Some((f, _)) = filtered {
                trained_on += &format!(", {} of them {}", passing(f), f.describe());
            }
            trained_on +=
                &format!("; samples trained on per epoch (from the run's metrics.csv): {history}");
        }
        // Flags that no longer parse (a checkpoint of another version) read as unrecorded.
        None => match crate::train_drapes::training_drapes(&ck.state)
            .and_then(|flags| parse_filter_flags(&flags).ok())
        {
            None => trained_on += "; the drapes it trained on are not recorded in the checkpoint",
            Some(None) => trained_on += ", trained on every one of them",
            Some(Some(f)) => {
                trained_on += &format!(
                    ", trained on the {} of them that are {}",
                    passing(&f),
                    f.describe()
                )
            }
        },
    }
    let [net, dqs] = eval.summary();
    let (net_ms, sim_s) = eval.times();
    let mut md = format!(
        "# Model card: {method} for the {garment}\n\n\
         `{name}` ({size_mb:.1} MB): the network ({params} parameters), the garment template it \
         drapes ({n} vertices, {f} faces, carried in the file with its skinning weights) and \
         the body points it sees ({p} of the body's {v} vertices). `garnet drape --model \
         {name} [shape] [pose]` needs nothing else.\n\n",
        method = cfg.method_name(),
        garment = eval.garment,
        n = setup.template.vertices.len(),
        f = setup.template.faces.len(),
        p = setup.body_sampling.len(),
        v = setup.body_sampling.n_body,
    );
    md += &format!(
        "## Training\n\n\
         - dataset: '{ds}' (`{dir}`, spec `{dir}/spec.toml`), {train}; validation on its \
         'val' split\n\
         - command: `{cmd}`\n\
         - progress: {progress}{ep} epochs, {st} steps, last learning rate {lr:.1e}; best \
         validation E_dist {best}\n\
         - loss: {vertex}L_vertex (mean of {vertex_name}) + {pen} L_pen + {norm} L_norm + {bend} L_bend, lengths in \
         {unit}, d_tol {dtol} m\n{vertex_history}{clip}{mirror}{history}\n",
        train = trained_on,
        ds = train.manifest().spec.name,
        dir = train.dir().display(),
        cmd = state
            .command
            .as_deref()
            .unwrap_or("(not recorded in the checkpoint)"),
        progress = if state.averaged_epochs.is_empty() {
            String::new()
        } else {
            format!(
                "the networks averaged are of {}; the file records the last one's progress: ",
                epoch_list(&state.averaged_epochs)
            )
        },
        ep = state.epoch,
        st = state.step,
        lr = state.lr,
        best = state
            .best_e_dist_cm
            .map_or("n/a".to_string(), |b| format!("{b:.2} cm")),
        vertex = if loss.vertex == 1.0 {
            String::new()
        } else {
            format!("{} ", loss.vertex)
        },
        vertex_name = vertex_loss_name(loss.vertex_power),
        vertex_history = metrics_csv
            .as_deref()
            .and_then(vertex_power_history)
            .map_or(String::new(), |h| format!(
                "- L_vertex averaged, by epoch (from the run's metrics.csv): {h}\n"
            )),
        pen = loss.pen,
        norm = loss.norm,
        bend = loss.bend,
        unit = match loss.units_per_metre {
            100.0 => "cm".to_string(),
            1.0 => "m".to_string(),
            u => format!("units of 1/{u} m"),
        },
        dtol = loss.d_tol,
        clip = state.max_grad_norm.map_or(String::new(), |n| format!(
            "- gradients clipped to a joint L2 norm of {n} (the last run's setting)\n"
        )),
        mirror = if state.mirror {
            "- every other training sample mirrored left-right (the last run's setting)\n"
        } else {
            ""
        },
        history = metrics_csv
            .as_deref()
            .and_then(|csv| learning_rate_history(csv, !state.averaged_epochs.is_empty()))
            .map_or(String::new(), |h| format!(
                "- learning rate by epoch (from the run's metrics.csv): {h}\n"
            ))
            + &averaged_line(state),
    );
    md += &format!(
        "## Test metrics ('{split}' split of '{name}', `{dir}`: bodies never seen in \
         training)\n\n\
         | method | samples | E_dist (cm) | E_norm (deg) | vertices inside the body |\n\
         |---|---:|---:|---:|---:|\n",
        name = data.manifest().spec.name,
        dir = data.dir().display(),
    );
    let mut rows = vec![
        (cfg.method_name(), net),
        ("DQS warp (the input M)".to_string(), dqs),
    ];
    if let Some((f, e)) = filtered {
        let [net, dqs] = e.summary();
        rows.push((format!("{}, {}", cfg.method_name(), f.describe()), net));
        rows.push((format!("DQS warp, {}", f.describe()), dqs));
    }
    for (method, (samples, dist, norm, inside)) in rows {
        md += &format!(
            "| {method} | {samples} | {dist:.2} | {norm:.1} | {:.1}% |\n",
            inside * 100.0
        );
    }
    md += &format!(
        "\nTime per drape on this machine: network {net_ms:.0} ms (median, batch 1, CPU){}.\n",
        sim_s.map_or(String::new(), |s| format!(
            "; the simulator took {s:.2} s on the same samples ({:.0}x)",
            s * 1e3 / net_ms.max(1e-9)
        ))
    );
    md += &format!(
        "\nMade by `garnet export --model {} --data {}{} --out {}{}`.\n",
        source.display(),
        data.dir().display(),
        if train.dir() == data.dir() {
            String::new()
        } else {
            format!(" --train-data {}", train.dir().display())
        },
        path.display(),
        filter_flags(filtered.map(|(f, _)| f))
    );
    Ok(md)
}

/// The model card's line on how an averaged network was made from its runs' networks
/// (`garnet average`): the plain mean of their epochs, or each epoch with its weight; empty
/// for a network trained as it is.
fn averaged_line(state: &model::TrainState) -> String {
    if state.averaged_epochs.is_empty() {
        String::new()
    } else if state.averaged_weights.is_empty() {
        format!(
            "- weights: the mean of the networks of {} (`garnet average`)\n",
            epoch_list(&state.averaged_epochs)
        )
    } else {
        let terms: Vec<String> = state
            .averaged_weights
            .iter()
            .zip(&state.averaged_epochs)
            .map(|(w, e)| format!("{w} x epoch {e}"))
            .collect();
        format!(
            "- weights: the combination {} of networks (`garnet average --weights`)\n",
            terms.join(" + ")
        )
    }
}

/// The learning rates of a training log (`metrics.csv` text) as segments of epochs: a
/// constant rate as `3e-4 (epochs 1-22)`, a falling one as `1e-3 to 1e-5 (epochs 23-50)`,
/// with the epoch that wrote the best checkpoint (left out for a model averaged by `garnet
/// average`: `averaged`); `None` for a log without rows.
fn learning_rate_history(csv: &str, averaged: bool) -> Option<String> {
    let rows: Vec<(usize, f64, bool)> = csv
        .lines()
        .skip(1)
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Some((
                f.first()?.parse().ok()?,
                f.get(2)?.parse().ok()?,
                f.get(18) == Some(&"1"),
            ))
        })
        .collect();
    // (first epoch, last epoch, first rate, last rate)
    let mut segments: Vec<(usize, usize, f64, f64)> = Vec::new();
    for &(epoch, lr, _) in &rows {
        match segments.last_mut() {
            Some(s) if (lr == s.3 && s.2 == s.3) || (lr < s.3 && (s.0 == s.1 || s.3 < s.2)) => {
                s.1 = epoch;
                s.3 = lr;
            }
            _ => segments.push((epoch, epoch, lr, lr)),
        }
    }
    let best = rows.iter().rev().find(|r| r.2).map(|r| r.0);
    let text: Vec<String> = segments
        .iter()
        .map(|&(a, b, l0, l1)| {
            let span = epoch_span(a, b);
            if l0 == l1 {
                format!("{l0:.1e} ({span})")
            } else {
                format!("{l0:.1e} to {l1:.1e} ({span})")
            }
        })
        .collect();
    let source = match best {
        Some(b) if !averaged => format!("; best checkpoint from epoch {b}"),
        _ => String::new(),
    };
    (!text.is_empty()).then(|| text.join(", ") + &source)
}

/// The training samples per epoch of a training log (`metrics.csv` text) as runs of epochs
/// with the same count: `1229 (epochs 1-30), 1500 (epochs 31-45)`; `None` for a log without
/// rows.
fn training_samples_history(csv: &str) -> Option<String> {
    let text: Vec<String> = column_runs(csv, "train_samples", None)
        .iter()
        .map(|(a, b, n)| format!("{n} ({})", epoch_span(*a, *b)))
        .collect();
    (!text.is_empty()).then(|| text.join(", "))
}

/// What L_vertex averaged, by epoch, from a training log (`metrics.csv` text):
/// `squared distances (epochs 1-84), distances (epochs 85-89)`; `None` when every epoch
/// used the paper's squared distances (rows logged before the column existed did).
fn vertex_power_history(csv: &str) -> Option<String> {
    let runs = column_runs(csv, "vertex_power", Some("2"));
    if runs.iter().all(|r| r.2 == "2") {
        return None;
    }
    let text: Vec<String> = runs
        .iter()
        .map(|(a, b, p)| {
            let what = p
                .parse()
                .map_or_else(|_| format!("power {p}"), vertex_loss_name);
            format!("{what} ({})", epoch_span(*a, *b))
        })
        .collect();
    Some(text.join(", "))
}

/// What L_vertex averages with distances to the power `p`: `squared distances` (2),
/// `distances` (1), `distances to the power 1.5`.
fn vertex_loss_name(p: f64) -> String {
    match p {
        2.0 => "squared distances".into(),
        1.0 => "distances".into(),
        p => format!("distances to the power {p}"),
    }
}

/// Runs of epochs with the same value in the column named `name` of a training log
/// (`metrics.csv` text), as (first epoch, last epoch, value); an empty or missing field
/// reads as `empty` (a row logged before the column existed), or skips the row when that is
/// `None`.
fn column_runs(csv: &str, name: &str, empty: Option<&str>) -> Vec<(usize, usize, String)> {
    let Some(col) = model::metrics_log::HEADER
        .split(',')
        .position(|c| c == name)
    else {
        return Vec::new();
    };
    let mut runs: Vec<(usize, usize, String)> = Vec::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let value = match f.get(col).filter(|v| !v.is_empty()) {
            Some(v) => *v,
            None => match empty {
                Some(e) => e,
                None => continue,
            },
        };
        let Some(epoch) = f.first().and_then(|e| e.parse().ok()) else {
            continue;
        };
        match runs.last_mut() {
            Some(r) if r.2 == value => r.1 = epoch,
            _ => runs.push((epoch, epoch, value.to_string())),
        }
    }
    runs
}

/// `epoch A` or `epochs A-B`.
fn epoch_span(first: usize, last: usize) -> String {
    if first == last {
        format!("epoch {first}")
    } else {
        format!("epochs {first}-{last}")
    }
}

/// Epochs as `epochs 70-76` when they follow one another, else `epochs 70, 72, 74`.
fn epoch_list(epochs: &[usize]) -> String {
    let consecutive = epochs.windows(2).all(|w| w[1] == w[0] + 1);
    match (epochs.first(), epochs.last()) {
        (Some(&a), Some(&b)) if consecutive => epoch_span(a, b),
        _ => {
            let list: Vec<String> = epochs.iter().map(usize::to_string).collect();
            format!("epochs {}", list.join(", "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{
        epoch_list, learning_rate_history, training_samples_history, vertex_power_history,
    };

    #[test]
    fn learning_rates_fold_into_constant_and_falling_segments() {
        let header = model::metrics_log::HEADER;
        let row = |e: usize, lr: f64, best: u8| {
            format!("{e},0,{lr},1.0,8,1,1,0,0,0,2,1,1,0,0,0,3.5,20,{best},100")
        };
        let mut csv = format!("{header}\n");
        for e in 1..=3 {
            csv += &(row(e, 3e-4, 0) + "\n");
        }
        for (e, lr) in [(4, 1e-3), (5, 6e-4), (6, 2e-4), (7, 1e-5)] {
            csv += &(row(e, lr, u8::from(e == 6)) + "\n");
        }
        csv += &(row(8, 1e-5, 0) + "\n");
        assert_eq!(
            learning_rate_history(&csv, false).unwrap(),
            "3.0e-4 (epochs 1-3), 1.0e-3 to 1.0e-5 (epochs 4-7), 1.0e-5 (epoch 8); \
             best checkpoint from epoch 6"
        );
        assert_eq!(
            learning_rate_history(&csv, true).unwrap(),
            "3.0e-4 (epochs 1-3), 1.0e-3 to 1.0e-5 (epochs 4-7), 1.0e-5 (epoch 8)"
        );
        assert_eq!(learning_rate_history(header, false), None);
        assert_eq!(epoch_list(&[3, 5, 8]), "epochs 3, 5, 8");
        assert_eq!(epoch_list(&[4]), "epoch 4");
    }

    /// A run fine-tuned on every drape after epochs on the clean ones shows both counts.
    #[test]
    fn training_samples_fold_into_runs_of_equal_counts() {
        let header = model::metrics_log::HEADER;
        let row =
            |e: usize, n: u64| format!("{e},0,1e-4,1.0,{n},1,1,0,0,0,2,1,1,0,0,0,3.5,20,0,100");
        let mut csv = format!("{header}\n");
        for (e, n) in [
            (1, 1229),
            (2, 1229),
            (3, 1229),
            (4, 1500),
            (5, 1500),
            (6, 7),
        ] {
            csv += &(row(e, n) + "\n");
        }
        assert_eq!(
            training_samples_history(&csv).unwrap(),
            "1229 (epochs 1-3), 1500 (epochs 4-5), 7 (epoch 6)"
        );
        assert_eq!(training_samples_history(header), None);
    }

    /// Rows logged before the column existed read as squared distances; a log that never
    /// changed the power says nothing.
    #[test]
    fn vertex_powers_fold_into_runs_and_old_rows_read_as_squared() {
        let header = model::metrics_log::HEADER;
        let base = |e: usize| format!("{e},0,1e-4,1.0,8,1,1,0,0,0,2,1,1,0,0,0,3.5,20,0");
        let mut csv = format!("{header}\n{}\n", base(1));
        csv += &format!("{},100,2\n", base(2));
        assert_eq!(vertex_power_history(&csv), None);
        csv += &format!("{},100,1\n{},100,1\n", base(3), base(4));
        csv += &format!("{},100,1.5\n", base(5));
        assert_eq!(
            vertex_power_history(&csv).unwrap(),
            "squared distances (epochs 1-2), distances (epochs 3-4), distances to the power \
             1.5 (epoch 5)"
        );
    }
}
