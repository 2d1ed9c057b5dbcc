//! Scoring and training on a session: stratified folds, cross-validation, and
//! the calibrated decoder.

use errp_valid::Valid;

use super::session::{CalibrationSession, SessionOptions, simulate_session};
use super::{Accuracy, CalibrationSetup};
use crate::classify::{Classifier, ErrorModel, Features, stratified_folds};
use crate::error::Result;
use crate::platt::PlattScaling;
use crate::rng::derive_seed;

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
    setup: &Valid<CalibrationSetup>,
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
    let CalibratedModel {
        accuracy,
        model,
        platt,
    } = calibrate_features(classifier, &session.features, &session.labels, folds, seed)?;
    Ok(Calibrated {
        session,
        accuracy,
        model,
        platt,
    })
}

/// A decoder trained as a calibration trains it, with its scores.
#[derive(Debug, Clone)]
pub struct CalibratedModel<M> {
    /// k-fold cross-validated accuracy.
    pub accuracy: Accuracy,
    /// The decoder trained on every trial.
    pub model: M,
    /// Platt scaling fitted on the out-of-fold decisions, the training
    /// set's class prior removed.
    pub platt: PlattScaling,
}

/// What [`calibrate_session`] does with a session's features and labels,
/// on any features: the out-of-fold decisions of a stratified
/// `folds`-fold cross-validation (folds drawn from [`cv_seed`]`(seed)`)
/// give the accuracy and the Platt scaling (class prior removed); the model
/// is then trained on every trial. The same features and seed give the
/// loop's very decoder.
pub fn calibrate_features<C: Classifier>(
    classifier: &C,
    features: &Features,
    labels: &[bool],
    folds: usize,
    seed: u64,
) -> Result<CalibratedModel<C::Model>> {
    let decisions = out_of_fold_decisions(classifier, features, labels, folds, cv_seed(seed))?;
    let predicted: Vec<bool> = decisions.iter().map(|&d| d >= 0.0).collect();
    let accuracy = Accuracy::score(labels, &predicted);
    let platt =
        PlattScaling::fit(&decisions, labels)?.balanced(accuracy.n_error, accuracy.n_correct);
    let model = classifier.fit(features, labels, derive_seed(seed, "calibration/fit", 0))?;
    Ok(CalibratedModel {
        accuracy,
        model,
        platt,
    })
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
        // A fold's fit is a fraction of a second: a stop request is seen
        // between two.
        crate::stop::check()?;
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
