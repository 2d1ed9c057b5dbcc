//! The Gaussian classifier of the self-calibration papers (Grizou et al.
//! 2014; Iturrate, Grizou et al. 2015, PLOS ONE 10:e0131491), as their
//! code ran (`lfui`'s `GaussianUninformativePrior_classifier` with
//! `('shrink', 0.5)`): one Gaussian per class fitted on soft labels, each
//! covariance shrunk half-way to a multiple of the identity, and each
//! class's density the Student-t posterior predictive under a
//! non-informative prior; the class posterior at equal priors. Its
//! probabilistic confusion matrix, from a k-fold cross-validation on its
//! own soft labels, corrects the posterior: an unreliable classifier's
//! posteriors are flattened towards the class proportions.
//!
//! Classes are in the reference code's order: correct first, error
//! second ([`SoftLabel`]).

use nalgebra::{DMatrix, DVector};

use crate::classify::Features;
use crate::error::{BciError, Result, check};
use crate::special::ln_gamma;

/// A soft label: the probability that a trial is correct and that it is an
/// error, in that order. The self-calibration learner labels a trial 0.9
/// correct under a hypothesis whose optimal actions include the trial's
/// action (0.1 otherwise): its assumed user error rate is 0.1.
pub type SoftLabel = [f64; 2];

/// The papers' covariance shrinkage (`shrink_cov(cov, 0.5)`).
pub const PAPER_SHRINK: f64 = 0.5;

/// The papers' folds for the confusion matrix.
pub const PAPER_FOLDS: usize = 10;

/// One class: its Student-t predictive density.
#[derive(Debug, Clone)]
struct ClassDensity {
    mean: DVector<f64>,
    /// Lower Cholesky factor of the Student-t's scale matrix.
    scale_l: DMatrix<f64>,
    /// The log of the density's normalising constant.
    log_c: f64,
    /// Degrees of freedom: trials minus features.
    nu: f64,
}

impl ClassDensity {
    fn log_density(&self, e: &[f64]) -> f64 {
        let d = self.mean.len();
        let mut z = DVector::from_iterator(d, e.iter().zip(self.mean.iter()).map(|(x, m)| x - m));
        // z <- L^-1 (e - mu); L is a Cholesky factor, so its diagonal is
        // positive and the solve cannot fail.
        self.scale_l.solve_lower_triangular_mut(&mut z);
        let mahal = z.norm_squared();
        self.log_c - 0.5 * (self.nu + d as f64) * (mahal / self.nu).ln_1p()
    }
}

/// The weighted sums of one class's trials that its Gaussian is fitted
/// from: the total weight, the weighted sum and the weighted sum of outer
/// products. Sums add and subtract, so a learner that labels a growing
/// history under many hypotheses, or leaves one fold out, keeps them up to
/// date instead of passing over every trial again.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassMoments {
    /// The sum of the weights.
    pub weight: f64,
    /// The weighted sum of the trials.
    pub sum: DVector<f64>,
    /// The weighted sum of their outer products.
    pub outer: DMatrix<f64>,
}

impl ClassMoments {
    /// No trial, of `n_features` features.
    pub fn new(n_features: usize) -> Self {
        Self {
            weight: 0.0,
            sum: DVector::zeros(n_features),
            outer: DMatrix::zeros(n_features, n_features),
        }
    }

    /// Adds the trial `x` with weight `w`.
    pub fn add(&mut self, x: &[f64], w: f64) {
        let v = DVector::from_column_slice(x);
        self.weight += w;
        self.sum.axpy(w, &v, 1.0);
        self.outer.ger(w, &v, &v, 1.0);
    }

    /// Adds `scale` times `other`'s sums (a negative scale takes them
    /// away).
    pub fn add_scaled(&mut self, other: &ClassMoments, scale: f64) {
        self.weight += scale * other.weight;
        self.sum.axpy(scale, &other.sum, 1.0);
        self.outer.zip_apply(&other.outer, |a, b| *a += scale * b);
    }
}

/// The papers' classifier, trained. With no more trials than features
/// (where the Student-t has no degrees of freedom) it knows nothing, and
/// its posterior is even.
#[derive(Debug, Clone)]
pub struct GaussianClassifier {
    classes: Option<[ClassDensity; 2]>,
    n_features: usize,
}

impl GaussianClassifier {
    /// Fits on every trial of `x` (one per row) with its soft label, each
    /// covariance shrunk by `shrink` in [0, 1].
    pub fn fit(x: &Features, labels: &[SoftLabel], shrink: f64) -> Result<Self> {
        let rows: Vec<usize> = (0..x.nrows()).collect();
        Self::fit_rows(x, &rows, labels, shrink)
    }

