//! The discrete grid task end to end (sec. 4 of the paper): the synthetic user
//! judges each action, the EEG generator turns the judgement into an epoch,
//! the decoder gives p(error), the controller updates its belief and acts.

use errp_bci::{
    Accuracy, Assessment, AssessmentKind, EegGenerator, EpochWindow, ErrorModel, GeneratorParams,
    LdaModel, Montage, PlattScaling, Preprocessor, rng::derive_seed, rng::stream,
};
use errp_robot::{Cell, Grid, GridAction, GridControlParams, GridController, QTable};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SimError};

/// Timing and limits of a grid episode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GridTaskParams {
    /// The device's strategy (tau, epsilon, p_c, reward model).
    pub control: GridControlParams,
    /// Shortest inter-action interval (s); the paper: 3.
    pub interval_min_secs: f64,
    /// Longest inter-action interval (s); the paper: 3.5.
    pub interval_max_secs: f64,
    /// EEG decoded per action, for the net time (s); the paper: 0.8.
    pub epoch_secs: f64,
    /// An episode that has not converged after this many actions fails.
    pub max_actions: usize,
}

impl Default for GridTaskParams {
    fn default() -> Self {
        Self {
            control: GridControlParams::default(),
            interval_min_secs: 3.0,
            interval_max_secs: 3.5,
            epoch_secs: 0.8,
            max_actions: 300,
        }
    }
}

/// What turns the user's assessment into p(error).
#[derive(Debug, Clone)]
pub enum AssessmentDecoder {
    /// No EEG: the assessment is reported flipped with probability
    /// 1 - accuracy, as p(error) = accuracy (decoded error) or 1 - accuracy
    /// (decoded correct), the calibrated output of such a decoder.
    Oracle {
        /// Probability of reporting the assessment right.
        accuracy: f64,
    },
    /// Synthetic EEG through the real preprocessing and decoder, as trained
    /// on a calibration session.
    Eeg(Box<EegDecoder>),
}

/// The calibrated EEG pipeline used online.
#[derive(Debug, Clone)]
pub struct EegDecoder {
    /// The synthetic user's EEG model (at the calibrated ErrP-to-noise ratio).
    pub generator: GeneratorParams,
    /// The montage.
    pub montage: Montage,
    /// Preprocessing fitted on the calibration session's EOG recording.
    pub preprocessor: Preprocessor,
    /// The decoder trained on the calibration session.
    pub model: LdaModel,
    /// How decision values become p(error).
    pub p_error: PErrorMapping,
}

/// How the decoder's decision value y becomes p(error).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PErrorMapping {
    /// The paper's p = 1 / (1 + e^-y) (sec. 2.2.1).
    Sigmoid,
    /// Platt scaling fitted on the calibration session's out-of-fold
    /// decisions: p = 1 / (1 + e^-(a y + b)).
    Platt(PlattScaling),
}

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

/// Seconds of EEG streamed before the first action so that filters settle.
const WARM_UP_SECS: f64 = 2.0;

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
    let mut online = OnlineEeg::new(decoder, seed)?;

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
            (AssessmentDecoder::Eeg(_), Some(eeg)) => eeg.decode(error, interval, record_steps),
            (AssessmentDecoder::Eeg(_), None) => unreachable!("EEG decoder without a stream"),
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

/// The EEG stream of one episode.
struct OnlineEeg<'a> {
    generator: EegGenerator,
    preprocessor: Preprocessor,
    model: &'a LdaModel,
    mapping: PErrorMapping,
    window: EpochWindow,
    fcz_row: usize,
}

impl<'a> OnlineEeg<'a> {
    fn new(decoder: &'a AssessmentDecoder, seed: u64) -> Result<Option<Self>> {
        let AssessmentDecoder::Eeg(d) = decoder else {
            return Ok(None);
        };
        let fs = d.generator.sfreq_hz;
        let mut generator = EegGenerator::new(
            d.generator.clone(),
            &d.montage,
            derive_seed(seed, "grid/eeg", 0),
        )?;
        let mut preprocessor = d.preprocessor.clone();
        preprocessor.reset();
        preprocessor.process(&generator.generate((WARM_UP_SECS * fs) as usize));
        let fcz = d.montage.index("FCz")?;
        let fcz_row = preprocessor
            .outputs()
            .iter()
            .position(|&o| o == fcz)
            .unwrap_or(0);
        Ok(Some(Self {
            generator,
            preprocessor,
            model: &d.model,
            mapping: d.p_error,
            window: EpochWindow::paper(fs),
            fcz_row,
        }))
    }

    /// Streams the EEG from this action's onset to the next one (the whole
    /// inter-action interval, so filters see continuous EEG) and decodes the
    /// epoch at the onset. Returns p(error), the decoded class and FCz.
    fn decode(&mut self, error: bool, interval_secs: f64, keep_fcz: bool) -> (f64, bool, Vec<f64>) {
        let fs = self.generator.params().sfreq_hz;
        let onset = self.generator.now_secs();
        self.generator.schedule(Assessment {
            onset_secs: onset,
            kind: if error {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            },
        });
        let n = ((interval_secs * fs).round() as usize).max(self.window.span());
        let raw = self.generator.generate(n);
        let clean = self.preprocessor.process(&raw);
        let y = self.model.decision(&self.window.extract(&clean, 0));
        let p = match self.mapping {
            PErrorMapping::Sigmoid => errp_bci::sigmoid(y),
            PErrorMapping::Platt(s) => s.p_error(y),
        };
        let fcz = if keep_fcz {
            clean.channel(self.fcz_row)[..self.window.span()].to_vec()
        } else {
            Vec::new()
        };
        (p, y >= 0.0, fcz)
    }
}
