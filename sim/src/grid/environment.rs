//! The grid as an environment for an agent of the user's own: the agent
//! moves the cursor, the synthetic user judges each action against the
//! goal, and the testbed's decoder turns the EEG of that judgement into
//! p(error), the agent's only feedback. What a Gymnasium environment steps.

use std::sync::Arc;

use errp_bci::{EegBlock, rng::stream};
use errp_robot::{Cell, Grid, GridAction};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::error::{Result, SimError};
use crate::grid::decoder::AssessmentDecoder;
use crate::grid::episode::{
    ActionDecoder, Decoded, GridDecoding, GridEpisodeResult, GridStep, GridTally,
};
use crate::grid::params::GridTaskParams;

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

/// One episode of the grid with the actions chosen from outside.
pub struct GridEnvironment {
    decoder: Arc<AssessmentDecoder>,
    actions_decoder: ActionDecoder,
    params: GridTaskParams,
    grid: Grid,
    cell: Cell,
    goal: Cell,
    rng_user: ChaCha8Rng,
    tally: GridTally,
    total_secs: f64,
    committed: Option<Cell>,
    ended: bool,
    /// Every action, kept for a recording ([`GridEnvironment::keep_steps`]).
    steps: Option<Vec<GridStep>>,
}

impl GridEnvironment {
    /// An episode from `start` (or a random cell) towards the user's `goal`
    /// (or a random cell), everything random from `seed`: the same seed and
    /// actions give the same feedback.
    pub fn new(
        decoder: Arc<AssessmentDecoder>,
        params: GridTaskParams,
        start: Option<Cell>,
        goal: Option<Cell>,
        seed: u64,
    ) -> Result<Self> {
        let grid = Grid::paper();
        let mut rng_cells = stream(seed, "grid/env/cells");
        let mut draw = |given: Option<Cell>, name: &str| -> Result<Cell> {
            match given {
                Some(c) if grid.contains(c) => Ok(c),
                Some(c) => Err(SimError::Scenario(format!(
                    "{name}: cell {c} is outside the {}x{} grid, expected x and y from 0 to {}",
                    grid.width,
                    grid.height,
                    grid.width - 1
                ))),
                None => Ok(Cell::new(
                    rng_cells.random_range(0..grid.width),
                    rng_cells.random_range(0..grid.height),
                )),
            }
        };
        let goal = draw(goal, "goal")?;
        let start = draw(start, "start")?;
        let actions_decoder = ActionDecoder::start(&GridDecoding::Builtin(&decoder), seed)?;
        Ok(Self {
            decoder,
            actions_decoder,
            params,
            grid,
            cell: start,
            goal,
            rng_user: stream(seed, "grid/user"),
            tally: GridTally::new(&grid, start),
            total_secs: 0.0,
            committed: None,
            ended: false,
            steps: None,
        })
    }

    /// The cursor.
    pub fn cell(&self) -> Cell {
        self.cell
    }

    /// The user's goal.
    pub fn goal(&self) -> Cell {
        self.goal
    }

    /// Actions taken so far.
    pub fn actions(&self) -> usize {
        self.tally.actions()
    }

    /// Keeps every action from now on, for [`GridEnvironment::result`].
    pub fn keep_steps(&mut self) {
        self.steps.get_or_insert_with(Vec::new);
    }

    /// True once the agent said "goal reached".
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// The episode so far as the task scores one: the cell where the agent
    /// said "goal reached" is the committed goal, the time is the sum of
    /// the inter-action intervals, and the steps (kept since
    /// [`GridEnvironment::keep_steps`]) hold no belief (NaN): the agent's
    /// is its own.
    pub fn result(&self) -> GridEpisodeResult {
        let steps = self.steps.clone().unwrap_or_default();
        self.tally.clone().result(
            self.goal,
            self.committed,
            self.params.epoch_secs,
            self.total_secs,
            steps,
        )
    }

    /// True if the decoder streams EEG, so that epochs can be returned.
    pub fn streams(&self) -> bool {
        matches!(*self.decoder, AssessmentDecoder::Eeg(_))
    }

    /// Takes `action`: the user judges it against the goal (an error when it
    /// does not bring the cursor closer, or says "goal reached" off the
    /// goal), the EEG of that judgement is decoded, and the cursor moves
    /// (a move against a border leaves it in place). `keep_epoch` returns
    /// the preprocessed epoch too, and needs streamed EEG.
    pub fn step(&mut self, action: GridAction, keep_epoch: bool) -> Result<GridFeedback> {
        if keep_epoch && !self.streams() {
            return Err(SimError::Scenario(
                "observe_epoch: the epochs are only there with streamed EEG (eeg = \"stream\" \
                 and decoder = \"eeg\" in the scenario)"
                    .into(),
            ));
        }
        let error = !self.grid.is_correct(self.cell, action, self.goal);
        let interval = self
            .rng_user
            .random_range(self.params.interval_min_secs..=self.params.interval_max_secs);
        let Decoded {
            p_error,
            says_error,
            epoch,
            ..
        } = self.actions_decoder.decode(
            &mut GridDecoding::Builtin(&self.decoder),
            error,
            interval,
            false,
            keep_epoch,
        )?;
        let reached = action == GridAction::GoalReached && self.cell == self.goal;
        let from = self.cell;
        self.cell = self.grid.step(self.cell, action);
        self.tally.action(&self.grid, self.cell, error, says_error);
        if let Some(steps) = self.steps.as_mut() {
            steps.push(GridStep {
                onset_secs: self.total_secs,
                from,
                action,
                to: self.cell,
                error,
                p_error,
                decoded_error: says_error,
                belief: vec![f64::NAN; self.grid.n_cells()],
                fcz: Vec::new(),
            });
        }
        self.total_secs += interval;
        if action == GridAction::GoalReached && !self.ended {
            self.ended = true;
            self.committed = Some(from);
        }
        Ok(GridFeedback {
            cell: self.cell,
            p_error,
            decoded_error: says_error,
            error,
            reached,
            interval_secs: interval,
            epoch,
        })
    }
}
