//! One scenario input for every front end: a scenario file or a built-in
//! scenario, and the values a command line or a Python call sets in it
//! (the accuracy, the seed, the runs, the grid's decoder and EEG mode, any
//! dotted key). [`ScenarioInput::load`] reads it once, sets the values as
//! the file's own keys, validates the result and keeps the text as run, for
//! recordings that say how they were made.

use std::path::{Path, PathBuf};

use errp_bci::RequestedAccuracy;

use crate::error::{Result, SimError};
use crate::grid::{DecoderChoice, EegMode};
use crate::names::Names;
use crate::rules::{self, Claim, Origin, OwnEegFrom, TaskValue};
use crate::scenario::{AnyScenario, apply_overrides, parse_scenario, parse_scenario_table};
use crate::scenario_file::{parse_toml, read_scenario};
use crate::task_kind::TaskKind;

/// The built-in grid scenario (`scenarios/grid_fixed_goals.toml`): what a
/// Python call or a sweep runs without a scenario file.
pub const BUILT_IN_GRID: &str = include_str!("../../scenarios/grid_fixed_goals.toml");
/// The built-in e-puck scenario (`scenarios/mexico_to_pisa.toml`).
pub const BUILT_IN_EPUCK: &str = include_str!("../../scenarios/mexico_to_pisa.toml");

/// Where a scenario comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ScenarioSource {
    /// A TOML file.
    File(PathBuf),
    /// Built-in text, named in errors by the path it has in the repository.
    BuiltIn {
        /// The TOML text.
        text: &'static str,
        /// Its path in the repository.
        name: &'static str,
    },
    /// Text held in memory (a sweep's scenario, a recording's), named in
    /// errors by `name`.
    Text {
        /// The TOML text.
        text: String,
        /// What names it.
        name: PathBuf,
    },
}

impl ScenarioSource {
    /// The built-in scenario of `task` ([`BUILT_IN_GRID`],
    /// [`BUILT_IN_EPUCK`]), named by its path in the repository.
    pub fn built_in(task: TaskKind) -> Self {
        ScenarioSource::BuiltIn {
            text: match task {
                TaskKind::Grid => BUILT_IN_GRID,
                TaskKind::Epuck => BUILT_IN_EPUCK,
            },
            name: task.built_in_path(),
        }
    }

    /// The file `path`, or the built-in scenario of `task`.
    pub fn file_or_built_in(path: Option<PathBuf>, task: TaskKind) -> Self {
        match path {
            Some(p) => ScenarioSource::File(p),
            None => Self::built_in(task),
        }
    }

    /// The path that names it in errors.
    pub fn path(&self) -> &Path {
        match self {
            ScenarioSource::File(p) => p,
            ScenarioSource::BuiltIn { name, .. } => Path::new(name),
            ScenarioSource::Text { name, .. } => name,
        }
    }

    /// Its text (a file's read within [`crate::MAX_SCENARIO_BYTES`], as
    /// UTF-8).
    pub fn read(&self) -> Result<String> {
        match self {
            ScenarioSource::File(p) => read_scenario(p),
            ScenarioSource::BuiltIn { text, .. } => Ok((*text).to_string()),
            ScenarioSource::Text { text, .. } => Ok(text.clone()),
        }
    }
}

/// A scenario's seed set from outside (`--seed`, `seed=`): a whole number
/// from 0 to `i64::MAX`, as a TOML integer holds it; checked once, where
/// it enters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScenarioSeed(u64);

impl ScenarioSeed {
    /// The largest seed.
    pub const MAX: u64 = i64::MAX as u64;

    /// `seed` if it is at most [`Self::MAX`].
    pub fn new(seed: u64) -> Option<Self> {
        (seed <= Self::MAX).then_some(Self(seed))
    }

    /// The seed.
    pub fn get(self) -> u64 {
        self.0
    }

    fn as_toml(self) -> i64 {
        i64::try_from(self.0).expect("checked: at most i64::MAX")
    }
}

/// A scenario and the values set in it from outside, each checked where
/// it entered (a flag's parser, a keyword's check).
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioInput {
    /// The scenario.
    pub source: ScenarioSource,
    /// `user.accuracy`: a new decoder accuracy, which replaces the file's
    /// other ways of giving it.
    pub accuracy: Option<RequestedAccuracy>,
    /// `seed`: a new simulated user, new runs and new free goals.
    pub seed: Option<ScenarioSeed>,
    /// `runs` (e-puck scenarios).
    pub runs: Option<u64>,
    /// `decoder` (grid scenarios).
    pub decoder: Option<DecoderChoice>,
    /// `eeg` (grid scenarios).
    pub eeg: Option<EegMode>,
    /// Any dotted keys, set after the values above, in order.
    pub keys: Vec<(String, toml::Value)>,
}

/// A scenario loaded from a [`ScenarioInput`].
#[derive(Debug, Clone)]
pub struct LoadedScenario {
    /// The validated scenario.
    pub scenario: AnyScenario,
    /// Its text as run: the file's with the values set, comments and
    /// layout kept.
    pub text: String,
}

impl ScenarioInput {
    /// Loads `source` as it is written ([`ScenarioInput::load`] with
    /// nothing set).
    pub fn load_as_written(source: ScenarioSource) -> Result<AnyScenario> {
        Ok(Self::new(source).load(&Names::FILE)?.scenario)
    }

