//! The calibration session of sec. 4.1 and its cross-validated score.

use nalgebra::DMatrix;
use rand::Rng;
use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

use crate::classify::{Classifier, ErrorModel, Features};
use crate::erp::AssessmentKind;
use crate::error::{Result, check};
use crate::features::{EpochWindow, FeatureExtractor};
use crate::generator::{Assessment, Components, EegBlock, EegGenerator, GeneratorParams};
use crate::montage::Montage;
use crate::platt::PlattScaling;
use crate::preprocess::{PreprocessParams, Preprocessor};
use crate::rng::{derive_seed, stream};

/// How the calibration session runs (sec. 4.1 of the paper).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CalibrationParams {
    /// Number of actions (the paper: 400).
    pub n_actions: usize,
    /// Probability that an action is erroneous (the paper: 20 %).
    pub error_rate: f64,
    /// Shortest inter-action interval (s).
    pub interval_min_secs: f64,
    /// Longest inter-action interval (s).
    pub interval_max_secs: f64,
    /// Length of the EOG recording (deliberate blinks and saccades) that the
    /// EOG regression is fitted on, before the session (s).
    pub eog_session_secs: f64,
    /// Cross-validation folds.
    pub folds: usize,
}

impl Default for CalibrationParams {
    fn default() -> Self {
        Self {
            n_actions: 400,
            error_rate: 0.2,
            interval_min_secs: 3.0,
            interval_max_secs: 3.5,
            eog_session_secs: 60.0,
            folds: 10,
        }
    }
}

impl CalibrationParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        check(
            self.n_actions >= 20,
            "n_actions",
            self.n_actions,
            "at least 20",
        )?;
        check(
            self.error_rate > 0.0 && self.error_rate < 1.0,
            "error_rate",
            self.error_rate,
            "a probability in (0, 1)",
        )?;
        check_intervals(
            self.interval_min_secs,
            self.interval_max_secs,
            "an epoch lasts 0.8 s",
        )?;
        check(
            self.eog_session_secs >= 15.0 && self.eog_session_secs.is_finite(),
            "eog_session_secs",
            self.eog_session_secs,
            "at least 15 s",
        )?;
        check(self.folds >= 2, "folds", self.folds, "at least 2")
    }
}

/// Per-class and mean detection rates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Accuracy {
    /// Fraction of correct assessments classified as correct.
    pub correct: f64,
    /// Fraction of erroneous assessments classified as error.
    pub error: f64,
    /// Number of correct trials scored.
    pub n_correct: usize,
    /// Number of error trials scored.
    pub n_error: usize,
}

impl Accuracy {
    /// Scores predictions (`true` = error) against labels.
    pub fn score(labels: &[bool], predicted: &[bool]) -> Self {
        let mut hits = [0usize; 2];
        let mut counts = [0usize; 2];
        for (&l, &p) in labels.iter().zip(predicted) {
            counts[usize::from(l)] += 1;
            hits[usize::from(l)] += usize::from(l == p);
        }
        let rate = |k: usize| {
            if counts[k] == 0 {
                f64::NAN
            } else {
                hits[k] as f64 / counts[k] as f64
            }
        };
        Self {
            correct: rate(0),
            error: rate(1),
            n_correct: counts[0],
            n_error: counts[1],
        }
    }

    /// Mean of the two per-class rates: the paper's "accuracy".
    pub fn mean(&self) -> f64 {
        (self.correct + self.error) / 2.0
    }

    /// The accuracy over all the trials of `parts` together: each class rate
    /// weighted by its trial count (a part without trials of a class, whose
    /// rate is undefined, adds nothing to it).
    pub fn pooled<'a>(parts: impl IntoIterator<Item = &'a Accuracy>) -> Accuracy {
        let (mut ch, mut cn, mut eh, mut en) = (0.0, 0, 0.0, 0);
        for a in parts {
            if a.n_correct > 0 {
                ch += a.correct * a.n_correct as f64;
                cn += a.n_correct;
            }
            if a.n_error > 0 {
                eh += a.error * a.n_error as f64;
                en += a.n_error;
            }
        }
        Accuracy {
            correct: ch / cn.max(1) as f64,
            error: eh / en.max(1) as f64,
            n_correct: cn,
            n_error: en,
        }
    }
}

