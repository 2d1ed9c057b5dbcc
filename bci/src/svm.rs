//! The continuous decoder's classifier (sec. 2.2.2): a support vector machine
//! with a radial basis function kernel and Platt-scaled probability output.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::classify::{
    Classifier, ErrorModel, Features, check_training_set, dot_f32, stratified_folds,
};
use crate::error::{Result, check};
use crate::platt::PlattScaling;
use crate::rng::derive_seed;
use crate::smo::solve_dual;

/// Folds of the internal cross-validation that the Platt scaling is fitted
/// on (libsvm's `-b 1` uses 5).
const PLATT_FOLDS: usize = 5;

/// The RBF-kernel C-SVC of sec. 2.2.2, K(u, v) = exp(-gamma |u - v|^2) on
/// z-scored features, trained by our own libsvm-style SMO solver
/// (second-order working-set selection, Fan, Chen & Lin 2005).
///
/// p(error) comes from Platt scaling fitted on out-of-fold decision values of
/// an internal stratified 5-fold cross-validation, as libsvm does for
/// probability outputs. Like libsvm's, those folds share the z-scoring of the
/// whole training set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SvmDecoder {
    /// Penalty on margin violations (libsvm's and scikit-learn's default: 1).
    pub c: f64,
    /// Kernel width; `None` = 1 / n_features, which after z-scoring is
    /// scikit-learn's `gamma = "scale"` (1 / (n_features x variance)).
    pub gamma: Option<f64>,
    /// Stopping tolerance on the maximal KKT violation (libsvm: 1e-3).
    pub tolerance: f64,
}

impl Default for SvmDecoder {
    fn default() -> Self {
        Self {
            c: 1.0,
            gamma: None,
            tolerance: 1e-3,
        }
    }
}

impl SvmDecoder {
    fn validate(&self) -> Result<()> {
        check(
            self.c.is_finite() && self.c > 0.0,
            "c",
            self.c,
            "a finite penalty > 0",
        )?;
        if let Some(g) = self.gamma {
            check(g.is_finite() && g > 0.0, "gamma", g, "a finite width > 0")?;
        }
        check(
            self.tolerance.is_finite() && self.tolerance > 0.0,
            "tolerance",
            self.tolerance,
            "a finite tolerance > 0, e.g. 1e-3",
        )
    }
}

/// A trained [`SvmDecoder`]. Support vectors are stored z-scored, row-major
/// with their squared norms, so a decision is one z-scoring pass and one pass
/// of `n_support` dot products.
#[derive(Debug, Clone, PartialEq)]
pub struct SvmModel {
    mean: Vec<f64>,
    inv_sd: Vec<f64>,
    gamma: f64,
    /// `(n_support, n_features)`, row-major, z-scored, in `f32`: the
    /// prediction's dot products run twice as wide, and a decision moves by
    /// less than 1e-5 (tested).
    support: Vec<f32>,
    /// Squared norm of each (rounded) support vector.
    support_sq_norms: Vec<f64>,
    /// `alpha_i y_i` of each support vector.
    coef: Vec<f64>,
    bias: f64,
    platt: PlattScaling,
    iterations: usize,
}

impl SvmModel {
    /// Number of support vectors.
    pub fn n_support(&self) -> usize {
        self.coef.len()
    }

    /// Kernel width used (on z-scored features).
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// The constant b of the decision function (libsvm's -rho).
    pub fn bias(&self) -> f64 {
        self.bias
    }

    /// `alpha_i y_i` of each support vector (y = +1 for error).
    pub fn dual_coefficients(&self) -> &[f64] {
        &self.coef
    }

    /// The Platt scaling that maps decisions to p(error), fitted on the
    /// internal cross-validation.
    pub fn platt(&self) -> PlattScaling {
        self.platt
    }

    /// SMO iterations the final training took.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Mean of each feature over the training set (the z-scoring).
    pub fn feature_means(&self) -> &[f64] {
        &self.mean
    }

    /// 1 / SD of each feature over the training set (the z-scoring).
    pub fn feature_inv_sds(&self) -> &[f64] {
        &self.inv_sd
    }

    /// The support vectors, z-scored, `(n_support, n_features)` row-major.
    pub fn support_vectors(&self) -> &[f32] {
        &self.support
    }

