//! The e-puck as an environment for an agent of the user's own: the agent
//! drives the robot with motion primitives, the synthetic user watches it
//! from the ceiling camera's pose and judges its motion against the goal,
//! and the testbed's calibrated sliding-window decoder turns the EEG of
//! those judgements into p(error) every 62.5 ms: the agent's feedback.
//! What a Gymnasium environment steps.

use std::sync::Arc;

use errp_bci::EegBlock;
use errp_robot::{Pose, WheelSpeeds};

use crate::epuck::decoder::ContinuousDecoder;
use crate::epuck::observer::{EpisodeStart, EpuckObserver};
use crate::epuck::plant::{EpuckDriver, EpuckPlant, PlantWindow, WindowDecoding};
use crate::epuck::scenario::EpuckScenario;
use crate::error::{Result, SimError};

/// The most decoder windows one action may last (4 s).
pub const MAX_WINDOWS_PER_ACTION: usize = 64;

/// A motion primitive of the agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EpuckAction {
    /// Drive straight at the scenario's drive speed.
    Forward,
    /// Turn in place anticlockwise at the scenario's turn speed.
    TurnLeft,
    /// Turn in place clockwise.
    TurnRight,
    /// Stand still: on a goal, a commitment to it.
    Stop,
}

impl EpuckAction {
    /// All actions, by index.
    pub const ALL: [EpuckAction; 4] = [
        EpuckAction::Forward,
        EpuckAction::TurnLeft,
        EpuckAction::TurnRight,
        EpuckAction::Stop,
    ];

    /// What the robot does under the action ([`crate::epuck::PHASE_NAMES`]):
    /// 0 turning, 1 driving, 2 stopped.
    fn phase(self) -> usize {
        match self {
            EpuckAction::TurnLeft | EpuckAction::TurnRight => 0,
            EpuckAction::Forward => 1,
            EpuckAction::Stop => 2,
        }
    }
}

/// An action held for all its physics steps, heading for the user's goal
/// as far as an observer is told.
struct Primitive {
    command: WheelSpeeds,
    phase: usize,
    target: usize,
}

impl EpuckDriver for Primitive {
    fn phase(&self) -> usize {
        self.phase
    }

    fn target(&self) -> usize {
        self.target
    }

    fn command(&mut self, _tracked: &Pose, _time_secs: f64) -> WheelSpeeds {
        self.command
    }
}

/// What one action gave the agent.
#[derive(Debug, Clone, PartialEq)]
pub struct EpuckFeedback {
    /// The pose the ceiling camera saw at the end of the action.
    pub tracked: Pose,
    /// The decoder's p(error) of each 62.5 ms window of the action.
    pub p_error: Vec<f64>,
    /// The scenario's detector reported an error in one of the windows.
    pub detected: bool,
    /// ErrPs the user produced during the action (for scoring only).
    pub errps: usize,
    /// The goal within the scenario's goal radius of the true pose, if any.
    pub on_goal: Option<usize>,
    /// Episode time at the end of the action (s).
    pub time_secs: f64,
    /// The last window of preprocessed EEG, `(n_channels, n_samples)`, when
    /// asked for.
    pub window: Option<EegBlock>,
}

/// One e-puck episode with the motion chosen from outside: the loop of
/// [`EpuckPlant`](crate::epuck::EpuckPlant), which an episode of the shared control runs
/// too, driven by the agent's actions.
pub struct EpuckEnvironment {
    decoder: Arc<ContinuousDecoder>,
    scenario: EpuckScenario,
    plant: EpuckPlant,
    ended: bool,
}

impl EpuckEnvironment {
    /// An episode of `scenario` from its start pose, the user wanting its
    /// goal (or goal `goal` of the layout), everything random from `seed`.
    pub fn new(
        decoder: Arc<ContinuousDecoder>,
        scenario: &EpuckScenario,
        goal: Option<usize>,
        seed: u64,
    ) -> Result<Self> {
        let goal = goal.unwrap_or(scenario.episode.goal);
        let plant = EpuckPlant::new(scenario, goal, &decoder, false, seed)?;
        Ok(Self {
            decoder,
            scenario: scenario.clone(),
            plant,
            ended: false,
        })
    }

    /// The user's goal (an index into the layout).
    pub fn goal(&self) -> usize {
        self.plant.goal()
    }

    /// The pose the camera sees.
    pub fn tracked(&self) -> Pose {
        self.plant.tracked()
    }

    /// Episode time (s).
    pub fn time_secs(&self) -> f64 {
        self.plant.time_secs()
    }

    /// The scenario.
    pub fn scenario(&self) -> &EpuckScenario {
        &self.scenario
    }

    /// What an observer is told when the episode starts, so that it can
    /// score the episode again from what it observes (the detector's T_e
    /// and the response spans of the decoder).
    pub fn start(&self) -> EpisodeStart {
        self.plant.start(&self.decoder)
    }

    /// True once the episode ended: the robot stopped on a goal, or
    /// [`EpuckEnvironment::end`] was called.
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// Ends the episode without a commitment (a time limit outside it, a
    /// reset or a close) and tells `observer`; nothing if it already ended.
    pub fn end(&mut self, observer: &mut impl EpuckObserver) {
        if self.ended {
            return;
        }
        self.ended = true;
        if observer.watches() {
            let time_secs = self.plant.time_secs();
            observer.on_event(time_secs, "the episode ended without a commitment", true);
            observer.on_end(time_secs, None);
        }
    }

