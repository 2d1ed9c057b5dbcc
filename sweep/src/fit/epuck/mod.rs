//! `errp fit epuck`: the continuous decoder's operating point estimated from
//! the paper's two e-puck runs (sec. 5.3: Mexico to Pisa in 60 s with 11
//! detected errors, Lisbon to Tokyo in 121 s with 26, both reaching the
//! goal).
//!
//! For every accuracy of the grid, each of the two shipped city scenarios is
//! swept ([`run_sweep`], so the runs are resumable, their rows checked and
//! their targeting cached); every run gives (time, detections, reached).
//! A decoder calibrated to one cross-validated accuracy can do better or
//! worse online (140 examples leave room), so each accuracy is run with
//! several calibrations, one sweep seed each, and the likelihood is that of
//! the pooled runs: the likelihood of a simulated user whose decoder has
//! that accuracy, whichever decoder the calibration gave. The likelihood
//! of each paper run at that accuracy is the Monte Carlo estimate of
//! [`log_likelihood`]; their sum is maximised over the grid ([`Surface`]).
//! Both scenarios use the same seeds, so each calibration drives both, as
//! the paper's two runs were driven by one subject's decoder.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use errp_bci::rng::stream;
use errp_bci::stop::WindDown;
use errp_sim::{PAPER_EPUCK, Result, SimError, create_dir};
use serde::Serialize;

use super::density::{Observed, SimRun, log_likelihood, percentile_of, quantile, resample};
use super::files;
use super::surface::Surface;
use crate::cache::TargetCache;
use crate::manifest::EPISODES;
use crate::observer::SweepObserver;
use crate::plot::{Curve, CurvePoint, FitPanel, FitPlot};
use crate::run::{SweepOptions, SweepOutcome, run_sweep};
use crate::spec::{InputNames, Shard, SweepSpec, SweepTask, sweep_fixed};

/// One of the paper's e-puck runs and the shipped scenario that replays it.
#[derive(Debug, Clone, Copy)]
pub struct PaperRun {
    /// The scenario's name (as in [`PAPER_EPUCK`]).
    pub name: &'static str,
    /// Its file, relative to the repository.
    pub file: &'static str,
    /// The shipped scenario's text.
    pub scenario: &'static str,
    /// What the paper reports.
    pub observed: Observed,
}

/// The paper's two runs (sec. 5.3), in its order.
pub fn paper_runs() -> [PaperRun; 2] {
    let observed = |name: &str| {
        let (_, secs, det) = PAPER_EPUCK
            .iter()
            .find(|(n, _, _)| *n == name)
            .copied()
            .expect("both runs are in PAPER_EPUCK");
        Observed {
            time_secs: secs,
            detections: det as f64,
        }
    };
    [
        PaperRun {
            name: "Mexico to Pisa",
            file: "scenarios/mexico_to_pisa.toml",
            scenario: include_str!("../../../../scenarios/mexico_to_pisa.toml"),
            observed: observed("Mexico to Pisa"),
        },
        PaperRun {
            name: "Lisbon to Tokyo",
            file: "scenarios/lisbon_to_tokyo.toml",
            scenario: include_str!("../../../../scenarios/lisbon_to_tokyo.toml"),
            observed: observed("Lisbon to Tokyo"),
        },
    ]
}

/// What `errp fit epuck` runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpuckFitSpec {
    /// The grid of decoder accuracies (cross-validated mean accuracy on the
    /// button-locked calibration examples, `user.accuracy`).
    pub accuracies: Vec<f64>,
    /// Calibrations at each accuracy: sweep seeds `seed`, `seed + 1`, ...
    pub calibrations: usize,
    /// Runs of each scenario per calibration and accuracy.
    pub runs: usize,
    /// The first sweep seed.
    pub seed: u64,
    /// Bootstrap replicates for the Monte Carlo error.
    pub bootstrap: usize,
}

/// How the fit was made, for its result file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Provenance {
    /// The command line.
    pub command: String,
    /// The `errp` version.
    pub errp_version: String,
    /// The source commit the program was built from ("unknown" outside a
    /// git checkout).
    pub commit: String,
}

/// One paper run at one accuracy.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunStats {
    /// Runs.
    pub runs: usize,
    /// Runs that converged on the goal.
    pub reached: usize,
    /// Median, 10 % and 90 % quantiles of the time of the runs that reached
    /// the goal (s).
    pub time_secs: [f64; 3],
    /// The same for the detections.
    pub detections: [f64; 3],
    /// Where the paper's time lies among those runs' times (0 to 1,
    /// mid-rank).
    pub time_percentile: f64,
    /// Where the paper's detections lie among theirs.
    pub detections_percentile: f64,
}

impl RunStats {
    fn of(runs: &[SimRun], obs: &Observed) -> Self {
        let ok: Vec<&SimRun> = runs.iter().filter(|r| r.reached).collect();
        let t: Vec<f64> = ok.iter().map(|r| r.time_secs).collect();
        let d: Vec<f64> = ok.iter().map(|r| r.detections).collect();
        let q = |v: &[f64]| [quantile(v, 0.5), quantile(v, 0.1), quantile(v, 0.9)];
        Self {
            runs: runs.len(),
            reached: ok.len(),
            time_secs: q(&t),
            detections: q(&d),
            time_percentile: percentile_of(&t, obs.time_secs),
            detections_percentile: percentile_of(&d, obs.detections),
        }
    }

