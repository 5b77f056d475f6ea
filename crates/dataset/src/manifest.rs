//! The manifest: `manifest.json` of a dataset folder, listing the spec (and its hash), the
//! files with their sha256 checksums, every stored sample (its shard and position, split,
//! body, pose, simulator statistics and wall times), every failed sample with its reason,
//! and the bodies of each split. It is rewritten (atomically) after every shard.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{DatasetError, Result};
use crate::layout::manifest_path;
use crate::plan::Plan;
use crate::poses::MocapFile;
use crate::records::{FailureRecord, SampleRecord, Timing};
use crate::shard::ShardInfo;
use crate::spec::{LoadedSpec, Spec};

/// Format tag of manifests.
pub const MANIFEST_FORMAT: &str = "garnet-dataset-2";

/// A file of the dataset and its checksum.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileEntry {
    /// Path relative to the dataset folder.
    pub file: String,
    /// Hex sha256.
    pub sha256: String,
}

/// A garment of the dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GarmentInfo {
    /// Its name.
    pub name: String,
    /// `tshirt`, `sweater` or `jeans`.
    pub kind: String,
    /// Template edge length, metres.
    pub edge: f32,
    /// Samples per body.
    pub poses_per_body: u32,
    /// Whether each body has its own cut (template `NAME-bBBBBB`).
    pub per_body_cut: bool,
}

/// A finished shard.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardEntry {
    /// Shard index.
    pub index: u64,
    /// Path relative to the dataset folder.
    pub file: String,
    /// Hex sha256 of the file.
    pub sha256: String,
    /// File size, bytes.
    pub bytes: u64,
    /// Samples stored in it.
    pub samples: u32,
    /// Samples of its range that failed.
    pub failures: u32,
}

/// A stored sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleEntry {
    /// What it is.
    #[serde(flatten)]
    pub record: SampleRecord,
    /// The shard holding it.
    pub shard: u64,
    /// Its position among the shard's samples.
    pub offset: u32,
    /// Wall times (absent when recovered from a shard whose parts were gone).
    pub timing: Option<Timing>,
}

/// A failed sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FailureEntry {
    /// What failed and why.
    #[serde(flatten)]
    pub record: FailureRecord,
    /// The shard whose range it is in.
    pub shard: u64,
    /// Wall times, if known.
    pub timing: Option<Timing>,
}

/// The manifest of a dataset folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`MANIFEST_FORMAT`].
    pub format: String,
    /// Version of garnet that wrote it.
    pub garnet_version: String,
    /// Hash of the spec ([`crate::spec::spec_hash`]).
    pub spec_hash: String,
    /// The spec.
    pub spec: Spec,
    /// Samples in the whole dataset (stored, failed or not made yet).
    pub total_samples: u64,
    /// Samples per shard.
    pub shard_size: u64,
    /// Shards of the whole dataset.
    pub shard_count: u64,
    /// Whether every shard of the dataset is here.
    pub complete: bool,
    /// The garments.
    pub garments: Vec<GarmentInfo>,
    /// Split name -> its body indices.
    pub splits: BTreeMap<String, Vec<u32>>,
    /// Splits that use only held-out poses (unseen-pose splits).
    pub held_out_splits: Vec<String>,
    /// The body faces file.
    pub body_faces: Option<FileEntry>,
    /// Template id -> its file.
    pub templates: BTreeMap<String, FileEntry>,
    /// The mocap files read, relative to the mocap root.
    pub mocap: Vec<MocapFile>,
    /// Finished shards, by index.
    pub shards: Vec<ShardEntry>,
    /// Stored samples, by index.
    pub samples: Vec<SampleEntry>,
    /// Failed samples, by index.
    pub failures: Vec<FailureEntry>,
}

