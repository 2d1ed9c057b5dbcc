//! Scenario files: what to run, validated on load.
//!
//! A scenario is TOML. `ScenarioFile` mirrors the file (serde, unknown keys
//! rejected); loading (through [`crate::ScenarioInput`]) checks every value and returns a checked
//! [`GridScenario`], or an error naming the file, the field, the value and the
//! accepted range.

use std::path::{Path, PathBuf};

use errp_bci::{GoalSet, Realism, RequestedAccuracy, subject};
use errp_robot::{Cell, Grid, GridControlParams, Valid};
use rand::Rng;
use serde::Deserialize;

use crate::error::Result;
use crate::grid::p_error::PErrorChoice;
use crate::grid::params::{GridTaskParams, TimingFile, set_timing};
pub use crate::grid::params::{MAX_ACTIONS, MAX_INTERVAL_SECS};
use crate::own_eeg::{OwnEegFields, OwnEegSpec};
use crate::rules::{self, Claim, Origin};
use crate::scenario_file::{
    Pair, checked_realism, field_error, parse_toml, robot_error, scenario_name, table_into, whole,
};
use crate::task_kind::TaskKind;

/// Most epochs per class in an epoch bank (about 9 KB each, per level of a
/// sweep).
pub const MAX_BANK_PER_CLASS: u64 = 20_000;
/// Epochs per class in a bank when a scenario sets none.
pub(crate) const DEFAULT_BANK_PER_CLASS: usize = 1000;
/// Most `[[episode]]` pairs, free goals or repeats in a scenario file.
pub const MAX_PAIRS: u64 = 10_000;
/// Most episodes a scenario runs (pairs times repeats).
pub const MAX_EPISODES: usize = 100_000;

/// Which decoder turns the user's assessments into p(error).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DecoderChoice {
    /// Synthetic EEG through the real preprocessing and LDA (the default).
    Eeg,
    /// Assessments flipped with probability 1 - accuracy; no EEG.
    Oracle,
}

impl DecoderChoice {
    /// As a scenario file spells it (`decoder = "eeg"`).
    pub fn key(self) -> &'static str {
        match self {
            DecoderChoice::Eeg => "eeg",
            DecoderChoice::Oracle => "oracle",
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
    task: String,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default = "default_seed")]
    seed: u64,
    #[serde(default = "default_decoder")]
    decoder: DecoderChoice,
    #[serde(default = "default_p_error")]
    p_error: PErrorChoice,
    #[serde(default)]
    eeg: Option<EegFile>,
    #[serde(default)]
    bank_per_class: Option<f64>,
    #[serde(default)]
    user: Option<UserFile>,
    #[serde(default)]
    episode: Vec<EpisodeFile>,
    #[serde(default)]
    free_goals: Option<FreeGoalsFile>,
    #[serde(default)]
    repeats: Option<f64>,
    /// Straight into the robot's type: its field names are the file's.
    #[serde(default)]
    control: GridControlParams,
    #[serde(default)]
    timing: Option<TimingFile>,
    /// Straight into the EEG model's type: how far the user is from the
    /// ideal one (all off by default).
    #[serde(default)]
    realism: Realism,
}

fn default_seed() -> u64 {
    1
}
fn default_decoder() -> DecoderChoice {
    DecoderChoice::Eeg
}
fn default_p_error() -> PErrorChoice {
    PErrorChoice::Platt
}

/// A scenario's `eeg`: a mode (`eeg = "bank"`) or own EEG (an `[eeg]`
/// table with `recording = "s01.edf"`).
#[derive(Debug)]
enum EegFile {
    Mode(EegMode),
    OwnEeg(OwnEegFields),
}

