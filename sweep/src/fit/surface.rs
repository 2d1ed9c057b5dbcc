//! A likelihood surface over a one-dimensional grid: the estimate, its
//! likelihood-ratio interval, the Monte Carlo spread of the estimate, and
//! the estimate left out one observation at a time.

use serde::Serialize;

use super::density::quantile;

/// The 95 % point of chi-square with one degree of freedom: a grid point is
/// inside the likelihood-ratio interval when twice its log-likelihood's
/// distance below the maximum is at most this (Wilks).
pub const CHI2_1_95: f64 = 3.841_458_820_694_124;

/// The log-likelihood of every observation at every grid point, with the
/// Monte Carlo replicates that measure its simulation error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Surface {
    /// The grid (the fitted parameter's values), increasing.
    pub grid: Vec<f64>,
    /// Each observation's log-likelihood, `[observation][grid point]`.
    pub log_lik: Vec<Vec<f64>>,
    /// Its Monte Carlo standard error (sd over bootstrap replicates of the
    /// simulated runs), `[observation][grid point]`.
    pub mc_sd: Vec<Vec<f64>>,
    /// The sum over observations at each grid point.
    pub total: Vec<f64>,
    /// The Monte Carlo standard error of the sum.
    pub total_sd: Vec<f64>,
    /// Index of the maximum-likelihood grid point.
    pub estimate: usize,
    /// The 95 % likelihood-ratio interval: the lowest and highest grid
    /// points within [`CHI2_1_95`] / 2 of the maximum.
    pub interval: (f64, f64),
    /// Whether that interval reaches the grid's lower and upper ends (the
    /// true interval may then extend beyond the grid).
    pub interval_at_edge: (bool, bool),
    /// The 5 % and 95 % quantiles of the estimate over the bootstrap
    /// replicates: how far Monte Carlo error alone moves it.
    pub mc_interval: (f64, f64),
    /// The estimate from every observation but the `i`th, as a grid index.
    pub leave_one_out: Vec<usize>,
}

impl Surface {
    /// The surface of `log_lik[obs][point]` over `grid`, with `replicates[obs]
    /// [point][b]` the log-likelihood of bootstrap replicate `b` (the same
    /// `b` resamples every point independently).
    pub fn new(grid: Vec<f64>, log_lik: Vec<Vec<f64>>, replicates: &[Vec<Vec<f64>>]) -> Self {
        let n = grid.len();
        let m = log_lik.len();
        let total: Vec<f64> = (0..n).map(|j| log_lik.iter().map(|l| l[j]).sum()).collect();
        let mc_sd: Vec<Vec<f64>> = replicates
            .iter()
            .map(|per_point| per_point.iter().map(|r| finite_sd(r)).collect())
            .collect();
        let n_boot = replicates
            .first()
            .and_then(|p| p.first())
            .map_or(0, Vec::len);
        let boot_total = |j: usize, b: usize| -> f64 { (0..m).map(|i| replicates[i][j][b]).sum() };
        let total_sd: Vec<f64> = (0..n)
            .map(|j| finite_sd(&(0..n_boot).map(|b| boot_total(j, b)).collect::<Vec<_>>()))
            .collect();
        let estimate = argmax(&total);
        let best = total[estimate];
        let inside: Vec<usize> = (0..n)
            .filter(|&j| 2.0 * (best - total[j]) <= CHI2_1_95)
            .collect();
        let (lo, hi) = (
            inside.first().copied().unwrap_or(estimate),
            inside.last().copied().unwrap_or(estimate),
        );
        let boot_estimates: Vec<f64> = (0..n_boot)
            .map(|b| grid[argmax(&(0..n).map(|j| boot_total(j, b)).collect::<Vec<_>>())])
            .collect();
        let mc_interval = if boot_estimates.is_empty() {
            (grid[estimate], grid[estimate])
        } else {
            (
                quantile(&boot_estimates, 0.05),
                quantile(&boot_estimates, 0.95),
            )
        };
        let leave_one_out = (0..m)
            .map(|i| {
                argmax(
                    &(0..n)
                        .map(|j| (0..m).filter(|&k| k != i).map(|k| log_lik[k][j]).sum())
                        .collect::<Vec<f64>>(),
                )
            })
            .collect();
        Self {
            interval: (grid[lo], grid[hi]),
            interval_at_edge: (lo == 0, hi + 1 == n),
            grid,
            log_lik,
            mc_sd,
            total,
            total_sd,
            estimate,
            mc_interval,
            leave_one_out,
        }
    }

