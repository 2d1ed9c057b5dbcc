//! What a sweep runs: a scenario, the accuracy levels, the swept parameters,
//! and how every level's scenario is derived from the file.
//!
//! A swept value is written into the scenario's TOML before the scenario is
//! validated, so every scenario field can be swept and a bad value gets the
//! same error as in a scenario file.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use toml::{Table, Value};

use errp_sim::parse_toml;
use errp_sim::rules::{self, Claim, Origin, OwnEegFrom};
use errp_sim::task::format_number;
use errp_sim::{AnyScenario, Names, ScenarioInput, ScenarioSource, TaskKind};
use errp_sim::{Result, SimError};

mod axis;
mod scenario;
mod shard;
mod values;

pub use axis::{Axis, aliases, parse_axis, sweepable};
pub use scenario::{read_task, sweep_fixed, sweep_scenario};
pub use shard::Shard;
use values::repeated;
pub use values::{parse_accuracies, parse_values, value_text};

/// Everything that defines a sweep's results. Two sweeps with equal specs
/// write equal files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepSpec {
    /// Which task the scenario is.
    pub task: TaskKind,
    /// The scenario file, as given.
    pub scenario_path: PathBuf,
    /// The scenario file's text: what was run, even if the file changes.
    pub scenario_toml: String,
    /// Decoder accuracy levels (mean of the per-class rates).
    pub accuracies: Vec<f64>,
    /// Swept scenario parameters; every combination is run at every accuracy.
    pub axes: Vec<Axis>,
    /// Scenario values set for every level (e.g. `eeg = "bank"`).
    pub fixed: Vec<(String, Value)>,
    /// Episodes per level.
    pub episodes: usize,
    /// The sweep seed: every calibration and episode seed derives from it.
    pub seed: u64,
}

/// A sweep whose levels were built and checked, once
/// ([`SweepSpec::checked`]): its size, that no level is given twice, and
/// every level's scenario.
#[derive(Debug, Clone)]
pub struct CheckedSweep {
    spec: SweepSpec,
    levels: Vec<Level>,
}

impl CheckedSweep {
    /// What the sweep runs.
    pub fn spec(&self) -> &SweepSpec {
        &self.spec
    }

    /// Its levels, each with its checked scenario.
    pub fn levels(&self) -> &[Level] {
        &self.levels
    }
}

/// One level of a sweep: an accuracy and one value of every axis, with the
/// validated scenario that results.
#[derive(Debug, Clone)]
pub struct Level {
    /// Position in the sweep (accuracy varies fastest).
    pub index: usize,
    /// The decoder's accuracy: the level's, or on recordings the one its
    /// recording gives, set once its decoder is prepared (0 before).
    pub accuracy: f64,
    /// One value per axis.
    pub values: Vec<Value>,
    /// The scenario with the level's values written in.
    pub scenario: AnyScenario,
}

/// Most episodes per level.
pub const MAX_EPISODES: usize = 1_000_000;

/// Most levels in a sweep (accuracies times every swept value).
pub const MAX_LEVELS: usize = 1000;

/// The key of a recording in a scenario, and the axis that sweeps
/// recordings (`--param eeg.recording=a.edf,b.edf`).
pub const OWN_EEG_KEY: &str = "eeg.recording";

impl SweepSpec {
    /// True if `self` and `other` are one sweep: the same scenario text
    /// (wherever the file is, however its path is spelled: only its file
    /// name, which names a scenario that sets no `name`, must agree), the
    /// same levels, episodes and seed.
    pub fn same_sweep(&self, other: &Self) -> bool {
        let name = |s: &Self| s.scenario_path.file_name().map(|n| n.to_os_string());
        Self {
            scenario_path: PathBuf::new(),
            ..self.clone()
        } == Self {
            scenario_path: PathBuf::new(),
            ..other.clone()
        } && name(self) == name(other)
    }

    /// Episodes over all levels.
    pub fn total_episodes(&self) -> usize {
        self.n_levels() * self.episodes
    }

    /// Levels: every combination of the axes' values, at every accuracy.
    pub fn n_levels(&self) -> usize {
        self.accuracies.len().max(1) * self.axes.iter().map(|a| a.values.len()).product::<usize>()
    }

