//! `errp fit grid`: the Q-value scale of the grid task estimated from Table 1
//! (sec. 4.3), the four subjects' mean actions on the fixed goals, and
//! checked on what the fit did not see: the free goals and the
//! accuracy-time correlation r.
//!
//! The paper states the soft-max temperature (tau = 0.3) but not the scale
//! of the Q-values it divides, which is what sets how much one action moves
//! the belief: it is fitted as `control.goal_reward` (the Q-values are
//! proportional to it; scaling it by k is dividing tau by k).
//!
//! Each subject is simulated as the paper ran them: a decoder calibrated to
//! the subject's online accuracy on that goal set (Table 1's accuracy row),
//! then five runs, one per start/goal pair. A subject is simulated with
//! several calibrations (the decoders a calibration at that accuracy can
//! give), and each calibration with several repeats of the five runs; a
//! *group* is five runs of one calibration, one per pair. The likelihood of a
//! subject's row is P(all five reached) (Jeffreys' estimate over the groups)
//! times the density of the mean of five runs' actions among the groups that
//! reached every goal, at the paper's mean: a normal density over ln(mean
//! actions), fitted to those groups. Episodes read epochs from a bank
//! ([`EegMode::Bank`]), which agrees with streamed EEG (`errp table1 --eeg
//! bank`) and is two hundred times faster; every grid point runs the same
//! episodes' seeds (common random numbers), so the surface is smooth.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use errp_bci::rng::{derive_seed, stream};
use errp_bci::stop::WindDown;
use errp_bci::{GoalSet, subjects};
use errp_robot::{Cell, Grid, GridControlParams, QTable};
use errp_sim::grid::{
    AssessmentDecoder, DecoderChoice, EegMode, FIXED_PAIRS, GridEpisodeResult, GridScenario,
    GridShared, GridTaskParams, PairFamily, free_pairs, prepare_grid_decoder, run_grid_episode,
};
use errp_sim::{PAPER, Result, SimError, create_dir, mean_sd, pearson};
use rayon::prelude::*;
use serde::Serialize;

use super::density::{SimRun, percentile_of, quantile, resample};
use super::epuck::Provenance;
use super::files;
use super::grid_pairs::{PairsFit, pairs_fit};
use super::grid_trial::{TrialLatencyFit, trial_latency_fit};
use super::surface::{Surface, argmax};
use crate::cache::TargetCache;
use crate::observer::SweepObserver;
use crate::plot::{Curve, CurvePoint, FitPanel, FitPlot};

mod episodes;
mod output;

use episodes::{Episodes, PointRuns, analyse};
use output::write_fit;
pub use output::{grid_fit_plot, grid_surface_csv};

/// What `errp fit grid` runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridFitSpec {
    /// The grid of Q-value scales (`control.goal_reward`, at tau = 0.3).
    pub goal_rewards: Vec<f64>,
    /// The device's epsilon (`control.epsilon`), held fixed.
    pub epsilon: f64,
    /// Calibrations per subject and goal set.
    pub calibrations: usize,
    /// Groups of five runs per calibration.
    pub repeats: usize,
    /// The base seed.
    pub seed: u64,
    /// Bootstrap replicates for the Monte Carlo error.
    pub bootstrap: usize,
    /// The simulated users (left out of the written spec when ideal).
    #[serde(skip_serializing_if = "errp_bci::Realism::is_ideal")]
    pub realism: errp_bci::Realism,
    /// The fixed pairs' total Manhattan lengths, fitted jointly with the
    /// goal reward ([`PairFamily`]: each group of five runs draws its own
    /// set of that length); empty: the shipped pairs ([`FIXED_PAIRS`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pair_lengths: Vec<usize>,
    /// The ErrP's single-trial latency SDs (ms,
    /// [`Realism::trial_latency_sd_ms`](errp_bci::Realism::trial_latency_sd_ms)),
    /// fitted jointly with the rest: the whole fit is run at each
    /// ([`TrialLatencyFit`]); empty: the users' own.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub trial_latency_sds: Vec<f64>,
}

/// The largest number of pair lengths in one fit.
pub const MAX_PAIR_LENGTHS: usize = 32;
/// The largest number of single-trial latency SDs in one fit (each runs
/// the whole fit).
pub const MAX_TRIAL_LATENCY_SDS: usize = 16;

/// Epochs per class in each calibration's bank.
pub const GRID_FIT_BANK: usize = 1000;
/// The largest number of calibrations per subject and goal set.
pub const MAX_GRID_CALIBRATIONS: usize = 50;
/// The largest number of groups per calibration.
pub const MAX_GRID_REPEATS: usize = 1000;

