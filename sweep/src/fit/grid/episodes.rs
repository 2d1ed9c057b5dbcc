//! The fit's episodes (every calibration's groups of five runs at every
//! goal reward) and their analysis: the statistics of each cell and table
//! against Table 1, and the likelihood surface.

use std::sync::atomic::{AtomicUsize, Ordering};

use errp_bci::GoalSet;
use errp_bci::rng::{derive_seed, labelled};
use errp_bci::stop::WindDown;
use errp_robot::{Cell, Grid, GridControlParams, QTable};
use errp_sim::grid::{
    FIXED_PAIRS, GridEpisodeResult, GridTaskParams, PairFamily, free_pairs, run_grid_episode,
};
use errp_sim::{Result, SimError};
use rayon::prelude::*;

use super::calibrate::Calibration;
use super::spec::GridFitSpec;
use crate::observer::SweepObserver;

/// `runs[point][calibration][repeat][pair]`.
pub(super) type PointRuns = Vec<Vec<Vec<Vec<Run>>>>;

/// The episodes of a fit: every calibration's groups of five runs at every
/// goal reward.
pub(super) struct Episodes<'a> {
    pub(super) spec: &'a GridFitSpec,
    pub(super) calibrations: &'a [Calibration],
    pub(super) base: GridTaskParams,
    pub(super) family: &'a PairFamily,
    pub(super) wind_down: &'a WindDown,
    pub(super) observer: &'a dyn SweepObserver,
    pub(super) done: AtomicUsize,
    pub(super) total: usize,
}

impl Episodes<'_> {
    /// `runs[point][calibration][repeat][pair]` of the calibrations of
    /// `goals` (all if none; the others' lists are empty), the fixed pairs
    /// drawn from the family at `length` if given (one set per group, the
    /// same at every goal reward); `None` if cancelled.
    pub(super) fn run(
        &self,
        goals: Option<GoalSet>,
        length: Option<usize>,
    ) -> Result<Option<PointRuns>> {
        let spec = self.spec;
        let mut runs = Vec::with_capacity(spec.goal_rewards.len());
        for &g in &spec.goal_rewards {
            let mut params = self.base;
            params.control = self.base.control.with(|c| {
                c.goal_reward = g;
                c.epsilon = spec.epsilon;
            })?;
            let table = QTable::compute(Grid::paper(), &params.control.part(GridControlParams::q))?;
            let at_point: Vec<Vec<Vec<Run>>> = self
                .calibrations
                .par_iter()
                .map(|c| {
                    if goals.is_some_and(|goals| goals != c.goals) {
                        return Ok(Vec::new());
                    }
                    (0..spec.repeats)
                        .map(|r| self.group(c, r, length, &table, &params))
                        .collect::<Result<Vec<_>>>()
                })
                .collect::<Result<Vec<_>>>()
                .or_else(|e| {
                    if self.wind_down.requested() {
                        Ok(Vec::new())
                    } else {
                        Err(e)
                    }
                })?;
            if at_point.len() != self.calibrations.len() {
                return Ok(None);
            }
            runs.push(at_point);
        }
        Ok(Some(runs))
    }

    /// Group `r` of calibration `c`: five runs, one per pair.
    pub(super) fn group(
        &self,
        c: &Calibration,
        r: usize,
        length: Option<usize>,
        table: &QTable,
        params: &GridTaskParams,
    ) -> Result<Vec<Run>> {
        if self.wind_down.requested() {
            return Err(SimError::Sweep("interrupted".into()));
        }
        let group_pairs = match (c.goals, length) {
            (GoalSet::Fixed, Some(length)) => {
                let mut rng = labelled(derive_seed(c.seed, "fit/grid/pairs", r as u64), "pairs");
                self.family.draw(length, &mut rng).ok_or_else(|| {
                    SimError::Sweep(format!("no fixed pair set has total length {length}"))
                })?
            }
            _ => pairs(c.goals, c.seed, r),
        };
        let group = group_pairs
            .into_iter()
            .enumerate()
            .map(|(j, (start, goal))| {
                let seed = derive_seed(c.seed, "fit/grid/run", (r * 5 + j) as u64);
                run_grid_episode(start, goal, table, params, &c.decoder, seed, false)
                    .map(|e| Run::from(&e))
            })
            .collect::<Result<Vec<Run>>>()?;
        let n = self.done.fetch_add(5, Ordering::Relaxed) + 5;
        self.observer.episodes_done(n, self.total);
        Ok(group)
    }
}

/// A run's outcome, as the fit keeps it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Run {
    pub(super) reached: bool,
    pub(super) actions: f64,
    pub(super) total_secs: f64,
    pub(super) online: f64,
}

impl From<&GridEpisodeResult> for Run {
    fn from(r: &GridEpisodeResult) -> Self {
        Self {
            reached: r.reached(),
            actions: r.actions as f64,
            total_secs: r.total_secs,
            online: r.online.mean(),
        }
    }
}

/// The start/goal pairs of group `repeat` of a calibration.
pub(super) fn pairs(goals: GoalSet, seed: u64, repeat: usize) -> Vec<(Cell, Cell)> {
    match goals {
        GoalSet::Fixed => FIXED_PAIRS.to_vec(),
        GoalSet::Free => free_pairs(
            &Grid::paper(),
            5,
            &mut labelled(derive_seed(seed, "fit/grid/free", repeat as u64), "pairs"),
        ),
    }
}
