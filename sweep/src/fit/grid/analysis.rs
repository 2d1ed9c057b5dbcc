//! The fit's episodes analysed: the statistics of each cell and table
//! against Table 1, the likelihood surface and its bootstrap.

use errp_bci::GoalSet;
use errp_bci::rng::{derive_seed, labelled};
use errp_sim::{mean_sd, pearson};

use super::calibrate::Calibration;
use super::episodes::Run;
use super::likelihood::group_log_likelihood;
use super::paper::PaperRow;
use super::result::{CellStats, GRID_DENSITY, GRID_FIT_FORMAT, GridFit, REACHED_LEVEL, TableStats};
use super::spec::GridFitSpec;
use crate::fit::density::{SimRun, percentile_of, quantile, resample};
use crate::fit::estimate::{FitEstimate, FitProvenance};
use crate::fit::surface::{Surface, argmax};

/// The groups of one subject on one goal set at a grid point, as
/// [`SimRun`]s (time = mean actions, reached = every goal reached).
pub(super) fn groups_of(
    calibrations: &[Calibration],
    at_point: &[Vec<Vec<Run>>],
    subject: usize,
    goals: GoalSet,
) -> Vec<SimRun> {
    calibrations
        .iter()
        .zip(at_point)
        .filter(|(c, _)| c.subject == subject && c.goals == goals)
        .flat_map(|(c, groups)| {
            groups.iter().map(move |g| SimRun {
                time_secs: g.iter().map(|r| r.actions).sum::<f64>() / g.len() as f64,
                detections: 0.0,
                reached: g.iter().all(|r| r.reached),
                calibration: c.index,
            })
        })
        .collect()
}

/// The statistics of one subject on one goal set at a grid point; `groups`
/// are its [`groups_of`].
pub(super) fn cell_stats(
    calibrations: &[Calibration],
    at_point: &[Vec<Vec<Run>>],
    subject: usize,
    row: &PaperRow,
    goals: GoalSet,
    groups: &[SimRun],
) -> CellStats {
    let all: Vec<Run> = calibrations
        .iter()
        .zip(at_point)
        .filter(|(c, _)| c.subject == subject && c.goals == goals)
        .flat_map(|(_, groups)| groups.iter().flatten().copied())
        .collect();
    let means: Vec<f64> = groups
        .iter()
        .filter(|g| g.reached)
        .map(|g| g.time_secs)
        .collect();
    let actions = mean_sd(&all.iter().map(|r| r.actions).collect::<Vec<_>>());
    let online: Vec<f64> = all
        .iter()
        .map(|r| r.online)
        .filter(|v| v.is_finite())
        .collect();
    let se = (row.actions_sd.powi(2) / 5.0 + actions.1.powi(2) / all.len() as f64).sqrt();
    CellStats {
        runs: all.len(),
        reached: all.iter().filter(|r| r.reached).count(),
        groups: (groups.len(), means.len()),
        actions,
        group_mean: [
            quantile(&means, 0.5),
            quantile(&means, 0.1),
            quantile(&means, 0.9),
        ],
        percentile: percentile_of(&means, row.actions_mean),
        z: (actions.0 - row.actions_mean) / se,
        online_accuracy: mean_sd(&online).0,
    }
}

pub(super) fn table_stats(
    calibrations: &[Calibration],
    at_point: &[Vec<Vec<Run>>],
    goals: GoalSet,
    subjects: usize,
    spec: &GridFitSpec,
) -> TableStats {
    let mut rs = Vec::new();
    let mut all_reached = 0;
    for index in 0..spec.calibrations {
        for repeat in 0..spec.repeats {
            let runs: Vec<Run> = (0..subjects)
                .flat_map(|s| {
                    let k = calibrations
                        .iter()
                        .position(|c| c.subject == s && c.goals == goals && c.index == index)
                        .expect("every calibration was run");
                    at_point[k][repeat].clone()
                })
                .collect();
            all_reached += usize::from(runs.iter().all(|r| r.reached));
            let ok: Vec<&Run> = runs.iter().filter(|r| r.online.is_finite()).collect();
            let acc: Vec<f64> = ok.iter().map(|r| r.online).collect();
            let time: Vec<f64> = ok.iter().map(|r| r.total_secs).collect();
            rs.push(pearson(&acc, &time).0);
        }
    }
    let finite: Vec<f64> = rs.iter().copied().filter(|r| r.is_finite()).collect();
    TableStats {
        tables: rs.len(),
        all_reached,
        r_negative: finite.iter().filter(|&&r| r < 0.0).count(),
        median_r: quantile(&finite, 0.5),
    }
}

