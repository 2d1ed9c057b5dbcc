//! A calibration run: accuracy targeting, then the calibration session at the
//! ratio found, scored and trained like the paper's; and its recording.

#[cfg(feature = "rerun")]
mod view;

#[cfg(feature = "rerun")]
pub use view::{calibration_recording, record_calibration};

use errp_bci::{
    Calibrated, CalibrationParams, ChannelKind, GeneratorParams, LdaDecoder, LdaModel,
    MeanAccuracy, Protocol, SessionOptions, Setup, TargetingParams, TargetingResult, TargetingStep,
    Valid, calibrate, target_accuracy,
};

use crate::error::Result;
use crate::key::StableKey;

/// What to calibrate: a synthetic user recorded with protocol `P` (the
/// discrete session or the button-locked one), targeted at a mean accuracy.
#[derive(Debug, Clone)]
pub struct Request<P> {
    /// Requested mean accuracy.
    pub accuracy: MeanAccuracy,
    /// Seed of the synthetic user and session.
    pub seed: u64,
    /// EEG model, protocol, preprocessing, montage.
    pub setup: Valid<Setup<P>>,
    /// Search settings.
    pub search: TargetingParams,
}

impl<P: Protocol> Request<P> {
    /// A request with the paper's protocol and the default EEG model.
    pub fn new(accuracy: MeanAccuracy, seed: u64) -> Self {
        Self {
            accuracy,
            seed,
            setup: Valid::default(),
            search: TargetingParams::default(),
        }
    }
}

/// The version of [`Request::targeting_key`]: raise it when what the key
/// holds changes (a field of the setup added, removed or renamed).
pub const TARGETING_KEY_VERSION: u32 = 2;

impl<P: Protocol + serde::Serialize> Request<P> {
    /// This request's key in a [`TargetingCache`]: every field of the
    /// request, the montage by its channels ([`crate::StableKey`]).
    pub fn targeting_key(&self) -> String {
        let Self {
            accuracy,
            seed,
            setup,
            search,
        } = self;
        let Setup {
            generator,
            calibration,
            preprocess,
            montage,
        } = setup.get();
        let channels: Vec<(&str, &str, [f64; 3])> = montage
            .channels()
            .iter()
            .map(|c| {
                let kind = match c.kind {
                    ChannelKind::Eeg => "eeg",
                    ChannelKind::Eog => "eog",
                };
                (c.name.as_str(), kind, c.position)
            })
            .collect();
        StableKey::new("targeting", TARGETING_KEY_VERSION)
            .float("accuracy", accuracy.get())
            .int("seed", *seed)
            .value("generator", generator)
            .value("calibration", calibration)
            .value("preprocess", preprocess)
            .value("montage", &channels)
            .value("search", search)
            .finish()
    }
}

/// The outcome of a calibration whose decoder is a model `M`.
#[derive(Debug, Clone)]
pub struct Report<M> {
    /// The search for the ErrP-to-noise ratio.
    pub targeting: TargetingResult,
    /// The EEG model at the ratio found.
    pub generator: Valid<GeneratorParams>,
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
    let setup = Valid::new(request.setup.at_ratio(targeting.ratio)?)?;
    let calibrated = calibrate(&LdaDecoder::default(), &setup, request.seed, options)?;
    Ok(CalibrationReport {
        targeting,
        generator: setup.generator.clone(),
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

#[cfg(test)]
mod tests {
    use errp_bci::{ContinuousCalibrationParams, DetectorParams, OnlineTarget, PreprocessParams};

    use super::*;
    use crate::key::shape;

    /// What the targeting key (on disk) and the decoder keys (in memory)
    /// hold of each parameter struct. A field renamed, added or removed
    /// changes the keys: this fails until the list is updated and, for the
    /// targeting key, [`TARGETING_KEY_VERSION`] raised (old cache entries
    /// are then never read as new ones).
    #[test]
    fn the_keys_hold_these_fields() {
        let fields = |v: Vec<String>| v.join(" ");
        // Held by the targeting key, on disk: raise TARGETING_KEY_VERSION.
        assert_eq!(
            fields(shape(&GeneratorParams::default())),
            "alpha_bandwidth_hz alpha_hz alpha_uv amplitude_variability background_uv \
             blink_rate_hz blink_uv errp_to_noise latency_jitter_ms line_hz line_noise_uv \
             saccade_rate_hz saccade_uv sensor_noise_uv sfreq_hz spatial_length"
        );
        assert_eq!(
            fields(shape(&CalibrationParams::default())),
            "eog_session_secs error_rate folds interval_max_secs interval_min_secs n_actions"
        );
        assert_eq!(
            fields(shape(&ContinuousCalibrationParams::default())),
            "eog_session_secs folds interval_max_secs interval_min_secs per_class \
             trigger_jitter_ms"
        );
        assert_eq!(
            fields(shape(&PreprocessParams::default())),
            "high_hz line_hz low_hz"
        );
        assert_eq!(
            fields(shape(&TargetingParams::default())),
            "max_evaluations max_ratio tolerance"
        );
        assert_eq!(TARGETING_KEY_VERSION, 2);
        // Held by the e-puck's decoder key, in memory.
        assert_eq!(
            fields(shape(&DetectorParams::default())),
            "mode refractory_secs smooth_windows"
        );
        let target = OnlineTarget {
            hit_rate: 0.7,
            false_alarms_per_min: Some(1.0),
        };
        assert_eq!(fields(shape(&target)), "false_alarms_per_min hit_rate");
    }

    /// The targeting key of a request holds every value in it: a ratio
    /// tolerance or an EEG parameter changed in the last bit is another
    /// entry, and equal requests share one.
    #[test]
    fn a_targeting_key_changes_with_any_value() {
        let base = Request::<CalibrationParams>::new(MeanAccuracy::new(0.75).unwrap(), 1);
        let key = base.targeting_key();
        assert!(key.starts_with("targeting/v2;accuracy=f:"), "{key}");
        assert_eq!(key, base.clone().targeting_key());
        let mut other = base.clone();
        let generator = base
            .setup
            .generator
            .with(|g| g.alpha_hz = f64::from_bits(g.alpha_hz.to_bits() + 1))
            .unwrap();
        other.setup = base.setup.with(|s| s.generator = generator).unwrap();
        assert_ne!(other.targeting_key(), key);
        let mut other = base.clone();
        other.seed = 2;
        assert_ne!(other.targeting_key(), key);
        let mut other = base;
        other.search.tolerance *= 2.0;
        assert_ne!(other.targeting_key(), key);
    }
}
