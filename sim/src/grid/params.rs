//! Timing and limits of a grid episode, and the strategy it runs.

use errp_robot::{GridControlParams, Valid};
use serde::{Deserialize, Serialize};

/// Timing and limits of a grid episode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GridTaskParams {
    /// The device's strategy (tau, epsilon, p_c, reward model), checked
    /// where the scenario entered.
    pub control: Valid<GridControlParams>,
    /// Shortest inter-action interval (s); the paper: 3.
    pub interval_min_secs: f64,
    /// Longest inter-action interval (s); the paper: 3.5.
    pub interval_max_secs: f64,
    /// EEG decoded per action, for the net time (s); the paper: 0.8.
    pub epoch_secs: f64,
    /// An episode that has not converged after this many actions fails.
    pub max_actions: usize,
}

impl Default for GridTaskParams {
    fn default() -> Self {
        Self {
            control: Valid::default(),
            interval_min_secs: 3.0,
            interval_max_secs: 3.5,
            epoch_secs: 0.8,
            max_actions: 300,
        }
    }
}
