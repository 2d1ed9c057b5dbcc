//! The crate's error type.

use std::fmt::Display;

use thiserror::Error;

/// Everything that can go wrong in `errp_robot`.
#[derive(Debug, Error)]
pub enum RobotError {
    /// A parameter is outside its accepted range: loaders map `name` to
    /// their own spelling of the field (`control.tau`) instead of checking
    /// the range again.
    #[error("{name} = {value} is invalid: expected {expected}")]
    InvalidParameter {
        /// The field, as the parameter struct names it.
        name: &'static str,
        /// The value given.
        value: String,
        /// The accepted range, in words.
        expected: String,
    },
    /// Parameters that are each valid do not fit together, or a layout
    /// cannot be built.
    #[error("invalid parameter: {0}")]
    Parameter(String),
    /// A likelihood vector cannot update a belief.
    #[error("invalid likelihood: {0}")]
    Likelihood(String),
}

/// Shorthand for results in this crate.
pub type Result<T, E = RobotError> = std::result::Result<T, E>;

/// An [`RobotError::InvalidParameter`] unless `ok` (and, for numbers, the
/// value is finite: NaN and infinities are never accepted).
pub(crate) fn check(ok: bool, name: &'static str, v: impl Display, expected: &str) -> Result<()> {
    ok.then_some(())
        .ok_or_else(|| RobotError::InvalidParameter {
            name,
            value: errp_valid::shown(v),
            expected: expected.to_string(),
        })
}
