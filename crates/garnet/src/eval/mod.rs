//! Trained models on a dataset split, as the paper reports them ([`evaluate`]): Table 1
//! (E_dist in cm, E_norm in degrees, per garment and variant, DQS as a row, plus the share
//! of vertices inside the body), Figure 4's precision curves (PNG), and Table 2's timing
//! (network per drape, DQS warp, simulator), with E_dist by motion; written as Markdown,
//! JSON (naming the dataset's spec and its hash) and two charts ([`EvalReport::write`]).

pub mod motion;
pub mod pictures;
pub mod save;

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, Context};
use body::{BodyModel, Phenotype, Pose, Skinning};
use dataset::batches::{BatchOptions, Batches, Order};
use dataset::{Dataset, DrapeFilter};
use geom::metrics::{face_normal_angles, precision_curve, vertex_distances};
use geom::{Bvh, TriMesh};
use glam::Vec3;
use model::{Base, Draper};
use render::plot::{Chart, Series};
use serde::Serialize;

use crate::drape::{checkpoint_template, push_out_gap, PUSH_OUT_WITHIN};
use crate::drapes::{check_body_skinning, keep_drapes};
use motion::{ByMotion, MotionRow};
use pictures::KeptDrapes;
use save::{save_folders, DrapeSaver, SavedDrape};

/// What [`EvalData::evaluate`] makes besides the network's and the DQS warp's rows.
#[derive(Clone, Copy, Debug, Default)]
pub struct EvalOutputs<'a> {
    /// Also the network's drapes pushed out of the body as `garnet drape` does.
    pub push_out: bool,
    /// Also a row of the surface-anchored M (the template placed on the posed body by its
    /// surface anchors, [`model::Base::Anchored`]): where the fitted-start simulator starts
    /// its drapes, as a baseline.
    pub fitted: bool,
    /// Write every drape and its errors into this folder (see [`save`]).
    pub save_drapes: Option<&'a Path>,
    /// Keep every drape of the network for the pictures (see [`pictures`]).
    pub keep_drapes: bool,
}

/// One row of Table 1 and its curves.
#[derive(Serialize)]
struct Row {
    garment: String,
    method: String,
    samples: usize,
    e_dist_cm: f32,
    e_norm_deg: f32,
    inside_share: f32,
    /// Share of vertices within each of [`DIST_THRESHOLDS_CM`].
    dist_curve: Vec<f32>,
    /// Share of faces within each of [`NORM_THRESHOLDS_DEG`].
    norm_curve: Vec<f32>,
}

/// One row of Table 2.
#[derive(Serialize)]
struct Timing {
    garment: String,
    method: String,
    vertices: usize,
    network_ms: f64,
    dqs_ms: f64,
    simulator_s: Option<f64>,
}

/// Thresholds of the distance precision curve, cm.
fn dist_thresholds() -> Vec<f32> {
    (0..=50).map(|k| k as f32 * 0.1).collect()
}

/// Thresholds of the normal precision curve, degrees.
fn norm_thresholds() -> Vec<f32> {
    (0..=60).map(|k| k as f32).collect()
}

/// Accumulates per-vertex distances, per-face angles and inside counts of one method.
#[derive(Default)]
struct Errors {
    dists_cm: Vec<f32>,
    angles_deg: Vec<f32>,
    sample_dist: Vec<f32>,
    sample_norm: Vec<f32>,
    inside: usize,
    vertices: usize,
}

impl Errors {
    /// Adds one drape; returns its mean vertex distance, cm.
    fn add(
        &mut self,
        gt: &[Vec3],
        pred: &[Vec3],
        faces: &[[u32; 3]],
        body: &Bvh,
    ) -> anyhow::Result<f32> {
        let d: Vec<f32> = vertex_distances(gt, pred)?
            .iter()
            .map(|m| m * 100.0)
            .collect();
        let a: Vec<f32> = face_normal_angles(gt, pred, faces)?
            .iter()
            .map(|r| r.to_degrees())
            .collect();
        let mean_dist = d.iter().sum::<f32>() / d.len().max(1) as f32;
        self.sample_dist.push(mean_dist);
        self.sample_norm
            .push(a.iter().sum::<f32>() / a.len().max(1) as f32);
        self.inside += body.contains_points(pred).iter().filter(|&&i| i).count();
        self.vertices += pred.len();
        self.dists_cm.extend(d);
        self.angles_deg.extend(a);
        Ok(mean_dist)
    }

