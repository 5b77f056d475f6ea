//! `--at-rest`, `--max-strain PCT` and `--max-slide CM`: which drapes of a dataset `garnet
//! eval` uses (a training recipe names its own in `[drapes]`).

use anyhow::bail;
use clap::Args;
use dataset::DrapeFilter;

/// Leave poor labels out: drapes that never came to rest, whose garment was stretched far
/// beyond what cloth does (caught on a body part in an extreme pose), or slid down the body.
#[derive(Args, Debug, Clone, Default)]
pub struct DrapeFilterArgs {
    /// Use only drapes that came to rest within the simulator's step budget.
    #[arg(long)]
    pub at_rest: bool,
    /// Use only drapes whose strain p99 (simulator statistics) is at most this, percent.
    #[arg(long, value_name = "PCT")]
    pub max_strain: Option<f32>,
    /// Use only drapes whose garment slid at most this far on the body, cm (simulator
    /// statistics).
    #[arg(long, value_name = "CM")]
    pub max_slide: Option<f32>,
}

impl DrapeFilterArgs {
    /// The filter, `None` when neither flag is given; errors on a negative or non-finite
    /// percentage.
    pub fn filter(&self) -> anyhow::Result<Option<DrapeFilter>> {
        if let Some(m) = self.max_strain.filter(|m| !(m.is_finite() && *m >= 0.0)) {
            bail!("--max-strain must be a non-negative percentage, got {m}");
        }
        if let Some(m) = self.max_slide.filter(|m| !(m.is_finite() && *m >= 0.0)) {
            bail!("--max-slide must be a non-negative distance in cm, got {m}");
        }
        let any = self.at_rest || self.max_strain.is_some() || self.max_slide.is_some();
        Ok(any.then_some(DrapeFilter {
            at_rest: self.at_rest,
            max_strain_p99: self.max_strain.map(|m| m / 100.0),
            max_slid_m: self.max_slide.map(|m| m / 100.0),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_give_the_filter_and_bad_values_are_refused() {
        let args = DrapeFilterArgs {
            at_rest: true,
            max_strain: Some(5.0),
            max_slide: Some(10.0),
        };
        let f = args.filter().unwrap().unwrap();
        assert!(f.at_rest);
        assert_eq!((f.max_strain_p99, f.max_slid_m), (Some(0.05), Some(0.1)));
        assert_eq!(DrapeFilterArgs::default().filter().unwrap(), None);
        let bad = DrapeFilterArgs {
            max_strain: Some(-1.0),
            ..DrapeFilterArgs::default()
        };
        assert!(bad.filter().is_err());
    }
}
