//! The crate's error type.

use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong in `errp_sim`.
#[derive(Debug, Error)]
pub enum SimError {
    /// The EEG side failed (bad parameters, untrainable data, ...).
    #[error(transparent)]
    Bci(#[from] errp_bci::BciError),
    /// The shared-control side failed.
    #[error(transparent)]
    Robot(#[from] errp_robot::RobotError),
    /// A scenario is invalid.
    #[error("{0}")]
    Scenario(String),
    /// A sweep cannot run as asked (bad levels, a resume that does not
    /// match, shards that do not merge).
    #[error("{0}")]
    Sweep(String),
    /// A live loop stopped: its decoder did not appear, went silent or
    /// sent what is not a decision.
    #[error("{0}")]
    Live(String),
    /// An input file cannot be read.
    #[error("cannot read {path}: {source}")]
    Input {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// An output file cannot be created or written.
    #[error("cannot write {path}: {source}")]
    Output {
        /// The file the user asked for.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The Rerun SDK refused to record.
    #[error("recording to {path} failed: {message}")]
    Record {
        /// The `.rrd` file.
        path: PathBuf,
        /// The SDK's message.
        message: String,
    },
}

/// Shorthand for results in this crate.
pub type Result<T, E = SimError> = std::result::Result<T, E>;

/// Checks a p(error) that a decoder of the user's own returned.
pub fn check_p_error(p: f64) -> Result<f64> {
    if p.is_finite() && (0.0..=1.0).contains(&p) {
        Ok(p)
    } else {
        Err(SimError::Scenario(format!(
            "decoder: returned p(error) = {p}, expected a number from 0 to 1"
        )))
    }
}