    /// E_norm (degrees) of the drape added last (0 before any).
    fn last_norm_deg(&self) -> f32 {
        self.sample_norm.last().copied().unwrap_or(0.0)
    }

    fn row(&self, garment: &str, method: &str) -> Row {
        let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len().max(1) as f32;
        Row {
            garment: garment.into(),
            method: method.into(),
            samples: self.sample_dist.len(),
            e_dist_cm: mean(&self.sample_dist),
            e_norm_deg: mean(&self.sample_norm),
            inside_share: self.inside as f32 / self.vertices.max(1) as f32,
            dist_curve: precision_curve(&self.dists_cm, &dist_thresholds()),
            norm_curve: precision_curve(&self.angles_deg, &norm_thresholds()),
        }
    }
}

/// The dataset garment whose template has the faces of `template`.
fn matching_garment(data: &Dataset, split: &str, template: &TriMesh) -> anyhow::Result<String> {
    for g in &data.manifest().garments {
        let Some(&first) = data.select(Some(split), Some(&g.name))?.first() else {
            continue;
        };
        let id = data.sample(first)?.record.template;
        if data.template(&id)?.mesh.faces == template.faces {
            return Ok(g.name.clone());
        }
    }
    Err(anyhow!(
        "{}: no garment of split '{split}' has the model's template ({} vertices)",
        data.dir().display(),
        template.vertices.len()
    ))
}

/// Median of `v` (0 for none).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// What evaluating one model on a split gives: its Table 1 row, the DQS row of the same
/// samples, and its Table 2 row.
pub struct ModelEvaluation {
    /// The dataset garment the model drapes.
    pub garment: String,
    net: Row,
    /// The network's drapes pushed out of the body as `garnet drape` does, when asked.
    pushed: Option<Row>,
    dqs: Row,
    /// The surface-anchored M of the same samples, when asked.
    fitted: Option<Row>,
    timing: Timing,
    by_motion: Vec<MotionRow>,
    /// The network's drapes, when kept for the pictures.
    kept: Option<KeptDrapes>,
}

impl ModelEvaluation {
    /// (samples, E_dist cm, E_norm degrees, share of vertices inside the body) of the
    /// network, then of the DQS warp.
    pub fn summary(&self) -> [(usize, f32, f32, f32); 2] {
        [&self.net, &self.dqs].map(|r| (r.samples, r.e_dist_cm, r.e_norm_deg, r.inside_share))
    }

    /// Median network time per drape (ms) and median simulator time of the same samples (s).
    pub fn times(&self) -> (f64, Option<f64>) {
        (self.timing.network_ms, self.timing.simulator_s)
    }

    /// Names this model's rows `method` (not the DQS row): a label of the caller's.
    fn set_method(&mut self, method: &str) {
        self.net.method = method.into();
        if let Some(p) = &mut self.pushed {
            p.method = format!("{method}, pushed out");
        }
        self.timing.method = method.into();
        for m in &mut self.by_motion {
            m.set_method(method);
        }
    }

    /// Appends ` (model)` to the method name of this model's rows (not of the DQS row).
    fn name_model(&mut self, model: &str) {
        let suffix = format!(" ({model})");
        let rows = [Some(&mut self.net), self.pushed.as_mut()];
        for method in rows.into_iter().flatten().map(|r| &mut r.method) {
            method.push_str(&suffix);
        }
        self.timing.method.push_str(&suffix);
        for m in &mut self.by_motion {
            m.add_to_method(&suffix);
        }
    }
}

/// Names the model file in the rows of the evaluations whose garment and method another
/// evaluation shares (two checkpoints of one variant), so that the tables tell them apart.
/// `evaluations[i]` is the evaluation of `models[i]`.
fn name_repeated_methods(evaluations: &mut [ModelEvaluation], models: &[PathBuf]) {
    let key = |e: &ModelEvaluation| (e.garment.clone(), e.timing.method.clone());
    let mut count: HashMap<(String, String), usize> = HashMap::new();
    for e in evaluations.iter() {
        *count.entry(key(e)).or_default() += 1;
    }
    for (e, path) in evaluations.iter_mut().zip(models) {
        if count[&key(e)] > 1 {
            e.name_model(&path.display().to_string());
        }
    }
}