/// One subject on one goal set, as the paper reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaperRow {
    /// S1..S4.
    pub subject: String,
    /// Mean online accuracy (fraction): what the decoder is calibrated to.
    pub accuracy: f64,
    /// Mean actions over the five runs.
    pub actions_mean: f64,
    /// Their sd.
    pub actions_sd: f64,
}

/// The paper's rows of a goal set, in subject order.
pub fn paper_rows(goals: GoalSet) -> Vec<PaperRow> {
    subjects()
        .iter()
        .map(|s| {
            let (_, _, v) = PAPER
                .iter()
                .find(|(n, g, _)| *n == s.name && *g == goals)
                .expect("Table 1 has every subject and goal set");
            PaperRow {
                subject: s.name.clone(),
                accuracy: s.accuracy(goals),
                actions_mean: v[0],
                actions_sd: v[1],
            }
        })
        .collect()
}

/// A subject's simulated runs on a goal set at one grid point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellStats {
    /// Runs.
    pub runs: usize,
    /// Runs that converged on the user's goal.
    pub reached: usize,
    /// Groups of five runs, and those that reached all five goals.
    pub groups: (usize, usize),
    /// Mean and sd of the actions over every run (as `errp table1`).
    pub actions: (f64, f64),
    /// Median, 10 % and 90 % of the mean actions of the groups that reached
    /// every goal.
    pub group_mean: [f64; 3],
    /// Where the paper's mean lies among those group means (0 to 1).
    pub percentile: f64,
    /// (ours - paper) / sqrt(paper sd^2 / 5 + our sd^2 / runs): the
    /// difference in standard errors.
    pub z: f64,
    /// Mean over runs of each run's online accuracy (mean of the per-class
    /// rates; runs without an action of a class left out), as Table 1's row.
    pub online_accuracy: f64,
}

/// Tables of one goal set at one grid point: each is one group of every
/// subject (same calibration and repeat index), 20 runs, as the paper's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableStats {
    /// Tables.
    pub tables: usize,
    /// Tables in which all 20 goals were reached.
    pub all_reached: usize,
    /// Tables in which r (online accuracy vs total time) is negative.
    pub r_negative: usize,
    /// Median r.
    pub median_r: f64,
}

/// The result of `errp fit grid`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridFit {
    /// Result file format.
    pub format: u32,
    /// The scenario field fitted.
    pub parameter: String,
    /// The maximum-likelihood goal reward (a grid point).
    pub estimate: f64,
    /// Its 95 % likelihood-ratio interval.
    pub interval_95: (f64, f64),
    /// Whether that interval reaches the grid's ends.
    pub interval_at_edge: (bool, bool),
    /// The 5-95 % spread of the estimate over bootstrap replicates.
    pub mc_interval_90: (f64, f64),
    /// Table 1's fixed-goal rows (fitted).
    pub fixed: Vec<PaperRow>,
    /// Its free-goal rows (held out).
    pub free: Vec<PaperRow>,
    /// The likelihood surface of the fixed-goal rows, one observation per
    /// subject.
    pub surface: Surface,
    /// Each subject's own maximum-likelihood goal reward (its profile's
    /// peak): what would fit that subject alone.
    pub own_estimates: Vec<f64>,
    /// The free-goal rows' log-likelihood at every grid point (held out,
    /// summed over subjects).
    pub free_log_lik: Vec<f64>,
    /// `fixed_stats[subject][grid point]`.
    pub fixed_stats: Vec<Vec<CellStats>>,
    /// `free_stats[subject][grid point]`.
    pub free_stats: Vec<Vec<CellStats>>,
    /// Tables on the fixed goals, per grid point.
    pub fixed_tables: Vec<TableStats>,
    /// Tables on the free goals, per grid point.
    pub free_tables: Vec<TableStats>,
    /// P(all 40 of the paper's goals reached) at each grid point: the
    /// share of fixed-goal tables with 20/20 times that of free-goal tables
    /// (each Jeffreys' estimate).
    pub p_all_reached: Vec<f64>,
    /// The largest-likelihood goal reward among those at which the paper's
    /// 40/40 is not rejected ([`p_all_reached`](Self::p_all_reached) at
    /// least [`REACHED_LEVEL`]); none if there is none. When the
    /// fixed-goal actions pull the estimate to where goals are missed, this
    /// is the scale that keeps the paper's main result.
    pub reached_estimate: Option<f64>,
    /// How the likelihood is estimated, in words.
    pub density: String,
    /// The fixed pairs' length fitted jointly with the goal reward, when
    /// asked for (`spec.pair_lengths`); the rest of this result is then the
    /// fit at [`PairsFit::chosen`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pairs: Option<PairsFit>,
    /// The single-trial latency SD fitted jointly with the rest, when asked
    /// for (`spec.trial_latency_sds`); the rest of this result is then the
    /// fit at [`TrialLatencyFit::chosen`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trial_latency: Option<TrialLatencyFit>,
    /// What was run.
    pub spec: GridFitSpec,
    /// How.
    pub provenance: Provenance,
}

