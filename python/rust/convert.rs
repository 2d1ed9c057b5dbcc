//! Conversions between Python and the crates' types: errors, scenario
//! overrides, EEG blocks as numpy arrays, and a decoder of the caller's own
//! called from inside the Rust loop.

use std::path::PathBuf;

use errp_bci::{EegBlock, Montage, RequestedAccuracy};
use errp_sim::epuck::EpuckScenario;
use errp_sim::grid::GridScenario;
use errp_sim::{
    AnyScenario, LoadedScenario, Names, ScenarioInput, ScenarioSeed, ScenarioSource, SimError,
    TaskKind,
};
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};

/// A crate error as a Python exception: files that cannot be read or
/// written are `OSError`, everything else is a `ValueError` whose message
/// names the field and what it accepts.
pub(crate) fn py_err(e: SimError) -> PyErr {
    let text = chain(&e);
    match e {
        SimError::Input { .. } | SimError::Output { .. } | SimError::Record { .. } => {
            PyOSError::new_err(text)
        }
        SimError::Bci(errp_bci::BciError::Interrupted) => PyKeyboardInterrupt::new_err(text),
        _ => PyValueError::new_err(text),
    }
}

/// An error and its causes, each once.
fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let part = s.to_string();
        if !text.contains(&part) {
            text.push_str(": ");
            text.push_str(&part);
        }
        source = s.source();
    }
    text
}

/// A `ValueError` naming `field`.
pub(crate) fn value_error(field: &str, value: impl std::fmt::Display, expected: &str) -> PyErr {
    PyValueError::new_err(format!("{field} = {value} is invalid: expected {expected}"))
}

/// The task named `text`, for the keyword `field`.
pub(crate) fn task_kind(field: &str, text: &str) -> PyResult<TaskKind> {
    text.parse()
        .map_err(|_| value_error(field, format!("{text:?}"), TaskKind::EXPECTED))
}

/// `overrides={"control.tau": 0.5, ...}` as scenario keys and TOML values,
/// in the dictionary's order; `set` are the keys the keyword arguments set,
/// which the dictionary may not set again.
fn overrides(
    set: &[&str],
    given: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(String, toml::Value)>> {
    let mut out: Vec<(String, toml::Value)> = Vec::new();
    if let Some(d) = given {
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyValueError::new_err(format!(
                    "overrides: key {k} is not a string; keys are the scenario's dotted \
                     fields, e.g. \"control.tau\""
                ))
            })?;
            if set.contains(&key.as_str()) || out.iter().any(|(have, _)| *have == key) {
                return Err(PyValueError::new_err(format!(
                    "overrides: `{key}` is set twice (once by a keyword argument)"
                )));
            }
            let value = toml_value(&key, &v)?;
            out.push((key, value));
        }
    }
    Ok(out)
}

/// A Python scalar or list as a TOML value.
pub(crate) fn toml_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        let i: i64 = v.extract().map_err(|_| {
            value_error(
                &format!("overrides[\"{key}\"]"),
                v,
                "an integer that fits 64 bits",
            )
        })?;
        return Ok(toml::Value::Integer(i));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyDict>() {
        // A table of its own (the EEG model's `realism`, say): its keys
        // named under this one in errors.
        let mut table = toml::Table::new();
        for (k, x) in v.extract::<Bound<'_, PyDict>>()?.iter() {
            let name: String = k.extract().map_err(|_| {
                value_error(
                    &format!("overrides[\"{key}\"]"),
                    &k,
                    "a dict with string keys",
                )
            })?;
            let value = toml_value(&format!("{key}.{name}"), &x)?;
            table.insert(name, value);
        }
        return Ok(toml::Value::Table(table));
    }
    if let Ok(items) = v.extract::<Vec<Bound<'_, PyAny>>>() {
        return Ok(toml::Value::Array(
            items
                .iter()
                .map(|x| toml_value(key, x))
                .collect::<PyResult<_>>()?,
        ));
    }
    Err(value_error(
        &format!("overrides[\"{key}\"]"),
        v.repr()?,
        "a bool, int, float, str or a list of them",
    ))
}