/// A dataset opened for evaluation: the body faces, the template body and the simulator
/// time of each stored sample.
pub struct EvalData {
    data: Dataset,
    body_faces: Vec<[u32; 3]>,
    body_rest: body::ShapedBody,
    body_model: BodyModel,
    sim_times: HashMap<u64, f64>,
}

impl EvalData {
    /// Opens the dataset at `dir` (and loads the body model for the DQS timing).
    pub fn open(dir: &Path) -> anyhow::Result<Self> {
        let data = Dataset::open(dir)?;
        let body_faces = data.body_faces()?;
        let body_model = BodyModel::load()?;
        let body_rest = body_model.shape(&Phenotype::default())?;
        let sim_times = data
            .manifest()
            .samples
            .iter()
            .filter_map(|e| Some((e.record.index, e.timing.as_ref()?.drape_s)))
            .collect();
        Ok(Self {
            data,
            body_faces,
            body_rest,
            body_model,
            sim_times,
        })
    }

    /// The dataset.
    pub fn dataset(&self) -> &Dataset {
        &self.data
    }

    /// The dataset's spec name, spec hash and folder.
    pub fn id(&self) -> DatasetId {
        let m = self.data.manifest();
        DatasetId {
            name: m.spec.name.clone(),
            spec_sha256: m.spec_hash.clone(),
            dir: self.data.dir().to_path_buf(),
        }
    }

