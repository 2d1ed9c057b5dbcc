//! The data tables of a recording, declared once: each table's entity path
//! and its columns with their types, in the order written. A writer (`epuck::view`,
//! `grid::view`) fills a table's struct, one vector per column, and sends
//! it as one chunk (its `send`); the reader
//! (`inspect`) gets the same columns back as a view of borrowed slices
//! ([`EpuckRunsView::of`] and the like), each checked for its name, its
//! type and its length. A column's name and type live here and nowhere
//! else.
//!
//! The tables, by entity path (columns in the order written):
//!
//! | entity | task | one row per | columns |
//! |---|---|---|---|
//! | `/errp/runs` | both | run, at its start | `run`, `seed`, `goal`, `start_x`, `start_y`, `start_heading_deg` (e-puck, cm), `t_e`, `detection_from_s`, `detection_to_s`, `window_from_s`, `window_to_s` (e-puck); `goal_x`, `goal_y`, `epoch_s` (grid, cells; `goal` is the cell index) |
//! | `/errp/frames` | e-puck | physics step (64 Hz) | `run`, `t_s`, `x_cm`, `y_cm`, `heading_deg`, `tracked_x_cm`, `tracked_y_cm`, `phase` (0 turning, 1 driving, 2 stopped), `target` |
//! | `/errp/windows` | e-puck | decoder window (16 Hz) | `run`, `t_s`, `p_error`, `evidence`, `detected`, `step` (0 turn, 1 linear, 2 stopped on a goal, 3 idle), `target`, `belief` (one value per goal) |
//! | `/errp/errps` | e-puck | ErrP of the user | `run`, `t_s` (seen), `onset_s`, `phase` |
//! | `/errp/actions` | grid | action | `run`, `t_s` (onset), `from_x`, `from_y`, `action`, `to_x`, `to_y`, `error`, `p_error` (NaN: a live decision missed, not scored), `decoded_error`, `belief` (one value per cell) |
//! | `/errp/ends` | both | run, at its end | `run`, `t_s`, `committed` (goal index, -1 for none; the grid: cell index) |
//! | `/errp/events` | e-puck | event of the log | `run`, `t_s`, `warn`, `text` |
//! | `/errp/decisions` | both, live (`errp stream`) | decision received from the decoder | `run`, `t_s` (arrival, on the run's simulated clock), `id` (as sent: the action, or the window's last timestamp), `p_error`, `latency_s` (link clock, from the action's onset or the window's end; NaN for a stray one), `fate` (`applied`, `late`, `stray`), `applied_to` (the run's action or device window, from 0; -1 if not applied) |

use std::collections::BTreeMap;

use rerun::external::arrow::array::{
    ArrayRef, BooleanArray, Float64Array, Int64Array, StringArray,
};
use rerun::{ComponentDescriptor, RecordingStream, SerializedComponentBatch};

use crate::record::data::{Column, Table};
use crate::record::{SIM_TIME, paths};

/// The owned type of a column of `kind`.
macro_rules! owned {
    (F64) => { Vec<f64> };
    (I64) => { Vec<i64> };
    (Bool) => { Vec<bool> };
    (Str) => { Vec<String> };
    (Rows) => { (Vec<f64>, usize) };
}

/// The borrowed type of a column of `kind`.
macro_rules! borrowed {
    ($a:lifetime, F64) => {
        &$a[f64]
    };
    ($a:lifetime, I64) => {
        &$a[i64]
    };
    ($a:lifetime, Bool) => {
        &$a[bool]
    };
    ($a:lifetime, Str) => {
        &$a[String]
    };
    ($a:lifetime, Rows) => {
        (&$a[f64], usize)
    };
}

/// A column of `kind` as sent.
macro_rules! to_column {
    (F64, $v:expr) => {
        Column::F64($v)
    };
    (I64, $v:expr) => {
        Column::I64($v)
    };
    (Bool, $v:expr) => {
        Column::Bool($v)
    };
    (Str, $v:expr) => {
        Column::Str($v)
    };
    (Rows, $v:expr) => {{
        let (values, width) = $v;
        Column::F64Rows(values, width)
    }};
}