/// Averages of the preprocessed EEG around the action onsets, per class,
/// filtered offline with zero phase (so latencies are those of the EEG).
#[derive(Debug, Clone, PartialEq)]
pub struct GrandAverage {
    /// Channel names, one per row.
    pub channels: Vec<String>,
    /// Latency of each column (ms after the onset).
    pub times_ms: Vec<f64>,
    /// Mean after erroneous actions, `(n_channels, n_times)`, uV.
    pub error: DMatrix<f64>,
    /// Mean after correct actions, `(n_channels, n_times)`, uV.
    pub correct: DMatrix<f64>,
}

impl GrandAverage {
    /// Error minus correct.
    pub fn difference(&self) -> DMatrix<f64> {
        &self.error - &self.correct
    }
}

/// A calibration protocol, the part of a [`Setup`] that says what is
/// recorded: [`CalibrationParams`] (the discrete session) or
/// [`ContinuousCalibrationParams`](crate::ContinuousCalibrationParams) (the
/// button-locked one).
pub trait Protocol: std::fmt::Debug + Clone + PartialEq + Default {
    /// Checks the protocol's parameters.
    fn check(&self) -> Result<()>;
}

impl Protocol for CalibrationParams {
    fn check(&self) -> Result<()> {
        self.validate()
    }
}

/// Everything that defines a simulated user and recording: the EEG model,
/// the calibration protocol `P`, the preprocessing and the montage.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup<P> {
    /// The synthetic EEG.
    pub generator: GeneratorParams,
    /// The calibration protocol.
    pub calibration: P,
    /// The preprocessing.
    pub preprocess: PreprocessParams,
    /// The montage.
    pub montage: Montage,
}

impl<P: Protocol> Default for Setup<P> {
    fn default() -> Self {
        Self {
            generator: GeneratorParams::default(),
            calibration: P::default(),
            preprocess: PreprocessParams::default(),
            montage: Montage::standard(),
        }
    }
}

impl<P: Protocol> Setup<P> {
    /// The default setup with the EEG model at ErrP-to-noise `ratio`.
    pub fn with_ratio(ratio: f64) -> Self {
        Self::default().at_ratio(ratio)
    }

    /// This setup with the EEG model at ErrP-to-noise `ratio`.
    pub fn at_ratio(&self, ratio: f64) -> Self {
        Self {
            generator: GeneratorParams {
                errp_to_noise: ratio,
                ..self.generator.clone()
            },
            ..self.clone()
        }
    }

    /// Checks every part.
    pub fn validate(&self) -> Result<()> {
        self.generator.validate()?;
        self.calibration.check()?;
        self.preprocess.validate(self.generator.sfreq_hz)
    }
}

/// The setup of the discrete calibration session (sec. 2.2).
pub type CalibrationSetup = Setup<CalibrationParams>;

/// A simulated calibration session, preprocessed and cut into features.
#[derive(Debug, Clone)]
pub struct CalibrationSession {
    /// Features, `(n_actions, n_features)`: 312 temporal ones for the
    /// discrete decoder.
    pub features: Features,
    /// `true` where the action was erroneous.
    pub labels: Vec<bool>,
    /// The assessments, on the session clock.
    pub assessments: Vec<Assessment>,
    /// The preprocessor fitted on the EOG recording.
    pub preprocessor: Preprocessor,
    /// Grand averages over every EEG channel, when asked for.
    pub grand_average: Option<GrandAverage>,
}

/// A consumer of raw blocks (all channels) and the assessments whose onsets
/// fall in each, e.g. an EDF writer.
pub type RawSink<'a> = &'a mut dyn FnMut(&EegBlock, &[Assessment]) -> Result<()>;

