//! The data a recording carries beside what the viewer draws: how it was
//! made ([`Provenance`], a static JSON document at [`PROVENANCE`](crate::record::paths::PROVENANCE)) and, for
//! every run, tables of what happened (one Rerun chunk per table and run,
//! sent with `send_columns` on the `sim_time` timeline, each row also
//! holding its `run` and its time `t_s` within the run). `errp inspect` and
//! `errp.read_recording` read them back (the `inspect` module) and recompute
//! each run's result from them.
//!
//! The tables, their columns and types are declared once, in the
//! `schema` module beside this one.

use rerun::RecordingStream;
use serde::{Deserialize, Serialize};

use crate::pace::Speed;
use crate::record::{RrdFile, paths, record_error};
use crate::task_kind::TaskKind;

/// [`Provenance::format`] of the recordings this build writes.
pub const FORMAT: &str = "errp-recording";
/// [`Provenance::format_version`] this build writes and reads.
pub const FORMAT_VERSION: u32 = 1;

/// How a recording was made: enough to make it again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`] when written.
    pub format_version: u32,
    /// The errp version that wrote it.
    pub errp_version: String,
    /// The source commit it was built from ("unknown" outside git).
    pub commit: String,
    /// The task (`"epuck"` or `"grid"`).
    pub task: TaskKind,
    /// The scenario's name.
    pub scenario_name: String,
    /// The scenario file as run: its text with the command line's overrides
    /// set (`--accuracy`, `--decoder`, ...).
    pub scenario_text: String,
    /// The seed of the runs (after `--seed`).
    pub seed: u64,
    /// Runs (e-puck) or episodes (grid) recorded.
    pub runs: usize,
    /// The command line or call that made it.
    pub command: Vec<String>,
    /// The decoder's calibration, as `errp run` printed it.
    pub decoder_summary: String,
    /// Set when an agent of the caller's own chose the actions (a
    /// Gymnasium environment of `errp.gym`), not the shared control: what
    /// drove them. Each run's seed is in `/errp/runs`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agent: Option<String>,
    /// Set when the EEG was the user's own (`[eeg] recording = ...`): the
    /// file's name, size and SHA-256 (under the key `eeg_recording`).
    #[serde(
        default,
        rename = "eeg_recording",
        skip_serializing_if = "Option::is_none"
    )]
    pub own_eeg: Option<crate::files::FileDigest>,
    /// Set when a decoder outside the process decided, live (`errp
    /// stream`): how. The decisions are in `/errp/decisions`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub live: Option<LiveProvenance>,
}

/// How a live session ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LiveProvenance {
    /// Simulated seconds per second of the link's clock.
    pub speed: Speed,
    /// The decoder's stream, as `--decisions` found it (`name=...`).
    pub decoder: String,
}

impl Provenance {
    /// The provenance of a recording of `task` made now by this build.
    pub fn new(task: TaskKind, scenario_name: &str, scenario_text: String, seed: u64) -> Self {
        Self {
            format: FORMAT.into(),
            format_version: FORMAT_VERSION,
            errp_version: env!("CARGO_PKG_VERSION").into(),
            commit: "unknown".into(),
            task,
            scenario_name: scenario_name.into(),
            scenario_text,
            seed,
            runs: 0,
            command: Vec::new(),
            decoder_summary: String::new(),
            agent: None,
            own_eeg: None,
            live: None,
        }
    }

    /// Logs the document, static, at [`PROVENANCE`](crate::record::paths::PROVENANCE) (a text document the
    /// viewer shows).
    pub fn log(&self, rec: &RecordingStream) -> Result<(), rerun::RecordingStreamError> {
        let json = serde_json::to_string_pretty(self).unwrap_or_default();
        rec.log_static(paths::PROVENANCE, &rerun::TextDocument::new(json))
    }

    /// [`Provenance::log`] into `file`, with `runs` set, its error naming
    /// the file.
    pub fn write(&self, file: &RrdFile, runs: usize) -> crate::Result<()> {
        let mut p = self.clone();
        p.runs = runs;
        p.log(file.stream()).map_err(record_error(file.path()))
    }
}

/// One column of a table.
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// Floating-point values.
    F64(Vec<f64>),
    /// Integers.
    I64(Vec<i64>),
    /// Integers, some missing (an empty CSV field, a Parquet null, a
    /// pandas `Int64` NA): a decision's action or window when it was not
    /// applied.
    OptI64(Vec<Option<i64>>),
    /// Flags.
    Bool(Vec<bool>),
    /// Text.
    Str(Vec<String>),
    /// A list of `width` values per row, flattened.
    F64Rows(Vec<f64>, usize),
}

impl Column {
    /// Rows in the column.
    pub fn len(&self) -> usize {
        match self {
            Column::F64(v) => v.len(),
            Column::I64(v) => v.len(),
            Column::OptI64(v) => v.len(),
            Column::Bool(v) => v.len(),
            Column::Str(v) => v.len(),
            Column::F64Rows(v, w) => v.len().checked_div(*w).unwrap_or(0),
        }
    }

    /// True if it has no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One table: named columns of equal length, in the order written.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// The columns.
    pub columns: Vec<(String, Column)>,
}

impl Table {
    /// Rows in the table.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, c)| c.len())
    }

    /// The column `name`, if present.
    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|(n, _)| n == name).map(|(_, c)| c)
    }

    pub(crate) fn append(&mut self, name: &str, column: Column) -> Result<(), String> {
        match self.columns.iter_mut().find(|(n, _)| n == name) {
            None => {
                self.columns.push((name.to_string(), column));
                Ok(())
            }
            Some((_, have)) => match (have, column) {
                (Column::F64(a), Column::F64(b)) => {
                    a.extend(b);
                    Ok(())
                }
                (Column::I64(a), Column::I64(b)) => {
                    a.extend(b);
                    Ok(())
                }
                (Column::OptI64(a), Column::OptI64(b)) => {
                    a.extend(b);
                    Ok(())
                }
                (Column::Bool(a), Column::Bool(b)) => {
                    a.extend(b);
                    Ok(())
                }
                (Column::Str(a), Column::Str(b)) => {
                    a.extend(b);
                    Ok(())
                }
                (Column::F64Rows(a, w), Column::F64Rows(b, v)) if *w == v => {
                    a.extend(b);
                    Ok(())
                }
                _ => Err(format!("column `{name}` changes type between chunks")),
            },
        }
    }
}
