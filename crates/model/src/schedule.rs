//! Learning-rate schedules: over epochs ([`CosineSchedule`]) or over a compute budget
//! ([`TimeBudget`]).

use serde::{Deserialize, Serialize};

use crate::error::{ModelError, Result};

/// Cosine annealing: the learning rate falls from `start_lr` at epoch `from_epoch` to
/// `end_lr` at epoch `to_epoch` along half a cosine, and stays at `end_lr` after. Epochs are
/// counted as completed epochs (the rate of the epoch that starts after `e` are done). The
/// rate changes once an epoch, or at every step when `steps_per_epoch` is set, so that a
/// schedule of a few long epochs ends at `end_lr` instead of a rung above it.
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
    /// Steps in one epoch, when the rate follows the cosine step by step (`None`: epoch by
    /// epoch).
    pub steps_per_epoch: Option<u64>,
}

impl CosineSchedule {
    /// A schedule; fails when a rate is not a positive number or the epochs do not increase.
    pub fn new(start_lr: f64, end_lr: f64, from_epoch: usize, to_epoch: usize) -> Result<Self> {
        check_rates(start_lr, end_lr)?;
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
            steps_per_epoch: None,
        })
    }

    /// The same schedule followed step by step, an epoch being `steps` steps (at least 1).
    pub fn per_step(self, steps: u64) -> Self {
        CosineSchedule {
            steps_per_epoch: Some(steps.max(1)),
            ..self
        }
    }

    /// The learning rate of the epoch that starts after `epoch` epochs are completed.
    pub fn lr(&self, epoch: usize) -> f64 {
        self.lr_at(epoch as f64)
    }

    /// The learning rate of step `step` (0-based, counting every batch) of the epoch that
    /// starts after `epoch` epochs: [`CosineSchedule::lr`] of that epoch unless the schedule
    /// goes step by step, then the cosine at the fractional epoch `epoch + step / steps`.
    pub fn lr_of_step(&self, epoch: usize, step: usize) -> f64 {
        match self.steps_per_epoch {
            Some(n) => self.lr_at(epoch as f64 + step as f64 / n as f64),
            None => self.lr(epoch),
        }
    }

    /// The cosine at `position` (completed epochs, fractional).
    fn lr_at(&self, position: f64) -> f64 {
        let span = (self.to_epoch - self.from_epoch) as f64;
        let t = ((position - self.from_epoch as f64).max(0.0) / span).min(1.0);
        self.end_lr + (self.start_lr - self.end_lr) * 0.5 * (1.0 + (std::f64::consts::PI * t).cos())
    }

    /// Whether `self` and `other` fall between the same rates and end at the same epoch (a
    /// resumed run with the same command keeps its schedule's start).
    pub fn same_plan(&self, other: &CosineSchedule) -> bool {
        self.start_lr == other.start_lr
            && self.end_lr == other.end_lr
            && self.to_epoch == other.to_epoch
            && self.steps_per_epoch == other.steps_per_epoch
    }
}

/// A fixed compute budget: training stops once its steps have used `minutes` of CPU time
/// (of every thread of the process, so a run on one thread gets `minutes` of one core), and
/// the learning rate follows the budget: `start_lr` for `warmup_minutes`, then half a cosine
/// to `end_lr` at the budget's end. Validation and checkpoints do not count. Two designs
/// compared on the same budget have had the same compute, whatever their step cost.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimeBudget {
    /// The budget, CPU minutes (> 0).
    pub minutes: f64,
    /// CPU minutes at `start_lr` before the cosine starts (>= 0, < `minutes`).
    pub warmup_minutes: f64,
    /// Learning rate at the start.
    pub start_lr: f64,
    /// Learning rate at the budget's end (equal to `start_lr`: a constant rate).
    pub end_lr: f64,
}

impl TimeBudget {
    /// A budget; fails when a rate is not a positive number or the minutes are out of range.
    pub fn new(minutes: f64, warmup_minutes: f64, start_lr: f64, end_lr: f64) -> Result<Self> {
        check_rates(start_lr, end_lr)?;
        if !(minutes.is_finite() && minutes > 0.0) {
            return Err(ModelError::InvalidInput(format!(
                "the budget must be > 0 minutes, got {minutes}"
            )));
        }
        if !(warmup_minutes.is_finite() && (0.0..minutes).contains(&warmup_minutes)) {
            return Err(ModelError::InvalidInput(format!(
                "the warm-up must be >= 0 and under the budget ({minutes} minutes), got \
                 {warmup_minutes}"
            )));
        }
        Ok(TimeBudget {
            minutes,
            warmup_minutes,
            start_lr,
            end_lr,
        })
    }

