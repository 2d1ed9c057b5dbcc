//! A calibration run: accuracy targeting, then the calibration session at the
//! ratio found, scored and trained like the paper's; and its recording.

#[cfg(feature = "rerun")]
mod view;

#[cfg(feature = "rerun")]
pub use view::{calibration_recording, record_calibration};

use errp_bci::{
    Calibrated, CalibrationParams, GeneratorParams, LdaDecoder, LdaModel, MeanAccuracy, Protocol,
    SessionOptions, Setup, TargetingParams, TargetingResult, TargetingStep, calibrate,
    target_accuracy,
};

use crate::error::Result;

/// What to calibrate: a synthetic user recorded with protocol `P` (the
/// discrete session or the button-locked one), targeted at a mean accuracy.
#[derive(Debug, Clone)]
pub struct Request<P> {
    /// Requested mean accuracy.
    pub accuracy: MeanAccuracy,
    /// Seed of the synthetic user and session.
    pub seed: u64,
    /// EEG model, protocol, preprocessing, montage.
    pub setup: Setup<P>,
    /// Search settings.
    pub search: TargetingParams,
}

impl<P: Protocol> Request<P> {
    /// A request with the paper's protocol and the default EEG model.
    pub fn new(accuracy: MeanAccuracy, seed: u64) -> Self {
        Self {
            accuracy,
            seed,
            setup: Setup::default(),
            search: TargetingParams::default(),
        }
    }

    /// This request's key in a [`TargetingCache`].
    pub fn targeting_key(&self) -> String {
        let Self {
            accuracy,
            seed,
            setup,
            search,
        } = self;
        format!(
            "{setup:?} {search:?} accuracy={:?} seed={seed}",
            accuracy.get()
        )
    }
}

/// The outcome of a calibration whose decoder is a model `M`.
#[derive(Debug, Clone)]
pub struct Report<M> {
    /// The search for the ErrP-to-noise ratio.
    pub targeting: TargetingResult,
    /// The EEG model at the ratio found.
    pub generator: GeneratorParams,
    /// The calibration session at that ratio, its cross-validated accuracy
    /// and the decoder trained on all of it.
    pub calibrated: Calibrated<M>,
}

/// The discrete calibration of the grid task and `errp calibrate`.
pub type CalibrationRequest = Request<CalibrationParams>;

/// Its outcome: the LDA decoder.
pub type CalibrationReport = Report<LdaModel>;

/// Targets the requested accuracy, then simulates the calibration session at
/// the ratio found from scratch (raw EEG through the whole pipeline), scores
/// it by k-fold cross-validation and trains the decoder on every trial.
/// `progress` sees each targeting step; `options` asks for grand averages
/// and a sink for the raw session (`errp calibrate --save`, `--export`).
pub fn run_calibration(
    request: &CalibrationRequest,
    progress: impl FnMut(&TargetingStep),
    options: SessionOptions<'_>,
) -> Result<CalibrationReport> {
    let decoder = LdaDecoder::default();
    let targeting = target_accuracy(
        request.accuracy,
        &decoder,
        &request.setup,
        &request.search,
        request.seed,
        progress,
    )?;
    calibrate_at(request, targeting, options)
}

/// The second half of [`run_calibration`], for a ratio already found (by
/// an earlier search with the same request): simulates the session at
/// `targeting.ratio`, scores it and trains on it.
pub fn calibrate_at(
    request: &CalibrationRequest,
    targeting: TargetingResult,
    options: SessionOptions<'_>,
) -> Result<CalibrationReport> {
    let setup = request.setup.at_ratio(targeting.ratio);
    let calibrated = calibrate(&LdaDecoder::default(), &setup, request.seed, options)?;
    Ok(CalibrationReport {
        targeting,
        generator: setup.generator,
        calibrated,
    })
}

/// Where targeting results are looked up before searching and kept after:
/// the one place a sweep's on-disk cache plugs into the decoder preparation
/// that `errp run`, Table 1 and sweeps share. The result of a search is a
/// pure function of the request, so a cached result is the one the search
/// would find.
pub trait TargetingCache: Sync {
    /// The targeting of `request` (text naming everything the search
    /// depends on) of `kind` (the decoder: "grid-lda-online",
    /// "epuck-svm"): from the cache if it holds it and `verify` accepts
    /// it, else `search`'s result, then kept. The flag is true for a cache
    /// hit.
    ///
    /// `verify` evaluates a cached result again and says why it cannot be
    /// what the search finds (see
    /// [`TargetingResult::inconsistency`](errp_bci::TargetingResult::inconsistency)),
    /// or `None`; an entry it rejects, or that it fails on, is a miss.
    fn get_or_search(
        &self,
        kind: &str,
        request: &str,
        search: &mut dyn FnMut() -> Result<TargetingResult>,
        verify: &mut dyn FnMut(&TargetingResult) -> Result<Option<String>>,
    ) -> Result<(TargetingResult, bool)>;
}

/// No cache: every request is searched.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoCache;

impl TargetingCache for NoCache {
    fn get_or_search(
        &self,
        _kind: &str,
        _request: &str,
        search: &mut dyn FnMut() -> Result<TargetingResult>,
        _verify: &mut dyn FnMut(&TargetingResult) -> Result<Option<String>>,
    ) -> Result<(TargetingResult, bool)> {
        Ok((search()?, false))
    }
}
