//! The grid as an environment for an agent of the user's own: the agent
//! moves the cursor, the synthetic user judges each action against the
//! goal, and the testbed's decoder turns the EEG of that judgement into
//! p(error), the agent's only feedback. What a Gymnasium environment steps.

use std::sync::Arc;

use errp_bci::{EegBlock, rng::labelled};
use errp_robot::{Cell, Grid, GridAction};
use rand::Rng;

use crate::error::{Result, SimError};
use crate::grid::decoder::AssessmentDecoder;
use crate::grid::own_eeg::own_eeg_control;
use crate::grid::params::GridTaskParams;
use crate::grid::plant::{GridDecoding, GridEpisodeResult, GridPlant};

/// What one action gave the agent.
#[derive(Debug, Clone, PartialEq)]
pub struct GridFeedback {
    /// The cursor after the action.
    pub cell: Cell,
    /// The decoder's p(error) for the user's EEG after the action.
    pub p_error: f64,
    /// The decoder's class: true if it read an error.
    pub decoded_error: bool,
    /// What the user thought: true if the action was an error (for
    /// scoring only; the agent sees only the decoder's output).
    pub error: bool,
    /// The action was "goal reached" on the user's goal.
    pub reached: bool,
    /// Seconds until the next action (the inter-action interval).
    pub interval_secs: f64,
    /// The preprocessed epoch the decoder read, `(n_channels, n_samples)`
    /// from the onset, when asked for (streamed EEG only).
    pub epoch: Option<EegBlock>,
}

/// One episode of the grid with the actions chosen from outside: the
/// `GridPlant` the episode's shared control drives, driven by an agent.
pub struct GridEnvironment {
    decoder: Arc<AssessmentDecoder>,
    plant: GridPlant,
    params: GridTaskParams,
    committed: Option<Cell>,
    ended: bool,
}

impl GridEnvironment {
    /// An episode from `start` (or a random cell) towards the user's `goal`
    /// (or a random cell), everything random from `seed`: the same seed and
    /// actions give the same feedback, and with the start and goal given,
    /// the same as the episode of that seed ([`crate::grid::run_grid_episode`]).
    pub fn new(
        decoder: Arc<AssessmentDecoder>,
        params: GridTaskParams,
        start: Option<Cell>,
        goal: Option<Cell>,
        seed: u64,
    ) -> Result<Self> {
        let grid = Grid::paper();
        let mut rng_cells = labelled(seed, "grid/env/cells");
        let mut draw = |given: Option<Cell>, name: &str| -> Result<Cell> {
            match given {
                Some(c) if grid.contains(c) => Ok(c),
                Some(c) => Err(SimError::OutOfRange {
                    name: name.to_string(),
                    given: format!(
                        "cell {c} is outside the {}x{} grid",
                        grid.width, grid.height
                    ),
                    expected: format!("x and y from 0 to {}", grid.width - 1),
                }),
                None => Ok(Cell::new(
                    rng_cells.random_range(0..grid.width),
                    rng_cells.random_range(0..grid.height),
                )),
            }
        };
        let goal = draw(goal, "goal")?;
        let start = draw(start, "start")?;
        let plant = GridPlant::new(grid, start, goal, &GridDecoding::Builtin(&decoder), seed)?;
        // A decoder calibrated on a recording knows its own accuracy.
        let params = match decoder.as_ref() {
            AssessmentDecoder::OwnEeg(bank) => GridTaskParams {
                control: own_eeg_control(&params, bank)?,
                ..params
            },
            _ => params,
        };
        Ok(Self {
            decoder,
            plant,
            params,
            committed: None,
            ended: false,
        })
    }

    /// The cursor.
    pub fn cell(&self) -> Cell {
        self.plant.cell()
    }

    /// The user's goal.
    pub fn goal(&self) -> Cell {
        self.plant.goal()
    }

    /// Actions taken so far.
    pub fn actions(&self) -> usize {
        self.plant.actions()
    }

    /// Keeps every action from now on, for [`GridEnvironment::result`].
    pub fn keep_steps(&mut self) {
        self.plant.keep_steps();
    }

    /// True once the agent said "goal reached" or committed to a goal.
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// Ends the episode on `goal`, in place of any "goal reached" before:
    /// the decision of an agent that commits to a goal of its belief, as
    /// the shared control does when its belief converges (its "goal
    /// reached" actions are actions like the others, which the user
    /// judges).
    pub fn commit(&mut self, goal: Cell) {
        self.ended = true;
        self.committed = Some(goal);
    }

    /// The episode so far as the task scores one: the cell where the agent
    /// said "goal reached" (or the goal it committed to) is the committed
    /// goal, the time is the sum of the inter-action intervals, and the
    /// steps (kept since [`GridEnvironment::keep_steps`]) hold no belief
    /// (NaN): the agent's is its own.
    pub fn result(&self) -> GridEpisodeResult {
        self.plant.result(self.committed, self.params.epoch_secs)
    }

    /// True if the decoder synthesises each action's EEG, so that epochs can
    /// be returned.
    pub fn per_action(&self) -> bool {
        matches!(*self.decoder, AssessmentDecoder::Eeg(_))
    }

    /// Takes `action`: the user judges it against the goal (an error when it
    /// does not bring the cursor closer, or says "goal reached" off the
    /// goal), the EEG of that judgement is decoded, and the cursor moves
    /// (a move against a border leaves it in place). `keep_epoch` returns
    /// the preprocessed epoch too, and needs streamed EEG.
    pub fn step(&mut self, action: GridAction, keep_epoch: bool) -> Result<GridFeedback> {
        if keep_epoch && !self.per_action() {
            return Err(SimError::Scenario(
                "observe_epoch: the epochs are only there with EEG synthesised per action (eeg = \
                 \"per_action\" and decoder = \"eeg\" in the scenario)"
                    .into(),
            ));
        }
        let goal = self.plant.goal();
        let mut judged = self.plant.act(
            &mut GridDecoding::Builtin(&self.decoder),
            action,
            &self.params,
            (false, keep_epoch),
            &[],
        )?;
        let n_cells = self.plant.grid().n_cells();
        self.plant.keep(&mut judged, || vec![f64::NAN; n_cells]);
        if action == GridAction::GoalReached && !self.ended {
            self.ended = true;
            self.committed = Some(judged.from);
        }
        Ok(GridFeedback {
            cell: judged.to,
            p_error: judged.decoded.p_error,
            decoded_error: judged.decoded.says_error,
            error: judged.error,
            reached: action == GridAction::GoalReached && judged.from == goal,
            interval_secs: judged.interval_secs,
            epoch: judged.decoded.epoch,
        })
    }
}
