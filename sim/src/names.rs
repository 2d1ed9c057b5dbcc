//! How each front end names the values it takes, in its errors: the one
//! table a refusal reads a flag's or a keyword's name from.

/// The names of every value a front end can set, as its errors print them:
/// `--runs` on the command line, `runs` in Python, `runs` as the scenario
/// file's own key. One table per front end ([`Names::CLI`],
/// [`Names::PYTHON`], [`Names::FILE`]); a refusal reads the name of the
/// value it refuses from the table of the entry the value came through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Names {
    /// The scenario file.
    pub scenario: &'static str,
    /// The task.
    pub task: &'static str,
    /// The decoder's accuracy (a run's, or a sweep's levels).
    pub accuracy: &'static str,
    /// The seed (a run's, or a sweep's).
    pub seed: &'static str,
    /// The runs of an e-puck scenario.
    pub runs: &'static str,
    /// The grid's decoder (the EEG decoder or the oracle).
    pub decoder: &'static str,
    /// The grid's EEG mode, set in a scenario (per action or a bank).
    pub eeg: &'static str,
    /// The grid's EEG mode of every level of a sweep.
    pub sweep_eeg: &'static str,
    /// The recording to write.
    pub save: &'static str,
    /// A swept parameter.
    pub param: &'static str,
    /// The episodes per level of a sweep.
    pub episodes: &'static str,
    /// A live session's speed.
    pub speed: &'static str,
    /// A live session's timeout.
    pub timeout: &'static str,
    /// A live session's calibration length.
    pub calibration_actions: &'static str,
}

impl Names {
    /// The command line's flags.
    pub const CLI: Names = Names {
        scenario: "--scenario",
        task: "--task",
        accuracy: "--accuracy",
        seed: "--seed",
        runs: "--runs",
        decoder: "--decoder",
        eeg: "--eeg",
        sweep_eeg: "--eeg",
        save: "--save",
        param: "--param",
        episodes: "--episodes",
        speed: "--speed",
        timeout: "--timeout",
        calibration_actions: "--calibration-actions",
    };

    /// The Python package's keywords (`errp.run`, the tasks and
    /// environments, `errp.sweep`); the grid's decoder and EEG mode are
    /// entries of `overrides=`.
    pub const PYTHON: Names = Names {
        scenario: "scenario=",
        task: "task=",
        accuracy: "accuracy",
        seed: "seed",
        runs: "runs",
        decoder: "overrides[\"decoder\"]",
        eeg: "overrides[\"eeg\"]",
        sweep_eeg: "per_action=",
        save: "save",
        param: "params=",
        episodes: "episodes=",
        speed: "speed",
        timeout: "timeout",
        calibration_actions: "calibration_actions",
    };

    /// The scenario file's own keys: for values set as keys (a sweep's
    /// levels) or a file loaded as written.
    pub const FILE: Names = Names {
        scenario: "scenario",
        task: "task",
        accuracy: "user.accuracy",
        seed: "seed",
        runs: "runs",
        decoder: "decoder",
        eeg: "eeg",
        sweep_eeg: "eeg",
        save: "save",
        param: "param",
        episodes: "episodes",
        speed: "speed",
        timeout: "timeout",
        calibration_actions: "calibration_actions",
    };
}
