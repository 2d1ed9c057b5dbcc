//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong in `errp_robot`.
#[derive(Debug, Error)]
pub enum RobotError {
    /// A parameter is outside its accepted range.
    #[error("invalid parameter: {0}")]
    Parameter(String),
    /// A likelihood vector cannot update a belief.
    #[error("invalid likelihood: {0}")]
    Likelihood(String),
}

/// Shorthand for results in this crate.
pub type Result<T, E = RobotError> = std::result::Result<T, E>;
