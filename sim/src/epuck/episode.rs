//! One episode of the continuous task (sec. 5 of the paper): the shared
//! control drives the loop of [`EpuckPlant`](crate::epuck::EpuckPlant) (the e-puck in the
//! rapier2d arena, the overhead tracker, the synthetic user, streamed EEG,
//! the sliding-window SVM and the detector). After each 62.5 ms window the
//! controller updates its belief (eq. 6-7) and reacts to a detection, and
//! the window is scored against the ErrPs the user produced.

use errp_bci::{Accuracy, ResponseSpan};
use errp_robot::{EpuckController, StepKind};
use serde::{Deserialize, Serialize};

use crate::epuck::decoder::ContinuousDecoder;
use crate::epuck::observer::EpuckObserver;
use crate::epuck::plant::{
    EpuckPlant, LiveWindowDecoder, WINDOW_STEP_SECS, WindowDecoder, WindowDecoding,
};
use crate::epuck::scenario::EpuckScenario;
use crate::error::Result;

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

/// Runs one episode of `scenario` to convergence or time-out. Every random
/// stream (EEG, tracker, wheels) is derived from `seed`.
pub fn run_epuck_episode(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    seed: u64,
    observer: &mut impl EpuckObserver,
) -> Result<EpuckEpisodeResult> {
    run_epuck_episode_with(scenario, decoder, seed, observer, None)
}

/// [`run_epuck_episode`] with `window_decoder`, if given, in place of the
/// calibrated SVM: the EEG, its preprocessing and everything else are the
/// scenario's. Its p(error) goes through the scenario's detector at the
/// scenario's `control.t_e`, and is scored over the response spans measured
/// for the built-in decoder.
pub fn run_epuck_episode_with(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    seed: u64,
    observer: &mut impl EpuckObserver,
    mut window_decoder: Option<WindowDecoder<'_>>,
) -> Result<EpuckEpisodeResult> {
    let mode = match window_decoder.as_mut() {
        Some(d) => Mode::Own(d),
        None => Mode::Builtin,
    };
    run_episode(scenario, decoder, seed, observer, mode)
}

/// [`run_epuck_episode`] with a decoder outside the process, live
/// (`errp stream`): `live` streams each window's raw EEG and returns the
/// p(error)s that came for it, and `observer` watches (a recording). The
/// detector runs at the scenario's `control.t_e`, as for a decoder of the
/// user's own.
pub fn run_epuck_episode_live(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    seed: u64,
    live: LiveWindowDecoder<'_>,
    observer: &mut impl EpuckObserver,
) -> Result<EpuckEpisodeResult> {
    run_episode(scenario, decoder, seed, observer, Mode::Live(live))
}

