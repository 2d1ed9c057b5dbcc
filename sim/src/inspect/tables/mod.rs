//! The tidy tables of a recording, one row per observation with a `run`
//! column (runs from 1, as `errp run` numbers them): what `errp inspect
//! --csv` writes and `errp.read_recording` returns as DataFrames.

use std::fmt::Write as _;

use errp_robot::Grid;

use crate::epuck::PHYSICS_DT_SECS;
use crate::inspect::{Recording, Runs};
use crate::record::data::Column;
use crate::record::schema::FramesView;

mod epuck;

use epuck::epuck_tables;

/// One tidy table.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvTable {
    /// Its name (the file is `NAME.csv`).
    pub name: &'static str,
    /// Named columns of equal length.
    pub columns: Vec<(&'static str, Column)>,
}

impl CsvTable {
    /// Rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, c)| c.len())
    }

    /// The table as CSV text: a header, then one line per row. Numbers are
    /// written exactly (the shortest text that reads back to the same
    /// value); a missing number is an empty field.
    pub fn to_csv(&self) -> String {
        let mut out = String::new();
        let names: Vec<&str> = self.columns.iter().map(|(n, _)| *n).collect();
        out.push_str(&names.join(","));
        out.push('\n');
        for i in 0..self.rows() {
            for (k, (_, c)) in self.columns.iter().enumerate() {
                if k > 0 {
                    out.push(',');
                }
                match c {
                    Column::F64(v) if v[i].is_nan() => {}
                    Column::F64(v) => {
                        let _ = write!(out, "{:?}", v[i]);
                    }
                    Column::I64(v) => {
                        let _ = write!(out, "{}", v[i]);
                    }
                    Column::OptI64(v) => {
                        if let Some(x) = v[i] {
                            let _ = write!(out, "{x}");
                        }
                    }
                    Column::Bool(v) => out.push_str(if v[i] { "True" } else { "False" }),
                    Column::Str(v) => out.push_str(&quote(&v[i])),
                    Column::F64Rows(..) => {}
                }
            }
            out.push('\n');
        }
        out
    }
}

/// The key of a Parquet file's metadata that names the errp table it holds
/// (how `errp inspect --parquet` knows a file it may replace).
pub const PARQUET_TABLE_KEY: &str = "errp.table";

impl CsvTable {
    /// The table as a Parquet file (Snappy-compressed, one row group): the
    /// columns of [`CsvTable::to_csv`] with their types (float64, int64,
    /// bool, string); a missing number is null. The file's metadata names
    /// the table under [`PARQUET_TABLE_KEY`].
    pub fn to_parquet(&self) -> Result<Vec<u8>, String> {
        use std::sync::Arc;

        use parquet::arrow::ArrowWriter;
        use parquet::basic::Compression;
        use parquet::file::metadata::KeyValue;
        use parquet::file::properties::WriterProperties;
        use rerun::external::arrow::array::{
            ArrayRef, BooleanArray, Float64Array, Int64Array, RecordBatch, StringArray,
        };
        use rerun::external::arrow::datatypes::{DataType, Field, Schema};

        let mut fields = Vec::new();
        let mut arrays: Vec<ArrayRef> = Vec::new();
        for (name, c) in &self.columns {
            let (kind, array): (DataType, ArrayRef) = match c {
                Column::F64(v) => (
                    DataType::Float64,
                    Arc::new(Float64Array::from_iter(
                        v.iter().map(|&x| (!x.is_nan()).then_some(x)),
                    )),
                ),
                Column::I64(v) => (DataType::Int64, Arc::new(Int64Array::from(v.clone()))),
                Column::OptI64(v) => (DataType::Int64, Arc::new(Int64Array::from(v.clone()))),
                Column::Bool(v) => (DataType::Boolean, Arc::new(BooleanArray::from(v.clone()))),
                Column::Str(v) => (DataType::Utf8, Arc::new(StringArray::from(v.clone()))),
                Column::F64Rows(..) => continue,
            };
            fields.push(Field::new(*name, kind, true));
            arrays.push(array);
        }
        let schema = Arc::new(Schema::new(fields));
        let batch = RecordBatch::try_new(schema.clone(), arrays).map_err(|e| e.to_string())?;
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .set_key_value_metadata(Some(vec![KeyValue::new(
                PARQUET_TABLE_KEY.to_string(),
                self.name.to_string(),
            )]))
            .build();
        let mut out = Vec::new();
        let mut writer =
            ArrowWriter::try_new(&mut out, schema, Some(props)).map_err(|e| e.to_string())?;
        writer.write(&batch).map_err(|e| e.to_string())?;
        writer.close().map_err(|e| e.to_string())?;
        Ok(out)
    }
}

