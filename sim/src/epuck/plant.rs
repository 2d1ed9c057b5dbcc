//! The e-puck's closed loop below the decision maker, one copy for both
//! ways of driving it: an episode of the shared control
//! ([`crate::epuck::run_epuck_episode`]) and the environment an agent steps
//! ([`crate::epuck::EpuckEnvironment`]).
//!
//! Time advances in physics steps of 1/64 s (4 EEG samples). In each step
//! the synthetic user judges the motion the camera saw (an ErrP is
//! scheduled into the EEG), the driver commands the wheels, the obstacle
//! reflex and the wheel noise act, rapier2d moves the robot and the camera
//! tracks it. Every 4 steps (62.5 ms, the paper's window step) 16 more EEG
//! samples are streamed through the preprocessing, the 800 ms window is
//! decoded into p(error) and the detector reads it at T_e.

use errp_bci::{
    AssessmentKind, Decision, Detector, EegBlock, SlidingWindow,
    rng::{derive_seed, labelled},
};
use errp_robot::{
    AvoidanceParams, EpuckController, EpuckParams, Phase, Pose, WheelSpeeds, wrap_angle,
};
use rand_chacha::ChaCha8Rng;

use crate::epuck::decoder::ContinuousDecoder;
use crate::epuck::observer::{EpisodeStart, EpuckObserver, PhysicsFrame, WindowFrame};
use crate::epuck::scenario::EpuckScenario;
use crate::epuck::tracker::CameraTracker;
use crate::epuck::user::SyntheticUser;
use crate::epuck::world::World;
use crate::error::{Result, SimError, check_p_error};

/// Physics steps per decoder window step.
pub const STEPS_PER_WINDOW: usize = 4;
/// The decoder's window step: 62.5 ms (sec. 2.2.2).
pub const WINDOW_STEP_SECS: f64 = errp_bci::WINDOW_STEP_SECS;
/// The physics time step (s).
pub const PHYSICS_DT_SECS: f64 = WINDOW_STEP_SECS / STEPS_PER_WINDOW as f64;

/// The distance (m) and the sideways speed (m/s, its size) of one physics
/// step from `from` to `to`: what an episode measures of the motion, and
/// what `errp inspect` measures again from a recording's frames.
pub(crate) fn step_motion(from: Pose, to: Pose) -> (f64, f64) {
    let (dx, dy) = (to.x_m - from.x_m, to.y_m - from.y_m);
    let mid = from.heading_rad + 0.5 * wrap_angle(to.heading_rad - from.heading_rad);
    let lateral = (-mid.sin() * dx + mid.cos() * dy) / PHYSICS_DT_SECS;
    ((dx * dx + dy * dy).sqrt(), lateral.abs())
}

/// A decoder of the user's own for the e-puck: given the sliding window
/// every 62.5 ms (the last 800 ms of preprocessed EEG, `(n_channels,
/// n_samples)`), it returns p(error), a number from 0 to 1.
pub type WindowDecoder<'a> = &'a mut (dyn FnMut(&EegBlock) -> Result<f64> + Send);

/// One window of a live episode, as the live decoder is told of it: the
/// raw EEG of its last 62.5 ms (to stream) and what the device is doing.
#[derive(Debug, Clone, Copy)]
pub struct LiveWindow<'b> {
    /// The raw samples of the hop, all channels `(n_channels, 16)`.
    pub raw: &'b EegBlock,
    /// The episode time at the window's end (s).
    pub time_secs: f64,
    /// What the robot is doing ([`crate::epuck::PHASE_NAMES`]).
    pub phase: usize,
    /// The goal it heads for.
    pub target: usize,
    /// The pose the camera sees.
    pub tracked: Pose,
    /// The belief over the goals before the window.
    pub belief: &'b [f64],
    /// On the episode's first window: the raw EEG of the 2 s before time 0
    /// (the filters' warm-up), to stream first.
    pub warm_up: Option<&'b EegBlock>,
}