/// A column read back as `kind`, or what it is instead.
macro_rules! from_column {
    (F64, $c:expr) => {
        match $c {
            Column::F64(v) => Ok(&v[..]),
            _ => Err("numbers"),
        }
    };
    (I64, $c:expr) => {
        match $c {
            Column::I64(v) => Ok(&v[..]),
            _ => Err("integers"),
        }
    };
    (Bool, $c:expr) => {
        match $c {
            Column::Bool(v) => Ok(&v[..]),
            _ => Err("flags"),
        }
    };
    (Str, $c:expr) => {
        match $c {
            Column::Str(v) => Ok(&v[..]),
            _ => Err("text"),
        }
    };
    (Rows, $c:expr) => {
        match $c {
            Column::F64Rows(v, w) => Ok((&v[..], *w)),
            _ => Err("rows of numbers"),
        }
    };
}

/// An empty column of `kind`.
macro_rules! empty {
    (Rows) => {
        (&[][..], 0)
    };
    ($kind:ident) => {
        &[]
    };
}

/// Declares the tables: for each, the owned struct the writer fills and
/// the view the reader gets.
macro_rules! tables {
    ($(
        $(#[$doc:meta])*
        $name:ident, $view:ident at $entity:expr => { $( $col:ident: $kind:ident ),* $(,)? }
    )*) => {$(
        $(#[$doc])*
        #[derive(Debug, Clone, Default, PartialEq)]
        pub struct $name {
            $(
                #[doc = concat!("Column `", stringify!($col), "`.")]
                pub $col: owned!($kind),
            )*
        }

        impl $name {
            /// The table's entity path.
            pub const ENTITY: &'static str = $entity;
            /// The column names, in the order written.
            pub const COLUMNS: &'static [&'static str] = &[$(stringify!($col)),*];

            /// Sends the rows as one chunk, at `times` (s) on the
            /// `sim_time` timeline; nothing when there are none.
            pub(crate) fn send(
                self,
                rec: &RecordingStream,
                times: &[f64],
            ) -> Result<(), rerun::RecordingStreamError> {
                send_table(rec, Self::ENTITY, times, vec![
                    $( (stringify!($col), to_column!($kind, self.$col)) ),*
                ])
            }
        }

        #[doc = concat!("[`", stringify!($name), "`] read back: its columns borrowed from a recording's table.")]
        #[derive(Debug, Clone, Copy)]
        pub struct $view<'a> {
            /// Rows.
            pub rows: usize,
            $(
                #[doc = concat!("Column `", stringify!($col), "`.")]
                pub $col: borrowed!('a, $kind),
            )*
        }

        impl<'a> $view<'a> {
            /// The table in `tables`, checked: every column present, of
            /// its type and of the table's length. The error says what is
            /// wrong.
            pub fn of(tables: &'a BTreeMap<String, Table>) -> Result<Self, String> {
                let table = tables
                    .get($entity)
                    .ok_or_else(|| format!("it has no table {}", $entity))?;
                Self::read(table)
            }

            /// [`Self::of`], with no rows when the table is absent (a run
            /// may have none of its rows).
            pub fn of_or_empty(tables: &'a BTreeMap<String, Table>) -> Result<Self, String> {
                match tables.get($entity) {
                    Some(table) => Self::read(table),
                    None => Ok(Self::empty()),
                }
            }

            /// The table in `tables`, or no rows when it is absent or does
            /// not fit the schema (for tables `Recording::open` has
            /// checked).
            pub fn or_empty(tables: &'a BTreeMap<String, Table>) -> Self {
                Self::of_or_empty(tables).unwrap_or_else(|_| Self::empty())
            }

            /// No rows.
            pub fn empty() -> Self {
                Self { rows: 0, $( $col: empty!($kind), )* }
            }

            fn read(table: &'a Table) -> Result<Self, String> {
                let rows = table.rows();
                Ok(Self {
                    rows,
                    $( $col: {
                        let name = stringify!($col);
                        let column = table.column(name).ok_or_else(|| {
                            format!("its table {} has no column `{name}`", $entity)
                        })?;
                        if column.len() != rows {
                            return Err(format!(
                                "its table {} has columns of different lengths",
                                $entity
                            ));
                        }
                        from_column!($kind, column).map_err(|what| {
                            format!("column `{name}` of {} is not {what}", $entity)
                        })?
                    }, )*
                })
            }
        }
    )*};
}

tables! {
    /// `/errp/runs` of an e-puck recording: one row per run, at its start
    /// (positions in cm).
    EpuckRuns, EpuckRunsView at paths::RUNS => {
        run: I64,
        seed: I64,
        goal: I64,
        start_x: F64,
        start_y: F64,
        start_heading_deg: F64,
        t_e: F64,
        detection_from_s: F64,
        detection_to_s: F64,
        window_from_s: F64,
        window_to_s: F64,
    }

    /// `/errp/runs` of a grid recording: one row per episode, at its start
    /// (cells; `goal` is the cell index).
    GridRuns, GridRunsView at paths::RUNS => {
        run: I64,
        seed: I64,
        goal: I64,
        start_x: I64,
        start_y: I64,
        goal_x: I64,
        goal_y: I64,
        epoch_s: F64,
    }

    /// `/errp/frames`: one row per physics step of the e-puck (64 Hz).
    Frames, FramesView at paths::FRAMES => {
        run: I64,
        t_s: F64,
        x_cm: F64,
        y_cm: F64,
        heading_deg: F64,
        tracked_x_cm: F64,
        tracked_y_cm: F64,
        phase: I64,
        target: I64,
    }

    /// `/errp/windows`: one row per decoder window of the e-puck (16 Hz),
    /// `belief` one value per goal.
    Windows, WindowsView at paths::WINDOWS => {
        run: I64,
        t_s: F64,
        p_error: F64,
        evidence: F64,
        detected: Bool,
        step: I64,
        target: I64,
        belief: Rows,
    }

    /// `/errp/errps`: one row per ErrP of the e-puck's user (`t_s` when
    /// seen).
    Errps, ErrpsView at paths::ERRPS => {
        run: I64,
        t_s: F64,
        onset_s: F64,
        phase: I64,
    }

    /// `/errp/events`: one row per event of the e-puck's log.
    Events, EventsView at paths::EVENTS => {
        run: I64,
        t_s: F64,
        warn: Bool,
        text: Str,
    }

    /// `/errp/actions`: one row per grid action (`t_s` its onset),
    /// `belief` one value per cell.
    Actions, ActionsView at paths::ACTIONS => {
        run: I64,
        t_s: F64,
        from_x: I64,
        from_y: I64,
        action: Str,
        to_x: I64,
        to_y: I64,
        error: Bool,
        p_error: F64,
        decoded_error: Bool,
        belief: Rows,
    }

    /// `/errp/decisions` of a live session: one row per decision
    /// received, in order of arrival (`t_s` on the run's simulated clock).
    LiveDecisions, LiveDecisionsView at paths::DECISIONS => {
        run: I64,
        t_s: F64,
        id: F64,
        p_error: F64,
        latency_s: F64,
        fate: Str,
        applied_to: I64,
    }

    /// `/errp/ends`: one row per run, at its end (`committed`: the goal
    /// index, or the grid's cell index; -1 for none).
    Ends, EndsView at paths::ENDS => {
        run: I64,
        t_s: F64,
        committed: I64,
    }
}

/// Sends one table (one run's rows) as a chunk of `entity`: `times` are the
/// rows' positions on the `sim_time` timeline (s), and every column has as
/// many rows.
fn send_table(
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
            Column::OptI64(v) => (std::sync::Arc::new(Int64Array::from(v)), 1),
            Column::Bool(v) => (std::sync::Arc::new(BooleanArray::from(v)), 1),
            Column::Str(v) => (std::sync::Arc::new(StringArray::from(v)), 1),
            Column::F64Rows(v, w) => (std::sync::Arc::new(Float64Array::from(v)), w),
        };
        let batch = SerializedComponentBatch::new(array, ComponentDescriptor::partial(name));
        out.push(batch.partitioned(std::iter::repeat_n(width, rows))?);
    }
    rec.send_columns(entity, [time], out)
}