impl<'de> Deserialize<'de> for EegFile {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = EegFile;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "\"per_action\", \"bank\" or a table naming a recording \
                     ([eeg] recording = \"s01.edf\")",
                )
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> std::result::Result<EegFile, E> {
                EegMode::deserialize(serde::de::value::StrDeserializer::<E>::new(v))
                    .map(EegFile::Mode)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> std::result::Result<EegFile, A::Error> {
                OwnEegFields::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(EegFile::OwnEeg)
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// How the EEG reaches the decoder during episodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EegMode {
    /// Synthesised when each action happens, the whole inter-action
    /// interval generated (the default; faithful, ~0.7 ms per action).
    /// Spelled `"per_action"`; `"stream"`, its former name, is still read.
    #[serde(alias = "stream")]
    PerAction,
    /// Drawn from a bank of epochs synthesised in advance (fast, for sweeps).
    Bank,
}

impl EegMode {
    /// As a scenario file spells it (`eeg = "per_action"`).
    pub fn key(self) -> &'static str {
        match self {
            EegMode::PerAction => "per_action",
            EegMode::Bank => "bank",
        }
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct UserFile {
    #[serde(default)]
    accuracy: Option<f64>,
    #[serde(default)]
    subject: Option<String>,
    #[serde(default)]
    goals: Option<GoalSetFile>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum GoalSetFile {
    Fixed,
    Free,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct EpisodeFile {
    start: Pair<i64>,
    goal: Pair<i64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FreeGoalsFile {
    count: f64,
}

/// Where a grid decoder's accuracy comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum GridAccuracy {
    /// Asked for: the synthetic user's EEG is targeted at it (or the
    /// oracle has it).
    Requested(RequestedAccuracy),
    /// Whatever a person's own EEG gives: the decoder is calibrated on
    /// its first part and decodes epochs of the rest.
    OwnEeg(Box<OwnEegSpec>),
}

impl GridAccuracy {
    /// The accuracy asked for, if any.
    pub fn requested(&self) -> Option<RequestedAccuracy> {
        match self {
            Self::Requested(a) => Some(*a),
            Self::OwnEeg(_) => None,
        }
    }

    /// The own EEG, if the EEG is a person's.
    pub fn own_eeg(&self) -> Option<&OwnEegSpec> {
        match self {
            Self::Requested(_) => None,
            Self::OwnEeg(r) => Some(r),
        }
    }
}

/// A validated grid scenario: loaded through [`crate::ScenarioInput`] or
/// made in code ([`GridScenario::builder`]), checked either way; it cannot
/// be written as a struct literal outside this crate.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct GridScenario {
    /// The file it came from.
    pub path: PathBuf,
    /// Display name.
    pub name: String,
    /// What it reproduces, in words.
    pub description: String,
    /// Base seed of every episode.
    pub seed: u64,
    /// EEG or oracle decoder.
    pub decoder: DecoderChoice,
    /// p(error) mapping of the EEG decoder.
    pub p_error: PErrorChoice,
    /// Streamed or banked EEG.
    pub eeg: EegMode,
    /// Epochs per class in the bank (bank mode).
    pub bank_per_class: usize,
    /// The decoder's mean accuracy: targeted in (0.5, 1), perfect (the
    /// oracle only), or what a person's own EEG gives.
    pub accuracy: GridAccuracy,
    /// Who the accuracy comes from ("accuracy 0.7438", "subject S2, fixed goals").
    pub user: String,
    /// (start, goal) of every episode, in order (repeats included).
    pub episodes: Vec<(Cell, Cell)>,
    /// Strategy and timing.
    pub params: GridTaskParams,
    /// How far the simulated user is from the ideal one (`[realism]`).
    pub realism: Realism,
}

impl GridScenario {
    /// Validates scenario text; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        Self::from_file(parse_toml(text, path)?, path)
    }

    /// Validates a scenario given as a TOML table (a file's with values set
    /// from the command line or a sweep); errors name fields, not lines.
    pub fn from_table(table: &toml::Table, path: &Path) -> Result<Self> {
        Self::from_file(table_into(table, path)?, path)
    }

    fn from_file(file: ScenarioFile, path: &Path) -> Result<Self> {
        let bad =
            |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
        if file.task != TaskKind::Grid.as_str() {
            return Err(bad("task", format!("{:?}", file.task), TaskKind::EXPECTED));
        }

        let (eeg, recorded) = match &file.eeg {
            None => (EegMode::PerAction, None),
            Some(EegFile::Mode(mode)) => (*mode, None),
            Some(EegFile::OwnEeg(r)) => {
                (EegMode::Bank, Some(r.clone().check(path, TaskKind::Grid)?))
            }
        };
        let (accuracy, user) = match recorded {
            Some(r) => {
                refuse_with_own_eeg(&file, &r, path)?;
                let user = format!("recording {}", r.written);
                (GridAccuracy::OwnEeg(Box::new(r)), user)
            }
            None => {
                let (a, user) = user_accuracy(&file, path)?;
                (GridAccuracy::Requested(a), user)
            }
        };

        // Strategy and timing, on top of the paper's defaults.
        // The device knows its decoder's accuracy from the calibration: the
        // one asked for, or (a recording) its cross-validated accuracy, set
        // when the recording is read.
        // Checked here, once: the controllers take it checked.
        let mut params = GridTaskParams {
            control: assumed_control(file.control, &accuracy, path)?,
            ..GridTaskParams::default()
        };
        set_timing(&mut params, file.timing.as_ref(), path)?;

        let pairs = start_goal_pairs(&file, path)?;
        let bank_per_class = match file.bank_per_class {
            Some(n) => whole(
                path,
                "bank_per_class",
                n,
                1,
                MAX_BANK_PER_CLASS,
                &format!(" (default {DEFAULT_BANK_PER_CLASS})"),
            )?,
            None => DEFAULT_BANK_PER_CLASS,
        };
        let repeats = match file.repeats {
            Some(n) => whole(path, "repeats", n, 1, MAX_PAIRS, " (default 1)")?,
            None => 1,
        };
        if pairs.len() * repeats > MAX_EPISODES {
            return Err(bad(
                "repeats",
                repeats.to_string(),
                &format!(
                    "at most {MAX_EPISODES} episodes in all: {} pairs x {repeats} repeats is \
                     {}",
                    pairs.len(),
                    pairs.len() * repeats
                ),
            ));
        }
        let episodes = (0..repeats).flat_map(|_| pairs.iter().copied()).collect();
        let realism = checked_realism(file.realism, path)?;
        let scenario = Self {
            path: path.to_path_buf(),
            name: scenario_name(file.name, path),
            description: file.description.unwrap_or_default(),
            seed: file.seed,
            decoder: file.decoder,
            p_error: file.p_error,
            eeg,
            bank_per_class,
            accuracy,
            user,
            episodes,
            params,
            realism,
        };
        match scenario.accuracy.own_eeg() {
            Some(eeg) => {
                let eeg = eeg.clone();
                scenario.on_own_eeg(eeg)
            }
            None => Ok(scenario),
        }
    }
}

/// The control a scenario runs, as the loader and the builder both derive
/// it: the device assumes the accuracy asked of its decoder (an own EEG's
/// cross-validated accuracy is set when the file is read); checked
/// once, the controllers take it checked.
pub(crate) fn assumed_control(
    control: GridControlParams,
    accuracy: &GridAccuracy,
    path: &Path,
) -> Result<Valid<GridControlParams>> {
    let control = GridControlParams {
        assumed_accuracy: accuracy
            .requested()
            .map_or(control.assumed_accuracy, RequestedAccuracy::get),
        ..control
    };
    Valid::new(control).map_err(|e| robot_error(path, "control", e))
}

/// The user of a `[user]` table, an accuracy or a subject of Table 1 with
/// a goal set, in words too; an accuracy `decoder` can be asked for.
fn user_accuracy(file: &ScenarioFile, path: &Path) -> Result<(RequestedAccuracy, String)> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    // The user: an accuracy, or a subject of Table 1 with a goal set.
    let empty = UserFile::default();
    let u = file.user.as_ref().unwrap_or(&empty);
    let (accuracy, user) = match (&u.accuracy, &u.subject) {
        (Some(_), Some(_)) => {
            return Err(bad(
                "user",
                "both accuracy and subject".into(),
                "one of `user.accuracy` or `user.subject`",
            ));
        }
        (Some(a), None) => (*a, format!("accuracy {a}")),
        (None, Some(name)) => {
            let s = subject(name)
                .map_err(|e| bad("user.subject", format!("{name:?}"), &e.to_string()))?;
            let (set, label) = match u.goals.unwrap_or(GoalSetFile::Fixed) {
                GoalSetFile::Fixed => (GoalSet::Fixed, "fixed"),
                GoalSetFile::Free => (GoalSet::Free, "free"),
            };
            (
                s.accuracy(set),
                format!("subject {}, {label} goals", s.name),
            )
        }
        (None, None) => {
            return Err(bad(
                "user",
                "empty".into(),
                "`user.accuracy = 0.7438` or `user.subject = \"S1\"`",
            ));
        }
    };
    let oracle = file.decoder == DecoderChoice::Oracle;
    let requested = rules::accuracy_for(TaskKind::Grid, oracle, accuracy, Origin::Scenario(path))?;
    Ok((requested, user))
}

/// What a scenario on own EEG is also given, as its file writes it, in
/// the order [`rules::own_eeg_is_the_user`] reports them: a user (the
/// own EEG is the user), the oracle (it has no EEG), a bank's size (the
/// bank is the own EEG's held-out epochs). A `[realism]` table (a
/// simulated user's) is not used: [`GridScenario::on_own_eeg`].
fn refuse_with_own_eeg(file: &ScenarioFile, own: &OwnEegSpec, path: &Path) -> Result<()> {
    let at = Origin::Scenario(path);
    let goals = file
        .user
        .as_ref()
        .and_then(|u| u.goals)
        .map(|g| format!("{g:?}").to_lowercase());
    let bank = file.bank_per_class.map(|n| n.to_string());
    let mut claims = Vec::new();
    if let Some(u) = &file.user {
        if let Some(a) = u.accuracy {
            claims.push((Claim::Accuracy(a), at));
        }
        if let Some(name) = &u.subject {
            claims.push((Claim::Subject(name), at));
        }
    }
    if let Some(g) = &goals {
        claims.push((Claim::Goals(g), at));
    }
    if file.decoder == DecoderChoice::Oracle {
        claims.push((Claim::Oracle, at));
    }
    if let Some(n) = &bank {
        claims.push((Claim::BankPerClass(n), at));
    }
    rules::own_eeg_is_the_user(Some(own.origin(path, TaskKind::Grid)), &claims)
}

impl GridScenario {
    /// This scenario on a person's own EEG `eeg` (given in memory, from
    /// Python): its decoder calibrated on the EEG's first part, its
    /// user the person (a simulated user's `[realism]` is not used, and
    /// its user says so). Refused for the oracle, which reads no EEG.
    pub fn on_own_eeg(mut self, eeg: OwnEegSpec) -> Result<Self> {
        if self.decoder == DecoderChoice::Oracle {
            let own = eeg.origin(&self.path, TaskKind::Grid);
            rules::own_eeg_is_the_user(
                Some(own),
                &[(Claim::Oracle, Origin::Scenario(&self.path))],
            )?;
        }
        self.user = format!("recording {}", eeg.written);
        if self.realism != Realism::default() {
            // The recording is the person; the table describes a simulated one.
            self.user.push_str(" ([realism] not used)");
            self.realism = Realism::default();
        }
        self.eeg = EegMode::Bank;
        self.accuracy = GridAccuracy::OwnEeg(Box::new(eeg));
        Ok(self)
    }
}

/// The start/goal pairs of the `[[episode]]` tables, then the free goals
/// drawn from the scenario's seed.
fn start_goal_pairs(file: &ScenarioFile, path: &Path) -> Result<Vec<(Cell, Cell)>> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    // Episodes: fixed pairs and/or free goals drawn from the seed.
    let grid = errp_robot::Grid::paper();
    if file.episode.len() as u64 > MAX_PAIRS {
        return Err(bad(
            "episode",
            format!("{} tables", file.episode.len()),
            &format!("at most {MAX_PAIRS} [[episode]] tables (use `repeats`)"),
        ));
    }
    let mut pairs = Vec::new();
    for (k, e) in file.episode.iter().enumerate() {
        let cell = |field: &str, v: [i64; 2]| -> Result<Cell> {
            let inside =
                (0..grid.width as i64).contains(&v[0]) && (0..grid.height as i64).contains(&v[1]);
            if inside {
                Ok(Cell::new(v[0] as usize, v[1] as usize))
            } else {
                Err(bad(
                    &format!("episode[{k}].{field}"),
                    format!("[{}, {}]", v[0], v[1]),
                    "a cell [x, y] with 0 <= x, y <= 4 on the 5x5 grid",
                ))
            }
        };
        let (s, g) = (cell("start", e.start.0)?, cell("goal", e.goal.0)?);
        if s == g {
            return Err(bad(
                &format!("episode[{k}].goal"),
                format!("[{}, {}]", g.x, g.y),
                "a goal different from the start",
            ));
        }
        pairs.push((s, g));
    }
    if let Some(free) = &file.free_goals {
        let count = whole(path, "free_goals.count", free.count, 1, MAX_PAIRS, "")?;
        let mut rng = errp_bci::rng::labelled(file.seed, "scenario/free-goals");
        pairs.extend(free_pairs(&grid, count, &mut rng));
    }
    if pairs.is_empty() {
        return Err(bad(
            "episode",
            "none".into(),
            "at least one [[episode]] with start and goal, or a [free_goals] table",
        ));
    }
    Ok(pairs)
}