    /// Fits on the trials `rows` of `x` (`labels` holds one soft label per
    /// row of `x`).
    pub fn fit_rows(
        x: &Features,
        rows: &[usize],
        labels: &[SoftLabel],
        shrink: f64,
    ) -> Result<Self> {
        if labels.len() != x.nrows() {
            return Err(BciError::Training(format!(
                "{} trials but {} soft labels",
                x.nrows(),
                labels.len()
            )));
        }
        let d = x.ncols();
        Self::build(rows.len(), d, shrink, |k| {
            let w: Vec<f64> = rows.iter().map(|&i| labels[i][k]).collect();
            let total: f64 = w.iter().sum();
            if !(total.is_finite() && total > 0.0 && w.iter().all(|&v| v >= 0.0)) {
                return None;
            }
            let mut mean = DVector::zeros(d);
            for (&i, &wi) in rows.iter().zip(&w) {
                for j in 0..d {
                    mean[j] += wi * x[(i, j)];
                }
            }
            mean /= total;
            let mut cov = DMatrix::zeros(d, d);
            let mut c = DVector::zeros(d);
            for (&i, &wi) in rows.iter().zip(&w) {
                for j in 0..d {
                    c[j] = x[(i, j)] - mean[j];
                }
                cov.ger(wi / total, &c, &c, 1.0);
            }
            Some((mean, cov))
        })
    }

    /// The classifier of `n` trials whose classes' sums are `moments`
    /// (correct, error), each covariance shrunk by `shrink`: what
    /// [`GaussianClassifier::fit`] gives on those trials, up to rounding
    /// (the covariance is the mean outer product less the mean's, in one
    /// pass).
    pub fn from_moments(moments: &[ClassMoments; 2], n: usize, shrink: f64) -> Result<Self> {
        Self::build(n, moments[0].sum.len(), shrink, |k| {
            let m = &moments[k];
            if !(m.weight.is_finite() && m.weight > 0.0) {
                return None;
            }
            let mean = &m.sum / m.weight;
            let mut cov = &m.outer / m.weight;
            cov.ger(-1.0, &mean, &mean, 1.0);
            Some((mean, cov))
        })
    }

    /// The classifier of `n` trials of `d` features whose classes have the
    /// weighted mean and covariance `class(k)` (none for a class without
    /// weight), each covariance shrunk by `shrink`.
    fn build(
        n: usize,
        d: usize,
        shrink: f64,
        class: impl Fn(usize) -> Option<(DVector<f64>, DMatrix<f64>)>,
    ) -> Result<Self> {
        check(
            (0.0..=1.0).contains(&shrink),
            "shrink",
            shrink,
            "a number in [0, 1]",
        )?;
        if n <= d {
            return Ok(Self {
                classes: None,
                n_features: d,
            });
        }
        let fit_class = |k: usize| -> Result<ClassDensity> {
            let (mean, cov) = class(k).ok_or_else(|| no_weight(k, n))?;
            density(mean, cov, shrink, n)
        };
        Ok(Self {
            classes: Some([fit_class(0)?, fit_class(1)?]),
            n_features: d,
        })
    }

    /// Number of features expected.
    pub fn n_features(&self) -> usize {
        self.n_features
    }

    /// The log densities of `e` under each class, none if the classifier
    /// knows nothing.
    pub fn log_densities(&self, e: &[f64]) -> Option<[f64; 2]> {
        debug_assert_eq!(e.len(), self.n_features);
        self.classes
            .as_ref()
            .map(|[c, w]| [c.log_density(e), w.log_density(e)])
    }

    /// The posterior of each class at equal priors ([0.5, 0.5] if the
    /// classifier knows nothing).
    pub fn posterior(&self, e: &[f64]) -> SoftLabel {
        match self.log_densities(e) {
            Some([a, b]) => {
                let m = a.max(b);
                let (ea, eb) = ((a - m).exp(), (b - m).exp());
                [ea / (ea + eb), eb / (ea + eb)]
            }
            None => [0.5, 0.5],
        }
    }
}

fn no_weight(class: usize, n: usize) -> BciError {
    BciError::Training(format!(
        "the {} class has no weight in {n} trials (soft labels must be >= 0, each class \
         above 0 in all)",
        ["correct", "error"][class]
    ))
}

