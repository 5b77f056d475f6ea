//! Merging the folders of a job array (`--shard i/n` runs) into one dataset.

use std::path::{Path, PathBuf};

use garment::GarmentTemplate;

use crate::error::{DatasetError, Result};
use crate::hash::sha256_hex;
use crate::layout::{self, body_faces_path, spec_path};
use crate::manifest::Manifest;

/// What a merge did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MergeReport {
    /// Shards in the merged dataset.
    pub shards: u64,
    /// Shards of the dataset.
    pub shard_count: u64,
    /// Stored samples in the merged dataset.
    pub samples: u64,
    /// Failed samples listed.
    pub failures: u64,
    /// Whether every shard is there.
    pub complete: bool,
    /// Shards that are missing (none when complete).
    pub missing: Vec<u64>,
}

fn read(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| DatasetError::io(path, e))
}

/// Merges the datasets in `inputs` (all of one spec) into the new folder `out`. Every
/// shard's checksum is verified while it is copied; a shard present in two inputs must be
/// identical, and so must templates of one id (compared by content).
pub fn merge(out: &Path, inputs: &[PathBuf]) -> Result<MergeReport> {
    if inputs.is_empty() {
        return Err(DatasetError::Invalid(
            "merge needs at least one input folder".into(),
        ));
    }
    if layout::manifest_path(out).exists() {
        return Err(DatasetError::Invalid(format!(
            "{} already holds a dataset; merge into a new folder",
            out.display()
        )));
    }
    let manifests: Vec<Manifest> = inputs
        .iter()
        .map(|d| Manifest::load(d))
        .collect::<Result<_>>()?;
    let first = &manifests[0];
    for (m, dir) in manifests.iter().zip(inputs).skip(1) {
        if m.spec_hash != first.spec_hash || m.mocap != first.mocap {
            return Err(DatasetError::Invalid(format!(
                "{} and {} are datasets of different specs or mocap files (spec {} vs {})",
                inputs[0].display(),
                dir.display(),
                first.spec_hash,
                m.spec_hash
            )));
        }
    }
    layout::create_dirs(out)?;
    let mut merged = first.clone();
    merged.shards.clear();
    merged.samples.clear();
    merged.failures.clear();
    merged.templates.clear();
    let text = read(&spec_path(&inputs[0]))?;
    geom::io::write_bytes_atomic(spec_path(out), &text)?;
    let faces = first.body_faces.clone().ok_or_else(|| {
        DatasetError::Invalid(format!("{} has no body faces", inputs[0].display()))
    })?;
    copy_checked(
        &inputs[0].join(&faces.file),
        &body_faces_path(out),
        &faces.sha256,
    )?;
    let mut seen: std::collections::BTreeMap<u64, String> = Default::default();
    for (m, dir) in manifests.iter().zip(inputs) {
        for (id, entry) in &m.templates {
            merge_template(dir, out, &mut merged, id, entry)?;
        }
        let mut taken = std::collections::BTreeSet::new();
        for e in &m.shards {
            if let Some(have) = seen.get(&e.index) {
                if *have != e.sha256 {
                    return Err(DatasetError::Invalid(format!(
                        "shard {} differs between the inputs ({} in {})",
                        e.index,
                        e.file,
                        dir.display()
                    )));
                }
                continue;
            }
            copy_checked(&dir.join(&e.file), &out.join(&e.file), &e.sha256)?;
            seen.insert(e.index, e.sha256.clone());
            taken.insert(e.index);
            merged.shards.push(e.clone());
        }
        let mine = |shard: &u64| taken.contains(shard);
        merged
            .samples
            .extend(m.samples.iter().filter(|s| mine(&s.shard)).cloned());
        merged
            .failures
            .extend(m.failures.iter().filter(|f| mine(&f.shard)).cloned());
    }
    merged.sort();
    merged.save(out)?;
    Ok(MergeReport {
        shards: merged.shards.len() as u64,
        shard_count: merged.shard_count,
        samples: merged.samples.len() as u64,
        failures: merged.failures.len() as u64,
        complete: merged.complete,
        missing: (0..merged.shard_count)
            .filter(|&s| merged.shard(s).is_none())
            .collect(),
    })
}

/// Copies `from` to `to` (atomically) after checking its sha256 against `sha256`.
fn copy_checked(from: &Path, to: &Path, sha256: &str) -> Result<()> {
    let bytes = read(from)?;
    let actual = sha256_hex(&bytes);
    if actual != sha256 {
        return Err(DatasetError::corrupt(
            from,
            format!("checksum mismatch: sha256 {actual}, the manifest says {sha256}"),
        ));
    }
    geom::io::write_bytes_atomic(to, &bytes)?;
    Ok(())
}

/// Adds template `id` of input `dir` to the merge, or checks it equals the one there.
fn merge_template(
    dir: &Path,
    out: &Path,
    merged: &mut Manifest,
    id: &str,
    entry: &crate::manifest::FileEntry,
) -> Result<()> {
    let from = dir.join(&entry.file);
    let to = out.join(&entry.file);
    match merged.templates.get(id) {
        None => {
            copy_checked(&from, &to, &entry.sha256)?;
            merged.templates.insert(id.to_string(), entry.clone());
        }
        // Template files of equal content may differ in bytes (their metadata is a hash
        // map), so compare what they hold.
        Some(have) if have.sha256 != entry.sha256 => {
            let a = GarmentTemplate::load(&to)?;
            let b = GarmentTemplate::load(&from)?;
            if a != b {
                return Err(DatasetError::Invalid(format!(
                    "template {id} differs between the inputs ({})",
                    from.display()
                )));
            }
        }
        Some(_) => {}
    }
    Ok(())
}
