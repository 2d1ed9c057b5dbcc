//! `errp.run` and `errp.sweep`: a scenario's runs as `errp run` makes
//! them, and Monte Carlo sweeps as `errp sweep` writes them.

use std::path::PathBuf;
use std::sync::{Mutex, PoisonError};

use errp_bci::stop::WindDown;
use errp_sim::Names;
use errp_sim::TaskKind;
use errp_sim::calibration::CalibrationReport;
use errp_sim::epuck::{
    ContinuousDecoder, ContinuousReport, EpuckEpisodeResult, EpuckScenario, EpuckTask, epuck_row,
    epuck_run_seed,
};
use errp_sim::grid::{
    GridEpisodeResult, GridScenario, GridTask, OwnEegReport, decoder_accuracy, grid_row,
};
use errp_sim::task::{EpisodeRow, Task, TaskInfo, format_number};
use errp_sim::{AnyScenario, RunOutcome};
use errp_sweep::{
    Shard, SweepOptions, SweepOutcome, SweepSpec, TargetCache, parse_axis, sweep_scenario,
};
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{Keys, load, py_err, task_kind, value_error};
use crate::interrupt::{CALIBRATING, EPISODES, Meter, RUNS, long_or, long_shown};

/// What a sweep reports from Python: its progress (its decoders
/// calibrated, then its episodes) on the meter, and its warnings kept for
/// the caller, who raises them as Python warnings.
#[derive(Debug, Default)]
struct SweepWatch {
    meter: Meter,
    warnings: Mutex<Vec<String>>,
}

impl SweepWatch {
    fn keep(&self, text: &str) {
        self.warnings
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(text.to_owned());
    }
}

impl errp_sweep::SweepObserver for SweepWatch {
    fn decoder_ready(&self, _info: &errp_sweep::DecoderInfo, done: usize, total: usize) {
        self.meter.set(CALIBRATING, done, total);
    }

    fn episodes_done(&self, done: usize, total: usize) {
        self.meter.set(EPISODES, done, total);
    }

    fn note(&self, text: &str) {
        self.keep(text);
    }

    fn warning(&self, text: &str) {
        self.keep(text);
    }
}

/// Most worker threads of a sweep.
pub(crate) const MAX_THREADS: usize = 1024;

/// A grid scenario's episodes as the CSV text `run` and the tasks' `run`
/// return: the columns of `episodes.csv` without the sweep's swept values
/// and checksum, one row per episode.
pub(crate) fn grid_csv(
    s: &GridScenario,
    recorded: Option<&OwnEegReport>,
    episodes: &[GridEpisodeResult],
) -> String {
    let rows = episodes
        .iter()
        .enumerate()
        .map(|(k, r)| (errp_sim::grid::grid_episode_seed(s.seed, k), grid_row(r)));
    csv(&GridTask::INFO, decoder_accuracy(s, recorded), rows)
}

/// An e-puck scenario's runs as CSV text, as [`grid_csv`].
pub(crate) fn epuck_csv(s: &EpuckScenario, results: &[EpuckEpisodeResult]) -> String {
    let rows = results
        .iter()
        .enumerate()
        .map(|(k, r)| (epuck_run_seed(s.seed, k), epuck_row(&s.layout, r)));
    csv(&EpuckTask::INFO, s.accuracy.get(), rows)
}

fn csv(info: &TaskInfo, accuracy: f64, rows: impl Iterator<Item = (u64, EpisodeRow)>) -> String {
    let mut cols = vec!["level", "accuracy", "episode", "seed"];
    cols.extend(info.row_columns());
    let mut text = cols.join(",") + "\n";
    for (k, (seed, row)) in rows.enumerate() {
        let mut f = vec![
            "0".to_string(),
            format_number(accuracy),
            k.to_string(),
            seed.to_string(),
        ];
        f.extend(row.csv_fields());
        text += &(f.join(",") + "\n");
    }
    text
}

/// The columns of an episode's row of `task` ("grid" or "epuck"), as
/// `episodes.csv` names them.
#[pyfunction]
pub(crate) fn episode_columns(task: &str) -> PyResult<Vec<&'static str>> {
    Ok(task_kind("task", task)?.info().row_columns())
}

