//! Online, asynchronous ErrP detection (sec. 2.2.2 of the paper, and how
//! asynchronous-ErrP studies score it): the 800 ms window sliding every
//! 62.5 ms over streamed EEG, the detector that turns its p(error) stream
//! into error events, and the detector's operating point measured on a
//! held-out continuous recording.
//!
//! Without a cue, a decoder that looks every 62.5 ms has about 16 chances a
//! second to fire on background EEG, and one ErrP is visible in several
//! consecutive windows. Asynchronous-ErrP studies therefore do not count
//! windows: they aggregate consecutive windows into events and score events
//! per ErrP (a hit when an event follows the ErrP within the decoder's
//! response span) and per unit of error-free time (false alarms per minute).
//! [`Detector`] does this; [`DetectorMode::Literal`] keeps the paper's
//! literal reading (each window against T_e on its own).

use std::collections::VecDeque;

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::classify::ErrorModel;
use crate::continuous::ContinuousFeatures;
use crate::erp::AssessmentKind;
use crate::error::{Result, check};
use crate::generator::{Assessment, EegBlock, EegGenerator, GeneratorParams};
use crate::montage::Montage;
use crate::preprocess::Preprocessor;
use crate::rng::stream;
use crate::svm::SvmModel;

/// The decoder's window step: 62.5 ms (sec. 2.2.2).
pub const WINDOW_STEP_SECS: f64 = 0.0625;
/// Seconds of EEG streamed before a recording so the causal filters settle;
/// recording time 0 is generator time `WARM_UP_SECS`.
pub const WARM_UP_SECS: f64 = 2.0;

/// Streamed EEG and the 800 ms window sliding over its preprocessed
/// channels, one hop of 62.5 ms at a time.
#[derive(Debug)]
pub struct SlidingWindow {
    generator: EegGenerator,
    preprocessor: Preprocessor,
    features: ContinuousFeatures,
    window: EegBlock,
    scratch: Vec<f64>,
    raw: EegBlock,
    /// Rows of FCz and Cz among the preprocessed channels.
    fcz_cz: [usize; 2],
}

impl SlidingWindow {
    /// Starts a stream from `generator` (fresh, at its time 0) through a
    /// reset copy of `preprocessor`, and lets the filters settle for
    /// [`WARM_UP_SECS`]: recording time 0 is generator time `WARM_UP_SECS`.
    pub fn start(
        mut generator: EegGenerator,
        preprocessor: &Preprocessor,
        features: &ContinuousFeatures,
        montage: &Montage,
    ) -> Result<Self> {
        let fs = generator.params().sfreq_hz;
        let mut preprocessor = preprocessor.clone();
        preprocessor.reset();
        let warm = preprocessor.process(&generator.generate((WARM_UP_SECS * fs) as usize));
        let span = features.span();
        let mut window = EegBlock::zeros(warm.n_channels, span);
        for ch in 0..warm.n_channels {
            let src = warm.channel(ch);
            window
                .channel_mut(ch)
                .copy_from_slice(&src[src.len() - span..]);
        }
        let row = |name: &str| -> Result<usize> {
            let i = montage.index(name)?;
            Ok(preprocessor
                .outputs()
                .iter()
                .position(|&o| o == i)
                .unwrap_or(0))
        };
        let fcz_cz = [row("FCz")?, row("Cz")?];
        let hop = (WINDOW_STEP_SECS * fs).round() as usize;
        Ok(Self {
            generator,
            preprocessor,
            features: features.clone(),
            window,
            scratch: Vec::with_capacity(features.n_features(warm.n_channels)),
            raw: EegBlock::zeros(montage.len(), hop),
            fcz_cz,
        })
    }

    /// Schedules the potential of an assessment at recording time
    /// `onset_secs` (its time zero).
    pub fn schedule(&mut self, onset_secs: f64, kind: AssessmentKind) {
        self.generator.schedule(Assessment {
            onset_secs: WARM_UP_SECS + onset_secs,
            kind,
        });
    }

