//! `errp fit grid` over the ErrP's single-trial latency SD, a per-trial
//! heterogeneity with a published range (Fidencio et al. 2024: 16.7 to
//! 21.3 ms): the whole fit at each SD, its profile, and the fit at the
//! chosen SD.

use super::result::{CellStats, GridFit, TrialLatencyFit};
use super::spec::GridFitSpec;
use crate::fit::surface::{CHI2_1_95, argmax};

/// The index of the grid point a fit reports at: its 40/40 goal reward, or
/// its maximum if none keeps the paper's 40/40.
fn reported_point(fit: &GridFit) -> usize {
    let g = fit.reached_estimate.unwrap_or(fit.estimate.value);
    fit.surface
        .grid
        .iter()
        .position(|&x| x == g)
        .unwrap_or(fit.surface.estimate)
}

/// The fit over the SDs: each SD's profile over the rest, the estimates,
/// and the fit at the chosen SD (`fits`: one per `spec.trial_latency_sds`).
pub(super) fn trial_latency_fit(spec: &GridFitSpec, fits: Vec<GridFit>) -> GridFit {
    let sds = spec.trial_latency_sds.clone();
    let profile: Vec<f64> = fits
        .iter()
        .map(|f| match &f.pairs {
            Some(p) => p.profile[argmax(&p.profile)],
            None => f.surface.total[f.surface.estimate],
        })
        .collect();
    let reached: Vec<Option<f64>> = fits
        .iter()
        .map(|f| match &f.pairs {
            Some(p) => p
                .reached
                .iter()
                .flatten()
                .map(|r| r.1)
                .max_by(f64::total_cmp),
            None => f
                .reached_estimate
                .map(|_| f.surface.total[reported_point(f)]),
        })
        .collect();
    let points: Vec<usize> = fits.iter().map(reported_point).collect();
    let top = argmax(&profile);
    let within: Vec<usize> = (0..sds.len())
        .filter(|&k| profile[k] >= profile[top] - CHI2_1_95 / 2.0)
        .collect();
    // The first of equal maxima, as `argmax` takes.
    let reached_at = (0..sds.len())
        .filter_map(|k| reached[k].map(|l| (k, l)))
        .fold(None, |best: Option<(usize, f64)>, (k, l)| match best {
            Some((_, b)) if b >= l => best,
            _ => Some((k, l)),
        })
        .map(|(k, _)| k);
    let chosen = reached_at.unwrap_or(top);
    let z = |stats: &dyn Fn(&GridFit) -> &Vec<Vec<CellStats>>| -> Vec<Vec<f64>> {
        fits.iter()
            .zip(&points)
            .map(|(f, &j)| stats(f).iter().map(|per_point| per_point[j].z).collect())
            .collect()
    };
    let trial = TrialLatencyFit {
        profile,
        reached,
        point: fits
            .iter()
            .zip(&points)
            .map(|(f, &j)| (f.pairs.as_ref().map(|p| p.chosen), f.surface.grid[j]))
            .collect(),
        p_all_reached: fits
            .iter()
            .zip(&points)
            .map(|(f, &j)| f.p_all_reached[j])
            .collect(),
        fixed_z: z(&|f| &f.fixed_stats),
        free_z: z(&|f| &f.free_stats),
        estimate: sds[top],
        interval_95: (
            sds[*within.first().unwrap_or(&top)],
            sds[*within.last().unwrap_or(&top)],
        ),
        chosen: sds[chosen],
        sds,
    };
    let mut fit = fits.into_iter().nth(chosen).expect("one fit per SD");
    fit.spec = spec.clone();
    fit.trial_latency = Some(trial);
    fit
}
