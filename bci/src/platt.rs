//! Platt scaling: a calibrated p(error) from a decoder's decision values.

use serde::{Deserialize, Serialize};

use crate::classify::sigmoid;
use crate::error::{BciError, Result};

/// p(error) = 1 / (1 + e^-(a y + b)) for a decision value y.
///
/// The paper maps the LDA output y straight through the logistic function.
/// With ~80 error trials and dozens of PCA components, y is the log-likelihood
/// ratio of an over-fitted model and is over-confident on new trials; fitting
/// `a` and `b` on out-of-fold decisions (Platt 1999, with his target
/// smoothing) gives probabilities that match the decoder's real error rates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlattScaling {
    /// Slope on the decision value.
    pub a: f64,
    /// Offset.
    pub b: f64,
}

impl PlattScaling {
    /// The identity mapping (the paper's p = sigmoid(y)).
    pub const IDENTITY: Self = Self { a: 1.0, b: 0.0 };

    /// Fits on decision values and labels (`true` = error) by Newton's
    /// method on the regularised log-loss.
    pub fn fit(decisions: &[f64], labels: &[bool]) -> Result<Self> {
        if decisions.len() != labels.len() || decisions.is_empty() {
            return Err(BciError::Training(
                "Platt scaling needs one label per decision".into(),
            ));
        }
        let n_pos = labels.iter().filter(|&&l| l).count() as f64;
        let n_neg = labels.len() as f64 - n_pos;
        if n_pos == 0.0 || n_neg == 0.0 {
            return Err(BciError::Training(
                "Platt scaling needs both classes".into(),
            ));
        }
        let hi = (n_pos + 1.0) / (n_pos + 2.0);
        let lo = 1.0 / (n_neg + 2.0);
        let targets: Vec<f64> = labels.iter().map(|&l| if l { hi } else { lo }).collect();
        // Log-loss, computed stably (log(1 + e^z) without overflow).
        let loss = |a: f64, b: f64| -> f64 {
            decisions
                .iter()
                .zip(&targets)
                .map(|(&y, &t)| {
                    let z = a * y + b;
                    let log1pexp = if z > 0.0 {
                        z + (-z).exp().ln_1p()
                    } else {
                        z.exp().ln_1p()
                    };
                    log1pexp - t * z
                })
                .sum()
        };
        let (mut a, mut b) = (1.0, 0.0);
        let mut current = loss(a, b);
        for _ in 0..100 {
            let (mut ga, mut gb, mut haa, mut hab, mut hbb) = (0.0, 0.0, 1e-12, 0.0, 1e-12);
            for (&y, &t) in decisions.iter().zip(&targets) {
                let p = sigmoid(a * y + b);
                let d = p - t;
                let w = p * (1.0 - p);
                ga += d * y;
                gb += d;
                haa += w * y * y;
                hab += w * y;
                hbb += w;
            }
            let det = haa * hbb - hab * hab;
            if det.abs() < 1e-300 {
                break;
            }
            let da = (hbb * ga - hab * gb) / det;
            let db = (haa * gb - hab * ga) / det;
            // Backtracking line search: Newton steps can overshoot.
            let mut step = 1.0;
            let mut improved = false;
            while step > 1e-10 {
                let (na, nb) = (a - step * da, b - step * db);
                let l = loss(na, nb);
                if l < current {
                    (a, b, current) = (na, nb, l);
                    improved = true;
                    break;
                }
                step /= 2.0;
            }
            if !improved || (step * da).abs() < 1e-10 && (step * db).abs() < 1e-10 {
                break;
            }
        }
        if !(a.is_finite() && b.is_finite()) {
            return Err(BciError::Training("Platt scaling did not converge".into()));
        }
        Ok(Self { a, b })
    }

    /// The same mapping with the calibration session's class prior removed:
    /// `b` minus log(n_error / n_correct), so that p(error) = 0.5 where the
    /// two classes are equally likely, as for the equal-prior LDA boundary.
    /// Online, errors are not 20 % of the actions as in calibration, and the
    /// likelihood of eq. (4) should carry the evidence of the EEG alone.
    pub fn balanced(&self, n_error: usize, n_correct: usize) -> Self {
        Self {
            a: self.a,
            b: self.b - (n_error as f64 / n_correct as f64).ln(),
        }
    }

    /// Calibrated p(error) for a decision value.
    pub fn p_error(&self, decision: f64) -> f64 {
        sigmoid(self.a * decision + self.b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_known_logistic_relation() {
        // Decisions on a grid; labels drawn deterministically so that the
        // empirical error rate at y is sigmoid(0.5 y - 1).
        let mut d = Vec::new();
        let mut l = Vec::new();
        for i in -40..=40 {
            let y = f64::from(i) / 4.0;
            let p = sigmoid(0.5 * y - 1.0);
            for k in 0..200 {
                d.push(y);
                l.push((f64::from(k) + 0.5) / 200.0 < p);
            }
        }
        let s = PlattScaling::fit(&d, &l).unwrap();
        assert!(
            (s.a - 0.5).abs() < 0.02 && (s.b + 1.0).abs() < 0.03,
            "{s:?}"
        );
    }

    #[test]
    fn over_confident_decisions_are_shrunk() {
        // A decoder right 75 % of the time whatever |y| says: y = +-4.
        let mut d = Vec::new();
        let mut l = Vec::new();
        for k in 0..400 {
            let label = k % 2 == 0;
            let right = (k / 2) % 4 != 0;
            let says_error = if right { label } else { !label };
            d.push(if says_error { 4.0 } else { -4.0 });
            l.push(label);
        }
        let s = PlattScaling::fit(&d, &l).unwrap();
        assert!((s.p_error(4.0) - 0.75).abs() < 0.02, "{}", s.p_error(4.0));
        assert!((s.p_error(-4.0) - 0.25).abs() < 0.02);
        assert!(PlattScaling::fit(&[1.0], &[true]).is_err());
    }
}
