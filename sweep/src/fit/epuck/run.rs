//! `errp fit epuck` from start to end: check, sweep both scenarios at
//! every accuracy with several calibrations, read the runs back, analyse,
//! write the files.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use errp_bci::stop::WindDown;
use errp_sim::{Names, Result, SimError, TaskKind, create_dir};

use super::analysis::analyse;
use super::output::write_fit;
use super::result::EpuckFit;
use super::spec::{EpuckFitSpec, PaperRun, check_spec, paper_runs};
use crate::cache::TargetCache;
use crate::fit::density::SimRun;
use crate::fit::estimate::FitProvenance;
use crate::fit::files;
use crate::manifest::EPISODES;
use crate::observer::SweepObserver;
use crate::run::{SweepOptions, SweepOutcome, run_sweep};
use crate::spec::{Shard, SweepSpec, sweep_fixed};

/// The directory of a paper run's sweeps inside the fit's directory.
pub fn run_dir(out: &Path, run: &PaperRun) -> PathBuf {
    let stem = Path::new(run.file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| run.name.to_string());
    out.join(stem)
}

/// The sweep of a paper run with one seed: `OUT/<scenario>/seed-<seed>`.
pub fn sweep_dir(out: &Path, run: &PaperRun, seed: u64) -> PathBuf {
    run_dir(out, run).join(format!("seed-{seed}"))
}

/// The outcome of [`run_epuck_fit`].
#[derive(Debug)]
pub enum FitOutcome {
    /// Wound down (its `WindDown` was requested); rerunning resumes the sweeps.
    Interrupted,
    /// The fit, and the files written.
    Complete(Box<EpuckFit>, Vec<PathBuf>),
}

/// Runs the sweeps into `out` (resuming what is there), computes the fit
/// and writes [`FIT_FILES`](crate::fit::FIT_FILES). `before_sweep(i, n, run, seed)` is called
/// before sweep i of n, for progress.
pub fn run_epuck_fit(
    spec: &EpuckFitSpec,
    out: &Path,
    cache: &TargetCache,
    provenance: FitProvenance,
    wind_down: &WindDown,
    observer: &dyn SweepObserver,
    mut before_sweep: impl FnMut(usize, usize, &PaperRun, u64),
) -> Result<FitOutcome> {
    check_spec(spec)?;
    check_out(out)?;
    let runs = paper_runs();
    create_dir(out)?;
    let levels = spec.accuracies.len();
    let mut per_run = vec![vec![Vec::new(); levels]; runs.len()];
    let total = spec.calibrations * runs.len();
    for k in 0..spec.calibrations {
        let seed = spec.seed + k as u64;
        for (i, run) in runs.iter().enumerate() {
            before_sweep(k * runs.len() + i, total, run, seed);
            let sweep = SweepSpec {
                task: TaskKind::Epuck,
                scenario_path: PathBuf::from(run.file),
                scenario_toml: run.scenario.to_string(),
                accuracies: spec.accuracies.clone(),
                axes: Vec::new(),
                fixed: sweep_fixed(TaskKind::Epuck, Path::new(run.file), None, &NAMES)?,
                episodes: spec.runs,
                seed,
            };
            create_dir(&run_dir(out, run))?;
            let opts = SweepOptions {
                out: sweep_dir(out, run, seed),
                cache: cache.clone(),
                shard: Shard::ALL,
                chunk: 0,
                repair: false,
            };
            match run_sweep(&sweep.checked(&NAMES)?, &opts, wind_down, observer)? {
                SweepOutcome::Interrupted { .. } => return Ok(FitOutcome::Interrupted),
                SweepOutcome::Complete { .. } => {}
            }
            let read = read_runs(&opts.out.join(EPISODES), levels, spec.runs, k)?;
            for (j, level) in read.into_iter().enumerate() {
                per_run[i][j].extend(level);
            }
        }
    }
    let fit = analyse(spec, &runs, &per_run, provenance);
    let files = write_fit(&fit, out)?;
    Ok(FitOutcome::Complete(Box::new(fit), files))
}

const NAMES: Names = Names::CLI;

/// Refuses an `out` that holds anything a fit did not write.
fn check_out(out: &Path) -> Result<()> {
    let ours: Vec<PathBuf> = paper_runs().iter().map(|r| run_dir(out, r)).collect();
    files::check_out(out, |p| ours.iter().any(|o| o == p), "a fit's")
}

/// Reads a finished e-puck sweep's runs (of `calibration`), grouped by
/// level. The sweep has
/// just checked every row; this checks the shape again.
fn read_runs(
    path: &Path,
    levels: usize,
    runs: usize,
    calibration: usize,
) -> Result<Vec<Vec<SimRun>>> {
    let bad = |what: String| SimError::Sweep(format!("{}: {what}", path.display()));
    let file = errp_sim::open_regular(path).map_err(|source| SimError::Input {
        path: path.to_path_buf(),
        source,
    })?;
    let mut lines = BufReader::new(file).lines();
    let header = lines
        .next()
        .transpose()
        .map_err(|source| SimError::Input {
            path: path.to_path_buf(),
            source,
        })?
        .ok_or_else(|| bad("empty".into()))?;
    let cols: Vec<&str> = header.split(',').collect();
    let col = |name: &str| {
        cols.iter()
            .position(|c| *c == name)
            .ok_or_else(|| bad(format!("no column {name}")))
    };
    let (i_level, i_success, i_time, i_det) = (
        col("level")?,
        col("success")?,
        col("time_secs")?,
        col("detected")?,
    );
    let mut out = vec![Vec::with_capacity(runs); levels];
    for (n, line) in lines.enumerate() {
        let line = line.map_err(|source| SimError::Input {
            path: path.to_path_buf(),
            source,
        })?;
        let f: Vec<&str> = line.split(',').collect();
        let field = |i: usize| f.get(i).copied().unwrap_or("");
        let parse = |i: usize| {
            field(i)
                .parse::<f64>()
                .map_err(|_| bad(format!("line {}: {:?} is not a number", n + 2, field(i))))
        };
        let level = field(i_level)
            .parse::<usize>()
            .ok()
            .filter(|&l| l < levels)
            .ok_or_else(|| bad(format!("line {}: no level {:?}", n + 2, field(i_level))))?;
        out[level].push(SimRun {
            time_secs: parse(i_time)?,
            detections: parse(i_det)?,
            reached: field(i_success) == "1",
            calibration,
        });
    }
    if out.iter().any(|l| l.len() != runs) {
        return Err(bad(format!(
            "expected {runs} runs at each of {levels} levels"
        )));
    }
    Ok(out)
}
