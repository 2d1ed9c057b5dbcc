//! The world and the loop: synthetic user, episode runners and Rerun recording.
//!
//! `errp_sim` is the only crate that touches the Rerun SDK (and, for the
//! e-puck, rapier2d). It ties the EEG side ([`errp_bci`]) to the agent side
//! ([`errp_robot`]) and writes what happened to `.rrd` files.

mod calibration;
mod calibration_view;
mod error;
mod grid_task;
mod output;
mod record;

pub use calibration::{CalibrationReport, CalibrationRequest, run_calibration};
pub use calibration_view::{LATENCY_TIMELINE, calibration_recording, record_calibration};
pub use error::{Result, SimError};
pub use grid_task::{
    AssessmentDecoder, EegDecoder, GridEpisodeResult, GridStep, GridTaskParams, run_grid_episode,
};
pub use output::PendingFile;
pub use record::RrdFile;
