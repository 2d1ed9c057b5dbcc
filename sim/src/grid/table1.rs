//! Table 1 of the paper, re-run: the four subjects at their accuracies, on
//! the fixed and the free goals.

use errp_bci::{ActionInformation, GoalSet, TargetingStep, rng::derive_seed, subjects};
use errp_robot::{Cell, Grid, GridControlParams, QTable};
use rayon::prelude::*;

use crate::error::Result;
use crate::grid::decoder::INFORMATION_PER_CLASS;
use crate::grid::episode::run_grid_episode;
use crate::grid::params::GridTaskParams;
use crate::grid::plant::GridEpisodeResult;
use crate::grid::run::prepare_decoder;
use crate::grid::scenario::{DecoderChoice, EegMode, GridScenario, free_pairs};
use crate::stats::mean_sd;
use crate::stats::pearson;

/// The five fixed start/goal pairs (`scenarios/grid_fixed_goals.toml`): a
/// set of the total length `errp fit grid` estimates from Table 1 (8), as
/// the fit draws it (`fits/grid.json`, `pairs.example`).
pub const FIXED_PAIRS: [(Cell, Cell); 5] = [
    (Cell::new(3, 0), Cell::new(3, 2)),
    (Cell::new(2, 1), Cell::new(2, 0)),
    (Cell::new(3, 2), Cell::new(1, 2)),
    (Cell::new(1, 2), Cell::new(0, 2)),
    (Cell::new(2, 2), Cell::new(3, 3)),
];

/// The fixed pairs chosen before they were fitted, to resemble Fig. 4:
/// corner to corner, across the middle row and column, a diagonal through
/// the centre (total length 28;
/// `scenarios/variants/grid_fixed_goals_corners.toml`). Long runs, for
/// tests and benchmarks of the decoder in the loop.
pub const CORNER_PAIRS: [(Cell, Cell); 5] = [
    (Cell::new(0, 0), Cell::new(4, 4)),
    (Cell::new(4, 0), Cell::new(0, 4)),
    (Cell::new(0, 2), Cell::new(4, 2)),
    (Cell::new(2, 0), Cell::new(2, 4)),
    (Cell::new(1, 3), Cell::new(3, 1)),
];

/// One cell of the table: a subject on a goal set.
#[derive(Debug, Clone)]
pub struct Table1Cell {
    /// S1..S4.
    pub subject: String,
    /// Fixed or free goals.
    pub goals: GoalSet,
    /// The accuracy the decoder was calibrated to.
    pub accuracy: f64,
    /// Every run.
    pub runs: Vec<GridEpisodeResult>,
    /// The EEG decoder's calibration, as (cross-validated accuracy on the
    /// calibration session, accuracy on held-out closed-loop epochs, which
    /// the targeting hits): `None` for the oracle.
    pub calibration: Option<(f64, f64)>,
    /// What one action's p(error) tells of the user's verdict, measured on
    /// [`INFORMATION_PER_CLASS`] fresh closed-loop actions of each class.
    pub information: ActionInformation,
}

impl Table1Cell {
    /// (mean, sd) of a per-run quantity over the runs where it is defined
    /// (a run's mean accuracy is not when it took no action of a class).
    pub fn stat(&self, f: impl Fn(&GridEpisodeResult) -> f64) -> (f64, f64) {
        mean_sd(
            &self
                .runs
                .iter()
                .map(f)
                .filter(|v| v.is_finite())
                .collect::<Vec<_>>(),
        )
    }
}

/// Options of a Table 1 run.
#[derive(Debug, Clone)]
pub struct Table1Options {
    /// Runs per start/goal pair (the paper: 1, so 5 runs per cell).
    pub repeats: usize,
    /// Base seed.
    pub seed: u64,
    /// EEG (default) or oracle decoder.
    pub decoder: DecoderChoice,
    /// Streamed (default) or banked EEG.
    pub eeg: EegMode,
    /// Strategy and timing.
    pub params: GridTaskParams,
    /// The simulated users (the same effects for every subject; each
    /// subject's calibration is targeted at its Table 1 accuracy online).
    pub realism: errp_bci::Realism,
}