    /// Streams one more hop through the preprocessing, slides the window,
    /// and returns the new preprocessed samples `(n_channels, hop)`.
    pub fn advance(&mut self) -> EegBlock {
        self.generator.generate_into(&mut self.raw);
        let fresh = self.preprocessor.process(&self.raw);
        let hop = fresh.n_samples;
        for ch in 0..fresh.n_channels {
            let w = self.window.channel_mut(ch);
            w.copy_within(hop.., 0);
            let n = w.len();
            w[n - hop..].copy_from_slice(fresh.channel(ch));
        }
        fresh
    }

    /// p(error) of the current window.
    pub fn p_error(&mut self, model: &SvmModel) -> f64 {
        self.scratch.clear();
        self.features
            .extract_into(&self.window, 0, &mut self.scratch);
        model.p_error(&self.scratch)
    }

    /// Rows of FCz and Cz in the blocks [`advance`](Self::advance) returns.
    pub fn fcz_cz(&self) -> [usize; 2] {
        self.fcz_cz
    }
}

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

impl DetectorParams {
    /// The paper's literal reading: each window against T_e.
    pub fn literal() -> Self {
        Self {
            mode: DetectorMode::Literal,
            smooth_windows: 1,
            refractory_secs: 0.0,
        }
    }

    /// Checks every field; names them as the scenario's `[detector]` does.
    pub fn validate(&self) -> Result<()> {
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
    params: DetectorParams,
    t_e: f64,
    recent: VecDeque<f64>,
    last_detection_secs: f64,
}

impl Detector {
    /// A detector with threshold `t_e` (in (0, 1]).
    pub fn new(params: DetectorParams, t_e: f64) -> Result<Self> {
        params.validate()?;
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

/// The held-out continuous recording on which a calibrated decoder's online
/// operating point is measured: the user watches correct continuous motion
/// and now and then an error, EEG streams, the decoder slides.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OnlineRecordingParams {
    /// Length of the recording (s): 60 to 3600.
    pub duration_secs: f64,
    /// Shortest gap between two ErrPs (s); longer than the response span, so
    /// each ErrP is scored on its own.
    pub error_gap_min_secs: f64,
    /// Longest gap between two ErrPs (s).
    pub error_gap_max_secs: f64,
}

impl Default for OnlineRecordingParams {
    fn default() -> Self {
        Self {
            duration_secs: 600.0,
            error_gap_min_secs: 4.0,
            error_gap_max_secs: 8.0,
        }
    }
}

impl OnlineRecordingParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        check(
            self.duration_secs.is_finite() && (60.0..=3600.0).contains(&self.duration_secs),
            "duration_secs",
            self.duration_secs,
            "a length in [60, 3600] s",
        )?;
        check(
            self.error_gap_min_secs.is_finite() && self.error_gap_min_secs >= 3.0,
            "error_gap_min_secs",
            self.error_gap_min_secs,
            "at least 3 s (longer than the decoder's response span)",
        )?;
        check(
            self.error_gap_max_secs.is_finite()
                && self.error_gap_max_secs >= self.error_gap_min_secs
                && self.error_gap_max_secs <= 60.0,
            "error_gap_max_secs",
            self.error_gap_max_secs,
            "at least error_gap_min_secs and at most 60 s",
        )
    }
}

/// The decoder's output over a held-out continuous recording.
#[derive(Debug, Clone, PartialEq)]
pub struct OnlineRecording {
    /// p(error) of the window ending at `(k + 1) * WINDOW_STEP_SECS`.
    pub p_error: Vec<f64>,
    /// Time zeros of the ErrPs (s).
    pub errps: Vec<f64>,
}

impl OnlineRecording {
    /// End time of window `k` (s).
    pub fn window_end_secs(k: usize) -> f64 {
        (k + 1) as f64 * WINDOW_STEP_SECS
    }

