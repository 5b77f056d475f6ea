//! Generation: make the samples of the selected shards in parallel, save each as a part
//! file as soon as it is made, and write a shard (then the manifest) as soon as all of its
//! samples are made.
//!
//! Resuming is the same call: finished shards are kept, the parts of unfinished shards are
//! reused, stray temporary files are removed, and only the missing samples are made.
//! Killing the process at any moment loses at most the drapes in flight: every file is
//! written to a temporary name and renamed.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use body::{BodyModel, Phenotype};

use crate::cache::KeyedCache;
use crate::error::{DatasetError, Result};
use crate::layout::{self, body_faces_path, shard_file, spec_path, template_file};
use crate::manifest::{FileEntry, Manifest};
use crate::plan::Plan;
use crate::poses::PoseLibrary;
use crate::reuse::Reuse;
use crate::sample::Maker;
use crate::selection::ShardSelection;
use crate::shard::{self, ShardInfo};
use crate::spec::LoadedSpec;
use crate::templates::{TemplateError, TemplateStore};

/// How far a generation is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Progress {
    /// Samples of the selected shards made (stored or failed), this run or before.
    pub done: u64,
    /// Samples of the selected shards.
    pub total: u64,
    /// Of `done`, how many failed.
    pub failed: u64,
    /// Of `done`, how many this run made.
    pub made: u64,
}

/// Settings of a generation run.
pub struct GenerateOptions<'a> {
    /// Worker threads (samples in parallel; each drape also uses them).
    pub jobs: usize,
    /// The shards this run makes.
    pub selection: ShardSelection,
    /// Of those, only the shards holding a sample of one of these splits (names; empty:
    /// any split), say the test split alone for an evaluation.
    pub only_splits: Vec<String>,
    /// Of those, only the shards holding a sample of one of these garments (names; empty:
    /// any garment).
    pub only_garments: Vec<String>,
    /// The folder clip paths are relative to (needed when the spec names clips).
    pub mocap_root: Option<PathBuf>,
    /// A dataset of a smaller spec whose samples are taken instead of made again (see
    /// [`crate::reuse`]).
    pub reuse: Option<PathBuf>,
    /// Stop after making this many samples (the run can be resumed later).
    pub max_new_samples: Option<u64>,
    /// Set to stop: samples in flight finish and are saved, no new one starts.
    pub cancel: Option<&'a AtomicBool>,
    /// Called after each sample.
    pub progress: Option<&'a (dyn Fn(&Progress) + Sync)>,
}

impl GenerateOptions<'_> {
    /// One job per core, all shards, no limit, no hooks.
    pub fn new(mocap_root: Option<PathBuf>) -> Self {
        Self {
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
            selection: ShardSelection::ALL,
            only_splits: Vec::new(),
            only_garments: Vec::new(),
            mocap_root,
            reuse: None,
            max_new_samples: None,
            cancel: None,
            progress: None,
        }
    }
}

/// What a generation run did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GenerateReport {
    /// Samples in the whole dataset.
    pub total_samples: u64,
    /// Samples of the selected shards.
    pub selected_samples: u64,
    /// Of those, made by earlier runs (in shards or parts).
    pub resumed: u64,
    /// Of `resumed`, taken from the `--reuse` dataset by this run.
    pub reused: u64,
    /// Samples made by this run.
    pub made: u64,
    /// Of those, failed.
    pub failed: u64,
    /// Shards written by this run.
    pub shards_written: u64,
    /// Temporary files of interrupted writes removed.
    pub stray_temps_removed: usize,
    /// Whether every selected shard is finished.
    pub finished: bool,
    /// Whether every shard of the dataset is in the folder.
    pub complete: bool,
    /// Wall time of the run, seconds.
    pub wall_s: f64,
}

