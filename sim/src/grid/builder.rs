//! Grid scenarios made in code ([`GridScenario::builder`]): Table 1's
//! cells, a fit's users, a decoder for benches, checked as a file's values
//! are.

use errp_bci::{Realism, RequestedAccuracy};

use crate::error::Result;
use crate::grid::p_error::PErrorChoice;
use crate::grid::params::GridTaskParams;
use crate::grid::scenario::{
    DEFAULT_BANK_PER_CLASS, DecoderChoice, EegMode, GridAccuracy, GridScenario, MAX_BANK_PER_CLASS,
    MAX_EPISODES, assumed_control,
};
use crate::rules::{self, Origin};
use crate::scenario_file::{field_error, whole};
use crate::task_kind::TaskKind;
use errp_robot::Cell;

/// A grid scenario made in code, field by field, and checked once by
/// [`GridScenarioBuilder::build`] as a file's values are (Table 1's cells,
/// a fit's users, a decoder for benches).
#[derive(Debug, Clone)]
pub struct GridScenarioBuilder {
    scenario: GridScenario,
    accuracy: f64,
}

impl GridScenario {
    /// A scenario at `path` (a label in errors and its name, until
    /// [`GridScenarioBuilder::name`]) whose `decoder` has the mean
    /// `accuracy`, run from `seed`; everything else as a file that sets
    /// nothing has it
    /// (streamed EEG, Platt-scaled p(error), 1000 epochs per class, the
    /// paper's strategy and timing, the ideal user), with no episodes.
    pub fn builder(
        path: &str,
        decoder: DecoderChoice,
        accuracy: f64,
        seed: u64,
    ) -> GridScenarioBuilder {
        GridScenarioBuilder {
            scenario: Self {
                path: path.into(),
                name: path.to_string(),
                description: String::new(),
                seed,
                decoder,
                p_error: PErrorChoice::Platt,
                eeg: EegMode::PerAction,
                bank_per_class: DEFAULT_BANK_PER_CLASS,
                // Set by `build`, once checked.
                accuracy: GridAccuracy::Requested(RequestedAccuracy::Perfect),
                user: format!("accuracy {accuracy}"),
                episodes: Vec::new(),
                params: GridTaskParams::default(),
                realism: Realism::default(),
            },
            accuracy,
        }
    }
}

impl GridScenarioBuilder {
    /// The display name.
    pub fn name(mut self, name: &str) -> Self {
        self.scenario.name = name.to_string();
        self
    }

    /// Streamed or banked EEG.
    pub fn eeg(mut self, eeg: EegMode) -> Self {
        self.scenario.eeg = eeg;
        self
    }

    /// Epochs per class in the bank.
    pub fn bank_per_class(mut self, n: usize) -> Self {
        self.scenario.bank_per_class = n;
        self
    }

    /// Strategy and timing.
    pub fn params(mut self, params: GridTaskParams) -> Self {
        self.scenario.params = params;
        self
    }

    /// The simulated user's distance from the ideal one.
    pub fn realism(mut self, realism: Realism) -> Self {
        self.scenario.realism = realism;
        self
    }

    /// Who the accuracy comes from, in words.
    pub fn user(mut self, user: &str) -> Self {
        self.scenario.user = user.to_string();
        self
    }

    /// The (start, goal) of every episode, in order.
    pub fn episodes(mut self, episodes: Vec<(Cell, Cell)>) -> Self {
        self.scenario.episodes = episodes;
        self
    }

    /// The scenario, checked as a file's values are (the accuracy against
    /// the decoder, the bank's size, the number of episodes; the error
    /// names the scenario and the field) and with what a file's loader
    /// derives (the accuracy the control assumes).
    pub fn build(self) -> Result<GridScenario> {
        let Self {
            mut scenario,
            accuracy,
        } = self;
        let path = scenario.path.clone();
        let bad =
            |field: &str, value: String, expected: &str| field_error(&path, field, value, expected);
        let oracle = scenario.decoder == DecoderChoice::Oracle;
        scenario.accuracy = GridAccuracy::Requested(rules::accuracy_for(
            TaskKind::Grid,
            oracle,
            accuracy,
            Origin::Scenario(&path),
        )?);
        // What the loader derives from the accuracy, derived the same way.
        scenario.params.control =
            assumed_control(*scenario.params.control.get(), &scenario.accuracy, &path)?;
        whole(
            &path,
            "bank_per_class",
            scenario.bank_per_class as f64,
            1,
            MAX_BANK_PER_CLASS,
            &format!(" (default {DEFAULT_BANK_PER_CLASS})"),
        )?;
        if scenario.episodes.len() > MAX_EPISODES {
            return Err(bad(
                "episodes",
                scenario.episodes.len().to_string(),
                &format!("at most {MAX_EPISODES}"),
            ));
        }
        Ok(scenario)
    }
}
