//! The held-out session, the decoder's response span on it, and
//! the detector's operating point scored per event.

use rand::Rng;
use serde::{Deserialize, Serialize};

use errp_valid::{Check, Valid};

use super::detector::{Detector, DetectorParams};
use super::{SlidingWindow, WINDOW_STEP_SECS};
use crate::continuous::ContinuousFeatures;
use crate::erp::AssessmentKind;
use crate::error::{BciError, Result, check};
use crate::generator::{EegFeed, EegGenerator, GeneratorParams, HybridSource};
use crate::montage::Montage;
use crate::preprocess::Preprocessor;
use crate::rng::labelled;
use crate::svm::SvmModel;

/// The held-out session on which a calibrated decoder's online operating
/// point is measured: the user watches correct motion and now and then an
/// error, the EEG is fed in, the decoder slides.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HeldOutParams {
    /// Length of the session (s): 60 to 3600.
    pub duration_secs: f64,
    /// Shortest gap between two ErrPs (s); longer than the response span, so
    /// each ErrP is scored on its own.
    pub error_gap_min_secs: f64,
    /// Longest gap between two ErrPs (s).
    pub error_gap_max_secs: f64,
}

impl Default for HeldOutParams {
    fn default() -> Self {
        Self {
            duration_secs: 600.0,
            error_gap_min_secs: 4.0,
            error_gap_max_secs: 8.0,
        }
    }
}

/// Checked where it is made; [`simulate_held_out`] takes it checked.
impl Check for HeldOutParams {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl HeldOutParams {
    /// Checks every field.
    fn validate(&self) -> Result<()> {
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

/// The decoder's output over a held-out session.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldOutSession {
    /// p(error) of the window ending at `(k + 1) * WINDOW_STEP_SECS`.
    pub p_error: Vec<f64>,
    /// Time zeros of the ErrPs (s).
    pub errps: Vec<f64>,
}

impl HeldOutSession {
    /// End time of window `k` (s).
    pub fn window_end_secs(k: usize) -> f64 {
        (k + 1) as f64 * WINDOW_STEP_SECS
    }