/// Which decoder reads the windows of an episode.
enum Mode<'d, 'a> {
    Builtin,
    Own(&'d mut WindowDecoder<'a>),
    Live(LiveWindowDecoder<'a>),
}

/// The one episode loop of every [`Mode`].
fn run_episode(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    seed: u64,
    observer: &mut impl EpuckObserver,
    mut mode: Mode<'_, '_>,
) -> Result<EpuckEpisodeResult> {
    let goal = scenario.episode.goal;
    let names = scenario.layout.goals();
    let own = !matches!(mode, Mode::Builtin);
    let mut plant = EpuckPlant::new(scenario, goal, decoder, own, seed)?;
    let mut controller = shared_control(scenario, decoder)?;
    let mut score = Score::new(decoder.detection_span(), decoder.window_span(), plant.t_e());
    let watching = observer.watches();
    if watching {
        observer.on_start(&plant.start(decoder));
        let goal_name = &names[goal].name;
        observer.on_event(0.0, &format!("the user wants {goal_name}"), false);
    }
    let n_windows = (scenario.params.max_secs / WINDOW_STEP_SECS).ceil() as usize;
    let mut last_target = controller.target();
    let mut committed = None;
    for k in 0..n_windows {
        // A stop request (Ctrl-C in Python) ends a long run within a second
        // of simulated time, not at its end.
        if k % 16 == 0 {
            errp_bci::stop::check()?;
        }
        let live = matches!(mode, Mode::Live(_));
        let belief = live.then(|| controller.belief().probabilities());
        let decoding = match &mut mode {
            Mode::Builtin => WindowDecoding::Builtin,
            Mode::Own(d) => WindowDecoding::Own(&mut **d),
            Mode::Live(d) => WindowDecoding::Live(d, belief.as_deref().unwrap_or_default()),
        };
        let w = plant.window(&mut controller, decoder, decoding, observer)?;
        let time_secs = plant.time_secs();
        let obs = controller.observe(w.decision.detected, &plant.tracked(), time_secs)?;
        let used = obs.step != StepKind::Idle;
        let detected = w.decision.detected && used;
        for &(onset, phase) in &w.errps {
            score.errp(onset, phase);
        }
        let pose = plant.pose();
        let step = step_index(obs.step);
        let real = score.window(time_secs, w.p_error, step, detected, [pose.x_m, pose.y_m]);
        if watching {
            if detected {
                let what = if obs.detected {
                    format!("stop {:.0} s", scenario.params.control.stop_secs)
                } else {
                    "a veto of the goal".to_string()
                };
                let fp = if real { "" } else { ", a false positive" };
                let evidence = w.decision.evidence;
                observer.on_event(
                    time_secs,
                    &format!("error detected (evidence {evidence:.2}){fp}: {what}"),
                    !real,
                );
            }
            if controller.target() != last_target {
                last_target = controller.target();
                let name = &names[last_target].name;
                observer.on_event(time_secs, &format!("new goal: {name}"), false);
            }
            let belief = controller.belief().probabilities();
            let frame = plant.window_frame(
                &w,
                belief,
                controller.target(),
                detected,
                step_index(obs.step),
            );
            observer.on_window(&frame);
        }
        if let Some(j) = obs.converged {
            committed = Some(j);
            if watching {
                let whose = if j == goal {
                    "the user's goal"
                } else {
                    "a wrong goal"
                };
                let name = &names[j].name;
                observer.on_event(
                    time_secs,
                    &format!("converged on {name} ({whose})"),
                    j != goal,
                );
            }
            break;
        }
    }
    if watching {
        if committed.is_none() {
            observer.on_event(plant.time_secs(), "time-out: no convergence", true);
        }
        observer.on_end(plant.time_secs(), committed);
    }
    let (time_secs, path_m) = (plant.time_secs(), plant.path_m());
    Ok(score.finish(
        goal,
        committed,
        time_secs,
        path_m,
        plant.max_lateral_m_per_s(),
    ))
}

/// The shared control of an episode of `scenario` with `decoder`. Left
/// open by the scenario: the stop on a goal, long enough for the user's
/// verdict on the arrival to reach the detector, and the veto window, the
/// end of the detector's response span. On own EEG, the control assumes
/// the cross-validated accuracy it gives.
pub fn shared_control(
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
) -> Result<EpuckController> {
    let params = &scenario.params;
    let span = decoder.detection_span();
    // A changed copy of the scenario's checked parameters, checked again.
    let control = params.control.with(|c| {
        if let Some(r) = &decoder.own_eeg {
            c.assumed_accuracy = r.accuracy;
        }
        c.goal_hold_secs = Some(params.goal_hold_secs(&span));
        c.veto_window_secs = Some(c.veto_window_secs.unwrap_or(span.to_secs));
    })?;
    Ok(EpuckController::new(
        control,
        scenario.layout.clone(),
        scenario.episode.start,
    )?)
}

/// The controller's update on a window ([`crate::epuck::STEP_NAMES`]).
fn step_index(step: StepKind) -> usize {
    match step {
        StepKind::Turn { .. } => 0,
        StepKind::Linear => 1,
        StepKind::StopOnGoal(_) => 2,
        StepKind::Idle => 3,
    }
}

/// An episode's windows and detections scored against the ErrPs the user
/// produced: by the episode as it runs, and by `errp inspect` from a
/// recording's tables.
pub(crate) struct Score {
    span: ResponseSpan,
    window_span: ResponseSpan,
    t_e: f64,
    /// How long after its time zero an ErrP can still score a window.
    horizon: f64,
    /// Each ErrP's time zero, and the phase the user was judging.
    errps: Vec<(f64, usize)>,
    /// The first ErrP whose spans can still hold a window.
    recent: usize,
    detections: Vec<f64>,
    detected_at: Vec<[f64; 2]>,
    by_phase: [usize; 3],
    by_judged: [usize; 3],
    false_detections: usize,
    hits: usize,
    n_err_windows: usize,
    false_alarms: usize,
    n_clean_windows: usize,
    clean_windows: usize,
}

impl Score {
    /// Scoring over the detector's response `span` and the windows'
    /// `window_span`, with the detector at `t_e`.
    pub(crate) fn new(span: ResponseSpan, window_span: ResponseSpan, t_e: f64) -> Self {
        Self {
            span,
            window_span,
            t_e,
            horizon: span.to_secs.max(window_span.to_secs) + WINDOW_STEP_SECS,
            errps: Vec::new(),
            recent: 0,
            detections: Vec::new(),
            detected_at: Vec::new(),
            by_phase: [0; 3],
            by_judged: [0; 3],
            false_detections: 0,
            hits: 0,
            n_err_windows: 0,
            false_alarms: 0,
            n_clean_windows: 0,
            clean_windows: 0,
        }
    }

