//! Synthetic EEG for Python: the calibration session of `errp calibrate`,
//! and a streaming generator.

use errp_bci::{
    Accuracy, Assessment, AssessmentKind, CalibrationSession, ContinuousFeatures, EegBlock,
    EpochWindow, GeneratorParams, MeanAccuracy, Montage, SessionOptions, SvmDecoder, TargetingStep,
    Valid, calibrate_continuous_with, continuous_schedule, cv_seed, stratified_folds,
};
use errp_sim::calibration::{CalibrationRequest, run_calibration};
use errp_sim::epuck::{ContinuousRequest, target_continuous};
use numpy::ndarray::Array1;
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{
    block_to_numpy, blocks_to_array3, channel_names, py_err, toml_value, value_error,
};
use crate::interrupt::{CALIBRATING, Meter, long_shown};

/// The most samples one `generate` call returns: an hour at 256 Hz.
pub(crate) const MAX_GENERATE_SAMPLES: usize = 3600 * errp_bci::SFREQ_HZ as usize;

/// Simulates the discrete calibration session of `errp calibrate
/// --accuracy ACCURACY --seed SEED`: the ErrP-to-noise ratio targeted so
/// that the paper's decoder reaches `accuracy` by cross-validation, then 400
/// actions (20 % erroneous) at that ratio. Returns the raw EEG (all 40
/// channels, uV), its events, the preprocessed epochs and the targeting.
///
/// With `continuous`, the continuous decoder's calibration session instead
/// (sec. 5.1), as the e-puck task calibrates it: the ratio targeted for the
/// RBF SVM on the 512 features of an 800 ms window, then 70 erroneous and
/// 70 correct assessments; the epochs are the example windows, from the
/// user's button presses (`window_starts`).
#[pyfunction]
#[pyo3(signature = (accuracy=0.7438, seed=1, continuous=false, progress=None))]
pub(crate) fn simulate_session<'py>(
    py: Python<'py>,
    accuracy: f64,
    seed: u64,
    continuous: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let accuracy = MeanAccuracy::new(accuracy).map_err(|e| py_err(e.into()))?;
    let meter = Meter::default();
    let (sim, raw, events) = long_shown(py, &meter, progress, || {
        let step = |_: &TargetingStep| meter.step(CALIBRATING, 0);
        let mut rec = RawRecorder::default();
        let sim = {
            let mut sink = rec.sink();
            let options = SessionOptions {
                raw_sink: Some(&mut sink),
                ..SessionOptions::default()
            };
            if continuous {
                continuous_calibration(accuracy, seed, step, options)?
            } else {
                discrete_calibration(accuracy, seed, step, options)?
            }
        };
        let (raw, events) = rec.finish();
        Ok::<_, errp_sim::SimError>((sim, raw, events))
    })?
    .map_err(py_err)?;
    // Discrete: each action's epoch from its onset.
    let starts = match &sim.window_starts {
        Some(w) => w.clone(),
        None => events.iter().map(|a| a.onset_secs).collect(),
    };
    let out = Recorded {
        raw: &raw,
        events: &events,
        starts: &starts,
        sim: &sim,
    };
    let d = out.dict(py, accuracy, seed)?;
    if let Some(w) = &sim.window_starts {
        d.set_item("window_starts", Array1::from(w.clone()).into_pyarray(py))?;
    }
    Ok(d)
}

/// A calibration session and what its cross-validation found.
struct Simulated {
    generator: Valid<GeneratorParams>,
    accuracy: Accuracy,
    session: CalibrationSession,
    /// The examples' window starts (s), for the continuous protocol.
    window_starts: Option<Vec<f64>>,
    /// Samples per epoch: the span of the decoder's features.
    span: usize,
    folds: usize,
}

fn discrete_calibration(
    accuracy: MeanAccuracy,
    seed: u64,
    step: impl FnMut(&TargetingStep),
    options: SessionOptions<'_>,
) -> errp_sim::Result<Simulated> {
    let request = CalibrationRequest::new(accuracy, seed);
    let report = run_calibration(&request, step, options)?;
    Ok(Simulated {
        span: EpochWindow::paper(report.generator.sfreq_hz).span(),
        generator: report.generator,
        accuracy: report.calibrated.accuracy,
        session: report.calibrated.session,
        window_starts: None,
        folds: request.setup.calibration.folds,
    })
}