/// Runs the eight cells (in parallel; the results do not depend on the
/// number of threads: every cell and run has its own derived seed).
pub fn run_table1(
    options: &Table1Options,
    progress: impl Fn(&str, &TargetingStep) + Sync,
) -> Result<Vec<Table1Cell>> {
    let grid = Grid::paper();
    let table = QTable::compute(grid, &options.params.control.part(GridControlParams::q))?;
    let jobs: Vec<(String, GoalSet, f64, usize)> = subjects()
        .into_iter()
        .enumerate()
        .flat_map(|(i, s)| {
            [
                (
                    s.name.clone(),
                    GoalSet::Fixed,
                    s.accuracy(GoalSet::Fixed),
                    2 * i,
                ),
                (
                    s.name.clone(),
                    GoalSet::Free,
                    s.accuracy(GoalSet::Free),
                    2 * i + 1,
                ),
            ]
        })
        .collect();
    jobs.par_iter()
        .map(|(name, goals, accuracy, k)| {
            let cell_seed = derive_seed(options.seed, "table1/cell", *k as u64);
            let pairs: Vec<(Cell, Cell)> = match goals {
                GoalSet::Fixed => FIXED_PAIRS.to_vec(),
                GoalSet::Free => free_pairs(
                    &grid,
                    5,
                    &mut errp_bci::rng::labelled(cell_seed, "table1/free-goals"),
                ),
            };
            let scenario = GridScenario::builder("table1", options.decoder, *accuracy, cell_seed)
                .name(&format!("{name} {goals:?}"))
                .eeg(options.eeg)
                .user(name)
                .params(options.params)
                .realism(options.realism.clone())
                .build()?;
            let label = format!(
                "{name} {}",
                if *goals == GoalSet::Fixed {
                    "fixed"
                } else {
                    "free"
                }
            );
            let (decoder, report) = prepare_decoder(&scenario, |s| progress(&label, s))?;
            let information = decoder.information(
                &options.params,
                INFORMATION_PER_CLASS,
                derive_seed(cell_seed, "table1/information", 0),
            )?;
            let mut runs = Vec::new();
            for r in 0..options.repeats {
                for (j, &(start, goal)) in pairs.iter().enumerate() {
                    let seed = derive_seed(cell_seed, "table1/run", (r * pairs.len() + j) as u64);
                    runs.push(run_grid_episode(
                        start,
                        goal,
                        &table,
                        &options.params,
                        &decoder,
                        seed,
                        false,
                    )?);
                }
            }
            Ok(Table1Cell {
                subject: name.clone(),
                goals: *goals,
                accuracy: *accuracy,
                runs,
                calibration: report
                    .map(|r| (r.calibrated.accuracy.mean(), r.targeting.accuracy.mean())),
                information,
            })
        })
        .collect()
}

/// Pearson r and p between each run's online mean accuracy and its total
/// time, over every run of a goal set that has a mean accuracy (the paper:
/// r = -0.47, p = 0.038 fixed; r = -0.79, p = 3e-5 free).
pub fn accuracy_time_correlation(cells: &[Table1Cell], goals: GoalSet) -> (f64, f64) {
    // A run with no action of a class has no mean accuracy: left out.
    let runs: Vec<&GridEpisodeResult> = cells
        .iter()
        .filter(|c| c.goals == goals)
        .flat_map(|c| c.runs.iter())
        .filter(|r| r.online.mean().is_finite())
        .collect();
    let acc: Vec<f64> = runs.iter().map(|r| r.online.mean()).collect();
    let time: Vec<f64> = runs.iter().map(|r| r.total_secs).collect();
    pearson(&acc, &time)
}