    /// A model from its parts (those the accessors give), e.g. a model kept
    /// outside the program. Every part is checked: one mean and one inverse
    /// SD per feature, `n_support x n_features` support values, one
    /// coefficient per support vector, everything finite, `gamma > 0`.
    pub fn from_parts(parts: SvmParts) -> Result<Self> {
        let p = &parts;
        let d = p.mean.len();
        check(d > 0, "mean", d, "at least one feature")?;
        check(
            p.inv_sd.len() == d,
            "inv_sd",
            p.inv_sd.len(),
            &format!("one value per feature ({d})"),
        )?;
        check(
            p.support.len() == p.coef.len() * d,
            "support",
            p.support.len(),
            &format!("n_support x n_features = {} x {d}", p.coef.len()),
        )?;
        let finite = p
            .mean
            .iter()
            .chain(&p.inv_sd)
            .chain(&p.coef)
            .all(|v| v.is_finite())
            && p.support.iter().all(|v| v.is_finite())
            && [p.bias, p.platt.a, p.platt.b].iter().all(|v| v.is_finite());
        check(finite, "model", "not finite", "finite numbers throughout")?;
        check(
            p.gamma.is_finite() && p.gamma > 0.0,
            "gamma",
            p.gamma,
            "a finite width > 0",
        )?;
        Ok(Self::assemble(parts, 0))
    }

    /// The model of consistent parts, with the squared norms of its support
    /// vectors.
    fn assemble(parts: SvmParts, iterations: usize) -> Self {
        let d = parts.mean.len();
        let support_sq_norms = parts
            .support
            .chunks_exact(d)
            .map(|sv| sv.iter().map(|&v| f64::from(v) * f64::from(v)).sum())
            .collect();
        Self {
            mean: parts.mean,
            inv_sd: parts.inv_sd,
            gamma: parts.gamma,
            support: parts.support,
            support_sq_norms,
            coef: parts.coef,
            bias: parts.bias,
            platt: parts.platt,
            iterations,
        }
    }
}

/// The parts of an [`SvmModel`], for [`SvmModel::from_parts`].
#[derive(Debug, Clone, PartialEq)]
pub struct SvmParts {
    /// Mean of each feature.
    pub mean: Vec<f64>,
    /// 1 / SD of each feature.
    pub inv_sd: Vec<f64>,
    /// Kernel width on the z-scored features.
    pub gamma: f64,
    /// Support vectors, z-scored, `(n_support, n_features)` row-major.
    pub support: Vec<f32>,
    /// `alpha_i y_i` of each support vector.
    pub coef: Vec<f64>,
    /// The constant of the decision function.
    pub bias: f64,
    /// The Platt scaling of the decisions.
    pub platt: PlattScaling,
}

impl ErrorModel for SvmModel {
    /// `sum_i alpha_i y_i K(sv_i, x) + b`; `>= 0` means error.
    fn decision(&self, x: &[f64]) -> f64 {
        let d = self.mean.len();
        assert_eq!(x.len(), d, "feature count");
        let z: Vec<f32> = x
            .iter()
            .zip(&self.mean)
            .zip(&self.inv_sd)
            .map(|((v, m), s)| ((v - m) * s) as f32)
            .collect();
        let z_sq: f64 = z.iter().map(|&v| f64::from(v) * f64::from(v)).sum();
        let mut sum = 0.0;
        for (k, sv) in self.support.chunks_exact(d).enumerate() {
            let dot = dot_f32(sv, &z);
            let dist = (z_sq + self.support_sq_norms[k] - 2.0 * dot).max(0.0);
            sum += self.coef[k] * (-self.gamma * dist).exp();
        }
        sum + self.bias
    }

    /// The Platt-scaled decision. Its 0.5 point is where the internal
    /// cross-validation puts it, not exactly at decision 0 (as in libsvm).
    fn p_error(&self, x: &[f64]) -> f64 {
        self.platt.p_error(self.decision(x))
    }

    fn n_features(&self) -> usize {
        self.mean.len()
    }
}

impl Classifier for SvmDecoder {
    type Model = SvmModel;

    /// Labels: `true` (error) is the positive class. The seed draws the folds
    /// of the internal cross-validation of the Platt scaling.
    fn fit(&self, x: &Features, labels: &[bool], seed: u64) -> Result<SvmModel> {
        self.validate()?;
        check_training_set(x, labels)?;
        let (n, d) = x.shape();

        // z-score, as the LDA does.
        let mean: Vec<f64> = (0..d).map(|j| x.column(j).mean()).collect();
        let inv_sd: Vec<f64> = (0..d)
            .map(|j| {
                let m = mean[j];
                let v = x.column(j).iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1) as f64;
                if v > 0.0 { 1.0 / v.sqrt() } else { 1.0 }
            })
            .collect();
        let z = DMatrix::from_fn(n, d, |i, j| (x[(i, j)] - mean[j]) * inv_sd[j]);
        let gamma = self.gamma.unwrap_or(1.0 / d as f64);
        let kernel = rbf_kernel(&z, gamma);
        let y: Vec<f64> = labels.iter().map(|&l| if l { 1.0 } else { -1.0 }).collect();

