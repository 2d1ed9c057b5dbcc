//! What every fit's result holds: the estimate on its grid with its
//! intervals, how the result was made, and the limits every fit checks.

use serde::Serialize;

use super::surface::Surface;

/// The largest grid of a fit.
pub const MAX_FIT_POINTS: usize = 200;
/// The most bootstrap replicates of a fit.
pub const MAX_BOOTSTRAP: usize = 10_000;

/// A fit's estimate of one scenario field: the maximum-likelihood grid
/// point and its intervals (written first in the result file).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitEstimate {
    /// The scenario field fitted.
    pub parameter: String,
    /// The maximum-likelihood value (a grid point).
    #[serde(rename = "estimate")]
    pub value: f64,
    /// Its 95 % likelihood-ratio interval.
    pub interval_95: (f64, f64),
    /// Whether that interval reaches the grid's ends.
    pub interval_at_edge: (bool, bool),
    /// The 5-95 % spread of the estimate over bootstrap replicates of the
    /// simulated runs (Monte Carlo error only).
    pub mc_interval_90: (f64, f64),
}

impl FitEstimate {
    /// The estimate of `parameter` that `surface` gives.
    pub fn of(parameter: &str, surface: &Surface) -> Self {
        Self {
            parameter: parameter.into(),
            value: surface.estimate_value(),
            interval_95: surface.interval,
            interval_at_edge: surface.interval_at_edge,
            mc_interval_90: surface.mc_interval,
        }
    }
}

/// How the fit was made, for its result file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitProvenance {
    /// The command line.
    pub command: String,
    /// The `errp` version.
    pub errp_version: String,
    /// The source commit the program was built from ("unknown" outside a
    /// git checkout).
    pub commit: String,
}
