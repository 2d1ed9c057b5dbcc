//! The discrete decoder of sec. 2.2.1: z-score, PCA (95 % variance) and
//! shrinkage LDA, with p(error) = 1 / (1 + e^-y).

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::{Deserialize, Serialize};

use crate::classify::{Classifier, ErrorModel, Features, check_training_set, sigmoid};
use crate::error::{BciError, Result, check};

/// How the LDA covariance is regularised.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shrinkage {
    /// Ledoit-Wolf analytic shrinkage towards a scaled identity.
    LedoitWolf,
    /// A fixed shrinkage intensity in [0, 1].
    Fixed(f64),
}

/// The z-score + PCA + shrinkage-LDA decoder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LdaDecoder {
    /// Fraction of variance the PCA keeps (the paper: 0.95).
    pub pca_variance: f64,
    /// Covariance regularisation.
    pub shrinkage: Shrinkage,
}

impl Default for LdaDecoder {
    fn default() -> Self {
        Self {
            pca_variance: 0.95,
            shrinkage: Shrinkage::LedoitWolf,
        }
    }
}

/// A trained [`LdaDecoder`]. The z-score, projection and discriminant are
/// folded into one weight vector, so a decision is one dot product.
#[derive(Debug, Clone, PartialEq)]
pub struct LdaModel {
    weights: Vec<f64>,
    bias: f64,
    n_components: usize,
    shrinkage: f64,
}

impl LdaModel {
    /// Number of principal components kept.
    pub fn n_components(&self) -> usize {
        self.n_components
    }

    /// Shrinkage intensity used.
    pub fn shrinkage(&self) -> f64 {
        self.shrinkage
    }

    /// Weights in feature space (z-score and PCA folded in).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
}

impl ErrorModel for LdaModel {
    fn decision(&self, x: &[f64]) -> f64 {
        assert_eq!(x.len(), self.weights.len(), "feature count");
        self.weights.iter().zip(x).map(|(w, v)| w * v).sum::<f64>() + self.bias
    }

    fn p_error(&self, x: &[f64]) -> f64 {
        sigmoid(self.decision(x))
    }

    fn n_features(&self) -> usize {
        self.weights.len()
    }
}

impl Classifier for LdaDecoder {
    type Model = LdaModel;

    /// Equal class priors: the bias puts the boundary half-way between the
    /// projected class means, so y is the log-likelihood ratio of the two
    /// Gaussian classes and both per-class rates are balanced (the paper
    /// reports their mean). The seed is unused: the fit is deterministic.
    fn fit(&self, x: &Features, labels: &[bool], _seed: u64) -> Result<LdaModel> {
        check(
            self.pca_variance > 0.0 && self.pca_variance <= 1.0,
            "pca_variance",
            self.pca_variance,
            "a fraction in (0, 1]",
        )?;
        if let Shrinkage::Fixed(s) = self.shrinkage {
            check(
                (0.0..=1.0).contains(&s),
                "shrinkage",
                s,
                "a fraction in [0, 1]",
            )?;
        }
        check_training_set(x, labels)?;
        let (n, d) = x.shape();

        // z-score.
        let mean = DVector::from_fn(d, |j, _| x.column(j).mean());
        let sd = DVector::from_fn(d, |j, _| {
            let m = mean[j];
            let v = x.column(j).iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1) as f64;
            if v > 0.0 { v.sqrt() } else { 1.0 }
        });
        let z = DMatrix::from_fn(n, d, |i, j| (x[(i, j)] - mean[j]) / sd[j]);

        // PCA keeping `pca_variance` of the variance.
        let basis = pca_basis(&z, self.pca_variance);
        let scores = &z * &basis;

        // Class means and pooled, class-centred scores.
        let k = basis.ncols();
        let class_mean = |want: bool| {
            let rows: Vec<usize> = (0..n).filter(|&i| labels[i] == want).collect();
            DVector::from_fn(k, |c, _| {
                rows.iter().map(|&i| scores[(i, c)]).sum::<f64>() / rows.len() as f64
            })
        };
        let (m0, m1) = (class_mean(false), class_mean(true));
        let centred = DMatrix::from_fn(n, k, |i, c| {
            scores[(i, c)] - if labels[i] { m1[c] } else { m0[c] }
        });
        let shrinkage = match self.shrinkage {
            Shrinkage::LedoitWolf => ledoit_wolf_shrinkage(&centred),
            Shrinkage::Fixed(s) => s,
        };
        let emp = centred.transpose() * &centred / n as f64;
        let nu = emp.trace() / k as f64;
        let cov = emp * (1.0 - shrinkage) + DMatrix::identity(k, k) * (shrinkage * nu);
        let chol = cov
            .cholesky()
            .ok_or_else(|| BciError::Training("the within-class covariance is singular".into()))?;
        let w = chol.solve(&(&m1 - &m0));
        let b = -w.dot(&(&m0 + &m1)) / 2.0;

        // Fold z-score and projection into one weight vector.
        let w_z = &basis * &w;
        let weights: Vec<f64> = (0..d).map(|j| w_z[j] / sd[j]).collect();
        let bias = b - weights
            .iter()
            .zip(mean.iter())
            .map(|(w, m)| w * m)
            .sum::<f64>();
        Ok(LdaModel {
            weights,
            bias,
            n_components: k,
            shrinkage,
        })
    }
}

