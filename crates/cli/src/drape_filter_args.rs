//! `--at-rest` and `--max-strain PCT`: which drapes of a dataset `train` and `eval` use.

use anyhow::{bail, Context};
use clap::{Args, Parser};
use dataset::{Dataset, DrapeFilter};

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
    /// statistics; drapes made before it was recorded are kept).
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

/// The command-line flags that give `filter`, each after a space (" --at-rest --max-strain 5");
/// `""` for no filter (every drape).
pub fn filter_flags(filter: Option<&DrapeFilter>) -> String {
    let mut flags = String::new();
    let Some(filter) = filter else {
        return flags;
    };
    if filter.at_rest {
        flags += " --at-rest";
    }
    if let Some(m) = filter.max_strain_p99 {
        flags += &format!(" --max-strain {}", m * 100.0);
    }
    if let Some(m) = filter.max_slid_m {
        flags += &format!(" --max-slide {}", m * 100.0);
    }
    flags
}

/// The filter whose flags [`filter_flags`] wrote as `flags` (`None` for `""`: every
/// drape); errors, quoting them, on flags it does not take.
pub fn parse_filter_flags(flags: &str) -> anyhow::Result<Option<DrapeFilter>> {
    /// The filter's flags alone on a command line.
    #[derive(Parser)]
    struct FilterLine {
        #[command(flatten)]
        drapes: DrapeFilterArgs,
    }
    let line =
        FilterLine::try_parse_from(std::iter::once("filter").chain(flags.split_whitespace()))
            .with_context(|| format!("reading the drape filter flags '{flags}'"))?;
    line.drapes.filter()
}

/// Keeps in `indices` (the `garment` samples of `split` in `data`) only the drapes `filter`
/// passes; returns how many were dropped. Errors, naming the dataset and the filter, when
/// none is left.
pub fn keep_drapes(
    data: &Dataset,
    split: &str,
    garment: &str,
    indices: &mut Vec<u64>,
    filter: &DrapeFilter,
) -> anyhow::Result<usize> {
    let before = indices.len();
    let dropped = data.retain_drapes(indices, filter);
    if indices.is_empty() {
        bail!(
            "{}: no '{garment}' sample of split '{split}' is one of the {} (none of the {before} \
             samples is; --at-rest, --max-strain, --max-slide)",
            data.dir().display(),
            filter.describe()
        );
    }
    Ok(dropped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_give_back_the_filter() {
        let args = DrapeFilterArgs {
            at_rest: true,
            max_strain: Some(5.0),
            max_slide: Some(10.0),
        };
        let f = args.filter().unwrap().unwrap();
        assert_eq!(
            filter_flags(Some(&f)),
            " --at-rest --max-strain 5 --max-slide 10"
        );
        assert_eq!(DrapeFilterArgs::default().filter().unwrap(), None);
        // And back again.
        assert_eq!(
            parse_filter_flags(&filter_flags(Some(&f))).unwrap(),
            Some(f)
        );
        assert_eq!(parse_filter_flags("").unwrap(), None);
        let err = parse_filter_flags(" --max-strain 5 --seed 3").unwrap_err();
        assert!(
            format!("{err:#}").contains("' --max-strain 5 --seed 3'"),
            "{err:#}"
        );
    }
}
