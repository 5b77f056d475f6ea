//! `--shard`: the shards one run makes, `i/n` (a job array's task) or a list of ranges.

use crate::error::{DatasetError, Result};

/// The shards a run makes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ShardSelection {
    /// The shards `s` with `s % count == index` (`--shard i/n`).
    Modulo {
        /// This run's index, `< count`.
        index: u64,
        /// Number of runs.
        count: u64,
    },
    /// The shards in any of these inclusive ranges (`--shard 0-9,12`).
    Ranges(Vec<(u64, u64)>),
}

impl ShardSelection {
    /// Every shard.
    pub const ALL: Self = Self::Modulo { index: 0, count: 1 };

    /// Parses `i/n` (0-based `i < n`) or a comma-separated list of shard indices and
    /// inclusive ranges `a-b`.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            DatasetError::Invalid(format!(
                "--shard '{text}' must be i/n with 0 <= i < n (e.g. 0/4), or shard ranges a-b with a <= b and single shards, comma-separated (e.g. 0-9,12)"
            ))
        };
        let num = |t: &str| t.trim().parse::<u64>().map_err(|_| bad());
        let s = match text.split_once('/') {
            Some((i, n)) => Self::Modulo {
                index: num(i)?,
                count: num(n)?,
            },
            None => Self::Ranges(
                text.split(',')
                    .map(|r| match r.split_once('-') {
                        Some((a, b)) => Ok((num(a)?, num(b)?)),
                        None => num(r).map(|a| (a, a)),
                    })
                    .collect::<Result<_>>()?,
            ),
        };
        s.check().map_err(|_| bad())?;
        Ok(s)
    }

    /// Errors unless `index < count`, or every range has `a <= b`.
    pub fn check(&self) -> Result<()> {
        let ok = match self {
            Self::Modulo { index, count } => index < count,
            Self::Ranges(r) => !r.is_empty() && r.iter().all(|(a, b)| a <= b),
        };
        if !ok {
            return Err(DatasetError::Invalid(format!(
                "shard selection {self} selects nothing: it needs 0 <= i < n, or ranges a-b with a <= b"
            )));
        }
        Ok(())
    }

    /// Whether shard `s` is this run's.
    pub fn contains(&self, s: u64) -> bool {
        match self {
            Self::Modulo { index, count } => s % count == *index,
            Self::Ranges(r) => r.iter().any(|(a, b)| (*a..=*b).contains(&s)),
        }
    }
}

impl std::fmt::Display for ShardSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Modulo { index, count } => write!(f, "{index}/{count}"),
            Self::Ranges(r) => {
                let parts: Vec<String> = r
                    .iter()
                    .map(|(a, b)| {
                        if a == b {
                            a.to_string()
                        } else {
                            format!("{a}-{b}")
                        }
                    })
                    .collect();
                write!(f, "{}", parts.join(","))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_partitions() {
        let s = ShardSelection::parse("1/3").unwrap();
        assert_eq!(s, ShardSelection::Modulo { index: 1, count: 3 });
        assert!(s.contains(4) && !s.contains(5));
        for bad in ["3/3", "a/2", "1/0", "-1/2", "4-2", "1,,2", "", "x-3"] {
            assert!(ShardSelection::parse(bad).is_err(), "{bad}");
        }
        let all: Vec<u64> = (0..3)
            .flat_map(|i| {
                (0..10).filter(move |&s| ShardSelection::Modulo { index: i, count: 3 }.contains(s))
            })
            .collect();
        assert_eq!(all.len(), 10);
    }

    #[test]
    fn parses_ranges() {
        let s = ShardSelection::parse("2-4, 9").unwrap();
        assert_eq!(s, ShardSelection::Ranges(vec![(2, 4), (9, 9)]));
        let picked: Vec<u64> = (0..12).filter(|&k| s.contains(k)).collect();
        assert_eq!(picked, [2, 3, 4, 9]);
        assert_eq!(s.to_string(), "2-4,9");
        assert_eq!(ShardSelection::parse("1").unwrap().to_string(), "1");
    }
}