/// Eigenvectors of the covariance of `z` (`(n, d)`, centred) that explain at
/// least `fraction` of its variance, largest first: shape `(d, k)`.
pub fn pca_basis(z: &DMatrix<f64>, fraction: f64) -> DMatrix<f64> {
    let n = z.nrows();
    let cov = z.transpose() * z / (n.max(2) - 1) as f64;
    let eig = SymmetricEigen::new(cov);
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let total: f64 = eig.eigenvalues.iter().map(|v| v.max(0.0)).sum();
    let mut kept = Vec::new();
    let mut acc = 0.0;
    for &i in &order {
        kept.push(i);
        acc += eig.eigenvalues[i].max(0.0);
        if acc >= fraction * total {
            break;
        }
    }
    let mut basis = DMatrix::zeros(z.ncols(), kept.len());
    for (c, &i) in kept.iter().enumerate() {
        // Sign convention: largest-magnitude entry positive (deterministic).
        let v = eig.eigenvectors.column(i);
        let big = v
            .iter()
            .fold(0.0f64, |a, &x| if x.abs() > a.abs() { x } else { a });
        let sign = if big < 0.0 { -1.0 } else { 1.0 };
        basis.set_column(c, &(v * sign));
    }
    basis
}

/// Ledoit-Wolf shrinkage intensity for centred data `x` `(n, p)`, as in
/// Ledoit & Wolf (2004) and scikit-learn's `ledoit_wolf_shrinkage`.
pub fn ledoit_wolf_shrinkage(x: &DMatrix<f64>) -> f64 {
    let (n, p) = x.shape();
    let nf = n as f64;
    let x2 = x.map(|v| v * v);
    let emp_trace: Vec<f64> = (0..p).map(|j| x2.column(j).sum() / nf).collect();
    let mu = emp_trace.iter().sum::<f64>() / p as f64;
    let beta_sum = (x2.transpose() * &x2).sum();
    let delta_sum = (x.transpose() * x).map(|v| v * v).sum() / (nf * nf);
    let beta = (beta_sum / nf - delta_sum) / (p as f64 * nf);
    let delta =
        (delta_sum - 2.0 * mu * emp_trace.iter().sum::<f64>() + p as f64 * mu * mu) / p as f64;
    let beta = beta.min(delta);
    if beta <= 0.0 || delta <= 0.0 {
        0.0
    } else {
        (beta / delta).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lda_on_a_hand_computed_two_dimensional_case() {
        // Class 0 around (0, 0), class 1 around (2, 0); within-class spread
        // only along y for class 0 and x/y symmetric: with no shrinkage and no
        // PCA truncation, w is proportional to S^-1 (m1 - m0).
        let rows = [
            ([-1.0, 0.0], false),
            ([1.0, 0.0], false),
            ([0.0, 1.0], false),
            ([0.0, -1.0], false),
            ([1.0, 0.0], true),
            ([3.0, 0.0], true),
            ([2.0, 1.0], true),
            ([2.0, -1.0], true),
        ];
        let x = DMatrix::from_fn(8, 2, |i, j| rows[i].0[j]);
        let labels: Vec<bool> = rows.iter().map(|r| r.1).collect();
        let dec = LdaDecoder {
            pca_variance: 1.0,
            shrinkage: Shrinkage::Fixed(0.0),
        };
        let m = dec.fit(&x, &labels, 0).unwrap();
        // Pooled within-class covariance is 0.5 I, so w = 2 (2, 0) = (4, 0) in
        // raw units, boundary at x = 1: y(x) = 4 (x - 1).
        assert!((m.decision(&[1.0, 0.0])).abs() < 1e-9);
        assert!(
            (m.decision(&[2.0, 0.0]) - 4.0).abs() < 1e-9,
            "{}",
            m.decision(&[2.0, 0.0])
        );
        assert!((m.decision(&[1.0, 5.0])).abs() < 1e-9, "y is irrelevant");
        assert!((m.p_error(&[2.0, 0.0]) - sigmoid(4.0)).abs() < 1e-12);
    }

    #[test]
    fn pca_keeps_the_dominant_direction() {
        // Points along (1, 1) with a little spread along (1, -1).
        let z = DMatrix::from_row_slice(4, 2, &[-2.0, -2.1, -1.0, -0.9, 1.0, 1.1, 2.0, 1.9]);
        let basis = pca_basis(&z, 0.95);
        assert_eq!(basis.ncols(), 1);
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!((basis[(0, 0)].abs() - s).abs() < 0.01 && (basis[(1, 0)].abs() - s).abs() < 0.01);
        assert_eq!(pca_basis(&z, 1.0).ncols(), 2);
    }

    #[test]
    fn ledoit_wolf_matches_scikit_learn() {
        // scikit-learn's formula (assume_centered=True) worked by hand:
        let x = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, -1.0, -1.0]);
        let s = ledoit_wolf_shrinkage(&x);
        // mu = 2/3, sum((X'X)^2)/n^2 = 10/9, delta = (10/9 - 16/9 + 8/9) / 2
        // = 1/9, beta = (6/3 - 10/9) / 6 = 4/27, capped at delta -> 1.
        assert!((s - 1.0).abs() < 1e-12, "{s}");
        // A tall well-conditioned case shrinks little.
        let y = DMatrix::from_fn(400, 3, |i, j| {
            (((i * 7 + j * 13) % 17) as f64 - 8.0) * (j + 1) as f64
        });
        let y = DMatrix::from_fn(400, 3, |i, j| y[(i, j)] - y.column(j).mean());
        assert!(ledoit_wolf_shrinkage(&y) < 0.1);
    }
}