/// Checks `save=` before any work.
pub(crate) fn check_save(save: Option<&PathBuf>) -> PyResult<()> {
    let Some(p) = save else { return Ok(()) };
    if p.extension().and_then(|e| e.to_str()) != Some("rrd") {
        return Err(value_error(
            "save",
            format!("{:?}", p.display().to_string()),
            "a file name ending in .rrd",
        ));
    }
    if !cfg!(feature = "rerun") {
        return Err(PyValueError::new_err(
            "save: this errp was built without Rerun; reinstall it with the default features \
             (pip install ./python) to write recordings",
        ));
    }
    check_ours(p)
}

/// Refuses to replace an existing `path` that errp did not write (one
/// that does not begin with a Rerun recording's signature).
fn check_ours(path: &std::path::Path) -> PyResult<()> {
    if errp_sim::is_foreign(path, b"RRF2") {
        return Err(PyValueError::new_err(format!(
            "save: {}: the file exists and is not a Rerun recording; errp replaces only files \
             it wrote: move it away or give another name",
            path.display()
        )));
    }
    Ok(())
}

/// What `errp.run` reports as it goes: the calibration, then the
/// episodes or runs, on the meter.
pub(crate) struct RunMeter<'a> {
    meter: &'a Meter,
    /// Grid episodes, or e-puck runs.
    total: usize,
}

impl<'a> RunMeter<'a> {
    /// `total` episodes or runs shown on `meter`.
    pub(crate) fn new(meter: &'a Meter, total: usize) -> Self {
        Self { meter, total }
    }
}

impl errp_sim::RunObserver for RunMeter<'_> {
    fn targeting(&self, _step: &errp_bci::TargetingStep) {
        self.meter.step(CALIBRATING, 0);
    }

    fn online_step(&self, _step: &errp_bci::OnlineStep) {
        self.meter.step(CALIBRATING, 0);
    }

    fn grid_episode(&self, k: usize, _result: &errp_sim::grid::GridEpisodeResult) {
        self.meter.set(EPISODES, k + 1, self.total);
    }

    fn epuck_run_done(&self) {
        self.meter.step(RUNS, self.total);
    }
}

/// Runs a scenario as `errp run` does (the same decoder, seeds and
/// results, on the same path: [`errp_sim::run_scenario`]) and returns its
/// episodes as CSV text, one row per episode, and what was calibrated.
#[pyfunction]
#[pyo3(signature = (scenario=None, *, seed=None, runs=None, accuracy=None, overrides=None, save=None, progress=None))]
#[allow(clippy::too_many_arguments, reason = "Python's keywords, one each")]
pub(crate) fn run<'py>(
    py: Python<'py>,
    scenario: Option<PathBuf>,
    seed: Option<u64>,
    runs: Option<usize>,
    accuracy: Option<f64>,
    overrides: Option<&Bound<'py, PyDict>>,
    save: Option<PathBuf>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    check_save(save.as_ref())?;
    let keys = Keys {
        accuracy,
        seed,
        runs,
    };
    let loaded = load(scenario, TaskKind::Epuck, keys, overrides)?;
    let total = match &loaded.scenario {
        AnyScenario::Grid(s) => s.episodes.len(),
        AnyScenario::Epuck(s) => s.runs,
    };
    let provenance = errp_sim::RunProvenance {
        command: vec!["python: errp.run".into()],
        commit: None,
    };
    let options = errp_sim::RunOptions {
        save: save.as_deref(),
        provenance: &provenance,
        names: &Names::PYTHON,
    };
    let meter = Meter::default();
    let watch = RunMeter {
        meter: &meter,
        total,
    };
    let done = long_shown(py, &meter, progress, || {
        errp_sim::run_scenario(loaded, options, &watch)
    })?
    .map_err(|e| py_err(e.error))?;
    let out = PyDict::new(py);
    out.set_item("task", done.outcome.kind().as_str())?;
    match &done.outcome {
        RunOutcome::Grid(report) => {
            let s = &report.scenario;
            let own_eeg = report.own_eeg.as_ref();
            out.set_item("csv", grid_csv(s, own_eeg, &report.episodes))?;
            let info = grid_summary(s, own_eeg, report.calibration.as_ref());
            out.set_item("decoder", info)?;
        }
        RunOutcome::Epuck(r) => {
            let s = &r.scenario;
            out.set_item("csv", epuck_csv(s, &r.results))?;
            out.set_item("decoder", epuck_summary(s, &r.decoder, &r.report))?;
        }
    }
    Ok(out)
}