fn continuous_calibration(
    accuracy: MeanAccuracy,
    seed: u64,
    step: impl FnMut(&TargetingStep),
    options: SessionOptions<'_>,
) -> errp_sim::Result<Simulated> {
    let request = ContinuousRequest::new(accuracy, seed);
    let targeting = target_continuous(&request, step)?;
    let setup = Valid::new(request.setup.at_ratio(targeting.ratio)?)?;
    let c = calibrate_continuous_with(&SvmDecoder::default(), &setup, seed, options)?;
    let (_, starts) = continuous_schedule(&request.setup.calibration, seed);
    Ok(Simulated {
        generator: setup.generator.clone(),
        accuracy: c.accuracy,
        session: c.session,
        window_starts: Some(starts),
        span: ContinuousFeatures::paper(setup.generator.sfreq_hz).span(),
        folds: request.setup.calibration.folds,
    })
}

/// The raw blocks of a session and the assessments whose onsets fall in
/// them, as the session's raw sink gives them.
#[derive(Default)]
struct RawRecorder {
    blocks: Vec<EegBlock>,
    events: Vec<Assessment>,
}

impl RawRecorder {
    fn sink(&mut self) -> impl FnMut(&EegBlock, &[Assessment]) -> errp_bci::Result<()> + '_ {
        |block, now| {
            self.blocks.push(block.clone());
            self.events.extend_from_slice(now);
            Ok(())
        }
    }

    fn finish(self) -> (EegBlock, Vec<Assessment>) {
        (EegBlock::concat(&self.blocks), self.events)
    }
}

/// A simulated session as Python receives it.
struct Recorded<'a> {
    raw: &'a EegBlock,
    events: &'a [Assessment],
    /// The start of each epoch (s).
    starts: &'a [f64],
    sim: &'a Simulated,
}

impl Recorded<'_> {
    fn dict<'py>(
        &self,
        py: Python<'py>,
        accuracy: MeanAccuracy,
        seed: u64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (generator, cv, session) = (&self.sim.generator, &self.sim.accuracy, &self.sim.session);
        let montage = Montage::standard();
        let fs = generator.sfreq_hz;
        // The epochs a decoder of the user's own reads in the closed loop:
        // the session through the preprocessing fitted on its EOG recording
        // (notch, band-pass, CAR, EOG regression), `span` samples from each
        // start.
        let mut preprocessor = session.preprocessor.clone();
        let span = self.sim.span;
        let clean = py.detach(|| {
            preprocessor.reset();
            preprocessor.process(self.raw)
        });
        let mut epochs = Vec::with_capacity(self.starts.len());
        for &t in self.starts {
            let start = (t * fs).round() as usize;
            if start + span > clean.n_samples {
                continue;
            }
            let mut e = EegBlock::zeros(clean.n_channels, span);
            for ch in 0..clean.n_channels {
                e.channel_mut(ch)
                    .copy_from_slice(&clean.channel(ch)[start..start + span]);
            }
            epochs.push(e);
        }
        let refs: Vec<&EegBlock> = epochs.iter().collect();
        let kind = |c: &errp_bci::Channel| match c.kind {
            errp_bci::ChannelKind::Eeg => "eeg",
            errp_bci::ChannelKind::Eog => "eog",
        };
        let d = PyDict::new(py);
        d.set_item("data", block_to_numpy(py, self.raw))?;
        d.set_item(
            "ch_names",
            montage
                .channels()
                .iter()
                .map(|c| c.name.clone())
                .collect::<Vec<_>>(),
        )?;
        d.set_item(
            "ch_types",
            montage.channels().iter().map(kind).collect::<Vec<_>>(),
        )?;
        d.set_item("sfreq", fs)?;
        d.set_item(
            "onsets",
            Array1::from_iter(self.events.iter().map(|a| a.onset_secs)).into_pyarray(py),
        )?;
        d.set_item(
            "labels",
            self.events
                .iter()
                .map(|a| match a.kind {
                    AssessmentKind::Error => "error",
                    AssessmentKind::Correct => "correct",
                })
                .collect::<Vec<_>>(),
        )?;
        d.set_item("epochs", blocks_to_array3(&refs).into_pyarray(py))?;
        d.set_item(
            "epoch_ch_names",
            channel_names(&montage, session.preprocessor.outputs()),
        )?;
        d.set_item("errp_to_noise", generator.errp_to_noise)?;
        d.set_item("accuracy", accuracy.get())?;
        d.set_item("cv_correct", cv.correct)?;
        d.set_item("cv_error", cv.error)?;
        d.set_item("cv_mean", cv.mean())?;
        d.set_item("seed", seed)?;
        // The folds the session's accuracy was cross-validated on.
        let folds = stratified_folds(&session.labels, self.sim.folds, cv_seed(seed));
        d.set_item(
            "cv_folds",
            Array1::from_iter(folds.into_iter().map(|k| k as i64)).into_pyarray(py),
        )?;
        Ok(d)
    }
}

