//! The calibration of the continuous decoder (sec. 5.1): trigger-locked
//! examples of each class, scored by cross-validation.

use errp_valid::{Check, Valid};
use rand::Rng;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::calibration::{
    Accuracy, Calibrated, CalibrationParams, CalibrationSession, CalibrationSetup, Protocol,
    SessionOptions, Setup, check_eog_session, check_intervals, cv_seed, out_of_fold_decisions,
    simulate_session_with,
};
use crate::classify::Classifier;
use crate::continuous::ContinuousFeatures;
use crate::erp::AssessmentKind;
use crate::error::{BciError, Result, check};
use crate::generator::Assessment;
use crate::rng::{derive_seed, labelled};
use crate::svm::{SvmDecoder, SvmModel};

/// How the calibration of the continuous decoder runs (sec. 5.1 of the
/// paper): two steps, one where the user presses a button on every erroneous
/// robot action and one on every correct action, "always with separations of
/// at least one second between two trigger events", until "around 70
/// examples of each class".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContinuousCalibrationParams {
    /// Examples of each class (the paper: around 70).
    pub per_class: usize,
    /// Shortest interval between two assessments (s; the paper: 1 s).
    pub interval_min_secs: f64,
    /// Longest interval between two assessments (s).
    pub interval_max_secs: f64,
    /// SD of the button press around the assessment (ms): the example window
    /// is locked to the press, which follows the assessment only up to the
    /// spread of the reaction time.
    pub trigger_jitter_ms: f64,
    /// Length of the EOG session the EOG regression is fitted on (s).
    pub eog_session_secs: f64,
    /// Cross-validation folds.
    pub folds: usize,
}

impl Default for ContinuousCalibrationParams {
    fn default() -> Self {
        Self {
            per_class: 70,
            interval_min_secs: 1.0,
            interval_max_secs: 2.0,
            trigger_jitter_ms: 50.0,
            eog_session_secs: 60.0,
            folds: 10,
        }
    }
}

impl ContinuousCalibrationParams {
    /// Checks every field.
    fn validate(&self) -> Result<()> {
        check(
            self.per_class >= 10,
            "per_class",
            self.per_class,
            "at least 10 examples of each class",
        )?;
        check_intervals(
            self.interval_min_secs,
            self.interval_max_secs,
            "the paper's separation of trigger events",
        )?;
        check(
            self.trigger_jitter_ms.is_finite() && (0.0..=200.0).contains(&self.trigger_jitter_ms),
            "trigger_jitter_ms",
            self.trigger_jitter_ms,
            "an SD in [0, 200] ms",
        )?;
        check_eog_session(self.eog_session_secs)?;
        check(
            self.folds >= 2 && self.folds <= self.per_class,
            "folds",
            self.folds,
            "at least 2 and at most per_class",
        )
    }
}