    /// Length of the session (s).
    pub fn duration_secs(&self) -> f64 {
        Self::window_end_secs(self.p_error.len()) - WINDOW_STEP_SECS
    }
}

/// Feeds a held-out session of `params.duration_secs` through
/// `preprocessor` and `model`: ErrPs U[error_gap_min, error_gap_max] s
/// apart (from 2 s on), and the correct-assessment potential half-way
/// between two of them (the user sees the motion corrected). All draws come
/// from `seed` (labelled streams distinct from the calibration's).
pub fn simulate_held_out(
    generator: &Valid<GeneratorParams>,
    montage: &Montage,
    preprocessor: &Preprocessor,
    model: &SvmModel,
    params: &Valid<HeldOutParams>,
    seed: u64,
) -> Result<HeldOutSession> {
    simulate_held_out_from(generator, None, montage, preprocessor, model, params, seed)
}

/// [`simulate_held_out`] on a person's own EEG (`hybrid`: its background,
/// the subject's response), or on the synthetic user without it.
pub fn simulate_held_out_from(
    generator: &Valid<GeneratorParams>,
    hybrid: Option<&HybridSource>,
    montage: &Montage,
    preprocessor: &Preprocessor,
    model: &SvmModel,
    params: &Valid<HeldOutParams>,
    seed: u64,
) -> Result<HeldOutSession> {
    let gen_seed = crate::rng::derive_seed(seed, "online/eeg", 0);
    let eeg: EegFeed = match hybrid {
        Some(h) => h.online_feed(generator, gen_seed)?.into(),
        None => EegGenerator::new(generator, montage, gen_seed)?.into(),
    };
    let features = ContinuousFeatures::paper(generator.sfreq_hz);
    let mut window = SlidingWindow::start(eeg, preprocessor, &features, montage)?;
    let mut gaps = labelled(seed, "online/schedule");
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
    for k in 0..n {
        // A second of EEG (16 windows) between checks.
        if k % 16 == 0 {
            crate::stop::check()?;
        }
        window.advance();
        p_error.push(window.p_error(model));
    }
    Ok(HeldOutSession { p_error, errps })
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

/// A lag responds when as many firings as it has, or more, would come by
/// chance with this probability at most (binomial, at the background rate):
/// one-sided, so that over the 33 lags examined a stray lag is unlikely
/// (about 3 %) to stretch the span.
pub const SPAN_ALPHA: f64 = 0.001;

/// P(X >= k) for X ~ Binomial(n, p).
pub fn binomial_upper_tail(k: usize, n: usize, p: f64) -> f64 {
    if k == 0 {
        return 1.0;
    }
    if k > n {
        return 0.0;
    }
    if p <= 0.0 {
        return 0.0;
    }
    if p >= 1.0 {
        return 1.0;
    }
    // 1 - P(X < k), the terms built by their ratios.
    let mut term = (1.0 - p).powi(n as i32);
    let mut below = 0.0;
    for i in 0..k {
        below += term;
        term *= (n - i) as f64 / (i + 1) as f64 * p / (1.0 - p);
    }
    (1.0 - below).max(0.0)
}

/// The windows of `recording` (a held-out session) at which `detector` fires.
pub fn firings(recording: &HeldOutSession, mut detector: Detector) -> Vec<bool> {
    recording
        .p_error
        .iter()
        .enumerate()
        .map(|(k, &p)| {
            detector
                .push(p, HeldOutSession::window_end_secs(k))
                .detected
        })
        .collect()
}

/// Measures the span of lags over which `fired` (one flag per window of
/// `recording`, for example [`firings`] of a detector) responds to an ErrP.
///
/// For every lag (window end minus the latest ErrP's time zero, in steps of
/// 62.5 ms, up to 2 s) the firings are compared with the background rate,
/// over windows with no ErrP in the last 2 s. A lag responds when that many
/// firings would come by chance with probability [`SPAN_ALPHA`] at most
/// (binomial upper tail at the background rate); the span runs from the
/// first to the last responding lag. So an early response (a window that holds only the
/// start of an ErrP) counts as a response as soon as it is more frequent
/// than chance, not only when it is a sizeable share of the peak: scoring
/// over this span does not call early responses false alarms.
pub fn response_span(recording: &HeldOutSession, fired: &[bool]) -> ResponseSpan {
    let n_lags = (LAG_RANGE_SECS / WINDOW_STEP_SECS).round() as usize + 1;
    let mut above = vec![0usize; n_lags];
    let mut count = vec![0usize; n_lags];
    let (mut base_above, mut base_n) = (0usize, 0usize);
    let mut next = 0; // first ErrP after the current window
    for (k, &hit) in fired.iter().enumerate().take(recording.p_error.len()) {
        let t = HeldOutSession::window_end_secs(k);
        while next < recording.errps.len() && recording.errps[next] <= t {
            next += 1;
        }
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
    // The background rate, at least one firing's worth, so that a decoder
    // that never fires on background EEG still needs a few firings at a lag.
    let base = (base_above.max(1) as f64 / base_n.max(1) as f64).min(1.0);
    let responds = |l: usize| {
        above[l] > 0
            && above[l] as f64 > base * count[l] as f64
            && binomial_upper_tail(above[l], count[l], base) <= SPAN_ALPHA
    };
    let lag_secs = |l: usize| l as f64 * WINDOW_STEP_SECS;
    match (
        (0..n_lags).find(|&l| responds(l)),
        (0..n_lags).rev().find(|&l| responds(l)),
    ) {
        (Some(first), Some(last)) => ResponseSpan {
            from_secs: lag_secs(first),
            to_secs: lag_secs(last),
        },
        // A decoder that never responds: the span the features could see
        // (the temporal window's [200, 800] ms).
        _ => ResponseSpan {
            from_secs: 0.45,
            to_secs: 0.85,
        },
    }
}

/// The response span of `detector` at `t_e` on `recording`: the span over
/// which single windows respond at `t_e` ([`response_span`] of the literal
/// reading's firings), delayed by the detector's smoothing. A mean of the
/// last n windows responds as soon as its newest window does and until its
/// oldest stops; its own firings, one event per ErrP at most, are too sparse
/// at any one lag to be told from chance lag by lag.
pub fn detector_span(
    recording: &HeldOutSession,
    detector: Valid<DetectorParams>,
    t_e: f64,
) -> Result<ResponseSpan> {
    let windows = firings(recording, Detector::new(DetectorParams::literal(), t_e)?);
    Ok(response_span(recording, &windows).delayed(detector.delay_secs()))
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
    recording: &HeldOutSession,
    mut detector: Detector,
    span: ResponseSpan,
) -> OperatingPoint {
    let mut detections = Vec::new();
    let mut clean_windows = 0usize;
    let mut next = 0;
    for (k, &p) in recording.p_error.iter().enumerate() {
        let t = HeldOutSession::window_end_secs(k);
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
