//! The fit's runs analysed: each paper run's likelihood at every accuracy,
//! the surface and its bootstrap, each run held out in turn.

use errp_bci::rng::labelled;

use super::result::{DENSITY, EpuckFit, FIT_FORMAT, HeldOut, RunStats};
use super::spec::{EpuckFitSpec, PaperRun};
use crate::fit::density::{SimRun, log_likelihood, resample};
use crate::fit::estimate::{FitEstimate, FitProvenance};
use crate::fit::surface::Surface;

/// The fit from the runs, `per_run[observation][grid point]`.
pub fn analyse(
    spec: &EpuckFitSpec,
    runs: &[PaperRun],
    per_run: &[Vec<Vec<SimRun>>],
    provenance: FitProvenance,
) -> EpuckFit {
    let log_lik: Vec<Vec<f64>> = runs
        .iter()
        .zip(per_run)
        .map(|(r, levels)| {
            levels
                .iter()
                .map(|sims| log_likelihood(sims, &r.observed))
                .collect()
        })
        .collect();
    let replicates: Vec<Vec<Vec<f64>>> = runs
        .iter()
        .zip(per_run)
        .enumerate()
        .map(|(i, (r, levels))| {
            levels
                .iter()
                .enumerate()
                .map(|(j, sims)| {
                    let mut rng = labelled(
                        errp_bci::rng::derive_seed(
                            spec.seed,
                            "fit/bootstrap",
                            (i * 1000 + j) as u64,
                        ),
                        "fit/bootstrap",
                    );
                    (0..spec.bootstrap)
                        .map(|_| log_likelihood(&resample(sims, &mut rng), &r.observed))
                        .collect()
                })
                .collect()
        })
        .collect();
    let surface = Surface::new(spec.accuracies.clone(), log_lik, &replicates);
    let stats: Vec<Vec<RunStats>> = runs
        .iter()
        .zip(per_run)
        .map(|(r, levels)| {
            levels
                .iter()
                .map(|s| RunStats::of(s, &r.observed))
                .collect()
        })
        .collect();
    let held_out = runs
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let j = surface.leave_one_out[i];
            HeldOut {
                name: r.name.to_string(),
                fitted_without: surface.grid[j],
                stats: stats[i][j].clone(),
            }
        })
        .collect();
    EpuckFit {
        format: FIT_FORMAT,
        estimate: FitEstimate::of("user.accuracy", &surface),
        observations: runs
            .iter()
            .map(|r| {
                (
                    r.name.to_string(),
                    r.file.to_string(),
                    r.observed.time_secs,
                    r.observed.detections,
                )
            })
            .collect(),
        stats,
        surface,
        held_out,
        density: DENSITY.into(),
        spec: spec.clone(),
        provenance,
    }
}
