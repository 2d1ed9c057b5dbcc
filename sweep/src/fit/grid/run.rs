//! `errp fit grid` from start to end: check, calibrate, run the episodes,
//! analyse, write the files.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicUsize;

use errp_bci::GoalSet;
use errp_bci::stop::WindDown;
use errp_sim::grid::{GridTaskParams, PairFamily};
use errp_sim::{Result, create_dir};

use super::analysis::analyse;
use super::calibrate::calibrate_users;
use super::episodes::{Episodes, PointRuns};
use super::output::write_fit;
use super::pairs::pairs_fit;
use super::paper::paper_rows;
use super::result::GridFit;
use super::spec::{GridFitSpec, check_spec};
use super::trial_latency::trial_latency_fit;
use crate::cache::TargetCache;
use crate::fit::estimate::FitProvenance;
use crate::fit::files;
use crate::observer::SweepObserver;

/// The outcome of [`run_grid_fit`].
#[derive(Debug)]
pub enum GridFitOutcome {
    /// Wound down (its `WindDown` was requested) (nothing written; the targetings found
    /// are in the cache).
    Interrupted,
    /// The fit, and the files written.
    Complete(Box<GridFit>, Vec<PathBuf>),
}

/// Refuses an `out` that holds anything the fit did not write.
fn check_out(out: &Path) -> Result<()> {
    files::check_out(out, |_| false, "a grid fit's")
}

/// Calibrates every subject's decoders, runs every grid point and writes
/// [`FIT_FILES`](crate::fit::FIT_FILES) into `out`. The observer sees each decoder as it is
/// ready, then the episodes.
pub fn run_grid_fit(
    spec: &GridFitSpec,
    out: &Path,
    cache: &TargetCache,
    provenance: FitProvenance,
    wind_down: &WindDown,
    observer: &dyn SweepObserver,
) -> Result<GridFitOutcome> {
    check_spec(spec)?;
    check_out(out)?;
    let fit = if spec.trial_latency_sds.is_empty() {
        fit_users(spec, cache, provenance, wind_down, observer)?
    } else {
        let mut fits = Vec::with_capacity(spec.trial_latency_sds.len());
        for &sd in &spec.trial_latency_sds {
            let mut at = spec.clone();
            at.realism.trial_latency_sd_ms = Some(sd);
            at.trial_latency_sds = Vec::new();
            match fit_users(&at, cache, provenance.clone(), wind_down, observer)? {
                Some(fit) => fits.push(fit),
                None => return Ok(GridFitOutcome::Interrupted),
            }
        }
        Some(trial_latency_fit(spec, fits))
    };
    let Some(fit) = fit else {
        return Ok(GridFitOutcome::Interrupted);
    };
    create_dir(out)?;
    let files = write_fit(&fit, out)?;
    Ok(GridFitOutcome::Complete(Box::new(fit), files))
}

/// The fit for the users of `spec.realism`: every subject's decoders
/// calibrated, every grid point (and pair length) run and analysed; `None`
/// if cancelled.
fn fit_users(
    spec: &GridFitSpec,
    cache: &TargetCache,
    provenance: FitProvenance,
    wind_down: &WindDown,
    observer: &dyn SweepObserver,
) -> Result<Option<GridFit>> {
    let fixed = paper_rows(GoalSet::Fixed);
    let free = paper_rows(GoalSet::Free);
    let base = GridTaskParams::default();
    let Some(calibrations) = calibrate_users(spec, cache, wind_down, observer, base)? else {
        return Ok(None);
    };
    let family = PairFamily::paper();
    let sets = spec.pair_lengths.len();
    let per_set = spec.goal_rewards.len() * spec.repeats * 5 * calibrations.len() / 2;
    let episodes = Episodes {
        spec,
        calibrations: &calibrations,
        base,
        family: &family,
        wind_down,
        observer,
        done: AtomicUsize::new(0),
        total: per_set * (sets.max(1) + 1),
    };
    let fit = if sets == 0 {
        let Some(runs) = episodes.run(None, None)? else {
            return Ok(None);
        };
        analyse(spec, &calibrations, &runs, &fixed, &free, provenance)
    } else {
        let Some(free_runs) = episodes.run(Some(GoalSet::Free), None)? else {
            return Ok(None);
        };
        let mut fits = Vec::with_capacity(sets);
        for &length in &spec.pair_lengths {
            let Some(fixed_runs) = episodes.run(Some(GoalSet::Fixed), Some(length))? else {
                return Ok(None);
            };
            // runs[point][calibration]: the fixed calibrations' runs at this
            // length, the free ones' (which no length changes) shared.
            let runs: PointRuns = fixed_runs
                .into_iter()
                .zip(&free_runs)
                .map(|(at_fixed, at_free)| {
                    at_fixed
                        .into_iter()
                        .zip(at_free)
                        .zip(&calibrations)
                        .map(|((f, r), c)| {
                            if c.goals == GoalSet::Fixed {
                                f
                            } else {
                                r.clone()
                            }
                        })
                        .collect()
                })
                .collect();
            fits.push(analyse(
                spec,
                &calibrations,
                &runs,
                &fixed,
                &free,
                provenance.clone(),
            ));
        }
        pairs_fit(spec, &family, fits)
    };
    Ok(Some(fit))
}
