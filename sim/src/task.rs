//! What a Monte Carlo driver needs of a task: its scenario and decoder
//! types, the one way to prepare a decoder, one episode as a CSV row, and
//! the columns and labels that describe its results.
//!
//! The grid's `GridTask` and the e-puck's `EpuckTask` implement it; `errp sweep` is
//! written once over it, so a sweep prepares decoders on the path `errp run`
//! takes and a new task needs no change to the sweep.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use errp_bci::Accuracy;

use crate::calibration::TargetingCache;
use crate::error::Result;
use crate::task_kind::TaskKind;

/// The fixed facts of a task: its name, the columns of its episode rows and
/// what its summaries call things.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TaskInfo {
    /// Which task.
    pub kind: TaskKind,
    /// The task's own columns of an episode row, between `success` and the
    /// online accuracy columns, in the order of [`EpisodeRow::fields`].
    pub columns: &'static [EpisodeColumn],
    /// The column of the cost a sweep summarises (over successful episodes).
    pub cost_column: &'static str,
    /// The cost as a table heading, with its unit.
    pub cost_label: &'static str,
    /// A column that is empty when the episode committed to no goal.
    pub committed_column: &'static str,
    /// The columns of the online detector's hit rate and false alarms per
    /// minute, if the task has a detector.
    pub detector_columns: Option<(&'static str, &'static str)>,
    /// Episode rows written between two syncs to disk when the caller does
    /// not choose (about a second of work on two cores).
    pub rows_per_sync: usize,
    /// Short names of sweepable scenario parameters and their dotted keys in
    /// the scenario file; the alias list and its help text derive from it.
    pub sweepable: &'static [(&'static str, &'static str)],
}

/// A column of a task's episode rows: its name and what it may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EpisodeColumn {
    /// The CSV header's name.
    pub name: &'static str,
    /// What a field of it may hold.
    pub kind: ColumnKind,
}

impl EpisodeColumn {
    /// A column `name` of `kind`.
    pub const fn new(name: &'static str, kind: ColumnKind) -> Self {
        Self { name, kind }
    }
}

/// What a field of an episode row may hold: checked when a sweep's rows
/// are read back (a resume, a merge), so a corrupted or edited row is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnKind {
    /// A whole number >= 0.
    Count,
    /// A coordinate of the 5x5 grid, 0 to 4.
    Cell,
    /// A grid coordinate, or empty (no goal).
    OptCell,
    /// A finite number >= 0 (seconds, metres).
    NonNegative,
    /// A number from 0 to 1, or empty (undefined).
    OptRate,
    /// A finite number >= 0, or empty (undefined).
    OptNonNegative,
    /// One of the 25 cities.
    City,
    /// One of the 25 cities, or empty (no goal).
    OptCity,
}

impl ColumnKind {
    /// What the kind accepts, for error messages.
    pub fn expected(self) -> &'static str {
        match self {
            ColumnKind::Count => "a whole number >= 0",
            ColumnKind::Cell => "a grid coordinate from 0 to 4",
            ColumnKind::OptCell => "a grid coordinate from 0 to 4, or empty (no goal)",
            ColumnKind::NonNegative => "a number >= 0",
            ColumnKind::OptRate => "a number from 0 to 1, or empty (undefined)",
            ColumnKind::OptNonNegative => "a number >= 0, or empty (undefined)",
            ColumnKind::City => "one of the 25 cities",
            ColumnKind::OptCity => "one of the 25 cities, or empty (no goal)",
        }
    }

    /// True if `text` is a field of this kind, written as the sweep writes
    /// it.
    pub fn accepts(self, text: &str) -> bool {
        let count = |t: &str| t.bytes().all(|b| b.is_ascii_digit()) && t.parse::<u64>().is_ok();
        let number = |t: &str| t.parse::<f64>().ok().filter(|x| x.is_finite());
        let cell = |t: &str| t.len() == 1 && (b'0'..=b'4').contains(&t.as_bytes()[0]);
        let city = |t: &str| {
            static NAMES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
            NAMES
                .get_or_init(|| {
                    errp_robot::GoalLayout::cities()
                        .names()
                        .iter()
                        .map(|n| n.to_string())
                        .collect()
                })
                .iter()
                .any(|n| n == t)
        };
        match self {
            ColumnKind::Count => count(text),
            ColumnKind::Cell => cell(text),
            ColumnKind::OptCell => text.is_empty() || cell(text),
            ColumnKind::NonNegative => number(text).is_some_and(|x| x >= 0.0),
            ColumnKind::OptRate => {
                text.is_empty() || number(text).is_some_and(|x| (0.0..=1.0).contains(&x))
            }
            ColumnKind::OptNonNegative => text.is_empty() || number(text).is_some_and(|x| x >= 0.0),
            ColumnKind::City => city(text),
            ColumnKind::OptCity => text.is_empty() || city(text),
        }
    }
}

