//! The plan of a dataset: every sample enumerated from the spec and its seed, the split
//! of the bodies, and the shards.
//!
//! Samples are numbered garment after garment, then body after body, then pose slot
//! after pose slot: sample `k` of garment `g` is body `b = (k - offset_g) / ppb_g` in slot
//! `(k - offset_g) % ppb_g`, where `ppb_g` is the garment's poses per body. Everything
//! about a sample is a pure function of the spec and `k` (see [`crate::rng`]), so any
//! subset of samples, in any order, on any machine, comes out the same.

use std::collections::BTreeMap;
use std::path::Path;

use crate::cuts::GarmentPlan;
use crate::error::{DatasetError, Result};
use crate::pool::PosePool;
use crate::rng::{derive, SplitMix64, Stream};
use crate::spec::{LoadedSpec, SplitSize};

/// Body counts of the splits (in the map's order) for `bodies` bodies: counts must add up
/// to `bodies`; fractions must add up to 1 and are rounded by largest remainder.
pub fn split_counts(
    sizes: &BTreeMap<String, SplitSize>,
    bodies: u32,
) -> std::result::Result<Vec<u32>, String> {
    let total = bodies as u64;
    if sizes.values().all(|s| matches!(s, SplitSize::Count(_))) {
        let counts: Vec<u64> = sizes
            .values()
            .map(|s| match s {
                SplitSize::Count(c) => *c,
                SplitSize::Fraction(_) => 0,
            })
            .collect();
        let sum: u64 = counts.iter().sum();
        if sum != total {
            return Err(format!(
                "the split counts add up to {sum}, not to bodies.count = {bodies}"
            ));
        }
        return Ok(counts.into_iter().map(|c| c as u32).collect());
    }
    let fractions: Vec<f64> = sizes
        .values()
        .map(|s| match s {
            SplitSize::Fraction(f) => *f,
            SplitSize::Count(c) => *c as f64,
        })
        .collect();
    if fractions.iter().any(|f| !(0.0..=1.0).contains(f)) {
        return Err("fractions must be in [0, 1]".into());
    }
    let sum: f64 = fractions.iter().sum();
    if (sum - 1.0).abs() > 1e-6 {
        return Err(format!("the split fractions add up to {sum}, not to 1"));
    }
    let exact: Vec<f64> = fractions.iter().map(|f| f * total as f64).collect();
    let mut counts: Vec<u32> = exact.iter().map(|e| e.floor() as u32).collect();
    let mut order: Vec<usize> = (0..exact.len()).collect();
    // Largest remainders first; ties to the earlier split.
    order.sort_by(|&a, &b| {
        let (ra, rb) = (exact[a] - exact[a].floor(), exact[b] - exact[b].floor());
        rb.total_cmp(&ra).then(a.cmp(&b))
    });
    let short = bodies - counts.iter().sum::<u32>();
    for &i in order.iter().take(short as usize) {
        counts[i] += 1;
    }
    Ok(counts)
}

/// What sample `index` is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleDesc {
    /// Sample index.
    pub index: u64,
    /// Garment index in the plan.
    pub garment: usize,
    /// Body index.
    pub body: u32,
    /// Pose slot of this body and garment (0..poses_per_body).
    pub slot: u32,
    /// Split index (into [`Plan::split_names`]).
    pub split: usize,
    /// Pose index in the pool.
    pub pose: usize,
}

/// Every sample of a dataset.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The spec's seed.
    pub seed: u64,
    /// The garments, in spec order.
    pub garments: Vec<GarmentPlan>,
    /// First sample index of each garment, and the total at the end: `[garments + 1]`.
    pub offsets: Vec<u64>,
    /// Number of bodies.
    pub bodies: u32,
    /// The split names, sorted.
    pub split_names: Vec<String>,
    /// `[bodies]`: each body's split index.
    pub body_split: Vec<usize>,
    /// `[splits]`: whether a split uses only the held-out poses.
    pub held_out: Vec<bool>,
    /// All poses.
    pub pool: PosePool,
    /// Pool indices open to ordinary splits, and to held-out splits.
    eligible: [Vec<usize>; 2],
    /// Samples per shard.
    pub shard_size: u64,
}