/// A live window decoder: streams the window's raw EEG in real time and
/// returns the p(error)s a decoder outside sent in time for it, in order
/// (none, one or several), each read by the detector.
pub type LiveWindowDecoder<'a> = &'a mut (dyn FnMut(&LiveWindow<'_>) -> Result<Vec<f64>> + Send);

/// How a window's p(error) is found.
pub enum WindowDecoding<'d, 'a> {
    /// The calibrated SVM of the decoder.
    Builtin,
    /// A decoder of the user's own, given the preprocessed window.
    Own(&'d mut WindowDecoder<'a>),
    /// A decoder outside the process, live, told `belief` (the belief
    /// before the window).
    Live(&'d mut LiveWindowDecoder<'a>, &'d [f64]),
}

/// What moves the e-puck, physics step by physics step: the shared control
/// in an episode, an agent's motion primitive in the environment.
pub trait EpuckDriver {
    /// What the robot is doing ([`crate::epuck::PHASE_NAMES`]): 0 turning,
    /// 1 driving, 2 stopped.
    fn phase(&self) -> usize;
    /// The goal the robot heads for.
    fn target(&self) -> usize;
    /// The wheel command for the next physics step, from the pose the
    /// camera saw at `time_secs`.
    fn command(&mut self, tracked: &Pose, time_secs: f64) -> WheelSpeeds;
}

/// The shared control drives in an episode.
impl EpuckDriver for EpuckController {
    fn phase(&self) -> usize {
        match EpuckController::phase(self) {
            Phase::Turning => 0,
            Phase::Driving => 1,
            Phase::Stopped { .. } => 2,
        }
    }

    fn target(&self) -> usize {
        EpuckController::target(self)
    }

    fn command(&mut self, tracked: &Pose, time_secs: f64) -> WheelSpeeds {
        EpuckController::command(self, tracked, time_secs)
    }
}

/// One decoder window of the loop.
#[derive(Debug, Clone)]
pub struct PlantWindow {
    /// The decoder's output.
    pub p_error: f64,
    /// The detector's verdict on it.
    pub decision: Decision,
    /// The ErrPs the user produced in the window: each one's time zero and
    /// the phase the user was judging ([`crate::epuck::PHASE_NAMES`]).
    pub errps: Vec<(f64, usize)>,
    /// The preprocessed samples of the last 62.5 ms.
    fresh: EegBlock,
}

/// The world, the camera, the wheels, the user, the EEG stream and the
/// detector of one episode, and what it measured on the way.
pub struct EpuckPlant {
    world: World,
    tracker: CameraTracker,
    wheels_rng: ChaCha8Rng,
    user: SyntheticUser,
    eeg: SlidingWindow,
    detector: Detector,
    t_e: f64,
    avoidance: AvoidanceParams,
    epuck: EpuckParams,
    time_secs: f64,
    pose: Pose,
    tracked: Pose,
    path_m: f64,
    max_lateral_m_per_s: f64,
}

impl EpuckPlant {
    /// The loop of an episode of `scenario` from its start pose, the user
    /// wanting `goal` of its layout, its detector at the T_e of `decoder`
    /// (or the scenario's, for a decoder of the user's own:
    /// `own_decoder`), every random stream (camera, wheels, EEG) derived
    /// from `seed`.
    pub fn new(
        scenario: &EpuckScenario,
        goal: usize,
        decoder: &ContinuousDecoder,
        own_decoder: bool,
        seed: u64,
    ) -> Result<Self> {
        let n = scenario.layout.len();
        if goal >= n {
            return Err(SimError::OutOfRange {
                name: "goal".into(),
                given: format!("{goal} is not a goal of the layout"),
                expected: format!("0 to {}", n - 1),
            });
        }
        let params = &scenario.params;
        let t_e = decoder.detector_t_e(params, own_decoder);
        let world = World::new(
            &scenario.arena,
            &params.control.epuck,
            scenario.episode.start,
            PHYSICS_DT_SECS,
        )?;
        let mut tracker = CameraTracker::new(params.tracker, labelled(seed, "epuck/tracker"));
        let pose = world.pose();
        let tracked = tracker.observe(0.0, &pose);
        Ok(Self {
            world,
            tracker,
            wheels_rng: labelled(seed, "epuck/wheels"),
            user: SyntheticUser::new(params.user, &scenario.layout, goal),
            eeg: decoder.start_stream(derive_seed(seed, "epuck/eeg", 0))?,
            detector: Detector::new(params.detector, t_e)?,
            t_e,
            avoidance: params.avoidance,
            epuck: params.control.epuck,
            time_secs: 0.0,
            pose,
            tracked,
            path_m: 0.0,
            max_lateral_m_per_s: 0.0,
        })
    }

    /// Runs one decoder window: [`STEPS_PER_WINDOW`] physics steps driven
    /// by `driver`, then p(error) of the new window as `decoding` says (a
    /// decoder of the user's own, one outside, or the calibrated SVM of
    /// `decoder`), and the detector's verdict. A live decoder's window
    /// without a p(error) has none (not a number) and detects nothing. `observer` sees the user's
    /// ErrPs and every physics step; the window is the caller's to report
    /// ([`EpuckPlant::window_frame`]), with what the driver made of it.
    pub fn window(
        &mut self,
        driver: &mut impl EpuckDriver,
        decoder: &ContinuousDecoder,
        decoding: WindowDecoding<'_, '_>,
        observer: &mut impl EpuckObserver,
    ) -> Result<PlantWindow> {
        let watching = observer.watches();
        let mut errps = Vec::new();
        for _ in 0..STEPS_PER_WINDOW {
            if let Some(e) = self.user.observe(self.time_secs, &self.tracked) {
                if e.kind == AssessmentKind::Error {
                    let phase = driver.phase();
                    errps.push((e.onset_secs, phase));
                    if watching {
                        observer.on_errp(self.time_secs, e.onset_secs, phase);
                        observer.on_event(self.time_secs, "the user sees an error (ErrP)", false);
                    }
                }
                self.eeg.schedule(e.onset_secs, e.kind);
            }
            let command = driver.command(&self.tracked, self.time_secs);
            let applied = self.physics_step(command);
            if watching {
                observer.on_physics(&PhysicsFrame {
                    time_secs: self.time_secs,
                    pose: self.pose,
                    tracked: self.tracked,
                    wheels: applied,
                    phase: driver.phase(),
                    target: driver.target(),
                });
            }
        }
        let fresh = self.eeg.advance();
        let p_error = match decoding {
            WindowDecoding::Own(decode) => check_p_error(decode(self.eeg.window())?)?,
            WindowDecoding::Builtin => self.eeg.p_error(&decoder.model),
            WindowDecoding::Live(decide, belief) => {
                let got = decide(&LiveWindow {
                    raw: self.eeg.raw(),
                    time_secs: self.time_secs,
                    phase: driver.phase(),
                    target: driver.target(),
                    tracked: self.tracked,
                    belief,
                    warm_up: (self.time_secs <= WINDOW_STEP_SECS + 1e-9)
                        .then(|| self.eeg.warm_up_raw()),
                })?;
                return self.live_window(&got, errps, fresh);
            }
        };
        let decision = self.detector.push(p_error, self.time_secs);
        Ok(PlantWindow {
            p_error,
            decision,
            errps,
            fresh,
        })
    }

    /// The window of a live decoder that sent the p(error)s `got` for it:
    /// the detector reads each; the window detects if any detection fired.
    fn live_window(
        &mut self,
        got: &[f64],
        errps: Vec<(f64, usize)>,
        fresh: EegBlock,
    ) -> Result<PlantWindow> {
        let mut decision = Decision {
            evidence: f64::NAN,
            detected: false,
        };
        let mut p_error = f64::NAN;
        for &p in got {
            p_error = check_p_error(p)?;
            let d = self.detector.push(p, self.time_secs);
            if !decision.detected {
                decision = d;
            }
        }
        Ok(PlantWindow {
            p_error,
            decision,
            errps,
            fresh,
        })
    }

    /// One physics step under `command`: the obstacle reflex, the wheel
    /// noise, rapier2d, the camera. Returns the wheel speeds applied.
    fn physics_step(&mut self, command: WheelSpeeds) -> WheelSpeeds {
        let readings = if self.avoidance.enabled {
            self.world.proximity()
        } else {
            [0.0; 8]
        };
        let safe = self.avoidance.apply(&readings, command, &self.epuck);
        let applied = safe.apply_noise(&self.epuck, &mut self.wheels_rng);
        self.world.step(applied.to_twist(&self.epuck));
        self.time_secs += PHYSICS_DT_SECS;
        let next = self.world.pose();
        let (distance, lateral) = step_motion(self.pose, next);
        self.max_lateral_m_per_s = self.max_lateral_m_per_s.max(lateral);
        self.path_m += distance;
        self.pose = next;
        self.tracked = self.tracker.observe(self.time_secs, &next);
        applied
    }

    /// What an observer is told of window `w`: the driver's belief, target
    /// and use of the detection, and the step it took (0 turn, 1 linear, 2
    /// stopped on a goal, 3 idle; [`crate::epuck::STEP_NAMES`]).
    pub fn window_frame(
        &self,
        w: &PlantWindow,
        belief: Vec<f64>,
        target: usize,
        detected: bool,
        step: usize,
    ) -> WindowFrame {
        let [fcz, cz] = self.eeg.fcz_cz();
        WindowFrame {
            time_secs: self.time_secs,
            p_error: w.p_error,
            evidence: w.decision.evidence,
            belief,
            target,
            detected,
            step,
            tracked: self.tracked,
            fcz_cz: [w.fresh.channel(fcz).to_vec(), w.fresh.channel(cz).to_vec()],
        }
    }

    /// What an observer is told when the episode starts, so that it can
    /// score the episode again from what it observes: the detector's T_e
    /// and the response spans of `decoder`.
    pub fn start(&self, decoder: &ContinuousDecoder) -> EpisodeStart {
        let span = decoder.detection_span();
        let window_span = decoder.window_span();
        EpisodeStart {
            pose: self.pose,
            goal: self.user.goal(),
            t_e: self.t_e,
            detection_span: (span.from_secs, span.to_secs),
            window_span: (window_span.from_secs, window_span.to_secs),
        }
    }

    /// Episode time (s).
    pub fn time_secs(&self) -> f64 {
        self.time_secs
    }

    /// The true pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// The pose the camera sees.
    pub fn tracked(&self) -> Pose {
        self.tracked
    }

    /// The detector's threshold on p(error).
    pub fn t_e(&self) -> f64 {
        self.t_e
    }

    /// The user's goal.
    pub fn goal(&self) -> usize {
        self.user.goal()
    }

    /// The current window of preprocessed EEG, `(n_channels, n_samples)`.
    pub fn eeg_window(&self) -> &EegBlock {
        self.eeg.window()
    }

    /// Distance driven so far (m).
    pub fn path_m(&self) -> f64 {
        self.path_m
    }

    /// The largest sideways speed of the body seen so far (m/s).
    pub fn max_lateral_m_per_s(&self) -> f64 {
        self.max_lateral_m_per_s
    }
}
