//! Unstated parameters estimated from the paper's own numbers by maximum
//! likelihood over a grid, with Monte Carlo likelihoods (`errp fit`).

mod density;
mod epuck;
mod estimate;
mod files;
mod grid;
mod report;
mod surface;

pub use density::{Observed, SimRun, log_kde, log_likelihood, percentile_of, quantile, resample};
pub use epuck::{
    DENSITY, EpuckFit, EpuckFitSpec, FIT_FORMAT, FitOutcome, HeldOut, MAX_CALIBRATIONS,
    MAX_FIT_RUNS, PaperRun, RunStats, analyse, fit_plot, paper_runs, run_dir, run_epuck_fit,
    surface_csv, sweep_dir,
};
pub use estimate::{FitEstimate, FitProvenance, MAX_BOOTSTRAP, MAX_FIT_POINTS};
pub use files::FIT_FILES;
pub use grid::{
    CellStats, GRID_DENSITY, GRID_FIT_BANK, GRID_FIT_FORMAT, GridFit, GridFitOutcome, GridFitSpec,
    MAX_GRID_CALIBRATIONS, MAX_GRID_REPEATS, MAX_PAIR_LENGTHS, MAX_TRIAL_LATENCY_SDS, PairsFit,
    PaperRow, REACHED_LEVEL, TableStats, TrialLatencyFit, grid_fit_plot, grid_surface_csv,
    group_log_likelihood, log_normal_density, paper_rows, run_grid_fit,
};
pub use report::{EpuckFitReport, GridFitReport};
pub use surface::{CHI2_1_95, Surface, argmax};