    /// True if the sweep's EEG is a person's recording, in the scenario
    /// (`[eeg] recording = ...`) or swept (`--param eeg.recording=a.edf,b.edf`):
    /// its levels then have no accuracy set, each decoder the accuracy its
    /// recording gives.
    pub fn on_own_eeg(&self) -> bool {
        toml::from_str::<Table>(&self.scenario_toml).is_ok_and(|t| self.own_eeg(&t).is_some())
    }

    /// The seed of episode `k` of `level`: at its accuracy
    /// ([`episode_seed`](Self::episode_seed)), or on recordings one sequence
    /// for every level (common random numbers: the subjects face the same
    /// goals and noise).
    pub fn level_episode_seed(&self, level: &Level, k: usize) -> u64 {
        if self.accuracies.is_empty() {
            let base = errp_bci::rng::derive_seed(self.seed, "sweep/recordings", 0);
            errp_bci::rng::derive_seed(base, "sweep/episode", k as u64)
        } else {
            self.episode_seed(level.accuracy, k)
        }
    }

    /// The accuracy and axis values of level `index` (accuracy fastest, then
    /// the last axis).
    pub fn level_values(&self, index: usize) -> (f64, Vec<Value>) {
        let mut rest = index;
        // On recordings, no accuracy is set: 0 until each level's decoder
        // is prepared (`Level::accuracy`).
        let n = self.accuracies.len().max(1);
        let accuracy = self.accuracies.get(rest % n).copied().unwrap_or(0.0);
        rest /= n;
        let mut values = vec![Value::Boolean(false); self.axes.len()];
        for (i, axis) in self.axes.iter().enumerate().rev() {
            values[i] = axis.values[rest % axis.values.len()].clone();
            rest /= axis.values.len();
        }
        (accuracy, values)
    }

