//! `errp fit epuck`: the continuous decoder's operating point estimated from
//! the paper's two e-puck runs (sec. 5.3: Mexico to Pisa in 60 s with 11
//! detected errors, Lisbon to Tokyo in 121 s with 26, both reaching the
//! goal).
//!
//! For every accuracy of the grid, each of the two shipped city scenarios is
//! swept ([`run_sweep`], so the runs are resumable, their rows checked and
//! their targeting cached); every run gives (time, detections, reached).
//! A decoder calibrated to one cross-validated accuracy can do better or
//! worse online (140 examples leave room), so each accuracy is run with
//! several calibrations, one sweep seed each, and the likelihood is that of
//! the pooled runs: the likelihood of a simulated user whose decoder has
//! that accuracy, whichever decoder the calibration gave. The likelihood
//! of each paper run at that accuracy is the Monte Carlo estimate of
//! [`log_likelihood`]; their sum is maximised over the grid ([`Surface`]).
//! Both scenarios use the same seeds, so each calibration drives both, as
//! the paper's two runs were driven by one subject's decoder.

mod analysis;
mod output;
mod result;
mod run;
mod spec;

pub use analysis::analyse;
pub use output::{fit_plot, surface_csv};
pub use result::{DENSITY, EpuckFit, FIT_FORMAT, HeldOut, RunStats};
pub use run::{FitOutcome, run_dir, run_epuck_fit, sweep_dir};
pub use spec::{EpuckFitSpec, MAX_CALIBRATIONS, MAX_FIT_RUNS, PaperRun, paper_runs};
