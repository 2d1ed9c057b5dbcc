//! The cores of the Gymnasium environments (`errp.gym`): a scenario's
//! decoder calibrated once, then episodes stepped from Python.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use errp_robot::{Cell, GridAction};
use errp_sim::epuck::{
    ContinuousDecoder, EpuckAction, EpuckEnvironment, EpuckScenario, EpuckTask as EpuckInfo,
    prepare_continuous_decoder,
};
use errp_sim::grid::{
    AssessmentDecoder, GridEnvironment, GridScenario, GridTask as GridInfo, prepare_decoder,
};
use errp_sim::task::Task;
use errp_sim::{AgentInfo, EpuckAgentRecording, GridAgentRecording};
use numpy::PyArray2;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{Keys, block_to_numpy, load_epuck, load_grid, py_err, value_error};
use crate::interrupt::{CALIBRATING, Meter, long_shown};
use crate::run::check_save;

/// Who drives an environment's recorded episodes.
fn agent(class: &str, id: &str) -> AgentInfo {
    AgentInfo {
        command: vec![format!("python: errp.gym.{class}")],
        agent: format!(
            "an agent of the caller's own in errp.gym.{class} ({id}), not the shared control"
        ),
    }
}

/// What `close()` says of a recording: the path written, or why not.
fn closed(out: errp_sim::Result<Option<PathBuf>>) -> PyResult<Option<PathBuf>> {
    out.map_err(py_err)
}

/// How many calibrated decoders of each task a process keeps, so that
/// environments of one scenario (made again by `gym.make`, vectorised
/// copies) calibrate once.
const KEPT_DECODERS: usize = 8;

/// Decoders by [`Task::decoder_key`]: equal keys give equal decoders.
type Kept<D> = Mutex<Vec<(String, Arc<D>)>>;

static GRID_DECODERS: Kept<AssessmentDecoder> = Mutex::new(Vec::new());
static EPUCK_DECODERS: Kept<ContinuousDecoder> = Mutex::new(Vec::new());

/// A kept decoder of `key`.
fn cached<D>(kept: &Kept<D>, key: &str) -> Option<Arc<D>> {
    let kept = kept.lock().unwrap_or_else(|e| e.into_inner());
    kept.iter().find(|(k, _)| k == key).map(|(_, d)| d.clone())
}

/// Keeps `d` under `key`, dropping the oldest beyond [`KEPT_DECODERS`].
fn keep<D>(kept: &Kept<D>, key: String, d: Arc<D>) -> Arc<D> {
    let mut kept = kept.lock().unwrap_or_else(|e| e.into_inner());
    kept.retain(|(k, _)| *k != key);
    kept.push((key, d.clone()));
    if kept.len() > KEPT_DECODERS {
        kept.remove(0);
    }
    d
}

/// A grid scenario's decoder and the episode being stepped.
#[pyclass(module = "errp._core")]
pub(crate) struct GridEnvCore {
    scenario: GridScenario,
    decoder: Arc<AssessmentDecoder>,
    episode: Option<GridEnvironment>,
    /// The seed of the episode being stepped.
    seed: u64,
    save: GridAgentRecording,
}

/// A cell from `(x, y)`.
fn cell(name: &str, c: Option<(i64, i64)>) -> PyResult<Option<Cell>> {
    match c {
        None => Ok(None),
        Some((x, y)) if (0..5).contains(&x) && (0..5).contains(&y) => {
            Ok(Some(Cell::new(x as usize, y as usize)))
        }
        Some((x, y)) => Err(value_error(
            name,
            format!("({x}, {y})"),
            "a cell (x, y) of the 5x5 grid, x and y from 0 to 4",
        )),
    }
}

