//! The likelihood of one subject's Table 1 row given the simulated groups:
//! P(all five reached) times a normal density of ln(mean actions).

use errp_sim::mean_sd;

use crate::fit::density::SimRun;

/// Smallest sd of ln(mean actions).
const MIN_SD: f64 = 0.02;

/// log P(all reached) + log density of ln `mean` among the groups that
/// reached (see the module docs); groups are [`SimRun`]s whose `time_secs`
/// is the group's mean actions.
pub fn group_log_likelihood(groups: &[SimRun], mean: f64) -> f64 {
    let ok: Vec<f64> = groups
        .iter()
        .filter(|g| g.reached && g.time_secs > 0.0)
        .map(|g| g.time_secs.ln())
        .collect();
    let p = (ok.len() as f64 + 0.5) / (groups.len() as f64 + 1.0);
    p.ln() + log_normal_density(&ok, mean.ln())
}

/// Log of the normal density fitted to `samples` (mean, sample sd, at least
/// 0.02) at `x`; minus infinity for fewer than two samples. A
/// parametric density, not a kernel one: the paper's means can lie in the
/// tail of the simulated ones, where a kernel estimate from a few hundred
/// groups is all noise.
pub fn log_normal_density(samples: &[f64], x: f64) -> f64 {
    if samples.len() < 2 {
        return f64::NEG_INFINITY;
    }
    let (m, sd) = mean_sd(samples);
    let sd = sd.max(MIN_SD);
    -0.5 * ((x - m) / sd).powi(2) - sd.ln() - 0.5 * (2.0 * std::f64::consts::PI).ln()
}

#[cfg(test)]
mod tests {
    use super::{group_log_likelihood, log_normal_density};
    use crate::fit::density::SimRun;

    #[test]
    fn the_normal_density_integrates_to_one() {
        let s: Vec<f64> = (0..40).map(|k| 2.0 + 0.05 * k as f64).collect();
        let dx = 0.001;
        let total: f64 = (0..8000)
            .map(|i| log_normal_density(&s, i as f64 * dx).exp() * dx)
            .sum();
        assert!((total - 1.0).abs() < 0.01, "{total}");
        assert_eq!(log_normal_density(&[1.0], 1.0), f64::NEG_INFINITY);
    }

    #[test]
    fn the_group_likelihood_prefers_groups_near_the_paper_and_reaching() {
        let groups = |centre: f64, reached: bool| -> Vec<SimRun> {
            (0..100)
                .map(|k| SimRun {
                    time_secs: centre * (1.0 + 0.002 * (k as f64 - 50.0)),
                    detections: 0.0,
                    reached: reached || k % 2 == 0,
                    calibration: k % 5,
                })
                .collect()
        };
        let near = group_log_likelihood(&groups(16.0, true), 16.0);
        assert!(near > group_log_likelihood(&groups(30.0, true), 16.0) + 5.0);
        // Half the groups fail: about ln 2 lower.
        let gap = near - group_log_likelihood(&groups(16.0, false), 16.0);
        assert!((gap - 2f64.ln()).abs() < 0.3, "{gap}");
    }
}
