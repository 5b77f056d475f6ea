//! Batches of samples for training, streamed shard by shard.
//!
//! In order, samples come by index. Shuffled, an epoch's order is drawn from its seed and
//! epoch number: the shards are shuffled, then the samples of each window of
//! [`Dataset::cache_shards`] consecutive shards are shuffled together. Each shard is thus
//! read once per epoch, and memory holds at most that many shards.

use std::collections::BTreeMap;

use crate::error::{DatasetError, Result};
use crate::reader::{Dataset, Sample};
use crate::rng::{derive, SplitMix64, Stream};

/// The order of an epoch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// By sample index.
    InOrder,
    /// Shuffled by `seed` and `epoch` (same seed and epoch, same order).
    Shuffled {
        /// Seed of the shuffle.
        seed: u64,
        /// Epoch number.
        epoch: u64,
    },
}

/// How batches are made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchOptions {
    /// Samples per batch (at least 1).
    pub batch_size: usize,
    /// Sample order.
    pub order: Order,
    /// Leave out a last batch smaller than `batch_size`.
    pub drop_last: bool,
}

/// The order in which an epoch visits `indices` (stored sample indices).
pub fn epoch_order(data: &Dataset, indices: &[u64], order: Order) -> Vec<u64> {
    let mut sorted = indices.to_vec();
    sorted.sort_unstable();
    let Order::Shuffled { seed, epoch } = order else {
        return sorted;
    };
    let m = data.manifest();
    let mut by_shard: BTreeMap<u64, Vec<u64>> = BTreeMap::new();
    for k in sorted {
        let shard = m.sample(k).map_or(u64::MAX, |e| e.shard);
        by_shard.entry(shard).or_default().push(k);
    }
    let mut groups: Vec<Vec<u64>> = by_shard.into_values().collect();
    // The epoch's stream: the split stream's space, keyed by (seed, epoch).
    let mut rng = SplitMix64::new(derive(seed, Stream::Split, &[u64::MAX, epoch]));
    rng.shuffle(&mut groups);
    let mut out = Vec::with_capacity(indices.len());
    for window in groups.chunks(data.cache_shards()) {
        let mut w: Vec<u64> = window.concat();
        rng.shuffle(&mut w);
        out.extend(w);
    }
    out
}

/// An iterator of batches (`Vec<Sample>`) over an epoch; each item reads its samples.
pub struct Batches<'a> {
    data: &'a Dataset,
    order: Vec<u64>,
    next: usize,
    opts: BatchOptions,
}

impl<'a> Batches<'a> {
    /// Batches of `indices` (stored sample indices, e.g. from [`Dataset::select`]).
    pub fn new(data: &'a Dataset, indices: &[u64], opts: BatchOptions) -> Self {
        Self {
            order: epoch_order(data, indices, opts.order),
            data,
            next: 0,
            opts: BatchOptions {
                batch_size: opts.batch_size.max(1),
                ..opts
            },
        }
    }

    /// Number of batches in the epoch.
    pub fn batch_count(&self) -> usize {
        let (n, b) = (self.order.len(), self.opts.batch_size);
        if self.opts.drop_last {
            n / b
        } else {
            n.div_ceil(b)
        }
    }

    /// The same epoch without its first `batches` batches, which are never read: where a
    /// training run stopped inside an epoch resumes it. Skipping past the end leaves none.
    pub fn skip_batches(mut self, batches: usize) -> Self {
        self.next = batches
            .saturating_mul(self.opts.batch_size)
            .min(self.order.len());
        self
    }
}

impl Iterator for Batches<'_> {
    type Item = Result<Vec<Sample>>;

    fn next(&mut self) -> Option<Self::Item> {
        let b = self.opts.batch_size;
        let end = (self.next + b).min(self.order.len());
        if self.next >= end || (self.opts.drop_last && end - self.next < b) {
            return None;
        }
        let batch = self.order[self.next..end]
            .iter()
            .map(|&k| self.data.sample(k))
            .collect();
        self.next = end;
        Some(batch)
    }
}

/// The points of `field` of every sample stacked row-major into `[B, N, 3]` floats;
/// errors if the samples' point counts differ (different templates).
pub fn stack(samples: &[Sample], field: impl Fn(&Sample) -> &[glam::Vec3]) -> Result<Vec<f32>> {
    let n = samples.first().map_or(0, |s| field(s).len());
    let mut out = Vec::with_capacity(samples.len() * n * 3);
    for s in samples {
        let points = field(s);
        if points.len() != n {
            return Err(DatasetError::Invalid(format!(
                "sample {} has {} points, the batch's first has {n}",
                s.record.index,
                points.len()
            )));
        }
        out.extend(points.iter().flat_map(|p| p.to_array()));
    }
    Ok(out)
}