/// A CSV field: quoted when it holds a comma, a quote or a line break.
fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The seconds each run spent turning, driving and stopped, from its
/// frames (one pass over them).
pub fn phase_secs(rec: &Recording) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]; rec.n_runs()];
    let frames = FramesView::or_empty(&rec.tables);
    for (r, p) in frames.run.iter().zip(frames.phase) {
        if let Some(slot) = usize::try_from(*r)
            .ok()
            .and_then(|r| out.get_mut(r))
            .and_then(|run| usize::try_from(*p).ok().and_then(|p| run.get_mut(p)))
        {
            *slot += PHYSICS_DT_SECS;
        }
    }
    out
}

/// Every tidy table of `rec`.
pub fn csv_tables(rec: &Recording) -> Vec<CsvTable> {
    let mut out = task_tables(rec);
    if rec.live.is_some() {
        out.push(decisions_table(rec));
    }
    out
}

/// A live session's decisions as received, one row each: the run, the
/// grid action or device window it was applied to (from 1, as the runs;
/// missing when it was late or stray), and its latency in ms, measured on
/// the bridge's clock.
fn decisions_table(rec: &Recording) -> CsvTable {
    let d = crate::record::schema::LiveDecisionsView::or_empty(&rec.tables);
    CsvTable {
        name: "decisions",
        columns: vec![
            ("run", Column::I64(d.run.iter().map(|r| r + 1).collect())),
            ("t_s", Column::F64(d.t_s.to_vec())),
            ("id", Column::F64(d.id.to_vec())),
            ("p_error", Column::F64(d.p_error.to_vec())),
            (
                "latency_ms",
                Column::F64(d.latency_s.iter().map(|l| l * 1000.0).collect()),
            ),
            ("fate", Column::Str(d.fate.to_vec())),
            (
                "applied_to",
                Column::OptI64(
                    d.applied_to
                        .iter()
                        .map(|&a| (a >= 0).then_some(a + 1))
                        .collect(),
                ),
            ),
        ],
    }
}

/// The task's tables of `rec`.
fn task_tables(rec: &Recording) -> Vec<CsvTable> {
    match &rec.runs {
        Runs::Epuck { scenario, results } => {
            let names: Vec<String> = scenario
                .layout
                .goals()
                .iter()
                .map(|g| g.name.clone())
                .collect();
            epuck_tables(rec, results, &names)
        }
        Runs::Grid { results, .. } => grid_tables(results),
    }
}

fn name_of(names: &[String], i: i64) -> String {
    usize::try_from(i)
        .ok()
        .and_then(|i| names.get(i))
        .cloned()
        .unwrap_or_default()
}

/// One row per grid episode.
fn grid_runs_table(results: &[crate::grid::GridEpisodeResult]) -> CsvTable {
    let n = results.len() as i64;
    let cell_text = |c: errp_robot::Cell| c.to_string();
    CsvTable {
        name: "runs",
        columns: vec![
            ("run", Column::I64((1..=n).collect())),
            (
                "start",
                Column::Str(results.iter().map(|r| cell_text(r.start)).collect()),
            ),
            (
                "goal",
                Column::Str(results.iter().map(|r| cell_text(r.goal)).collect()),
            ),
            (
                "committed",
                Column::Str(
                    results
                        .iter()
                        .map(|r| r.committed.map_or(String::new(), cell_text))
                        .collect(),
                ),
            ),
            (
                "reached",
                Column::Bool(results.iter().map(|r| r.reached()).collect()),
            ),
            (
                "actions",
                Column::I64(results.iter().map(|r| r.actions as i64).collect()),
            ),
            (
                "net_s",
                Column::F64(results.iter().map(|r| r.net_secs).collect()),
            ),
            (
                "total_s",
                Column::F64(results.iter().map(|r| r.total_secs).collect()),
            ),
            (
                "acc_correct",
                Column::F64(results.iter().map(|r| r.online.correct).collect()),
            ),
            (
                "acc_error",
                Column::F64(results.iter().map(|r| r.online.error).collect()),
            ),
        ],
    }
}

