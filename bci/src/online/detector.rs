//! The detector: how the sliding window's p(error) stream becomes error events
//! (the smoothed events of asynchronous-ErrP studies, or the paper's literal
//! reading).

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use super::WINDOW_STEP_SECS;
use errp_valid::{Check, Valid};

use crate::error::{BciError, Result, check};

/// How window outputs become detected errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DetectorMode {
    /// The paper read literally: every window with p(error) >= T_e is a
    /// detected error.
    Literal,
    /// The asynchronous detector: p(error) averaged over the last
    /// `smooth_windows` windows must reach T_e, and after a detection none
    /// follows for `refractory_secs`.
    Smoothed,
}

impl std::fmt::Display for DetectorMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            DetectorMode::Literal => "literal",
            DetectorMode::Smoothed => "smoothed",
        })
    }
}

/// The asynchronous detector's settings (T_e itself is the shared-control
/// parameter of eq. 6-7 and is passed in separately).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DetectorParams {
    /// Literal (the paper) or smoothed (default).
    pub mode: DetectorMode,
    /// Windows averaged (smoothed mode): 1 to 16.
    pub smooth_windows: usize,
    /// Least time between two detections (s, smoothed mode): an ErrP stays
    /// visible for about half a second of windows and must give one event.
    pub refractory_secs: f64,
}

impl Default for DetectorParams {
    fn default() -> Self {
        Self {
            mode: DetectorMode::Smoothed,
            smooth_windows: 4,
            refractory_secs: 1.0,
        }
    }
}

/// Checked where a scenario enters; the detector takes it checked.
impl Check for DetectorParams {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl DetectorParams {
    /// The paper's literal reading: each window against T_e.
    pub fn literal() -> Valid<Self> {
        let literal = Self {
            mode: DetectorMode::Literal,
            smooth_windows: 1,
            refractory_secs: 0.0,
        };
        match Valid::new(literal) {
            Ok(v) => v,
            Err(e) => unreachable!("the literal reading is within the rules: {e}"),
        }
    }

    /// Checks every field; names them as the scenario's `[detector]` does.
    fn validate(&self) -> Result<()> {
        check(
            (1..=16).contains(&self.smooth_windows),
            "smooth_windows",
            self.smooth_windows,
            "1 to 16 windows (up to 1 s of 62.5 ms steps)",
        )?;
        check(
            self.refractory_secs.is_finite() && (0.0..=10.0).contains(&self.refractory_secs),
            "refractory_secs",
            self.refractory_secs,
            "a time in [0, 10] s",
        )
    }

    /// How much later than the window that sees an ErrP best the detector
    /// can fire (s): the averaging delays it by up to `smooth_windows - 1`
    /// steps.
    pub fn delay_secs(&self) -> f64 {
        match self.mode {
            DetectorMode::Literal => 0.0,
            DetectorMode::Smoothed => (self.smooth_windows - 1) as f64 * WINDOW_STEP_SECS,
        }
    }
}

/// One decision of the [`Detector`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// The evidence compared with T_e: p(error) (literal) or its moving
    /// average (smoothed).
    pub evidence: f64,
    /// An error is detected at this window.
    pub detected: bool,
}

/// Turns the stream of window p(error) into detected errors.
#[derive(Debug, Clone)]
pub struct Detector {
    params: Valid<DetectorParams>,
    t_e: f64,
    recent: VecDeque<f64>,
    last_detection_secs: f64,
}

impl Detector {
    /// A detector with threshold `t_e` (in (0, 1]).
    pub fn new(params: Valid<DetectorParams>, t_e: f64) -> Result<Self> {
        check(
            t_e.is_finite() && t_e > 0.0 && t_e <= 1.0,
            "t_e",
            t_e,
            "a threshold in (0, 1]",
        )?;
        Ok(Self {
            params,
            t_e,
            recent: VecDeque::with_capacity(params.smooth_windows),
            last_detection_secs: f64::NEG_INFINITY,
        })
    }

    /// The settings.
    pub fn params(&self) -> &DetectorParams {
        &self.params
    }

    /// The threshold T_e.
    pub fn t_e(&self) -> f64 {
        self.t_e
    }

    /// The window ending at `time_secs` gave `p_error`: is an error detected?
    pub fn push(&mut self, p_error: f64, time_secs: f64) -> Decision {
        match self.params.mode {
            DetectorMode::Literal => Decision {
                evidence: p_error,
                detected: p_error >= self.t_e,
            },
            DetectorMode::Smoothed => {
                if self.recent.len() == self.params.smooth_windows {
                    self.recent.pop_front();
                }
                self.recent.push_back(p_error);
                let evidence = self.recent.iter().sum::<f64>() / self.recent.len() as f64;
                let ready = self.recent.len() == self.params.smooth_windows
                    && time_secs - self.last_detection_secs >= self.params.refractory_secs - 1e-9;
                let detected = ready && evidence >= self.t_e;
                if detected {
                    self.last_detection_secs = time_secs;
                }
                Decision { evidence, detected }
            }
        }
    }
}