/// Generates (or resumes) the dataset of `spec` in folder `out`. Errors name the file or
/// the field; failed drapes are not errors but listed in the manifest.
pub fn generate(
    model: &BodyModel,
    spec: &LoadedSpec,
    out: &Path,
    opts: &GenerateOptions<'_>,
) -> Result<GenerateReport> {
    let t0 = Instant::now();
    opts.selection.check()?;
    let jobs = opts.jobs.max(1);
    let library = PoseLibrary::load(&spec.spec, opts.mocap_root.as_deref())?;
    let plan = Plan::new(spec, &library.frame_counts())?;
    layout::create_dirs(out)?;
    let stray_temps_removed = layout::remove_stray_temps(out)?;
    let mut manifest = open_manifest(out, spec, &plan, &library)?;
    let template_body = model.shape(&Phenotype::default())?;
    if !body_faces_path(out).is_file() || manifest.body_faces.is_none() {
        crate::body_faces::write(&body_faces_path(out), &template_body.mesh.faces)?;
        manifest.body_faces = Some(file_entry(out, layout::BODY_FACES)?);
    }
    let mut drape_options = spec.spec.simulator.drape_options().expect("validated");
    // Every thread of the workers' pool runs a drape of its own: a solve split over two
    // threads would only walk its factor twice (the drapes are the same either way).
    drape_options.cloth.split_solve = false;
    let maker = Maker {
        model,
        template_body,
        spec: &spec.spec,
        plan: &plan,
        library: &library,
        drape_options,
        templates: TemplateStore::new(out, plan.garments.len() + 2 * jobs + 2),
        bodies: KeyedCache::new(2 * jobs + 4),
        morphs: KeyedCache::new(2 * jobs + 2),
    };
    for (g, garment) in plan.garments.iter().enumerate() {
        if garment.per_body() {
            continue;
        }
        match maker.templates.get(model, plan.seed, g, garment, 0) {
            Ok(_) => note_template(out, &mut manifest, &garment.template_id(0))?,
            Err(TemplateError::Build(m) | TemplateError::Save(m)) => {
                return Err(DatasetError::spec(&spec.path, format!("garments[{g}]"), m))
            }
        }
    }
    reconcile(out, &plan, &mut manifest, &spec.hash)?;
    manifest.save(out)?;
    let reuse = match &opts.reuse {
        Some(dir) => Some(Reuse::open(dir, spec, &library)?),
        None => None,
    };
    let selection = scoped_selection(&plan, opts)?;
    let run =
        crate::run::Run::prepare(out, &plan, &spec.hash, manifest, &selection, reuse.as_ref())?;
    let mut report = GenerateReport {
        total_samples: plan.total(),
        selected_samples: run.progress.total,
        resumed: run.progress.done,
        reused: run.reused,
        stray_temps_removed,
        ..Default::default()
    };
    // Shards whose samples were all made before the interruption.
    for s in run.ready.clone() {
        run.finish_shard(s)?;
        report.shards_written += 1;
    }
    report.shards_written += run.work(&maker, jobs, opts)?;
    let progress = run.snapshot();
    let mut manifest = run.manifest.into_inner().unwrap_or_else(|p| p.into_inner());
    manifest.sort();
    manifest.save(out)?;
    report.made = progress.made;
    report.failed = progress.failed - run.resumed_failed;
    report.finished = (0..plan.shard_count())
        .filter(|&s| selection.contains(s))
        .all(|s| manifest.shard(s).is_some());
    report.complete = manifest.complete;
    report.wall_s = t0.elapsed().as_secs_f64();
    Ok(report)
}

