//! `errp.GridTask` and `errp.EpuckTask`: a scenario with its decoder
//! calibrated once, run with the testbed's decoder or with a decoder of the
//! caller's own in the closed loop.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use errp_bci::EegBlock;
use errp_sim::epuck::{ContinuousDecoder, EpuckScenario};
use errp_sim::grid::{
    AssessmentDecoder, EegDecoder, EpochBlocks, GridDecoding, GridScenario, prepare_decoder,
};
use errp_sim::rules::{self, Claim, Origin, OwnEegFrom};
use errp_sim::{
    BatchRecord, PendingRecording, RunProvenance, run_epuck_batch_recorded, run_grid_batch,
};
use errp_sim::{Names, TaskKind};
use numpy::{IntoPyArray, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{
    Keys, PyDecoder, blocks_to_array3, channel_names, check_callable, load_epuck, load_grid,
    py_err, value_error,
};
use crate::interrupt::{CALIBRATING, Meter, long, long_shown};
use crate::run::{
    DecoderSummary, RunMeter, check_save, epuck_csv, epuck_summary, grid_csv, grid_summary,
    summary_dict,
};

/// The call a task's recording names.
fn made_by(class: &str, own_decoder: bool) -> RunProvenance {
    let call = if own_decoder {
        format!("errp.{class}(decoder=...).run (a decoder of the caller's own)")
    } else {
        format!("errp.{class}.run")
    };
    RunProvenance {
        command: vec![format!("python: {call}")],
        commit: None,
    }
}

/// The EEG pipeline behind a grid decoder, if it reads EEG.
fn eeg_of(d: &AssessmentDecoder) -> Option<&EegDecoder> {
    match d {
        AssessmentDecoder::Eeg(e) => Some(e),
        AssessmentDecoder::EegBank(b) => Some(&b.decoder),
        AssessmentDecoder::Oracle { .. } | AssessmentDecoder::OwnEeg(_) => None,
    }
}

/// The grid task of a scenario (Table 1's protocol): its decoder calibrated
/// once at the scenario's accuracy, then episodes decoded by it or by a
/// decoder of the caller's own.
#[pyclass(module = "errp._core")]
pub(crate) struct GridTask {
    scenario: GridScenario,
    /// The scenario file as run (overrides set), for a recording.
    text: String,
    builtin: Arc<AssessmentDecoder>,
    decoder: Option<Py<PyAny>>,
    scores: Option<(Vec<f64>, Vec<f64>)>,
    calibration: DecoderSummary,
    calls: AtomicUsize,
}

#[pymethods]
impl GridTask {
    /// Calibrates the scenario's decoder; with `decoder` (called with each
    /// action's epoch) or `batch_decoder` (called once with a bank of
    /// epochs), a decoder of the caller's own replaces it in the loop.
    #[new]
    #[pyo3(signature = (scenario=None, *, decoder=None, batch_decoder=None, seed=None, accuracy=None, overrides=None, progress=None, eeg=None))]
    #[allow(clippy::too_many_arguments, reason = "Python's keywords, one each")]
    fn new(
        py: Python<'_>,
        scenario: Option<PathBuf>,
        decoder: Option<Py<PyAny>>,
        batch_decoder: Option<Py<PyAny>>,
        seed: Option<u64>,
        accuracy: Option<f64>,
        overrides: Option<&Bound<'_, PyDict>>,
        progress: Option<&Bound<'_, PyAny>>,
        eeg: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let given = Origin::Input(&Names::PYTHON);
        let supplied = eeg.map(|_| OwnEegFrom::Supplied(TaskKind::Grid));
        if let Some(a) = accuracy {
            rules::own_eeg_is_the_user(supplied, &[(Claim::Accuracy(a), given)]).map_err(py_err)?;
        }
        let keys = Keys {
            accuracy,
            seed,
            runs: None,
        };
        let (s, text) = load_grid(scenario, keys, overrides, "errp.GridTask")?;
        let s = match eeg {
            Some(eeg) => {
                let recorded = crate::own_eeg::supplied_own_eeg(
                    eeg,
                    std::path::Path::new("eeg_options"),
                    TaskKind::Grid,
                )?;
                s.on_own_eeg(recorded).map_err(py_err)?
            }
            None => s,
        };
        check_callable(py, "decoder", decoder.as_ref())?;
        check_callable(py, "batch_decoder", batch_decoder.as_ref())?;
        if decoder.is_some() && batch_decoder.is_some() {
            return Err(PyValueError::new_err(
                "decoder and batch_decoder: give one of them, not both",
            ));
        }
        if decoder.is_some() || batch_decoder.is_some() {
            let own = s
                .accuracy
                .own_eeg()
                .map(|e| e.origin(&s.path, TaskKind::Grid));
            rules::own_eeg_is_the_user(own, &[(Claim::OwnDecoder, given)]).map_err(py_err)?;
        }
        let meter = Meter::default();
        let (builtin, calibration) = long_shown(py, &meter, progress, || {
            prepare_decoder(&s, |_| meter.step(CALIBRATING, 0))
        })?
        .map_err(py_err)?;
        let recorded = match &builtin {
            AssessmentDecoder::OwnEeg(bank) => Some(&bank.report),
            _ => None,
        };
        let info = grid_summary(&s, recorded, calibration.as_ref());
        if (decoder.is_some() || batch_decoder.is_some()) && eeg_of(&builtin).is_none() {
            return Err(PyValueError::new_err(
                "decoder: the scenario's decoder is the oracle (no EEG); a decoder of your own \
                 reads EEG: set decoder = \"eeg\" in the scenario (overrides={\"decoder\": \"eeg\"})",
            ));
        }
        let mut task = Self {
            scenario: s,
            text,
            builtin: Arc::new(builtin),
            decoder,
            scores: None,
            calibration: info,
            calls: AtomicUsize::new(0),
        };
        if let Some(f) = batch_decoder {
            task.score_bank(py, f)?;
        }
        Ok(task)
    }

    /// Runs every episode of the scenario (episode k from the seed `errp
    /// run` gives it) and returns the rows as CSV text; with `save`, records
    /// them into that `.rrd` as `errp run --save` does.
    #[pyo3(signature = (save=None, progress=None))]
    fn run(
        &self,
        py: Python<'_>,
        save: Option<PathBuf>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<String> {
        check_save(save.as_ref())?;
        let s = &self.scenario;
        if save.is_some() {
            errp_sim::check_recordable_episodes(s, &Names::PYTHON).map_err(py_err)?;
        }
        let recording = PendingRecording::open(save.as_deref(), TaskKind::Grid).map_err(py_err)?;
        let own = self.decoder.is_some() || self.scores.is_some();
        let made_by = made_by("GridTask", own);
        let record = BatchRecord {
            flag: "save",
            text: &self.text,
            decoder_summary: "",
            made_by: &made_by,
        };
        let meter = Meter::default();
        let watch = RunMeter::new(&meter, s.episodes.len());
        let run = |decoding: GridDecoding<'_>| {
            run_grid_batch(s.clone(), None, decoding, recording, record, &watch)
        };
        let builtin = &self.builtin;
        let (report, _) = match (&self.decoder, &self.scores) {
            (Some(f), _) => {
                let mut dec = PyDecoder::new(f.clone_ref(py));
                let eeg = eeg_of(builtin).expect("checked: an EEG decoder");
                let result = long_shown(py, &meter, progress, || {
                    let mut call = |b: &EegBlock| dec.call(b);
                    run(GridDecoding::Epochs {
                        source: eeg.source(),
                        decode: &mut call,
                    })
                })?;
                self.calls.fetch_add(dec.calls, Ordering::Relaxed);
                result.map_err(|e| dec.error(e.error))?
            }
            (None, Some((error, correct))) => long_shown(py, &meter, progress, || {
                run(GridDecoding::Scores { error, correct })
            })?
            .map_err(|e| py_err(e.error))?,
            (None, None) => {
                long_shown(py, &meter, progress, || run(GridDecoding::Builtin(builtin)))?
                    .map_err(|e| py_err(e.error))?
            }
        };
        Ok(grid_csv(s, report.own_eeg.as_ref(), &report.episodes))
    }

    /// What the calibration found: the requested accuracy, the ErrP-to-noise
    /// ratio and the cross-validated accuracies of the testbed's decoder.
    #[getter]
    fn calibration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        summary_dict(py, &self.calibration)
    }

    /// Names of the channels of each epoch (the preprocessed EEG channels).
    #[getter]
    fn ch_names(&self) -> Vec<String> {
        eeg_of(&self.builtin).map_or_else(Vec::new, |e| {
            channel_names(&e.montage, e.preprocessor.outputs())
        })
    }

    /// Sampling rate of the epochs (Hz).
    #[getter]
    fn sfreq(&self) -> f64 {
        eeg_of(&self.builtin).map_or(errp_bci::SFREQ_HZ, |e| e.generator.sfreq_hz)
    }

    /// Samples per epoch, from the action's onset: the span of the paper's
    /// feature window ([200, 800] ms at 64 Hz).
    #[getter]
    fn n_samples(&self) -> usize {
        errp_bci::EpochWindow::paper(self.sfreq()).span()
    }

    /// Times the per-epoch decoder was called so far.
    #[getter]
    fn decoder_calls(&self) -> usize {
        self.calls.load(Ordering::Relaxed)
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.scenario.name.clone()
    }

    /// The scenario's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.scenario.seed
    }
}

