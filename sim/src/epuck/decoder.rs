//! The continuous ErrP decoder of the e-puck task (sec. 2.2.2): calibrated on
//! button-locked examples (sec. 5.1), then run online on an 800 ms window
//! that slides every 62.5 ms over streamed EEG.

use errp_bci::{
    Accuracy, ContinuousCalibrationParams, ContinuousFeatures, ContinuousSetup, Detector,
    DetectorMode, DetectorParams, EegFeed, EegGenerator, GeneratorParams, HeldOutParams,
    HeldOutSession, HybridSource, Montage, OnlineStep, OnlineTarget, OnlineTargeting,
    OperatingPoint, Preprocessor, ResponseSpan, SlidingWindow, SvmDecoder, SvmModel,
    TargetingParams, TargetingResult, TargetingStep, Valid, calibrate_continuous, detector_span,
    operating_point, rng::derive_seed, simulate_held_out_from, target_continuous_accuracy,
    target_online,
};

use std::sync::Arc;

use crate::calibration::{Report, Request};
use crate::epuck::params::EpuckTaskParams;
use crate::error::Result;

/// The button-locked calibration of the e-puck task.
pub type ContinuousRequest = Request<ContinuousCalibrationParams>;

/// Its outcome: the SVM decoder.
pub type ContinuousReport = Report<SvmModel>;

/// Targets the requested accuracy with the SVM decoder, then re-runs the
/// calibration session at the ratio found, scores it and trains on it.
pub fn run_continuous_calibration(
    request: &ContinuousRequest,
    progress: impl FnMut(&TargetingStep),
) -> Result<ContinuousReport> {
    calibrate_continuous_at(request, target_continuous(request, progress)?)
}

/// The first half of [`run_continuous_calibration`]: the ErrP-to-noise
/// ratio at which the SVM reaches the requested accuracy.
pub fn target_continuous(
    request: &ContinuousRequest,
    progress: impl FnMut(&TargetingStep),
) -> Result<TargetingResult> {
    Ok(target_continuous_accuracy(
        request.accuracy,
        &SvmDecoder::default(),
        &request.setup,
        &request.search,
        request.seed,
        progress,
    )?)
}

/// The second half of [`run_continuous_calibration`], for a ratio already
/// found (e.g. from a sweep's cache): re-runs the session at
/// `targeting.ratio`, scores it and trains on it.
pub fn calibrate_continuous_at(
    request: &ContinuousRequest,
    targeting: TargetingResult,
) -> Result<ContinuousReport> {
    let setup = Valid::new(request.setup.at_ratio(targeting.ratio)?)?;
    let calibrated = calibrate_continuous(&SvmDecoder::default(), &setup, request.seed)?;
    Ok(ContinuousReport {
        targeting,
        generator: setup.generator.clone(),
        calibrated,
    })
}

/// What the calibrated decoder does online, measured at calibration time on
/// a held-out session (same user, fresh EEG): the span over
/// which its windows respond to an ErrP, and the operating point of the
/// scenario's detector beside the paper's literal per-window reading.
#[derive(Debug, Clone, PartialEq)]
pub struct OnlineReport {
    /// Window ends, after an ErrP's time zero, at which the decoder's
    /// windows respond (p(error) >= T_e clearly above its background rate).
    pub window_span: ResponseSpan,
    /// The detector in force.
    pub detector: Valid<DetectorParams>,
    /// T_e.
    pub t_e: f64,
    /// The detector in force, scored per ErrP and per minute of error-free
    /// time over its own response span (measured from its detections).
    pub point: OperatingPoint,
    /// Each window against T_e on its own (the paper read literally).
    pub literal: OperatingPoint,
}

impl OnlineReport {
    /// Scores `detector` at `t_e`, and the literal reading, on a held-out
    /// session `recording` of the calibrated pipeline.
    pub fn from_held_out(
        recording: &HeldOutSession,
        detector: Valid<DetectorParams>,
        t_e: f64,
    ) -> Result<Self> {
        let window_span = detector_span(recording, DetectorParams::literal(), t_e)?;
        let point = operating_point(
            recording,
            Detector::new(detector, t_e)?,
            detector_span(recording, detector, t_e)?,
        );
        let literal = operating_point(
            recording,
            Detector::new(DetectorParams::literal(), t_e)?,
            window_span,
        );
        Ok(Self {
            window_span,
            detector,
            t_e,
            point,
            literal,
        })
    }
}