    /// Evaluates the model at `path` on `split` (the drapes `filter` keeps, when given; at
    /// most `max_samples` samples of its garment), with the extra `outputs`.
    pub fn evaluate(
        &self,
        path: &Path,
        split: &str,
        filter: Option<&DrapeFilter>,
        max_samples: Option<usize>,
        outputs: EvalOutputs,
        device: &burn::prelude::Device,
    ) -> anyhow::Result<ModelEvaluation> {
        let data = &self.data;
        let draper =
            Draper::load(path, device).with_context(|| format!("loading {}", path.display()))?;
        check_body_skinning(draper.setup(), data, path)?;
        let template = checkpoint_template(&draper, path)?;
        let faces = &template.mesh.faces;
        let garment = matching_garment(data, split, &template.mesh)?;
        let mut indices = data.select(Some(split), Some(&garment))?;
        if let Some(f) = filter {
            keep_drapes(data, split, &garment, &mut indices, f)?;
        }
        if let Some(n) = max_samples {
            indices.truncate(n);
        }
        let method = draper.setup().config.method_name();
        eprintln!(
            "{}: {method} on {} '{garment}' samples",
            path.display(),
            indices.len()
        );
        let (mut net, mut pushed, mut dqs, mut fitted) = (
            Errors::default(),
            Errors::default(),
            Errors::default(),
            Errors::default(),
        );
        let base =
            crate::drape::base_anchors(draper.setup().config.base, &template, &self.body_model)?;
        let anchors = match outputs.fitted {
            true => crate::drape::base_anchors(Base::Anchored, &template, &self.body_model)?,
            false => None,
        };
        let mut by_motion = ByMotion::default();
        let mut kept = outputs.keep_drapes.then(KeptDrapes::default);
        let mut saver = outputs
            .save_drapes
            .map(|dir| DrapeSaver::new(dir, faces, &self.body_faces))
            .transpose()?;
        let push_out = outputs.push_out;
        let (mut net_ms, mut dqs_ms, mut sim_s) = (Vec::new(), Vec::new(), Vec::new());
        let opts = BatchOptions {
            batch_size: 1,
            order: Order::InOrder,
            drop_last: false,
        };
        for batch in Batches::new(data, &indices, opts) {
            for s in batch? {
                let a = &s.arrays;
                let body_mesh = TriMesh::new(a.body.clone(), self.body_faces.clone());
                let start = Instant::now();
                let placed = base.as_ref().map(|b| b.place(&body_mesh));
                let mut pred = draper.drape(&a.body, placed.as_ref().unwrap_or(&a.warped))?;
                net_ms.push(start.elapsed().as_secs_f64() * 1e3);
                // The DQS warp of the same pose (its cost does not depend on the shape).
                let pose = Pose {
                    root_translation: a.root_translation,
                    rotations: a.rotations.clone(),
                };
                let start = Instant::now();
                garment::warp::warp(&template, &self.body_rest, &pose, Skinning::Dqs)?;
                dqs_ms.push(start.elapsed().as_secs_f64() * 1e3);
                sim_s.extend(self.sim_times.get(&s.record.index));
                // With the push-out, its collider's BVH serves the inside counts too.
                let collider = push_out
                    .then(|| sim::BodyCollider::new(&body_mesh, push_out_gap()))
                    .transpose()?;
                let own_bvh;
                let body = match &collider {
                    Some(c) => c.bvh(),
                    None => {
                        own_bvh = Bvh::from_mesh(&body_mesh)?;
                        &own_bvh
                    }
                };
                let net_cm = net.add(&a.draped, &pred, faces, body)?;
                let dqs_cm = dqs.add(&a.draped, &a.warped, faces, body)?;
                if let Some(anchors) = &anchors {
                    fitted.add(&a.draped, &anchors.place(&body_mesh), faces, body)?;
                }
                if let Some(saver) = &mut saver {
                    saver.save(&SavedDrape {
                        index: s.record.index,
                        pose: &s.record.pose,
                        body: &a.body,
                        sim: &a.draped,
                        dqs: &a.warped,
                        net: &pred,
                        errors: [net_cm, net.last_norm_deg(), dqs_cm],
                    })?;
                }
                if let Some(k) = &mut kept {
                    k.push(s.record.index, &pred, net_cm);
                }
                if let Some(c) = &collider {
                    c.push_out(&mut pred, PUSH_OUT_WITHIN, push_out_gap());
                    pushed.add(&a.draped, &pred, faces, body)?;
                }
                by_motion.add(&s.record.pose, net_cm, dqs_cm);
            }
        }
        if let Some(saver) = saver {
            let dir = saver.finish()?;
            eprintln!("drapes and their errors written to {}", dir.display());
        }
        Ok(ModelEvaluation {
            by_motion: by_motion.rows(&garment, &method),
            net: net.row(&garment, &method),
            pushed: push_out.then(|| pushed.row(&garment, &format!("{method}, pushed out"))),
            dqs: dqs.row(&garment, "DQS"),
            fitted: outputs
                .fitted
                .then(|| fitted.row(&garment, "surface-anchored M")),
            timing: Timing {
                garment: garment.clone(),
                method,
                vertices: template.mesh.vertices.len(),
                network_ms: median(net_ms),
                dqs_ms: median(dqs_ms),
                simulator_s: (!sim_s.is_empty()).then(|| median(sim_s)),
            },
            garment,
            kept,
        })
    }
}

/// The dataset an evaluation ran on: its spec's name and the SHA-256 of its spec.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DatasetId {
    /// The spec's name (`standard-lbs`).
    pub name: String,
    /// The SHA-256 of the resolved spec the dataset was generated from.
    pub spec_sha256: String,
    /// The dataset folder.
    pub dir: PathBuf,
}

/// What to evaluate: which drapes, how many, and the extra outputs.
#[derive(Clone, Debug, Default)]
pub struct EvalOptions {
    /// Only the drapes this filter keeps (every drape when `None`).
    pub filter: Option<DrapeFilter>,
    /// At most this many samples per model.
    pub max_samples: Option<usize>,
    /// Also rows of each network's drapes after the push-out (`garnet drape`'s default).
    pub push_out: bool,
    /// Also a row per garment of the surface-anchored M (see [`EvalOutputs::fitted`]).
    pub fitted: bool,
    /// Also write every evaluated drape and its errors under this folder, one folder per
    /// model (see [`save`]).
    pub save_drapes: Option<PathBuf>,
    /// `[models]` the row name of each model in the tables, in place of its method (or
    /// empty: the method names, with the model file where two models share one).
    pub labels: Vec<String>,
    /// Also draw one drape per garment by every model beside the simulator's
    /// (`drapes.png`, see [`pictures`]).
    pub pictures: bool,
}

