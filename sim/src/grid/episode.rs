//! The discrete grid task end to end (sec. 4 of the paper): the synthetic user
//! judges each action, the EEG generator turns the judgement into an epoch,
//! the decoder gives p(error), the controller updates its belief and acts.

use errp_bci::{Accuracy, Components, EegBlock, rng::derive_seed, rng::stream};
use errp_robot::{Cell, Grid, GridAction, GridController, QTable};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::error::{Result, SimError, check_p_error};
use crate::grid::decoder::{AssessmentDecoder, EegSource, OnlineEeg, decide, oracle_report};
use crate::grid::params::GridTaskParams;

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

/// What a grid episode counts as it goes, the one scoring of the episode,
/// the environment an agent steps and `errp inspect`: the cells visited
/// and, per action, the user's verdict and the decoder's.
#[derive(Debug, Clone)]
pub(crate) struct GridTally {
    start: Cell,
    visits: Vec<u32>,
    labels: Vec<bool>,
    decoded: Vec<bool>,
}

impl GridTally {
    /// An episode starting on `start` of `grid`.
    pub(crate) fn new(grid: &Grid, start: Cell) -> Self {
        let mut visits = vec![0u32; grid.n_cells()];
        visits[grid.index(start)] += 1;
        Self {
            start,
            visits,
            labels: Vec::new(),
            decoded: Vec::new(),
        }
    }

    /// An action that moved the cursor `to`, an error to the user
    /// (`error`), decoded as one (`decoded`) or not.
    pub(crate) fn action(&mut self, grid: &Grid, to: Cell, error: bool, decoded: bool) {
        self.visits[grid.index(to)] += 1;
        self.labels.push(error);
        self.decoded.push(decoded);
    }

    /// Actions so far.
    pub(crate) fn actions(&self) -> usize {
        self.labels.len()
    }

    /// The result of the episode towards `goal` that ended `committed` (or
    /// not) after `total_secs`, with `epoch_secs` of EEG per action and the
    /// `steps` kept.
    pub(crate) fn result(
        self,
        goal: Cell,
        committed: Option<Cell>,
        epoch_secs: f64,
        total_secs: f64,
        steps: Vec<GridStep>,
    ) -> GridEpisodeResult {
        let actions = self.actions();
        GridEpisodeResult {
            start: self.start,
            goal,
            committed,
            actions,
            net_secs: actions as f64 * epoch_secs,
            total_secs,
            online: Accuracy::score(&self.labels, &self.decoded),
            visits: self.visits,
            steps,
        }
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

/// [`run_grid_episode`] with any [`GridDecoding`].
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
    let mut rng_user = stream(seed, "grid/user");
    let mut rng_policy = stream(seed, "grid/policy");
    let mut decoder = ActionDecoder::start(&decoding, seed)?;

    let mut cell = start;
    let mut tally = GridTally::new(&grid, start);
    let mut steps = Vec::new();
    let mut total_secs = 0.0;
    let mut committed = None;
    for _ in 0..params.max_actions {
        let action = controller.choose(cell, &mut rng_policy);
        let error = !grid.is_correct(cell, action, goal);
        let interval = rng_user.random_range(params.interval_min_secs..=params.interval_max_secs);
        let Decoded {
            p_error,
            says_error,
            fcz,
            ..
        } = decoder.decode(&mut decoding, error, interval, record_steps, false)?;
        controller.observe(cell, action, p_error)?;
        let to = grid.step(cell, action);
        tally.action(&grid, to, error, says_error);
        if record_steps {
            steps.push(GridStep {
                onset_secs: total_secs,
                from: cell,
                action,
                to,
                error,
                p_error,
                decoded_error: says_error,
                belief: controller.belief().probabilities(),
                fcz,
            });
        }
        total_secs += interval;
        cell = to;
        if let Some(found) = controller.converged() {
            committed = Some(found);
            break;
        }
    }
    Ok(tally.result(goal, committed, params.epoch_secs, total_secs, steps))
}

/// What a decoded action gives: p(error), the decoder's class, the FCz
/// trace (when asked) and the preprocessed epoch (when asked, and the EEG
/// is streamed).
pub(crate) struct Decoded {
    pub(crate) p_error: f64,
    pub(crate) says_error: bool,
    pub(crate) fcz: Vec<f64>,
    pub(crate) epoch: Option<EegBlock>,
}

/// A [`GridDecoding`] with its EEG stream and random draws, decoding one
/// action after another.
pub(crate) struct ActionDecoder {
    online: Option<OnlineEeg>,
    rng_oracle: ChaCha8Rng,
    rng_bank: ChaCha8Rng,
}

impl ActionDecoder {
    /// Checks `decoding` and starts its EEG stream (if it streams), with
    /// every random draw from `seed`.
    pub(crate) fn start(decoding: &GridDecoding<'_>, seed: u64) -> Result<Self> {
        if let GridDecoding::Scores { error, correct } = decoding {
            if error.is_empty() || correct.is_empty() {
                return Err(SimError::Scenario(
                    "decoder: the bank needs at least one scored epoch of each class".into(),
                ));
            }
            for &p in error.iter().chain(correct.iter()) {
                check_p_error(p)?;
            }
        }
        let source = match decoding {
            GridDecoding::Builtin(AssessmentDecoder::Eeg(d)) => Some(d.source()),
            GridDecoding::Epochs { source, .. } => Some(*source),
            _ => None,
        };
        let online = match source {
            Some(source) => Some(OnlineEeg::start(
                source,
                derive_seed(seed, "grid/eeg", 0),
                Components::default(),
            )?),
            None => None,
        };
        Ok(Self {
            online,
            rng_oracle: stream(seed, "grid/oracle"),
            rng_bank: stream(seed, "grid/bank/draw"),
        })
    }

