//! Which drapes a checkpoint's network trained on, for `garnet export`'s model card and
//! `garnet average`: the record `garnet train` writes, else the recorded command line.

use clap::Parser;
use model::TrainState;

use crate::drape_filter_args::filter_flags;
use crate::train_cmd::TrainArgs;

/// `garnet train`'s arguments alone on a command line, to read back a recorded one.
#[derive(Parser)]
struct TrainLine {
    #[command(flatten)]
    args: TrainArgs,
}

/// The flags that chose the training drapes of the latest run that trained the network
/// whose progress is `state` (`""`: every drape; see [`TrainState::train_drapes`]): as
/// recorded, else read from the last `garnet train` of the recorded command line (a
/// checkpoint written before the record existed); `None` when neither says, or that command
/// line no longer parses.
pub fn training_drapes(state: &TrainState) -> Option<String> {
    if let Some(flags) = &state.train_drapes {
        return Some(flags.clone());
    }
    let train = state
        .command
        .as_deref()?
        .rsplit("; then ")
        .find(|c| c.starts_with("garnet train "))?;
    let line = TrainLine::try_parse_from(train.split_whitespace().skip(1)).ok()?;
    let filter = line.args.drapes.filter().ok()?;
    Some(filter_flags(filter.as_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(command: Option<&str>, train_drapes: Option<&str>) -> TrainState {
        TrainState {
            command: command.map(str::to_string),
            train_drapes: train_drapes.map(str::to_string),
            ..TrainState::default()
        }
    }

    /// Checkpoints written before the record existed: the last training command of the
    /// chain says (a network averaged or grown after it trained on what it trained on).
    #[test]
    fn drapes_come_from_the_record_else_the_last_training_command() {
        let train = "garnet train --data d --garment tshirt --variant local";
        let filtered = format!("{train} --at-rest --max-strain 5 --seed 4");
        let average = "garnet average --models a.garnet b.garnet --out c.garnet";
        for (command, expected) in [
            (train.to_string(), Some("")),
            (
                format!("{filtered}; then {average}"),
                Some(" --at-rest --max-strain 5"),
            ),
            (
                format!("{filtered}; then {train}; then {average}"),
                Some(""),
            ),
            (average.to_string(), None),
            (format!("{train} --no-such-flag"), None),
        ] {
            assert_eq!(
                training_drapes(&state(Some(&command), None)).as_deref(),
                expected,
                "{command}"
            );
        }
        assert_eq!(training_drapes(&state(None, None)), None);
        // The record wins over the command line.
        assert_eq!(
            training_drapes(&state(Some(&filtered), Some(""))).as_deref(),
            Some("")
        );
    }
}