/// Evaluates the models at `models` (any garments and variants) on `split` of the dataset
/// at `data`: Table 1, Table 2, the precision curves and E_dist by motion.
pub fn evaluate(
    data: &Path,
    split: &str,
    models: &[PathBuf],
    opts: &EvalOptions,
    device: &burn::prelude::Device,
) -> anyhow::Result<EvalReport> {
    if !opts.labels.is_empty() && opts.labels.len() != models.len() {
        return Err(anyhow!(
            "{} labels for {} models: give one label per model, in the models' order",
            opts.labels.len(),
            models.len()
        ));
    }
    let data = EvalData::open(data)?;
    let save_dirs = opts
        .save_drapes
        .as_ref()
        .map(|root| save_folders(root, models));
    let mut evaluations = Vec::new();
    for (i, path) in models.iter().enumerate() {
        evaluations.push(data.evaluate(
            path,
            split,
            opts.filter.as_ref(),
            opts.max_samples,
            EvalOutputs {
                push_out: opts.push_out,
                fitted: opts.fitted,
                save_drapes: save_dirs.as_ref().map(|d| d[i].as_path()),
                keep_drapes: opts.pictures,
            },
            device,
        )?);
    }
    if opts.labels.is_empty() {
        name_repeated_methods(&mut evaluations, models);
    } else {
        for (e, label) in evaluations.iter_mut().zip(&opts.labels) {
            e.set_method(label);
        }
    }
    let pictures = match opts.pictures {
        true => pictures::draw(&data, &evaluations)?,
        false => None,
    };
    let mut report = EvalReport {
        split: split.to_string(),
        dataset: data.id(),
        only: opts.filter.map(|f| f.describe()),
        rows: Vec::new(),
        timings: Vec::new(),
        motions: Vec::new(),
        pictures,
    };
    let mut dqs_done: BTreeSet<String> = BTreeSet::new();
    for e in evaluations {
        report.rows.push(e.net);
        report.rows.extend(e.pushed);
        if dqs_done.insert(e.garment) {
            report.rows.push(e.dqs);
            report.rows.extend(e.fitted);
        }
        report.timings.push(e.timing);
        report.motions.extend(e.by_motion);
    }
    Ok(report)
}

/// An evaluation's tables (see [`evaluate`]).
#[derive(Serialize)]
pub struct EvalReport {
    /// The split evaluated on.
    pub split: String,
    /// The dataset evaluated on.
    pub dataset: DatasetId,
    /// Which drapes were evaluated, when not every one.
    pub only: Option<String>,
    /// Table 1: each network's row, and DQS's once per garment.
    #[serde(rename = "table1")]
    rows: Vec<Row>,
    /// Table 2.
    #[serde(rename = "table2")]
    timings: Vec<Timing>,
    /// E_dist by motion.
    #[serde(rename = "by_motion")]
    motions: Vec<MotionRow>,
    /// One drape per garment by every model (`drapes.png`), when asked.
    #[serde(skip)]
    pictures: Option<render::Image>,
}

impl EvalReport {
    /// Table 1 as (garment, method, samples, E_dist cm, E_norm degrees, share of vertices
    /// inside the body), in the report's order.
    pub fn table1(&self) -> Vec<(String, String, usize, f32, f32, f32)> {
        self.rows
            .iter()
            .map(|r| {
                (
                    r.garment.clone(),
                    r.method.clone(),
                    r.samples,
                    r.e_dist_cm,
                    r.e_norm_deg,
                    r.inside_share,
                )
            })
            .collect()
    }

    /// The report as Markdown (results.md).
    pub fn markdown(&self) -> String {
        markdown(self)
    }

    /// Writes results.md, results.json and the two precision-curve PNGs into `out`.
    pub fn write(&self, out: &Path) -> anyhow::Result<()> {
        write_reports(out, self)
    }
}

