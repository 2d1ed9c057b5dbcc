//! From `episodes.csv` to `summary.csv`, the printed table and the plots.
//!
//! The episodes are read back from disk one level at a time, so memory does
//! not grow with the number of episodes, and a merged sweep is summarised by
//! the same code as an unsharded one.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use errp_sim::{Result, SimError};
use errp_sim::{RunningPearson, pearson};
use errp_sim::{mean_sd, median};

use crate::manifest::EPISODES;
use crate::spec::SweepSpec;
use errp_sim::TaskKind;

/// The statistics of one level.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelSummary {
    /// Level index.
    pub level: usize,
    /// Decoder accuracy.
    pub accuracy: f64,
    /// The swept parameters' values (`tau=0.3, strategy=greedy`).
    pub series: String,
    /// Episodes.
    pub episodes: usize,
    /// Episodes that converged on the user's goal.
    pub successes: usize,
    /// Episodes that converged on another goal.
    pub wrong: usize,
    /// Episodes that did not converge in time.
    pub no_commit: usize,
    /// Mean, sd and median of the cost over the successful episodes.
    pub cost: (f64, f64, f64),
    /// Mean online accuracy over the episodes.
    pub online_accuracy: f64,
    /// Pearson r and p between online accuracy and cost (successful
    /// episodes).
    pub r_p: (f64, f64),
    /// E-puck: mean per-episode hit rate per ErrP, and mean false alarms
    /// per minute of error-free time (NaN for the grid).
    pub detector: (f64, f64),
}

impl LevelSummary {
    /// Fraction of successful episodes.
    pub fn success_rate(&self) -> f64 {
        self.successes as f64 / self.episodes as f64
    }
}

/// A finished sweep's summary.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepReport {
    /// Task.
    pub task: TaskKind,
    /// One row per level.
    pub levels: Vec<LevelSummary>,
    /// Per series (axis values), Pearson r and p between online accuracy and
    /// cost over all its successful episodes.
    pub series: Vec<(String, usize, (f64, f64))>,
    /// The files written.
    pub files: Vec<PathBuf>,
}

/// Column positions in `episodes.csv`.
struct Columns {
    level: usize,
    success: usize,
    committed: usize,
    cost: usize,
    online: usize,
    /// E-puck: hit rate and false alarms per minute.
    detector: Option<(usize, usize)>,
}

fn columns(header: &str, task: TaskKind, path: &Path) -> Result<Columns> {
    let names: Vec<&str> = header.split(',').collect();
    let find = |name: &str| {
        names
            .iter()
            .position(|c| *c == name)
            .ok_or_else(|| SimError::Sweep(format!("{}: no column `{name}`", path.display())))
    };
    Ok(Columns {
        level: find("level")?,
        success: find("success")?,
        committed: find(task.info().committed_column)?,
        cost: find(task.info().cost_column)?,
        online: find("online_accuracy")?,
        detector: match task.info().detector_columns {
            None => None,
            Some((hits, false_alarms)) => Some((find(hits)?, find(false_alarms)?)),
        },
    })
}

