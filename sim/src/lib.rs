//! The world and the loop: synthetic user, episode runners and Rerun recording.
//!
//! `errp_sim` is the only crate that touches the Rerun SDK (and, for the
//! e-puck, rapier2d). It ties the EEG side ([`errp_bci`]) to the agent side
//! ([`errp_robot`]) and writes what happened to `.rrd` files.

#![warn(clippy::unwrap_used, clippy::print_stdout, clippy::iter_over_hash_type)]

mod calibration;
mod calibration_view;
mod epuck;
mod error;
mod grid;
mod output;
mod paper;
mod record;
mod stats;
mod sweep;

pub use calibration::{CalibrationReport, CalibrationRequest, calibrate_at, run_calibration};
pub use calibration_view::{LATENCY_TIMELINE, calibration_recording, record_calibration};
pub use epuck::decoder::{
    ContinuousDecoder, ContinuousReport, ContinuousRequest, OnlineReport, calibrate_continuous_at,
    run_continuous_calibration, run_online_calibration,
};
pub use epuck::episode::{
    EpuckEpisode, EpuckEpisodeResult, EpuckObserver, EpuckTaskParams, PHYSICS_DT_SECS,
    PhysicsFrame, WINDOW_STEP_SECS, WindowFrame, run_epuck_episode,
};
pub use epuck::run::{
    EpuckSummary, epuck_run_seed, finish_continuous_decoder, prepare_continuous_decoder,
    prepare_continuous_decoder_with, run_epuck_batch, run_epuck_once, summarise,
};
pub use epuck::scenario::{AnyScenario, EpuckScenario, load_scenario, load_scenario_with};
pub use epuck::tracker::{CameraTracker, TrackerParams};
pub use epuck::user::{Elicited, Judgement, SeenMotion, SyntheticUser, UserParams};
pub use epuck::view::{EpuckRecorder, RUN_GAP_SECS, epuck_recording};
pub use epuck::world::{ArenaSpec, Obstacle, ProximitySensors, World};
pub use error::{Result, SimError};
pub use errp_robot::AvoidanceParams;
pub use grid::episode::{
    AssessmentDecoder, EegDecoder, EegSource, EpochBank, EpochBankParts, GridEpisodeResult,
    GridStep, GridTaskParams, PErrorChoice, PErrorMapping, run_grid_episode,
};
pub use grid::run::{
    GridRunReport, decoder_from_calibration, pooled_accuracy, prepare_decoder, run_grid_scenario,
};
pub use grid::scenario::{DecoderChoice, EegMode, GridScenario, free_pairs};
pub use grid::table1::{
    FIXED_PAIRS, Table1Cell, Table1Options, accuracy_time_correlation, run_table1,
};
pub use grid::view::{SIM_TIME, grid_recording, record_grid_run};
pub use output::PendingFile;
pub use paper::{PAPER, PAPER_EPUCK, PAPER_POOLED};
pub use record::RrdFile;
pub use stats::{
    StreamingPearson, correlation_p_value, incomplete_beta, mean_sd, median, pearson,
    wilson_interval,
};
pub use sweep::{
    Axis, DecoderInfo, EPISODES, Level, LevelPoint, LevelSummary, MANIFEST, Manifest, PaperPoint,
    PlotError, Series, Shard, SweepObserver, SweepOptions, SweepOutcome, SweepPlot, SweepReport,
    SweepSpec, SweepTask, TargetCache, cost_column, episodes_header, finish_dir, merge_sweeps,
    parse_accuracies, parse_axis, parse_values, read_task, run_sweep, summarise_dir, summary_csv,
    sweep_plot,
};