/// The manifest of `out`: read and checked against the spec and the mocap files, or new.
fn open_manifest(
    out: &Path,
    spec: &LoadedSpec,
    plan: &Plan,
    library: &PoseLibrary,
) -> Result<Manifest> {
    let path = layout::manifest_path(out);
    if !path.is_file() {
        geom::io::write_bytes_atomic(spec_path(out), spec.resolved_toml().as_bytes())?;
        return Ok(Manifest::new(spec, plan, library.files.clone()));
    }
    let m = Manifest::load(out)?;
    if m.spec_hash != spec.hash {
        return Err(DatasetError::Invalid(format!(
            "{} holds a dataset of another spec than {} (with its base and --poses), which \
             differs in {}; run it with the spec and --poses it was started with (its \
             resolved spec is {}), or use another --out folder",
            out.display(),
            spec.path.display(),
            crate::spec::differences(&m.spec, &spec.spec).join(", "),
            spec_path(out).display()
        )));
    }
    for f in &library.files {
        if let Some(old) = m.mocap.iter().find(|o| o.path == f.path) {
            if old.sha256 != f.sha256 {
                return Err(DatasetError::Invalid(format!(
                    "mocap file {} changed since this dataset was started (sha256 {} then, {} now)",
                    f.path, old.sha256, f.sha256
                )));
            }
        }
    }
    Ok(m)
}

/// The manifest entry of file `rel` of `out`.
fn file_entry(out: &Path, rel: &str) -> Result<FileEntry> {
    Ok(FileEntry {
        file: rel.to_string(),
        sha256: crate::hash::sha256_file(&out.join(rel))?,
    })
}

/// Records template `id` in the manifest if it is not there yet.
fn note_template(out: &Path, m: &mut Manifest, id: &str) -> Result<()> {
    if !m.templates.contains_key(id) {
        m.templates
            .insert(id.to_string(), file_entry(out, &template_file(id))?);
    }
    Ok(())
}

/// Records a shard and the templates its samples use.
pub(crate) fn note_shard(out: &Path, m: &mut Manifest, info: &ShardInfo) -> Result<()> {
    m.add_shard(shard_file(info.meta.shard), info);
    for r in &info.meta.samples {
        note_template(out, m, &r.template)?;
    }
    Ok(())
}

/// Makes the manifest agree with the shard files on disk: forgets shards whose file is
/// gone or has another size, and adds shards an interrupted run wrote but did not record.
fn reconcile(out: &Path, plan: &Plan, m: &mut Manifest, hash: &str) -> Result<()> {
    for e in m.shards.clone() {
        let ok = std::fs::metadata(out.join(&e.file)).is_ok_and(|md| md.len() == e.bytes);
        if !ok {
            m.remove_shard(e.index);
        }
    }
    for name in layout::list(&out.join("shards"))? {
        let Some(s) = layout::parse_shard_name(&name) else {
            continue;
        };
        if s >= plan.shard_count() {
            return Err(DatasetError::corrupt(
                &out.join("shards").join(&name),
                format!("the spec has only {} shards", plan.shard_count()),
            ));
        }
        if m.shard(s).is_none() {
            let info = shard::recover(out, s, hash)?;
            note_shard(out, m, &info)?;
        }
    }
    m.sort();
    Ok(())
}

/// `opts.selection` narrowed to the shards that hold a sample of `opts.only_splits` and
/// `opts.only_garments`; an error when no shard is left.
fn scoped_selection(plan: &Plan, opts: &GenerateOptions) -> Result<ShardSelection> {
    if opts.only_splits.is_empty() && opts.only_garments.is_empty() {
        return Ok(opts.selection.clone());
    }
    // Ascending shards, runs of consecutive ones joined into one range.
    let mut shards: Vec<(u64, u64)> = Vec::new();
    for s in plan
        .shards_holding(&opts.only_splits, &opts.only_garments)?
        .into_iter()
        .filter(|&s| opts.selection.contains(s))
    {
        match shards.last_mut() {
            Some((_, end)) if *end + 1 == s => *end = s,
            _ => shards.push((s, s)),
        }
    }
    if shards.is_empty() {
        return Err(DatasetError::Invalid(format!(
            "no shard of the selection {} holds a sample of split(s) [{}] and garment(s) [{}]",
            opts.selection,
            opts.only_splits.join(", "),
            opts.only_garments.join(", ")
        )));
    }
    Ok(ShardSelection::Ranges(shards))
}
