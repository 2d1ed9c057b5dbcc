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
    /// A field of a scenario is invalid: where (the file, with the line
    /// when the text is the file as written), the field as the file spells
    /// it, its value and what is accepted.
    #[error("{at}: field `{field}` = {value} is invalid: expected {expected}")]
    Field {
        /// The file, and the line if known.
        at: String,
        /// The field (`control.tau`).
        field: String,
        /// The value, as written.
        value: String,
        /// What is accepted, in words.
        expected: String,
    },
    /// A parameter named as its caller spells it is invalid (the form of
    /// the lower crates' `InvalidParameter`).
    #[error("{name} = {value} is invalid: expected {expected}")]
    InvalidParameter {
        /// The parameter (`tracker.rate_hz`).
        name: String,
        /// Its value.
        value: String,
        /// What is accepted, in words.
        expected: String,
    },
    /// A value outside what is accepted, given to a call or a flag (not a
    /// scenario's field): what it is named, what was given, in words, and
    /// what is accepted.
    #[error("{name}: {given}, expected {expected}")]
    OutOfRange {
        /// The flag, keyword or argument (`--speed`, `goal`).
        name: String,
        /// What was given, in words (`0 is not a speed`).
        given: String,
        /// What is accepted, in words.
        expected: String,
    },
    /// A decoder of the caller's own (Python's) raised: its message.
    #[error("decoder raised: {0}")]
    DecoderRaised(String),
    /// A scenario cannot be run as asked: its values do not combine
    /// ([`crate::rules`]), or it cannot be used for what it was given to.
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
    /// A recording was asked of a build without the Rerun SDK.
    #[error("{}: this build records nothing (built without the `rerun` feature)", path.display())]
    NoRecorder {
        /// The `.rrd` asked for.
        path: PathBuf,
    },
    /// A run stopped because one of its outputs failed (the failure is
    /// reported where it happened).
    #[error("the run was stopped: its output failed")]
    OutputFailed,
}

/// Shorthand for results in this crate.
pub type Result<T, E = SimError> = std::result::Result<T, E>;

/// Checks a p(error) that a decoder of the user's own returned.
pub fn check_p_error(p: f64) -> Result<f64> {
    if p.is_finite() && (0.0..=1.0).contains(&p) {
        Ok(p)
    } else {
        Err(SimError::OutOfRange {
            name: "decoder".into(),
            given: format!("returned p(error) = {p}"),
            expected: "a number from 0 to 1".into(),
        })
    }
}