    /// Runs `action` for `windows` decoder windows of 62.5 ms (4 physics
    /// steps each, with the scenario's obstacle reflex and wheel noise);
    /// `keep_window` returns the last window's EEG too.
    pub fn step(
        &mut self,
        action: EpuckAction,
        windows: usize,
        keep_window: bool,
    ) -> Result<EpuckFeedback> {
        self.step_observed(action, windows, keep_window, &mut ())
    }

    /// [`EpuckEnvironment::step`] with `observer` watching, as an episode
    /// of the shared control is watched: every physics step (its phase is
    /// the action's: 0 turning, 1 driving, 2 stopped; its target the user's
    /// goal), every window (no belief: an agent drives; the step 0 turn, 1
    /// linear, 2 stopped on a goal, 3 stopped elsewhere), the user's ErrPs,
    /// and the end when the robot stops on a goal.
    pub fn step_observed(
        &mut self,
        action: EpuckAction,
        windows: usize,
        keep_window: bool,
        observer: &mut impl EpuckObserver,
    ) -> Result<EpuckFeedback> {
        if !(1..=MAX_WINDOWS_PER_ACTION).contains(&windows) {
            return Err(SimError::OutOfRange {
                name: "windows_per_action".into(),
                given: format!("{windows} is out of range"),
                expected: format!("1 to {MAX_WINDOWS_PER_ACTION} windows of 62.5 ms"),
            });
        }
        let goal = self.plant.goal();
        let mut driver = Primitive {
            command: self.command(action),
            phase: action.phase(),
            target: goal,
        };
        let watching = observer.watches();
        let mut p_error = Vec::with_capacity(windows);
        let mut detected = false;
        let mut errps = 0;
        for _ in 0..windows {
            let w = self.window_driven(&mut driver, observer)?;
            detected |= w.decision.detected;
            errps += w.errps.len();
            p_error.push(w.p_error);
            if watching {
                let time_secs = self.plant.time_secs();
                if w.decision.detected {
                    let evidence = w.decision.evidence;
                    let text = format!("error detected (evidence {evidence:.2})");
                    observer.on_event(time_secs, &text, false);
                }
                let step = match driver.phase {
                    2 if self.on_goal().is_some() => 2,
                    2 => 3,
                    p => p,
                };
                let frame =
                    self.plant
                        .window_frame(&w, Vec::new(), goal, w.decision.detected, step);
                observer.on_window(&frame);
            }
        }
        let on_goal = self.on_goal();
        if action == EpuckAction::Stop
            && let Some(g) = on_goal
            && !self.ended
        {
            self.ended = true;
            if watching {
                let name = &self.scenario.layout.goals()[g].name;
                let whose = if g == goal {
                    "the user's goal"
                } else {
                    "a wrong goal"
                };
                let time_secs = self.plant.time_secs();
                observer.on_event(
                    time_secs,
                    &format!("stopped on {name} ({whose})"),
                    g != goal,
                );
                observer.on_end(time_secs, Some(g));
            }
        }
        Ok(EpuckFeedback {
            tracked: self.plant.tracked(),
            p_error,
            detected,
            errps,
            on_goal,
            time_secs: self.plant.time_secs(),
            window: keep_window.then(|| self.plant.eeg_window().clone()),
        })
    }

    /// One decoder window with the wheels commanded physics step by physics
    /// step by `driver`, for an agent that steers finer than the motion
    /// primitives (the shared control itself: an episode is this
    /// environment driven by [`crate::epuck::shared_control`]). `observer`
    /// sees the physics steps and the user's ErrPs; the window, its
    /// p(error) and the detector's verdict are returned.
    pub fn window_driven(
        &mut self,
        driver: &mut impl EpuckDriver,
        observer: &mut impl EpuckObserver,
    ) -> Result<PlantWindow> {
        self.plant
            .window(driver, &self.decoder, WindowDecoding::Builtin, observer)
    }

    /// The wheel command of `action` at the scenario's speeds.
    fn command(&self, action: EpuckAction) -> WheelSpeeds {
        let control = &self.scenario.params.control;
        let top = control.epuck.max_speed_m_per_s();
        let turn = control.turn_speed_fraction * top;
        match action {
            EpuckAction::Forward => {
                let v = control.drive_speed_fraction * top;
                WheelSpeeds {
                    left_m_per_s: v,
                    right_m_per_s: v,
                }
            }
            EpuckAction::TurnLeft => WheelSpeeds {
                left_m_per_s: -turn,
                right_m_per_s: turn,
            },
            EpuckAction::TurnRight => WheelSpeeds {
                left_m_per_s: turn,
                right_m_per_s: -turn,
            },
            EpuckAction::Stop => WheelSpeeds::ZERO,
        }
    }

    /// The goal within the scenario's goal radius of the true pose, if any.
    fn on_goal(&self) -> Option<usize> {
        let pose = self.plant.pose();
        let radius = self.scenario.params.control.goal_radius_m;
        self.scenario.layout.goals().iter().position(|g| {
            (g.x_m - pose.x_m).powi(2) + (g.y_m - pose.y_m).powi(2) <= radius * radius
        })
    }
}
