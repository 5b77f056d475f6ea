//! Shard files: the finished samples of a fixed range of sample indices.
//!
//! `shards/shard-SSSSSS.safetensors` holds the tensors of every finished sample of its
//! range ([`crate::tensors`]) and one metadata entry `garnet_dataset_shard`, the JSON
//! [`ShardMeta`]: the spec hash, the shard index, the records of its samples and of its
//! failed samples, all sorted by index. Nothing in it depends on the machine, the number
//! of jobs, the order of work or the time, so the same spec always gives the same bytes.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{DatasetError, Result};
use crate::hash::sha256_hex;
use crate::layout::shard_file;
use crate::parts::{self, Part};
use crate::records::{FailureRecord, SampleRecord, Timing};
use crate::tensors::{self, RawTensor};

/// Metadata key of shard files.
pub const SHARD_KEY: &str = "garnet_dataset_shard";

/// Format tag of shard files.
pub const SHARD_FORMAT: &str = "garnet-dataset-shard-2";

/// The metadata of a shard.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardMeta {
    /// [`SHARD_FORMAT`].
    pub format: String,
    /// Hash of the spec.
    pub spec_hash: String,
    /// Shard index.
    pub shard: u64,
    /// The stored samples, by index.
    pub samples: Vec<SampleRecord>,
    /// The failed samples of the range, by index.
    pub failures: Vec<FailureRecord>,
}

/// A shard just written or found on disk.
#[derive(Clone, Debug)]
pub struct ShardInfo {
    /// Its metadata.
    pub meta: ShardMeta,
    /// Hex sha256 of the file.
    pub sha256: String,
    /// File size, bytes.
    pub bytes: u64,
    /// Wall times of its samples (those whose parts were still there), by index.
    pub timings: Vec<(u64, Timing)>,
}

/// Builds shard `shard` of dataset folder `dir` from the parts of samples `range` (all
/// must be there) and writes it atomically. The parts are left in place.
pub fn assemble(
    dir: &Path,
    shard: u64,
    range: std::ops::Range<u64>,
    spec_hash: &str,
) -> Result<ShardInfo> {
    let mut meta = ShardMeta {
        format: SHARD_FORMAT.into(),
        spec_hash: spec_hash.into(),
        shard,
        samples: Vec::new(),
        failures: Vec::new(),
    };
    let mut all: Vec<RawTensor> = Vec::new();
    let mut timings = Vec::new();
    for k in range {
        match parts::read(dir, k, spec_hash)? {
            Some(Part::Done { meta: m, tensors }) => {
                timings.push((k, m.timing));
                meta.samples.push(m.record);
                all.extend(tensors);
            }
            Some(Part::Failed(f)) => {
                timings.push((k, f.timing));
                meta.failures.push(f.failure);
            }
            None => {
                return Err(DatasetError::Invalid(format!(
                    "shard {shard}: sample {k} is not made yet"
                )))
            }
        }
    }
    let json = serde_json::to_string(&meta).expect("shard metadata serialises");
    let bytes = tensors::serialize(&all, SHARD_KEY, json)?;
    geom::io::write_bytes_atomic(dir.join(shard_file(shard)), &bytes)?;
    Ok(ShardInfo {
        meta,
        sha256: sha256_hex(&bytes),
        bytes: bytes.len() as u64,
        timings,
    })
}

/// The metadata of shard file `bytes` (read from `path`), checked against the expected
/// spec hash and shard index.
pub fn read_meta(bytes: &[u8], path: &Path, spec_hash: &str, shard: u64) -> Result<ShardMeta> {
    let (_, json) = tensors::parse(bytes, SHARD_KEY, path)?;
    let meta: ShardMeta =
        serde_json::from_str(&json).map_err(|e| DatasetError::corrupt(path, e.to_string()))?;
    if meta.format != SHARD_FORMAT {
        return Err(DatasetError::corrupt(
            path,
            format!("format {}, expected {SHARD_FORMAT}", meta.format),
        ));
    }
    if meta.spec_hash != spec_hash || meta.shard != shard {
        return Err(DatasetError::corrupt(
            path,
            format!(
                "shard {} of spec {}, expected shard {shard} of spec {spec_hash}",
                meta.shard, meta.spec_hash
            ),
        ));
    }
    Ok(meta)
}

/// Reads shard `shard` of `dir` from disk (after an interrupted run wrote it but not the
/// manifest), with the timings of the parts still there.
pub fn recover(dir: &Path, shard: u64, spec_hash: &str) -> Result<ShardInfo> {
    let path = dir.join(shard_file(shard));
    let bytes = std::fs::read(&path).map_err(|e| DatasetError::io(&path, e))?;
    let meta = read_meta(&bytes, &path, spec_hash, shard)?;
    let mut timings = Vec::new();
    let indices = meta.samples.iter().map(|s| s.index);
    for k in indices.chain(meta.failures.iter().map(|f| f.index)) {
        let timing = match parts::read(dir, k, spec_hash) {
            Ok(Some(Part::Done { meta, .. })) => Some(meta.timing),
            Ok(Some(Part::Failed(f))) => Some(f.timing),
            _ => None,
        };
        if let Some(t) = timing {
            timings.push((k, t));
        }
    }
    Ok(ShardInfo {
        sha256: sha256_hex(&bytes),
        bytes: bytes.len() as u64,
        meta,
        timings,
    })
}