/// An EEG block `(n_channels, n_samples)` as a numpy array.
pub(crate) fn block_to_numpy<'py>(py: Python<'py>, b: &EegBlock) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((b.n_channels, b.n_samples), b.data.clone())
        .expect("a block's data is n_channels x n_samples")
        .into_pyarray(py)
}

/// Blocks of one shape as a `(n_blocks, n_channels, n_samples)` float32
/// array (half the memory of float64; EEG in uV needs no more).
pub(crate) fn blocks_to_array3(blocks: &[&EegBlock]) -> Array3<f32> {
    let (c, s) = blocks
        .first()
        .map_or((0, 0), |b| (b.n_channels, b.n_samples));
    let mut data = Vec::with_capacity(blocks.len() * c * s);
    for b in blocks {
        data.extend(b.data.iter().map(|&x| x as f32));
    }
    Array3::from_shape_vec((blocks.len(), c, s), data).expect("blocks of one shape")
}

/// The names of the channels a preprocessor outputs (indices into the
/// montage).
pub(crate) fn channel_names(montage: &Montage, outputs: &[usize]) -> Vec<String> {
    outputs
        .iter()
        .map(|&i| montage.channels()[i].name.clone())
        .collect()
}

/// Calls a decoder of the caller's own from the Rust loop (the GIL released
/// around it), remembering the first Python exception so that it reaches
/// the caller unchanged.
pub(crate) struct PyDecoder {
    f: Py<PyAny>,
    raised: Option<PyErr>,
    pub(crate) calls: usize,
}

impl PyDecoder {
    /// Wraps the callable `f`.
    pub(crate) fn new(f: Py<PyAny>) -> Self {
        Self {
            f,
            raised: None,
            calls: 0,
        }
    }

    /// p(error) of one window or epoch: `f(x)` for `x` an `(n_channels,
    /// n_samples)` float64 array.
    pub(crate) fn call(&mut self, block: &EegBlock) -> errp_sim::Result<f64> {
        self.calls += 1;
        let result = Python::attach(|py| -> PyResult<f64> {
            let x = block_to_numpy(py, block);
            let out = self.f.bind(py).call1((x,))?;
            out.extract::<f64>().map_err(|_| {
                let shown = out.repr().map(|r| r.to_string()).unwrap_or_default();
                PyValueError::new_err(format!(
                    "decoder: returned {shown}, expected p(error), a float from 0 to 1"
                ))
            })
        });
        result.map_err(|e| {
            let text = Python::attach(|py| e.value(py).to_string());
            self.raised.get_or_insert(e);
            SimError::DecoderRaised(text)
        })
    }

    /// The Python exception behind `e`, if the decoder raised one; else `e`
    /// as a Python exception.
    pub(crate) fn error(&mut self, e: SimError) -> PyErr {
        self.raised.take().unwrap_or_else(|| py_err(e))
    }
}

/// Checks that the argument `name`, if given, can be called.
pub(crate) fn check_callable(py: Python<'_>, name: &str, f: Option<&Py<PyAny>>) -> PyResult<()> {
    match f {
        Some(f) if !f.bind(py).is_callable() => Err(PyValueError::new_err(format!(
            "{name}: expected a callable returning p(error), got {}",
            f.bind(py).get_type().name()?
        ))),
        _ => Ok(()),
    }
}

/// The keyword arguments that set a scenario's keys, set before
/// `overrides=` and as `errp run`'s flags set them
/// ([`errp_sim::ScenarioInput`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Keys {
    /// `accuracy=`: `user.accuracy`.
    pub(crate) accuracy: Option<f64>,
    /// `seed=`: `seed` (a new simulated user, new runs, new free goals).
    pub(crate) seed: Option<u64>,
    /// `runs=`: `runs` (e-puck scenarios).
    pub(crate) runs: Option<usize>,
}

impl Keys {
    /// Only `accuracy=`.
    pub(crate) fn accuracy(accuracy: Option<f64>) -> Self {
        Self {
            accuracy,
            ..Self::default()
        }
    }

