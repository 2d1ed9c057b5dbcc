//! From `episodes.csv` to `summary.csv`, the printed table and the plots.
//!
//! The episodes are read back from disk one level at a time, so memory does
//! not grow with the number of episodes, and a merged sweep is summarised by
//! the same code as an unsharded one.

use std::fmt;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use errp_bci::GoalSet;

use errp_sim::write_atomic;
use errp_sim::{AnyScenario, parse_scenario};
use errp_sim::{PAPER, PAPER_EPUCK};
use errp_sim::{Result, SimError};
use errp_sim::{StreamingPearson, pearson, wilson_interval};
use errp_sim::{mean_sd, median};

use crate::manifest::{EPISODES, Manifest};
use crate::plot::{self, LevelPoint, PaperPoint, Series, SweepPlot};
use crate::rows::cost_column;
use crate::spec::{SweepSpec, SweepTask, format_number, value_text};

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
#[derive(Debug, Clone)]
pub struct SweepReport {
    /// Task.
    pub task: SweepTask,
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

fn columns(header: &str, task: SweepTask, path: &Path) -> Result<Columns> {
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
        committed: find(match task {
            SweepTask::Grid => "committed_x",
            SweepTask::Epuck => "committed",
        })?,
        cost: find(cost_column(task))?,
        online: find("online_accuracy")?,
        detector: match task {
            SweepTask::Grid => None,
            SweepTask::Epuck => Some((find("hit_rate")?, find("false_alarms_per_min")?)),
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
    let mut lines = BufReader::new(File::open(&path).map_err(io)?).lines();
    let header = lines
        .next()
        .transpose()
        .map_err(io)?
        .ok_or_else(|| SimError::Sweep(format!("{}: empty", path.display())))?;
    let cols = columns(&header, spec.task, &path)?;
    let mut levels = Vec::with_capacity(spec.n_levels());
    let mut series: Vec<(String, StreamingPearson)> = Vec::new();
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
        let acc = current.get_or_insert_with(|| Acc::new(level));
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
    fn new(level: usize) -> Self {
        Self {
            level,
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

    fn finish(
        self,
        spec: &SweepSpec,
        series: &mut Vec<(String, StreamingPearson)>,
    ) -> LevelSummary {
        let (accuracy, values) = spec.level_values(self.level);
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
                series.push((label.clone(), StreamingPearson::default()));
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

/// A statistic in the summary: 6 decimals, empty when undefined.
fn stat(x: f64) -> String {
    if x.is_finite() {
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.to_string() }
    } else {
        String::new()
    }
}

/// The text of `summary.csv`.
pub fn summary_csv(spec: &SweepSpec, report: &SweepReport) -> String {
    let cost = cost_column(spec.task);
    let mut cols = vec!["level".to_string(), "accuracy".into()];
    cols.extend(spec.axes.iter().map(|a| a.name.clone()));
    cols.extend(
        [
            "episodes",
            "success_rate",
            "success_lo95",
            "success_hi95",
            "wrong_goal_rate",
            "no_commit_rate",
        ]
        .map(String::from),
    );
    cols.extend(["mean", "sd", "median"].map(|s| format!("{cost}_{s}")));
    cols.push("online_accuracy".into());
    cols.push(format!("r_online_{cost}"));
    cols.push(format!("p_online_{cost}"));
    let epuck = spec.task == SweepTask::Epuck;
    if epuck {
        cols.extend(["hit_rate", "false_alarms_per_min"].map(String::from));
    }
    let mut out = cols.join(",");
    out.push('\n');
    for l in &report.levels {
        let (_, values) = spec.level_values(l.level);
        let n = l.episodes as f64;
        let (lo, hi) = wilson_interval(l.successes, l.episodes);
        let mut f = vec![l.level.to_string(), format_number(l.accuracy)];
        f.extend(values.iter().map(value_text));
        f.extend([
            l.episodes.to_string(),
            stat(l.success_rate()),
            stat(lo),
            stat(hi),
            stat(l.wrong as f64 / n),
            stat(l.no_commit as f64 / n),
            stat(l.cost.0),
            stat(l.cost.1),
            stat(l.cost.2),
            stat(l.online_accuracy),
            stat(l.r_p.0),
            stat(l.r_p.1),
        ]);
        if epuck {
            f.extend([stat(l.detector.0), stat(l.detector.1)]);
        }
        out.push_str(&f.join(","));
        out.push('\n');
    }
    out
}

impl fmt::Display for SweepReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let cost = match self.task {
            SweepTask::Grid => "actions",
            SweepTask::Epuck => "time (s)",
        };
        let width = self
            .levels
            .iter()
            .map(|l| l.series.len())
            .max()
            .unwrap_or(0)
            .max(6);
        let with_series = self.levels.iter().any(|l| !l.series.is_empty());
        if with_series {
            write!(f, "{:<width$}  ", "series")?;
        }
        let epuck = self.task == SweepTask::Epuck;
        write!(
            f,
            "{:>8} {:>6} {:>8} {:>15} {:>17} {:>7} {:>7} {:>6} {:>7}",
            "accuracy",
            "n",
            "success",
            "95% CI",
            format!("{cost} mean ± sd"),
            "median",
            "online",
            "r",
            "p"
        )?;
        if epuck {
            write!(f, " {:>6} {:>8}", "hits", "FA/min")?;
        }
        writeln!(f)?;
        for l in &self.levels {
            let (lo, hi) = wilson_interval(l.successes, l.episodes);
            if with_series {
                write!(f, "{:<width$}  ", l.series)?;
            }
            let num = |x: f64, d: usize| {
                if x.is_finite() {
                    format!("{x:.d$}")
                } else {
                    "-".into()
                }
            };
            write!(
                f,
                "{:>8} {:>6} {:>7.1}% {:>15} {:>17} {:>7} {:>7} {:>6} {:>7}",
                format_number(l.accuracy),
                l.episodes,
                100.0 * l.success_rate(),
                format!("[{:.1}, {:.1}]", 100.0 * lo, 100.0 * hi),
                format!("{} ± {}", num(l.cost.0, 1), num(l.cost.1, 1)),
                num(l.cost.2, 1),
                num(l.online_accuracy, 3),
                num(l.r_p.0, 2),
                num(l.r_p.1, 3),
            )?;
            if epuck {
                write!(
                    f,
                    " {:>6} {:>8}",
                    num(l.detector.0, 3),
                    num(l.detector.1, 2)
                )?;
            }
            writeln!(f)?;
        }
        for (label, n, (r, p)) in &self.series {
            let name = if label.is_empty() {
                "all levels".to_string()
            } else {
                label.clone()
            };
            writeln!(
                f,
                "{name}: online accuracy vs {cost} over {n} successful episodes: r = {r:.3}, p = {}",
                if p.is_finite() {
                    format!("{p:.3e}")
                } else {
                    "-".into()
                }
            )?;
        }
        Ok(())
    }
}

/// The plot of a sweep, with the paper's figures where they apply.
pub fn sweep_plot(spec: &SweepSpec, report: &SweepReport, scenario: &AnyScenario) -> SweepPlot {
    let mut series: Vec<Series> = Vec::new();
    for l in &report.levels {
        let (lo, hi) = wilson_interval(l.successes, l.episodes);
        let point = LevelPoint {
            accuracy: l.accuracy,
            success_rate: l.success_rate(),
            success_lo: lo,
            success_hi: hi,
            mean: l.cost.0,
            sd: l.cost.1,
            median: l.cost.2,
            n: l.episodes,
        };
        match series.iter_mut().find(|s| s.label == l.series) {
            Some(s) => s.points.push(point),
            None => series.push(Series {
                label: l.series.clone(),
                points: vec![point],
            }),
        }
    }
    for s in &mut series {
        s.points.sort_by(|a, b| a.accuracy.total_cmp(&b.accuracy));
    }
    let decoder = match scenario {
        AnyScenario::Grid(s) => match s.decoder {
            errp_sim::grid::DecoderChoice::Oracle => "oracle decoder".to_string(),
            errp_sim::grid::DecoderChoice::Eeg => {
                format!("EEG decoder ({:?})", s.eeg).to_lowercase()
            }
        },
        AnyScenario::Epuck(_) => "sliding-window SVM decoder".to_string(),
    };
    let (task, cost_label, paper, paper_label) = match scenario {
        AnyScenario::Grid(_) => (
            "Grid task".to_string(),
            "actions to convergence (successful episodes)".to_string(),
            PAPER
                .iter()
                .map(|(name, set, row)| PaperPoint {
                    label: format!(
                        "{name} {}",
                        if *set == GoalSet::Fixed {
                            "fixed"
                        } else {
                            "free"
                        }
                    ),
                    accuracy: row[6] / 100.0,
                    value: row[0],
                    sd: Some(row[1]),
                })
                .collect::<Vec<_>>(),
            "paper, Table 1 (S1-S4, fixed and free goals)".to_string(),
        ),
        AnyScenario::Epuck(s) => {
            let paper: Vec<PaperPoint> = PAPER_EPUCK
                .iter()
                .filter(|(name, _, _)| *name == s.name)
                .map(|(name, secs, _)| PaperPoint {
                    label: name.to_string(),
                    // The paper gives no accuracy for its continuous
                    // decoder: drawn at the scenario's.
                    accuracy: s.accuracy,
                    value: *secs,
                    sd: None,
                })
                .collect();
            (
                format!("E-puck task, {}", s.name),
                "time to convergence, s (successful episodes)".to_string(),
                paper,
                format!(
                    "paper, {} (one run; drawn at the scenario's {})",
                    s.name,
                    format_number(s.accuracy)
                ),
            )
        }
    };
    SweepPlot {
        title: format!(
            "{task}: {} accuracies{} x {} episodes, {decoder}, seed {}",
            spec.accuracies.len(),
            if series.len() > 1 {
                format!(" x {} settings", series.len())
            } else {
                String::new()
            },
            spec.episodes,
            spec.seed
        ),
        cost_label,
        series,
        paper,
        paper_label,
    }
}

/// Writes `summary.csv`, `sweep.svg`, `sweep.png` and the final `sweep.json`
/// of a complete sweep in `dir`, each atomically.
pub fn finish_dir(dir: &Path, manifest: &Manifest) -> Result<SweepReport> {
    let spec = &manifest.spec;
    let mut report = summarise_dir(dir, spec)?;
    // The scenario as the file gives it (the e-puck's paper point is drawn
    // at its accuracy), else the first level's.
    let scenario = match parse_scenario(&spec.scenario_toml, &spec.scenario_path) {
        Ok(s) => s,
        Err(_) => spec
            .levels()?
            .into_iter()
            .next()
            .map(|l| l.scenario)
            .ok_or_else(|| SimError::Sweep("a sweep without levels".into()))?,
    };
    let plot = sweep_plot(spec, &report, &scenario);
    let plot_error =
        |e: plot::PlotError| SimError::Sweep(format!("plotting the sweep failed: {e}"));
    let files = [
        ("summary.csv", summary_csv(spec, &report).into_bytes()),
        (
            "sweep.svg",
            plot::svg(&plot).map_err(plot_error)?.into_bytes(),
        ),
        ("sweep.png", plot::png(&plot).map_err(plot_error)?),
    ];
    for (name, bytes) in &files {
        write_atomic(&dir.join(name), bytes)?;
        report.files.push(dir.join(name));
    }
    manifest.write(dir)?;
    report.files.push(dir.join(crate::manifest::MANIFEST));
    report.files.push(dir.join(EPISODES));
    Ok(report)
}