/// Summarises `dir/episodes.csv`, which must hold every episode of `spec`.
pub fn summarise_dir(dir: &Path, spec: &SweepSpec) -> Result<SweepReport> {
    let path = dir.join(EPISODES);
    let io = |source| SimError::Input {
        path: path.clone(),
        source,
    };
    let mut lines = BufReader::new(errp_sim::open_regular(&path).map_err(io)?).lines();
    let header = lines
        .next()
        .transpose()
        .map_err(io)?
        .ok_or_else(|| SimError::Sweep(format!("{}: empty", path.display())))?;
    let cols = columns(&header, spec.task, &path)?;
    let mut levels = Vec::with_capacity(spec.n_levels());
    let mut series: Vec<(String, RunningPearson)> = Vec::new();
    let mut current: Option<Acc> = None;
    let mut rows = 0usize;
    for line in lines {
        let line = line.map_err(io)?;
        let f: Vec<&str> = line.split(',').collect();
        let parse = |i: usize| -> Result<f64> {
            let s = f.get(i).copied().unwrap_or("");
            if s.is_empty() {
                return Ok(f64::NAN);
            }
            s.parse::<f64>().map_err(|_| {
                SimError::Sweep(format!(
                    "{}: bad number {s:?} in row {}",
                    path.display(),
                    rows + 1
                ))
            })
        };
        let level = parse(cols.level)? as usize;
        if current.as_ref().is_some_and(|c| c.level != level) {
            levels.push(current.take().expect("checked").finish(spec, &mut series));
        }
        // On recordings, the level's accuracy is the one its rows carry
        // (its decoder's, checked as they were written).
        let measured = parse(1)?;
        let acc = current.get_or_insert_with(|| Acc::new(level, measured));
        let success = parse(cols.success)? == 1.0;
        acc.n += 1;
        if success {
            acc.cost.push(parse(cols.cost)?);
            acc.cost_online.push(parse(cols.online)?);
        } else if f.get(cols.committed).is_some_and(|s| !s.is_empty()) {
            acc.wrong += 1;
        } else {
            acc.no_commit += 1;
        }
        let online = parse(cols.online)?;
        if online.is_finite() {
            acc.online_sum += online;
            acc.online_n += 1;
        }
        if let Some((hit, fa)) = cols.detector {
            for (k, v) in [parse(hit)?, parse(fa)?].into_iter().enumerate() {
                if v.is_finite() {
                    acc.detector[k].0 += v;
                    acc.detector[k].1 += 1;
                }
            }
        }
        rows += 1;
    }
    if let Some(c) = current {
        levels.push(c.finish(spec, &mut series));
    }
    if rows != spec.total_episodes() || levels.len() != spec.n_levels() {
        return Err(SimError::Sweep(format!(
            "{}: {rows} episodes of {}; the sweep is not complete",
            path.display(),
            spec.total_episodes()
        )));
    }
    Ok(SweepReport {
        task: spec.task,
        levels,
        series: series
            .into_iter()
            .map(|(label, s)| (label, s.len(), s.r_p()))
            .collect(),
        files: Vec::new(),
    })
}

/// One level's rows while they are read.
struct Acc {
    level: usize,
    /// The accuracy column of the level's rows.
    measured: f64,
    n: usize,
    wrong: usize,
    no_commit: usize,
    cost: Vec<f64>,
    cost_online: Vec<f64>,
    online_sum: f64,
    online_n: usize,
    /// Sums and counts of the defined hit rates and false-alarm rates.
    detector: [(f64, usize); 2],
}

impl Acc {
    fn new(level: usize, measured: f64) -> Self {
        Self {
            level,
            measured,
            n: 0,
            wrong: 0,
            no_commit: 0,
            cost: Vec::new(),
            cost_online: Vec::new(),
            online_sum: 0.0,
            online_n: 0,
            detector: [(0.0, 0); 2],
        }
    }

    fn finish(self, spec: &SweepSpec, series: &mut Vec<(String, RunningPearson)>) -> LevelSummary {
        let (mut accuracy, values) = spec.level_values(self.level);
        if spec.accuracies.is_empty() {
            accuracy = self.measured;
        }
        let label = spec.series_label(&values);
        let (mean, sd) = mean_sd(&self.cost);
        // Pairs with an undefined online accuracy are left out of r.
        let (x, y): (Vec<f64>, Vec<f64>) = self
            .cost_online
            .iter()
            .zip(&self.cost)
            .filter(|(o, _)| o.is_finite())
            .map(|(o, c)| (*o, *c))
            .unzip();
        let pos = match series.iter().position(|(l, _)| *l == label) {
            Some(i) => i,
            None => {
                series.push((label.clone(), RunningPearson::default()));
                series.len() - 1
            }
        };
        for (o, c) in x.iter().zip(&y) {
            series[pos].1.push(*o, *c);
        }
        LevelSummary {
            level: self.level,
            accuracy,
            series: label,
            episodes: self.n,
            successes: self.cost.len(),
            wrong: self.wrong,
            no_commit: self.no_commit,
            cost: (mean, sd, median(&self.cost)),
            online_accuracy: if self.online_n == 0 {
                f64::NAN
            } else {
                self.online_sum / self.online_n as f64
            },
            r_p: pearson(&x, &y),
            detector: (mean_of(self.detector[0]), mean_of(self.detector[1])),
        }
    }
}

/// The mean of a (sum, count) pair; NaN for none.
fn mean_of((sum, n): (f64, usize)) -> f64 {
    if n == 0 { f64::NAN } else { sum / n as f64 }
}