/// What a calibration found, for Python.
pub(crate) type DecoderSummary = Vec<(&'static str, f64)>;

/// A summary as a Python dict.
pub(crate) fn summary_dict<'py>(
    py: Python<'py>,
    s: &DecoderSummary,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in s {
        d.set_item(k, v)?;
    }
    Ok(d)
}

/// What the grid decoder's calibration found (none for the oracle).
pub(crate) fn grid_summary(
    s: &GridScenario,
    recorded: Option<&OwnEegReport>,
    calibration: Option<&CalibrationReport>,
) -> DecoderSummary {
    let mut info = vec![("accuracy", decoder_accuracy(s, recorded))];
    if let Some(r) = recorded {
        let a = r.cross_validated;
        info.extend([
            ("cv_correct", a.correct),
            ("cv_error", a.error),
            ("cv_mean", a.mean()),
            ("held_out_mean", r.held_out.mean()),
        ]);
    }
    if let Some(c) = calibration {
        let a = c.calibrated.accuracy;
        info.extend([
            ("errp_to_noise", c.targeting.ratio),
            ("cv_correct", a.correct),
            ("cv_error", a.error),
            ("cv_mean", a.mean()),
        ]);
    }
    info
}

/// What the continuous decoder's calibration found, with its T_e and its
/// operating point on the held-out session.
pub(crate) fn epuck_summary(
    s: &EpuckScenario,
    decoder: &ContinuousDecoder,
    report: &ContinuousReport,
) -> DecoderSummary {
    let a = report.calibrated.accuracy;
    let mut info = vec![
        // On a recording, the accuracy the control assumes: its own.
        (
            "accuracy",
            decoder
                .own_eeg
                .as_ref()
                .map_or(s.accuracy.get(), |r| r.accuracy),
        ),
        ("cv_correct", a.correct),
        ("cv_error", a.error),
        ("cv_mean", a.mean()),
        ("t_e", decoder.detector_t_e(&s.params, false)),
    ];
    if decoder.own_eeg.is_none() {
        // A hybrid's response has the amplitude it has: no ratio.
        info.insert(1, ("errp_to_noise", report.generator.errp_to_noise));
    }
    if let Some(o) = &decoder.online {
        info.extend([
            ("online_hit_rate", o.point.hit_rate),
            ("online_false_alarms_per_min", o.point.false_alarms_per_min),
        ]);
    }
    info
}

/// The keywords of `errp.sweep`, which its Python wrapper passes as one
/// dictionary (every key present).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct SweepKeywords {
    accuracy: Option<String>,
    task: Option<String>,
    scenario: Option<PathBuf>,
    episodes: usize,
    seed: u64,
    params: Option<Vec<String>>,
    #[pyo3(default)]
    per_action: Option<bool>,
    /// `per_action=`'s former name, still read.
    #[pyo3(default)]
    stream: Option<bool>,
    cache: Option<PathBuf>,
    threads: Option<usize>,
}

/// The grid's EEG mode of a sweep, as `per_action=` (or its former name
/// `stream=`) gives it, and the names that name the keyword given.
fn eeg_mode(per_action: Option<bool>, stream: Option<bool>) -> (Option<&'static str>, Names) {
    match (per_action, stream) {
        (None, Some(s)) => (
            Some(if s { "stream" } else { "bank" }),
            Names {
                sweep_eeg: "stream=",
                ..Names::PYTHON
            },
        ),
        (p, _) => (
            p.map(|p| if p { "per_action" } else { "bank" }),
            Names::PYTHON,
        ),
    }
}

/// The `task=` of a sweep: none (the scenario's), "grid" or "epuck".
fn sweep_task(task: Option<&str>) -> PyResult<Option<TaskKind>> {
    task.map(|t| task_kind("task", t)).transpose()
}

