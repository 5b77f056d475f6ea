//! Progress as plain lines for a log file: what a long job started under `nohup` or a batch
//! system prints instead of a progress bar, which needs a terminal.

use std::time::{Duration, Instant};

/// How often the long commands (dataset generation, training) write a progress line when
/// they have no terminal.
pub const LOG_EVERY: Duration = Duration::from_secs(300);

/// Throttled progress lines: at most one per `every`, with the rate and the time left
/// counted from the first report of this run.
pub struct LogLines {
    every: Duration,
    /// What is counted ("samples", "batches").
    noun: &'static str,
    /// Time and count of the first report.
    first: Option<(Instant, u64)>,
    /// Time of the last line given.
    last: Option<Instant>,
}

impl LogLines {
    /// Lines about `noun` ("samples") at most once per `every`.
    pub fn new(every: Duration, noun: &'static str) -> LogLines {
        LogLines {
            every,
            noun,
            first: None,
            last: None,
        }
    }

    /// The line for `done` of `total` items at `now`, or `None` when the last line is
    /// younger than `every` (the first report only starts the clock), e.g.
    /// `1200/4500 samples (27%); 41.2 a minute this run; about 1h20m left`.
    pub fn line(&mut self, now: Instant, done: u64, total: u64) -> Option<String> {
        let Some((t0, done0)) = self.first else {
            self.first = Some((now, done));
            self.last = Some(now);
            return None;
        };
        if self
            .last
            .is_some_and(|t| now.duration_since(t) < self.every)
        {
            return None;
        }
        self.last = Some(now);
        let minutes = now.duration_since(t0).as_secs_f64() / 60.0;
        let per_minute = done.saturating_sub(done0) as f64 / minutes.max(1e-9);
        let left = match per_minute > 0.0 {
            true => format!(
                "about {} left",
                hours_minutes(total.saturating_sub(done) as f64 / per_minute)
            ),
            false => "none made yet this run".into(),
        };
        let share = 100.0 * done as f64 / total.max(1) as f64;
        Some(format!(
            "{done}/{total} {} ({share:.0}%); {per_minute:.1} a minute this run; {left}",
            self.noun
        ))
    }
}

/// `minutes` as `1h20m` or `35m`, rounded to the minute.
fn hours_minutes(minutes: f64) -> String {
    let m = minutes.round() as u64;
    match m / 60 {
        0 => format!("{m}m"),
        h => format!("{h}h{:02}m", m % 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_per_period_with_the_rate_of_this_run() {
        let t0 = Instant::now();
        let at = |s: u64| t0 + Duration::from_secs(s);
        let mut log = LogLines::new(Duration::from_secs(300), "samples");
        // The first report starts the clock; 100 samples were made by an earlier run.
        assert_eq!(log.line(at(0), 100, 1000), None);
        assert_eq!(log.line(at(120), 140, 1000), None);
        // Ten minutes later: 60 made, 6 a minute, 840 left: 140 minutes.
        assert_eq!(
            log.line(at(600), 160, 1000).as_deref(),
            Some("160/1000 samples (16%); 6.0 a minute this run; about 2h20m left")
        );
        assert_eq!(log.line(at(800), 170, 1000), None);
        let line = log.line(at(900), 190, 1000).unwrap();
        assert!(line.ends_with("about 2h15m left"), "{line}");
    }

    #[test]
    fn nothing_made_yet_says_so() {
        let t0 = Instant::now();
        let mut log = LogLines::new(Duration::from_secs(60), "batches");
        assert_eq!(log.line(t0, 0, 10), None);
        let line = log.line(t0 + Duration::from_secs(61), 0, 10).unwrap();
        assert!(line.starts_with("0/10 batches (0%)"), "{line}");
        assert!(line.ends_with("none made yet this run"), "{line}");
        assert_eq!(hours_minutes(59.6), "1h00m");
        assert_eq!(hours_minutes(35.2), "35m");
    }
}