/// A streaming synthetic EEG generator (34 EEG + 6 EOG channels, 256 Hz, in
/// uV): 1/f background with an alpha rhythm, spatially correlated, line
/// noise, blinks and saccades, and the ErrP of each scheduled assessment.
/// State (filters, noise, pending potentials) carries across calls, so ten
/// blocks of 1 s equal one block of 10 s.
#[pyclass(module = "errp._core")]
pub(crate) struct EegGenerator {
    inner: errp_bci::EegGenerator,
}

#[pymethods]
impl EegGenerator {
    /// A generator seeded `seed`; `errp_to_noise` scales the ErrP against
    /// the background (the knob the accuracy targeting turns; a session's
    /// `errp_to_noise` gives the same user); `params` sets other fields of
    /// the EEG model by name (`blink_rate_hz`, `line_noise_uv`, ...).
    #[new]
    #[pyo3(signature = (seed=0, errp_to_noise=1.0, params=None))]
    fn new(seed: u64, errp_to_noise: f64, params: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut table = toml::Table::new();
        if let Some(p) = params {
            for (k, v) in p.iter() {
                let key: String = k.extract()?;
                table.insert(key.clone(), toml_value(&key, &v)?);
            }
        }
        if table.contains_key("errp_to_noise") {
            return Err(PyValueError::new_err(
                "params: give errp_to_noise as its own argument, not in params",
            ));
        }
        table.insert("errp_to_noise".into(), toml::Value::Float(errp_to_noise));
        let gp: GeneratorParams = toml::Value::Table(table).try_into().map_err(|e| {
            PyValueError::new_err(format!(
                "params: {}",
                e.to_string().lines().next().unwrap_or("")
            ))
        })?;
        let gp = errp_bci::Valid::new(gp).map_err(|e| py_err(e.into()))?;
        let inner = errp_bci::EegGenerator::new(&gp, &Montage::standard(), seed)
            .map_err(|e| py_err(e.into()))?;
        Ok(Self { inner })
    }

    /// Schedules the potential of an assessment: `kind` is "error" or
    /// "correct", `onset_secs` its time zero on the generator's clock (s;
    /// it may lie in the past of the stream by up to the potential's
    /// length, or in the future).
    fn schedule(&mut self, onset_secs: f64, kind: &str) -> PyResult<()> {
        let kind = match kind {
            "error" => AssessmentKind::Error,
            "correct" => AssessmentKind::Correct,
            other => {
                return Err(value_error(
                    "kind",
                    format!("{other:?}"),
                    "\"error\" or \"correct\"",
                ));
            }
        };
        if !(onset_secs.is_finite() && onset_secs >= 0.0) {
            return Err(value_error("onset_secs", onset_secs, "a time >= 0 (s)"));
        }
        self.inner.schedule(Assessment { onset_secs, kind });
        Ok(())
    }

    /// The next `n_samples` samples, `(n_channels, n_samples)` float64 in
    /// uV, rows in `ch_names` order.
    fn generate<'py>(
        &mut self,
        py: Python<'py>,
        n_samples: usize,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        if n_samples > MAX_GENERATE_SAMPLES {
            return Err(value_error(
                "n_samples",
                n_samples,
                &format!("at most {MAX_GENERATE_SAMPLES} (an hour at 256 Hz) per call"),
            ));
        }
        let inner = &mut self.inner;
        let block = py.detach(|| inner.generate(n_samples));
        Ok(block_to_numpy(py, &block))
    }

    /// Channel names, EEG first, then EOG.
    #[getter]
    fn ch_names(&self) -> Vec<String> {
        self.inner
            .montage()
            .channels()
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }

    /// "eeg" or "eog" for each channel.
    #[getter]
    fn ch_types(&self) -> Vec<&'static str> {
        self.inner
            .montage()
            .channels()
            .iter()
            .map(|c| match c.kind {
                errp_bci::ChannelKind::Eeg => "eeg",
                errp_bci::ChannelKind::Eog => "eog",
            })
            .collect()
    }

    /// Sampling rate (Hz).
    #[getter]
    fn sfreq(&self) -> f64 {
        self.inner.params().sfreq_hz
    }

    /// The generator's clock: seconds generated so far.
    #[getter]
    fn now_secs(&self) -> f64 {
        self.inner.now_secs()
    }

    /// The ErrP-to-noise ratio.
    #[getter]
    fn errp_to_noise(&self) -> f64 {
        self.inner.params().errp_to_noise
    }
}