/// The sweep `errp.sweep`'s keywords ask for, on the scenario `text` of
/// `task` at `path`; errors name the keywords as `names` does.
fn sweep_spec(
    task: TaskKind,
    (text, path): (String, PathBuf),
    accuracy: Option<String>,
    params: Option<Vec<String>>,
    eeg: Option<&str>,
    (episodes, seed): (usize, u64),
    names: &Names,
) -> PyResult<SweepSpec> {
    let mut spec = SweepSpec {
        task,
        scenario_path: path,
        scenario_toml: text,
        accuracies: Vec::new(),
        axes: params
            .unwrap_or_default()
            .iter()
            .map(|p| parse_axis(task, p, names))
            .collect::<errp_sim::Result<_>>()
            .map_err(py_err)?,
        fixed: Vec::new(),
        episodes,
        seed,
    };
    // On own EEG no accuracy is targeted: no levels are needed (the
    // sweep's check refuses accuracy=, saying why).
    if accuracy.is_none() && !spec.on_own_eeg() {
        return Err(PyValueError::new_err(
            "accuracy: give the decoder accuracy levels (e.g. \"0.6:0.9:0.05\" or [0.7, 0.8]); \
             only a sweep over recordings (eeg.recording) has none",
        ));
    }
    spec.set_levels(accuracy.as_deref(), eeg, names)
        .map_err(py_err)?;
    Ok(spec)
}

/// Runs a Monte Carlo sweep as `errp sweep` does, into `out`, and returns
/// the paths of its files. A rerun of the same sweep into the same
/// directory resumes it.
#[pyfunction]
#[pyo3(signature = (out, keywords, progress=None))]
pub(crate) fn sweep<'py>(
    py: Python<'py>,
    out: PathBuf,
    keywords: SweepKeywords,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let SweepKeywords {
        accuracy,
        task,
        scenario,
        episodes,
        seed,
        params,
        per_action,
        stream,
        cache,
        threads,
    } = keywords;
    let want = sweep_task(task.as_deref())?;
    if !(1..=errp_sweep::MAX_EPISODES).contains(&episodes) {
        return Err(value_error(
            "episodes",
            episodes,
            &format!("a whole number from 1 to {}", errp_sweep::MAX_EPISODES),
        ));
    }
    let threads = match threads {
        Some(n) if !(1..=MAX_THREADS).contains(&n) => {
            return Err(value_error(
                "threads",
                n,
                &format!("a whole number from 1 to {MAX_THREADS}"),
            ));
        }
        Some(n) => n,
        None => rayon::current_num_threads(),
    };
    let (eeg, names) = eeg_mode(per_action, stream);
    let (task, text, path) = sweep_scenario(scenario.as_deref(), want, names).map_err(py_err)?;
    let spec = sweep_spec(
        task,
        (text, path),
        accuracy,
        params,
        eeg,
        (episodes, seed),
        &names,
    )?;
    let sweep = spec.checked(&names).map_err(py_err)?;
    let opts = SweepOptions {
        out: out.clone(),
        cache: match cache {
            Some(dir) => TargetCache::new(dir),
            None => TargetCache::disabled(),
        },
        shard: Shard::ALL,
        chunk: 0,
        repair: false,
    };
    let wind_down = WindDown::new();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| PyValueError::new_err(format!("threads: cannot start them: {e}")))?;
    // Ctrl-C's stop request winds the sweep down too: the rows written so
    // far are kept, and the same call later resumes.
    let watch = SweepWatch::default();
    if let Some(why) = opts.cache.unwritable("give another cache= directory") {
        watch.keep(&format!("cache: {why}"));
    }
    let outcome = long_or(py, progress.map(|p| (&watch.meter, p)), || {
        pool.install(|| errp_sweep::run_sweep(&sweep, &opts, &wind_down, &watch))
    })?
    .map_err(py_err)?;
    match outcome {
        SweepOutcome::Interrupted { .. } => {
            Err(PyKeyboardInterrupt::new_err("the sweep was interrupted"))
        }
        SweepOutcome::Complete { ran, total, .. } => {
            let d = PyDict::new(py);
            d.set_item("out", out.clone())?;
            d.set_item("episodes_csv", out.join(errp_sweep::EPISODES))?;
            d.set_item("summary_csv", out.join("summary.csv"))?;
            d.set_item("manifest", out.join(errp_sweep::MANIFEST))?;
            d.set_item("ran", ran)?;
            d.set_item("total", total)?;
            d.set_item("task", task.to_string())?;
            d.set_item(
                "warnings",
                watch
                    .warnings
                    .into_inner()
                    .unwrap_or_else(PoisonError::into_inner),
            )?;
            Ok(d)
        }
    }
}