    /// Share of the runs that reached the goal.
    pub fn p_reached(&self) -> f64 {
        self.reached as f64 / self.runs.max(1) as f64
    }
}

/// The held-out check of one paper run: the fit to the other run alone, and
/// where this one lies under it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeldOut {
    /// The run left out.
    pub name: String,
    /// The accuracy fitted without it.
    pub fitted_without: f64,
    /// Its statistics at that accuracy.
    pub stats: RunStats,
}

/// The result of `errp fit epuck`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpuckFit {
    /// Result file format.
    pub format: u32,
    /// The scenario field fitted.
    pub parameter: String,
    /// The maximum-likelihood accuracy (a grid point).
    pub estimate: f64,
    /// Its 95 % likelihood-ratio interval.
    pub interval_95: (f64, f64),
    /// Whether that interval reaches the grid's ends.
    pub interval_at_edge: (bool, bool),
    /// The 5-95 % spread of the estimate over bootstrap replicates of the
    /// simulated runs (Monte Carlo error only).
    pub mc_interval_90: (f64, f64),
    /// The paper's runs, in order: name, scenario file, observed time and
    /// detections.
    pub observations: Vec<(String, String, f64, f64)>,
    /// `stats[observation][grid point]`.
    pub stats: Vec<Vec<RunStats>>,
    /// The likelihood surface.
    pub surface: Surface,
    /// Each run held out in turn.
    pub held_out: Vec<HeldOut>,
    /// How the likelihood is estimated, in words.
    pub density: String,
    /// What was run.
    pub spec: EpuckFitSpec,
    /// How.
    pub provenance: Provenance,
}

/// Result file format written by this version.
pub const FIT_FORMAT: u32 = 1;

/// The density estimate, as the result file describes it.
pub const DENSITY: &str = "P(reached) (Jeffreys: (k + 1/2) / (n + 1)) times a Gaussian product \
     kernel density of (ln time, detections) over the runs that reached the goal, Scott's \
     bandwidth per dimension (sd n^(-1/6); at least 0.02 and 0.5)";

pub use super::files::FIT_FILES;

mod analysis;

#[allow(unused_imports)]
pub use analysis::*;

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
/// and writes [`FIT_FILES`]. `before_sweep(i, n, run, seed)` is called
/// before sweep i of n, for progress.
pub fn run_epuck_fit(
    spec: &EpuckFitSpec,
    out: &Path,
    cache: &TargetCache,
    provenance: Provenance,
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
                task: SweepTask::Epuck,
                scenario_path: PathBuf::from(run.file),
                scenario_toml: run.scenario.to_string(),
                accuracies: spec.accuracies.clone(),
                axes: Vec::new(),
                fixed: sweep_fixed(SweepTask::Epuck, None, NAMES)?,
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

const NAMES: InputNames = InputNames::CLI;

/// The largest grid, runs per point and bootstrap replicates.
pub const MAX_FIT_POINTS: usize = 200;
/// See [`MAX_FIT_POINTS`].
pub const MAX_FIT_RUNS: usize = 100_000;
/// See [`MAX_FIT_POINTS`].
pub const MAX_BOOTSTRAP: usize = 10_000;
/// See [`MAX_FIT_POINTS`].
pub const MAX_CALIBRATIONS: usize = 100;

fn check_spec(spec: &EpuckFitSpec) -> Result<()> {
    let bad = |what: String| Err(SimError::Sweep(what));
    if spec.accuracies.len() < 2 || spec.accuracies.len() > MAX_FIT_POINTS {
        return bad(format!(
            "--accuracy gives {} value(s): a fit needs 2 to {MAX_FIT_POINTS}",
            spec.accuracies.len()
        ));
    }
    if spec.accuracies.windows(2).any(|w| w[1] <= w[0]) {
        return bad("--accuracy must list increasing values".into());
    }
    if spec.runs < 5 || spec.runs > MAX_FIT_RUNS {
        return bad(format!(
            "--runs {} is invalid: expected 5 to {MAX_FIT_RUNS} runs per calibration and \
             accuracy",
            spec.runs
        ));
    }
    if spec.calibrations < 1 || spec.calibrations > MAX_CALIBRATIONS {
        return bad(format!(
            "--calibrations {} is invalid: expected 1 to {MAX_CALIBRATIONS} per accuracy",
            spec.calibrations
        ));
    }
    if spec.seed.checked_add(spec.calibrations as u64).is_none() {
        return bad(format!(
            "--seed {} is invalid: the seeds of {} calibrations from it must stay below 2^64",
            spec.seed, spec.calibrations
        ));
    }
    if spec.bootstrap < 10 || spec.bootstrap > MAX_BOOTSTRAP {
        return bad(format!(
            "--bootstrap {} is invalid: expected 10 to {MAX_BOOTSTRAP} replicates",
            spec.bootstrap
        ));
    }
    Ok(())
}

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
