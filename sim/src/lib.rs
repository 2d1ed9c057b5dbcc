//! The world and the loop: synthetic user, episode runners and Rerun recording.
//!
//! `errp_sim` is the only crate that touches the Rerun SDK (and, for the
//! e-puck, rapier2d). It ties the EEG side ([`errp_bci`]) to the agent side
//! ([`errp_robot`]) and writes what happened to `.rrd` files.

mod calibration;
mod calibration_view;
mod error;
mod grid_run;
mod grid_task;
mod grid_view;
mod output;
mod record;
mod scenario;
mod stats;
mod table1;

pub use calibration::{CalibrationReport, CalibrationRequest, run_calibration};
pub use calibration_view::{LATENCY_TIMELINE, calibration_recording, record_calibration};
pub use error::{Result, SimError};
pub use grid_run::{GridRunReport, mean_sd, pooled_accuracy, prepare_decoder, run_grid_scenario};
pub use grid_task::{
    AssessmentDecoder, EegDecoder, EpochBank, GridEpisodeResult, GridStep, GridTaskParams,
    PErrorMapping, run_grid_episode,
};
pub use grid_view::{SIM_TIME, grid_recording, record_grid_run};
pub use output::PendingFile;
pub use record::RrdFile;
pub use scenario::{DecoderChoice, EegMode, PErrorChoice, Scenario, free_pairs};
pub use stats::{incomplete_beta, pearson};
pub use table1::{
    FIXED_PAIRS, PAPER, PAPER_POOLED, Table1Cell, Table1Options, accuracy_time_correlation,
    run_table1,
};
