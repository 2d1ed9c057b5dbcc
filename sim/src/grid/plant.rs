//! The grid's one closed loop below the decision maker: the user judges
//! an action against the goal, waits the inter-action interval, the EEG of
//! that judgement is decoded, the cursor moves and the action is scored.
//! The episode ([`crate::grid::run_grid_episode_with`], the shared control
//! choosing) and the environment ([`crate::grid::GridEnvironment`], an
//! agent choosing) both drive a [`GridPlant`], so that an environment
//! driven by the shared control is the episode, bit for bit
//! (`sim/tests/it/grid_identity.rs`).

use errp_bci::{Accuracy, Components, EegBlock, rng::derive_seed, rng::labelled};
use errp_robot::{Cell, Grid, GridAction};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::error::{Result, SimError, check_p_error};
use crate::grid::decoder::{AssessmentDecoder, EegSource, OnlineEeg, decide, oracle_report};
use crate::grid::own_eeg::OwnEegDraw;
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

/// A decoder of the user's own: what it is given of each action's EEG and
/// gives back as p(error).
pub type EpochDecoder<'a> = &'a mut (dyn FnMut(&EegBlock) -> Result<f64> + Send);

/// An action of a live episode, as the live decoder is told of it before
/// it decides: the device's action, the user's verdict (for the EEG the
/// live loop streams; never for the decision) and the belief before it.
#[derive(Debug, Clone, Copy)]
pub struct LiveAction<'b> {
    /// The cursor before the action.
    pub from: Cell,
    /// The action.
    pub action: GridAction,
    /// The cursor after it.
    pub to: Cell,
    /// The user's verdict: true if it is an error to them.
    pub error: bool,
    /// The interval to the next action (s, simulated time).
    pub interval_secs: f64,
    /// The belief over the goals before the action (cell index order).
    pub belief: &'b [f64],
}

/// A live decoder: streams the action's EEG in real time and returns the
/// p(error) a decoder outside sent back for it in time, or none (a missed
/// decision: the belief is not updated).
pub type LiveDecoder<'a> = &'a mut (dyn FnMut(&LiveAction<'_>) -> Result<Option<f64>> + Send);

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
    /// A decoder outside the process, in real time (`errp stream`): the
    /// EEG is its to stream, and a decision it misses leaves the belief as
    /// it was.
    Live(LiveDecoder<'a>),
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
            GridDecoding::Live(decide) => GridDecoding::Live(&mut **decide),
        }
    }
}

/// The seed of episode `k` of a grid scenario with base seed `seed`.
pub fn grid_episode_seed(seed: u64, k: usize) -> u64 {
    derive_seed(seed, "grid/episode", k as u64)
}

/// One episode's world: the cursor, the user's goal and clock, the decoder
/// of the user's EEG, and the tally that scores the episode.
pub(crate) struct GridPlant {
    grid: Grid,
    cell: Cell,
    goal: Cell,
    rng_user: ChaCha8Rng,
    decoder: ActionDecoder,
    tally: GridTally,
    total_secs: f64,
    /// Every action, when kept.
    steps: Option<Vec<GridStep>>,
}

/// One action as the plant took it.
pub(crate) struct Judged {
    /// The cursor before the action.
    pub(crate) from: Cell,
    /// The action.
    pub(crate) action: GridAction,
    /// The cursor after it.
    pub(crate) to: Cell,
    /// The user's verdict: true if the action was an error.
    pub(crate) error: bool,
    /// The action's onset (s since the episode started).
    pub(crate) onset_secs: f64,
    /// The inter-action interval that followed it (s).
    pub(crate) interval_secs: f64,
    /// What the decoder made of the user's EEG.
    pub(crate) decoded: Decoded,
}

impl GridPlant {
    /// An episode on `grid` from `start` towards the user's `goal` (both on
    /// the grid: the callers check them), decoded by `decoding`, every
    /// random draw from `seed`.
    pub(crate) fn new(
        grid: Grid,
        start: Cell,
        goal: Cell,
        decoding: &GridDecoding<'_>,
        seed: u64,
    ) -> Result<Self> {
        Ok(Self {
            grid,
            cell: start,
            goal,
            rng_user: labelled(seed, "grid/user"),
            decoder: ActionDecoder::start(decoding, seed)?,
            tally: GridTally::new(&grid, start),
            total_secs: 0.0,
            steps: None,
        })
    }

    /// The grid.
    pub(crate) fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The cursor.
    pub(crate) fn cell(&self) -> Cell {
        self.cell
    }

    /// The user's goal.
    pub(crate) fn goal(&self) -> Cell {
        self.goal
    }

    /// Actions so far.
    pub(crate) fn actions(&self) -> usize {
        self.tally.actions()
    }

    /// Keeps every action from now on (see [`GridPlant::keep`]).
    pub(crate) fn keep_steps(&mut self) {
        self.steps.get_or_insert_with(Vec::new);
    }