fn grid_tables(results: &[crate::grid::GridEpisodeResult]) -> Vec<CsvTable> {
    let grid = Grid::paper();
    let runs = grid_runs_table(results);
    let mut a: (Vec<i64>, Vec<i64>, Vec<f64>) = Default::default();
    let mut cells: [Vec<i64>; 4] = Default::default();
    let mut act = Vec::new();
    let mut flags: [Vec<bool>; 2] = Default::default();
    let mut p = Vec::new();
    // Belief per cell: run, step, time, x, y, p.
    let mut b: (Vec<i64>, Vec<i64>, Vec<f64>) = Default::default();
    let mut b_cell: (Vec<i64>, Vec<i64>, Vec<f64>) = Default::default();
    let mut v: (Vec<i64>, Vec<i64>, Vec<i64>, Vec<i64>) = Default::default();
    for (k, r) in results.iter().enumerate() {
        let run = k as i64 + 1;
        for (j, s) in r.steps.iter().enumerate() {
            a.0.push(run);
            a.1.push(j as i64 + 1);
            a.2.push(s.onset_secs);
            cells[0].push(s.from.x as i64);
            cells[1].push(s.from.y as i64);
            act.push(s.action.name().to_string());
            cells[2].push(s.to.x as i64);
            cells[3].push(s.to.y as i64);
            flags[0].push(s.error);
            p.push(s.p_error);
            flags[1].push(s.decoded_error);
            for (i, &q) in s.belief.iter().enumerate() {
                let c = grid.cell(i);
                b.0.push(run);
                b.1.push(j as i64 + 1);
                b.2.push(s.onset_secs);
                b_cell.0.push(c.x as i64);
                b_cell.1.push(c.y as i64);
                b_cell.2.push(q);
            }
        }
        for (i, &count) in r.visits.iter().enumerate() {
            let c = grid.cell(i);
            v.0.push(run);
            v.1.push(c.x as i64);
            v.2.push(c.y as i64);
            v.3.push(i64::from(count));
        }
    }
    let [fx, fy, tx, ty] = cells;
    let [err, dec] = flags;
    vec![
        runs,
        CsvTable {
            name: "actions",
            columns: vec![
                ("run", Column::I64(a.0)),
                ("step", Column::I64(a.1)),
                ("t_s", Column::F64(a.2)),
                ("from_x", Column::I64(fx)),
                ("from_y", Column::I64(fy)),
                ("action", Column::Str(act)),
                ("to_x", Column::I64(tx)),
                ("to_y", Column::I64(ty)),
                ("error", Column::Bool(err)),
                ("p_error", Column::F64(p)),
                ("decoded_error", Column::Bool(dec)),
            ],
        },
        CsvTable {
            name: "belief",
            columns: vec![
                ("run", Column::I64(b.0)),
                ("step", Column::I64(b.1)),
                ("t_s", Column::F64(b.2)),
                ("x", Column::I64(b_cell.0)),
                ("y", Column::I64(b_cell.1)),
                ("p", Column::F64(b_cell.2)),
            ],
        },
        CsvTable {
            name: "visits",
            columns: vec![
                ("run", Column::I64(v.0)),
                ("x", Column::I64(v.1)),
                ("y", Column::I64(v.2)),
                ("visits", Column::I64(v.3)),
            ],
        },
    ]
}