impl std::fmt::Display for OnlineReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let row = |f: &mut std::fmt::Formatter<'_>, name: &str, p: &OperatingPoint| {
            writeln!(
                f,
                "  {name:<34} hit rate {:5.1} %  false alarms {:5.2}/min  median latency {:.2} s  \
                 (responds {:.2}-{:.2} s after an ErrP)",
                100.0 * p.hit_rate,
                p.false_alarms_per_min,
                p.median_latency_secs,
                p.span.from_secs,
                p.span.to_secs
            )
        };
        writeln!(
            f,
            "Online operating point (held-out recording: {} ErrPs, {:.1} min error-free):",
            self.point.n_errps, self.point.clean_minutes,
        )?;
        let t_e = format!("{:.3}", self.t_e);
        let t_e = t_e.trim_end_matches('0').trim_end_matches('.');
        let name = match self.detector.mode {
            DetectorMode::Smoothed => format!(
                "detector: mean of {} windows >= {t_e}",
                self.detector.smooth_windows
            ),
            DetectorMode::Literal => format!("detector: each window >= {t_e}"),
        };
        row(f, &name, &self.point)?;
        if self.detector.mode != DetectorMode::Literal {
            row(f, &format!("literal: each window >= {t_e}"), &self.literal)?;
        }
        Ok(())
    }
}

/// Calibrates the continuous decoder for an online operating point: the
/// ErrP-to-noise ratio (and T_e, if false alarms are targeted) at which
/// `detector`, run over the held-out session of
/// [`ContinuousDecoder::record_held_out`], meets `target`. Every evaluation
/// is a full calibration at the ratio tried and its held-out session; the
/// one the search picks becomes the decoder (measured online at the T_e
/// found) and the report, so nothing is calibrated or recorded twice.
pub fn run_online_calibration(
    request: &ContinuousRequest,
    target: Valid<OnlineTarget>,
    detector: Valid<DetectorParams>,
    t_e: f64,
    progress: impl FnMut(&OnlineStep),
) -> Result<(ContinuousDecoder, ContinuousReport, OnlineTargeting)> {
    let mut evaluated: Vec<(f64, ContinuousReport, HeldOutSession)> = Vec::new();
    let search = target_online(
        target,
        detector,
        t_e,
        // Within 2 points of the target hit rate.
        &TargetingParams {
            tolerance: 0.02,
            ..request.search.clone()
        },
        |ratio| -> Result<_> {
            let mut report = calibrate_continuous_at(
                request,
                TargetingResult {
                    requested: target.hit_rate,
                    ratio,
                    accuracy: Accuracy {
                        correct: f64::NAN,
                        error: f64::NAN,
                        n_correct: 0,
                        n_error: 0,
                    },
                    steps: Vec::new(),
                },
            )?;
            report.targeting.accuracy = report.calibrated.accuracy;
            let recording =
                ContinuousDecoder::from_report(&report).record_held_out(request.seed)?;
            evaluated.push((ratio, report, recording.clone()));
            Ok(recording)
        },
        progress,
    )?;
    let (_, report, recording) = evaluated
        .into_iter()
        .find(|(ratio, _, _)| ratio.to_bits() == search.ratio.to_bits())
        .expect("the ratio found is one of the evaluations");
    let mut decoder =
        ContinuousDecoder::from_report(&report).with_closed_loop(&request.setup, request.seed)?;
    decoder.online = Some(OnlineReport::from_held_out(
        &recording, detector, search.t_e,
    )?);
    Ok((decoder, report, search))
}

/// The span attributed to an ErrP by a decoder not measured online: the
/// window ends at which its features can see the ErrP's peaks.
const UNMEASURED_SPAN: ResponseSpan = ResponseSpan {
    from_secs: 0.45,
    to_secs: 1.1,
};

/// The seed of the held-out session of a calibration seeded `seed`.
fn held_out_seed(seed: u64) -> u64 {
    derive_seed(seed, "online/held-out", 0)
}

/// The calibrated online pipeline: the user's EEG model, the preprocessing
/// fitted on the calibration's EOG session, the trained SVM, and what it
/// does online.
#[derive(Debug, Clone)]
pub struct ContinuousDecoder {
    /// The synthetic user's EEG model (at the calibrated ErrP-to-noise
    /// ratio) as calibrated: the held-out session's.
    pub generator: Valid<GeneratorParams>,
    /// The same user in the closed loop ([`Realism::closed_loop`]; the same
    /// model for an ideal user): what the episodes stream.
    ///
    /// [`Realism::closed_loop`]: errp_bci::Realism::closed_loop
    pub closed_loop: Valid<GeneratorParams>,
    /// The montage.
    pub montage: Montage,
    /// Preprocessing fitted during calibration.
    pub preprocessor: Preprocessor,
    /// The SVM with its Platt scaling.
    pub model: SvmModel,
    /// Temporal + theta PSD features of one window.
    pub features: ContinuousFeatures,
    /// The operating point on a held-out session (set by
    /// [`measure_online`](Self::measure_online)).
    pub online: Option<OnlineReport>,
    /// A person's own EEG in place of the synthetic user's EEG: the
    /// held-out session and the episodes feed on its background with the
    /// subject's response (a hybrid).
    pub hybrid: Option<Arc<HybridSource>>,
    /// What the hybrid was made of, and the accuracy the shared control
    /// assumes (its cross-validated accuracy).
    pub own_eeg: Option<Box<crate::epuck::hybrid_report::HybridReport>>,
}