impl GridTask {
    /// Streams the scenario's bank of epochs (`bank_per_class` of each
    /// class), has `f` score them in one call, and keeps the scores.
    fn score_bank(&mut self, py: Python<'_>, f: Py<PyAny>) -> PyResult<()> {
        let eeg = eeg_of(&self.builtin).expect("checked: an EEG decoder");
        let s = &self.scenario;
        let blocks = long(py, || {
            EpochBlocks::build(eeg.source(), &s.params, s.bank_per_class, s.seed)
        })?
        .map_err(py_err)?;
        let all: Vec<&EegBlock> = blocks.error.iter().chain(&blocks.correct).collect();
        let x = blocks_to_array3(&all).into_pyarray(py);
        let out = f.bind(py).call1((x,))?;
        let np = py.import("numpy")?;
        let p = np.call_method1("asarray", (out, "float64"))?;
        let p: PyReadonlyArray1<'_, f64> = p.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "batch_decoder: expected a 1-D array of {} p(error) values, one per epoch",
                all.len()
            ))
        })?;
        if p.len() != all.len() {
            return Err(value_error(
                "batch_decoder",
                format!("an array of {} values", p.len()),
                &format!("{} p(error) values, one per epoch", all.len()),
            ));
        }
        // Any 1-D array, a strided view (a column of predict_proba) too.
        let p = p.as_array().to_vec();
        for (i, &v) in p.iter().enumerate() {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(value_error(
                    &format!("batch_decoder: p(error) of epoch {i}"),
                    v,
                    "a number from 0 to 1",
                ));
            }
        }
        let n_error = blocks.error.len();
        self.scores = Some((p[..n_error].to_vec(), p[n_error..].to_vec()));
        Ok(())
    }
}