/// What else to produce while the session is simulated.
#[derive(Default)]
pub struct SessionOptions<'a> {
    /// Which parts of the signal to generate (all, by default).
    pub components: Components,
    /// Compute grand averages over all EEG channels in [-200, 800] ms.
    pub grand_average: bool,
    /// Called with each raw block (all channels) and the assessments whose
    /// onsets fall in it, e.g. to export the raw EEG.
    pub raw_sink: Option<RawSink<'a>>,
}

/// The EOG recording that precedes a session: the same user and montage,
/// asked to blink and look around (2 blinks and 1 saccade per second on
/// average), no actions.
pub fn eog_session(
    params: &GeneratorParams,
    calib: &CalibrationParams,
    montage: &Montage,
    seed: u64,
) -> Result<EegBlock> {
    let eye = GeneratorParams {
        blink_rate_hz: params.blink_rate_hz.max(0.5),
        saccade_rate_hz: params.saccade_rate_hz.max(1.0),
        ..params.clone()
    };
    let mut g = EegGenerator::new(eye, montage, derive_seed(seed, "calibration/eog", 0))?;
    Ok(g.generate((calib.eog_session_secs * params.sfreq_hz) as usize))
}

/// The action schedule of a session: onsets at U[min, max] s intervals, each
/// erroneous with probability `error_rate`.
pub fn schedule(calib: &CalibrationParams, seed: u64) -> Vec<Assessment> {
    let mut rng = stream(seed, "calibration/schedule");
    let mut t = 2.0;
    (0..calib.n_actions)
        .map(|_| {
            let kind = if rng.random_bool(calib.error_rate) {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            };
            let a = Assessment {
                onset_secs: t,
                kind,
            };
            t += rng.random_range(calib.interval_min_secs..=calib.interval_max_secs);
            a
        })
        .collect()
}

/// Simulates a calibration session: EOG recording, preprocessor fit, then
/// `n_actions` assessed actions streamed through the generator and the
/// preprocessor in 1 s blocks, and the paper's temporal features.
pub fn simulate_session(
    setup: &CalibrationSetup,
    seed: u64,
    options: SessionOptions<'_>,
) -> Result<CalibrationSession> {
    setup.validate()?;
    let assessments = schedule(&setup.calibration, seed);
    let onsets: Vec<f64> = assessments.iter().map(|a| a.onset_secs).collect();
    let window = EpochWindow::paper(setup.generator.sfreq_hz);
    simulate_session_with(setup, seed, &assessments, &onsets, &window, options)
}

