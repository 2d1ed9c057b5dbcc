//! The result of `errp fit epuck`: the estimate, each paper run's
//! statistics at every accuracy, and each run held out in turn.

use serde::Serialize;

use super::spec::EpuckFitSpec;
use crate::fit::density::{Observed, SimRun, percentile_of, quantile};
use crate::fit::estimate::{FitEstimate, FitProvenance};
use crate::fit::surface::Surface;

/// One paper run at one accuracy.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunStats {
    /// Runs.
    pub runs: usize,
    /// Runs that converged on the goal.
    pub reached: usize,
    /// Median, 10 % and 90 % quantiles of the time of the runs that reached
    /// the goal (s).
    pub time_secs: [f64; 3],
    /// The same for the detections.
    pub detections: [f64; 3],
    /// Where the paper's time lies among those runs' times (0 to 1,
    /// mid-rank).
    pub time_percentile: f64,
    /// Where the paper's detections lie among theirs.
    pub detections_percentile: f64,
}

impl RunStats {
    pub(super) fn of(runs: &[SimRun], obs: &Observed) -> Self {
        let ok: Vec<&SimRun> = runs.iter().filter(|r| r.reached).collect();
        let t: Vec<f64> = ok.iter().map(|r| r.time_secs).collect();
        let d: Vec<f64> = ok.iter().map(|r| r.detections).collect();
        let q = |v: &[f64]| [quantile(v, 0.5), quantile(v, 0.1), quantile(v, 0.9)];
        Self {
            runs: runs.len(),
            reached: ok.len(),
            time_secs: q(&t),
            detections: q(&d),
            time_percentile: percentile_of(&t, obs.time_secs),
            detections_percentile: percentile_of(&d, obs.detections),
        }
    }

    /// Share of the runs that reached the goal.
    pub fn p_reached(&self) -> f64 {
        self.reached as f64 / self.runs.max(1) as f64
    }
}

/// The held-out check of one paper run: the fit to the other run alone, and
/// where this one lies under it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeldOut {
    /// The run left out.
    pub name: String,
    /// The accuracy fitted without it.
    pub fitted_without: f64,
    /// Its statistics at that accuracy.
    pub stats: RunStats,
}

/// The result of `errp fit epuck`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpuckFit {
    /// Result file format.
    pub format: u32,
    /// The accuracy (`user.accuracy`) fitted: the maximum-likelihood grid
    /// point and its intervals.
    #[serde(flatten)]
    pub estimate: FitEstimate,
    /// The paper's runs, in order: name, scenario file, observed time and
    /// detections.
    pub observations: Vec<(String, String, f64, f64)>,
    /// `stats[observation][grid point]`.
    pub stats: Vec<Vec<RunStats>>,
    /// The likelihood surface.
    pub surface: Surface,
    /// Each run held out in turn.
    pub held_out: Vec<HeldOut>,
    /// How the likelihood is estimated, in words.
    pub density: String,
    /// What was run.
    pub spec: EpuckFitSpec,
    /// How.
    pub provenance: FitProvenance,
}

/// Result file format written by this version.
pub const FIT_FORMAT: u32 = 1;

/// The density estimate, as the result file describes it.
pub const DENSITY: &str = "P(reached) (Jeffreys: (k + 1/2) / (n + 1)) times a Gaussian product \
     kernel density of (ln time, detections) over the runs that reached the goal, Scott's \
     bandwidth per dimension (sd n^(-1/6); at least 0.02 and 0.5)";