/// The e-puck task of a scenario (sec. 5): its continuous decoder
/// calibrated once, then runs decoded by it or by a decoder of the caller's
/// own, called with every 62.5 ms window.
#[pyclass(module = "errp._core")]
pub(crate) struct EpuckTask {
    scenario: EpuckScenario,
    /// The scenario file as run (overrides set), for a recording.
    text: String,
    builtin: Arc<ContinuousDecoder>,
    decoder: Option<Py<PyAny>>,
    calibration: DecoderSummary,
    calls: AtomicUsize,
}

#[pymethods]
impl EpuckTask {
    /// Calibrates the scenario's continuous decoder; with `decoder`, a
    /// decoder of the caller's own replaces it in the loop.
    #[new]
    #[pyo3(signature = (scenario=None, *, decoder=None, seed=None, accuracy=None, overrides=None, progress=None, eeg=None))]
    #[allow(clippy::too_many_arguments, reason = "Python's keywords, one each")]
    fn new(
        py: Python<'_>,
        scenario: Option<PathBuf>,
        decoder: Option<Py<PyAny>>,
        seed: Option<u64>,
        accuracy: Option<f64>,
        overrides: Option<&Bound<'_, PyDict>>,
        progress: Option<&Bound<'_, PyAny>>,
        eeg: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let given = Origin::Input(&Names::PYTHON);
        let supplied = eeg.map(|_| OwnEegFrom::Supplied(TaskKind::Epuck));
        let mut claims = Vec::new();
        if let Some(a) = accuracy {
            claims.push((Claim::Accuracy(a), given));
        }
        if decoder.is_some() {
            claims.push((Claim::OwnDecoder, given));
        }
        rules::own_eeg_is_the_user(supplied, &claims).map_err(py_err)?;
        let keys = Keys {
            accuracy,
            seed,
            runs: None,
        };
        let (s, text) = load_epuck(scenario, keys, overrides, "errp.EpuckTask")?;
        let s = match eeg {
            Some(eeg) => s.on_own_eeg(crate::own_eeg::supplied_own_eeg(
                eeg,
                std::path::Path::new("eeg_options"),
                TaskKind::Epuck,
            )?),
            None => s,
        };
        check_callable(py, "decoder", decoder.as_ref())?;
        if decoder.is_some() {
            let own = s
                .own_eeg
                .as_deref()
                .map(|e| e.origin(&s.path, TaskKind::Epuck));
            rules::own_eeg_is_the_user(own, &[(Claim::OwnDecoder, given)]).map_err(py_err)?;
        }
        let meter = Meter::default();
        let (builtin, report) = long_shown(py, &meter, progress, || {
            errp_sim::epuck::prepare_continuous_decoder_with(
                &s,
                |_| meter.step(CALIBRATING, 0),
                |_| meter.step(CALIBRATING, 0),
            )
        })?
        .map_err(py_err)?;
        let info = epuck_summary(&s, &builtin, &report);
        Ok(Self {
            scenario: s,
            text,
            builtin: Arc::new(builtin),
            decoder,
            calibration: info,
            calls: AtomicUsize::new(0),
        })
    }

