//! Recordings read back: [`Recording::open`] decodes an `.rrd` that
//! `errp run --save` (or the Python package) wrote, checks it, and
//! recomputes every run's result from its data tables
//! ([`crate::record::data`]): the same result types, so the same tables,
//! as the run printed.

use std::path::{Path, PathBuf};

use crate::epuck::{EpuckEpisodeResult, EpuckScenario};
use crate::grid::{GridEpisodeResult, GridScenario};
use crate::record::data::Provenance;
use crate::scenario::AnyScenario;
use crate::task_kind::TaskKind;

mod epuck_replay;
mod frames;
mod grid_replay;
mod live;
mod read;
mod report;
mod rows;
mod tables;

pub use crate::record::data::Table;
pub use live::{LiveDecisionLog, LiveReplay};
pub use read::MAX_RECORDING_BYTES;
pub use report::{Comparison, RecordingHeadline, RecordingReport};
pub use tables::{CsvTable, PARQUET_TABLE_KEY, csv_tables, phase_secs};

use epuck_replay::epuck_results;
use grid_replay::grid_results;

/// Why a recording cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum InspectError {
    /// The file cannot be opened or read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a whole recording of errp of this format.
    #[error("{}: {why}", path.display())]
    Bad {
        /// The file.
        path: PathBuf,
        /// What is wrong, in words.
        why: String,
    },
}

/// The runs a recording holds, as the task's result types.
#[derive(Debug, Clone)]
pub enum Runs {
    /// E-puck runs.
    Epuck {
        /// The scenario as run.
        scenario: Box<EpuckScenario>,
        /// One result per run.
        results: Vec<EpuckEpisodeResult>,
    },
    /// Grid episodes (each with its steps, without EEG).
    Grid {
        /// The scenario as run.
        scenario: Box<GridScenario>,
        /// One result per episode.
        results: Vec<GridEpisodeResult>,
    },
}

impl Runs {
    /// Their task.
    pub fn kind(&self) -> TaskKind {
        match self {
            Runs::Epuck { .. } => TaskKind::Epuck,
            Runs::Grid { .. } => TaskKind::Grid,
        }
    }
}

/// A recording read back.
#[derive(Debug, Clone)]
pub struct Recording {
    /// The file.
    pub path: PathBuf,
    /// How it was made.
    pub provenance: Provenance,
    /// Its data tables by entity path ([`crate::record::data`]).
    pub tables: std::collections::BTreeMap<String, Table>,
    /// Every run, recomputed from the tables.
    pub runs: Runs,
    /// A live session's decisions (`errp stream --save`).
    pub live: Option<LiveDecisionLog>,
}

impl Recording {
    /// Reads and checks `path`, and recomputes its runs.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, InspectError> {
        let path = path.as_ref();
        let raw = read::read_raw(path)?;
        let provenance = read::parse_provenance(path, &raw)?;
        let bad = |why: String| InspectError::Bad {
            path: path.to_path_buf(),
            why,
        };
        let scenario = crate::ScenarioInput::load_as_written(crate::ScenarioSource::Text {
            text: provenance.scenario_text.clone(),
            name: "scenario".into(),
        })
        .map_err(|e| bad(format!("its scenario does not load: {e}")))?;
        let tables = raw.tables;
        let runs = match scenario {
            AnyScenario::Epuck(s) => {
                let results = epuck_results(&tables, &s).map_err(&bad)?;
                Runs::Epuck {
                    scenario: s,
                    results,
                }
            }
            AnyScenario::Grid(s) => {
                let results = grid_results(&tables).map_err(&bad)?;
                Runs::Grid {
                    scenario: s,
                    results,
                }
            }
        };
        let n = match &runs {
            Runs::Epuck { results, .. } => results.len(),
            Runs::Grid { results, .. } => results.len(),
        };
        if n != provenance.runs {
            return Err(bad(format!(
                "it holds {n} whole run(s) of the {} it was made with: it is truncated",
                provenance.runs
            )));
        }
        let live = provenance
            .live
            .as_ref()
            .map(|l| live::decision_log(&tables, n, (l.speed, &l.decoder), runs.kind()))
            .transpose()
            .map_err(&bad)?;
        Ok(Self {
            path: path.to_path_buf(),
            provenance,
            tables,
            runs,
            live,
        })
    }

    /// The number of runs.
    pub fn n_runs(&self) -> usize {
        self.provenance.runs
    }
}
