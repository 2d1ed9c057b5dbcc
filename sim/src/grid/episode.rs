//! The discrete grid task end to end (sec. 4 of the paper): the synthetic user
//! judges each action, the EEG generator turns the judgement into an epoch,
//! the decoder gives p(error), the controller updates its belief and acts.

use errp_bci::{Accuracy, Components, rng::derive_seed, rng::stream};
use errp_robot::{Cell, Grid, GridAction, GridController, QTable};
use rand::Rng;

use crate::error::{Result, SimError};
use crate::grid::decoder::{AssessmentDecoder, OnlineEeg, decide};
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
    let mut rng_oracle = stream(seed, "grid/oracle");
    let mut rng_bank = stream(seed, "grid/bank/draw");
    let mut online = match decoder {
        AssessmentDecoder::Eeg(d) => Some(OnlineEeg::start(
            d.source(),
            derive_seed(seed, "grid/eeg", 0),
            Components::default(),
        )?),
        _ => None,
    };

    let mut cell = start;
    let mut visits = vec![0u32; grid.n_cells()];
    visits[grid.index(cell)] += 1;
    let mut labels = Vec::new();
    let mut decoded = Vec::new();
    let mut steps = Vec::new();
    let mut total_secs = 0.0;
    let mut committed = None;
    for _ in 0..params.max_actions {
        let action = controller.choose(cell, &mut rng_policy);
        let error = !grid.is_correct(cell, action, goal);
        let interval = rng_user.random_range(params.interval_min_secs..=params.interval_max_secs);
        let (p_error, says_error, fcz) = match (decoder, online.as_mut()) {
            (AssessmentDecoder::Oracle { accuracy }, _) => {
                let right = rng_oracle.random::<f64>() < *accuracy;
                let says_error = if right { error } else { !error };
                let p = if says_error {
                    *accuracy
                } else {
                    1.0 - accuracy
                };
                (p, says_error, Vec::new())
            }
            (AssessmentDecoder::Eeg(d), Some(eeg)) => {
                let (x, fcz) = eeg.epoch(error, interval, record_steps);
                let (p, says) = decide(d, &x);
                (p, says, fcz)
            }
            (AssessmentDecoder::Eeg(_), None) => unreachable!("EEG decoder without a stream"),
            (AssessmentDecoder::EegBank(bank), _) => {
                let pool = if error { &bank.error } else { &bank.correct };
                let (x, fcz) = &pool[rng_bank.random_range(0..pool.len())];
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
        controller.observe(cell, action, p_error)?;
        let to = grid.step(cell, action);
        labels.push(error);
        decoded.push(says_error);
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
        visits[grid.index(cell)] += 1;
        if let Some(found) = controller.converged() {
            committed = Some(found);
            break;
        }
    }
    let actions = labels.len();
    Ok(GridEpisodeResult {
        start,
        goal,
        committed,
        actions,
        net_secs: actions as f64 * params.epoch_secs,
        total_secs,
        online: Accuracy::score(&labels, &decoded),
        visits,
        steps,
    })
}