    /// The label of a setting, one value per axis: `tau=0.3, strategy=greedy`
    /// (empty when no axis is swept).
    pub fn series_label(&self, values: &[Value]) -> String {
        self.axes
            .iter()
            .zip(values)
            .map(|(a, v)| format!("{}={}", a.name, value_text(v)))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The seed of the calibration sessions. Every level uses the same
    /// session (the same background EEG, artifacts and schedule) with the
    /// ErrP amplitude targeted at its accuracy, so decoders differ only in
    /// how much ErrP there is to find, and accuracy levels stay ordered.
    pub fn calibration_seed(&self) -> u64 {
        // Scenario files hold seeds as TOML integers (i64).
        errp_bci::rng::derive_seed(self.seed, "sweep/calibration", 0) & i64::MAX as u64
    }

    /// The seed of episode `k` at `accuracy`. It does not depend on the swept
    /// parameters (common random numbers: strategies at one accuracy face the
    /// same users, goals and noise), nor on threads, shards or order.
    pub fn episode_seed(&self, accuracy: f64, k: usize) -> u64 {
        let level = errp_bci::rng::derive_seed(self.seed, "sweep/accuracy", accuracy.to_bits());
        errp_bci::rng::derive_seed(level, "sweep/episode", k as u64)
    }

    /// Checks the sweep's size and that no level is given twice: the
    /// episodes per level, the number of levels, and axes that are distinct
    /// parameters.
    pub fn check(&self, names: &Names) -> Result<()> {
        let (accuracy, param) = (names.accuracy, names.param);
        if !(1..=MAX_EPISODES).contains(&self.episodes) {
            return Err(SimError::Sweep(format!(
                "{} {} is invalid: expected 1 to {MAX_EPISODES} episodes per level",
                names.episodes, self.episodes
            )));
        }
        if self.accuracies.is_empty() && !self.on_own_eeg() {
            return Err(SimError::Sweep(format!("{accuracy} gives no level")));
        }
        let levels = self
            .axes
            .iter()
            .try_fold(self.accuracies.len().max(1), |n, a| {
                n.checked_mul(a.values.len())
            });
        if levels.is_none_or(|n| n > MAX_LEVELS) {
            let sizes: Vec<String> = std::iter::once(self.accuracies.len().max(1))
                .chain(self.axes.iter().map(|a| a.values.len()))
                .map(|n| n.to_string())
                .collect();
            let n = levels.map_or("more than 2^64".into(), |n| n.to_string());
            let what = if self.axes.is_empty() {
                format!("{accuracy} gives {n} levels,")
            } else {
                format!(
                    "{n} levels ({} accuracies x {} {param} values) are",
                    sizes[0],
                    sizes[1..].join(" x ")
                )
            };
            return Err(SimError::Sweep(format!(
                "{what} too many: a sweep has at most {MAX_LEVELS}; split it into several sweeps"
            )));
        }
        for (i, a) in self.axes.iter().enumerate() {
            if let Some(b) = self.axes[..i]
                .iter()
                .find(|b| b.name == a.name || b.key == a.key)
            {
                return Err(SimError::Sweep(format!(
                    "{param} {} and {param} {} both set {}: give one {param} per field, with \
                     all its values (e.g. tau=0.3,0.5)",
                    b.name, a.name, a.key
                )));
            }
            if let Some(twice) = repeated(&a.values) {
                return Err(SimError::Sweep(format!(
                    "{param} {}: {twice} is given twice (each value once)",
                    a.name
                )));
            }
        }
        if let Some(twice) = repeated(
            &self
                .accuracies
                .iter()
                .map(|a| Value::Float(*a))
                .collect::<Vec<_>>(),
        ) {
            return Err(SimError::Sweep(format!(
                "{accuracy}: {twice} is given twice (each level once)"
            )));
        }
        Ok(())
    }

    /// Builds and checks every level once: the sweep as
    /// [`run_sweep`](crate::run_sweep) and
    /// [`prepare_sweep`](crate::prepare_sweep) take it. Errors name the
    /// inputs as `names` does.
    pub fn checked(self, names: &Names) -> Result<CheckedSweep> {
        let levels = self.levels(names)?;
        Ok(CheckedSweep { spec: self, levels })
    }

    /// Sets what the caller gave for every level: the accuracy levels
    /// (`accuracy`, none on own EEG) and the grid's EEG mode (`eeg`, as
    /// given: `per_action`, `bank`; otherwise the bank, but on own EEG,
    /// whose EEG is the recording's). What own EEG cannot take is refused
    /// when the levels are checked, by the rule
    /// ([`rules::own_eeg_is_the_user`]), naming `names`' inputs.
    pub fn set_levels(
        &mut self,
        accuracy: Option<&str>,
        eeg: Option<&str>,
        names: &Names,
    ) -> Result<()> {
        if let Some(a) = accuracy {
            self.accuracies = parse_accuracies(a, names)?;
        }
        if !self.on_own_eeg() || eeg.is_some() {
            self.fixed = sweep_fixed(self.task, &self.scenario_path, eeg, names)?;
        }
        Ok(())
    }

    /// Where the sweep's own EEG comes from, if it runs on one: swept
    /// (`--param eeg.recording=a.edf,b.edf`) or the scenario's (`[eeg]
    /// recording = ...`).
    fn own_eeg<'a>(&'a self, table: &'a Table) -> Option<OwnEegFrom<'a>> {
        if self.axes.iter().any(|a| a.key == OWN_EEG_KEY) {
            return Some(OwnEegFrom::Swept);
        }
        let recording = table
            .get("eeg")
            .and_then(Value::as_table)
            .and_then(|e| e.get("recording"))?;
        Some(OwnEegFrom::Scenario {
            path: &self.scenario_path,
            recording: recording.as_str().unwrap_or_default(),
        })
    }

    /// Checks a sweep over a person's own EEG by the rule
    /// ([`rules::own_eeg_is_the_user`]): no accuracy levels (a recording's
    /// decoder has the accuracy it gives) and no EEG mode set for every
    /// level (the `[eeg]` table is the recording's).
    fn check_own_eeg(&self, table: &Table, names: &Names) -> Result<()> {
        let at = Origin::Sweep(names);
        let mode = self
            .fixed
            .iter()
            .find(|(k, _)| k == "eeg")
            .map(|(_, v)| value_text(v));
        let mut claims = Vec::new();
        if let Some(&a) = self.accuracies.first() {
            claims.push((Claim::Accuracy(a), at));
        }
        if let Some(m) = &mode {
            claims.push((Claim::EegMode(m), at));
        }
        rules::own_eeg_is_the_user(self.own_eeg(table), &claims)
    }

    /// Builds and validates every level's scenario. An invalid swept value
    /// is reported with the level and the scenario's own field error.
    pub(crate) fn levels(&self, names: &Names) -> Result<Vec<Level>> {
        self.check(names)?;
        // The file's own errors quote its lines.
        let table: Table = parse_toml(&self.scenario_toml, &self.scenario_path)?;
        self.check_own_eeg(&table, names)?;
        let recordings = self.accuracies.is_empty();
        (0..self.n_levels())
            .map(|index| {
                let (accuracy, values) = self.level_values(index);
                let context = |why: String| {
                    let mut label = format!("accuracy={}", format_number(accuracy));
                    if recordings {
                        label = self.series_label(&values);
                    } else if !self.axes.is_empty() {
                        label = format!("{label}, {}", self.series_label(&values));
                    }
                    SimError::Sweep(format!("sweep level {label}: {why}"))
                };
                // The level's accuracy replaces the file's decoder (an online
                // target included); the sweep's seed gives the user (the
                // calibration).
                let mut keys: Vec<(String, Value)> = vec![(
                    "seed".into(),
                    Value::Integer(self.calibration_seed() as i64),
                )];
                if !recordings {
                    keys.insert(0, ("user.accuracy".into(), Value::Float(accuracy)));
                }
                keys.extend(self.fixed.iter().cloned());
                for (a, v) in self.axes.iter().zip(&values) {
                    keys.push((a.key.clone(), v.clone()));
                }
                let input = ScenarioInput {
                    keys,
                    ..ScenarioInput::new(ScenarioSource::Text {
                        text: self.scenario_toml.clone(),
                        name: self.scenario_path.clone(),
                    })
                };
                let scenario = input
                    .load(&Names::FILE)
                    .map_err(|e| context(e.to_string()))?
                    .scenario;
                Ok(Level {
                    index,
                    accuracy,
                    values,
                    scenario,
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_include_the_stop_without_binary_noise() {
        let v = parse_values("0.55:0.95:0.05", "--accuracy").unwrap();
        let x: Vec<f64> = v.iter().map(|v| v.as_float().unwrap()).collect();
        assert_eq!(x.len(), 9);
        assert_eq!(x[1], 0.6);
        assert_eq!(x[8], 0.95);
        assert_eq!(parse_values("0.1:0.5:0.1", "t").unwrap().len(), 5);
        assert_eq!(
            parse_values("2:10:4", "t").unwrap(),
            vec![Value::Integer(2), Value::Integer(6), Value::Integer(10)]
        );
        assert_eq!(
            parse_values("greedy,info_gain", "t").unwrap(),
            vec![
                Value::String("greedy".into()),
                Value::String("info_gain".into())
            ]
        );
    }

    #[test]
    fn bad_ranges_and_accuracies_say_what_is_expected() {
        for (text, needle) in [
            ("0.9:0.5:0.1", "stop >= start"),
            ("0.5:0.9:0", "step > 0"),
            ("a:b:c", "three numbers"),
            ("1:2", "start:stop:step"),
            ("0.6,,0.7", "empty item"),
        ] {
            let e = parse_values(text, "--accuracy").unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
        let e = parse_accuracies("1.7", &Names::CLI)
            .unwrap_err()
            .to_string();
        assert!(e.contains("1.7") && e.contains("(0.5, 1)"), "{e}");
        assert!(parse_accuracies("0.5", &Names::CLI).is_err());
        assert!(parse_accuracies("NaN", &Names::CLI).is_err());
    }

    #[test]
    fn params_resolve_short_names_and_refuse_the_accuracy() {
        let a = parse_axis(TaskKind::Grid, "tau=0.1:0.3:0.1", &Names::CLI).unwrap();
        assert_eq!(a.key, "control.tau");
        assert_eq!(a.values.len(), 3);
        assert_eq!(
            parse_axis(TaskKind::Epuck, "t_e=0.7,0.8", &Names::CLI)
                .unwrap()
                .key,
            "control.t_e"
        );
        assert_eq!(
            parse_axis(TaskKind::Grid, "timing.max_actions=50", &Names::CLI)
                .unwrap()
                .key,
            "timing.max_actions"
        );
        let e = parse_axis(TaskKind::Grid, "t_e=0.8", &Names::CLI)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("not a grid scenario parameter") && e.contains("tau"),
            "{e}"
        );
        assert!(parse_axis(TaskKind::Grid, "user.accuracy=0.7", &Names::CLI).is_err());
        assert!(parse_axis(TaskKind::Grid, "tau", &Names::CLI).is_err());
    }

    #[test]
    fn shards_partition_the_episodes() {
        let shards: Vec<Shard> = (1..=3)
            .map(|k| Shard::parse(&format!("{k}/3")).unwrap())
            .collect();
        for g in 0..30 {
            assert_eq!(shards.iter().filter(|s| s.owns(g)).count(), 1);
        }
        for bad in ["0/3", "4/3", "1/0", "x", "1/2/3"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    proptest::proptest! {
        /// Whatever the command line says, the parsers answer with values
        /// or an error naming the flag: no panic, no huge allocation.
        #[test]
        fn any_flag_text_parses_or_is_refused_naming_the_flag(text in "\\PC{0,40}|[-0-9.,:e]{0,30}") {
            if let Err(e) = parse_values(&text, "--param x") {
                proptest::prop_assert!(e.to_string().contains("--param x"));
            }
            match parse_accuracies(&text, &Names::CLI) {
                Ok(v) => proptest::prop_assert!(v.iter().all(|a| *a > 0.5 && *a <= 1.0) && v.len() <= 10_000),
                Err(e) => proptest::prop_assert!(e.to_string().contains("--accuracy")),
            }
            for task in [TaskKind::Grid, TaskKind::Epuck] {
                if let Err(e) = parse_axis(task, &text, &Names::CLI) {
                    proptest::prop_assert!(e.to_string().contains("--param"), "{}", e);
                }
            }
            if let Ok(s) = Shard::parse(&text) {
                proptest::prop_assert!(s.index >= 1 && s.index <= s.count);
            }
        }
    }

    #[test]
    fn a_sweep_seed_gives_every_level_its_user() {
        // A scenario's `[user] seed` (the city scenarios share one) is the
        // sweep's to set: each sweep seed is another simulated user.
        let spec = SweepSpec {
            task: TaskKind::Epuck,
            scenario_path: "scenarios/lisbon_to_tokyo.toml".into(),
            scenario_toml: include_str!("../../../scenarios/lisbon_to_tokyo.toml").into(),
            accuracies: vec![0.8],
            axes: vec![],
            fixed: vec![],
            episodes: 1,
            seed: 7,
        };
        let levels = spec.levels(&Names::CLI).unwrap();
        let AnyScenario::Epuck(s) = &levels[0].scenario else {
            panic!("an e-puck scenario")
        };
        assert_eq!(s.seed, spec.calibration_seed());
        assert_eq!(s.user_seed, s.seed);
    }

    #[test]
    fn levels_vary_accuracy_fastest() {
        let spec = SweepSpec {
            task: TaskKind::Grid,
            scenario_path: "x.toml".into(),
            scenario_toml: String::new(),
            accuracies: vec![0.6, 0.8],
            axes: vec![parse_axis(TaskKind::Grid, "tau=0.1,0.3,0.5", &Names::CLI).unwrap()],
            fixed: vec![],
            episodes: 10,
            seed: 1,
        };
        assert_eq!(spec.n_levels(), 6);
        assert_eq!(spec.total_episodes(), 60);
        assert_eq!(spec.level_values(0), (0.6, vec![Value::Float(0.1)]));
        assert_eq!(spec.level_values(1), (0.8, vec![Value::Float(0.1)]));
        assert_eq!(spec.level_values(5), (0.8, vec![Value::Float(0.5)]));
        assert_eq!(spec.episode_seed(0.6, 3), spec.episode_seed(0.6, 3));
        assert_ne!(spec.episode_seed(0.6, 3), spec.episode_seed(0.8, 3));
    }
}