    /// Runs `runs` runs (the scenario's by default; run k from the seed
    /// `errp run` gives it) and returns the rows as CSV text. With the
    /// testbed's decoder they run in parallel; a decoder of the caller's own
    /// runs them one after another. With `save` (at most 100 runs), the
    /// runs are recorded into that `.rrd` as `errp run --save` records
    /// them, one after another.
    #[pyo3(signature = (runs=None, *, save=None, progress=None))]
    fn run(
        &self,
        py: Python<'_>,
        runs: Option<usize>,
        save: Option<PathBuf>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<String> {
        check_save(save.as_ref())?;
        let max = errp_sim::epuck::MAX_RUNS as usize;
        let runs = runs.unwrap_or(self.scenario.runs);
        if !(1..=max).contains(&runs) {
            return Err(value_error(
                "runs",
                runs,
                &format!("a whole number from 1 to {max}"),
            ));
        }
        if save.is_some() {
            errp_sim::check_recordable_runs(runs as u64, &Names::PYTHON).map_err(py_err)?;
        }
        let s = &self.scenario;
        let d = &self.builtin;
        let recording = PendingRecording::open(save.as_deref(), TaskKind::Epuck).map_err(py_err)?;
        let made_by = made_by("EpuckTask", self.decoder.is_some());
        let record = BatchRecord {
            flag: "save",
            text: &self.text,
            decoder_summary: "",
            made_by: &made_by,
        };
        let meter = Meter::default();
        let watch = RunMeter::new(&meter, runs);
        let mut dec = self
            .decoder
            .as_ref()
            .map(|f| PyDecoder::new(f.clone_ref(py)));
        let result = long_shown(py, &meter, progress, || {
            let mut call;
            let window_decoder = match dec.as_mut() {
                Some(dec) => {
                    call = |b: &EegBlock| dec.call(b);
                    Some(&mut call as errp_sim::epuck::WindowDecoder<'_>)
                }
                None => None,
            };
            run_epuck_batch_recorded(s, d, runs, window_decoder, recording, record, &watch)
        })?;
        let (results, _) = match dec {
            Some(mut dec) => {
                self.calls.fetch_add(dec.calls, Ordering::Relaxed);
                result.map_err(|e| dec.error(e.error))?
            }
            None => result.map_err(|e| py_err(e.error))?,
        };
        Ok(epuck_csv(&self.scenario, &results))
    }

    /// What the calibration found (accuracy, ErrP-to-noise ratio,
    /// cross-validated accuracies, the detector's T_e and its operating
    /// point on a held-out session).
    #[getter]
    fn calibration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        summary_dict(py, &self.calibration)
    }

    /// Names of the channels of each window (the preprocessed EEG channels).
    #[getter]
    fn ch_names(&self) -> Vec<String> {
        channel_names(&self.builtin.montage, self.builtin.preprocessor.outputs())
    }

    /// Sampling rate of the windows (Hz).
    #[getter]
    fn sfreq(&self) -> f64 {
        self.builtin.generator.sfreq_hz
    }

    /// Samples per window (800 ms).
    #[getter]
    fn n_samples(&self) -> usize {
        self.builtin.features.span()
    }

    /// The detection threshold a decoder of the caller's own runs at: the
    /// scenario's `control.t_e`.
    #[getter]
    fn t_e(&self) -> f64 {
        self.builtin.detector_t_e(&self.scenario.params, true)
    }

    /// Times the decoder was called so far.
    #[getter]
    fn decoder_calls(&self) -> usize {
        self.calls.load(Ordering::Relaxed)
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.scenario.name.clone()
    }

    /// The scenario's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.scenario.seed
    }
}
