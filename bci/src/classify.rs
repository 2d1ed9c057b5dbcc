//! The classifier interface shared by every ErrP decoder.

use nalgebra::DMatrix;

use rand::seq::SliceRandom;

use crate::error::Result;
use crate::rng::labelled;

/// Feature matrix, one trial per row: shape `(n_trials, n_features)`.
pub type Features = DMatrix<f64>;

/// Something that learns p(error | features) from labelled trials
/// (scikit-learn / linfa `Fit` shape). Labels: `true` = error (class 1).
pub trait Classifier: Send + Sync {
    /// The trained model.
    type Model: ErrorModel;

    /// Fits on `x` `(n_trials, n_features)` and `labels` (`n_trials`).
    /// `seed` drives any randomness; the same seed gives the same model.
    fn fit(&self, x: &Features, labels: &[bool], seed: u64) -> Result<Self::Model>;
}

/// A trained decoder.
pub trait ErrorModel: Send + Sync + Clone + std::fmt::Debug {
    /// Raw decision value; `>= 0` means "error".
    fn decision(&self, x: &[f64]) -> f64;

    /// Probability that the trial is an error, in [0, 1].
    fn p_error(&self, x: &[f64]) -> f64;

    /// Number of features expected.
    fn n_features(&self) -> usize;
}

/// Logistic function, 1 / (1 + e^-y), without overflow.
pub fn sigmoid(y: f64) -> f64 {
    if y >= 0.0 {
        1.0 / (1.0 + (-y).exp())
    } else {
        let e = y.exp();
        e / (1.0 + e)
    }
}

/// Dot product of two `f32` vectors, accumulated in 16 lanes (vectorises
/// four wide on baseline x86-64: a plain running sum would be bound by the
/// latency of each addition) and summed in `f64`.
pub(crate) fn dot_f32(a: &[f32], b: &[f32]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    let mut acc = [0.0f32; 16];
    let (ca, cb) = (a.chunks_exact(16), b.chunks_exact(16));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| f64::from(*x) * f64::from(*y))
        .sum();
    for (x, y) in ca.zip(cb) {
        for k in 0..16 {
            acc[k] += x[k] * y[k];
        }
    }
    acc.iter().map(|&v| f64::from(v)).sum::<f64>() + tail
}

/// Checks the shapes and that both classes are present.
pub(crate) fn check_training_set(x: &Features, labels: &[bool]) -> Result<(usize, usize)> {
    use crate::error::BciError;
    if x.nrows() != labels.len() {
        return Err(BciError::Training(format!(
            "{} trials but {} labels",
            x.nrows(),
            labels.len()
        )));
    }
    let n_err = labels.iter().filter(|&&l| l).count();
    let n_cor = labels.len() - n_err;
    if n_err < 2 || n_cor < 2 {
        return Err(BciError::Training(format!(
            "need at least 2 trials of each class, got {n_cor} correct and {n_err} error"
        )));
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(BciError::Training(
            "features contain NaN or infinity".into(),
        ));
    }
    Ok((n_cor, n_err))
}

/// Fold index of every trial, for cross-validation: each class shuffled
/// and dealt round-robin.
pub fn stratified_folds(labels: &[bool], folds: usize, seed: u64) -> Vec<usize> {
    let mut rng = labelled(seed, "cv/folds");
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
