//! What `errp fit epuck` runs: the paper's two runs and the grid of
//! accuracies ([`EpuckFitSpec`]), its limits and its checks.

use errp_sim::{PAPER_EPUCK, Result, SimError};
use serde::Serialize;

use crate::fit::density::Observed;
use crate::fit::estimate::{MAX_BOOTSTRAP, MAX_FIT_POINTS};

/// One of the paper's e-puck runs and the shipped scenario that replays it.
#[derive(Debug, Clone, Copy)]
pub struct PaperRun {
    /// The scenario's name (as in [`PAPER_EPUCK`]).
    pub name: &'static str,
    /// Its file, relative to the repository.
    pub file: &'static str,
    /// The shipped scenario's text.
    pub scenario: &'static str,
    /// What the paper reports.
    pub observed: Observed,
}

/// The paper's two runs (sec. 5.3), in its order.
pub fn paper_runs() -> [PaperRun; 2] {
    let observed = |name: &str| {
        let (_, secs, det) = PAPER_EPUCK
            .iter()
            .find(|(n, _, _)| *n == name)
            .copied()
            .expect("both runs are in PAPER_EPUCK");
        Observed {
            time_secs: secs,
            detections: det as f64,
        }
    };
    [
        PaperRun {
            name: "Mexico to Pisa",
            file: "scenarios/mexico_to_pisa.toml",
            scenario: include_str!("../../../../scenarios/mexico_to_pisa.toml"),
            observed: observed("Mexico to Pisa"),
        },
        PaperRun {
            name: "Lisbon to Tokyo",
            file: "scenarios/lisbon_to_tokyo.toml",
            scenario: include_str!("../../../../scenarios/lisbon_to_tokyo.toml"),
            observed: observed("Lisbon to Tokyo"),
        },
    ]
}

/// What `errp fit epuck` runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpuckFitSpec {
    /// The grid of decoder accuracies (cross-validated mean accuracy on the
    /// button-locked calibration examples, `user.accuracy`).
    pub accuracies: Vec<f64>,
    /// Calibrations at each accuracy: sweep seeds `seed`, `seed + 1`, ...
    pub calibrations: usize,
    /// Runs of each scenario per calibration and accuracy.
    pub runs: usize,
    /// The first sweep seed.
    pub seed: u64,
    /// Bootstrap replicates for the Monte Carlo error.
    pub bootstrap: usize,
}

/// The most runs per grid point (the grid's size and the bootstrap's are
/// every fit's: [`MAX_FIT_POINTS`], [`MAX_BOOTSTRAP`]).
pub const MAX_FIT_RUNS: usize = 100_000;

/// The most calibrations per grid point.
pub const MAX_CALIBRATIONS: usize = 100;

pub(super) fn check_spec(spec: &EpuckFitSpec) -> Result<()> {
    let bad = |what: String| Err(SimError::Sweep(what));
    if spec.accuracies.len() < 2 || spec.accuracies.len() > MAX_FIT_POINTS {
        return bad(format!(
            "--accuracy gives {} value(s): a fit needs 2 to {MAX_FIT_POINTS}",
            spec.accuracies.len()
        ));
    }
    if spec.accuracies.windows(2).any(|w| w[1] <= w[0]) {
        return bad("--accuracy must list increasing values".into());
    }
    if spec.runs < 5 || spec.runs > MAX_FIT_RUNS {
        return bad(format!(
            "--runs {} is invalid: expected 5 to {MAX_FIT_RUNS} runs per calibration and \
             accuracy",
            spec.runs
        ));
    }
    if spec.calibrations < 1 || spec.calibrations > MAX_CALIBRATIONS {
        return bad(format!(
            "--calibrations {} is invalid: expected 1 to {MAX_CALIBRATIONS} per accuracy",
            spec.calibrations
        ));
    }
    if spec.seed.checked_add(spec.calibrations as u64).is_none() {
        return bad(format!(
            "--seed {} is invalid: the seeds of {} calibrations from it must stay below 2^64",
            spec.seed, spec.calibrations
        ));
    }
    if spec.bootstrap < 10 || spec.bootstrap > MAX_BOOTSTRAP {
        return bad(format!(
            "--bootstrap {} is invalid: expected 10 to {MAX_BOOTSTRAP} replicates",
            spec.bootstrap
        ));
    }
    Ok(())
}