impl Check for ContinuousCalibrationParams {
    type Error = BciError;

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl Protocol for ContinuousCalibrationParams {
    fn duration_secs(&self) -> f64 {
        self.eog_session_secs
            + 2.0
            + 2.0 * self.per_class as f64 * 0.5 * (self.interval_min_secs + self.interval_max_secs)
    }
}

/// A simulated user and its session for the continuous decoder: the EEG
/// model, the button-locked protocol, the preprocessing and the montage.
pub type ContinuousSetup = Setup<ContinuousCalibrationParams>;

/// The same setup as a [`CalibrationSetup`] for
/// [`simulate_session_with`], which reads only the EOG session length of
/// its protocol. The continuous protocol's checks include the discrete one's
/// (at least 10 examples per class, so 20 actions; error rate 0.5; the same
/// intervals, EOG session and folds), so the setup needs no check of its own.
fn session_setup(setup: &Valid<ContinuousSetup>) -> Valid<CalibrationSetup> {
    setup.part(|s| {
        let c = &s.calibration;
        CalibrationSetup {
            generator: s.generator.clone(),
            calibration: CalibrationParams {
                n_actions: 2 * c.per_class,
                error_rate: 0.5,
                interval_min_secs: c.interval_min_secs,
                interval_max_secs: c.interval_max_secs,
                eog_session_secs: c.eog_session_secs,
                folds: c.folds,
            },
            preprocess: s.preprocess.clone(),
            montage: s.montage.clone(),
        }
    })
}

/// The schedule of a continuous calibration (sec. 5.1): step one,
/// `per_class` erroneous assessments; step two, `per_class` correct ones;
/// U[interval_min, interval_max] s apart, from 2 s on. Returns the
/// assessments and the start of each example window (s): the button press,
/// i.e. the assessment onset plus N(0, trigger_jitter_ms).
pub fn continuous_schedule(
    params: &ContinuousCalibrationParams,
    seed: u64,
) -> (Vec<Assessment>, Vec<f64>) {
    let mut intervals = labelled(seed, "continuous/schedule");
    let mut presses = labelled(seed, "continuous/trigger");
    let mut t = 2.0;
    let mut assessments = Vec::with_capacity(2 * params.per_class);
    let mut windows = Vec::with_capacity(2 * params.per_class);
    for kind in [AssessmentKind::Error, AssessmentKind::Correct] {
        for _ in 0..params.per_class {
            assessments.push(Assessment {
                onset_secs: t,
                kind,
            });
            let jitter: f64 = presses.sample(StandardNormal);
            windows.push((t + params.trigger_jitter_ms / 1000.0 * jitter).max(0.0));
            t += intervals.random_range(params.interval_min_secs..=params.interval_max_secs);
        }
    }
    (assessments, windows)
}

/// Simulates a continuous calibration session: EOG session, preprocessor
/// fit, the schedule of [`continuous_schedule`] streamed through the
/// generator and the preprocessor, and the 512 features of
/// [`ContinuousFeatures::paper`] of every example window.
pub fn simulate_continuous_session(
    setup: &Valid<ContinuousSetup>,
    seed: u64,
    options: SessionOptions<'_>,
) -> Result<CalibrationSession> {
    let (assessments, windows) = continuous_schedule(&setup.calibration, seed);
    simulate_session_with(
        &session_setup(setup),
        seed,
        &assessments,
        &windows,
        &ContinuousFeatures::paper(setup.generator.sfreq_hz),
        options,
    )
}

/// Calibrates the continuous decoder as the paper did: simulate the session,
/// score the SVM by k-fold cross-validation (per-class rates, error where
/// the decision is `>= 0`), train it on every example. `platt` is the model's own Platt
/// scaling (the classes are balanced, so there is no prior to remove).
pub fn calibrate_continuous(
    classifier: &SvmDecoder,
    setup: &Valid<ContinuousSetup>,
    seed: u64,
) -> Result<Calibrated<SvmModel>> {
    calibrate_continuous_with(classifier, setup, seed, SessionOptions::default())
}

/// [`calibrate_continuous`], with what else to produce while the session is
/// simulated (e.g. the raw EEG, to a sink).
pub fn calibrate_continuous_with(
    classifier: &SvmDecoder,
    setup: &Valid<ContinuousSetup>,
    seed: u64,
    options: SessionOptions<'_>,
) -> Result<Calibrated<SvmModel>> {
    let session = simulate_continuous_session(setup, seed, options)?;
    let decisions = out_of_fold_decisions(
        classifier,
        &session.features,
        &session.labels,
        setup.calibration.folds,
        cv_seed(seed),
    )?;
    let predicted: Vec<bool> = decisions.iter().map(|&d| d >= 0.0).collect();
    let accuracy = Accuracy::score(&session.labels, &predicted);
    let model = classifier.fit(
        &session.features,
        &session.labels,
        derive_seed(seed, "calibration/fit", 0),
    )?;
    let platt = model.platt();
    Ok(Calibrated {
        session,
        accuracy,
        model,
        platt,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_has_two_steps_and_jittered_presses() {
        let p = ContinuousCalibrationParams::default();
        let (a, w) = continuous_schedule(&p, 3);
        assert_eq!(a.len(), 140);
        assert_eq!(w.len(), 140);
        assert!(a[..70].iter().all(|a| a.kind == AssessmentKind::Error));
        assert!(a[70..].iter().all(|a| a.kind == AssessmentKind::Correct));
        for pair in a.windows(2) {
            let dt = pair[1].onset_secs - pair[0].onset_secs;
            assert!((1.0..=2.0).contains(&dt), "{dt}");
        }
        let lags_ms: Vec<f64> = a
            .iter()
            .zip(&w)
            .map(|(a, w)| 1000.0 * (w - a.onset_secs))
            .collect();
        let mean = lags_ms.iter().sum::<f64>() / 140.0;
        let sd = (lags_ms.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / 139.0).sqrt();
        assert!(
            mean.abs() < 15.0 && (35.0..65.0).contains(&sd),
            "{mean} {sd}"
        );
        assert_eq!(continuous_schedule(&p, 3), (a, w));
    }

    #[test]
    fn bad_parameters_are_named() {
        let bad = |p: ContinuousCalibrationParams, name: &str| {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        };
        let d = ContinuousCalibrationParams::default;
        bad(
            ContinuousCalibrationParams {
                per_class: 3,
                ..d()
            },
            "per_class",
        );
        bad(
            ContinuousCalibrationParams {
                interval_min_secs: 0.5,
                ..d()
            },
            "interval_min_secs",
        );
        bad(
            ContinuousCalibrationParams {
                trigger_jitter_ms: -1.0,
                ..d()
            },
            "trigger_jitter_ms",
        );
        bad(ContinuousCalibrationParams { folds: 1, ..d() }, "folds");
        assert!(d().validate().is_ok());
    }
}