    /// `source` with nothing set.
    pub fn new(source: ScenarioSource) -> Self {
        Self {
            source,
            accuracy: None,
            seed: None,
            runs: None,
            decoder: None,
            eeg: None,
            keys: Vec::new(),
        }
    }

    /// Reads the scenario once, checks that each value set applies to its
    /// task (`names` name them), sets them as the file's own keys
    /// ([`apply_overrides`]) and validates the result, so that nothing
    /// derived from a value (the accuracy the device assumes, the free
    /// goals drawn from the seed) can be left behind. An error of the file
    /// as written quotes its line; one that only the values set cause
    /// names the file and the field.
    pub fn load(&self, names: &Names) -> Result<LoadedScenario> {
        let path = self.source.path();
        let text = self.source.read()?;
        let table: toml::Table = parse_toml(&text, path)?;
        let task = TaskKind::of_table(&table);
        if let Err(e) = self.check_task(task, &table, names) {
            // The file's own error first, with its line.
            return Err(parse_scenario(&text, path).err().unwrap_or(e));
        }
        let keys = self.pairs();
        if keys.is_empty() {
            let scenario = parse_scenario(&text, path)?;
            return Ok(LoadedScenario { scenario, text });
        }
        let as_run = apply_overrides(&text, &keys)
            .map_err(|e| SimError::Scenario(format!("{}: {e}", path.display())))?;
        let table: toml::Table = parse_toml(&as_run, path)?;
        match parse_scenario_table(&table, path) {
            Ok(mut scenario) => {
                if let (AnyScenario::Grid(s), Some(_)) = (&mut scenario, self.accuracy) {
                    s.user.push_str(&format!(" ({})", names.accuracy));
                }
                Ok(LoadedScenario {
                    scenario,
                    text: as_run,
                })
            }
            // The file's own error first, with its line.
            Err(e) => Err(parse_scenario(&text, path).err().unwrap_or(e)),
        }
    }

    /// Refuses what the values set cannot be combined with, by the rules
    /// ([`rules`]) and in the names of `names`: a value the scenario's task
    /// does not take, what a scenario on a person's own EEG cannot have, a
    /// perfect accuracy for anything but the grid's oracle. `table` is the
    /// scenario as written.
    fn check_task(&self, task: TaskKind, table: &toml::Table, names: &Names) -> Result<()> {
        let path = self.source.path();
        let set = Origin::Input(names);
        let mut given = Vec::new();
        if self.decoder.is_some() {
            given.push((TaskValue::Decoder, set));
        }
        if self.eeg.is_some() {
            given.push((TaskValue::EegMode, set));
        }
        if self.runs.is_some() {
            given.push((TaskValue::Runs, set));
        }
        rules::task_takes(task, path, &given)?;
        let recording = table
            .get("eeg")
            .and_then(toml::Value::as_table)
            .and_then(|t| t.get("recording"))
            .and_then(toml::Value::as_str);
        let own = recording.map(|recording| OwnEegFrom::Scenario { path, recording });
        let mut claims = Vec::new();
        if let Some(a) = self.accuracy {
            claims.push((Claim::Accuracy(a.get()), set));
        }
        if let Some(eeg) = self.eeg {
            claims.push((Claim::EegMode(eeg.key()), set));
        }
        if self.decoder == Some(DecoderChoice::Oracle) {
            claims.push((Claim::Oracle, set));
        }
        // A mode set as a key would replace the `[eeg]` table that names
        // the recording.
        for (key, value) in &self.keys {
            if let (true, Some(mode)) = (key == "eeg", value.as_str()) {
                claims.push((Claim::EegMode(mode), set));
            }
        }
        rules::own_eeg_is_the_user(own, &claims)?;
        if let Some(a) = self.accuracy {
            rules::accuracy_for(task, self.decoder_is_oracle(table), a.get(), set)?;
        }
        Ok(())
    }

    /// True if the decoder is the oracle: as set, else as the last key
    /// that sets it, else as the file writes it.
    fn decoder_is_oracle(&self, table: &toml::Table) -> bool {
        let oracle = DecoderChoice::Oracle.key();
        match self.decoder {
            Some(d) => d == DecoderChoice::Oracle,
            None => match self.keys.iter().rev().find(|(k, _)| k == "decoder") {
                Some((_, v)) => v.as_str() == Some(oracle),
                None => table.get("decoder").and_then(toml::Value::as_str) == Some(oracle),
            },
        }
    }

    /// The values set, as the file's dotted keys, in order (each the
    /// scenario's task takes: [`rules::task_takes`] refused the others).
    fn pairs(&self) -> Vec<(&str, toml::Value)> {
        let mut out: Vec<(&str, toml::Value)> = Vec::new();
        if let Some(a) = self.accuracy {
            out.push(("user.accuracy", toml::Value::Float(a.get())));
        }
        if let Some(seed) = self.seed {
            out.push(("seed", toml::Value::Integer(seed.as_toml())));
        }
        if let Some(runs) = self.runs {
            out.push(("runs", toml::Value::Integer(runs as i64)));
        }
        if let Some(d) = self.decoder {
            out.push(("decoder", toml::Value::String(d.key().into())));
        }
        if let Some(e) = self.eeg {
            out.push(("eeg", toml::Value::String(e.key().into())));
        }
        out.extend(self.keys.iter().map(|(k, v)| (k.as_str(), v.clone())));
        out
    }
}
