//! Recordings read back: [`Recording::open`] decodes an `.rrd` that
//! `errp run --save` (or the Python package) wrote, checks it, and
//! recomputes every run's result from its data tables
//! ([`crate::record::data`]): the same result types, so the same tables,
//! as the run printed.

use std::path::{Path, PathBuf};

use errp_robot::{Cell, Grid, GridAction, Pose};

use crate::epuck::episode::Score;
use crate::epuck::plant::step_motion;
use crate::epuck::{EpuckEpisodeResult, EpuckScenario};
use crate::grid::plant::GridTally;
use crate::grid::{GridEpisodeResult, GridScenario, GridStep};
use crate::record::data::{Column, Provenance};
use crate::record::paths;
use crate::scenario::AnyScenario;

mod frames;
mod grid_replay;
mod read;
mod report;
mod tables;

pub use read::{MAX_RECORDING_BYTES, Table};
pub use report::{Comparison, RecordingHeadline, RecordingReport};
pub use tables::{CsvTable, PARQUET_TABLE_KEY, csv_tables, phase_secs};

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
        Ok(Self {
            path: path.to_path_buf(),
            provenance,
            tables,
            runs,
        })
    }

    /// The number of runs.
    pub fn n_runs(&self) -> usize {
        self.provenance.runs
    }
}

/// Typed access to a table's columns, with errors naming what is missing.
struct View<'a> {
    name: &'a str,
    table: &'a Table,
}

impl<'a> View<'a> {
    fn of(
        tables: &'a std::collections::BTreeMap<String, Table>,
        name: &'a str,
    ) -> Result<Self, String> {
        tables
            .get(name)
            .map(|table| Self { name, table })
            .ok_or_else(|| format!("it has no table {name}"))
    }

    fn col(&self, c: &str) -> Result<&'a Column, String> {
        let col = self
            .table
            .column(c)
            .ok_or_else(|| format!("its table {} has no column `{c}`", self.name))?;
        if col.len() != self.table.rows() {
            return Err(format!(
                "its table {} has columns of different lengths",
                self.name
            ));
        }
        Ok(col)
    }

    fn f64(&self, c: &str) -> Result<&'a [f64], String> {
        match self.col(c)? {
            Column::F64(v) => Ok(v),
            _ => Err(format!("column `{c}` of {} is not numbers", self.name)),
        }
    }

    fn i64(&self, c: &str) -> Result<&'a [i64], String> {
        match self.col(c)? {
            Column::I64(v) => Ok(v),
            _ => Err(format!("column `{c}` of {} is not integers", self.name)),
        }
    }

    fn bool(&self, c: &str) -> Result<&'a [bool], String> {
        match self.col(c)? {
            Column::Bool(v) => Ok(v),
            _ => Err(format!("column `{c}` of {} is not flags", self.name)),
        }
    }

    fn rows(&self, c: &str) -> Result<(&'a [f64], usize), String> {
        match self.col(c)? {
            Column::F64Rows(v, w) => Ok((v, *w)),
            _ => Err(format!(
                "column `{c}` of {} is not rows of numbers",
                self.name
            )),
        }
    }

    /// The row indices of run `r` (runs are written in order).
    fn run_rows(&self, runs: &[i64], r: usize) -> std::ops::Range<usize> {
        let lo = runs.partition_point(|&x| x < r as i64);
        let hi = runs.partition_point(|&x| x <= r as i64);
        lo..hi
    }
}

/// Checks that `runs` counts 0, 1, ... in order (each run's rows together).
fn check_run_order(name: &str, runs: &[i64]) -> Result<(), String> {
    if runs.windows(2).any(|w| w[1] < w[0]) || runs.first().is_some_and(|&r| r < 0) {
        return Err(format!("its table {name} is not in run order"));
    }
    Ok(())
}

/// An index in `0..n`, or an error naming the column.
fn index(v: i64, n: usize, what: &str) -> Result<usize, String> {
    usize::try_from(v)
        .ok()
        .filter(|&i| i < n)
        .ok_or_else(|| format!("{what} {v} is out of range (0 to {})", n.saturating_sub(1)))
}

/// A pose from a recording's centimetres and degrees.
fn cm_deg(x: f64, y: f64, heading_deg: f64) -> Pose {
    Pose::new(x / 100.0, y / 100.0, heading_deg.to_radians())
}

/// The path driven (m), the largest sideways speed (m/s) and each frame's
/// time and true position (m).
type Replayed = (f64, f64, Vec<(f64, [f64; 2])>);

/// The frames `rows` of a run from `start`, measured as the episode measured
/// them.
fn replay_frames(
    frames: &View<'_>,
    rows: std::ops::Range<usize>,
    start: Pose,
) -> Result<Replayed, String> {
    let (t, x, y, h) = (
        frames.f64("t_s")?,
        frames.f64("x_cm")?,
        frames.f64("y_cm")?,
        frames.f64("heading_deg")?,
    );
    let mut pose = start;
    let mut path_m = 0.0;
    let mut max_lateral: f64 = 0.0;
    let mut frame_at = Vec::with_capacity(rows.len());
    for i in rows {
        let next = cm_deg(x[i], y[i], h[i]);
        let (distance, lateral) = step_motion(pose, next);
        max_lateral = max_lateral.max(lateral);
        path_m += distance;
        pose = next;
        frame_at.push((t[i], [pose.x_m, pose.y_m]));
    }
    Ok((path_m, max_lateral, frame_at))
}

/// Refuses windows whose beliefs are not one value per goal.
fn check_belief_width(windows: &View<'_>, n_goals: usize) -> Result<(), String> {
    let (_, width) = windows.rows("belief")?;
    if width != n_goals {
        return Err(format!(
            "its beliefs have {width} values, but the scenario has {n_goals} goals"
        ));
    }
    Ok(())
}

