//! The SMO solver of the SVM's dual problem (libsvm's algorithm).

use crate::error::{BciError, Result};

/// SMO iterations allowed per training example before giving up (libsvm
/// allows `max(10^7, 100 l)` and only warns; these problems take a few
/// hundred in all).
const ITERATIONS_PER_EXAMPLE: usize = 1000;

/// Floor of the curvature of a working pair (libsvm's `TAU`).
const TAU: f64 = 1e-12;

/// Solution of the C-SVC dual problem.
#[derive(Debug, Clone)]
pub(crate) struct DualSolution {
    /// Dual variables, one per training example.
    pub(crate) alpha: Vec<f64>,
    /// Offset: the decision function is `sum_j a_j y_j K(x_j, x) - rho`.
    pub(crate) rho: f64,
    /// SMO iterations taken.
    pub(crate) iterations: usize,
}

/// Solves the C-SVC dual, min 0.5 a'Qa - e'a subject to y'a = 0 and
/// 0 <= a <= c, with Q_ij = y_i y_j K_ij, by SMO with libsvm's second-order
/// working-set selection (WSS2), no shrinking. `kernel` is `(n, n)`
/// row-major, `y` is +-1. Stops when the maximal KKT violation
/// m(a) - M(a) is below `eps`. The decision function is
/// `sum_j a_j y_j K(x_j, x) - rho`.
pub(crate) fn solve_dual(kernel: &[f64], y: &[f64], c: f64, eps: f64) -> Result<DualSolution> {
    let n = y.len();
    debug_assert_eq!(kernel.len(), n * n);
    let q = |i: usize, j: usize| y[i] * y[j] * kernel[i * n + j];
    let mut alpha = vec![0.0; n];
    // Gradient of the objective, Q a - e.
    let mut grad = vec![-1.0; n];
    let max_iterations = ITERATIONS_PER_EXAMPLE * n.max(100);
    let mut iterations = 0;
    while let Some((i, j, violation)) = working_set(kernel, y, &alpha, &grad, c) {
        if violation < eps {
            break;
        }
        if iterations >= max_iterations {
            return Err(BciError::Training(format!(
                "the SVM solver did not converge in {max_iterations} iterations \
                 (KKT violation {violation:.3e}, tolerance {eps:e})"
            )));
        }
        iterations += 1;

        // Analytic update of (alpha_i, alpha_j), clipped to the box.
        let (old_i, old_j) = (alpha[i], alpha[j]);
        let qij = q(i, j);
        if y[i] != y[j] {
            let quad = (kernel[i * n + i] + kernel[j * n + j] + 2.0 * qij).max(TAU);
            let delta = (-grad[i] - grad[j]) / quad;
            let diff = alpha[i] - alpha[j];
            alpha[i] += delta;
            alpha[j] += delta;
            if diff > 0.0 {
                if alpha[j] < 0.0 {
                    alpha[j] = 0.0;
                    alpha[i] = diff;
                }
            } else if alpha[i] < 0.0 {
                alpha[i] = 0.0;
                alpha[j] = -diff;
            }
            if diff > 0.0 {
                if alpha[i] > c {
                    alpha[i] = c;
                    alpha[j] = c - diff;
                }
            } else if alpha[j] > c {
                alpha[j] = c;
                alpha[i] = c + diff;
            }
        } else {
            let quad = (kernel[i * n + i] + kernel[j * n + j] - 2.0 * qij).max(TAU);
            let delta = (grad[i] - grad[j]) / quad;
            let sum = alpha[i] + alpha[j];
            alpha[i] -= delta;
            alpha[j] += delta;
            if sum > c {
                if alpha[i] > c {
                    alpha[i] = c;
                    alpha[j] = sum - c;
                }
            } else if alpha[j] < 0.0 {
                alpha[j] = 0.0;
                alpha[i] = sum;
            }
            if sum > c {
                if alpha[j] > c {
                    alpha[j] = c;
                    alpha[i] = sum - c;
                }
            } else if alpha[i] < 0.0 {
                alpha[i] = 0.0;
                alpha[j] = sum;
            }
        }
        let (di, dj) = (alpha[i] - old_i, alpha[j] - old_j);
        for t in 0..n {
            grad[t] += q(i, t) * di + q(j, t) * dj;
        }
    }

    let rho = rho(&alpha, &grad, y, c);
    Ok(DualSolution {
        alpha,
        rho,
        iterations,
    })
}

