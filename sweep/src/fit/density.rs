//! The Monte Carlo likelihood of one observed run: how probable a simulated
//! model makes what the paper saw, estimated from the model's own runs.
//!
//! An observation is a run that reached its goal in `time_secs` with
//! `detections` detected errors (the paper's sec. 5.3). Its likelihood under
//! a model is P(reached) times the density of (time, detections) among the
//! model's runs that reached the goal. The density is a Gaussian product
//! kernel estimate over (ln time, detections), with Scott's bandwidth per
//! dimension (sd x n^(-1/6), for two dimensions); the log of time because
//! times are skewed to the right and scale with the robot's speed. The
//! Jacobian of the log (1 / time) is the same at every grid point, so it is
//! left out: log-likelihoods are comparable across a grid, not absolute.
//! P(reached) is (reached + 1/2) / (runs + 1), Jeffreys' estimate, so that a
//! level where no run (or every run) reached the goal is not infinitely
//! (un)likely.

use rand::Rng;

pub use errp_sim::{percentile_of, quantile};

/// One simulated run, as the likelihood sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimRun {
    /// Time to convergence (s).
    pub time_secs: f64,
    /// Detected errors.
    pub detections: f64,
    /// Converged on the user's goal.
    pub reached: bool,
    /// The calibration (the simulated user's decoder) the run belongs to:
    /// runs of one calibration share its decoder, so the bootstrap resamples
    /// calibrations, then runs within each.
    pub calibration: usize,
}

/// An observed run that reached its goal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observed {
    /// Time to convergence (s).
    pub time_secs: f64,
    /// Detected errors.
    pub detections: f64,
}

/// Smallest bandwidths: 2 % of time on the log scale, half a detection.
const MIN_BANDWIDTH: [f64; 2] = [0.02, 0.5];

/// log P(reached) + log density of `obs` among the runs that reached the
/// goal (see the module docs). Finite whenever a run reached the goal (one
/// such run gets a kernel of the smallest bandwidths); minus infinity when
/// none did, since the model then says nothing about the time and
/// detections of a successful run.
pub fn log_likelihood(runs: &[SimRun], obs: &Observed) -> f64 {
    let n = runs.len();
    let ok: Vec<[f64; 2]> = runs
        .iter()
        .filter(|r| r.reached && r.time_secs > 0.0)
        .map(|r| [r.time_secs.ln(), r.detections])
        .collect();
    let p_reached = (ok.len() as f64 + 0.5) / (n as f64 + 1.0);
    let x = [obs.time_secs.ln(), obs.detections];
    p_reached.ln() + log_kde(&ok, x)
}

/// Log of the Gaussian product-kernel density at `x` (Scott's bandwidths),
/// computed as a log-sum-exp so that a point far from every sample stays
/// finite. Minus infinity only for no samples.
pub fn log_kde(samples: &[[f64; 2]], x: [f64; 2]) -> f64 {
    let m = samples.len();
    if m == 0 {
        return f64::NEG_INFINITY;
    }
    let factor = (m as f64).powf(-1.0 / 6.0);
    let mut h = [0.0; 2];
    for d in 0..2 {
        let mean = samples.iter().map(|s| s[d]).sum::<f64>() / m as f64;
        let var = if m > 1 {
            samples.iter().map(|s| (s[d] - mean).powi(2)).sum::<f64>() / (m - 1) as f64
        } else {
            0.0
        };
        h[d] = (var.sqrt() * factor).max(MIN_BANDWIDTH[d]);
    }
    let terms: Vec<f64> = samples
        .iter()
        .map(|s| -0.5 * (((x[0] - s[0]) / h[0]).powi(2) + ((x[1] - s[1]) / h[1]).powi(2)))
        .collect();
    let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let sum: f64 = terms.iter().map(|t| (t - top).exp()).sum();
    top + sum.ln() - (m as f64).ln() - (2.0 * std::f64::consts::PI * h[0] * h[1]).ln()
}