/// The e-puck runs recomputed as `run_epuck_episode` scores them.
fn epuck_results(
    tables: &std::collections::BTreeMap<String, Table>,
    scenario: &EpuckScenario,
) -> Result<Vec<EpuckEpisodeResult>, String> {
    let n_goals = scenario.layout.goals().len();
    let runs = View::of(tables, paths::RUNS)?;
    let frames = View::of(tables, paths::FRAMES)?;
    let windows = View::of(tables, paths::WINDOWS)?;
    let ends = View::of(tables, paths::ENDS)?;
    let empty = Table::default();
    let errps = View {
        name: paths::ERRPS,
        table: tables.get(paths::ERRPS).unwrap_or(&empty),
    };
    let run_col = runs.i64("run")?;
    let f_run = frames.i64("run")?;
    let w_run = windows.i64("run")?;
    let e_run = if errps.table.rows() == 0 {
        &[][..]
    } else {
        errps.i64("run")?
    };
    let end_run = ends.i64("run")?;
    for (name, r) in [
        (paths::RUNS, run_col),
        (paths::FRAMES, f_run),
        (paths::WINDOWS, w_run),
        (paths::ERRPS, e_run),
        (paths::ENDS, end_run),
    ] {
        check_run_order(name, r)?;
    }
    let (w_t, w_p, w_detected, w_step) = (
        windows.f64("t_s")?,
        windows.f64("p_error")?,
        windows.bool("detected")?,
        windows.i64("step")?,
    );
    check_belief_width(&windows, n_goals)?;
    let (e_t, e_onset, e_phase) = if errps.table.rows() == 0 {
        (&[][..], &[][..], &[][..])
    } else {
        (
            errps.f64("t_s")?,
            errps.f64("onset_s")?,
            errps.i64("phase")?,
        )
    };
    let (end_t, end_committed) = (ends.f64("t_s")?, ends.i64("committed")?);
    let goal = runs.i64("goal")?;
    let (sx, sy, sh) = (
        runs.f64("start_x")?,
        runs.f64("start_y")?,
        runs.f64("start_heading_deg")?,
    );
    let t_e = runs.f64("t_e")?;
    let (d_from, d_to) = (runs.f64("detection_from_s")?, runs.f64("detection_to_s")?);
    let (w_from, w_to) = (runs.f64("window_from_s")?, runs.f64("window_to_s")?);

    let mut out = Vec::new();
    for (k, &r) in run_col.iter().enumerate() {
        if r != k as i64 {
            return Err(format!("its table {} skips run {k}", paths::RUNS));
        }
        let Some(e) = end_run.iter().position(|&x| x == r) else {
            // A run without its end: the recording stopped in it.
            break;
        };
        let span = errp_bci::ResponseSpan {
            from_secs: d_from[k],
            to_secs: d_to[k],
        };
        let window_span = errp_bci::ResponseSpan {
            from_secs: w_from[k],
            to_secs: w_to[k],
        };
        let fr = frames.run_rows(f_run, k);
        let wr = windows.run_rows(w_run, k);
        let er = errps.run_rows(e_run, k);
        let time_secs = end_t[e];
        let errps_run: Vec<(f64, f64, usize)> = er
            .clone()
            .map(|i| Ok((e_t[i], e_onset[i], index(e_phase[i], 3, "ErrP phase")?)))
            .collect::<Result<_, String>>()?;

        let start = cm_deg(sx[k], sy[k], sh[k]);
        let (path_m, max_lateral, frame_at) = replay_frames(&frames, fr, start)?;

        // The episode's own scoring, fed from the tables: each ErrP once the
        // user produced it (before the window that ends after it), each
        // window with the pose at its end.
        let mut score = Score::new(span, window_span, t_e[k]);
        let columns = WindowColumns {
            t: w_t,
            p: w_p,
            detected: w_detected,
            step: w_step,
        };
        score_run(&mut score, &columns, wr, &errps_run, &frame_at)?;
        let committed = match end_committed[e] {
            -1 => None,
            c => Some(index(c, n_goals, "committed goal")?),
        };
        let goal = index(goal[k], n_goals, "goal")?;
        out.push(score.finish(goal, committed, time_secs, path_m, max_lateral));
    }
    Ok(out)
}

/// A recording's window columns.
struct WindowColumns<'a> {
    t: &'a [f64],
    p: &'a [f64],
    detected: &'a [bool],
    step: &'a [i64],
}

/// Feeds `score` one run's windows (rows `rows` of `w`) and its ErrPs
/// `(seen at, onset, phase)`, with the poses of `frame_at`.
fn score_run(
    score: &mut Score,
    w: &WindowColumns<'_>,
    rows: std::ops::Range<usize>,
    errps_run: &[(f64, f64, usize)],
    frame_at: &[(f64, [f64; 2])],
) -> Result<(), String> {
    let mut known = 0usize;
    let mut frame = 0usize;
    for i in rows {
        let t = w.t[i];
        while known < errps_run.len() && errps_run[known].0 < t {
            score.errp(errps_run[known].1, errps_run[known].2);
            known += 1;
        }
        let step = index(w.step[i], 4, "window step")?;
        let mut at = [f64::NAN; 2];
        if w.detected[i] {
            while frame + 1 < frame_at.len() && frame_at[frame + 1].0 <= t {
                frame += 1;
            }
            if let Some(&(_, xy)) = frame_at.get(frame) {
                at = xy;
            }
        }
        score.window(t, w.p[i], step, w.detected[i], at);
    }
    for &(_, onset, phase) in &errps_run[known..] {
        score.errp(onset, phase);
    }
    Ok(())
}
