//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong in `errp_bci`.
#[derive(Debug, Error)]
pub enum BciError {
    /// A parameter is outside its accepted range.
    #[error("{name} = {value} is invalid: {expected}")]
    InvalidParameter {
        /// Parameter name as the user spells it.
        name: &'static str,
        /// The offending value, formatted.
        value: String,
        /// What is accepted instead.
        expected: String,
    },
    /// A channel name is not in the montage.
    #[error("unknown channel {0:?}")]
    UnknownChannel(String),
    /// A subject name is not in the subjects asset.
    #[error("unknown subject {name:?}: known subjects are {known}")]
    UnknownSubject {
        /// The requested name.
        name: String,
        /// Comma-separated list of known names.
        known: String,
    },
    /// A built-in asset could not be parsed (a bug in the shipped files).
    #[error("asset {file}: {message}")]
    Asset {
        /// Asset file name.
        file: &'static str,
        /// What is wrong.
        message: String,
    },
    /// Training data cannot produce a model (e.g. one class is missing).
    #[error("cannot train: {0}")]
    Training(String),
    /// A file's content is not what its format requires (the caller names
    /// the file).
    #[error("{0}")]
    Format(String),
    /// Writing an export file failed.
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// Stopped on request (the `stop` module) before the work was done.
    #[error("stopped on request (interrupted)")]
    Interrupted,
}

/// Shorthand for results in this crate.
pub type Result<T, E = BciError> = std::result::Result<T, E>;

/// Returns an [`BciError::InvalidParameter`] unless `ok`.
pub(crate) fn check(
    ok: bool,
    name: &'static str,
    value: impl std::fmt::Display,
    expected: &str,
) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(BciError::InvalidParameter {
            name,
            value: errp_valid::shown(value),
            expected: expected.to_string(),
        })
    }
}
