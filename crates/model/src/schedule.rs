//! Learning-rate schedules over epochs.

use serde::{Deserialize, Serialize};

use crate::error::{ModelError, Result};

/// Cosine annealing: the learning rate falls from `start_lr` at epoch `from_epoch` to
/// `end_lr` at epoch `to_epoch` along half a cosine, and stays at `end_lr` after. Epochs are
/// counted as completed epochs (the rate of the epoch that starts after `e` are done).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CosineSchedule {
    /// Learning rate at `from_epoch`.
    pub start_lr: f64,
    /// Learning rate at `to_epoch` and after.
    pub end_lr: f64,
    /// Epoch the schedule starts at.
    pub from_epoch: usize,
    /// Epoch the schedule ends at (> `from_epoch`).
    pub to_epoch: usize,
}

impl CosineSchedule {
    /// A schedule; fails when a rate is not a positive number or the epochs do not increase.
    pub fn new(start_lr: f64, end_lr: f64, from_epoch: usize, to_epoch: usize) -> Result<Self> {
        let rate_ok = |r: f64| r.is_finite() && r > 0.0;
        if !rate_ok(start_lr) || !rate_ok(end_lr) {
            return Err(ModelError::InvalidInput(format!(
                "learning rates must be > 0, got {start_lr} and {end_lr}"
            )));
        }
        if to_epoch <= from_epoch {
            return Err(ModelError::InvalidInput(format!(
                "the schedule must end after it starts (epochs {from_epoch} to {to_epoch})"
            )));
        }
        Ok(CosineSchedule {
            start_lr,
            end_lr,
            from_epoch,
            to_epoch,
        })
    }

    /// The learning rate of the epoch that starts after `epoch` epochs are completed.
    pub fn lr(&self, epoch: usize) -> f64 {
        let span = (self.to_epoch - self.from_epoch) as f64;
        let t = (epoch.saturating_sub(self.from_epoch) as f64 / span).min(1.0);
        self.end_lr + (self.start_lr - self.end_lr) * 0.5 * (1.0 + (std::f64::consts::PI * t).cos())
    }

    /// Whether `self` and `other` fall between the same rates and end at the same epoch (a
    /// resumed run with the same command keeps its schedule's start).
    pub fn same_plan(&self, other: &CosineSchedule) -> bool {
        self.start_lr == other.start_lr
            && self.end_lr == other.end_lr
            && self.to_epoch == other.to_epoch
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falls_along_half_a_cosine_and_stays_at_the_end() {
        let s = CosineSchedule::new(1e-3, 1e-5, 10, 20).unwrap();
        assert_eq!(s.lr(0), 1e-3);
        assert_eq!(s.lr(10), 1e-3);
        assert!((s.lr(15) - (1e-5 + 0.5 * (1e-3 - 1e-5))).abs() < 1e-12);
        assert!((s.lr(20) - 1e-5).abs() < 1e-15);
        assert!((s.lr(50) - 1e-5).abs() < 1e-15);
        let rates: Vec<f64> = (10..=20).map(|e| s.lr(e)).collect();
        assert!(rates.windows(2).all(|w| w[1] < w[0]));
    }

    #[test]
    fn refuses_bad_rates_and_epochs() {
        assert!(CosineSchedule::new(0.0, 1e-5, 0, 10).is_err());
        assert!(CosineSchedule::new(1e-3, f64::NAN, 0, 10).is_err());
        assert!(CosineSchedule::new(1e-3, 1e-5, 10, 10).is_err());
    }
}