#[pymethods]
impl GridEnvCore {
    /// Loads the scenario (the built-in fixed-goals one by default) and
    /// calibrates its decoder (unless one of the same key is kept), its
    /// targeting steps reported to `progress`.
    /// With `save`, every episode (up to 5000) is recorded into that `.rrd`
    /// when it ends, and the file is moved into place by `close()`.
    #[new]
    #[pyo3(signature = (scenario=None, *, accuracy=None, overrides=None, save=None, progress=None))]
    fn new(
        py: Python<'_>,
        scenario: Option<PathBuf>,
        accuracy: Option<f64>,
        overrides: Option<&Bound<'_, PyDict>>,
        save: Option<PathBuf>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        check_save(save.as_ref())?;
        let (s, text) = load_grid(
            scenario,
            Keys::accuracy(accuracy),
            overrides,
            "the grid environment",
        )?;
        let save =
            GridAgentRecording::create(save.as_deref(), &s, text, agent("GridEnv", "errp/Grid-v0"))
                .map_err(py_err)?;
        let key = GridInfo::decoder_key(&s);
        let decoder = match cached(&GRID_DECODERS, &key) {
            Some(d) => d,
            None => {
                let meter = Meter::default();
                let (d, _) = long_shown(py, &meter, progress, || {
                    prepare_decoder(&s, |_| meter.step(CALIBRATING, 0))
                })?
                .map_err(py_err)?;
                keep(&GRID_DECODERS, key, Arc::new(d))
            }
        };
        Ok(Self {
            scenario: s,
            decoder,
            episode: None,
            seed: 0,
            save,
        })
    }

    /// Starts an episode from `start` towards `goal` (each drawn from `seed`
    /// when not given) and returns (cursor, goal). A recorded episode in
    /// progress is written first.
    #[pyo3(signature = (seed, start=None, goal=None))]
    fn reset(
        &mut self,
        seed: u64,
        start: Option<(i64, i64)>,
        goal: Option<(i64, i64)>,
    ) -> PyResult<((usize, usize), (usize, usize))> {
        let (start, goal) = (cell("start", start)?, cell("goal", goal)?);
        self.write_episode().map_err(py_err)?;
        let mut env = GridEnvironment::new(
            self.decoder.clone(),
            self.scenario.params,
            start,
            goal,
            seed,
        )
        .map_err(py_err)?;
        self.save.start(&mut env);
        let (c, g) = (env.cell(), env.goal());
        self.episode = Some(env);
        self.seed = seed;
        Ok(((c.x, c.y), (g.x, g.y)))
    }

    /// Writes the episode in progress (if it took an action) and moves the
    /// recording into place; returns its path, or None when there is no
    /// recording or no episode in it. The environment records no more.
    fn close(&mut self) -> PyResult<Option<PathBuf>> {
        closed(self.finish())
    }

    /// True when `save=` was given and no more episodes will be recorded
    /// (5000 are).
    #[getter]
    fn recording_full(&self) -> bool {
        self.save.full()
    }

    /// Takes action 0-4 (up, down, left, right, goal reached) and returns
    /// a dict: cursor, p_error, decoded_error, error (the user's judgement,
    /// for scoring), reached, interval_secs and, with `keep_epoch`, epoch.
    #[pyo3(signature = (action, keep_epoch=false))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: i64,
        keep_epoch: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let Some(env) = self.episode.as_mut() else {
            return Err(PyRuntimeError::new_err(
                "step before reset: call reset() first",
            ));
        };
        let a = match action {
            0..=4 => GridAction::ALL[action as usize],
            _ => {
                return Err(value_error(
                    "action",
                    action,
                    "0 (up), 1 (down), 2 (left), 3 (right) or 4 (goal reached)",
                ));
            }
        };
        let f = py.detach(|| env.step(a, keep_epoch)).map_err(py_err)?;
        if env.ended() {
            self.write_episode().map_err(py_err)?;
        }
        let d = PyDict::new(py);
        d.set_item("cursor", (f.cell.x, f.cell.y))?;
        d.set_item("p_error", f.p_error)?;
        d.set_item("decoded_error", f.decoded_error)?;
        d.set_item("error", f.error)?;
        d.set_item("reached", f.reached)?;
        d.set_item("interval_secs", f.interval_secs)?;
        if let Some(e) = &f.epoch {
            let x: Bound<'py, PyArray2<f64>> = block_to_numpy(py, e);
            d.set_item("epoch", x)?;
        }
        Ok(d)
    }

    /// True if the decoder synthesises each action's EEG (so epochs can be
    /// observed).
    #[getter]
    fn per_action(&self) -> bool {
        matches!(*self.decoder, AssessmentDecoder::Eeg(_))
    }

    /// Channels and samples of an epoch: (names, samples, sfreq).
    #[getter]
    fn epoch_shape(&self) -> (Vec<String>, usize, f64) {
        match &*self.decoder {
            AssessmentDecoder::Eeg(e) => {
                let fs = e.generator.sfreq_hz;
                (
                    crate::convert::channel_names(&e.montage, e.preprocessor.outputs()),
                    errp_bci::EpochWindow::paper(fs).span(),
                    fs,
                )
            }
            _ => (Vec::new(), 0, errp_bci::SFREQ_HZ),
        }
    }

    /// The scenario's action limit (`timing.max_actions`).
    #[getter]
    fn max_actions(&self) -> usize {
        self.scenario.params.max_actions
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.scenario.name.clone()
    }
}

