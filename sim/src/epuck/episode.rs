//! One episode of the continuous task (sec. 5 of the paper): the e-puck in
//! the rapier2d arena, the overhead tracker, the synthetic user, streamed
//! EEG, the sliding-window SVM and the shared control, in one loop.
//!
//! Time advances in physics steps of 1/64 s (4 EEG samples). Every 4 steps
//! (62.5 ms, the paper's window step) 16 more EEG samples are streamed
//! through the preprocessing, the 800 ms window is decoded into p(error) and
//! the controller updates its belief (eq. 6-7) and reacts to a detection.

use errp_bci::{
    Accuracy, AssessmentKind, Detector, DetectorParams, EegBlock, ResponseSpan,
    rng::{derive_seed, stream},
};
use errp_robot::{
    AvoidanceParams, ContinuousControlParams, ContinuousController, GoalLayout, Phase, Pose,
    StepKind, WheelSpeeds, wrap_angle,
};
use serde::{Deserialize, Serialize};

use crate::epuck::decoder::ContinuousDecoder;
use crate::epuck::tracker::{CameraTracker, TrackerParams};
use crate::epuck::user::{SyntheticUser, UserParams};
use crate::epuck::world::{ArenaSpec, World};
use crate::error::{Result, SimError};

/// Everything that shapes a continuous episode besides the decoder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpuckTaskParams {
    /// Shared control and motion (sec. 5.1-5.2).
    pub control: ContinuousControlParams,
    /// The synthetic user.
    pub user: UserParams,
    /// The ceiling camera.
    pub tracker: TrackerParams,
    /// Obstacle reflex.
    pub avoidance: AvoidanceParams,
    /// How window outputs become detected errors.
    pub detector: DetectorParams,
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
            control: ContinuousControlParams::default(),
            user: UserParams::default(),
            tracker: TrackerParams::default(),
            avoidance: AvoidanceParams::default(),
            detector: DetectorParams::default(),
            max_secs: 600.0,
        }
    }
}

/// Physics steps per decoder window step.
pub const STEPS_PER_WINDOW: usize = 4;
/// The decoder's window step: 62.5 ms (sec. 2.2.2).
pub const WINDOW_STEP_SECS: f64 = errp_bci::WINDOW_STEP_SECS;
/// The physics time step (s).
pub const PHYSICS_DT_SECS: f64 = WINDOW_STEP_SECS / STEPS_PER_WINDOW as f64;
/// 0 turning, 1 driving, 2 stopped.
fn phase_index(phase: Phase) -> usize {
    match phase {
        Phase::Turning => 0,
        Phase::Driving => 1,
        Phase::Stopped { .. } => 2,
    }
}

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

/// An episode: where the e-puck starts and which goal the user wants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpuckEpisode {
    /// Start pose.
    pub start: Pose,
    /// Index of the user's goal in the layout.
    pub goal: usize,
}

/// What one continuous episode produced.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpuckEpisodeResult {
    /// The user's goal.
    pub goal: usize,
    /// The goal the belief converged on while the robot stood on it.
    pub committed: Option<usize>,
    /// Time from the start to convergence, or to the time-out (s).
    pub time_secs: f64,
    /// Errors detected: the detector's events that the controller used
    /// (while turning or driving each stopped the robot; on a goal each
    /// vetoed it).
    pub detected_errors: usize,
    /// Of those, while turning, while driving, and while stopped on a goal.
    pub detected_by_phase: [usize; 3],
    /// The true detections by what the user was judging when the ErrP
    /// behind each was elicited: a turn, a drive, or a stop.
    pub true_by_judged_phase: [usize; 3],
    /// Detections with no ErrP behind them (none within the detector's
    /// response span before them).
    pub false_detections: usize,
    /// ErrPs whose response span ended within the episode with no
    /// detection in it.
    pub missed_errors: usize,
    /// ErrPs elicited (error onsets and re-elicitations).
    pub errps: usize,
    /// ErrPs scored (their response span ended within the episode).
    pub errps_scored: usize,
    /// Error-free time the detector watched (s): windows outside every
    /// ErrP's response span, the stops after a detection excluded.
    pub clean_secs: f64,
    /// Per-window accuracy at T_e: windows inside an ErrP's window response
    /// span against windows with no ErrP near.
    pub online: Accuracy,
    /// Distance driven (m).
    pub path_m: f64,
    /// Largest sideways speed of the body seen over the episode (m/s).
    pub max_lateral_m_per_s: f64,
    /// Where errors were detected (true positions, m).
    pub detections: Vec<[f64; 2]>,
}