        // Platt scaling on out-of-fold decisions (libsvm's
        // svm_binary_svc_probability), from sub-matrices of the kernel.
        let fold_of = stratified_folds(labels, PLATT_FOLDS, derive_seed(seed, "svm/platt", 0));
        let mut decisions = vec![0.0; n];
        for k in 0..PLATT_FOLDS {
            let train: Vec<usize> = (0..n).filter(|&i| fold_of[i] != k).collect();
            let test: Vec<usize> = (0..n).filter(|&i| fold_of[i] == k).collect();
            if test.is_empty() {
                continue;
            }
            let kernel = &kernel;
            let sub: Vec<f64> = train
                .iter()
                .flat_map(|&i| train.iter().map(move |&j| kernel[i * n + j]))
                .collect();
            let yt: Vec<f64> = train.iter().map(|&i| y[i]).collect();
            let sol = solve_dual(&sub, &yt, self.c, self.tolerance)?;
            for &i in &test {
                decisions[i] = train
                    .iter()
                    .zip(&sol.alpha)
                    .filter(|&(_, &a)| a > 0.0)
                    .map(|(&j, &a)| a * y[j] * kernel[i * n + j])
                    .sum::<f64>()
                    - sol.rho;
            }
        }
        let platt = PlattScaling::fit(&decisions, labels)?;

        let sol = solve_dual(&kernel, &y, self.c, self.tolerance)?;
        let mut support = Vec::new();
        let mut coef = Vec::new();
        for i in (0..n).filter(|&i| sol.alpha[i] > 0.0) {
            support.extend(z.row(i).iter().map(|&v| v as f32));
            coef.push(sol.alpha[i] * y[i]);
        }
        Ok(SvmModel::assemble(
            SvmParts {
                mean,
                inv_sd,
                gamma,
                support,
                coef,
                bias: -sol.rho,
                platt,
            },
            sol.iterations,
        ))
    }
}