/// libsvm's second-order working-set selection (WSS2): `i`, the maximal
/// violator of the first-order condition, and `j`, the largest decrease of
/// the objective with it, with the KKT violation m(a) - M(a); `None` when
/// no pair can move.
fn working_set(
    kernel: &[f64],
    y: &[f64],
    alpha: &[f64],
    grad: &[f64],
    c: f64,
) -> Option<(usize, usize, f64)> {
    let n = y.len();
    // i: the maximal violator of the first-order condition.
    let mut g_max = f64::NEG_INFINITY;
    let mut i_best = None;
    for t in 0..n {
        let v = if y[t] > 0.0 {
            (alpha[t] < c).then_some(-grad[t])
        } else {
            (alpha[t] > 0.0).then_some(grad[t])
        };
        if let Some(v) = v
            && v >= g_max
        {
            g_max = v;
            i_best = Some(t);
        }
    }
    // j: the largest decrease of the objective with i (second order).
    let mut g_max2 = f64::NEG_INFINITY;
    let mut j_best = None;
    let mut obj_min = f64::INFINITY;
    if let Some(i) = i_best {
        for t in 0..n {
            let (movable, g) = if y[t] > 0.0 {
                (alpha[t] > 0.0, grad[t])
            } else {
                (alpha[t] < c, -grad[t])
            };
            if !movable {
                continue;
            }
            g_max2 = g_max2.max(g);
            let grad_diff = g_max + g;
            if grad_diff > 0.0 {
                // |phi(x_i) - phi(x_t)|^2 whatever the labels.
                let quad = kernel[i * n + i] + kernel[t * n + t] - 2.0 * kernel[i * n + t];
                let obj = -(grad_diff * grad_diff) / if quad > 0.0 { quad } else { TAU };
                if obj <= obj_min {
                    obj_min = obj;
                    j_best = Some(t);
                }
            }
        }
    }
    match (i_best, j_best) {
        (Some(i), Some(j)) => Some((i, j, g_max + g_max2)),
        _ => None,
    }
}

/// The bias rho of the decision function: the mean of y_i grad_i over the
/// free variables, else the middle of the feasible interval.
fn rho(alpha: &[f64], grad: &[f64], y: &[f64], c: f64) -> f64 {
    let n = y.len();
    // rho: the mean of y_i grad_i over free variables, else the middle of
    // the feasible interval.
    let (mut upper, mut lower) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut n_free, mut sum_free) = (0usize, 0.0);
    for t in 0..n {
        let yg = y[t] * grad[t];
        let at_upper = alpha[t] >= c;
        let at_lower = alpha[t] <= 0.0;
        if (at_upper && y[t] < 0.0) || (at_lower && y[t] > 0.0) {
            upper = upper.min(yg);
        } else if at_upper || at_lower {
            lower = lower.max(yg);
        } else {
            n_free += 1;
            sum_free += yg;
        }
    }
    if n_free > 0 {
        sum_free / n_free as f64
    } else {
        (upper + lower) / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::labelled;
    use rand::Rng;
    use rand_distr::StandardNormal;

    #[test]
    fn dual_solution_meets_the_kkt_conditions() {
        // Overlapping classes: some alphas at 0, some free, some at C.
        let mut rng = labelled(2, "test/kkt");
        let (n, d) = (120, 5);
        let y: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 1 { 1.0 } else { -1.0 })
            .collect();
        let x: Vec<f64> = (0..n * d)
            .map(|k| 0.5 * (y[k / d] + 1.0) + rng.sample::<f64, _>(StandardNormal))
            .collect();
        let gamma = 0.05;
        let kernel: Vec<f64> = (0..n * n)
            .map(|k| {
                let (a, b) = (&x[k / n * d..][..d], &x[k % n * d..][..d]);
                let dist: f64 = a.iter().zip(b).map(|(u, v)| (u - v).powi(2)).sum();
                (-gamma * dist).exp()
            })
            .collect();
        let (c, eps) = (2.0, 1e-3);
        let sol = solve_dual(&kernel, &y, c, eps).unwrap();
        assert!(sol.alpha.iter().all(|&a| (0.0..=c).contains(&a)));
        let balance: f64 = sol.alpha.iter().zip(&y).map(|(a, y)| a * y).sum();
        assert!(balance.abs() < 1e-9, "{balance}");
        let (mut free, mut bound) = (0, 0);
        for i in 0..n {
            let f: f64 = (0..n)
                .map(|j| sol.alpha[j] * y[j] * kernel[i * n + j])
                .sum::<f64>()
                - sol.rho;
            let margin = y[i] * f;
            let tol = eps + 1e-9;
            if sol.alpha[i] <= 0.0 {
                assert!(margin >= 1.0 - tol, "alpha = 0 but margin {margin}");
            } else if sol.alpha[i] >= c {
                bound += 1;
                assert!(margin <= 1.0 + tol, "alpha = C but margin {margin}");
            } else {
                free += 1;
                assert!((margin - 1.0).abs() <= tol, "free but margin {margin}");
            }
        }
        assert!(free > 0 && bound > 0, "{free} free, {bound} at C");
    }
}
