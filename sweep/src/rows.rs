//! The columns of `episodes.csv`, one episode's row, and the check of a row
//! read back from disk.
//!
//! Every row ends with `crc32`: the CRC-32 (IEEE, 8 hex digits) of the row's
//! text before it. A resume or a merge checks every field of every row
//! (its type and range, the level, episode and seed it must have, what the
//! task knows of it) and the checksum, so a row cut short, edited or
//! damaged on disk is found, never kept.

use errp_sim::task::{FieldError, Task};
use errp_sim::{Result, SimError};

use crate::spec::{Level, SweepSpec, value_text};
use errp_sim::task::format_number;

/// The name of the last column.
pub const CHECKSUM: &str = "crc32";

/// The longest row read back, in bytes (a row is about 100 bytes).
pub(crate) const MAX_ROW_BYTES: usize = 64 * 1024;

/// The header of `episodes.csv` for `spec`.
pub fn episodes_header(spec: &SweepSpec) -> String {
    let mut cols = vec!["level".to_string(), "accuracy".into()];
    cols.extend(spec.axes.iter().map(|a| a.name.clone()));
    cols.extend(["episode", "seed"].map(String::from));
    cols.extend(spec.task.info().row_columns().into_iter().map(String::from));
    cols.push(CHECKSUM.to_string());
    cols.join(",")
}

/// `text` with its checksum field appended.
fn with_checksum(text: String) -> String {
    let crc = crc32fast::hash(text.as_bytes());
    format!("{text},{crc:08x}")
}

/// Runs episode `k` of `level` and formats its CSV row.
pub(crate) fn run_row<T: Task>(
    spec: &SweepSpec,
    level: &Level,
    runner: &T::Runner,
    k: usize,
) -> Result<String> {
    let seed = spec.level_episode_seed(level, k);
    let mut f = vec![level.index.to_string(), format_number(level.accuracy)];
    f.extend(level.values.iter().map(value_text));
    f.extend([k.to_string(), seed.to_string()]);
    let row = T::run_episode(runner, k, seed)?;
    if row.fields.len() != T::INFO.columns.len() {
        return Err(SimError::Sweep(format!(
            "the {} task gave {} fields for its {} columns",
            T::INFO.kind,
            row.fields.len(),
            T::INFO.columns.len()
        )));
    }
    f.extend(row.csv_fields());
    Ok(with_checksum(f.join(",")))
}

/// What is wrong with a row read back: the column and what it must hold
/// (`column` is empty for the row as a whole).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct RowFault {
    pub(crate) column: String,
    pub(crate) value: String,
    pub(crate) expected: String,
}

impl RowFault {
    /// What is wrong, in words.
    pub(crate) fn describe(&self) -> String {
        if self.column.is_empty() {
            format!("the row is invalid: {}", self.expected)
        } else {
            format!(
                "field `{}` = {:?} is invalid: expected {}",
                self.column, self.value, self.expected
            )
        }
    }

    /// The fault as an error of `path` at `line`, with what to do.
    pub(crate) fn error(&self, path: &std::path::Path, line: usize, fix: &str) -> SimError {
        SimError::Sweep(format!(
            "{} line {line}: {}; {fix}",
            path.display(),
            self.describe()
        ))
    }
}

/// Checks the rows of one sweep as they are read back from disk.
pub(crate) struct RowCheck<'a, T: Task> {
    spec: &'a SweepSpec,
    levels: &'a [Level],
    scenarios: Vec<&'a T::Scenario>,
    columns: Vec<String>,
}

impl<'a, T: Task> RowCheck<'a, T> {
    /// A check of `spec`'s rows; `levels` are its levels.
    pub(crate) fn new(spec: &'a SweepSpec, levels: &'a [Level]) -> Result<Self> {
        let scenarios = levels
            .iter()
            .map(|l| {
                l.scenario.get::<T::Scenario>().ok_or_else(|| {
                    SimError::Sweep(format!(
                        "{} is not a {} scenario",
                        spec.scenario_path.display(),
                        T::INFO.kind
                    ))
                })
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            spec,
            levels,
            scenarios,
            columns: episodes_header(spec).split(',').map(String::from).collect(),
        })
    }

    /// Checks `text` (without its newline), which must be the row of sweep
    /// episode `g`.
    pub(crate) fn check(&self, g: usize, text: &str) -> std::result::Result<(), RowFault> {
        let fault = |column: &str, value: &str, expected: String| RowFault {
            column: column.to_string(),
            value: value.to_string(),
            expected,
        };
        let f: Vec<&str> = text.split(',').collect();
        if f.len() != self.columns.len() {
            return Err(fault(
                "",
                "",
                format!(
                    "it has {} fields, the header {} (a row cut short, or an edit)",
                    f.len(),
                    self.columns.len()
                ),
            ));
        }
        let (l, k) = (g / self.spec.episodes, g % self.spec.episodes);
        let level = &self.levels[l];
        // The fields the sweep decides before running: level, accuracy,
        // the swept values, episode and seed.
        let mut want = vec![level.index.to_string(), format_number(level.accuracy)];
        want.extend(level.values.iter().map(value_text));
        want.push(k.to_string());
        want.push(self.spec.level_episode_seed(level, k).to_string());
        for (i, w) in want.iter().enumerate() {
            if f[i] != w {
                let why = match i {
                    0 => format!("{w}: this row holds episode {g} of the sweep"),
                    1 => format!("{w}, the accuracy of level {l}"),
                    i if i == want.len() - 1 => {
                        format!("{w}, the seed of episode {k} at this accuracy")
                    }
                    i if i == want.len() - 2 => format!("{w}: this row holds episode {g}"),
                    _ => format!("{w}, the value of level {l}"),
                };
                return Err(fault(&self.columns[i], f[i], why));
            }
        }
        let success = want.len();
        let success_ok = match f[success] {
            "0" => false,
            "1" => true,
            other => return Err(fault("success", other, "0 or 1".into())),
        };
        let first = success + 1;
        let task = T::INFO.columns;
        for (c, text) in task.iter().zip(&f[first..first + task.len()]) {
            if !c.kind.accepts(text) {
                return Err(fault(c.name, text, c.kind.expected().into()));
            }
        }
        let rates = first + task.len();
        for i in rates..rates + 3 {
            let kind = errp_sim::task::ColumnKind::OptRate;
            if !kind.accepts(f[i]) {
                return Err(fault(&self.columns[i], f[i], kind.expected().into()));
            }
        }
        T::check_fields(
            self.scenarios[l],
            k,
            success_ok,
            &f[first..first + task.len()],
        )
        .map_err(|FieldError { column, expected }| {
            let i = first + task.iter().position(|c| c.name == column).unwrap_or(0);
            fault(column, f[i], expected)
        })?;
        let last = f.len() - 1;
        let body = &text[..text.len() - f[last].len() - 1];
        let crc = format!("{:08x}", crc32fast::hash(body.as_bytes()));
        if f[last] != crc {
            return Err(fault(
                CHECKSUM,
                f[last],
                format!(
                    "{crc}, the checksum of the row's other fields: the row was changed after \
                     it was written (an edit, or damage on disk)"
                ),
            ));
        }
        Ok(())
    }
}