/// Simulates a session with a given schedule and feature extractor: EOG
/// recording, preprocessor fit, then `assessments` (sorted by onset) streamed
/// through the generator and the preprocessor in 1 s blocks, and one feature
/// vector per assessment from the window that starts at the matching entry of
/// `window_onsets_secs` (rounded to samples), labelled by the assessment.
///
/// Only `eog_session_secs` of `setup.calibration` is used (and validated with
/// the rest); the schedule is the one given. Grand averages are locked to the
/// assessment onsets.
pub fn simulate_session_with(
    setup: &CalibrationSetup,
    seed: u64,
    assessments: &[Assessment],
    window_onsets_secs: &[f64],
    features: &dyn FeatureExtractor,
    mut options: SessionOptions<'_>,
) -> Result<CalibrationSession> {
    setup.validate()?;
    check(
        window_onsets_secs.len() == assessments.len(),
        "window_onsets_secs",
        window_onsets_secs.len(),
        &format!("one window per assessment ({})", assessments.len()),
    )?;
    check(
        assessments
            .windows(2)
            .all(|w| w[0].onset_secs <= w[1].onset_secs)
            && assessments
                .iter()
                .all(|a| a.onset_secs.is_finite() && a.onset_secs >= 0.0),
        "assessments",
        "unsorted",
        "onsets (s) finite, >= 0 and sorted",
    )?;
    check(
        window_onsets_secs.iter().all(|w| w.is_finite()),
        "window_onsets_secs",
        "not finite",
        "finite onsets (s)",
    )?;
    let (params, calib, preprocess, montage) = (
        &setup.generator,
        &setup.calibration,
        &setup.preprocess,
        &setup.montage,
    );
    let fs = params.sfreq_hz;
    let eog = eog_session(params, calib, montage, seed)?;
    let decoding = montage.decoding_indices();
    let mut pre = Preprocessor::fit(montage, preprocess, fs, &eog, &decoding)?;
    let preprocessor = pre.clone();
    let all_eeg: Vec<usize> = (0..montage.n_eeg()).collect();
    let pre_all = if options.grand_average {
        Some(Preprocessor::fit(montage, preprocess, fs, &eog, &all_eeg)?)
    } else {
        None
    };

    let ga_before = (0.2 * fs).round() as usize;
    let ga_len = ga_before + (0.8 * fs).round() as usize;
    let last_onset = assessments
        .iter()
        .map(|a| a.onset_secs)
        .chain(window_onsets_secs.iter().copied())
        .fold(0.0, f64::max);
    let total = ((last_onset * fs).ceil() as usize + features.span().max(ga_len) + 1).max(1);

    let mut generator =
        EegGenerator::new(params.clone(), montage, seed)?.with_components(options.components);
    for a in assessments {
        generator.schedule(*a);
    }
    let block_len = fs as usize;
    let mut decoded = EegBlock::zeros(decoding.len(), 0);
    let mut decoded_chunks = Vec::new();
    let mut full_chunks = Vec::new();
    let mut done = 0;
    let mut next_event = 0;
    while done < total {
        let n = block_len.min(total - done);
        let raw = generator.generate(n);
        if let Some(sink) = options.raw_sink.as_mut() {
            let end = (done + n) as f64 / fs;
            let first = next_event;
            while next_event < assessments.len() && assessments[next_event].onset_secs < end {
                next_event += 1;
            }
            sink(&raw, &assessments[first..next_event])?;
        }
        decoded_chunks.push(pre.process(&raw));
        if let Some(p) = pre_all.as_ref() {
            full_chunks.push(p.apply_spatial(&raw));
        }
        done += n;
    }
    concat_into(&mut decoded, &decoded_chunks);

    let onsets: Vec<usize> = assessments
        .iter()
        .map(|a| (a.onset_secs * fs).round() as usize)
        .collect();
    let n_features = features.n_features(decoding.len());
    let mut flat = Vec::with_capacity(onsets.len() * n_features);
    for &w in window_onsets_secs {
        features.extract_into(&decoded, (w * fs).round().max(0.0) as usize, &mut flat);
    }
    let features = DMatrix::from_row_slice(onsets.len(), n_features, &flat);
    let labels: Vec<bool> = assessments
        .iter()
        .map(|a| a.kind == AssessmentKind::Error)
        .collect();

    let grand_average = if options.grand_average {
        // Offline analysis, as for Fig. 1: zero-phase filtering, so that the
        // latencies are not delayed by the causal online filter.
        let mut full = EegBlock::zeros(all_eeg.len(), 0);
        concat_into(&mut full, &full_chunks);
        drop(full_chunks);
        let filter = pre.filter();
        for ch in 0..full.n_channels {
            filter.filtfilt(full.channel_mut(ch));
        }
        let mut sums = [
            DMatrix::zeros(all_eeg.len(), ga_len),
            DMatrix::zeros(all_eeg.len(), ga_len),
        ];
        let mut counts = [0usize; 2];
        for (&o, &l) in onsets.iter().zip(&labels) {
            if o < ga_before {
                continue;
            }
            counts[usize::from(l)] += 1;
            for ch in 0..all_eeg.len() {
                let x = &full.channel(ch)[o - ga_before..o - ga_before + ga_len];
                for (t, v) in x.iter().enumerate() {
                    sums[usize::from(l)][(ch, t)] += v;
                }
            }
        }
        let [c, e] = sums;
        Some(GrandAverage {
            channels: all_eeg
                .iter()
                .map(|&i| montage.channels()[i].name.clone())
                .collect(),
            times_ms: (0..ga_len)
                .map(|t| (t as f64 - ga_before as f64) / fs * 1000.0)
                .collect(),
            error: e / counts[1].max(1) as f64,
            correct: c / counts[0].max(1) as f64,
        })
    } else {
        None
    };

    Ok(CalibrationSession {
        features,
        labels,
        assessments: assessments.to_vec(),
        preprocessor,
        grand_average,
    })
}