impl Manifest {
    /// The manifest of a new, empty dataset of `spec`.
    pub fn new(spec: &LoadedSpec, plan: &Plan, mocap: Vec<MocapFile>) -> Self {
        let splits = plan
            .split_names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.clone(), plan.split_bodies(i)))
            .collect();
        Self {
            format: MANIFEST_FORMAT.into(),
            garnet_version: env!("CARGO_PKG_VERSION").into(),
            spec_hash: spec.hash.clone(),
            spec: spec.spec.clone(),
            total_samples: plan.total(),
            shard_size: plan.shard_size,
            shard_count: plan.shard_count(),
            complete: plan.total() == 0,
            garments: plan
                .garments
                .iter()
                .map(|g| GarmentInfo {
                    name: g.name.clone(),
                    kind: g.kind.name().to_string(),
                    edge: g.edge,
                    poses_per_body: g.poses_per_body,
                    per_body_cut: g.per_body(),
                })
                .collect(),
            splits,
            held_out_splits: plan
                .split_names
                .iter()
                .zip(&plan.held_out)
                .filter(|(_, &h)| h)
                .map(|(n, _)| n.clone())
                .collect(),
            body_faces: None,
            templates: BTreeMap::new(),
            mocap,
            shards: Vec::new(),
            samples: Vec::new(),
            failures: Vec::new(),
        }
    }

    /// Reads the manifest of dataset folder `dir`.
    pub fn load(dir: &Path) -> Result<Self> {
        let path = manifest_path(dir);
        let text = std::fs::read_to_string(&path).map_err(|e| DatasetError::io(&path, e))?;
        // The format first: a manifest of another format need not parse as this one.
        let value: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| DatasetError::corrupt(&path, format!("not a dataset manifest: {e}")))?;
        let format = value
            .get("format")
            .and_then(|f| f.as_str())
            .unwrap_or("none");
        if format != MANIFEST_FORMAT {
            return Err(DatasetError::corrupt(
                &path,
                format!(
                    "format {format}, expected {MANIFEST_FORMAT}: made by another version of \
                     garnet; generate it again with this one (from a spec of format {})",
                    crate::spec::SPEC_FORMAT
                ),
            ));
        }
        let m: Manifest = serde_json::from_value(value)
            .map_err(|e| DatasetError::corrupt(&path, format!("not a dataset manifest: {e}")))?;
        Ok(m)
    }

    /// Writes the manifest into dataset folder `dir` (atomically).
    pub fn save(&self, dir: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).expect("a manifest serialises");
        geom::io::write_bytes_atomic(manifest_path(dir), text.as_bytes())?;
        Ok(())
    }

    /// Records a finished shard: its entry, its samples and its failures (replacing what
    /// was recorded of that shard).
    pub fn add_shard(&mut self, file: String, info: &ShardInfo) {
        let s = info.meta.shard;
        self.remove_shard(s);
        let timing = |k: u64| info.timings.iter().find(|(i, _)| *i == k).map(|t| t.1);
        self.shards.push(ShardEntry {
            index: s,
            file,
            sha256: info.sha256.clone(),
            bytes: info.bytes,
            samples: info.meta.samples.len() as u32,
            failures: info.meta.failures.len() as u32,
        });
        for (offset, r) in info.meta.samples.iter().enumerate() {
            self.samples.push(SampleEntry {
                record: r.clone(),
                shard: s,
                offset: offset as u32,
                timing: timing(r.index),
            });
        }
        for f in &info.meta.failures {
            self.failures.push(FailureEntry {
                record: f.clone(),
                shard: s,
                timing: timing(f.index),
            });
        }
        self.sort();
    }

    /// Forgets shard `s` and its samples.
    pub fn remove_shard(&mut self, s: u64) {
        self.shards.retain(|e| e.index != s);
        self.samples.retain(|e| e.shard != s);
        self.failures.retain(|e| e.shard != s);
        self.complete = false;
    }

    /// Sorts shards, samples and failures by index and updates [`Manifest::complete`].
    pub fn sort(&mut self) {
        self.shards.sort_by_key(|e| e.index);
        self.samples.sort_by_key(|e| e.record.index);
        self.failures.sort_by_key(|e| e.record.index);
        self.complete = self.shards.len() as u64 == self.shard_count;
    }

    /// The entry of shard `s`, if finished.
    pub fn shard(&self, s: u64) -> Option<&ShardEntry> {
        self.shards
            .binary_search_by_key(&s, |e| e.index)
            .ok()
            .map(|i| &self.shards[i])
    }

    /// The entry of stored sample `k`, if stored.
    pub fn sample(&self, k: u64) -> Option<&SampleEntry> {
        self.samples
            .binary_search_by_key(&k, |e| e.record.index)
            .ok()
            .map(|i| &self.samples[i])
    }

    /// The bodies of this dataset's split `split` that are also bodies of `other`'s split
    /// `other_split`, ascending. Body `b`'s shape is drawn from the spec's seed, shape
    /// distribution and `b`, so two datasets share a body index exactly when they draw
    /// bodies alike. Errors if a split is unknown, or if the two draw their bodies
    /// differently (another seed or shape distribution: no body can be matched).
    pub fn shared_bodies(
        &self,
        split: &str,
        other: &Manifest,
        other_split: &str,
    ) -> Result<Vec<u32>> {
        if self.spec.seed != other.spec.seed
            || self.spec.bodies.distribution != other.spec.bodies.distribution
        {
            return Err(DatasetError::Invalid(format!(
                "'{}' and '{}' draw their bodies differently (another seed or shape \
                 distribution), so their bodies cannot be matched",
                self.spec.name, other.spec.name
            )));
        }
        let bodies = |m: &Manifest, s: &str| -> Result<BTreeSet<u32>> {
            m.splits
                .get(s)
                .map(|b| b.iter().copied().collect())
                .ok_or_else(|| {
                    let known: Vec<&str> = m.splits.keys().map(String::as_str).collect();
                    DatasetError::Invalid(format!(
                        "'{}' has no split '{s}' (the splits are {})",
                        m.spec.name,
                        known.join(", ")
                    ))
                })
        };
        let mine = bodies(self, split)?;
        let theirs = bodies(other, other_split)?;
        Ok(mine.intersection(&theirs).copied().collect())
    }
}
