//! `--shard i/n`: the shards one run of a job array makes.

use crate::error::{DatasetError, Result};

/// The shards `s` with `s % count == index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardSelection {
    /// This run's index, `< count`.
    pub index: u64,
    /// Number of runs.
    pub count: u64,
}

impl ShardSelection {
    /// Every shard.
    pub const ALL: Self = Self { index: 0, count: 1 };

    /// Parses `i/n` (0-based `i < n`).
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            DatasetError::Invalid(format!(
                "--shard '{text}' must be i/n with 0 <= i < n, e.g. 0/4"
            ))
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let s = Self {
            index: i.trim().parse().map_err(|_| bad())?,
            count: n.trim().parse().map_err(|_| bad())?,
        };
        s.check().map_err(|_| bad())?;
        Ok(s)
    }

    /// Errors unless `index < count`.
    pub fn check(&self) -> Result<()> {
        if self.index >= self.count {
            return Err(DatasetError::Invalid(format!(
                "shard selection {}/{} needs 0 <= i < n",
                self.index, self.count
            )));
        }
        Ok(())
    }

    /// Whether shard `s` is this run's.
    pub fn contains(&self, s: u64) -> bool {
        s % self.count == self.index
    }
}

impl std::fmt::Display for ShardSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_partitions() {
        let s = ShardSelection::parse("1/3").unwrap();
        assert_eq!((s.index, s.count), (1, 3));
        assert!(s.contains(4) && !s.contains(5));
        for bad in ["3/3", "1", "a/2", "1/0", "-1/2"] {
            assert!(ShardSelection::parse(bad).is_err(), "{bad}");
        }
        let all: Vec<u64> = (0..3)
            .flat_map(|i| {
                (0..10).filter(move |&s| ShardSelection { index: i, count: 3 }.contains(s))
            })
            .collect();
        assert_eq!(all.len(), 10);
    }
}
