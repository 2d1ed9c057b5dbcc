//! The data a recording carries beside what the viewer draws: how it was
//! made ([`Provenance`], a static JSON document at [`PROVENANCE`](crate::record::paths::PROVENANCE)) and, for
//! every run, tables of what happened (one Rerun chunk per table and run,
//! sent with `send_columns` on the `sim_time` timeline, each row also
//! holding its `run` and its time `t_s` within the run). `errp inspect` and
//! `errp.read_recording` read them back (the `inspect` module) and recompute
//! each run's result from them.
//!
//! The tables, by entity path (columns in the order written):
//!
//! | entity | task | one row per | columns |
//! |---|---|---|---|
//! | `/errp/runs` | both | run, at its start | `run`, `seed`, `goal`, `start_x`, `start_y`, `start_heading_deg` (e-puck, cm), `t_e`, `detection_from_s`, `detection_to_s`, `window_from_s`, `window_to_s` (e-puck); `goal_x`, `goal_y`, `epoch_s` (grid, cells; `goal` is the cell index) |
//! | `/errp/frames` | e-puck | physics step (64 Hz) | `run`, `t_s`, `x_cm`, `y_cm`, `heading_deg`, `tracked_x_cm`, `tracked_y_cm`, `phase` (0 turning, 1 driving, 2 stopped), `target` |
//! | `/errp/windows` | e-puck | decoder window (16 Hz) | `run`, `t_s`, `p_error`, `evidence`, `detected`, `step` (0 turn, 1 linear, 2 stopped on a goal, 3 idle), `target`, `belief` (one value per goal) |
//! | `/errp/errps` | e-puck | ErrP of the user | `run`, `t_s` (seen), `onset_s`, `phase` |
//! | `/errp/actions` | grid | action | `run`, `t_s` (onset), `from_x`, `from_y`, `action`, `to_x`, `to_y`, `error`, `p_error`, `decoded_error`, `belief` (one value per cell) |
//! | `/errp/ends` | both | run, at its end | `run`, `t_s`, `committed` (goal index, -1 for none; the grid: cell index) |
//! | `/errp/events` | e-puck | event of the log | `run`, `t_s`, `warn`, `text` |

use rerun::external::arrow::array::{
    ArrayRef, BooleanArray, Float64Array, Int64Array, StringArray,
};
use rerun::{ComponentDescriptor, RecordingStream, SerializedComponentBatch};
use serde::{Deserialize, Serialize};

use crate::record::{RrdFile, SIM_TIME, paths, record_error};

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
    /// `"epuck"` or `"grid"`.
    pub task: String,
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
}

impl Provenance {
    /// The provenance of a recording of `task` made now by this build.
    pub fn new(task: &str, scenario_name: &str, scenario_text: String, seed: u64) -> Self {
        Self {
            format: FORMAT.into(),
            format_version: FORMAT_VERSION,
            errp_version: env!("CARGO_PKG_VERSION").into(),
            commit: "unknown".into(),
            task: task.into(),
            scenario_name: scenario_name.into(),
            scenario_text,
            seed,
            runs: 0,
            command: Vec::new(),
            decoder_summary: String::new(),
            agent: None,
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

/// Sends one table (one run's rows) as a chunk of `entity`: `times` are the
/// rows' positions on the `sim_time` timeline (s), and every column has as
/// many rows.
pub(crate) fn send_table(
    rec: &RecordingStream,
    entity: &str,
    times: &[f64],
    columns: Vec<(&'static str, Column)>,
) -> Result<(), rerun::RecordingStreamError> {
    if times.is_empty() {
        return Ok(());
    }
    let time = rerun::log::TimeColumn::new_duration_secs(SIM_TIME, times.iter().copied());
    let mut out = Vec::with_capacity(columns.len());
    for (name, column) in columns {
        let rows = column.len();
        let (array, width): (ArrayRef, usize) = match column {
            Column::F64(v) => (std::sync::Arc::new(Float64Array::from(v)), 1),
            Column::I64(v) => (std::sync::Arc::new(Int64Array::from(v)), 1),
            Column::Bool(v) => (std::sync::Arc::new(BooleanArray::from(v)), 1),
            Column::Str(v) => (std::sync::Arc::new(StringArray::from(v)), 1),
            Column::F64Rows(v, w) => (std::sync::Arc::new(Float64Array::from(v)), w),
        };
        let batch = SerializedComponentBatch::new(array, ComponentDescriptor::partial(name));
        out.push(batch.partitioned(std::iter::repeat_n(width, rows))?);
    }
    rec.send_columns(entity, [time], out)
}