impl EpuckEpisodeResult {
    /// True if the robot converged on the user's goal.
    pub fn reached(&self) -> bool {
        self.committed == Some(self.goal)
    }

    /// Share of the scored ErrPs that a detection followed (NaN if none).
    pub fn hit_rate(&self) -> f64 {
        if self.errps_scored == 0 {
            f64::NAN
        } else {
            (self.errps_scored - self.missed_errors) as f64 / self.errps_scored as f64
        }
    }

    /// False detections per minute of error-free time (NaN if none).
    pub fn false_alarms_per_min(&self) -> f64 {
        if self.clean_secs <= 0.0 {
            f64::NAN
        } else {
            self.false_detections as f64 / (self.clean_secs / 60.0)
        }
    }
}

/// Runs one episode to convergence or time-out. Every random stream (EEG,
/// tracker, wheels) is derived from `seed`.
pub fn run_epuck_episode(
    params: &EpuckTaskParams,
    arena: &ArenaSpec,
    layout: &GoalLayout,
    episode: EpuckEpisode,
    decoder: &ContinuousDecoder,
    seed: u64,
    observer: &mut impl EpuckObserver,
) -> Result<EpuckEpisodeResult> {
    run_epuck_episode_with(
        params, arena, layout, episode, decoder, seed, observer, None,
    )
}

/// A decoder of the user's own for the e-puck: given the sliding window
/// every 62.5 ms (the last 800 ms of preprocessed EEG, `(n_channels,
/// n_samples)`), it returns p(error), a number from 0 to 1.
pub type WindowDecoder<'a> = &'a mut (dyn FnMut(&EegBlock) -> Result<f64> + Send);