/// The seed of the cross-validation folds of a session simulated from `seed`
/// (shared by [`calibrate`] and accuracy targeting, so both score alike).
pub fn cv_seed(seed: u64) -> u64 {
    derive_seed(seed, "calibration/cv", 0)
}

/// A calibrated decoder: the session, its cross-validated accuracy and the
/// model trained on all of it.
#[derive(Debug, Clone)]
pub struct Calibrated<M> {
    /// The simulated session.
    pub session: CalibrationSession,
    /// k-fold cross-validated accuracy.
    pub accuracy: Accuracy,
    /// The decoder trained on every trial, for online use.
    pub model: M,
    /// Platt scaling of the decision values, fitted on the out-of-fold
    /// decisions with the session's 20 % error prior removed: a calibrated
    /// p(error) for online use.
    pub platt: PlattScaling,
}

/// Runs a calibration session as the paper did: simulate it, score the
/// decoder by k-fold cross-validation, train it on every trial.
pub fn calibrate<C: Classifier>(
    classifier: &C,
    setup: &CalibrationSetup,
    seed: u64,
    options: SessionOptions<'_>,
) -> Result<Calibrated<C::Model>> {
    let session = simulate_session(setup, seed, options)?;
    calibrate_session(classifier, session, setup.calibration.folds, seed)
}

/// The second half of [`calibrate`], on a session already simulated (e.g.
/// by [`SessionParts::session_at`](crate::SessionParts::session_at)): scores
/// the decoder by `folds`-fold cross-validation and trains it on every trial,
/// with the folds and the fit seeded from the session's `seed`.
pub fn calibrate_session<C: Classifier>(
    classifier: &C,
    session: CalibrationSession,
    folds: usize,
    seed: u64,
) -> Result<Calibrated<C::Model>> {
    let decisions = out_of_fold_decisions(
        classifier,
        &session.features,
        &session.labels,
        folds,
        cv_seed(seed),
    )?;
    let predicted: Vec<bool> = decisions.iter().map(|&d| d >= 0.0).collect();
    let accuracy = Accuracy::score(&session.labels, &predicted);
    let platt = PlattScaling::fit(&decisions, &session.labels)?
        .balanced(accuracy.n_error, accuracy.n_correct);
    let model = classifier.fit(
        &session.features,
        &session.labels,
        derive_seed(seed, "calibration/fit", 0),
    )?;
    Ok(Calibrated {
        session,
        accuracy,
        model,
        platt,
    })
}

fn concat_into(dst: &mut EegBlock, chunks: &[EegBlock]) {
    let n: usize = chunks.iter().map(|c| c.n_samples).sum();
    let mut out = EegBlock::zeros(dst.n_channels, n);
    for ch in 0..dst.n_channels {
        let row = out.channel_mut(ch);
        let mut at = 0;
        for c in chunks {
            row[at..at + c.n_samples].copy_from_slice(c.channel(ch));
            at += c.n_samples;
        }
    }
    *dst = out;
}

/// Stratified k-fold cross-validation: every trial is scored by a model
/// trained without it. Folds are drawn from `seed`.
pub fn cross_validate<C: Classifier>(
    classifier: &C,
    x: &Features,
    labels: &[bool],
    folds: usize,
    seed: u64,
) -> Result<Accuracy> {
    let decisions = out_of_fold_decisions(classifier, x, labels, folds, seed)?;
    let predicted: Vec<bool> = decisions.iter().map(|&d| d >= 0.0).collect();
    Ok(Accuracy::score(labels, &predicted))
}

