//! The workers of a generation run: what is left to make, making it in parallel, and
//! writing each shard as soon as its last sample is made.

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;

use crate::error::{DatasetError, Result};
use crate::generate::{note_shard, GenerateOptions, Progress};
use crate::manifest::Manifest;
use crate::parts::{self, FailedPart, Part, PartMeta};
use crate::plan::Plan;
use crate::reuse::Reuse;
use crate::sample::{Maker, Outcome};
use crate::selection::ShardSelection;
use crate::shard;

/// The state of a run shared by its workers.
pub(crate) struct Run<'a> {
    out: &'a Path,
    plan: &'a Plan,
    hash: &'a str,
    pub(crate) manifest: Mutex<Manifest>,
    /// Samples to make, ascending.
    todo: Vec<u64>,
    /// Samples still to make per unfinished shard.
    remaining: HashMap<u64, AtomicU64>,
    /// Shards whose samples are all made but not written.
    pub(crate) ready: Vec<u64>,
    pub(crate) progress: Progress,
    pub(crate) resumed_failed: u64,
    /// Samples taken from the `--reuse` dataset.
    pub(crate) reused: u64,
    done: AtomicU64,
    failed: AtomicU64,
    made: AtomicU64,
}

impl<'a> Run<'a> {
    /// Finds what is left to do in the selected shards, taking from `reuse` the samples
    /// it holds.
    pub(crate) fn prepare(
        out: &'a Path,
        plan: &'a Plan,
        hash: &'a str,
        manifest: Manifest,
        selection: &ShardSelection,
        reuse: Option<&Reuse>,
    ) -> Result<Self> {
        let (mut todo, mut remaining, mut ready) = (Vec::new(), HashMap::new(), Vec::new());
        let mut reused = 0;
        let mut progress = Progress::default();
        for s in (0..plan.shard_count()).filter(|&s| selection.contains(s)) {
            let range = plan.shard_range(s);
            progress.total += range.end - range.start;
            if let Some(e) = manifest.shard(s) {
                progress.done += range.end - range.start;
                progress.failed += e.failures as u64;
                parts::remove(out, range)?; // leftovers of an interrupted clean-up
                continue;
            }
            let mut missing = Vec::new();
            for k in range {
                match parts::read(out, k, hash) {
                    Ok(Some(p)) => {
                        progress.done += 1;
                        progress.failed += matches!(p, Part::Failed(_)) as u64;
                    }
                    Ok(None) => match reuse.map(|r| r.take(out, plan, k)).transpose()? {
                        Some(Some(failed)) => {
                            reused += 1;
                            progress.done += 1;
                            progress.failed += failed as u64;
                        }
                        _ => missing.push(k),
                    },
                    // A damaged part is made again.
                    Err(_) => {
                        parts::remove(out, k..k + 1)?;
                        missing.push(k);
                    }
                }
            }
            if missing.is_empty() {
                ready.push(s);
            } else {
                remaining.insert(s, AtomicU64::new(missing.len() as u64));
                todo.extend(missing);
            }
        }
        Ok(Self {
            out,
            plan,
            hash,
            manifest: Mutex::new(manifest),
            todo,
            remaining,
            ready,
            resumed_failed: progress.failed,
            reused,
            done: AtomicU64::new(progress.done),
            failed: AtomicU64::new(progress.failed),
            made: AtomicU64::new(0),
            progress,
        })
    }

    pub(crate) fn snapshot(&self) -> Progress {
        Progress {
            done: self.done.load(Ordering::SeqCst),
            total: self.progress.total,
            failed: self.failed.load(Ordering::SeqCst),
            made: self.made.load(Ordering::SeqCst),
        }
    }

    /// Writes shard `s` from its parts, records it, then removes the parts.
    pub(crate) fn finish_shard(&self, s: u64) -> Result<()> {
        let range = self.plan.shard_range(s);
        let info = shard::assemble(self.out, s, range.clone(), self.hash)?;
        {
            let mut m = self.manifest.lock().unwrap_or_else(|p| p.into_inner());
            note_shard(self.out, &mut m, &info)?;
            m.save(self.out)?;
        }
        parts::remove(self.out, range)
    }

    /// Makes sample `k`, saves its part, and finishes its shard if it was the last.
    fn make_one(&self, maker: &Maker<'_>, k: u64, opts: &GenerateOptions<'_>) -> Result<bool> {
        let desc = self.plan.sample(k);
        let (outcome, timing) = maker.make(&desc)?;
        let spec_hash = self.hash.to_string();
        match outcome {
            Outcome::Done(b) => {
                let (record, arrays) = *b;
                let meta = PartMeta {
                    spec_hash,
                    record,
                    timing,
                };
                parts::write_done(self.out, &arrays, &meta, maker.spec.output.compact)?;
            }
            Outcome::Failed(failure) => {
                self.failed.fetch_add(1, Ordering::SeqCst);
                let part = FailedPart {
                    spec_hash,
                    failure,
                    timing,
                };
                parts::write_failed(self.out, &part)?;
            }
        }
        self.made.fetch_add(1, Ordering::SeqCst);
        self.done.fetch_add(1, Ordering::SeqCst);
        if let Some(f) = opts.progress {
            f(&self.snapshot());
        }
        let s = self.plan.shard_of(k);
        let left = self.remaining[&s].fetch_sub(1, Ordering::SeqCst) - 1;
        if left == 0 {
            self.finish_shard(s)?;
        }
        Ok(left == 0)
    }

    /// Runs `jobs` workers over the samples to make; returns the shards written.
    pub(crate) fn work(
        &self,
        maker: &Maker<'_>,
        jobs: usize,
        opts: &GenerateOptions<'_>,
    ) -> Result<u64> {
        let next = AtomicUsize::new(0);
        let claimed = AtomicU64::new(0);
        let stop = AtomicBool::new(false);
        let written = AtomicU64::new(0);
        let error: Mutex<Option<DatasetError>> = Mutex::new(None);
        let claim = || -> Option<u64> {
            let cancelled = opts.cancel.is_some_and(|c| c.load(Ordering::SeqCst));
            if stop.load(Ordering::SeqCst) || cancelled {
                return None;
            }
            if let Some(limit) = opts.max_new_samples {
                if claimed.fetch_add(1, Ordering::SeqCst) >= limit {
                    return None;
                }
            }
            self.todo.get(next.fetch_add(1, Ordering::SeqCst)).copied()
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| DatasetError::Invalid(format!("starting {jobs} threads: {e}")))?;
        pool.scope(|scope| {
            for _ in 0..jobs {
                scope.spawn(|_| {
                    while let Some(k) = claim() {
                        match self.make_one(maker, k, opts) {
                            Ok(wrote) => {
                                written.fetch_add(wrote as u64, Ordering::SeqCst);
                            }
                            Err(e) => {
                                stop.store(true, Ordering::SeqCst);
                                let mut slot = error.lock().unwrap_or_else(|p| p.into_inner());
                                slot.get_or_insert(e);
                                break;
                            }
                        }
                    }
                });
            }
        });
        match error.into_inner().unwrap_or_else(|p| p.into_inner()) {
            Some(e) => Err(e),
            None => Ok(written.into_inner()),
        }
    }
}
