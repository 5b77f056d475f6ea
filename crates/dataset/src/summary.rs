//! A summary of a dataset for people: counts per split and garment, simulator statistics
//! and failures.

use std::collections::BTreeMap;
use std::fmt::Write;

use serde::Serialize;
use sim::stats::percentile;

use crate::manifest::Manifest;

/// Percentiles of one quantity.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Spread {
    /// Median.
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Largest value.
    pub max: f64,
    /// Mean.
    pub mean: f64,
}

impl Spread {
    /// The spread of `values` (zeros for none).
    pub fn of(values: &[f64]) -> Self {
        if values.is_empty() {
            return Self::default();
        }
        let v: Vec<f32> = values.iter().map(|&x| x as f32).collect();
        let p = |q| percentile(&v, q) as f64;
        Self {
            p50: p(0.5),
            p90: p(0.9),
            p99: p(0.99),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            mean: values.iter().sum::<f64>() / values.len() as f64,
        }
    }
}

/// Counts and statistics of a dataset.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// Dataset name.
    pub name: String,
    /// Samples of the whole dataset.
    pub total_samples: u64,
    /// Shards present / of the dataset.
    pub shards: (u64, u64),
    /// Bytes of the shards present.
    pub shard_bytes: u64,
    /// (split, garment) -> stored samples.
    pub stored: BTreeMap<String, BTreeMap<String, u64>>,
    /// (split, garment) -> failed samples.
    pub failed: BTreeMap<String, BTreeMap<String, u64>>,
    /// Bodies per split.
    pub bodies: BTreeMap<String, usize>,
    /// Drape wall time, seconds (samples with known timing).
    pub drape_time_s: Spread,
    /// Whole-sample wall time, seconds.
    pub sample_time_s: Spread,
    /// Total steps per drape.
    pub steps: Spread,
    /// Share of stored drapes that came to rest.
    pub converged_share: f64,
    /// Max penetration per drape, mm.
    pub max_penetration_mm: Spread,
    /// Edge strain p99 per drape, percent.
    pub strain_p99_pct: Spread,
    /// Largest edge strain per drape, percent.
    pub strain_max_pct: Spread,
    /// How far each garment slid on the body per drape, cm.
    pub slid_cm: Spread,
    /// Failures: (sample index, garment, reason).
    pub failures: Vec<(u64, String, String)>,
}

impl Summary {
    /// Summarises `m`.
    pub fn of(m: &Manifest) -> Self {
        let mut s = Summary {
            name: m.spec.name.clone(),
            total_samples: m.total_samples,
            shards: (m.shards.len() as u64, m.shard_count),
            shard_bytes: m.shards.iter().map(|e| e.bytes).sum(),
            bodies: m.splits.iter().map(|(k, v)| (k.clone(), v.len())).collect(),
            ..Default::default()
        };
        for e in &m.samples {
            *s.stored
                .entry(e.record.split.clone())
                .or_default()
                .entry(e.record.garment.clone())
                .or_default() += 1;
        }
        for f in &m.failures {
            *s.failed
                .entry(f.record.split.clone())
                .or_default()
                .entry(f.record.garment.clone())
                .or_default() += 1;
            s.failures.push((
                f.record.index,
                f.record.garment.clone(),
                f.record.reason.clone(),
            ));
        }
        let stats: Vec<_> = m.samples.iter().map(|e| &e.record.stats).collect();
        let col = |f: &dyn Fn(&crate::records::SimStats) -> f64| -> Spread {
            Spread::of(&stats.iter().map(|s| f(s)).collect::<Vec<_>>())
        };
        s.steps = col(&|x| (x.animation_steps + x.settle_steps) as f64);
        s.max_penetration_mm = col(&|x| x.max_penetration_m as f64 * 1e3);
        s.strain_p99_pct = col(&|x| x.strain_p99 as f64 * 100.0);
        s.strain_max_pct = col(&|x| x.strain_max as f64 * 100.0);
        s.slid_cm = col(&|x| x.slid_m as f64 * 100.0);
        s.converged_share =
            stats.iter().filter(|x| x.converged).count() as f64 / stats.len().max(1) as f64;
        let times: Vec<_> = m.samples.iter().filter_map(|e| e.timing).collect();
        s.drape_time_s = Spread::of(&times.iter().map(|t| t.drape_s).collect::<Vec<_>>());
        s.sample_time_s = Spread::of(&times.iter().map(|t| t.sample_s).collect::<Vec<_>>());
        s
    }

    /// The summary as text for a terminal.
    pub fn report(&self) -> String {
        let mut o = String::new();
        let stored: u64 = self.stored.values().flat_map(|g| g.values()).sum();
        let failed: u64 = self.failed.values().flat_map(|g| g.values()).sum();
        let _ = writeln!(
            o,
            "dataset '{}': {} of {} samples stored, {} failed; shards {} of {} ({:.1} MB)",
            self.name,
            stored,
            self.total_samples,
            failed,
            self.shards.0,
            self.shards.1,
            self.shard_bytes as f64 / 1e6
        );
        let garments: std::collections::BTreeSet<&String> = self
            .stored
            .values()
            .chain(self.failed.values())
            .flat_map(|g| g.keys())
            .collect();
        let _ = write!(o, "\n{:<10} {:>7}", "split", "bodies");
        for g in &garments {
            let _ = write!(o, " {:>16}", format!("{g} ok/failed"));
        }
        o.push('\n');
        for (split, bodies) in &self.bodies {
            let _ = write!(o, "{split:<10} {bodies:>7}");
            for g in &garments {
                let get = |m: &BTreeMap<String, BTreeMap<String, u64>>| {
                    m.get(split).and_then(|x| x.get(*g)).copied().unwrap_or(0)
                };
                let cell = format!("{}/{}", get(&self.stored), get(&self.failed));
                let _ = write!(o, " {cell:>16}");
            }
            o.push('\n');
        }
        let row = |o: &mut String, name: &str, s: &Spread, unit: &str| {
            let _ = writeln!(
                o,
                "  {name:<22} p50 {:>8.2}  p90 {:>8.2}  p99 {:>8.2}  max {:>8.2}  mean {:>8.2} {unit}",
                s.p50, s.p90, s.p99, s.max, s.mean
            );
        };
        let _ = writeln!(o, "\nsimulator (stored samples):");
        row(&mut o, "drape time", &self.drape_time_s, "s");
        row(&mut o, "sample time", &self.sample_time_s, "s");
        row(&mut o, "steps", &self.steps, "");
        row(&mut o, "max penetration", &self.max_penetration_mm, "mm");
        row(&mut o, "strain p99", &self.strain_p99_pct, "%");
        row(&mut o, "strain max", &self.strain_max_pct, "%");
        row(&mut o, "slid", &self.slid_cm, "cm");
        let _ = writeln!(
            o,
            "  at rest: {:.1}% of drapes",
            self.converged_share * 100.0
        );
        if !self.failures.is_empty() {
            let _ = writeln!(o, "\nfailures:");
            for (k, g, reason) in self.failures.iter().take(50) {
                let _ = writeln!(o, "  sample {k} ({g}): {reason}");
            }
            if self.failures.len() > 50 {
                let _ = writeln!(o, "  ... and {} more", self.failures.len() - 50);
            }
        }
        o
    }
}