/// A bootstrap replicate of `runs`, resampled in two stages as they were
/// made: the calibrations with replacement, then the runs of each drawn
/// calibration with replacement. So the Monte Carlo error includes how much
/// the decoder differs between calibrations at one accuracy, not only
/// between runs of one decoder.
pub fn resample(runs: &[SimRun], rng: &mut impl Rng) -> Vec<SimRun> {
    let mut groups: Vec<usize> = runs.iter().map(|r| r.calibration).collect();
    groups.sort_unstable();
    groups.dedup();
    let mut out = Vec::with_capacity(runs.len());
    for _ in 0..groups.len() {
        let g = groups[rng.random_range(0..groups.len())];
        let members: Vec<&SimRun> = runs.iter().filter(|r| r.calibration == g).collect();
        for _ in 0..members.len() {
            out.push(*members[rng.random_range(0..members.len())]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use errp_bci::rng::labelled;
    use rand_distr::{Distribution, Normal};

    fn runs(n: usize, mean_ln_t: f64, mean_d: f64, reached: f64, seed: u64) -> Vec<SimRun> {
        let mut rng = labelled(seed, "test");
        let t = Normal::new(mean_ln_t, 0.3).unwrap();
        let d = Normal::new(mean_d, 3.0).unwrap();
        (0..n)
            .map(|_| SimRun {
                time_secs: t.sample(&mut rng).exp(),
                detections: d.sample(&mut rng).round().max(0.0),
                reached: rng.random_bool(reached),
                calibration: 0,
            })
            .collect()
    }

    #[test]
    fn the_density_integrates_to_one_and_peaks_at_the_samples() {
        let s: Vec<[f64; 2]> = (0..50).map(|k| [0.1 * k as f64, (k % 7) as f64]).collect();
        // Riemann sum over a wide box.
        let (dx, dy) = (0.02, 0.1);
        let mut total = 0.0;
        for i in 0..600 {
            for j in 0..200 {
                let x = [-3.0 + i as f64 * dx, -5.0 + j as f64 * dy];
                total += log_kde(&s, x).exp() * dx * dy;
            }
        }
        assert!((total - 1.0).abs() < 0.01, "{total}");
        assert!(log_kde(&s, [2.5, 3.0]) > log_kde(&s, [9.0, 3.0]));
        assert!(log_kde(&s, [100.0, 100.0]).is_finite());
        assert_eq!(log_kde(&[], [0.0, 0.0]), f64::NEG_INFINITY);
    }

    #[test]
    fn the_likelihood_prefers_the_model_that_made_the_observation() {
        // An observation of 60 s and 11 detections: a model centred there
        // beats one centred at 120 s and 26, and one that rarely reaches.
        let obs = Observed {
            time_secs: 60.0,
            detections: 11.0,
        };
        let near = runs(400, 60f64.ln(), 11.0, 0.95, 1);
        let far = runs(400, 120f64.ln(), 26.0, 0.95, 2);
        let failing = runs(400, 60f64.ln(), 11.0, 0.2, 3);
        let l_near = log_likelihood(&near, &obs);
        assert!(l_near > log_likelihood(&far, &obs) + 3.0);
        // Same density, a fifth of the successes: about ln(0.2) lower.
        let gap = l_near - log_likelihood(&failing, &obs);
        assert!((gap - (0.95f64 / 0.2).ln()).abs() < 0.5, "{gap}");
        // No run reached: finite through Jeffreys' P(reached) only if some
        // run reached; none reached is -inf density, hence -inf.
        let none = runs(10, 4.0, 11.0, 0.0, 4);
        assert_eq!(log_likelihood(&none, &obs), f64::NEG_INFINITY);
    }

    #[test]
    fn the_bootstrap_resamples_calibrations_then_runs() {
        // Two calibrations: every run of one reaches, none of the other.
        let mut v = runs(50, 4.0, 10.0, 1.0, 5);
        let mut w = runs(50, 4.0, 10.0, 0.0, 6);
        for r in &mut w {
            r.calibration = 1;
        }
        v.append(&mut w);
        let mut rng = labelled(9, "boot");
        let shares: Vec<f64> = (0..400)
            .map(|_| {
                let b = resample(&v, &mut rng);
                assert_eq!(b.len(), 100);
                b.iter().filter(|r| r.reached).count() as f64 / 100.0
            })
            .collect();
        // A replicate holds both calibrations (share 0.5 +- run noise) or
        // one twice (share 0 or 1), each about half the time.
        let extreme = shares.iter().filter(|&&s| s == 0.0 || s == 1.0).count();
        assert!((150..250).contains(&extreme), "{extreme}");
    }
}
