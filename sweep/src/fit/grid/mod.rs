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

mod analysis;
mod calibrate;
mod episodes;
mod likelihood;
mod output;
mod pairs;
mod paper;
mod result;
mod run;
mod spec;
mod trial_latency;

pub use calibrate::GRID_FIT_BANK;
pub use likelihood::{group_log_likelihood, log_normal_density};
pub use output::{grid_fit_plot, grid_surface_csv};
pub use paper::{PaperRow, paper_rows};
pub use result::{
    CellStats, GRID_DENSITY, GRID_FIT_FORMAT, GridFit, PairsFit, REACHED_LEVEL, TableStats,
    TrialLatencyFit,
};
pub use run::{GridFitOutcome, run_grid_fit};
pub use spec::{
    GridFitSpec, MAX_GRID_CALIBRATIONS, MAX_GRID_REPEATS, MAX_PAIR_LENGTHS, MAX_TRIAL_LATENCY_SDS,
};
