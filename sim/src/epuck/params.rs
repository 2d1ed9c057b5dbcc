//! What shapes a continuous episode besides the decoder: the parameters
//! of the task, and where an episode starts and which goal the user wants.

use errp_bci::{DetectorParams, ResponseSpan};
use errp_robot::{AvoidanceParams, EpuckControlParams, Pose, Valid};
use serde::{Deserialize, Serialize};

use crate::epuck::tracker::TrackerParams;
use crate::epuck::user::UserParams;

/// Everything that shapes a continuous episode besides the decoder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpuckTaskParams {
    /// Shared control and motion (sec. 5.1-5.2), checked where the
    /// scenario entered.
    pub control: Valid<EpuckControlParams>,
    /// The synthetic user.
    pub user: UserParams,
    /// The ceiling camera.
    pub tracker: TrackerParams,
    /// Obstacle reflex.
    pub avoidance: AvoidanceParams,
    /// How window outputs become detected errors, checked where the
    /// scenario entered.
    pub detector: Valid<DetectorParams>,
    /// The episode gives up after this long (s).
    pub max_secs: f64,
}

impl EpuckTaskParams {
    /// The stop on a goal that lets the user's verdict reach a detector that
    /// responds over `span` after an ErrP's time zero: the user needs up to
    /// the motion window to see the stop and the reaction latency to react.
    /// `control.goal_hold_secs` when the scenario sets it.
    pub fn goal_hold_secs(&self, span: &ResponseSpan) -> f64 {
        self.control.goal_hold_secs.unwrap_or(
            self.user.motion_window_secs + self.user.reaction_latency_secs + span.to_secs,
        )
    }
}

impl Default for EpuckTaskParams {
    fn default() -> Self {
        Self {
            control: Valid::default(),
            user: UserParams::default(),
            tracker: TrackerParams::default(),
            avoidance: AvoidanceParams::default(),
            detector: Valid::default(),
            max_secs: 600.0,
        }
    }
}

/// An episode: where the e-puck starts and which goal the user wants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpuckEpisode {
    /// Start pose.
    pub start: Pose,
    /// Index of the user's goal in the layout.
    pub goal: usize,
}
