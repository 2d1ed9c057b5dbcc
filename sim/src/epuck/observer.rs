//! What an episode tells those who watch it (a recording, a test): the
//! physics steps, the decoder windows, the user's ErrPs and events in
//! words.

use errp_robot::{Pose, WheelSpeeds};

/// One physics step, for observers.
#[derive(Debug, Clone, Copy)]
pub struct PhysicsFrame {
    /// Episode time at the end of the step (s).
    pub time_secs: f64,
    /// True pose.
    pub pose: Pose,
    /// Pose seen by the camera.
    pub tracked: Pose,
    /// Wheel speeds actually applied (after avoidance and noise).
    pub wheels: WheelSpeeds,
    /// What the controller was doing during the step: 0 turning, 1 driving,
    /// 2 stopped ([`PHASE_NAMES`]).
    pub phase: usize,
    /// The goal the robot heads for.
    pub target: usize,
}

/// The names of [`WindowFrame::step`], in index order.
pub const STEP_NAMES: [&str; 4] = ["turn", "linear", "stop-on-goal", "idle"];

/// The names of [`PhysicsFrame::phase`], in index order.
pub const PHASE_NAMES: [&str; 3] = ["turning", "driving", "stopped"];

/// What an observer learns when an episode starts: what is needed to score
/// it again from what it observes.
#[derive(Debug, Clone, Copy)]
pub struct EpisodeStart {
    /// The true pose at time 0.
    pub pose: Pose,
    /// The user's goal.
    pub goal: usize,
    /// The detector's threshold T_e on p(error).
    pub t_e: f64,
    /// Lags after an ErrP within which a detection counts as true (s).
    pub detection_span: (f64, f64),
    /// Lags after an ErrP within which a window scores as an error window (s).
    pub window_span: (f64, f64),
}

/// One decoder window, for observers.
#[derive(Debug, Clone)]
pub struct WindowFrame {
    /// Episode time at the end of the window (s).
    pub time_secs: f64,
    /// The decoder's output.
    pub p_error: f64,
    /// What the detector compared with T_e (p(error) or its moving average).
    pub evidence: f64,
    /// The belief after the update.
    pub belief: Vec<f64>,
    /// The goal the robot is heading to.
    pub target: usize,
    /// Whether the detector reported an error that the controller used (in
    /// motion it stops the robot; on a goal it vetoes the goal).
    pub detected: bool,
    /// The controller's update on this window ([`STEP_NAMES`]): 0 a turn
    /// step (eq. 6), 1 a linear step (eq. 7), 2 stopped on a goal, 3 idle
    /// (stopped after a detection: no update, and not error-free time).
    pub step: usize,
    /// The tracked pose the controller used.
    pub tracked: Pose,
    /// Preprocessed FCz and Cz samples of the last 62.5 ms (uV).
    pub fcz_cz: [Vec<f64>; 2],
}

/// Watches an episode as it runs. Every method does nothing by default, and
/// `()` watches nothing, so runs without a recording pay nothing.
pub trait EpuckObserver {
    /// Whether frames and events are wanted at all (`()` says no, so an
    /// unrecorded run does not even build them).
    fn watches(&self) -> bool {
        true
    }
    /// After each physics step.
    fn on_physics(&mut self, _frame: &PhysicsFrame) {}
    /// After each decoder window.
    fn on_window(&mut self, _frame: &WindowFrame) {}
    /// A notable event, in words.
    fn on_event(&mut self, _time_secs: f64, _text: &str, _warn: bool) {}
    /// Before the first step.
    fn on_start(&mut self, _start: &EpisodeStart) {}
    /// The user produced an ErrP at `onset_secs`, seen at `time_secs`,
    /// judging a move in phase `phase` ([`PHASE_NAMES`]).
    fn on_errp(&mut self, _time_secs: f64, _onset_secs: f64, _phase: usize) {}
    /// The episode ended at `time_secs`, converged on `committed` or timed
    /// out (`None`).
    fn on_end(&mut self, _time_secs: f64, _committed: Option<usize>) {}
}

impl EpuckObserver for () {
    fn watches(&self) -> bool {
        false
    }
}

/// An observer if there is one: a live run recorded or not.
impl EpuckObserver for Option<&mut dyn EpuckObserver> {
    fn watches(&self) -> bool {
        self.as_ref().is_some_and(|o| o.watches())
    }
    fn on_physics(&mut self, frame: &PhysicsFrame) {
        if let Some(o) = self {
            o.on_physics(frame);
        }
    }
    fn on_window(&mut self, frame: &WindowFrame) {
        if let Some(o) = self {
            o.on_window(frame);
        }
    }
    fn on_event(&mut self, time_secs: f64, text: &str, warn: bool) {
        if let Some(o) = self {
            o.on_event(time_secs, text, warn);
        }
    }
    fn on_start(&mut self, start: &EpisodeStart) {
        if let Some(o) = self {
            o.on_start(start);
        }
    }
    fn on_errp(&mut self, time_secs: f64, onset_secs: f64, phase: usize) {
        if let Some(o) = self {
            o.on_errp(time_secs, onset_secs, phase);
        }
    }
    fn on_end(&mut self, time_secs: f64, committed: Option<usize>) {
        if let Some(o) = self {
            o.on_end(time_secs, committed);
        }
    }
}