    /// Takes `action`: the user judges it against the goal (an error when
    /// it does not bring the cursor closer, or says "goal reached" off the
    /// goal), the interval to the next action is drawn, the EEG of the
    /// judgement is decoded with `decoding` (the one the plant started
    /// with; `keep_fcz` returns the FCz trace, `keep_epoch` the
    /// preprocessed epoch; a live decoder is told `belief`, the belief
    /// before the action), the cursor moves (a move against a border
    /// leaves it in place) and the action is scored.
    pub(crate) fn act(
        &mut self,
        decoding: &mut GridDecoding<'_>,
        action: GridAction,
        params: &GridTaskParams,
        keep: (bool, bool),
        belief: &[f64],
    ) -> Result<Judged> {
        let (keep_fcz, keep_epoch) = keep;
        let from = self.cell;
        let error = !self.grid.is_correct(from, action, self.goal);
        let interval_secs = self
            .rng_user
            .random_range(params.interval_min_secs..=params.interval_max_secs);
        let to = self.grid.step(from, action);
        let decoded = match decoding {
            GridDecoding::Live(decide) => {
                let p = decide(&LiveAction {
                    from,
                    action,
                    to,
                    error,
                    interval_secs,
                    belief,
                })?;
                Decoded::live(p)?
            }
            _ => self
                .decoder
                .decode(decoding, error, interval_secs, keep_fcz, keep_epoch)?,
        };
        self.cell = to;
        self.tally.action(
            &self.grid,
            to,
            error,
            (!decoded.missed()).then_some(decoded.says_error),
        );
        let onset_secs = self.total_secs;
        self.total_secs += interval_secs;
        Ok(Judged {
            from,
            action,
            to,
            error,
            onset_secs,
            interval_secs,
            decoded,
        })
    }

    /// Keeps `judged` (the last action) with the decision maker's
    /// `belief` over the goals after it, when steps are kept; its FCz
    /// trace moves into the step.
    pub(crate) fn keep(&mut self, judged: &mut Judged, belief: impl FnOnce() -> Vec<f64>) {
        if let Some(steps) = self.steps.as_mut() {
            steps.push(GridStep {
                onset_secs: judged.onset_secs,
                from: judged.from,
                action: judged.action,
                to: judged.to,
                error: judged.error,
                p_error: judged.decoded.p_error,
                decoded_error: judged.decoded.says_error,
                belief: belief(),
                fcz: std::mem::take(&mut judged.decoded.fcz),
            });
        }
    }

    /// The episode so far as the task scores one, ended `committed` (or
    /// not), with `epoch_secs` of EEG per action.
    pub(crate) fn result(&self, committed: Option<Cell>, epoch_secs: f64) -> GridEpisodeResult {
        self.tally.clone().result(
            self.goal,
            committed,
            epoch_secs,
            self.total_secs,
            self.steps.clone().unwrap_or_default(),
        )
    }

    /// [`GridPlant::result`], the plant spent.
    pub(crate) fn into_result(self, committed: Option<Cell>, epoch_secs: f64) -> GridEpisodeResult {
        self.tally.result(
            self.goal,
            committed,
            epoch_secs,
            self.total_secs,
            self.steps.unwrap_or_default(),
        )
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
    /// Actions whose decision was missed (a live decoder's): not scored.
    missed: usize,
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
            missed: 0,
        }
    }

    /// An action that moved the cursor `to`, an error to the user
    /// (`error`), decoded as one (`decoded`), not, or not decoded in time
    /// (none: not scored).
    pub(crate) fn action(&mut self, grid: &Grid, to: Cell, error: bool, decoded: Option<bool>) {
        self.visits[grid.index(to)] += 1;
        match decoded {
            Some(d) => {
                self.labels.push(error);
                self.decoded.push(d);
            }
            None => self.missed += 1,
        }
    }

    /// Actions so far.
    pub(crate) fn actions(&self) -> usize {
        self.labels.len() + self.missed
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

/// What a decoded action gives: p(error), the decoder's class, the FCz
/// trace (when asked) and the preprocessed epoch (when asked, and the EEG
/// is streamed); a live decision missed has no p(error) (not a number).
pub(crate) struct Decoded {
    pub(crate) p_error: f64,
    pub(crate) says_error: bool,
    pub(crate) fcz: Vec<f64>,
    pub(crate) epoch: Option<EegBlock>,
}

impl Decoded {
    /// A live decision that did not come in time (no p(error)).
    pub(crate) fn missed(&self) -> bool {
        self.p_error.is_nan()
    }

    /// A live decoder's decision: p(error), or none when it missed.
    fn live(p: Option<f64>) -> Result<Self> {
        let p = p.map(check_p_error).transpose()?;
        Ok(Self {
            p_error: p.unwrap_or(f64::NAN),
            says_error: p.is_some_and(|p| p >= 0.5),
            fcz: Vec::new(),
            epoch: None,
        })
    }
}

/// A [`GridDecoding`] with its EEG stream and random draws, decoding one
/// action after another.
pub(crate) struct ActionDecoder {
    online: Option<OnlineEeg>,
    rng_oracle: ChaCha8Rng,
    rng_bank: ChaCha8Rng,
    recorded: OwnEegDraw,
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
            rng_oracle: labelled(seed, "grid/oracle"),
            rng_bank: labelled(seed, "grid/bank/draw"),
            recorded: OwnEegDraw::new(),
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
            (GridDecoding::Builtin(AssessmentDecoder::OwnEeg(bank)), _) => {
                let epoch = self.recorded.draw(bank, error, &mut self.rng_bank);
                let (p, says) = bank.decide(&epoch.features);
                let fcz = if record_steps {
                    epoch.fcz.clone()
                } else {
                    Vec::new()
                };
                (p, says, fcz)
            }
            (GridDecoding::Live(_), _) => {
                return Err(SimError::Scenario(
                    "a live decoder decides in the plant's action, not here".into(),
                ));
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
