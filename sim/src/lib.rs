//! The world and the loop: synthetic user, episode runners and Rerun recording.
//!
//! `errp_sim` is the only crate that touches the Rerun SDK (and, for the
//! e-puck, rapier2d). Recording is the default-on `rerun` feature: without
//! it (`--no-default-features`) the crate builds without the Rerun SDK, for
//! cluster sweeps, and the recording modules are absent. It ties the EEG side ([`errp_bci`]) to the agent side
//! ([`errp_robot`]) and writes what happened to `.rrd` files.
//!
//! One module per task, and what they share:
//! - [`grid`]: the discrete 5x5 grid task (sec. 3-4), Table 1;
//! - [`epuck`]: the continuous e-puck task (sec. 5);
//! - [`calibration`]: the button-locked calibration session of the grid task
//!   and `errp calibrate`;
//! - [`record`]: `.rrd` files, the timelines they share, and the data
//!   tables and provenance every recording carries;
//! - [`inspect`]: recordings read back, each run recomputed from them;
//! - [`live`]: the loop on the wall clock with a decoder outside the
//!   process (`errp stream`);
//! - [`task`]: what a Monte Carlo driver (the sweep) needs of a task;
//! - at the top: scenario files of either task, the paper's numbers,
//!   statistics, atomic output files, the host and process behind files
//!   (`host`) and the error type.
//!
//! One path from a scenario to its result, as `errp run` and the Python
//! package take it: the built-in grid scenario, with the oracle decoder at
//! 90 %, run with nothing watching and nothing recorded.
//!
//! ```
//! use errp_bci::RequestedAccuracy;
//! use errp_sim::grid::DecoderChoice;
//! use errp_sim::{
//!     Names, RunOptions, RunOutcome, RunProvenance, ScenarioInput, ScenarioSource, TaskKind,
//!     run_scenario,
//! };
//!
//! let input = ScenarioInput {
//!     accuracy: Some(RequestedAccuracy::new(0.9).unwrap()),
//!     decoder: Some(DecoderChoice::Oracle),
//!     ..ScenarioInput::new(ScenarioSource::built_in(TaskKind::Grid))
//! };
//! let loaded = input.load(&Names::PYTHON).unwrap();
//! let options = RunOptions {
//!     save: None,
//!     provenance: &RunProvenance::default(),
//!     names: &Names::PYTHON,
//! };
//! let run = run_scenario(loaded, options, &()).unwrap();
//! let RunOutcome::Grid(report) = run.outcome else { unreachable!() };
//! assert_eq!(report.episodes.len(), 5);
//! assert!(report.episodes.iter().filter(|e| e.reached()).count() >= 3);
//! ```

#![forbid(unsafe_code)]
#![warn(clippy::unwrap_used, clippy::print_stdout, clippy::iter_over_hash_type)]
// No function over 100 lines of code (clippy.toml) outside the tests.
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

mod agents;
pub mod calibration;
pub mod epuck;
mod error;
mod files;
pub mod grid;
pub mod host;
mod input;
#[cfg(feature = "rerun")]
pub mod inspect;
mod key;
pub mod live;
mod names;
mod output;
pub mod own_eeg;
pub mod pace;
mod paper;
pub mod realism;
#[cfg(feature = "rerun")]
pub mod record;
pub mod rules;
mod runner;
mod scenario;
mod scenario_file;
#[cfg(test)]
mod snapshot;
mod stats;
pub mod task;
mod task_kind;

pub use agents::{AgentInfo, EpuckAgentRecording, GridAgentRecording};
pub use error::{Result, SimError, check_p_error};
pub use files::{append_regular, is_foreign, open_regular, open_regular_with, write_regular};
pub use input::{
    BUILT_IN_EPUCK, BUILT_IN_GRID, LoadedScenario, ScenarioInput, ScenarioSeed, ScenarioSource,
};
pub use key::StableKey;
pub use names::Names;
pub use output::{
    CreatedDirs, PendingFile, create_dir, create_dirs, forget_if_interrupted,
    remove_if_interrupted, remove_unfinished, write_atomic,
};
pub use paper::{PAPER, PAPER_EPUCK, PAPER_POOLED};
pub use runner::{
    BatchRecord, EpuckRun, MAX_RECORDED_EPISODES, MAX_RECORDED_RUNS, PendingRecording, RunError,
    RunHeadline, RunObserver, RunOptions, RunOutcome, RunProvenance, ScenarioRun,
    check_recordable_episodes, check_recordable_runs, epuck_decoder_summary, grid_decoder_summary,
    run_epuck_batch_recorded, run_grid_batch, run_scenario,
};
pub use scenario::{
    AnyScenario, apply_overrides, parse_scenario, parse_scenario_table, scenario_kind,
};
pub use scenario_file::{
    MAX_KEY_PARTS, MAX_SCENARIO_BYTES, key_parts, parse_toml, table_into, truncate,
};
pub use stats::{
    RunningPearson, correlation_p_value, fixed_or_dash, incomplete_beta, mean_sd, median, pearson,
    percentile_of, quantile, wilson_interval,
};
pub use task_kind::{TaskKind, UnknownTask};