/// Result file format written by this version.
pub const GRID_FIT_FORMAT: u32 = 1;

/// The level below which a goal reward is rejected because it makes the
/// paper's 40 reached goals (Table 1: 5/5 in every cell) improbable.
pub const REACHED_LEVEL: f64 = 0.05;

/// The density estimate, as the result file describes it.
pub const GRID_DENSITY: &str = "P(all five goals reached) (Jeffreys over the simulated groups of \
     five runs: (k + 1/2) / (n + 1)) times the normal density of ln(mean actions of the five \
     runs) fitted to the groups that reached every goal (their mean and sd, at least 0.02)";

/// The files `errp fit grid` writes (those of every fit).
pub use super::files::FIT_FILES as GRID_FIT_FILES;

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

/// One calibration of one subject on one goal set.
struct Calibration {
    subject: usize,
    goals: GoalSet,
    index: usize,
    seed: u64,
    decoder: AssessmentDecoder,
}

/// A run's outcome, as the fit keeps it.
#[derive(Debug, Clone, Copy)]
struct Run {
    reached: bool,
    actions: f64,
    total_secs: f64,
    online: f64,
}

impl From<&GridEpisodeResult> for Run {
    fn from(r: &GridEpisodeResult) -> Self {
        Self {
            reached: r.reached(),
            actions: r.actions as f64,
            total_secs: r.total_secs,
            online: r.online.mean(),
        }
    }
}

/// The outcome of [`run_grid_fit`].
#[derive(Debug)]
pub enum GridFitOutcome {
    /// Wound down (its `WindDown` was requested) (nothing written; the targetings found
    /// are in the cache).
    Interrupted,
    /// The fit, and the files written.
    Complete(Box<GridFit>, Vec<PathBuf>),
}

fn check_spec(spec: &GridFitSpec) -> Result<()> {
    let bad = |what: String| Err(SimError::Sweep(what));
    if spec.goal_rewards.len() < 2 || spec.goal_rewards.len() > super::MAX_FIT_POINTS {
        return bad(format!(
            "--goal-reward gives {} value(s): a fit needs 2 to {}",
            spec.goal_rewards.len(),
            super::MAX_FIT_POINTS
        ));
    }
    if let Some(v) = spec
        .goal_rewards
        .iter()
        .find(|v| !(v.is_finite() && **v > 0.0 && **v <= 100.0))
    {
        return bad(format!(
            "--goal-reward {v} is invalid: expected goal rewards in (0, 100]"
        ));
    }
    if spec.goal_rewards.windows(2).any(|w| w[1] <= w[0]) {
        return bad("--goal-reward must list increasing values".into());
    }
    if !(spec.epsilon.is_finite() && (0.0..1.0).contains(&spec.epsilon)) {
        return bad(format!(
            "--epsilon {} is invalid: expected a probability in [0, 1)",
            spec.epsilon
        ));
    }
    if spec.calibrations < 1 || spec.calibrations > MAX_GRID_CALIBRATIONS {
        return bad(format!(
            "--calibrations {} is invalid: expected 1 to {MAX_GRID_CALIBRATIONS} per subject \
             and goal set",
            spec.calibrations
        ));
    }
    if spec.repeats < 2 || spec.repeats > MAX_GRID_REPEATS {
        return bad(format!(
            "--repeats {} is invalid: expected 2 to {MAX_GRID_REPEATS} groups of five runs per \
             calibration",
            spec.repeats
        ));
    }
    let lengths = PairFamily::paper().lengths();
    if spec.pair_lengths.len() > MAX_PAIR_LENGTHS {
        return bad(format!(
            "--pair-length gives {} values: at most {MAX_PAIR_LENGTHS}",
            spec.pair_lengths.len()
        ));
    }
    if let Some(v) = spec.pair_lengths.iter().find(|v| !lengths.contains(*v)) {
        return bad(format!(
            "--pair-length {v} is invalid: five fixed pairs whose third keeps to the centre have a \
             total Manhattan length of {} to {}",
            lengths.start(),
            lengths.end()
        ));
    }
    if spec.pair_lengths.windows(2).any(|w| w[1] <= w[0]) {
        return bad("--pair-length must list increasing values".into());
    }
    if spec.trial_latency_sds.len() > MAX_TRIAL_LATENCY_SDS {
        return bad(format!(
            "--trial-latency-sd gives {} values: at most {MAX_TRIAL_LATENCY_SDS} (each runs the \
             whole fit)",
            spec.trial_latency_sds.len()
        ));
    }
    if let Some(v) = spec
        .trial_latency_sds
        .iter()
        .find(|v| !(v.is_finite() && (0.0..=100.0).contains(*v)))
    {
        return bad(format!(
            "--trial-latency-sd {v} is invalid: expected single-trial latency SDs in [0, 100] ms"
        ));
    }
    if spec.trial_latency_sds.windows(2).any(|w| w[1] <= w[0]) {
        return bad("--trial-latency-sd must list increasing values".into());
    }
    if spec.bootstrap < 10 || spec.bootstrap > super::MAX_BOOTSTRAP {
        return bad(format!(
            "--bootstrap {} is invalid: expected 10 to {} replicates",
            spec.bootstrap,
            super::MAX_BOOTSTRAP
        ));
    }
    Ok(())
}

