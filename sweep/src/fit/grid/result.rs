//! The result of `errp fit grid`: the estimate, the statistics of every
//! cell and table against Table 1, and the joint fits over the fixed pairs'
//! length and the single-trial latency SD.

use errp_robot::Cell;
use serde::Serialize;

use super::paper::PaperRow;
use super::spec::GridFitSpec;
use crate::fit::estimate::{FitEstimate, FitProvenance};
use crate::fit::surface::Surface;

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
    /// The goal reward (`control.goal_reward`) fitted: the
    /// maximum-likelihood grid point and its intervals.
    #[serde(flatten)]
    pub estimate: FitEstimate,
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
    pub provenance: FitProvenance,
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

/// The fixed pairs' total Manhattan length, profiled over the goal reward.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairsFit {
    /// The candidate lengths.
    pub lengths: Vec<usize>,
    /// Per length: the fixed rows' log-likelihood maximised over the goal
    /// reward (the profile likelihood of the length).
    pub profile: Vec<f64>,
    /// Per length: the goal reward at that maximum.
    pub goal_reward: Vec<f64>,
    /// Per length: P(all 40 of the paper's goals reached) there.
    pub p_all_reached: Vec<f64>,
    /// Per length: the largest-likelihood goal reward among those that keep
    /// the paper's 40/40 (P >= [`REACHED_LEVEL`](REACHED_LEVEL)), and its log-likelihood.
    pub reached: Vec<Option<(f64, f64)>>,
    /// `fixed_actions[length][subject][goal reward]`: the mean actions of
    /// the fixed-goal runs.
    pub fixed_actions: Vec<Vec<Vec<f64>>>,
    /// `fixed_z[length][subject]`: the fixed rows' z at the length's
    /// maximum-likelihood goal reward.
    pub fixed_z: Vec<Vec<f64>>,
    /// `free_z[length][subject]`: the held-out free rows' z there.
    pub free_z: Vec<Vec<f64>>,
    /// The maximum-likelihood length.
    pub estimate: usize,
    /// Its 95 % likelihood-ratio interval (the profile within 1.92 of its
    /// maximum).
    pub interval_95: (usize, usize),
    /// The largest-likelihood (length, goal reward) that keeps the paper's
    /// 40/40; none if no point does.
    pub reached_estimate: Option<(usize, f64)>,
    /// The length the rest of the result is fitted at: the 40/40 estimate's,
    /// or the maximum-likelihood one if none keeps 40/40.
    pub chosen: usize,
    /// One set of the chosen length, drawn from the family with the fit's
    /// seed: a pair set that a scenario can take.
    pub example: Vec<(Cell, Cell)>,
}

/// The single-trial latency SD, profiled over everything else the fit
/// estimates (the goal reward, and the fixed pairs' length when fitted).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrialLatencyFit {
    /// The candidate SDs (ms).
    pub sds: Vec<f64>,
    /// Per SD: the fixed rows' log-likelihood maximised over the rest (the
    /// profile likelihood of the SD).
    pub profile: Vec<f64>,
    /// Per SD: the largest log-likelihood among the points that keep the
    /// paper's 40/40 (P >= [`REACHED_LEVEL`](REACHED_LEVEL)); none
    /// if no point does.
    pub reached: Vec<Option<f64>>,
    /// Per SD: the pairs' length (none if not fitted) and the goal reward
    /// of the fit at that SD (its 40/40 point, or its maximum if none).
    pub point: Vec<(Option<usize>, f64)>,
    /// Per SD: P(all 40 of the paper's goals reached) there.
    pub p_all_reached: Vec<f64>,
    /// `fixed_z[sd][subject]`: the fixed rows' z there.
    pub fixed_z: Vec<Vec<f64>>,
    /// `free_z[sd][subject]`: the held-out free rows' z there.
    pub free_z: Vec<Vec<f64>>,
    /// The maximum-likelihood SD.
    pub estimate: f64,
    /// Its 95 % likelihood-ratio interval among the candidates (the
    /// profile within 1.92 of its maximum).
    pub interval_95: (f64, f64),
    /// The SD the rest of the result is fitted at: the one with the
    /// largest 40/40 log-likelihood, or the maximum-likelihood one if no SD
    /// keeps the paper's 40/40.
    pub chosen: f64,
}
