//! The discrete grid task end to end (sec. 4 of the paper): the synthetic user
//! judges each action, the EEG generator turns the judgement into an epoch,
//! the decoder gives p(error), the controller updates its belief and acts.

use errp_bci::{Accuracy, EegBlock, rng::stream};
use errp_robot::{Cell, Grid, GridAction, GridController, QTable};

use crate::error::{Result, SimError};
use crate::grid::decoder::{AssessmentDecoder, EegSource};
use crate::grid::params::GridTaskParams;
use crate::grid::plant::GridPlant;

/// One action of an episode, as recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct GridStep {
    /// Time of the action onset (s since the episode started).
    pub onset_secs: f64,
    /// Cursor before the action.
    pub from: Cell,
    /// The action.
    pub action: GridAction,
    /// Cursor after it.
    pub to: Cell,
    /// The user's assessment: true if it was an error.
    pub error: bool,
    /// The decoder's p(error).
    pub p_error: f64,
    /// The decoder's class: its decision value y >= 0 (sec. 2.2.1).
    pub decoded_error: bool,
    /// The belief over the goals after the update (cell index order).
    pub belief: Vec<f64>,
    /// Preprocessed FCz during the epoch (uV, 256 Hz), EEG decoder only.
    pub fcz: Vec<f64>,
}

/// The outcome of one episode (the metrics of Table 1 and Fig. 4).
#[derive(Debug, Clone, PartialEq)]
pub struct GridEpisodeResult {
    /// Start cell.
    pub start: Cell,
    /// The user's goal.
    pub goal: Cell,
    /// The goal the belief converged to, if it did.
    pub committed: Option<Cell>,
    /// Number of actions.
    pub actions: usize,
    /// EEG seconds decoded (epoch_secs per action).
    pub net_secs: f64,
    /// Wall time of the episode: the inter-action intervals.
    pub total_secs: f64,
    /// The decoder's accuracy over this episode's actions (its class
    /// decision y >= 0 against the user's assessment).
    pub online: Accuracy,
    /// How often the cursor was in each cell (index order), start included.
    pub visits: Vec<u32>,
    /// Every action, when asked for.
    pub steps: Vec<GridStep>,
}

impl GridEpisodeResult {
    /// True if the device committed to the user's goal.
    pub fn reached(&self) -> bool {
        self.committed == Some(self.goal)
    }
}

/// Runs one episode from `start` towards the user's `goal`. Everything random
/// derives from `seed`: the same seed gives the same episode, bit for bit.
pub fn run_grid_episode(
    start: Cell,
    goal: Cell,
    table: &QTable,
    params: &GridTaskParams,
    decoder: &AssessmentDecoder,
    seed: u64,
    record_steps: bool,
) -> Result<GridEpisodeResult> {
    run_grid_episode_with(
        start,
        goal,
        table,
        params,
        GridDecoding::Builtin(decoder),
        seed,
        record_steps,
    )
}

/// A decoder of the user's own: what it is given of each action's EEG and
/// gives back as p(error).
pub type EpochDecoder<'a> = &'a mut (dyn FnMut(&EegBlock) -> Result<f64> + Send);

/// What decodes each action of an episode.
pub enum GridDecoding<'a> {
    /// One of the testbed's decoders.
    Builtin(&'a AssessmentDecoder),
    /// A decoder of the user's own, given each action's preprocessed epoch,
    /// `(n_channels, n_samples)` from the onset, streamed from `source` as
    /// [`AssessmentDecoder::Eeg`] streams it; its p(error) must be in [0,
    /// 1], and p >= 0.5 is its class "error".
    Epochs {
        /// The user's EEG model and the calibrated preprocessing.
        source: EegSource<'a>,
        /// The decoder.
        decode: EpochDecoder<'a>,
    },
    /// p(error) that a decoder of the user's own gave to a bank of epochs
    /// of each class ([`EpochBlocks`](crate::grid::EpochBlocks)), drawn at
    /// random for each action as [`AssessmentDecoder::EegBank`] draws its
    /// epochs; p >= 0.5 is the class "error".
    Scores {
        /// p(error) of the error epochs.
        error: &'a [f64],
        /// p(error) of the correct epochs.
        correct: &'a [f64],
    },
}

impl GridDecoding<'_> {
    /// The same decoding, borrowed again (for the next episode).
    pub fn reborrow(&mut self) -> GridDecoding<'_> {
        match self {
            GridDecoding::Builtin(d) => GridDecoding::Builtin(d),
            GridDecoding::Epochs { source, decode } => GridDecoding::Epochs {
                source: *source,
                decode: &mut **decode,
            },
            GridDecoding::Scores { error, correct } => GridDecoding::Scores { error, correct },
        }
    }
}

/// [`run_grid_episode`] with any [`GridDecoding`]: the shared control
/// drives a [`GridPlant`] until its belief converges or the actions run out.
pub fn run_grid_episode_with(
    start: Cell,
    goal: Cell,
    table: &QTable,
    params: &GridTaskParams,
    mut decoding: GridDecoding<'_>,
    seed: u64,
    record_steps: bool,
) -> Result<GridEpisodeResult> {
    let grid: Grid = *table.grid();
    for (name, cell) in [("start", start), ("goal", goal)] {
        if !grid.contains(cell) {
            return Err(SimError::Scenario(format!(
                "{name} {cell} is outside the {}x{} grid",
                grid.width, grid.height
            )));
        }
    }
    let mut controller = GridController::with_table(table.clone(), params.control);
    let mut rng_policy = stream(seed, "grid/policy");
    let mut plant = GridPlant::new(grid, start, goal, &decoding, seed)?;
    if record_steps {
        plant.keep_steps();
    }
    let mut committed = None;
    for _ in 0..params.max_actions {
        let action = controller.choose(plant.cell(), &mut rng_policy);
        let mut judged = plant.act(&mut decoding, action, params, record_steps, false)?;
        controller.observe(judged.from, action, judged.decoded.p_error)?;
        plant.keep(&mut judged, || controller.belief().probabilities());
        if let Some(found) = controller.converged() {
            committed = Some(found);
            break;
        }
    }
    Ok(plant.into_result(committed, params.epoch_secs))
}
