//! How the grid's EEG decoders map a decision value to p(error): the
//! scenario's choice and the mapping a calibration fits.

use errp_bci::{ErrorModel, PlattScaling};
use serde::{Deserialize, Serialize};

/// How the EEG decoder's decision value becomes p(error).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PErrorChoice {
    /// The paper's 1 / (1 + e^-y).
    Sigmoid,
    /// Platt scaling fitted on the calibration session (the default).
    Platt,
}

/// How the decoder's decision value y becomes p(error).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PErrorMapping {
    /// The paper's p = 1 / (1 + e^-y) (sec. 2.2.1).
    Sigmoid,
    /// Platt scaling fitted on the calibration session's out-of-fold
    /// decisions: p = 1 / (1 + e^-(a y + b)).
    Platt(PlattScaling),
}

impl PErrorMapping {
    /// `model`'s p(error) for `features` under this mapping, and its class
    /// (decision value y >= 0, sec. 2.2.1).
    pub(crate) fn decide(&self, model: &impl ErrorModel, features: &[f64]) -> (f64, bool) {
        let y = model.decision(features);
        let p = match self {
            PErrorMapping::Sigmoid => errp_bci::sigmoid(y),
            PErrorMapping::Platt(s) => s.p_error(y),
        };
        (p, y >= 0.0)
    }
}