    /// The learning rate after `cpu_s` seconds of training.
    pub fn lr(&self, cpu_s: f64) -> f64 {
        let (warm, all) = (self.warmup_minutes * 60.0, self.minutes * 60.0);
        let t = ((cpu_s - warm).max(0.0) / (all - warm)).min(1.0);
        self.end_lr + (self.start_lr - self.end_lr) * 0.5 * (1.0 + (std::f64::consts::PI * t).cos())
    }

    /// Whether `cpu_s` seconds of training have used the budget.
    pub fn spent(&self, cpu_s: f64) -> bool {
        cpu_s >= self.minutes * 60.0
    }
}

/// Fails unless both learning rates are positive numbers.
fn check_rates(start_lr: f64, end_lr: f64) -> Result<()> {
    let rate_ok = |r: f64| r.is_finite() && r > 0.0;
    if !rate_ok(start_lr) || !rate_ok(end_lr) {
        return Err(ModelError::InvalidInput(format!(
            "learning rates must be > 0, got {start_lr} and {end_lr}"
        )));
    }
    Ok(())
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
    fn per_step_follows_the_cosine_inside_each_epoch() {
        let epochs = CosineSchedule::new(3e-4, 1e-5, 1, 4).unwrap();
        let steps = epochs.per_step(1000);
        // At each epoch's first step both give the epoch's rate.
        for e in 0..6 {
            assert_eq!(steps.lr_of_step(e, 0), epochs.lr(e));
            assert_eq!(epochs.lr_of_step(e, 500), epochs.lr(e));
        }
        // Inside an epoch the per-step rate falls between the rungs ...
        let mid = steps.lr_of_step(2, 500);
        assert!(mid < epochs.lr(2) && mid > epochs.lr(3));
        let direct = 1e-5 + (3e-4 - 1e-5) * 0.5 * (1.0 + (std::f64::consts::PI * 0.5).cos());
        assert!((mid - direct).abs() < 1e-15);
        // ... and the last epoch's last step is at the end rate, not a rung above it.
        assert!(epochs.lr(3) > 5e-5);
        assert!((steps.lr_of_step(3, 999) - 1e-5).abs() < 1e-9);
        assert!(!steps.same_plan(&epochs));
    }

    #[test]
    fn a_checkpoint_without_steps_per_epoch_reads_as_epoch_by_epoch() {
        let old = r#"{"start_lr":0.001,"end_lr":1e-5,"from_epoch":0,"to_epoch":3}"#;
        let s: CosineSchedule = serde_json::from_str(old).unwrap();
        assert_eq!(s, CosineSchedule::new(1e-3, 1e-5, 0, 3).unwrap());
    }

    #[test]
    fn refuses_bad_rates_and_epochs() {
        assert!(CosineSchedule::new(0.0, 1e-5, 0, 10).is_err());
        assert!(CosineSchedule::new(1e-3, f64::NAN, 0, 10).is_err());
        assert!(CosineSchedule::new(1e-3, 1e-5, 10, 10).is_err());
    }

    #[test]
    fn a_budget_holds_then_falls_along_the_cosine_and_ends() {
        let b = TimeBudget::new(10.0, 2.0, 1e-3, 1e-5).unwrap();
        assert_eq!(b.lr(0.0), 1e-3);
        assert_eq!(b.lr(120.0), 1e-3);
        assert!((b.lr(360.0) - (1e-5 + 0.5 * (1e-3 - 1e-5))).abs() < 1e-12);
        assert!((b.lr(600.0) - 1e-5).abs() < 1e-15);
        assert!((b.lr(900.0) - 1e-5).abs() < 1e-15);
        assert!(!b.spent(599.9) && b.spent(600.0));
        let flat = TimeBudget::new(10.0, 0.0, 3e-4, 3e-4).unwrap();
        assert_eq!(flat.lr(300.0), 3e-4);
    }

    #[test]
    fn refuses_bad_budgets() {
        assert!(TimeBudget::new(0.0, 0.0, 1e-3, 1e-5).is_err());
        assert!(TimeBudget::new(f64::NAN, 0.0, 1e-3, 1e-5).is_err());
        assert!(TimeBudget::new(10.0, 10.0, 1e-3, 1e-5).is_err());
        assert!(TimeBudget::new(10.0, -1.0, 1e-3, 1e-5).is_err());
        assert!(TimeBudget::new(10.0, 1.0, 0.0, 1e-5).is_err());
    }
}