    /// The estimate: the grid value of largest total log-likelihood.
    pub fn estimate_value(&self) -> f64 {
        self.grid[self.estimate]
    }
}

/// Index of the largest value (the first of ties; NaN never wins; 0 for an
/// empty or all-NaN slice).
pub fn argmax(v: &[f64]) -> usize {
    let mut best = 0;
    for (i, &x) in v.iter().enumerate() {
        if x > v[best] || v[best].is_nan() {
            best = i;
        }
    }
    best
}

/// Sample sd of the finite values (NaN for fewer than two; infinite if some
/// replicate is minus infinity while others are finite).
fn finite_sd(v: &[f64]) -> f64 {
    if v.iter().any(|x| x.is_infinite()) && v.iter().any(|x| x.is_finite()) {
        return f64::INFINITY;
    }
    let f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if f.len() < 2 {
        return f64::NAN;
    }
    let mean = f.iter().sum::<f64>() / f.len() as f64;
    (f.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (f.len() - 1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quadratic_surface_gives_its_vertex_and_wilks_interval() {
        // Two observations, each -(x - c)^2 / (2 s^2) with s = 0.05: the
        // sum has sd 0.05 / sqrt 2, so the 95 % interval is the vertex
        // +- 1.96 x 0.0354 = +- 0.069.
        let grid: Vec<f64> = (0..41).map(|k| 0.6 + 0.01 * k as f64).collect();
        let ll = |c: f64| -> Vec<f64> {
            grid.iter()
                .map(|x| -(x - c).powi(2) / (2.0 * 0.05f64.powi(2)))
                .collect()
        };
        let log_lik = vec![ll(0.78), ll(0.82)];
        let reps: Vec<Vec<Vec<f64>>> = log_lik
            .iter()
            .map(|l| l.iter().map(|&v| vec![v - 0.1, v, v + 0.1]).collect())
            .collect();
        let s = Surface::new(grid, log_lik, &reps);
        assert!((s.estimate_value() - 0.80).abs() < 1e-9);
        assert!((s.interval.0 - 0.74).abs() < 0.011, "{:?}", s.interval);
        assert!((s.interval.1 - 0.86).abs() < 0.011, "{:?}", s.interval);
        assert_eq!(s.interval_at_edge, (false, false));
        // Leaving out the first observation moves the estimate to the
        // second's vertex, and the other way round.
        assert!((s.grid[s.leave_one_out[0]] - 0.82).abs() < 1e-9);
        assert!((s.grid[s.leave_one_out[1]] - 0.78).abs() < 1e-9);
        // Replicates shifted by a constant leave the estimate alone.
        assert!((s.mc_interval.0 - 0.80).abs() < 1e-9);
        assert!((s.mc_sd[0][0] - 0.1).abs() < 1e-9);
        assert!((s.total_sd[0] - 0.2).abs() < 1e-9);
    }

    #[test]
    fn an_interval_that_reaches_the_grid_edge_says_so() {
        let grid = vec![0.7, 0.8, 0.9];
        let s = Surface::new(grid, vec![vec![-0.5, -0.2, 0.0]], &[]);
        assert_eq!(s.estimate, 2);
        assert_eq!(s.interval, (0.7, 0.9));
        assert_eq!(s.interval_at_edge, (true, true));
        assert_eq!(argmax(&[f64::NAN, 1.0, 3.0, 3.0]), 2);
    }
}