/// [`run_epuck_episode`] with `window_decoder`, if given, in place of the
/// calibrated SVM: the EEG, its preprocessing and everything else are the
/// scenario's. Its p(error) goes through the scenario's detector at the
/// scenario's `control.t_e`, and is scored over the response spans measured
/// for the built-in decoder.
#[allow(clippy::too_many_arguments)]
pub fn run_epuck_episode_with(
    params: &EpuckTaskParams,
    arena: &ArenaSpec,
    layout: &GoalLayout,
    episode: EpuckEpisode,
    decoder: &ContinuousDecoder,
    seed: u64,
    observer: &mut impl EpuckObserver,
    mut window_decoder: Option<WindowDecoder<'_>>,
) -> Result<EpuckEpisodeResult> {
    if episode.goal >= layout.goals().len() {
        return Err(SimError::Scenario(format!(
            "goal index {} is not in the layout of {} goals",
            episode.goal,
            layout.goals().len()
        )));
    }
    let mut world = World::new(arena, &params.control.epuck, episode.start, PHYSICS_DT_SECS)?;
    let mut tracker = CameraTracker::new(params.tracker, stream(seed, "epuck/tracker"));
    let mut wheels_rng = stream(seed, "epuck/wheels");
    let mut user = SyntheticUser::new(params.user, layout, episode.goal);
    let span = decoder.detection_span();
    let window_span = decoder.window_span();
    let mut control = params.control.clone();
    // Left open by the scenario: long enough for the user's verdict on the
    // arrival to reach the detector, and the end of its response span.
    control.goal_hold_secs = Some(params.goal_hold_secs(&span));
    control.veto_window_secs = Some(params.control.veto_window_secs.unwrap_or(span.to_secs));
    let mut controller = ContinuousController::new(control, layout.clone(), episode.start)?;
    let t_e = match window_decoder {
        Some(_) => params.control.t_e,
        None => decoder.t_e(params.control.t_e),
    };
    let mut detector = Detector::new(params.detector, t_e)?;
    let mut eeg = decoder.start_stream(derive_seed(seed, "epuck/eeg", 0))?;
    let fcz_cz = eeg.fcz_cz();

    let watching = observer.watches();
    if watching {
        observer.on_start(&EpisodeStart {
            pose: world.pose(),
            goal: episode.goal,
            t_e,
            detection_span: (span.from_secs, span.to_secs),
            window_span: (window_span.from_secs, window_span.to_secs),
        });
        let goal_name = &layout.goals()[episode.goal].name;
        observer.on_event(0.0, &format!("the user wants {goal_name}"), false);
    }

    let mut time_secs = 0.0;
    let mut pose = world.pose();
    let mut tracked = tracker.observe(0.0, &pose);
    // Each ErrP's time zero, and the phase the user was judging.
    let mut errps: Vec<(f64, usize)> = Vec::new();
    let mut recent = 0; // first ErrP whose spans can still hold a window
    let mut detections: Vec<f64> = Vec::new();
    let mut detected_at = Vec::new();
    let mut by_phase = [0usize; 3];
    let mut by_judged = [0usize; 3];
    let mut false_detections = 0usize;
    let (mut hits, mut n_err_windows, mut false_alarms, mut n_clean_windows) = (0, 0, 0, 0);
    let mut clean_windows = 0usize;
    let mut path_m = 0.0;
    let mut max_lateral: f64 = 0.0;
    let mut committed = None;
    let n_windows = (params.max_secs / WINDOW_STEP_SECS).ceil() as usize;
    let horizon = span.to_secs.max(window_span.to_secs) + WINDOW_STEP_SECS;
    let mut last_target = controller.target();
    'episode: for _ in 0..n_windows {
        for _ in 0..STEPS_PER_WINDOW {
            if let Some(e) = user.observe(time_secs, &tracked) {
                if e.kind == AssessmentKind::Error {
                    let phase = phase_index(controller.phase());
                    errps.push((e.onset_secs, phase));
                    if watching {
                        observer.on_errp(time_secs, e.onset_secs, phase);
                    }
                }
                eeg.schedule(e.onset_secs, e.kind);
                if watching && e.kind == AssessmentKind::Error {
                    observer.on_event(time_secs, "the user sees an error (ErrP)", false);
                }
            }
            let command = controller.command(&tracked, time_secs);
            let readings = if params.avoidance.enabled {
                world.proximity()
            } else {
                [0.0; 8]
            };
            let safe = params
                .avoidance
                .apply(&readings, command, &params.control.epuck);
            let applied = safe.apply_noise(&params.control.epuck, &mut wheels_rng);
            world.step(applied.to_twist(&params.control.epuck));
            time_secs += PHYSICS_DT_SECS;
            let next = world.pose();
            let (dx, dy) = (next.x_m - pose.x_m, next.y_m - pose.y_m);
            let mid = pose.heading_rad + 0.5 * wrap_angle(next.heading_rad - pose.heading_rad);
            let lateral = (-mid.sin() * dx + mid.cos() * dy) / PHYSICS_DT_SECS;
            max_lateral = max_lateral.max(lateral.abs());
            path_m += (dx * dx + dy * dy).sqrt();
            pose = next;
            tracked = tracker.observe(time_secs, &pose);
            if watching {
                observer.on_physics(&PhysicsFrame {
                    time_secs,
                    pose,
                    tracked,
                    wheels: applied,
                    phase: phase_index(controller.phase()),
                    target: controller.target(),
                });
            }
        }

        let fresh = eeg.advance();
        let p_error = match window_decoder.as_mut() {
            Some(decode) => crate::grid::check_p_error(decode(eeg.window())?)?,
            None => eeg.p_error(&decoder.model),
        };
        let decision = detector.push(p_error, time_secs);
        let obs = controller.observe(decision.detected, &tracked, time_secs)?;
        let used = obs.step != StepKind::Idle;

        // Scoring of this window against the ErrPs the user produced.
        while recent < errps.len() && errps[recent].0 < time_secs - horizon {
            recent += 1;
        }
        let errps_near = &errps[recent..];
        let says_error = p_error >= t_e;
        let in_window_span = errps_near
            .iter()
            .any(|&(o, _)| window_span.contains(o, time_secs));
        let near_errp = errps_near.iter().any(|&(o, _)| {
            o <= time_secs && time_secs - o <= window_span.to_secs + WINDOW_STEP_SECS
        });
        if in_window_span {
            n_err_windows += 1;
            hits += usize::from(says_error);
        } else if !near_errp {
            n_clean_windows += 1;
            false_alarms += usize::from(says_error);
        }
        // The latest ErrP whose detection span holds this window, if any.
        let judged = errps_near
            .iter()
            .rev()
            .find(|&&(o, _)| span.contains(o, time_secs))
            .map(|&(_, phase)| phase);
        let real = judged.is_some();
        if used && !real {
            clean_windows += 1;
        }
        let detected = decision.detected && used;
        if detected {
            detections.push(time_secs);
            detected_at.push([pose.x_m, pose.y_m]);
            by_phase[match obs.step {
                StepKind::Turn { .. } => 0,
                StepKind::Linear => 1,
                _ => 2,
            }] += 1;
            match judged {
                Some(k) => by_judged[k] += 1,
                None => false_detections += 1,
            }
            if watching {
                let what = if obs.detected {
                    format!("stop {:.0} s", params.control.stop_secs)
                } else {
                    "a veto of the goal".to_string()
                };
                observer.on_event(
                    time_secs,
                    &format!(
                        "error detected (evidence {:.2}){}: {what}",
                        decision.evidence,
                        if real { "" } else { ", a false positive" },
                    ),
                    !real,
                );
            }
        }
        if watching && controller.target() != last_target {
            last_target = controller.target();
            observer.on_event(
                time_secs,
                &format!("new goal: {}", layout.goals()[last_target].name),
                false,
            );
        }
        if watching {
            observer.on_window(&WindowFrame {
                time_secs,
                p_error,
                evidence: decision.evidence,
                belief: controller.belief().probabilities(),
                target: controller.target(),
                detected,
                step: match obs.step {
                    StepKind::Turn { .. } => 0,
                    StepKind::Linear => 1,
                    StepKind::StopOnGoal(_) => 2,
                    StepKind::Idle => 3,
                },
                tracked,
                fcz_cz: [
                    fresh.channel(fcz_cz[0]).to_vec(),
                    fresh.channel(fcz_cz[1]).to_vec(),
                ],
            });
        }
        if let Some(j) = obs.converged {
            committed = Some(j);
            observer.on_event(
                time_secs,
                &format!(
                    "converged on {} ({})",
                    layout.goals()[j].name,
                    if j == episode.goal {
                        "the user's goal"
                    } else {
                        "a wrong goal"
                    }
                ),
                j != episode.goal,
            );
            break 'episode;
        }
    }
    if committed.is_none() {
        observer.on_event(time_secs, "time-out: no convergence", true);
    }
    if watching {
        observer.on_end(time_secs, committed);
    }

    // ErrPs whose detection span closed within the episode, and those of
    // them with no detection in it.
    let scored: Vec<f64> = errps
        .iter()
        .map(|&(o, _)| o)
        .filter(|&o| o + span.to_secs <= time_secs)
        .collect();
    let missed_errors = scored
        .iter()
        .filter(|&&o| !detections.iter().any(|&t| span.contains(o, t)))
        .count();
    Ok(EpuckEpisodeResult {
        goal: episode.goal,
        committed,
        time_secs,
        detected_errors: detections.len(),
        detected_by_phase: by_phase,
        true_by_judged_phase: by_judged,
        false_detections,
        missed_errors,
        errps: errps.len(),
        errps_scored: scored.len(),
        clean_secs: clean_windows as f64 * WINDOW_STEP_SECS,
        online: Accuracy {
            correct: 1.0 - false_alarms as f64 / n_clean_windows.max(1) as f64,
            error: hits as f64 / n_err_windows.max(1) as f64,
            n_correct: n_clean_windows,
            n_error: n_err_windows,
        },
        path_m,
        max_lateral_m_per_s: max_lateral,
        detections: detected_at,
    })
}