    /// The scenario `source` with these keys and `given` (`overrides=`)
    /// set, each checked here, where it enters.
    fn input(
        self,
        source: ScenarioSource,
        given: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<ScenarioInput> {
        let accuracy = self
            .accuracy
            .map(|a| {
                RequestedAccuracy::new(a).map_err(|_| {
                    value_error(
                        "accuracy",
                        a,
                        "a mean accuracy strictly between 0.5 and 1 (1 for the grid's oracle \
                         decoder)",
                    )
                })
            })
            .transpose()?;
        let seed = self
            .seed
            .map(|seed| {
                ScenarioSeed::new(seed).ok_or_else(|| {
                    value_error(
                        "seed",
                        seed,
                        &format!("a whole number from 0 to {}", ScenarioSeed::MAX),
                    )
                })
            })
            .transpose()?;
        let runs = match self.runs {
            None => None,
            Some(runs) => {
                let max = errp_sim::epuck::MAX_RUNS;
                let n = u64::try_from(runs).ok().filter(|n| (1..=max).contains(n));
                Some(n.ok_or_else(|| {
                    value_error("runs", runs, &format!("a whole number from 1 to {max}"))
                })?)
            }
        };
        let set: Vec<&str> = [
            (accuracy.is_some(), "user.accuracy"),
            (seed.is_some(), "seed"),
            (runs.is_some(), "runs"),
        ]
        .into_iter()
        .filter_map(|(on, key)| on.then_some(key))
        .collect();
        Ok(ScenarioInput {
            accuracy,
            seed,
            runs,
            keys: overrides(&set, given)?,
            ..ScenarioInput::new(source)
        })
    }
}

/// The scenario keyword (the file given, or the built-in scenario of
/// `default`) with `keys` and `overrides=` set, loaded once.
pub(crate) fn load(
    scenario: Option<PathBuf>,
    default: TaskKind,
    keys: Keys,
    given: Option<&Bound<'_, PyDict>>,
) -> PyResult<LoadedScenario> {
    if let Some(p) = &scenario
        && !p.exists()
    {
        return Err(PyFileNotFoundError::new_err(format!(
            "scenario: {} does not exist",
            p.display()
        )));
    }
    let source = ScenarioSource::file_or_built_in(scenario, default);
    keys.input(source, given)?
        .load(&Names::PYTHON)
        .map_err(py_err)
}

/// A grid scenario (the built-in one by default) and its text as run;
/// `who` names what needs it in the error for an e-puck scenario.
pub(crate) fn load_grid(
    scenario: Option<PathBuf>,
    keys: Keys,
    given: Option<&Bound<'_, PyDict>>,
    who: &str,
) -> PyResult<(GridScenario, String)> {
    let shown = shown(&scenario);
    let loaded = load(scenario, TaskKind::Grid, keys, given)?;
    match loaded.scenario {
        AnyScenario::Grid(s) => Ok((*s, loaded.text)),
        AnyScenario::Epuck(_) => Err(PyValueError::new_err(format!(
            "scenario: {shown} is an e-puck scenario; {who} needs a grid scenario"
        ))),
    }
}

/// An e-puck scenario (the built-in Mexico-to-Pisa one by default) and its
/// text as run.
pub(crate) fn load_epuck(
    scenario: Option<PathBuf>,
    keys: Keys,
    given: Option<&Bound<'_, PyDict>>,
    who: &str,
) -> PyResult<(EpuckScenario, String)> {
    let shown = shown(&scenario);
    let loaded = load(scenario, TaskKind::Epuck, keys, given)?;
    match loaded.scenario {
        AnyScenario::Epuck(s) => Ok((*s, loaded.text)),
        AnyScenario::Grid(_) => Err(PyValueError::new_err(format!(
            "scenario: {shown} is a grid scenario; {who} needs an e-puck scenario"
        ))),
    }
}

fn shown(scenario: &Option<PathBuf>) -> String {
    scenario
        .as_ref()
        .map_or_else(String::new, |p| p.display().to_string())
}
