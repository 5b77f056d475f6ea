//! How far a training epoch has gone: the running sums behind an epoch's report, kept in a
//! mid-epoch checkpoint so that an epoch longer than one sitting (49,500 batch-1 steps are
//! about 3.5 hours of one core) is finished across several.

use serde::{Deserialize, Serialize};

use crate::loss::LossTerms;
use crate::train::StepReport;

/// The running sums of an epoch that has trained `batches` batches so far.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EpochProgress {
    /// Batches taken from the epoch's order, empty ones included (the ones a resumed epoch
    /// skips).
    pub batches: usize,
    /// Optimiser steps taken (one per non-empty batch).
    pub steps: usize,
    /// Samples trained.
    pub samples: usize,
    /// Sum of the steps' loss terms, each weighted by its batch's sample count.
    pub terms_sum: LossTerms,
    /// Sum of the steps' gradient norms (before clipping).
    pub grad_norm_sum: f64,
    /// Wall time spent in the epoch's training so far, seconds (every sitting together).
    pub seconds: f64,
    /// The training set and order the batches were taken from (see
    /// [`crate::Trainer::set_training_set`]); a resumed epoch must go on in the same one.
    pub training_set: Option<String>,
}

impl EpochProgress {
    /// A fresh epoch over `training_set`.
    pub fn new(training_set: Option<String>) -> EpochProgress {
        EpochProgress {
            training_set,
            ..EpochProgress::default()
        }
    }

    /// Counts one step on a batch of `samples` samples.
    pub fn add(&mut self, report: &StepReport, samples: usize) {
        self.terms_sum = self.terms_sum + report.terms.scaled(samples as f32);
        self.samples += samples;
        self.batches += 1;
        self.steps += 1;
        self.grad_norm_sum += report.grad_norm as f64;
    }

    /// Counts an empty batch: taken from the order, no step.
    pub fn add_empty(&mut self) {
        self.batches += 1;
    }

    /// The loss terms averaged over the samples so far.
    pub fn mean_terms(&self) -> LossTerms {
        self.terms_sum.scaled(1.0 / self.samples.max(1) as f32)
    }

    /// The gradient norm averaged over the steps so far.
    pub fn mean_grad_norm(&self) -> f32 {
        (self.grad_norm_sum / self.steps.max(1) as f64) as f32
    }
}
