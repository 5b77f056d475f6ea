//! Model cards: what a shipped model drapes, how it was trained (the recipe and its
//! command), and its test metrics against the DQS warp, measured by [`crate::eval`].

use std::path::Path;

use dataset::{Dataset, DrapeFilter};
use model::Checkpoint;

use crate::eval::ModelEvaluation;

/// What a model card reports.
pub struct CardInputs<'a> {
    /// The exported model file.
    pub path: &'a Path,
    /// Its checkpoint (as loaded from `path`).
    pub checkpoint: &'a Checkpoint,
    /// Its parameter count.
    pub params: usize,
    /// The dataset it was trained on.
    pub train: &'a Dataset,
    /// The dataset whose `split` the metrics are on.
    pub data: &'a Dataset,
    /// The split of the metrics.
    pub split: &'a str,
    /// The evaluation on every drape of the split.
    pub eval: &'a ModelEvaluation,
    /// The recipe's drape filter and the evaluation on the drapes it keeps, when it has one.
    pub filtered: Option<(&'a DrapeFilter, &'a ModelEvaluation)>,
    /// The command that exported it.
    pub export_command: &'a str,
}

/// The model card (Markdown) of `c`.
pub fn model_card(c: &CardInputs) -> anyhow::Result<String> {
    let ck = c.checkpoint;
    let setup = &ck.setup;
    let cfg = &setup.config;
    let state = &ck.state;
    let loss = &ck.loss;
    let name = c
        .path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("model");
    let size_mb = std::fs::metadata(c.path)?.len() as f64 / 1e6;
    let garment = &c.eval.garment;
    let mut train_indices = c.train.select(Some("train"), Some(garment))?;
    let mut md = format!(
        "# Model card: {method} for the {garment}\n\n\
         `{name}` ({size_mb:.1} MB): the network ({params} parameters), the garment template it \
         drapes ({n} vertices, {f} faces, carried in the file with its skinning weights) and \
         the body points it sees ({p} of the body's {v} vertices). `garnet drape --model \
         {name} [shape] [pose]` needs nothing else.\n\n## Training\n\n",
        method = cfg.method_name(),
        params = c.params,
        n = setup.template.vertices.len(),
        f = setup.template.faces.len(),
        p = setup.body_sampling.len(),
        v = setup.body_sampling.n_body,
    );
    let total = train_indices.len();
    let drapes = match c.filtered {
        Some((f, _)) => {
            c.train.retain_drapes(&mut train_indices, f);
            format!(
                "the {} of them that are {}",
                train_indices.len(),
                f.describe()
            )
        }
        None => "every one of them".to_string(),
    };
    md += &format!(
        "- dataset: '{}' (`{}`), {total} training samples of this garment, trained on {drapes}; \
         validation on its 'val' split\n",
        c.train.manifest().spec.name,
        c.train.dir().display(),
    );
    match &ck.recipe {
        Some(r) => {
            md += &format!(
                "- trained from scratch by `{}`; the recipe as run:\n\n```toml\n{}```\n\n",
                r.command,
                r.recipe.to_toml()
            )
        }
        None => md += "- the checkpoint records no recipe\n",
    }
    md += &format!(
        "- progress: {} epochs, {} steps, last learning rate {:.1e}; best validation E_dist {}\n\
         - loss: {} L_vertex ({}) + {} L_pen + {} L_norm ({}) + {} L_bend + {} L_curv, lengths in cm, d_tol {} m\n\n",
        state.epoch,
        state.step,
        state.lr,
        state
            .best_e_dist_cm
            .map_or("n/a".to_string(), |b| format!("{b:.2} cm")),
        loss.vertex,
        loss.vertex_loss.name(),
        loss.pen,
        loss.norm,
        loss.normal_loss.name(),
        loss.bend,
        loss.curvature,
        loss.d_tol,
    );
    md += &metrics_section(c);
    md += &format!("\nMade by `{}`.\n", c.export_command);
    Ok(md)
}

/// The card's test-metrics table and timing line.
fn metrics_section(c: &CardInputs) -> String {
    let method = c.checkpoint.setup.config.method_name();
    let mut md = format!(
        "## Test metrics ('{}' split of '{}', `{}`: bodies never seen in training)\n\n\
         | method | samples | E_dist (cm) | E_norm (deg) | vertices inside the body |\n\
         |---|---:|---:|---:|---:|\n",
        c.split,
        c.data.manifest().spec.name,
        c.data.dir().display(),
    );
    let [net, dqs] = c.eval.summary();
    let mut rows = vec![
        (method.clone(), net),
        ("DQS warp (the input M)".to_string(), dqs),
    ];
    if let Some((f, e)) = c.filtered {
        let [net, dqs] = e.summary();
        rows.push((format!("{method}, {}", f.describe()), net));
        rows.push((format!("DQS warp, {}", f.describe()), dqs));
    }
    for (method, (samples, dist, norm, inside)) in rows {
        md += &format!(
            "| {method} | {samples} | {dist:.2} | {norm:.1} | {:.1}% |\n",
            inside * 100.0
        );
    }
    let (net_ms, sim_s) = c.eval.times();
    md += &format!(
        "\nTime per drape on this machine: network {net_ms:.0} ms (median, batch 1, CPU){}.\n",
        sim_s.map_or(String::new(), |s| format!(
            "; the simulator took {s:.2} s on the same samples ({:.0}x)",
            s * 1e3 / net_ms.max(1e-9)
        ))
    );
    md
}