    /// Length of the recording (s).
    pub fn duration_secs(&self) -> f64 {
        Self::window_end_secs(self.p_error.len()) - WINDOW_STEP_SECS
    }
}

/// Streams a held-out recording of `params.duration_secs` through
/// `preprocessor` and `model`: ErrPs U[error_gap_min, error_gap_max] s
/// apart (from 2 s on), and the correct-assessment potential half-way
/// between two of them (the user sees the motion corrected). All draws come
/// from `seed` (labelled streams distinct from the calibration's).
pub fn record_online(
    generator: &GeneratorParams,
    montage: &Montage,
    preprocessor: &Preprocessor,
    model: &SvmModel,
    params: &OnlineRecordingParams,
    seed: u64,
) -> Result<OnlineRecording> {
    params.validate()?;
    let gen_seed = crate::rng::derive_seed(seed, "online/eeg", 0);
    let eeg = EegGenerator::new(generator.clone(), montage, gen_seed)?;
    let features = ContinuousFeatures::paper(generator.sfreq_hz);
    let mut window = SlidingWindow::start(eeg, preprocessor, &features, montage)?;
    let mut gaps = stream(seed, "online/schedule");
    let mut errps = Vec::new();
    let mut t = 2.0;
    while t < params.duration_secs - 2.0 {
        errps.push(t);
        window.schedule(t, AssessmentKind::Error);
        let gap = gaps.random_range(params.error_gap_min_secs..=params.error_gap_max_secs);
        window.schedule(t + 0.5 * gap, AssessmentKind::Correct);
        t += gap;
    }
    let n = (params.duration_secs / WINDOW_STEP_SECS).round() as usize;
    let mut p_error = Vec::with_capacity(n);
    for _ in 0..n {
        window.advance();
        p_error.push(window.p_error(model));
    }
    Ok(OnlineRecording { p_error, errps })
}

/// When, after an ErrP's time zero, windows (or detections) respond to it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ResponseSpan {
    /// Earliest window end that responds (s after time zero).
    pub from_secs: f64,
    /// Latest window end that responds (s after time zero).
    pub to_secs: f64,
}

impl ResponseSpan {
    /// True if a window ending at `t` responds to an ErrP at `errp`.
    pub fn contains(&self, errp: f64, t: f64) -> bool {
        let lag = t - errp;
        lag >= self.from_secs - 1e-9 && lag <= self.to_secs + 1e-9
    }

    /// The span of a detector that fires up to `delay_secs` later.
    pub fn delayed(&self, delay_secs: f64) -> Self {
        Self {
            from_secs: self.from_secs,
            to_secs: self.to_secs + delay_secs,
        }
    }
}

/// Lags examined for a response, s after time zero.
const LAG_RANGE_SECS: f64 = 2.0;

/// Measures the span of window ends over which the decoder responds to an
/// ErrP: for every lag (window end minus time zero, in steps of 62.5 ms, up
/// to 2 s) the share of windows at or above `t_e`, minus the share over
/// windows with no ErrP in the last 2 s; the span runs from the first to the
/// last lag whose excess is at least `fraction` of the largest excess.
pub fn response_span(recording: &OnlineRecording, t_e: f64, fraction: f64) -> ResponseSpan {
    let n_lags = (LAG_RANGE_SECS / WINDOW_STEP_SECS).round() as usize + 1;
    let mut above = vec![0usize; n_lags];
    let mut count = vec![0usize; n_lags];
    let (mut base_above, mut base_n) = (0usize, 0usize);
    let mut next = 0; // first ErrP after the current window
    for (k, &p) in recording.p_error.iter().enumerate() {
        let t = OnlineRecording::window_end_secs(k);
        while next < recording.errps.len() && recording.errps[next] <= t {
            next += 1;
        }
        let hit = p >= t_e;
        match next.checked_sub(1).map(|i| recording.errps[i]) {
            Some(o) if t - o <= LAG_RANGE_SECS + 1e-9 => {
                let lag = ((t - o) / WINDOW_STEP_SECS).round() as usize;
                count[lag] += 1;
                above[lag] += usize::from(hit);
            }
            _ => {
                base_n += 1;
                base_above += usize::from(hit);
            }
        }
    }
    let base = base_above as f64 / base_n.max(1) as f64;
    let excess: Vec<f64> = (0..n_lags)
        .map(|l| above[l] as f64 / count[l].max(1) as f64 - base)
        .collect();
    let peak = excess.iter().copied().fold(0.0, f64::max);
    let lag_secs = |l: usize| l as f64 * WINDOW_STEP_SECS;
    if peak <= 0.0 {
        // A decoder that never responds: the span the features could see
        // (the temporal window's [200, 800] ms).
        return ResponseSpan {
            from_secs: 0.45,
            to_secs: 0.85,
        };
    }
    let first = excess
        .iter()
        .position(|&e| e >= fraction * peak)
        .unwrap_or(0);
    let last = excess
        .iter()
        .rposition(|&e| e >= fraction * peak)
        .unwrap_or(n_lags - 1);
    ResponseSpan {
        from_secs: lag_secs(first),
        to_secs: lag_secs(last),
    }
}