impl GridEnvCore {
    /// Records the episode in progress, if it is recorded, took an action
    /// and is not written yet.
    fn write_episode(&mut self) -> errp_sim::Result<()> {
        match self.episode.as_ref() {
            Some(env) => self
                .save
                .write(self.seed, self.scenario.params.epoch_secs, env),
            None => Ok(()),
        }
    }

    /// Writes what is left and moves the recording into place.
    fn finish(&mut self) -> errp_sim::Result<Option<PathBuf>> {
        self.write_episode()?;
        self.save.finish()
    }
}

impl Drop for GridEnvCore {
    fn drop(&mut self) {
        if let Err(e) = self.finish() {
            eprintln!("errp.gym.GridEnv: the recording was not written: {e}");
        }
    }
}

/// An e-puck scenario's decoder and the episode being stepped.
#[pyclass(module = "errp._core")]
pub(crate) struct EpuckEnvCore {
    scenario: EpuckScenario,
    decoder: Arc<ContinuousDecoder>,
    episode: Option<EpuckEnvironment>,
    save: EpuckAgentRecording,
}

#[pymethods]
impl EpuckEnvCore {
    /// Loads the scenario (the built-in Mexico-to-Pisa one by default) and
    /// calibrates its continuous decoder (unless one of the same key is
    /// kept), its targeting steps reported to `progress`.
    /// With `save`, every episode (up to 100) is recorded into that `.rrd`
    /// as it runs, and the file is moved into place by `close()`.
    #[new]
    #[pyo3(signature = (scenario=None, *, accuracy=None, overrides=None, save=None, progress=None))]
    fn new(
        py: Python<'_>,
        scenario: Option<PathBuf>,
        accuracy: Option<f64>,
        overrides: Option<&Bound<'_, PyDict>>,
        save: Option<PathBuf>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        check_save(save.as_ref())?;
        let (s, text) = load_epuck(
            scenario,
            Keys::accuracy(accuracy),
            overrides,
            "the e-puck environment",
        )?;
        let key = EpuckInfo::decoder_key(&s);
        let decoder = match cached(&EPUCK_DECODERS, &key) {
            Some(d) => d,
            None => {
                let meter = Meter::default();
                let (d, _) = long_shown(py, &meter, progress, || {
                    prepare_continuous_decoder(&s, |_| meter.step(CALIBRATING, 0))
                })?
                .map_err(py_err)?;
                keep(&EPUCK_DECODERS, key, Arc::new(d))
            }
        };
        let save = EpuckAgentRecording::create(
            save.as_deref(),
            &s,
            decoder.detector_t_e(&s.params, false),
            text,
            agent("EpuckEnv", "errp/Epuck-v0"),
        )
        .map_err(py_err)?;
        Ok(Self {
            scenario: s,
            decoder,
            episode: None,
            save,
        })
    }

    /// Starts an episode from the scenario's start, the user wanting `goal`
    /// (the scenario's by default), and returns (x_m, y_m, heading_rad) as
    /// the camera sees it and the goal. A recorded episode in progress ends
    /// first, without a commitment.
    #[pyo3(signature = (seed, goal=None))]
    fn reset(&mut self, seed: u64, goal: Option<usize>) -> PyResult<((f64, f64, f64), usize)> {
        let env = EpuckEnvironment::new(self.decoder.clone(), &self.scenario, goal, seed)
            .map_err(py_err)?;
        self.end_episode();
        let name = &self.scenario.layout.goals()[env.goal()].name;
        self.save.start(&env, name, seed);
        let p = env.tracked();
        let g = env.goal();
        self.episode = Some(env);
        Ok(((p.x_m, p.y_m, p.heading_rad), g))
    }

