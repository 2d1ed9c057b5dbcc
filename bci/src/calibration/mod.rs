//! The calibration session of sec. 4.1 and its cross-validated score.

use errp_valid::{Check, Valid};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::error::{BciError, Result, check};
use crate::generator::{GeneratorParams, Realism};
use crate::montage::Montage;
use crate::preprocess::{PreprocessParams, Preprocessing};

pub(crate) mod continuous;
mod cv;
mod session;
pub(crate) mod targeting;

pub use cv::*;
pub use session::*;

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
    /// Length of the EOG session (deliberate blinks and saccades) that the
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
    fn validate(&self) -> Result<()> {
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
        check_eog_session(self.eog_session_secs)?;
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
        // No trial of a class: no rate (NaN), never an invented 0.
        let rate = |hits: f64, n: usize| if n == 0 { f64::NAN } else { hits / n as f64 };
        Accuracy {
            correct: rate(ch, cn),
            error: rate(eh, en),
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
/// button-locked one). Its [`Check`] is part of the setup's.
pub trait Protocol:
    Check<Error = BciError> + std::fmt::Debug + Clone + PartialEq + Default
{
    /// The session's expected length (s): where on the user's session
    /// clock a closed loop that follows it starts.
    fn duration_secs(&self) -> f64;
}

impl Check for CalibrationParams {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl Protocol for CalibrationParams {
    fn duration_secs(&self) -> f64 {
        self.eog_session_secs
            + self.n_actions as f64 * 0.5 * (self.interval_min_secs + self.interval_max_secs)
    }
}

/// How closely and how hard to search for an ErrP-to-noise ratio (for an
/// accuracy, or for an online hit rate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TargetingParams {
    /// Stop once the cross-validated mean accuracy is this close (fraction).
    pub tolerance: f64,
    /// Most decoder evaluations (each a full cross-validation).
    pub max_evaluations: usize,
    /// Largest ratio tried.
    pub max_ratio: f64,
}

impl Default for TargetingParams {
    fn default() -> Self {
        Self {
            tolerance: 0.005,
            max_evaluations: 16,
            max_ratio: 8.0,
        }
    }
}

/// Everything that defines a simulated user and its session: the EEG model,
/// the calibration protocol `P`, the preprocessing and the montage.
///
/// The sessions take it checked, as a `Valid<Setup<P>>`; the EEG model in
/// it is checked on its own, where it enters.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup<P> {
    /// The synthetic EEG.
    pub generator: Valid<GeneratorParams>,
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
            generator: Valid::default(),
            calibration: P::default(),
            preprocess: PreprocessParams::default(),
            montage: Montage::standard(),
        }
    }
}

/// The protocol, and the preprocessing against the EEG model's sampling
/// rate (the EEG model is checked on its own).
impl<P: Protocol> Check for Setup<P> {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.calibration.check()?;
        self.preprocessing().check()
    }
}

impl<P> Setup<P> {
    /// The preprocessing at the EEG model's sampling rate.
    fn preprocessing(&self) -> Preprocessing {
        Preprocessing {
            params: self.preprocess.clone(),
            sfreq_hz: self.generator.sfreq_hz,
        }
    }
}

/// The preprocessing of a checked setup (the setup's check includes its).
pub(crate) fn preprocessing<P>(setup: &Valid<Setup<P>>) -> Valid<Preprocessing> {
    setup.part(Setup::preprocessing)
}

impl<P: Protocol> Setup<P> {
    /// The default setup with the EEG model at ErrP-to-noise `ratio`.
    pub fn with_ratio(ratio: f64) -> Result<Self> {
        Self::default().at_ratio(ratio)
    }

    /// This setup with the EEG model at ErrP-to-noise `ratio` (the changed
    /// EEG model is checked again).
    pub fn at_ratio(&self, ratio: f64) -> Result<Self> {
        Ok(Self {
            generator: self.generator.with(|g| g.errp_to_noise = ratio)?,
            ..self.clone()
        })
    }

    /// This setup with the user of the given `realism` (checked again).
    pub fn with_realism(&self, realism: &Realism) -> Result<Self> {
        Ok(Self {
            generator: self.generator.with(|g| g.realism = realism.clone())?,
            ..self.clone()
        })
    }

    /// The EEG model of the closed loop that follows this calibration by
    /// user `seed` ([`Realism::closed_loop`]): the same as the
    /// calibration's for an ideal user.
    pub fn closed_loop_generator(&self, seed: u64) -> Result<Valid<GeneratorParams>> {
        let secs = self.calibration.duration_secs();
        self.generator
            .with(|g| g.realism = g.realism.closed_loop(secs, seed))
    }
}

/// The setup of the discrete calibration session (sec. 2.2).
pub type CalibrationSetup = Setup<CalibrationParams>;

/// Checks the length of a protocol's EOG session (for the regression
/// weights): at least 15 s.
pub(crate) fn check_eog_session(secs: f64) -> Result<()> {
    check(
        secs >= 15.0 && secs.is_finite(),
        "eog_session_secs",
        secs,
        "at least 15 s",
    )
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
    use crate::classify::stratified_folds;
    use crate::erp::AssessmentKind;

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
        assert!(c.check().unwrap_err().to_string().contains("error_rate"));
    }
}