    /// Decodes with `decoding` (the one it started with) an action the
    /// user judged erroneous (`error`) or correct, streaming `interval` s of
    /// EEG when the EEG is streamed.
    pub(crate) fn decode(
        &mut self,
        decoding: &mut GridDecoding<'_>,
        error: bool,
        interval: f64,
        record_steps: bool,
        keep_epoch: bool,
    ) -> Result<Decoded> {
        let mut epoch = None;
        let (p_error, says_error, fcz) = match (decoding, self.online.as_mut()) {
            (GridDecoding::Builtin(AssessmentDecoder::Oracle { accuracy }), _) => {
                let (p, says_error) = oracle_report(*accuracy, error, &mut self.rng_oracle);
                (p, says_error, Vec::new())
            }
            (GridDecoding::Builtin(AssessmentDecoder::Eeg(d)), Some(eeg)) if keep_epoch => {
                let (block, fcz) = eeg.epoch_block(error, interval);
                let (p, says) = decide(d, &eeg.features(&block));
                epoch = Some(block);
                (p, says, if record_steps { fcz } else { Vec::new() })
            }
            (GridDecoding::Builtin(AssessmentDecoder::Eeg(d)), Some(eeg)) => {
                let (x, fcz) = eeg.epoch(error, interval, record_steps);
                let (p, says) = decide(d, &x);
                (p, says, fcz)
            }
            (GridDecoding::Epochs { decode, .. }, Some(eeg)) => {
                let (block, fcz) = eeg.epoch_block(error, interval);
                let p = check_p_error(decode(&block)?)?;
                if keep_epoch {
                    epoch = Some(block);
                }
                (p, p >= 0.5, if record_steps { fcz } else { Vec::new() })
            }
            (
                GridDecoding::Builtin(AssessmentDecoder::Eeg(_)) | GridDecoding::Epochs { .. },
                None,
            ) => {
                unreachable!("EEG decoder without a stream")
            }
            (
                GridDecoding::Scores {
                    error: e,
                    correct: c,
                },
                _,
            ) => {
                let pool = if error { e } else { c };
                let p = pool[self.rng_bank.random_range(0..pool.len())];
                (p, p >= 0.5, Vec::new())
            }
            (GridDecoding::Builtin(AssessmentDecoder::EegBank(bank)), _) => {
                let pool = if error { &bank.error } else { &bank.correct };
                let (x, fcz) = &pool[self.rng_bank.random_range(0..pool.len())];
                let (p, says) = decide(&bank.decoder, x);
                (
                    p,
                    says,
                    if record_steps {
                        fcz.clone()
                    } else {
                        Vec::new()
                    },
                )
            }
        };
        Ok(Decoded {
            p_error,
            says_error,
            fcz,
            epoch,
        })
    }
}
