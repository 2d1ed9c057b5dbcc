//! The continuous ErrP decoder of the e-puck task (sec. 2.2.2): calibrated on
//! button-locked examples (sec. 5.1), then run online on an 800 ms window
//! that slides every 62.5 ms over streamed EEG.

use errp_bci::{
    Calibrated, ContinuousFeatures, ContinuousSetup, EegBlock, EegGenerator, ErrorModel,
    GeneratorParams, Montage, Preprocessor, SvmDecoder, SvmModel, TargetingParams, TargetingResult,
    TargetingStep, calibrate_continuous, target_continuous_accuracy,
};

use crate::error::Result;

/// What to calibrate.
#[derive(Debug, Clone)]
pub struct ContinuousRequest {
    /// Requested mean accuracy (cross-validated, per-class rates), in (0.5, 1).
    pub accuracy: f64,
    /// Seed of the synthetic user and session.
    pub seed: u64,
    /// EEG model, protocol, preprocessing, montage.
    pub setup: ContinuousSetup,
    /// Search settings.
    pub search: TargetingParams,
}

impl ContinuousRequest {
    /// A request with the paper's protocol and the default EEG model.
    pub fn new(accuracy: f64, seed: u64) -> Self {
        Self {
            accuracy,
            seed,
            setup: ContinuousSetup::default(),
            search: TargetingParams::default(),
        }
    }
}

/// The outcome of [`run_continuous_calibration`].
#[derive(Debug, Clone)]
pub struct ContinuousReport {
    /// The search for the ErrP-to-noise ratio.
    pub targeting: TargetingResult,
    /// The EEG model at the ratio found.
    pub generator: GeneratorParams,
    /// The session at that ratio, its cross-validated accuracy and the SVM
    /// trained on all of it.
    pub calibrated: Calibrated<SvmModel>,
}

/// Targets the requested accuracy with the SVM decoder, then re-runs the
/// calibration session at the ratio found, scores it and trains on it.
pub fn run_continuous_calibration(
    request: &ContinuousRequest,
    progress: impl FnMut(&TargetingStep),
) -> Result<ContinuousReport> {
    let svm = SvmDecoder::default();
    let targeting = target_continuous_accuracy(
        request.accuracy,
        &svm,
        &request.setup,
        &request.search,
        request.seed,
        progress,
    )?;
    calibrate_continuous_at(request, targeting)
}

/// The second half of [`run_continuous_calibration`], for a ratio already
/// found (e.g. from a sweep's cache): re-runs the session at
/// `targeting.ratio`, scores it and trains on it.
pub fn calibrate_continuous_at(
    request: &ContinuousRequest,
    targeting: TargetingResult,
) -> Result<ContinuousReport> {
    let svm = SvmDecoder::default();
    let generator = GeneratorParams {
        errp_to_noise: targeting.ratio,
        ..request.setup.generator.clone()
    };
    let setup = ContinuousSetup {
        generator: generator.clone(),
        ..request.setup.clone()
    };
    let calibrated = calibrate_continuous(&svm, &setup, request.seed)?;
    Ok(ContinuousReport {
        targeting,
        generator,
        calibrated,
    })
}

/// The calibrated online pipeline: the user's EEG model, the preprocessing
/// fitted on the calibration's EOG recording, and the trained SVM.
#[derive(Debug, Clone)]
pub struct ContinuousDecoder {
    /// The synthetic user's EEG model (at the calibrated ErrP-to-noise ratio).
    pub generator: GeneratorParams,
    /// The montage.
    pub montage: Montage,
    /// Preprocessing fitted during calibration.
    pub preprocessor: Preprocessor,
    /// The SVM with its Platt scaling.
    pub model: SvmModel,
    /// Temporal + theta PSD features of one window.
    pub features: ContinuousFeatures,
}

impl ContinuousDecoder {
    /// The online decoder a calibration produced.
    pub fn from_report(report: &ContinuousReport) -> Self {
        Self {
            generator: report.generator.clone(),
            montage: Montage::standard(),
            preprocessor: report.calibrated.session.preprocessor.clone(),
            model: report.calibrated.model.clone(),
            features: ContinuousFeatures::paper(report.generator.sfreq_hz),
        }
    }

    /// Samples between two decoder windows: 62.5 ms (sec. 2.2.2).
    pub fn hop_samples(&self) -> usize {
        (0.0625 * self.generator.sfreq_hz).round() as usize
    }
}

/// Seconds of EEG streamed before an episode so the causal filters settle.
pub const WARM_UP_SECS: f64 = 2.0;

/// Streamed EEG and the sliding window over its preprocessed channels.
pub(crate) struct OnlineWindow {
    pub(crate) generator: EegGenerator,
    preprocessor: Preprocessor,
    features: ContinuousFeatures,
    window: EegBlock,
    scratch: Vec<f64>,
    raw: EegBlock,
    /// Rows of FCz and Cz among the preprocessed channels.
    pub(crate) fcz_cz: [usize; 2],
}

impl OnlineWindow {
    /// Starts the stream and lets the filters settle; the episode's time 0
    /// is generator time [`WARM_UP_SECS`].
    pub(crate) fn start(d: &ContinuousDecoder, seed: u64) -> Result<Self> {
        let fs = d.generator.sfreq_hz;
        let mut generator = EegGenerator::new(d.generator.clone(), &d.montage, seed)?;
        let mut preprocessor = d.preprocessor.clone();
        preprocessor.reset();
        let warm = preprocessor.process(&generator.generate((WARM_UP_SECS * fs) as usize));
        let span = d.features.span();
        let mut window = EegBlock::zeros(warm.n_channels, span);
        for ch in 0..warm.n_channels {
            let src = warm.channel(ch);
            window
                .channel_mut(ch)
                .copy_from_slice(&src[src.len() - span..]);
        }
        let row = |name: &str| -> Result<usize> {
            let i = d.montage.index(name)?;
            Ok(preprocessor
                .outputs()
                .iter()
                .position(|&o| o == i)
                .unwrap_or(0))
        };
        let fcz_cz = [row("FCz")?, row("Cz")?];
        let n_ch = d.montage.len();
        Ok(Self {
            generator,
            preprocessor,
            features: d.features.clone(),
            window,
            scratch: Vec::with_capacity(d.features.n_features(warm.n_channels)),
            raw: EegBlock::zeros(n_ch, d.hop_samples()),
            fcz_cz,
        })
    }

    /// Streams `hop` more samples through the preprocessing, slides the
    /// window, and returns the new preprocessed samples `(n_channels, hop)`.
    pub(crate) fn advance(&mut self) -> EegBlock {
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
    pub(crate) fn p_error(&mut self, model: &SvmModel) -> f64 {
        self.scratch.clear();
        self.features
            .extract_into(&self.window, 0, &mut self.scratch);
        model.p_error(&self.scratch)
    }
}
