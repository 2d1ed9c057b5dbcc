//! Timing and limits of a grid episode, and the strategy it runs; a
//! scenario's `[timing]` table.

use std::path::Path;

use errp_robot::{GridControlParams, Valid};
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::scenario_file::{field_error, whole};

/// Most actions an episode may take before it gives up.
pub const MAX_ACTIONS: u64 = 10_000;
/// The longest inter-action interval, s.
pub const MAX_INTERVAL_SECS: f64 = 60.0;

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

/// A scenario's `[timing]` table, as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TimingFile {
    interval_min_secs: Option<f64>,
    interval_max_secs: Option<f64>,
    epoch_secs: Option<f64>,
    max_actions: Option<f64>,
}

/// The timing of a `[timing]` table set in `p`, on the paper's defaults:
/// intervals, the EEG per action, the most actions.
pub(crate) fn set_timing(
    p: &mut GridTaskParams,
    t: Option<&TimingFile>,
    path: &Path,
) -> Result<()> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    if let Some(t) = t {
        let d = GridTaskParams::default();
        p.interval_min_secs = t.interval_min_secs.unwrap_or(d.interval_min_secs);
        p.interval_max_secs = t.interval_max_secs.unwrap_or(d.interval_max_secs);
        p.epoch_secs = t.epoch_secs.unwrap_or(d.epoch_secs);
        if let Some(n) = t.max_actions {
            p.max_actions = whole(
                path,
                "timing.max_actions",
                n,
                1,
                MAX_ACTIONS,
                &format!(" (default {})", d.max_actions),
            )?;
        }
    }
    let (min, max) = (p.interval_min_secs, p.interval_max_secs);
    if !(min.is_finite() && (0.8..=MAX_INTERVAL_SECS).contains(&min)) {
        return Err(bad(
            "timing.interval_min_secs",
            min.to_string(),
            &format!("a time from 0.8 s (an epoch) to {MAX_INTERVAL_SECS} s (the paper: 3)"),
        ));
    }
    if !(max.is_finite() && max >= min && max <= MAX_INTERVAL_SECS) {
        return Err(bad(
            "timing.interval_max_secs",
            max.to_string(),
            &format!(
                "a time from interval_min_secs ({min} s) to {MAX_INTERVAL_SECS} s (the \
                 paper: 3.5)"
            ),
        ));
    }
    if !(p.epoch_secs.is_finite() && p.epoch_secs > 0.0 && p.epoch_secs <= min) {
        return Err(bad(
            "timing.epoch_secs",
            p.epoch_secs.to_string(),
            &format!(
                "a time > 0 s and at most interval_min_secs ({min} s): the EEG counted \
                 per action fits between two actions (the paper: 0.8)"
            ),
        ));
    }
    Ok(())
}
