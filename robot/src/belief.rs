//! A belief over candidate goals, kept in log space.

use crate::error::{Result, RobotError};

/// A probability distribution over `n` goals, stored as log-probabilities so
/// that long runs of small likelihoods never underflow. Invariants after every
/// update: finite, non-negative probabilities that sum to 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Belief {
    log_p: Vec<f64>,
}

impl Belief {
    /// The uniform belief over `n >= 1` goals.
    pub fn uniform(n: usize) -> Self {
        assert!(n >= 1, "a belief needs at least one goal");
        Self {
            log_p: vec![-(n as f64).ln(); n],
        }
    }

    /// Number of goals.
    pub fn len(&self) -> usize {
        self.log_p.len()
    }

    /// Always false: a belief has at least one goal.
    pub fn is_empty(&self) -> bool {
        self.log_p.is_empty()
    }

    /// Bayes' rule, the recursive posterior of eq. (2) of the paper:
    /// multiplies each goal's probability by its likelihood and
    /// renormalises. Likelihoods must be finite and >= 0, and not all 0.
    pub fn update(&mut self, likelihoods: &[f64]) -> Result<()> {
        if likelihoods.len() != self.log_p.len() {
            return Err(RobotError::Likelihood(format!(
                "{} likelihoods for {} goals",
                likelihoods.len(),
                self.log_p.len()
            )));
        }
        if let Some(bad) = likelihoods.iter().find(|l| !l.is_finite() || **l < 0.0) {
            return Err(RobotError::Likelihood(format!(
                "likelihood {bad} is not a finite number >= 0"
            )));
        }
        let updated: Vec<f64> = self
            .log_p
            .iter()
            .zip(likelihoods)
            .map(|(lp, l)| lp + l.ln())
            .collect();
        let norm = log_sum_exp(&updated);
        if !norm.is_finite() {
            return Err(RobotError::Likelihood(
                "every goal has likelihood 0: the belief would be undefined".into(),
            ));
        }
        self.log_p = updated.into_iter().map(|v| v - norm).collect();
        debug_assert!((self.probabilities().iter().sum::<f64>() - 1.0).abs() < 1e-9);
        Ok(())
    }

    /// Probabilities, summing to 1.
    pub fn probabilities(&self) -> Vec<f64> {
        self.log_p.iter().map(|v| v.exp()).collect()
    }

    /// Probability of goal `i`.
    pub fn probability(&self, i: usize) -> f64 {
        self.log_p[i].exp()
    }

    /// The most probable goal (the lowest index on ties) and its probability.
    pub fn most_probable(&self) -> (usize, f64) {
        let mut best = 0;
        for (i, v) in self.log_p.iter().enumerate() {
            if *v > self.log_p[best] {
                best = i;
            }
        }
        (best, self.log_p[best].exp())
    }
}

/// log(sum(exp(x))) without overflow; -inf for an all -inf input.
pub fn log_sum_exp(x: &[f64]) -> f64 {
    let m = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if m == f64::NEG_INFINITY {
        return m;
    }
    m + x.iter().map(|v| (v - m).exp()).sum::<f64>().ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bayes_rule_on_a_small_case() {
        let mut b = Belief::uniform(3);
        b.update(&[0.2, 0.6, 0.2]).unwrap();
        let p = b.probabilities();
        assert!((p[1] - 0.6).abs() < 1e-12 && (p[0] - 0.2).abs() < 1e-12);
        b.update(&[1.0, 0.5, 0.0]).unwrap();
        // 0.2 * 1 : 0.6 * 0.5 : 0 -> 0.4 : 0.6 : 0
        let p = b.probabilities();
        assert!((p[0] - 0.4).abs() < 1e-12 && (p[1] - 0.6).abs() < 1e-12 && p[2] == 0.0);
        assert_eq!(b.most_probable().0, 1);
    }

    #[test]
    fn thousands_of_tiny_likelihoods_do_not_underflow() {
        let mut b = Belief::uniform(25);
        let mut l = vec![1e-3; 25];
        l[7] = 2e-3;
        for _ in 0..5000 {
            b.update(&l).unwrap();
        }
        let p = b.probabilities();
        assert!(p.iter().all(|v| v.is_finite() && *v >= 0.0));
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((b.most_probable().1 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn bad_likelihoods_are_rejected_and_leave_the_belief_unchanged() {
        let mut b = Belief::uniform(2);
        let before = b.clone();
        assert!(b.update(&[f64::NAN, 1.0]).is_err());
        assert!(b.update(&[-0.1, 1.0]).is_err());
        assert!(b.update(&[0.0, 0.0]).is_err());
        assert!(b.update(&[1.0]).is_err());
        assert_eq!(b, before);
    }
}