/// The decision value of every trial from the model of the fold that left
/// it out (stratified k-fold, folds drawn from `seed`).
pub fn out_of_fold_decisions<C: Classifier>(
    classifier: &C,
    x: &Features,
    labels: &[bool],
    folds: usize,
    seed: u64,
) -> Result<Vec<f64>> {
    let fold_of = stratified_folds(labels, folds, seed);
    let mut decisions = vec![0.0; labels.len()];
    for k in 0..folds {
        let train: Vec<usize> = (0..labels.len()).filter(|&i| fold_of[i] != k).collect();
        let test: Vec<usize> = (0..labels.len()).filter(|&i| fold_of[i] == k).collect();
        if test.is_empty() {
            continue;
        }
        let xt = x.select_rows(train.iter());
        let yt: Vec<bool> = train.iter().map(|&i| labels[i]).collect();
        let model = classifier.fit(&xt, &yt, derive_seed(seed, "cv/fit", k as u64))?;
        for &i in &test {
            let row: Vec<f64> = x.row(i).iter().copied().collect();
            decisions[i] = model.decision(&row);
        }
    }
    Ok(decisions)
}

/// Fold index of every trial: each class shuffled and dealt round-robin.
pub fn stratified_folds(labels: &[bool], folds: usize, seed: u64) -> Vec<usize> {
    let mut rng = stream(seed, "cv/folds");
    let mut fold_of = vec![0; labels.len()];
    for class in [false, true] {
        let mut idx: Vec<usize> = (0..labels.len()).filter(|&i| labels[i] == class).collect();
        idx.shuffle(&mut rng);
        for (k, i) in idx.into_iter().enumerate() {
            fold_of[i] = k % folds;
        }
    }
    fold_of
}

/// Checks the bounds of the uniform interval between a protocol's events:
/// the minimum at least 1 s (`why`) and at most the maximum, which is
/// finite.
pub(crate) fn check_intervals(min_secs: f64, max_secs: f64, why: &str) -> Result<()> {
    check(
        min_secs >= 1.0 && min_secs <= max_secs,
        "interval_min_secs",
        min_secs,
        &format!("at least 1 s ({why}) and at most interval_max_secs"),
    )?;
    check(
        max_secs.is_finite(),
        "interval_max_secs",
        max_secs,
        "a finite number of seconds",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accuracy_scores_per_class() {
        let labels = [false, false, false, true, true];
        let pred = [false, true, false, true, false];
        let a = Accuracy::score(&labels, &pred);
        assert!((a.correct - 2.0 / 3.0).abs() < 1e-12);
        assert!((a.error - 0.5).abs() < 1e-12);
        assert!((a.mean() - (2.0 / 3.0 + 0.5) / 2.0).abs() < 1e-12);
    }

    #[test]
    fn schedule_follows_the_protocol() {
        let calib = CalibrationParams::default();
        let s = schedule(&calib, 3);
        assert_eq!(s.len(), 400);
        for w in s.windows(2) {
            let dt = w[1].onset_secs - w[0].onset_secs;
            assert!((3.0..=3.5).contains(&dt), "{dt}");
        }
        let errors = s.iter().filter(|a| a.kind == AssessmentKind::Error).count();
        // Binomial(400, 0.2): mean 80, sd 8.
        assert!((56..=104).contains(&errors), "{errors}");
    }

    #[test]
    fn folds_are_stratified() {
        let labels: Vec<bool> = (0..100).map(|i| i % 5 == 0).collect();
        let f = stratified_folds(&labels, 10, 1);
        for k in 0..10 {
            let errors = (0..100).filter(|&i| f[i] == k && labels[i]).count();
            assert_eq!(errors, 2);
        }
    }

    #[test]
    fn bad_calibration_parameters_are_named() {
        let c = CalibrationParams {
            error_rate: 1.5,
            ..CalibrationParams::default()
        };
        assert!(c.validate().unwrap_err().to_string().contains("error_rate"));
    }
}