/// The calibrated decoder behind one or more levels of a sweep, as
/// `sweep.json` lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DecoderInfo {
    /// Requested accuracy (on own EEG: the cross-validated one it
    /// gives, which the control assumes).
    pub accuracy: f64,
    /// `lda` (grid EEG), `svm` (e-puck) or `oracle`.
    pub kind: String,
    /// Seed of its calibration session.
    pub calibration_seed: u64,
    /// ErrP-to-noise ratio found by targeting.
    pub errp_to_noise: Option<f64>,
    /// Cross-validated correct-class rate of the calibration session.
    pub cv_correct: Option<f64>,
    /// Cross-validated error-class rate.
    pub cv_error: Option<f64>,
    /// Their mean: the accuracy reached.
    pub cv_mean: Option<f64>,
    /// E-puck: the detector's hit rate per ErrP on the held-out session.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub online_hit_rate: Option<f64>,
    /// E-puck: its false alarms per minute of error-free time there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub online_false_alarms_per_min: Option<f64>,
    /// A person's own EEG, when the decoder was calibrated on it: its
    /// name, size and SHA-256 (a sweep resumed on another file is refused
    /// by it).
    #[serde(default, rename = "recording", skip_serializing_if = "Option::is_none")]
    pub own_eeg: Option<crate::files::FileDigest>,
    /// True if the targeting came from the cache (not written to disk).
    #[serde(skip)]
    pub cached: bool,
}

/// One episode's outcome, as a sweep writes it.
#[derive(Debug, Clone, PartialEq)]
pub struct EpisodeRow {
    /// Converged on the user's goal.
    pub success: bool,
    /// The values of [`TaskInfo::columns`], formatted.
    pub fields: Vec<String>,
    /// The decoder's accuracy over the episode's decisions.
    pub online: Accuracy,
}

impl EpisodeRow {
    /// The row's fields as `episodes.csv` writes them, from `success` to
    /// `online_accuracy` (the columns of [`TaskInfo::row_columns`]).
    pub fn csv_fields(self) -> Vec<String> {
        let (_, _, acc) = overall(&self.online);
        let mut f = Vec::with_capacity(self.fields.len() + 4);
        f.push(u8::from(self.success).to_string());
        f.extend(self.fields);
        f.extend([
            rate_field(self.online.correct),
            rate_field(self.online.error),
            rate_field(acc),
        ]);
        f
    }
}

impl TaskInfo {
    /// The columns of an episode's row from `success` to `online_accuracy`:
    /// what [`EpisodeRow::csv_fields`] fills.
    pub fn row_columns(&self) -> Vec<&'static str> {
        let mut cols = vec!["success"];
        cols.extend(self.columns.iter().map(|c| c.name));
        cols.extend(["acc_correct", "acc_error", "online_accuracy"]);
        cols
    }
}

/// A result the paper reports, drawn beside a sweep's curves.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperPoint {
    /// What the point is (e.g. "S1 fixed"); not drawn, all paper points
    /// share one legend entry.
    pub label: String,
    /// The decoder accuracy the paper reports.
    pub accuracy: f64,
    /// The cost the paper reports, in the unit of the figure's cost axis.
    pub value: f64,
    /// Its standard deviation, drawn as an error bar when given.
    pub sd: Option<f64>,
}

/// The words and paper points of a sweep figure of one scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureText {
    /// The task, as the title starts (`Grid task`).
    pub task: String,
    /// The decoder, for the title.
    pub decoder: String,
    /// The cost axis.
    pub cost_label: String,
    /// What the paper reports for this scenario.
    pub paper: Vec<PaperPoint>,
    /// The legend entry of those points.
    pub paper_label: String,
}

