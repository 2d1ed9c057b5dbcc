//! The e-puck as an environment for an agent of the user's own: the agent
//! drives the robot with motion primitives, the synthetic user watches it
//! from the ceiling camera's pose and judges its motion against the goal,
//! and the testbed's calibrated sliding-window decoder turns the EEG of
//! those judgements into p(error) every 62.5 ms: the agent's feedback.
//! What a Gymnasium environment steps.

use std::sync::Arc;

use errp_bci::{AssessmentKind, Detector, EegBlock, SlidingWindow, rng::derive_seed, rng::stream};
use errp_robot::{Pose, WheelSpeeds};
use rand_chacha::ChaCha8Rng;

use crate::epuck::decoder::ContinuousDecoder;
use crate::epuck::episode::{
    EpisodeStart, EpuckObserver, PHYSICS_DT_SECS, PhysicsFrame, STEPS_PER_WINDOW, WindowFrame,
};
use crate::epuck::scenario::EpuckScenario;
use crate::epuck::tracker::CameraTracker;
use crate::epuck::user::SyntheticUser;
use crate::epuck::world::World;
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

/// One e-puck episode with the motion chosen from outside.
pub struct EpuckEnvironment {
    decoder: Arc<ContinuousDecoder>,
    scenario: EpuckScenario,
    world: World,
    tracker: CameraTracker,
    wheels_rng: ChaCha8Rng,
    user: SyntheticUser,
    eeg: SlidingWindow,
    detector: Detector,
    time_secs: f64,
    tracked: Pose,
    t_e: f64,
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
        let n = scenario.layout.len();
        let goal = match goal {
            Some(g) if g < n => g,
            Some(g) => {
                return Err(SimError::Scenario(format!(
                    "goal: {g} is not a goal of the layout, expected 0 to {}",
                    n - 1
                )));
            }
            None => scenario.episode.goal,
        };
        let params = &scenario.params;
        let start = scenario.episode.start;
        let world = World::new(
            &scenario.arena,
            &params.control.epuck,
            start,
            PHYSICS_DT_SECS,
        )?;
        let mut tracker = CameraTracker::new(params.tracker, stream(seed, "epuck/tracker"));
        let tracked = tracker.observe(0.0, &world.pose());
        let t_e = decoder.t_e(params.control.t_e);
        Ok(Self {
            eeg: decoder.start_stream(derive_seed(seed, "epuck/eeg", 0))?,
            detector: Detector::new(params.detector, t_e)?,
            user: SyntheticUser::new(params.user, &scenario.layout, goal),
            world,
            tracker,
            wheels_rng: stream(seed, "epuck/wheels"),
            scenario: scenario.clone(),
            decoder,
            time_secs: 0.0,
            tracked,
            t_e,
            ended: false,
        })
    }

    /// The user's goal (an index into the layout).
    pub fn goal(&self) -> usize {
        self.user.goal()
    }

    /// The pose the camera sees.
    pub fn tracked(&self) -> Pose {
        self.tracked
    }

    /// Episode time (s).
    pub fn time_secs(&self) -> f64 {
        self.time_secs
    }

    /// The scenario.
    pub fn scenario(&self) -> &EpuckScenario {
        &self.scenario
    }

    /// What an observer is told when the episode starts, so that it can
    /// score the episode again from what it observes (the detector's T_e
    /// and the response spans of the decoder).
    pub fn start(&self) -> EpisodeStart {
        let span = self.decoder.detection_span();
        let window_span = self.decoder.window_span();
        EpisodeStart {
            pose: self.world.pose(),
            goal: self.user.goal(),
            t_e: self.t_e,
            detection_span: (span.from_secs, span.to_secs),
            window_span: (window_span.from_secs, window_span.to_secs),
        }
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
            observer.on_event(
                self.time_secs,
                "the episode ended without a commitment",
                true,
            );
            observer.on_end(self.time_secs, None);
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
            return Err(SimError::Scenario(format!(
                "windows_per_action: {windows} is out of range, expected 1 to \
                 {MAX_WINDOWS_PER_ACTION} windows of 62.5 ms"
            )));
        }
        let params = &self.scenario.params;
        let epuck = &params.control.epuck;
        let top = epuck.max_speed_m_per_s();
        let command = match action {
            EpuckAction::Forward => {
                let v = params.control.drive_speed_fraction * top;
                WheelSpeeds {
                    left_m_per_s: v,
                    right_m_per_s: v,
                }
            }
            EpuckAction::TurnLeft | EpuckAction::TurnRight => {
                let s = params.control.turn_speed_fraction * top;
                let s = if action == EpuckAction::TurnLeft {
                    s
                } else {
                    -s
                };
                WheelSpeeds {
                    left_m_per_s: -s,
                    right_m_per_s: s,
                }
            }
            EpuckAction::Stop => WheelSpeeds::ZERO,
        };
        let watching = observer.watches();
        let phase = match action {
            EpuckAction::TurnLeft | EpuckAction::TurnRight => 0,
            EpuckAction::Forward => 1,
            EpuckAction::Stop => 2,
        };
        let goal = self.user.goal();
        let mut p_error = Vec::with_capacity(windows);
        let mut detected = false;
        let mut errps = 0;
        for _ in 0..windows {
            for _ in 0..STEPS_PER_WINDOW {
                if let Some(e) = self.user.observe(self.time_secs, &self.tracked) {
                    let error = e.kind == AssessmentKind::Error;
                    errps += usize::from(error);
                    self.eeg.schedule(e.onset_secs, e.kind);
                    if watching && error {
                        observer.on_errp(self.time_secs, e.onset_secs, phase);
                        observer.on_event(self.time_secs, "the user sees an error (ErrP)", false);
                    }
                }
                let readings = if params.avoidance.enabled {
                    self.world.proximity()
                } else {
                    [0.0; 8]
                };
                let safe = params.avoidance.apply(&readings, command, epuck);
                let applied = safe.apply_noise(epuck, &mut self.wheels_rng);
                self.world.step(applied.to_twist(epuck));
                self.time_secs += PHYSICS_DT_SECS;
                let pose = self.world.pose();
                self.tracked = self.tracker.observe(self.time_secs, &pose);
                if watching {
                    observer.on_physics(&PhysicsFrame {
                        time_secs: self.time_secs,
                        pose,
                        tracked: self.tracked,
                        wheels: applied,
                        phase,
                        target: goal,
                    });
                }
            }
            let fresh = self.eeg.advance();
            let p = self.eeg.p_error(&self.decoder.model);
            let decision = self.detector.push(p, self.time_secs);
            detected |= decision.detected;
            p_error.push(p);
            if watching {
                if decision.detected {
                    observer.on_event(
                        self.time_secs,
                        &format!("error detected (evidence {:.2})", decision.evidence),
                        false,
                    );
                }
                let fcz_cz = self.eeg.fcz_cz();
                observer.on_window(&WindowFrame {
                    time_secs: self.time_secs,
                    p_error: p,
                    evidence: decision.evidence,
                    belief: Vec::new(),
                    target: goal,
                    detected: decision.detected,
                    step: match phase {
                        2 if self.on_goal().is_some() => 2,
                        2 => 3,
                        p => p,
                    },
                    tracked: self.tracked,
                    fcz_cz: [
                        fresh.channel(fcz_cz[0]).to_vec(),
                        fresh.channel(fcz_cz[1]).to_vec(),
                    ],
                });
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
                observer.on_event(
                    self.time_secs,
                    &format!("stopped on {name} ({whose})"),
                    g != goal,
                );
                observer.on_end(self.time_secs, Some(g));
            }
        }
        Ok(EpuckFeedback {
            tracked: self.tracked,
            p_error,
            detected,
            errps,
            on_goal,
            time_secs: self.time_secs,
            window: keep_window.then(|| self.eeg.window().clone()),
        })
    }

    /// The goal within the scenario's goal radius of the true pose, if any.
    fn on_goal(&self) -> Option<usize> {
        let pose = self.world.pose();
        let radius = self.scenario.params.control.goal_radius_m;
        self.scenario.layout.goals().iter().position(|g| {
            (g.x_m - pose.x_m).powi(2) + (g.y_m - pose.y_m).powi(2) <= radius * radius
        })
    }
}