/// The Markdown of `report`.
fn markdown(report: &EvalReport) -> String {
    let (rows, timings, motions) = (&report.rows, &report.timings, &report.motions);
    let mut md = format!("# GarNet evaluation (split '{}')\n\n", report.split);
    md += &format!(
        "Dataset '{}' (spec sha256 {}).\n\n",
        report.dataset.name,
        &report.dataset.spec_sha256[..report.dataset.spec_sha256.len().min(16)]
    );
    if let Some(only) = &report.only {
        md += &format!("Only {only}.\n\n");
    }
    md += "## Table 1: errors\n\n| garment | method | samples | E_dist (cm) | E_norm (deg) | vertices inside body |\n|---|---|---:|---:|---:|---:|\n";
    for r in rows {
        md += &format!(
            "| {} | {} | {} | {:.3} | {:.2} | {:.2}% |\n",
            r.garment,
            r.method,
            r.samples,
            r.e_dist_cm,
            r.e_norm_deg,
            r.inside_share * 100.0
        );
    }
    md += "\n## Table 2: time per drape\n\n| garment | method | vertices | network (ms) | DQS warp (ms) | simulator (s) | simulator / network |\n|---|---|---:|---:|---:|---:|---:|\n";
    for t in timings {
        let (sim, ratio) = match t.simulator_s {
            Some(s) => (
                format!("{s:.2}"),
                format!("{:.0}x", s * 1e3 / t.network_ms.max(1e-9)),
            ),
            None => ("n/a".into(), "n/a".into()),
        };
        md += &format!(
            "| {} | {} | {} | {:.1} | {:.2} | {sim} | {ratio} |\n",
            t.garment, t.method, t.vertices, t.network_ms, t.dqs_ms
        );
    }
    md += &motion::markdown(motions);
    md += "\nPrecision curves: precision_dist.png (share of vertices within a distance of the \
           simulated drape), precision_norm.png (share of faces within an angle of its normal).\n";
    if report.pictures.is_some() {
        md += "\nPictures: drapes.png, per garment the simulator's drape of the sample of median \
               E_dist among the first model's drapes, then every model's drape of it.\n";
    }
    md
}

/// Writes results.md, results.json and the two precision-curve PNGs of `report` into `out`.
fn write_reports(out: &Path, report: &EvalReport) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let md = markdown(report);
    geom::io::write_bytes_atomic(out.join("results.md"), md.as_bytes())?;
    #[derive(Serialize)]
    struct Json<'a> {
        #[serde(flatten)]
        report: &'a EvalReport,
        dist_thresholds_cm: Vec<f32>,
        norm_thresholds_deg: Vec<f32>,
    }
    let json = serde_json::to_string_pretty(&Json {
        report,
        dist_thresholds_cm: dist_thresholds(),
        norm_thresholds_deg: norm_thresholds(),
    })?;
    geom::io::write_bytes_atomic(out.join("results.json"), json.as_bytes())?;
    let rows = &report.rows;
    let colors = render::palette::CURVES;
    let series = |curve: fn(&Row) -> &Vec<f32>, xs: Vec<f32>| -> Vec<Series> {
        rows.iter()
            .enumerate()
            .map(|(i, r)| Series {
                name: format!("{} {}", r.garment, r.method),
                color: colors[i % colors.len()],
                points: xs.iter().copied().zip(curve(r).iter().copied()).collect(),
            })
            .collect()
    };
    let chart = |title: &str, x_label: &str, x_max: f32| Chart {
        title: title.into(),
        x_label: x_label.into(),
        y_label: "share".into(),
        x_range: (0.0, x_max),
        y_range: (0.0, 1.0),
        ticks: 5,
        size: (640, 420),
    };
    let dist = chart(
        "vertex distance precision",
        "distance to the simulated drape (cm)",
        5.0,
    )
    .draw(&series(|r| &r.dist_curve, dist_thresholds()));
    let norm = chart(
        "face normal precision",
        "normal angle to the simulated drape (deg)",
        60.0,
    )
    .draw(&series(|r| &r.norm_curve, norm_thresholds()));
    let pictures = report.pictures.iter().map(|p| (p, "drapes.png"));
    for (img, name) in [(&dist, "precision_dist.png"), (&norm, "precision_norm.png")]
        .into_iter()
        .chain(pictures)
    {
        let p = out.join(name);
        geom::io::write_bytes_atomic(&p, &img.encode_png()?)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    Ok(())
}