/// A detector's online operating point, scored per event as
/// asynchronous-ErrP studies do.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OperatingPoint {
    /// Share of ErrPs followed by a detection within the response span.
    pub hit_rate: f64,
    /// Detections outside every ErrP's response span, per minute of the
    /// time outside them.
    pub false_alarms_per_min: f64,
    /// Median time from an ErrP's time zero to its first detection (s).
    pub median_latency_secs: f64,
    /// ErrPs scored.
    pub n_errps: usize,
    /// Minutes of error-free time scored.
    pub clean_minutes: f64,
    /// The response span the detections were attributed over.
    pub span: ResponseSpan,
}

/// Runs `detector` over `recording` and scores it: a detection within
/// `span` of an ErrP hits it (the first one gives the latency); any other
/// detection is a false alarm, counted per minute of the windows outside
/// every ErrP's `span`.
pub fn operating_point(
    recording: &OnlineRecording,
    mut detector: Detector,
    span: ResponseSpan,
) -> OperatingPoint {
    let mut detections = Vec::new();
    let mut clean_windows = 0usize;
    let mut next = 0;
    for (k, &p) in recording.p_error.iter().enumerate() {
        let t = OnlineRecording::window_end_secs(k);
        let d = detector.push(p, t);
        while next < recording.errps.len() && recording.errps[next] + span.to_secs < t - 1e-9 {
            next += 1;
        }
        let in_span = recording.errps[next..]
            .iter()
            .take_while(|&&o| o <= t)
            .any(|&o| span.contains(o, t));
        if in_span {
            if d.detected {
                detections.push((t, true));
            }
        } else {
            clean_windows += 1;
            if d.detected {
                detections.push((t, false));
            }
        }
    }
    let mut latencies = Vec::new();
    for &o in &recording.errps {
        if let Some(&(t, _)) = detections
            .iter()
            .find(|&&(t, real)| real && span.contains(o, t))
        {
            latencies.push(t - o);
        }
    }
    latencies.sort_by(f64::total_cmp);
    let false_alarms = detections.iter().filter(|d| !d.1).count();
    let clean_minutes = clean_windows as f64 * WINDOW_STEP_SECS / 60.0;
    OperatingPoint {
        hit_rate: latencies.len() as f64 / recording.errps.len().max(1) as f64,
        false_alarms_per_min: false_alarms as f64 / clean_minutes.max(1e-9),
        median_latency_secs: latencies
            .get(latencies.len() / 2)
            .copied()
            .unwrap_or(f64::NAN),
        n_errps: recording.errps.len(),
        clean_minutes,
        span,
    }
}