/// Refuses an `out` that holds anything the fit did not write.
fn check_out(out: &Path) -> Result<()> {
    files::check_out(out, |_| false, "a grid fit's")
}

/// The scenario of one calibration: the subject's accuracy, the paper's
/// task with `params`, epochs from a bank.
fn scenario(
    accuracy: f64,
    seed: u64,
    subject: &str,
    params: GridTaskParams,
    realism: &errp_bci::Realism,
) -> errp_sim::Result<GridScenario> {
    GridScenario::builder("fit grid", DecoderChoice::Eeg, accuracy, seed)
        .name(&format!("{subject} (fit grid)"))
        .eeg(EegMode::Bank)
        .bank_per_class(GRID_FIT_BANK)
        .user(subject)
        .params(params)
        .realism(realism.clone())
        .build()
}

/// The start/goal pairs of group `repeat` of a calibration.
fn pairs(goals: GoalSet, seed: u64, repeat: usize) -> Vec<(Cell, Cell)> {
    match goals {
        GoalSet::Fixed => FIXED_PAIRS.to_vec(),
        GoalSet::Free => free_pairs(
            &Grid::paper(),
            5,
            &mut stream(derive_seed(seed, "fit/grid/free", repeat as u64), "pairs"),
        ),
    }
}

/// Calibrates every subject's decoders, runs every grid point and writes
/// [`GRID_FIT_FILES`] into `out`. The observer sees each decoder as it is
/// ready, then the episodes.
pub fn run_grid_fit(
    spec: &GridFitSpec,
    out: &Path,
    cache: &TargetCache,
    provenance: Provenance,
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

/// Every subject's decoders on either goal set, `spec.calibrations` each,
/// calibrated in parallel through the cache; `None` if cancelled.
fn calibrate_users(
    spec: &GridFitSpec,
    cache: &TargetCache,
    wind_down: &WindDown,
    observer: &dyn SweepObserver,
    base: GridTaskParams,
) -> Result<Option<Vec<Calibration>>> {
    let fixed = paper_rows(GoalSet::Fixed);
    let free = paper_rows(GoalSet::Free);
    let mut jobs = Vec::new();
    for goals in [GoalSet::Fixed, GoalSet::Free] {
        for subject in 0..fixed.len() {
            for index in 0..spec.calibrations {
                let k = (goals as usize * fixed.len() + subject) * spec.calibrations + index;
                jobs.push((
                    subject,
                    goals,
                    index,
                    derive_seed(spec.seed, "fit/grid/calibration", k as u64),
                ));
            }
        }
    }
    let done = AtomicUsize::new(0);
    let calibrations: Vec<Calibration> = jobs
        .par_iter()
        .map(|&(subject, goals, index, seed)| {
            if wind_down.requested() {
                return Ok(None);
            }
            let rows = if goals == GoalSet::Fixed {
                &fixed
            } else {
                &free
            };
            let row = &rows[subject];
            let s = scenario(row.accuracy, seed, &row.subject, base, &spec.realism)?;
            let warn = |w: &str| observer.warning(w);
            let cache = cache.reporting(&warn);
            let prepared = prepare_grid_decoder(&s, &GridShared::default(), &cache, |_| {})?;
            observer.decoder_ready(
                &prepared.info(&s),
                done.fetch_add(1, Ordering::Relaxed) + 1,
                jobs.len(),
            );
            Ok(Some(Calibration {
                subject,
                goals,
                index,
                seed,
                decoder: prepared.decoder,
            }))
        })
        .collect::<Result<Vec<Option<Calibration>>>>()?
        .into_iter()
        .collect::<Option<Vec<_>>>()
        .unwrap_or_default();
    Ok((calibrations.len() == jobs.len()).then_some(calibrations))
}

/// The fit for the users of `spec.realism`: every subject's decoders
/// calibrated, every grid point (and pair length) run and analysed; `None`
/// if cancelled.
fn fit_users(
    spec: &GridFitSpec,
    cache: &TargetCache,
    provenance: Provenance,
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

#[cfg(test)]
mod tests {
    use super::*;

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
