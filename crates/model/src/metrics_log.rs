//! The per-epoch training log, a CSV file with one header line and one row per epoch:
//!
//! ```text
//! epoch,step,lr,seconds,train_samples,train_total,train_vertex,train_pen,train_norm,
//! train_bend,val_samples,val_total,val_vertex,val_pen,val_norm,val_bend,val_e_dist_cm,
//! val_e_norm_deg,best,train_grad_norm,train_cpu_s,train_curvature,val_curvature
//! ```
//!
//! Loss terms in the loss's units (vertex cm^2, or cm with `VertexLoss::Distance`; pen and
//! bend and curvature cm, curvature 0 when unweighted; norm none, or cm as a tilt);
//! the `val_*` fields are empty for an epoch without validation; `best` is 1 when the epoch
//! wrote `best.garnet`; `train_grad_norm` is the epoch's mean joint gradient norm before
//! clipping; `train_cpu_s` the CPU time the run's training steps have
//! used so far, seconds (what a compute budget counts). Appending a row drops any rows of that epoch or later (a resumed run rewrites
//! the epochs after its checkpoint). A log whose header is not [`HEADER`] is refused. The file is rewritten atomically (temporary file, rename).

use std::path::PathBuf;

use crate::error::{ModelError, Result};
use crate::loss::LossTerms;
use crate::trainer::Validation;

/// The CSV header line.
pub const HEADER: &str = "epoch,step,lr,seconds,train_samples,train_total,train_vertex,\
train_pen,train_norm,train_bend,val_samples,val_total,val_vertex,val_pen,val_norm,val_bend,\
val_e_dist_cm,val_e_norm_deg,best,train_grad_norm,train_cpu_s,train_curvature,val_curvature";

/// One epoch's row.
#[derive(Clone, Debug, PartialEq)]
pub struct MetricsRow {
    /// Epochs completed.
    pub epoch: usize,
    /// Optimiser steps taken.
    pub step: u64,
    /// Learning rate.
    pub lr: f64,
    /// Epoch wall time, seconds.
    pub seconds: f64,
    /// Mean training loss terms.
    pub train: LossTerms,
    /// Training samples seen.
    pub train_samples: usize,
    /// Mean joint gradient norm before clipping.
    pub grad_norm: f32,
    /// Validation results.
    pub validation: Option<Validation>,
    /// Whether the epoch wrote the best checkpoint.
    pub is_best: bool,
    /// CPU time of the run's training steps so far, seconds.
    pub train_cpu_s: f64,
}

impl MetricsRow {
    /// The CSV line (no newline).
    pub fn to_csv(&self) -> String {
        let t = &self.train;
        let mut s = format!(
            "{},{},{},{:.3},{},{},{},{},{},{},",
            self.epoch,
            self.step,
            self.lr,
            self.seconds,
            self.train_samples,
            t.total,
            t.vertex,
            t.pen,
            t.norm,
            t.bend
        );
        match &self.validation {
            Some(v) => s.push_str(&format!(
                "{},{},{},{},{},{},{},{},",
                v.samples,
                v.terms.total,
                v.terms.vertex,
                v.terms.pen,
                v.terms.norm,
                v.terms.bend,
                v.e_dist_cm,
                v.e_norm_deg
            )),
            None => s.push_str(",,,,,,,,"),
        }
        s.push_str(if self.is_best { "1," } else { "0," });
        s.push_str(&format!(
            "{},{:.1},{},",
            self.grad_norm, self.train_cpu_s, t.curvature
        ));
        if let Some(v) = &self.validation {
            s.push_str(&format!("{}", v.terms.curvature));
        }
        s
    }
}

/// A metrics CSV file.
#[derive(Clone, Debug)]
pub struct MetricsLog {
    path: PathBuf,
}

impl MetricsLog {
    /// The log at `path` (created by the first append).
    pub fn new(path: PathBuf) -> Self {
        MetricsLog { path }
    }

    /// Appends `row`, dropping existing rows of epoch `row.epoch` or later.
    pub fn append(&self, row: &MetricsRow) -> Result<()> {
        let old = match std::fs::read_to_string(&self.path) {
            Ok(s) => s,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) => {
                return Err(ModelError::Io {
                    path: self.path.clone(),
                    source: e,
                })
            }
        };
        let mut lines = old.lines();
        if let Some(header) = lines.next().filter(|h| *h != HEADER) {
            return Err(ModelError::InvalidInput(format!(
                "{}: not a metrics log of this version (header {header:?}); move it away",
                self.path.display()
            )));
        }
        let mut out = String::from(HEADER);
        out.push('\n');
        for line in lines {
            let epoch: Option<usize> = line.split(',').next().and_then(|e| e.parse().ok());
            if epoch.is_some_and(|e| e < row.epoch) {
                out.push_str(line);
                out.push('\n');
            }
        }
        out.push_str(&row.to_csv());
        out.push('\n');
        geom::io::write_bytes_atomic(&self.path, out.as_bytes())?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(epoch: usize, val: bool) -> MetricsRow {
        MetricsRow {
            epoch,
            step: epoch as u64 * 10,
            lr: 1e-3,
            seconds: 1.5,
            train: LossTerms {
                total: 0.5,
                vertex: 0.25,
                pen: 0.0,
                norm: 0.1,
                bend: 0.2,
                curvature: 0.05,
            },
            train_samples: 8,
            grad_norm: 2.5,
            validation: val.then_some(Validation {
                terms: LossTerms::default(),
                e_dist_cm: 1.25,
                e_norm_deg: 9.5,
                samples: 2,
            }),
            is_best: val,
            train_cpu_s: 12.34,
        }
    }

    #[test]
    fn appends_rows_and_rewrites_later_epochs() {
        let dir = tempfile::tempdir().unwrap();
        let log = MetricsLog::new(dir.path().join("m.csv"));
        log.append(&row(1, true)).unwrap();
        log.append(&row(2, false)).unwrap();
        log.append(&row(3, true)).unwrap();
        // A run resumed after epoch 1 rewrites epochs 2 and 3.
        log.append(&row(2, true)).unwrap();
        let text = std::fs::read_to_string(dir.path().join("m.csv")).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], HEADER);
        assert_eq!(lines.len(), 3);
        let cols = HEADER.split(',').count();
        assert!(lines.iter().all(|l| l.split(',').count() == cols));
        assert!(lines[1].starts_with("1,10,0.001,1.500,8,0.5,0.25,0,0.1,0.2,2,"));
        assert!(lines[2].starts_with("2,20,"));
        assert!(lines[2].ends_with(",1.25,9.5,1,2.5,12.3,0.05,0"));
        assert!(row(4, false).to_csv().ends_with(",,,,,,,,0,2.5,12.3,0.05,"));
    }

    #[test]
    fn a_log_with_another_header_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.csv");
        std::fs::write(&path, "epoch,step\n1,10\n").unwrap();
        let err = MetricsLog::new(path.clone()).append(&row(2, true));
        assert!(err.unwrap_err().to_string().contains("m.csv"));
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "epoch,step\n1,10\n"
        );
    }
}
