//! Shipping a model: a training checkpoint written without its optimiser state (a third of
//! its size), with a model card beside it (see [`crate::card`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use burn::module::Module;
use burn::prelude::Device;
use dataset::{Dataset, DrapeFilter};
use model::{load_checkpoint, save_checkpoint, Recipe};

use crate::card::{model_card, CardInputs};
use crate::eval::{EvalData, EvalOutputs};

/// What to export and where.
#[derive(Clone, Debug)]
pub struct ExportJob {
    /// The training checkpoint (`best.garnet` or `last.garnet` of `garnet train`).
    pub model: PathBuf,
    /// The dataset whose `split` gives the card's metrics.
    pub data: PathBuf,
    /// The dataset the model was trained on, when it is not `data` (a larger dataset of the
    /// same bodies); its training bodies must not be in `data`'s `split`.
    pub train_data: Option<PathBuf>,
    /// The split of the card's metrics.
    pub split: String,
    /// Evaluate at most this many samples.
    pub max_samples: Option<usize>,
    /// The model file to write (`.garnet`); the card goes beside it as `.md`.
    pub out: PathBuf,
}

/// The drape filter of a recipe's `[drapes]`, `None` for every drape.
pub fn recipe_filter(recipe: &Recipe) -> Option<DrapeFilter> {
    let d = &recipe.drapes;
    d.filters().then(|| DrapeFilter {
        at_rest: d.at_rest,
        max_strain_p99: d.max_strain_pct.map(|p| p / 100.0),
        max_slid_m: d.max_slide_cm.map(|c| c / 100.0),
    })
}

/// Exports `job.model` to `job.out` and writes its card, `job.out` with the extension `.md`;
/// the card's metrics are measured on bodies the model never saw (refused otherwise).
/// Returns the card's path.
pub fn export(job: &ExportJob, device: &Device) -> anyhow::Result<PathBuf> {
    if job.out.extension().and_then(|e| e.to_str()) != Some("garnet") {
        bail!("{}: the model file must end in .garnet", job.out.display());
    }
    let ck =
        load_checkpoint(&job.model).with_context(|| format!("loading {}", job.model.display()))?;
    let data = EvalData::open(&job.data)?;
    let train_data = job
        .train_data
        .as_deref()
        .map(|d| Dataset::open(d).with_context(|| format!("the training data {}", d.display())))
        .transpose()?;
    let train = train_data.as_ref().unwrap_or(data.dataset());
    let seen = train
        .manifest()
        .shared_bodies("train", data.dataset().manifest(), &job.split)?;
    if !seen.is_empty() {
        bail!(
            "{}: {} of its training bodies are in the '{}' split of {} (bodies {:?}...): the \
             card's figures must be on bodies the model never saw",
            train.dir().display(),
            seen.len(),
            job.split,
            job.data.display(),
            &seen[..seen.len().min(5)]
        );
    }
    let network = ck.model(device)?;
    if let Some(dir) = job.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let state = model::TrainState {
        partial: None,
        ..ck.state.clone()
    };
    save_checkpoint(
        &job.out,
        &network,
        None,
        &ck.setup,
        &ck.loss,
        &state,
        ck.recipe.as_ref(),
    )?;
    let exported = load_checkpoint(&job.out)?;
    let eval = |filter: Option<&DrapeFilter>| {
        data.evaluate(
            &job.out,
            &job.split,
            filter,
            job.max_samples,
            EvalOutputs::default(),
            device,
        )
    };
    let all = eval(None)?;
    let filter = ck.recipe.as_ref().and_then(|r| recipe_filter(&r.recipe));
    let filtered = filter.as_ref().map(|f| eval(Some(f))).transpose()?;
    let card = model_card(&CardInputs {
        path: &job.out,
        checkpoint: &exported,
        params: network.num_params(),
        train,
        data: data.dataset(),
        split: &job.split,
        eval: &all,
        filtered: filter.as_ref().zip(filtered.as_ref()),
        export_command: &export_command(job, train.dir(), data.dataset().dir()),
    })?;
    let card_path = job.out.with_extension("md");
    geom::io::write_bytes_atomic(&card_path, card.as_bytes())?;
    Ok(card_path)
}

/// The `garnet export` command line of `job`.
fn export_command(job: &ExportJob, train: &Path, data: &Path) -> String {
    let mut cmd = format!(
        "garnet export --model {} --data {}",
        job.model.display(),
        data.display()
    );
    if train != data {
        cmd += &format!(" --train-data {}", train.display());
    }
    if job.split != "test" {
        cmd += &format!(" --split {}", job.split);
    }
    if let Some(n) = job.max_samples {
        cmd += &format!(" --max-samples {n}");
    }
    cmd + &format!(" --out {}", job.out.display())
}