    /// Ends the episode in progress (without a commitment, if it took an
    /// action) and moves the recording into place; returns its path, or
    /// None when there is no recording or no episode in it. The environment
    /// records no more.
    fn close(&mut self) -> PyResult<Option<PathBuf>> {
        closed(self.finish())
    }

    /// True when `save=` was given and no more episodes will be recorded
    /// (100 are).
    #[getter]
    fn recording_full(&self) -> bool {
        self.save.full()
    }

    /// Runs action 0-3 (forward, turn left, turn right, stop) for
    /// `windows` windows of 62.5 ms and returns a dict: pose, p_error (one
    /// per window), detected, errps (for scoring), on_goal, time_secs and,
    /// with `keep_window`, window.
    #[pyo3(signature = (action, windows, keep_window=false))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: i64,
        windows: usize,
        keep_window: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let Some(env) = self.episode.as_mut() else {
            return Err(PyRuntimeError::new_err(
                "step before reset: call reset() first",
            ));
        };
        let a = match action {
            0..=3 => EpuckAction::ALL[action as usize],
            _ => {
                return Err(value_error(
                    "action",
                    action,
                    "0 (forward), 1 (turn left), 2 (turn right) or 3 (stop)",
                ));
            }
        };
        let save = &mut self.save;
        let f = py
            .detach(|| save.step(env, a, windows, keep_window))
            .map_err(py_err)?;
        let d = PyDict::new(py);
        d.set_item(
            "pose",
            (f.tracked.x_m, f.tracked.y_m, f.tracked.heading_rad),
        )?;
        d.set_item("p_error", f.p_error)?;
        d.set_item("detected", f.detected)?;
        d.set_item("errps", f.errps)?;
        d.set_item("on_goal", f.on_goal)?;
        d.set_item("time_secs", f.time_secs)?;
        if let Some(w) = &f.window {
            d.set_item("window", block_to_numpy(py, w))?;
        }
        Ok(d)
    }

    /// Channels and samples of a window: (names, samples, sfreq).
    #[getter]
    fn window_shape(&self) -> (Vec<String>, usize, f64) {
        let d = &self.decoder;
        (
            crate::convert::channel_names(&d.montage, d.preprocessor.outputs()),
            d.features.span(),
            d.generator.sfreq_hz,
        )
    }

    /// The names of the 25 goals.
    #[getter]
    fn goal_names(&self) -> Vec<String> {
        self.scenario
            .layout
            .names()
            .into_iter()
            .map(String::from)
            .collect()
    }

    /// The 25 goals: (name, x_m, y_m).
    #[getter]
    fn goals(&self) -> Vec<(String, f64, f64)> {
        self.scenario
            .layout
            .goals()
            .iter()
            .map(|g| (g.name.clone(), g.x_m, g.y_m))
            .collect()
    }

    /// How near its centre the robot must stop to be on a goal (m).
    #[getter]
    fn goal_radius_m(&self) -> f64 {
        self.scenario.params.control.goal_radius_m
    }

    /// The obstacles' outlines: one list of (x_m, y_m) per obstacle.
    #[getter]
    fn obstacles(&self) -> Vec<Vec<(f64, f64)>> {
        self.scenario
            .arena
            .obstacles
            .iter()
            .map(|o| o.outline())
            .collect()
    }

    /// The arena's side (m).
    #[getter]
    fn arena_size_m(&self) -> f64 {
        self.scenario.layout.arena_size_m()
    }

    /// The scenario's time limit (s).
    #[getter]
    fn max_secs(&self) -> f64 {
        self.scenario.params.max_secs
    }

    /// The scenario's goal.
    #[getter]
    fn scenario_goal(&self) -> usize {
        self.scenario.episode.goal
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.scenario.name.clone()
    }
}

impl EpuckEnvCore {
    /// Ends the recorded episode in progress, if it took a step.
    fn end_episode(&mut self) {
        if let Some(env) = self.episode.as_mut() {
            self.save.end(env);
        }
    }

    /// Ends what is in progress and moves the recording into place.
    fn finish(&mut self) -> errp_sim::Result<Option<PathBuf>> {
        self.end_episode();
        self.save.finish()
    }
}

impl Drop for EpuckEnvCore {
    fn drop(&mut self) {
        if let Err(e) = self.finish() {
            eprintln!("errp.gym.EpuckEnv: the recording was not written: {e}");
        }
    }
}