/// An online operating point to calibrate for, instead of a cross-validated
/// accuracy: the detector's hit rate per ErrP on the held-out recording, and
/// optionally its false alarms per minute (then T_e is calibrated too, as a
/// personal decision threshold).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OnlineTarget {
    /// Requested hit rate per ErrP, in (0, 1).
    pub hit_rate: f64,
    /// Requested false alarms per minute of error-free time, in (0, 60];
    /// `None`: keep the given T_e.
    pub false_alarms_per_min: Option<f64>,
}

impl OnlineTarget {
    /// Checks both fields; names them as the scenario's `[user]` does.
    pub fn validate(&self) -> Result<()> {
        check(
            self.hit_rate.is_finite() && self.hit_rate > 0.0 && self.hit_rate < 1.0,
            "hit_rate",
            self.hit_rate,
            "a hit rate per ErrP in (0, 1), e.g. 0.9",
        )?;
        if let Some(f) = self.false_alarms_per_min {
            check(
                f.is_finite() && f > 0.0 && f <= 60.0,
                "false_alarms_per_min",
                f,
                "a rate in (0, 60] per minute, e.g. 0.5",
            )?;
        }
        Ok(())
    }
}

/// One evaluation of [`target_online`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnlineStep {
    /// ErrP-to-noise ratio tried.
    pub ratio: f64,
    /// T_e used (calibrated when false alarms are targeted).
    pub t_e: f64,
    /// The operating point reached.
    pub point: OperatingPoint,
}

/// The outcome of [`target_online`]: the ratio and T_e whose operating point
/// is closest to the request, and every evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct OnlineTargeting {
    /// What was asked for.
    pub target: OnlineTarget,
    /// The ratio found.
    pub ratio: f64,
    /// The T_e found (or the one given).
    pub t_e: f64,
    /// The operating point there.
    pub point: OperatingPoint,
    /// Every evaluation, in order.
    pub steps: Vec<OnlineStep>,
}

