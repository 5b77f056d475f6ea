//! Part files: each sample of an unfinished shard, saved as soon as it is made, so an
//! interrupted generation loses at most the drapes in flight.
//!
//! `parts/KKKKKKKKKK.part` is a safetensors file with the sample's tensors
//! ([`crate::tensors`]) and one metadata entry `garnet_dataset_part` (JSON
//! [`PartMeta`]); `parts/KKKKKKKKKK.failed` is JSON [`FailedPart`]. Both are written
//! atomically and removed once their shard is written.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{DatasetError, Result};
use crate::layout::{failed_path, part_path};
use crate::records::{FailureRecord, SampleRecord, Timing};
use crate::tensors::{self, RawTensor, SampleArrays};

/// Metadata key of part files.
pub const PART_KEY: &str = "garnet_dataset_part";

/// The metadata of a finished sample's part file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartMeta {
    /// Hash of the spec it was made for.
    pub spec_hash: String,
    /// What the sample is.
    pub record: SampleRecord,
    /// How long it took.
    pub timing: Timing,
}

/// A failed sample's part file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FailedPart {
    /// Hash of the spec it was made for.
    pub spec_hash: String,
    /// What failed and why.
    pub failure: FailureRecord,
    /// How long it took.
    pub timing: Timing,
}

/// A part read back.
#[derive(Clone, Debug)]
pub enum Part {
    /// A finished sample and its tensors.
    Done {
        /// Its metadata.
        meta: PartMeta,
        /// Its tensors, ready to go into a shard.
        tensors: Vec<RawTensor>,
    },
    /// A failed sample.
    Failed(FailedPart),
}

/// Saves finished sample `record.index` of dataset folder `dir` (`compact`: without its
/// body and M, see [`crate::tensors`]).
pub fn write_done(dir: &Path, arrays: &SampleArrays, meta: &PartMeta, compact: bool) -> Result<()> {
    let k = meta.record.index;
    let json = serde_json::to_string(meta).expect("part metadata serialises");
    let bytes = tensors::serialize(&arrays.to_tensors(k, compact), PART_KEY, json)?;
    geom::io::write_bytes_atomic(part_path(dir, k), &bytes)?;
    Ok(())
}

/// Saves failed sample `part.failure.index` of dataset folder `dir`.
pub fn write_failed(dir: &Path, part: &FailedPart) -> Result<()> {
    let json = serde_json::to_string_pretty(part).expect("failure serialises");
    geom::io::write_bytes_atomic(failed_path(dir, part.failure.index), json.as_bytes())?;
    Ok(())
}

/// The part of sample `k` in `dir`, if there is one; an unreadable part, or one of
/// another spec, is an error naming the file.
pub fn read(dir: &Path, k: u64, spec_hash: &str) -> Result<Option<Part>> {
    let failed = failed_path(dir, k);
    if failed.is_file() {
        let text = std::fs::read_to_string(&failed).map_err(|e| DatasetError::io(&failed, e))?;
        let part: FailedPart = serde_json::from_str(&text)
            .map_err(|e| DatasetError::corrupt(&failed, e.to_string()))?;
        check(&failed, &part.spec_hash, part.failure.index, spec_hash, k)?;
        return Ok(Some(Part::Failed(part)));
    }
    let path = part_path(dir, k);
    if !path.is_file() {
        return Ok(None);
    }
    let bytes = std::fs::read(&path).map_err(|e| DatasetError::io(&path, e))?;
    let (st, json) = tensors::parse(&bytes, PART_KEY, &path)?;
    let meta: PartMeta =
        serde_json::from_str(&json).map_err(|e| DatasetError::corrupt(&path, e.to_string()))?;
    check(&path, &meta.spec_hash, meta.record.index, spec_hash, k)?;
    let mut raw: Vec<RawTensor> = st
        .tensors()
        .into_iter()
        .map(|(name, t)| (name, t.shape().to_vec(), t.data().to_vec()))
        .collect();
    raw.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(Some(Part::Done { meta, tensors: raw }))
}

fn check(path: &Path, hash: &str, index: u64, spec_hash: &str, k: u64) -> Result<()> {
    if hash != spec_hash || index != k {
        return Err(DatasetError::corrupt(
            path,
            format!("a part of another spec or sample (spec {hash}, sample {index})"),
        ));
    }
    Ok(())
}

/// Removes the part files of samples `range` in `dir` (missing ones are fine).
pub fn remove(dir: &Path, range: std::ops::Range<u64>) -> Result<()> {
    for k in range {
        for p in [part_path(dir, k), failed_path(dir, k)] {
            match std::fs::remove_file(&p) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(DatasetError::io(&p, e)),
            }
        }
    }
    Ok(())
}