impl ContinuousDecoder {
    /// The online decoder a calibration produced, not yet measured online.
    pub fn from_report(report: &ContinuousReport) -> Self {
        Self {
            generator: report.generator.clone(),
            closed_loop: report.generator.clone(),
            montage: Montage::standard(),
            preprocessor: report.calibrated.session.preprocessor.clone(),
            model: report.calibrated.model.clone(),
            features: ContinuousFeatures::paper(report.generator.sfreq_hz),
            online: None,
            hybrid: None,
            own_eeg: None,
        }
    }

    /// This decoder with the closed loop that follows the calibration of
    /// `setup` by user `seed` ([`Setup::closed_loop_generator`] at this
    /// decoder's ratio).
    ///
    /// [`Setup::closed_loop_generator`]: errp_bci::Setup::closed_loop_generator
    pub fn with_closed_loop(mut self, setup: &ContinuousSetup, seed: u64) -> Result<Self> {
        self.closed_loop = setup
            .at_ratio(self.generator.errp_to_noise)?
            .closed_loop_generator(seed)?;
        Ok(self)
    }

    /// The held-out session of this pipeline for a calibration
    /// seeded `seed`: [`HeldOutParams::default`] of fresh EEG.
    pub fn record_held_out(&self, seed: u64) -> Result<HeldOutSession> {
        Ok(simulate_held_out_from(
            &self.generator,
            self.hybrid.as_deref(),
            &self.montage,
            &self.preprocessor,
            &self.model,
            &Valid::<HeldOutParams>::default(),
            held_out_seed(seed),
        )?)
    }

    /// Measures the operating point of `detector` at threshold `t_e` on the
    /// held-out session for `seed` and keeps it.
    pub fn measure_online(
        &mut self,
        detector: Valid<DetectorParams>,
        t_e: f64,
        seed: u64,
    ) -> Result<()> {
        let recording = self.record_held_out(seed)?;
        self.online = Some(OnlineReport::from_held_out(&recording, detector, t_e)?);
        Ok(())
    }

    /// The span over which detections (of the detector in force) and windows
    /// are attributed to an ErrP: measured if
    /// [`measure_online`](Self::measure_online) ran, else the span the
    /// features can see.
    pub fn detection_span(&self) -> ResponseSpan {
        self.online
            .as_ref()
            .map_or(UNMEASURED_SPAN, |o| o.point.span)
    }

    /// The threshold the detector of an episode with `params` runs at: the
    /// one this decoder's operating point was measured at (calibrated, with
    /// an online false-alarm target), else the scenario's `control.t_e`,
    /// which is also the threshold for a decoder of the user's own
    /// (`own_decoder`) in place of this one's SVM. The one place T_e is
    /// resolved.
    pub fn detector_t_e(&self, params: &EpuckTaskParams, own_decoder: bool) -> f64 {
        match &self.online {
            Some(o) if !own_decoder => o.t_e,
            _ => params.control.t_e,
        }
    }

    /// The span over which single windows respond to an ErrP.
    pub fn window_span(&self) -> ResponseSpan {
        self.online
            .as_ref()
            .map_or(UNMEASURED_SPAN, |o| o.window_span)
    }

    /// Starts the online stream for one episode: EEG from `seed`, the
    /// filters settled; episode time 0 is generator time
    /// [`WARM_UP_SECS`](errp_bci::WARM_UP_SECS).
    pub fn start_stream(&self, seed: u64) -> Result<SlidingWindow> {
        let generator: EegFeed = match &self.hybrid {
            Some(h) => h.online_feed(&self.closed_loop, seed)?.into(),
            None => EegGenerator::new(&self.closed_loop, &self.montage, seed)?.into(),
        };
        Ok(SlidingWindow::start(
            generator,
            &self.preprocessor,
            &self.features,
            &self.montage,
        )?)
    }
}