/// T_e in [0.5, 0.999] at which `detector` gives `false_alarms_per_min` on
/// `recording` (bisection: false alarms fall as T_e rises), with the
/// operating point there, scored over the span measured at that T_e.
pub fn threshold_for_false_alarms(
    recording: &OnlineRecording,
    detector: DetectorParams,
    false_alarms_per_min: f64,
) -> Result<(f64, OperatingPoint)> {
    let at = |t_e: f64| -> Result<OperatingPoint> {
        let span = response_span(recording, t_e, SPAN_FRACTION).delayed(detector.delay_secs());
        Ok(operating_point(
            recording,
            Detector::new(detector, t_e)?,
            span,
        ))
    };
    let (mut lo, mut hi) = (0.5, 0.999);
    let mut best = (hi, at(hi)?);
    for _ in 0..18 {
        let mid = 0.5 * (lo + hi);
        let p = at(mid)?;
        if (p.false_alarms_per_min - false_alarms_per_min).abs()
            < (best.1.false_alarms_per_min - false_alarms_per_min).abs()
        {
            best = (mid, p);
        }
        if p.false_alarms_per_min > false_alarms_per_min {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(best)
}

/// Share of the largest excess response at which a response span starts and
/// ends (see [`response_span`]).
pub const SPAN_FRACTION: f64 = 0.2;

/// Searches the ErrP-to-noise ratio (and T_e, if false alarms are targeted)
/// at which the detector's operating point on the held-out recording meets
/// `target`. `evaluate(ratio)` calibrates the decoder at that ratio and
/// returns its held-out recording; the hit rate rises with the ratio, so the
/// search brackets it by doubling from 0.25 (up to `max_ratio`) and then
/// bisects until the hit rate is within `tolerance` or `max_evaluations`
/// are spent. Returns the closest evaluation.
/// Errors of `evaluate` pass through (any error type a [`BciError`]
/// converts into).
///
/// [`BciError`]: crate::BciError
#[allow(clippy::too_many_arguments)]
pub fn target_online<E: From<crate::error::BciError>>(
    target: OnlineTarget,
    detector: DetectorParams,
    t_e: f64,
    max_ratio: f64,
    tolerance: f64,
    max_evaluations: usize,
    mut evaluate: impl FnMut(f64) -> std::result::Result<OnlineRecording, E>,
    mut progress: impl FnMut(&OnlineStep),
) -> std::result::Result<OnlineTargeting, E> {
    target.validate()?;
    detector.validate()?;
    let mut steps: Vec<OnlineStep> = Vec::new();
    let mut eval = |ratio: f64, steps: &mut Vec<OnlineStep>| -> std::result::Result<f64, E> {
        let recording = evaluate(ratio)?;
        let (t, point) = match target.false_alarms_per_min {
            Some(f) => threshold_for_false_alarms(&recording, detector, f)?,
            None => {
                let span =
                    response_span(&recording, t_e, SPAN_FRACTION).delayed(detector.delay_secs());
                (
                    t_e,
                    operating_point(&recording, Detector::new(detector, t_e)?, span),
                )
            }
        };
        let step = OnlineStep {
            ratio,
            t_e: t,
            point,
        };
        progress(&step);
        steps.push(step);
        Ok(point.hit_rate)
    };
    let close = |h: f64| (h - target.hit_rate).abs() <= tolerance;
    let (mut lo, mut hi) = (0.0, 0.25);
    let mut hit = eval(hi, &mut steps)?;
    while hit < target.hit_rate && !close(hit) {
        if hi >= max_ratio || steps.len() >= max_evaluations {
            return Err(crate::error::BciError::InvalidParameter {
                name: "hit_rate",
                value: target.hit_rate.to_string(),
                expected: format!(
                    "a hit rate the detector can reach: it catches {:.1} % of ErrPs at the \
                     largest ErrP-to-noise ratio tried ({hi})",
                    100.0 * hit
                ),
            }
            .into());
        }
        lo = hi;
        hi = (hi * 2.0).min(max_ratio);
        hit = eval(hi, &mut steps)?;
    }
    while !close(hit) && steps.len() < max_evaluations {
        let mid = 0.5 * (lo + hi);
        hit = eval(mid, &mut steps)?;
        if hit < target.hit_rate {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let best = *steps
        .iter()
        .min_by(|a, b| {
            (a.point.hit_rate - target.hit_rate)
                .abs()
                .total_cmp(&(b.point.hit_rate - target.hit_rate).abs())
        })
        .expect("at least one evaluation");
    Ok(OnlineTargeting {
        target,
        ratio: best.ratio,
        t_e: best.t_e,
        point: best.point,
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_literal_detector_fires_on_every_window_at_t_e() {
        let mut d = Detector::new(DetectorParams::literal(), 0.8).unwrap();
        let out: Vec<bool> = [0.5, 0.8, 0.9, 0.79, 0.85]
            .iter()
            .enumerate()
            .map(|(k, &p)| d.push(p, k as f64 * WINDOW_STEP_SECS).detected)
            .collect();
        assert_eq!(out, [false, true, true, false, true]);
    }

    #[test]
    fn the_smoothed_detector_averages_and_then_waits() {
        let params = DetectorParams {
            mode: DetectorMode::Smoothed,
            smooth_windows: 3,
            refractory_secs: 0.5,
        };
        let mut d = Detector::new(params, 0.8).unwrap();
        // One window at 1.0 among lows never reaches a mean of 0.8.
        let mut fired = Vec::new();
        let ps = [
            0.6, 1.0, 0.6, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9, 0.9,
        ];
        for (k, &p) in ps.iter().enumerate() {
            if d.push(p, k as f64 * WINDOW_STEP_SECS).detected {
                fired.push(k);
            }
        }
        // Mean of (1.0, 0.6, 0.9) = 0.83 at k = 3 (at k = 2 the mean is
        // 0.73); the next no earlier than 0.5 s = 8 steps later.
        assert_eq!(fired, [3, 11]);
        assert!((params.delay_secs() - 0.125).abs() < 1e-12);
    }

    #[test]
    fn bad_detector_settings_are_named() {
        let e = DetectorParams {
            smooth_windows: 0,
            ..DetectorParams::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("smooth_windows") && e.contains("1 to 16"), "{e}");
        let e = Detector::new(DetectorParams::default(), 1.5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("t_e"), "{e}");
        let e = OnlineRecordingParams {
            duration_secs: 1e9,
            ..OnlineRecordingParams::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("duration_secs"), "{e}");
    }

    #[test]
    fn scoring_attributes_by_span_and_counts_false_alarms_per_minute() {
        // 60 s, ErrPs at 10 and 30 s; p = 1 at 10.75 s (a hit, 0.75 s late),
        // at 20 s (false) and at 31.5 s (outside [0.5, 1.0]: false).
        let n = (60.0 / WINDOW_STEP_SECS) as usize;
        let mut p = vec![0.0; n];
        let at = |t: f64| (t / WINDOW_STEP_SECS).round() as usize - 1;
        p[at(10.75)] = 1.0;
        p[at(20.0)] = 1.0;
        p[at(31.5)] = 1.0;
        let rec = OnlineRecording {
            p_error: p,
            errps: vec![10.0, 30.0],
        };
        let span = ResponseSpan {
            from_secs: 0.5,
            to_secs: 1.0,
        };
        let op = operating_point(
            &rec,
            Detector::new(DetectorParams::literal(), 0.8).unwrap(),
            span,
        );
        assert_eq!(op.n_errps, 2);
        assert!((op.hit_rate - 0.5).abs() < 1e-12);
        assert!((op.median_latency_secs - 0.75).abs() < 1e-9);
        // Clean time: 60 s minus two spans of 9 windows each.
        let clean_min = (n - 18) as f64 * WINDOW_STEP_SECS / 60.0;
        assert!((op.clean_minutes - clean_min).abs() < 1e-9);
        assert!((op.false_alarms_per_min - 2.0 / clean_min).abs() < 1e-9);
    }

    #[test]
    fn the_threshold_search_meets_a_false_alarm_rate() {
        // Background p(error) uniform in [0, 1) per window (seeded): the
        // literal detector's false alarms fall as T_e rises.
        let mut rng = stream(3, "test");
        let n = (600.0 / WINDOW_STEP_SECS) as usize;
        let p: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let rec = OnlineRecording {
            p_error: p,
            errps: vec![100.0],
        };
        let (t_e, op) = threshold_for_false_alarms(&rec, DetectorParams::literal(), 30.0).unwrap();
        assert!((op.false_alarms_per_min - 30.0).abs() < 3.0, "{t_e} {op:?}");
        // 16 windows a second: 30 a minute is a per-window rate of 1/32.
        assert!((t_e - (1.0 - 1.0 / 32.0)).abs() < 0.01, "{t_e}");
        let bad = OnlineTarget {
            hit_rate: 1.5,
            false_alarms_per_min: None,
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(bad.contains("hit_rate") && bad.contains("(0, 1)"), "{bad}");
    }

    #[test]
    fn the_response_span_is_where_windows_respond() {
        // Windows respond (p = 0.9) from 0.6 to 1.0 s after each ErrP, with
        // a few background false positives.
        let n = (300.0 / WINDOW_STEP_SECS) as usize;
        let errps: Vec<f64> = (0..50).map(|k| 3.0 + 5.0 * k as f64).collect();
        let mut p = vec![0.1; n];
        for &o in &errps {
            for k in 0..n {
                let lag = OnlineRecording::window_end_secs(k) - o;
                if (0.6 - 1e-9..=1.0 + 1e-9).contains(&lag) {
                    p[k] = 0.9;
                }
            }
        }
        for k in (7..n).step_by(97) {
            p[k] = 0.95;
        }
        let rec = OnlineRecording { p_error: p, errps };
        let s = response_span(&rec, 0.8, 0.25);
        assert!((s.from_secs - 0.625).abs() < 0.07, "{s:?}");
        assert!((s.to_secs - 1.0).abs() < 0.07, "{s:?}");
    }
}