    /// The user produced an ErrP with time zero `onset`, judging a move in
    /// `phase` ([`crate::epuck::PHASE_NAMES`]).
    pub(crate) fn errp(&mut self, onset: f64, phase: usize) {
        self.errps.push((onset, phase));
    }

    /// Scores the window that ended at `time_secs` with `p_error` and the
    /// controller's `step` ([`crate::epuck::STEP_NAMES`]), and the
    /// detection the controller used (`detected`) with the robot `at` (m).
    /// True if an ErrP's detection span holds the window.
    pub(crate) fn window(
        &mut self,
        time_secs: f64,
        p_error: f64,
        step: usize,
        detected: bool,
        at: [f64; 2],
    ) -> bool {
        while self.recent < self.errps.len() && self.errps[self.recent].0 < time_secs - self.horizon
        {
            self.recent += 1;
        }
        let near = &self.errps[self.recent..];
        let says_error = p_error >= self.t_e;
        let window_span = self.window_span;
        let in_window_span = near
            .iter()
            .any(|&(o, _)| window_span.contains(o, time_secs));
        let near_errp = near.iter().any(|&(o, _)| {
            o <= time_secs && time_secs - o <= window_span.to_secs + WINDOW_STEP_SECS
        });
        if in_window_span {
            self.n_err_windows += 1;
            self.hits += usize::from(says_error);
        } else if !near_errp {
            self.n_clean_windows += 1;
            self.false_alarms += usize::from(says_error);
        }
        // The latest ErrP whose detection span holds this window, if any.
        let judged = near
            .iter()
            .rev()
            .find(|&&(o, _)| self.span.contains(o, time_secs))
            .map(|&(_, phase)| phase);
        let real = judged.is_some();
        // Step 3 is idle: stopped after a detection, not error-free time.
        if step != 3 && !real {
            self.clean_windows += 1;
        }
        if detected {
            self.detections.push(time_secs);
            self.detected_at.push(at);
            self.by_phase[step.min(2)] += 1;
            match judged {
                Some(k) => self.by_judged[k] += 1,
                None => self.false_detections += 1,
            }
        }
        real
    }

    /// The result of the episode that ended at `time_secs`, committed to
    /// `committed` (or timed out), after driving `path_m` with sideways
    /// speeds up to `max_lateral_m_per_s`.
    pub(crate) fn finish(
        self,
        goal: usize,
        committed: Option<usize>,
        time_secs: f64,
        path_m: f64,
        max_lateral_m_per_s: f64,
    ) -> EpuckEpisodeResult {
        // ErrPs whose detection span closed within the episode, and those of
        // them with no detection in it.
        let span = self.span;
        let scored: Vec<f64> = self
            .errps
            .iter()
            .map(|&(o, _)| o)
            .filter(|&o| o + span.to_secs <= time_secs)
            .collect();
        let missed_errors = scored
            .iter()
            .filter(|&&o| !self.detections.iter().any(|&t| span.contains(o, t)))
            .count();
        EpuckEpisodeResult {
            goal,
            committed,
            time_secs,
            detected_errors: self.detections.len(),
            detected_by_phase: self.by_phase,
            true_by_judged_phase: self.by_judged,
            false_detections: self.false_detections,
            missed_errors,
            errps: self.errps.len(),
            errps_scored: scored.len(),
            clean_secs: self.clean_windows as f64 * WINDOW_STEP_SECS,
            // A class with no window has no rate (NaN: `-` when printed,
            // empty in a table), never an invented 0 or 100 %.
            online: Accuracy {
                correct: rate(
                    self.n_clean_windows - self.false_alarms,
                    self.n_clean_windows,
                ),
                error: rate(self.hits, self.n_err_windows),
                n_correct: self.n_clean_windows,
                n_error: self.n_err_windows,
            },
            path_m,
            max_lateral_m_per_s,
            detections: self.detected_at,
        }
    }
}

/// `k` of `n` as a fraction; NaN when `n` is 0.
fn rate(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        k as f64 / n as f64
    }
}