/// A task a Monte Carlo driver can run: levels of one scenario file, each
/// with its decoder prepared once and many seeded episodes.
pub trait Task: 'static {
    /// Its fixed facts.
    const INFO: TaskInfo;
    /// A validated scenario of the task.
    type Scenario: Send + Sync + 'static;
    /// What the decoders of several scenarios share (simulated once).
    type Shared: Sync;
    /// A prepared decoder, shared by the levels with equal
    /// [`decoder_key`](Self::decoder_key)s.
    type Decoder: Send + Sync;
    /// One level, ready to run episodes.
    type Runner: Send + Sync;

    /// What the scenario's decoder depends on: scenarios with equal keys
    /// share one decoder.
    fn decoder_key(scenario: &Self::Scenario) -> String;

    /// What the decoders of `scenarios` can share.
    fn shared(scenarios: &[&Self::Scenario]) -> Result<Self::Shared>;

    /// Prepares the scenario's decoder on the path `errp run` takes, with
    /// `cache` for the accuracy targeting.
    fn prepare(
        scenario: &Self::Scenario,
        shared: &Self::Shared,
        cache: &dyn TargetingCache,
    ) -> Result<(Self::Decoder, DecoderInfo)>;

    /// A level of `scenario` with its prepared decoder.
    fn runner(scenario: &Self::Scenario, decoder: Arc<Self::Decoder>) -> Result<Self::Runner>;

    /// Runs episode `k` of a level from `seed`.
    fn run_episode(runner: &Self::Runner, k: usize, seed: u64) -> Result<EpisodeRow>;

    /// Checks what the task knows of episode `k`'s row before running it
    /// (its start and goal) and how its fields must agree (`success` is 1
    /// exactly when the committed goal is the user's), for a row read back
    /// from disk. `fields` are the task's columns, each already of its
    /// [`ColumnKind`]. The error names the column and what it must be.
    fn check_fields(
        scenario: &Self::Scenario,
        k: usize,
        success: bool,
        fields: &[&str],
    ) -> std::result::Result<(), FieldError>;

    /// The words and paper points of a figure of `scenario`'s sweep.
    fn figure(scenario: &Self::Scenario) -> FigureText;

    /// About how many bytes a prepared decoder of `scenario` holds while a
    /// sweep runs (its epoch bank, say), so that a sweep too large for
    /// memory is refused before it starts. Small decoders: 0.
    fn decoder_bytes(_scenario: &Self::Scenario) -> usize {
        0
    }
}

/// A field of a row read back that is not what it must be.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldError {
    /// The column.
    pub column: &'static str,
    /// What it must be.
    pub expected: String,
}

/// A rate as a CSV field: empty when undefined.
pub fn rate_field(x: f64) -> String {
    if x.is_finite() {
        format_number(x)
    } else {
        String::new()
    }
}

/// A float in its shortest exact form (`0.3`, `1`, `0.7438`), as CSV files
/// and labels write it.
pub fn format_number(x: f64) -> String {
    format!("{x}")
}

/// A share (0 to 1) as an English ordinal percentile: `0.213` is "21st",
/// `0.5` "50th", `0.125` "13th"; "-" for NaN.
pub fn ordinal_percent(share: f64) -> String {
    if !share.is_finite() {
        return "-".into();
    }
    let n = (100.0 * share).round() as i64;
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

/// Correct decisions of an accuracy's two classes: (hits on errors, hits on
/// correct actions, their fraction of all decisions; NaN with none).
pub fn overall(a: &Accuracy) -> (usize, usize, f64) {
    let hits_error = (a.error * a.n_error as f64).round() as usize;
    let hits_correct = (a.correct * a.n_correct as f64).round() as usize;
    let n = a.n_error + a.n_correct;
    let acc = if n == 0 {
        f64::NAN
    } else {
        (hits_error + hits_correct) as f64 / n as f64
    };
    (hits_error, hits_correct, acc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinals() {
        let o = ordinal_percent;
        assert_eq!(
            [
                o(0.0),
                o(0.01),
                o(0.02),
                o(0.03),
                o(0.11),
                o(0.12),
                o(0.213),
                o(0.5),
                o(1.0)
            ],
            [
                "0th", "1st", "2nd", "3rd", "11th", "12th", "21st", "50th", "100th"
            ]
        );
        assert_eq!(o(f64::NAN), "-");
    }
}