impl Plan {
    /// The plan of `spec`, given each clip's frame count (see [`PosePool::new`]).
    /// Errors (naming the spec file and field) when a split's pose pool is smaller than a
    /// garment's poses per body.
    pub fn new(spec: &LoadedSpec, frame_counts: &[usize]) -> Result<Self> {
        let (s, file) = (&spec.spec, spec.path.as_path());
        let garments: Vec<GarmentPlan> = s
            .garments
            .iter()
            .map(|g| GarmentPlan::from_spec(g).expect("validated"))
            .collect();
        let mut offsets = vec![0u64];
        for g in &garments {
            offsets.push(offsets.last().unwrap() + s.bodies.count as u64 * g.poses_per_body as u64);
        }
        let counts = split_counts(&s.splits.bodies, s.bodies.count)
            .map_err(|m| DatasetError::spec(file, "splits.bodies", m))?;
        let mut order: Vec<u32> = (0..s.bodies.count).collect();
        SplitMix64::new(derive(s.seed, Stream::Split, &[])).shuffle(&mut order);
        let mut body_split = vec![0usize; s.bodies.count as usize];
        let mut next = order.into_iter();
        for (split, &c) in counts.iter().enumerate() {
            for b in next.by_ref().take(c as usize) {
                body_split[b as usize] = split;
            }
        }
        let split_names: Vec<String> = s.splits.bodies.keys().cloned().collect();
        let held_out: Vec<bool> = split_names
            .iter()
            .map(|n| {
                s.splits
                    .unseen_poses
                    .as_ref()
                    .is_some_and(|u| u.held_out.contains(n))
            })
            .collect();
        let pool = PosePool::new(s, file, frame_counts)?;
        let eligible = [true, false].map(|seen| {
            (0..pool.poses.len())
                .filter(|&i| pool.seen[i] == seen || s.splits.unseen_poses.is_none())
                .collect::<Vec<usize>>()
        });
        let plan = Self {
            seed: s.seed,
            garments,
            offsets,
            bodies: s.bodies.count,
            split_names,
            body_split,
            held_out,
            pool,
            eligible,
            shard_size: s.shard_size as u64,
        };
        plan.check_pool_sizes(file)?;
        Ok(plan)
    }

    fn check_pool_sizes(&self, file: &Path) -> Result<()> {
        for (g, garment) in self.garments.iter().enumerate() {
            for (split, name) in self.split_names.iter().enumerate() {
                let n = self.eligible[self.held_out[split] as usize].len();
                if (garment.poses_per_body as usize) > n {
                    return Err(DatasetError::spec(
                        file,
                        format!("garments[{g}].poses_per_body"),
                        format!(
                            "{} distinct poses per body, but split '{name}' can use only {n} of them; add pose sources or lower it",
                            garment.poses_per_body
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Number of samples.
    pub fn total(&self) -> u64 {
        *self.offsets.last().unwrap()
    }

    /// Number of shard files.
    pub fn shard_count(&self) -> u64 {
        self.total().div_ceil(self.shard_size)
    }

    /// The sample indices of shard `s`.
    pub fn shard_range(&self, s: u64) -> std::ops::Range<u64> {
        let start = s * self.shard_size;
        start..(start + self.shard_size).min(self.total())
    }

    /// The shard holding sample `k`.
    pub fn shard_of(&self, k: u64) -> u64 {
        k / self.shard_size
    }

    /// The shards, ascending, that hold at least one sample of a split in `splits` and a
    /// garment in `garments` (names; an empty list means any). An unknown name is an error
    /// listing the known ones.
    pub fn shards_holding(&self, splits: &[String], garments: &[String]) -> Result<Vec<u64>> {
        let known_splits: Vec<&str> = self.split_names.iter().map(String::as_str).collect();
        let known_garments: Vec<&str> = self.garments.iter().map(|g| g.name.as_str()).collect();
        let wanted = |names: &[String], known: &[&str], what: &str| -> Result<Vec<bool>> {
            DatasetError::check_known(what, names.iter().map(String::as_str), known)?;
            Ok(known
                .iter()
                .map(|k| names.is_empty() || names.iter().any(|n| n == k))
                .collect())
        };
        let split_ok = wanted(splits, &known_splits, "split")?;
        let garment_ok = wanted(garments, &known_garments, "garment")?;
        let mut shards = std::collections::BTreeSet::new();
        for (g, garment) in self.garments.iter().enumerate() {
            if !garment_ok[g] {
                continue;
            }
            let ppb = garment.poses_per_body as u64;
            for (b, &split) in self.body_split.iter().enumerate() {
                if split_ok[split] {
                    let first = self.offsets[g] + b as u64 * ppb;
                    shards.extend(self.shard_of(first)..=self.shard_of(first + ppb - 1));
                }
            }
        }
        Ok(shards.into_iter().collect())
    }

    /// Sample `k` (`k < total()`).
    pub fn sample(&self, k: u64) -> SampleDesc {
        assert!(k < self.total(), "sample {k} of {}", self.total());
        let garment = self.offsets.partition_point(|&o| o <= k) - 1;
        let ppb = self.garments[garment].poses_per_body as u64;
        let local = k - self.offsets[garment];
        let (body, slot) = ((local / ppb) as u32, (local % ppb) as u32);
        let split = self.body_split[body as usize];
        let eligible = &self.eligible[self.held_out[split] as usize];
        let mut rng = SplitMix64::new(derive(
            self.seed,
            Stream::Poses,
            &[garment as u64, body as u64],
        ));
        let chosen = rng.choose(eligible.len(), ppb as usize);
        SampleDesc {
            index: k,
            garment,
            body,
            slot,
            split,
            pose: eligible[chosen[slot as usize]],
        }
    }

    /// The body indices of split `split`, ascending.
    pub fn split_bodies(&self, split: usize) -> Vec<u32> {
        (0..self.bodies)
            .filter(|&b| self.body_split[b as usize] == split)
            .collect()
    }

    /// The seed body `b`'s shape is drawn from.
    pub fn body_seed(&self, b: u32) -> u64 {
        derive(self.seed, Stream::Body, &[b as u64])
    }
}
