//! What `errp fit grid` runs ([`GridFitSpec`]), its limits and its checks.

use errp_sim::grid::PairFamily;
use errp_sim::{Result, SimError};
use serde::Serialize;

use crate::fit::estimate::{MAX_BOOTSTRAP, MAX_FIT_POINTS};

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
    /// set of that length); empty: the shipped pairs ([`FIXED_PAIRS`](errp_sim::grid::FIXED_PAIRS)).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pair_lengths: Vec<usize>,
    /// The ErrP's single-trial latency SDs (ms,
    /// [`Realism::trial_latency_sd_ms`](errp_bci::Realism::trial_latency_sd_ms)),
    /// fitted jointly with the rest: the whole fit is run at each
    /// ([`TrialLatencyFit`](crate::fit::grid::TrialLatencyFit)); empty: the users' own.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub trial_latency_sds: Vec<f64>,
}

/// The largest number of pair lengths in one fit.
pub const MAX_PAIR_LENGTHS: usize = 32;

/// The largest number of single-trial latency SDs in one fit (each runs
/// the whole fit).
pub const MAX_TRIAL_LATENCY_SDS: usize = 16;

/// The largest number of calibrations per subject and goal set.
pub const MAX_GRID_CALIBRATIONS: usize = 50;

/// The largest number of groups per calibration.
pub const MAX_GRID_REPEATS: usize = 1000;

pub(super) fn check_spec(spec: &GridFitSpec) -> Result<()> {
    let bad = |what: String| Err(SimError::Sweep(what));
    if spec.goal_rewards.len() < 2 || spec.goal_rewards.len() > MAX_FIT_POINTS {
        return bad(format!(
            "--goal-reward gives {} value(s): a fit needs 2 to {}",
            spec.goal_rewards.len(),
            MAX_FIT_POINTS
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
    if spec.bootstrap < 10 || spec.bootstrap > MAX_BOOTSTRAP {
        return bad(format!(
            "--bootstrap {} is invalid: expected 10 to {} replicates",
            spec.bootstrap, MAX_BOOTSTRAP
        ));
    }
    Ok(())
}