/// The RBF kernel matrix of the rows of `z` `(n, d)`: `(n, n)`, row-major.
fn rbf_kernel(z: &DMatrix<f64>, gamma: f64) -> Vec<f64> {
    let n = z.nrows();
    let gram = z * z.transpose();
    let mut k = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let dist = (gram[(i, i)] + gram[(j, j)] - 2.0 * gram[(i, j)]).max(0.0);
            k[i * n + j] = if i == j { 1.0 } else { (-gamma * dist).exp() };
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lda::LdaDecoder;
    use crate::rng::labelled;
    use rand::Rng;
    use rand_distr::StandardNormal;

    /// `n` points per class of two Gaussian blobs `sep` apart along every
    /// axis of `d` dimensions.
    fn blobs(n: usize, d: usize, sep: f64, seed: u64) -> (Features, Vec<bool>) {
        let mut rng = labelled(seed, "test/blobs");
        let labels: Vec<bool> = (0..2 * n).map(|i| i % 2 == 1).collect();
        let x = DMatrix::from_fn(2 * n, d, |i, _| {
            let shift = if labels[i] { sep } else { 0.0 };
            shift + rng.sample::<f64, _>(StandardNormal)
        });
        (x, labels)
    }

    fn rows(x: &Features) -> Vec<Vec<f64>> {
        (0..x.nrows())
            .map(|i| x.row(i).iter().copied().collect())
            .collect()
    }

    #[test]
    fn separates_xor_that_a_linear_model_cannot() {
        // Four clusters at (+-1, +-1); error where the signs differ.
        let mut rng = labelled(1, "test/xor");
        let mut data = Vec::new();
        let mut labels = Vec::new();
        for k in 0..120 {
            let (sx, sy) = ([-1.0, 1.0][k % 2], [-1.0, 1.0][(k / 2) % 2]);
            data.push(sx + 0.2 * rng.sample::<f64, _>(StandardNormal));
            data.push(sy + 0.2 * rng.sample::<f64, _>(StandardNormal));
            labels.push(sx * sy < 0.0);
        }
        let x = DMatrix::from_row_slice(120, 2, &data);
        let svm = SvmDecoder::default().fit(&x, &labels, 3).unwrap();
        let lda = LdaDecoder::default().fit(&x, &labels, 3).unwrap();
        let hits = |m: &dyn Fn(&[f64]) -> f64| {
            rows(&x)
                .iter()
                .zip(&labels)
                .filter(|(r, l)| (m(r) >= 0.0) == **l)
                .count()
        };
        assert_eq!(hits(&|r| svm.decision(r)), 120);
        assert!(hits(&|r| lda.decision(r)) < 90, "LDA should fail on XOR");
    }

    #[test]
    fn the_f32_decision_matches_an_f64_reference() {
        // 512 features, as the continuous decoder has.
        let (x, labels) = blobs(70, 512, 0.15, 9);
        let m = SvmDecoder::default().fit(&x, &labels, 2).unwrap();
        let d = m.n_features();
        for r in rows(&x).iter().take(20) {
            let z: Vec<f64> = r
                .iter()
                .zip(&m.mean)
                .zip(&m.inv_sd)
                .map(|((v, mu), s)| (v - mu) * s)
                .collect();
            let reference: f64 = m
                .support
                .chunks_exact(d)
                .zip(&m.coef)
                .map(|(sv, c)| {
                    let dist: f64 = sv
                        .iter()
                        .zip(&z)
                        .map(|(&a, b)| (f64::from(a) - b).powi(2))
                        .sum();
                    c * (-m.gamma * dist).exp()
                })
                .sum::<f64>()
                + m.bias;
            assert!(
                (m.decision(r) - reference).abs() < 1e-5,
                "{} vs {reference}",
                m.decision(r)
            );
        }
    }

    #[test]
    fn a_model_rebuilt_from_its_parts_decides_alike_and_bad_parts_are_named() {
        let (x, labels) = blobs(30, 5, 1.5, 11);
        let m = SvmDecoder::default().fit(&x, &labels, 4).unwrap();
        let parts = SvmParts {
            mean: m.feature_means().to_vec(),
            inv_sd: m.feature_inv_sds().to_vec(),
            gamma: m.gamma(),
            support: m.support_vectors().to_vec(),
            coef: m.dual_coefficients().to_vec(),
            bias: m.bias(),
            platt: m.platt(),
        };
        let back = SvmModel::from_parts(parts.clone()).unwrap();
        for r in rows(&x) {
            assert_eq!(back.decision(&r), m.decision(&r));
            assert_eq!(back.p_error(&r), m.p_error(&r));
        }
        let bad = |p: SvmParts, name: &str| {
            let e = SvmModel::from_parts(p).unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        };
        let mut p = parts.clone();
        p.support.pop();
        bad(p, "support");
        let mut p = parts.clone();
        p.inv_sd.push(1.0);
        bad(p, "inv_sd");
        let mut p = parts.clone();
        p.coef[0] = f64::NAN;
        bad(p, "model");
        bad(
            SvmParts {
                gamma: 0.0,
                ..parts
            },
            "gamma",
        );
    }

    #[test]
    fn decisions_agree_with_labels_on_a_separable_set() {
        let (x, labels) = blobs(40, 10, 3.0, 4);
        let m = SvmDecoder::default().fit(&x, &labels, 1).unwrap();
        for (r, &l) in rows(&x).iter().zip(&labels) {
            assert_eq!(m.decision(r) >= 0.0, l);
        }
        assert!(m.n_support() < x.nrows());
        assert_eq!(m.gamma(), 0.1);
    }

    #[test]
    fn p_error_is_a_probability_increasing_with_the_decision() {
        let (x, labels) = blobs(50, 4, 1.0, 5);
        let m = SvmDecoder::default().fit(&x, &labels, 1).unwrap();
        assert!(m.platt().a > 0.0, "{:?}", m.platt());
        let (test, _) = blobs(100, 4, 1.0, 6);
        let mut pairs: Vec<(f64, f64)> = rows(&test)
            .iter()
            .map(|r| (m.decision(r), m.p_error(r)))
            .collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        for w in pairs.windows(2) {
            assert!((0.0..=1.0).contains(&w[0].1));
            assert!(w[1].1 >= w[0].1);
        }
        assert!(pairs[0].1 < 0.2 && pairs[pairs.len() - 1].1 > 0.8);
    }

    #[test]
    fn training_is_deterministic_and_parameters_are_checked() {
        let (x, labels) = blobs(30, 6, 1.0, 7);
        let d = SvmDecoder::default();
        assert_eq!(
            d.fit(&x, &labels, 9).unwrap(),
            d.fit(&x, &labels, 9).unwrap()
        );
        let bad = SvmDecoder {
            c: 0.0,
            ..SvmDecoder::default()
        };
        let e = bad.fit(&x, &labels, 9).unwrap_err().to_string();
        assert!(e.contains('c'), "{e}");
    }
}