/// The Student-t posterior predictive of a class with weighted mean `mean`
/// and weighted covariance `cov` over `n` trials (of both classes, as the
/// reference counts them), `cov` shrunk by `shrink` first.
fn density(
    mean: DVector<f64>,
    mut cov: DMatrix<f64>,
    shrink: f64,
    n: usize,
) -> Result<ClassDensity> {
    let d = mean.len();
    let trace = cov.trace();
    cov *= 1.0 - shrink;
    for j in 0..d {
        cov[(j, j)] += shrink * trace / d as f64;
    }
    // The scale (Gelman et al., Bayesian Data Analysis, sec. 3.6):
    // S = cov (n - 1), nu = n - d, W = S (n + 1) / (n nu).
    let (nf, nu) = (n as f64, (n - d) as f64);
    cov *= (nf - 1.0) * (nf + 1.0) / (nf * nu);
    let chol = cov.cholesky().ok_or_else(|| {
        BciError::Training(format!(
            "the covariance of {n} trials is singular (every feature constant?)"
        ))
    })?;
    let scale_l = chol.unpack();
    let half_log_det: f64 = (0..d).map(|j| scale_l[(j, j)].ln()).sum();
    let df = d as f64;
    let log_c = ln_gamma(0.5 * (nu + df))
        - ln_gamma(0.5 * nu)
        - half_log_det
        - 0.5 * df * nu.ln()
        - 0.5 * df * std::f64::consts::PI.ln();
    Ok(ClassDensity {
        mean,
        scale_l,
        log_c,
        nu,
    })
}

/// The fold of each of `n` trials in the reference code's k-fold split
/// (`cross_validation.m`): the trials in the order `shuffled` (a
/// permutation of 0..n), cut into `k` runs at `floor(linspace(1, n, k +
/// 1))`; with fewer trials than folds, one trial per fold.
pub fn reference_folds(shuffled: &[usize], k: usize) -> Vec<usize> {
    let n = shuffled.len();
    let k = k.min(n).max(1);
    let mut fold = vec![0; n];
    // Fold j (from 0) holds the positions (from 1) after end(j) up to
    // end(j + 1), with end(j) = 1 + floor((n - 1) j / k) and the first
    // fold starting at position 1.
    let end = |j: usize| 1 + (n - 1) * j / k;
    for j in 0..k {
        let first = if j == 0 { 1 } else { end(j) + 1 };
        for p in first..=end(j + 1) {
            fold[shuffled[p - 1]] = j;
        }
    }
    fold
}

/// The probabilistic confusion matrix of the classifier fitted on `x`
/// with `labels`, by cross-validation over `folds` (the fold of each
/// trial, from 0): `c[k][q]` is the probability that a trial predicted `q`
/// is given `k`, each trial weighted by its soft label and its predicted
/// posterior (`proba_confusion_matrix.m`, normalised per column as
/// `compute_estimates.m` does). A class never predicted gets an even
/// column.
pub fn confusion_matrix(
    x: &Features,
    labels: &[SoftLabel],
    folds: &[usize],
    shrink: f64,
) -> Result<[[f64; 2]; 2]> {
    if folds.len() != x.nrows() {
        return Err(BciError::Training(format!(
            "{} trials but {} fold numbers",
            x.nrows(),
            folds.len()
        )));
    }
    let k = folds.iter().max().map_or(0, |m| m + 1);
    let mut c = [[0.0; 2]; 2];
    for f in 0..k {
        let train: Vec<usize> = (0..x.nrows()).filter(|&i| folds[i] != f).collect();
        let model = GaussianClassifier::fit_rows(x, &train, labels, shrink)?;
        for i in (0..x.nrows()).filter(|&i| folds[i] == f) {
            let row: Vec<f64> = x.row(i).iter().copied().collect();
            let p = model.posterior(&row);
            for (given, &g) in labels[i].iter().enumerate() {
                for (predicted, &q) in p.iter().enumerate() {
                    c[given][predicted] += g * q;
                }
            }
        }
    }
    Ok(column_normalised(c))
}

/// Each column of `c` divided by its sum (an even column where the sum is
/// 0).
pub fn column_normalised(mut c: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    for q in 0..2 {
        let s = c[0][q] + c[1][q];
        if s > 0.0 && s.is_finite() {
            c[0][q] /= s;
            c[1][q] /= s;
        } else {
            c[0][q] = 0.5;
            c[1][q] = 0.5;
        }
    }
    c
}

/// The posterior `p` corrected by the confusion matrix `c`:
/// `p'(k) = sum over q of c[k][q] p(q)`.
pub fn corrected(c: &[[f64; 2]; 2], p: SoftLabel) -> SoftLabel {
    [
        c[0][0] * p[0] + c[0][1] * p[1],
        c[1][0] * p[0] + c[1][1] * p[1],
    ]
}