/// `count` start/goal pairs as a user choosing freely might: both cells
/// uniform on the grid, the goal different from the start.
pub fn free_pairs(grid: &Grid, count: usize, rng: &mut impl Rng) -> Vec<(Cell, Cell)> {
    (0..count)
        .map(|_| {
            let s = grid.cell(rng.random_range(0..grid.n_cells()));
            let mut g = s;
            while g == s {
                g = grid.cell(rng.random_range(0..grid.n_cells()));
            }
            (s, g)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_built_scenario_is_checked_as_a_file_is() {
        let built = |decoder, accuracy| GridScenario::builder("made", decoder, accuracy, 3);
        let s = built(DecoderChoice::Oracle, 1.0).build().unwrap();
        assert_eq!(s.accuracy.requested(), Some(RequestedAccuracy::Perfect));
        assert_eq!((s.seed, s.name.as_str()), (3, "made"));
        let s = built(DecoderChoice::Eeg, 0.8).name("S1").build().unwrap();
        assert_eq!(
            (
                s.accuracy.requested().map(RequestedAccuracy::get),
                s.name.as_str()
            ),
            (Some(0.8), "S1")
        );
        for (b, field) in [
            (built(DecoderChoice::Eeg, 1.0), "user.accuracy"),
            (built(DecoderChoice::Oracle, 0.5), "user.accuracy"),
            (
                built(DecoderChoice::Eeg, 0.8).bank_per_class(0),
                "bank_per_class",
            ),
        ] {
            let e = b.build().unwrap_err().to_string();
            assert!(e.starts_with("made: field `") && e.contains(field), "{e}");
        }
    }

    const OK: &str = r#"
task = "grid"
[user]
accuracy = 0.7438
[[episode]]
start = [0, 0]
goal = [4, 4]
"#;

    fn err(text: &str) -> String {
        GridScenario::parse(text, Path::new("scenarios/x.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn a_minimal_scenario_gets_the_papers_defaults() {
        let s = GridScenario::parse(OK, Path::new("x.toml")).unwrap();
        assert_eq!(s.params.control.tau, 0.3);
        assert_eq!(s.params.control.p_c, 0.9);
        assert_eq!(s.decoder, DecoderChoice::Eeg);
        assert_eq!(s.episodes, vec![(Cell::new(0, 0), Cell::new(4, 4))]);
    }

    #[test]
    fn every_bad_value_names_file_field_value_and_range() {
        for (text, field, value) in [
            (OK.replace("[0, 0]", "[0, 5]"), "episode[0].start", "[0, 5]"),
            (OK.replace("[4, 4]", "[0, 0]"), "episode[0].goal", "[0, 0]"),
            (OK.replace("0.7438", "1.7"), "user.accuracy", "1.7"),
            (OK.replace("0.7438", "0.5"), "user.accuracy", "0.5"),
            (OK.replace("0.7438", "nan"), "user.accuracy", "NaN"),
            (format!("{OK}[control]\ntau = -1.0\n"), "control.tau", "-1"),
            (format!("{OK}[control]\np_c = 1.0\n"), "control.p_c", "1"),
            (
                format!("{OK}[control]\nepsilon = 2.0\n"),
                "control.epsilon",
                "2",
            ),
            (OK.replace("\"grid\"", "\"maze\""), "task", "maze"),
        ] {
            let e = err(&text);
            assert!(e.contains("scenarios/x.toml"), "{e}");
            assert!(e.contains(field), "{field}: {e}");
            assert!(e.contains(value), "{value}: {e}");
            assert!(e.contains("expected"), "{e}");
        }
    }

    #[test]
    fn unknown_keys_and_subjects_are_rejected() {
        let e = err(&format!("{OK}colour = \"red\"\n"));
        assert!(
            e.contains("colour") && e.contains("scenarios/x.toml"),
            "{e}"
        );
        let e = err(&OK.replace("accuracy = 0.7438", "subject = \"S9\""));
        assert!(
            e.contains("user.subject") && e.contains("S1, S2, S3, S4"),
            "{e}"
        );
    }

    #[test]
    fn the_oracle_may_be_perfect_the_eeg_decoder_may_not() {
        let perfect = OK.replace("0.7438", "1.0");
        assert!(
            GridScenario::parse(&format!("decoder = \"oracle\"\n{perfect}"), Path::new("x"))
                .is_ok()
        );
        assert!(err(&perfect).contains("user.accuracy"));
    }

    #[test]
    fn free_goals_are_drawn_from_the_seed() {
        let text = "task = \"grid\"\nseed = 4\n[user]\nsubject = \"S2\"\ngoals = \"free\"\n[free_goals]\ncount = 5\n";
        let a = GridScenario::parse(text, Path::new("x")).unwrap();
        let b = GridScenario::parse(text, Path::new("x")).unwrap();
        assert_eq!(a.episodes, b.episodes);
        assert_eq!(a.episodes.len(), 5);
        assert!(a.episodes.iter().all(|(s, g)| s != g));
        assert!((a.accuracy.requested().unwrap().get() - 0.8248).abs() < 1e-12);
    }
}