/// Each subject's log-likelihood at each point, for `spec.bootstrap`
/// resamplings of its groups: the Monte Carlo spread of the estimate.
fn bootstrap(
    spec: &GridFitSpec,
    fixed_groups: &[Vec<Vec<SimRun>>],
    fixed: &[PaperRow],
) -> Vec<Vec<Vec<f64>>> {
    fixed_groups
        .iter()
        .zip(fixed)
        .enumerate()
        .map(|(i, (per_point, row))| {
            per_point
                .iter()
                .enumerate()
                .map(|(j, g)| {
                    let mut rng = labelled(
                        derive_seed(spec.seed, "fit/grid/bootstrap", (i * 1000 + j) as u64),
                        "fit/bootstrap",
                    );
                    (0..spec.bootstrap)
                        .map(|_| group_log_likelihood(&resample(g, &mut rng), row.actions_mean))
                        .collect()
                })
                .collect()
        })
        .collect()
}

pub(super) fn analyse(
    spec: &GridFitSpec,
    calibrations: &[Calibration],
    runs: &[Vec<Vec<Vec<Run>>>],
    fixed: &[PaperRow],
    free: &[PaperRow],
    provenance: FitProvenance,
) -> GridFit {
    let n = fixed.len();
    let groups = |goals: GoalSet| -> Vec<Vec<Vec<SimRun>>> {
        (0..n)
            .map(|s| {
                runs.iter()
                    .map(|at| groups_of(calibrations, at, s, goals))
                    .collect()
            })
            .collect()
    };
    let fixed_groups = groups(GoalSet::Fixed);
    let free_groups = groups(GoalSet::Free);
    let log_lik: Vec<Vec<f64>> = fixed_groups
        .iter()
        .zip(fixed)
        .map(|(per_point, row)| {
            per_point
                .iter()
                .map(|g| group_log_likelihood(g, row.actions_mean))
                .collect()
        })
        .collect();
    let replicates = bootstrap(spec, &fixed_groups, fixed);
    let own_estimates = log_lik
        .iter()
        .map(|l| spec.goal_rewards[argmax(l)])
        .collect();
    let free_log_lik = (0..spec.goal_rewards.len())
        .map(|j| {
            free_groups
                .iter()
                .zip(free)
                .map(|(per_point, row)| group_log_likelihood(&per_point[j], row.actions_mean))
                .sum()
        })
        .collect();
    let surface = Surface::new(spec.goal_rewards.clone(), log_lik, &replicates);
    let stats = |rows: &[PaperRow], goals: GoalSet, groups: &[Vec<Vec<SimRun>>]| {
        rows.iter()
            .enumerate()
            .map(|(s, row)| {
                runs.iter()
                    .zip(&groups[s])
                    .map(|(at, g)| cell_stats(calibrations, at, s, row, goals, g))
                    .collect()
            })
            .collect::<Vec<Vec<CellStats>>>()
    };
    let tables = |goals: GoalSet| -> Vec<TableStats> {
        runs.iter()
            .map(|at| table_stats(calibrations, at, goals, n, spec))
            .collect()
    };
    let fixed_tables = tables(GoalSet::Fixed);
    let free_tables = tables(GoalSet::Free);
    let jeffreys = |t: &TableStats| (t.all_reached as f64 + 0.5) / (t.tables as f64 + 1.0);
    let p_all_reached: Vec<f64> = fixed_tables
        .iter()
        .zip(&free_tables)
        .map(|(a, b)| jeffreys(a) * jeffreys(b))
        .collect();
    let reached_estimate = (0..p_all_reached.len())
        .filter(|&j| p_all_reached[j] >= REACHED_LEVEL)
        .max_by(|&a, &b| surface.total[a].total_cmp(&surface.total[b]))
        .map(|j| spec.goal_rewards[j]);
    GridFit {
        format: GRID_FIT_FORMAT,
        estimate: FitEstimate::of("control.goal_reward", &surface),
        fixed_stats: stats(fixed, GoalSet::Fixed, &fixed_groups),
        free_stats: stats(free, GoalSet::Free, &free_groups),
        fixed_tables,
        free_tables,
        p_all_reached,
        reached_estimate,
        fixed: fixed.to_vec(),
        free: free.to_vec(),
        surface,
        own_estimates,
        free_log_lik,
        density: GRID_DENSITY.into(),
        pairs: None,
        trial_latency: None,
        spec: spec.clone(),
        provenance,
    }
}
