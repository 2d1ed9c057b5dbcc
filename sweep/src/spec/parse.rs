//! A sweep's inputs parsed: values and ranges, accuracies, parameter axes, the scenario and the fixed values, with how the caller names them.

#[allow(clippy::wildcard_imports, unused_imports)]
use super::*;

/// The first value that appears twice in `values` (as the CSV writes it).
pub(super) fn repeated(values: &[Value]) -> Option<String> {
    let texts: Vec<String> = values.iter().map(value_text).collect();
    texts
        .iter()
        .enumerate()
        .find(|(i, t)| texts[..*i].contains(t))
        .map(|(_, t)| t.clone())
}

/// Rounds away the binary noise of `a + k * step` (`0.30000000000000004`).
pub(super) fn tidy(x: f64) -> f64 {
    let r = (x * 1e12).round() / 1e12;
    if r == 0.0 { 0.0 } else { r }
}

/// Parses `start:stop:step` (stop included), `a,b,c` or a single value.
/// Numbers stay numbers (integers if every part is one); anything else is a
/// string. `what` names the flag in errors.
pub fn parse_values(text: &str, what: &str) -> Result<Vec<Value>> {
    let bad = |why: &str| SimError::Sweep(format!("{what} {text:?} is invalid: {why}"));
    let text = text.trim();
    if text.is_empty() {
        return Err(bad("no values"));
    }
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    if parts.len() == 3 {
        let ints: Option<Vec<i64>> = parts.iter().map(|p| p.parse::<i64>().ok()).collect();
        if let Some([a, b, step]) = ints.as_deref() {
            if *step <= 0 || b < a {
                return Err(bad(
                    "a range start:stop:step needs step > 0 and stop >= start",
                ));
            }
            let n = (i128::from(*b) - i128::from(*a)) / i128::from(*step) + 1;
            if n > 10_000 {
                return Err(bad(&format!("it gives {n} values, more than 10000")));
            }
            return Ok((0..n as i64)
                .map(|k| Value::Integer(a + k * step))
                .collect());
        }
        let nums: Option<Vec<f64>> = parts.iter().map(|p| p.parse::<f64>().ok()).collect();
        let Some([a, b, step]) = nums.as_deref() else {
            return Err(bad(
                "a range start:stop:step takes three numbers, e.g. 0.55:0.95:0.05",
            ));
        };
        if !(a.is_finite() && b.is_finite() && step.is_finite() && *step > 0.0 && b >= a) {
            return Err(bad(
                "a range start:stop:step needs finite numbers, step > 0 and stop >= start",
            ));
        }
        // Counted in floating point: a tiny step gives more values than an
        // integer holds.
        let count = ((b - a) / step + 1e-9).floor() + 1.0;
        if !count.is_finite() || count > 10_000.0 {
            return Err(bad(&format!(
                "it gives {count:.3e} values, more than 10000"
            )));
        }
        let n = count as usize;
        return Ok((0..n)
            .map(|k| Value::Float(tidy(a + k as f64 * step)))
            .collect());
    }
    if parts.len() != 1 {
        return Err(bad("expected start:stop:step, a list a,b,c or one value"));
    }
    text.split(',')
        .map(str::trim)
        .map(|s| {
            if s.is_empty() {
                Err(bad("an empty item in the list"))
            } else if let Ok(i) = s.parse::<i64>() {
                Ok(Value::Integer(i))
            } else if let Ok(x) = s.parse::<f64>() {
                if x.is_finite() {
                    Ok(Value::Float(x))
                } else {
                    Err(bad("values must be finite"))
                }
            } else if s == "true" || s == "false" {
                Ok(Value::Boolean(s == "true"))
            } else {
                Ok(Value::String(s.to_string()))
            }
        })
        .collect()
}

/// Parses the `--accuracy` levels: numbers in (0.5, 1), 1 allowed for the
/// grid's oracle decoder. Errors name the levels as `names` does.
pub fn parse_accuracies(text: &str, names: &InputNames) -> Result<Vec<f64>> {
    let flag = names.accuracy;
    let values = parse_values(text, flag)?;
    let mut out = Vec::with_capacity(values.len());
    for v in values {
        let a = match v {
            Value::Float(x) => x,
            Value::Integer(i) => i as f64,
            other => {
                return Err(SimError::Sweep(format!(
                    "{flag} {text:?} is invalid: {} is not a number",
                    value_text(&other)
                )));
            }
        };
        // 1 is for the oracle; a grid EEG or e-puck scenario refuses it.
        if RequestedAccuracy::new(a).is_err() {
            return Err(SimError::Sweep(format!(
                "{flag} {text:?} is invalid: {a} is not a mean accuracy in (0.5, 1) \
                 (e.g. 0.55:0.95:0.05)"
            )));
        }
        out.push(a);
    }
    Ok(out)
}

/// The sweepable parameters of `task`: (short name, dotted key). Any other
/// parameter is named by its dotted path.
pub fn sweepable(task: SweepTask) -> &'static [(&'static str, &'static str)] {
    task.info().sweepable
}

/// The dotted key of short name `name` for `task`.
pub(super) fn alias(task: SweepTask, name: &str) -> Option<&'static str> {
    sweepable(task)
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, k)| *k)
}

/// The short names accepted for `task`, for error messages and help.
pub fn aliases(task: SweepTask) -> String {
    let names: Vec<&str> = sweepable(task).iter().map(|(n, _)| *n).collect();
    names.join(", ")
}

/// Parses one `--param NAME=VALUES` for `task`. Errors name it as `names`
/// does.
pub fn parse_axis(task: SweepTask, text: &str, names: &InputNames) -> Result<Axis> {
    let flag = names.param;
    let (name, values) = text.split_once('=').ok_or_else(|| {
        SimError::Sweep(format!(
            "{flag} {text:?} is invalid: expected NAME=VALUES, e.g. tau=0.1:0.5:0.1 or \
             strategy=greedy,info_gain"
        ))
    })?;
    let name = name.trim();
    let key = if name.contains('.') {
        name.to_string()
    } else {
        alias(task, name)
            .ok_or_else(|| {
                SimError::Sweep(format!(
                    "{flag} {name}: not a {task} scenario parameter; use one of {} or a \
                     dotted path into the scenario file (e.g. control.tau)",
                    aliases(task)
                ))
            })?
            .to_string()
    };
    if matches!(
        key.as_str(),
        "seed" | "task" | "user.accuracy" | "user.subject"
    ) {
        return Err(SimError::Sweep(format!(
            "{flag} {name}: sweep the accuracy with {} and set the seed with {}",
            names.accuracy, names.seed
        )));
    }
    if key.split('.').count() > errp_sim::MAX_KEY_PARTS
        || !key
            .split('.')
            .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_'))
    {
        return Err(SimError::Sweep(format!(
            "{flag} {}: not a scenario field: a field is a dotted key of 1 to {} parts of \
             letters, digits and _ (e.g. control.tau)",
            errp_sim::truncate(name, 60),
            errp_sim::MAX_KEY_PARTS
        )));
    }
    // Values given twice are refused with the other checks of a whole
    // sweep (`SweepSpec::check`).
    Ok(Axis {
        name: name.to_string(),
        key,
        values: parse_values(values, &format!("{flag} {name}"))?,
    })
}

/// The task of the scenario file at `path` and its text.
pub fn read_task(path: &Path) -> Result<(SweepTask, String)> {
    let text = ScenarioSource::File(path.to_path_buf()).read()?;
    let task = if is_epuck(&text, path)? {
        SweepTask::Epuck
    } else {
        SweepTask::Grid
    };
    Ok((task, text))
}

pub use errp_sim::{BUILT_IN_EPUCK, BUILT_IN_GRID};

/// How a caller names a sweep's inputs in its errors: `--task` on the
/// command line, `task=` in Python.
#[derive(Debug, Clone, Copy)]
pub struct InputNames {
    /// The scenario file.
    pub scenario: &'static str,
    /// The task.
    pub task: &'static str,
    /// The grid's EEG mode.
    pub eeg: &'static str,
    /// The accuracy levels.
    pub accuracy: &'static str,
    /// A swept parameter.
    pub param: &'static str,
    /// The episodes per level.
    pub episodes: &'static str,
    /// The sweep's seed.
    pub seed: &'static str,
}

impl InputNames {
    /// The command line's flags.
    pub const CLI: InputNames = InputNames {
        scenario: "--scenario",
        task: "--task",
        eeg: "--eeg",
        accuracy: "--accuracy",
        param: "--param",
        episodes: "--episodes",
        seed: "--seed",
    };
}

/// The scenario a sweep runs: the file at `path` (its task checked against
/// `task` when both are given), or the built-in scenario of `task`, as
/// (task, text, path).
pub fn sweep_scenario(
    path: Option<&Path>,
    task: Option<SweepTask>,
    names: InputNames,
) -> Result<(SweepTask, String, PathBuf)> {
    match (path, task) {
        (Some(path), task) => {
            let (t, text) = read_task(path)?;
            if let Some(want) = task
                && want != t
            {
                return Err(SimError::Sweep(format!(
                    "{} {want} does not match {}, a {t} scenario (its `task` field)",
                    names.task,
                    path.display()
                )));
            }
            Ok((t, text, path.to_path_buf()))
        }
        (None, Some(SweepTask::Grid)) => Ok((
            SweepTask::Grid,
            BUILT_IN_GRID.to_string(),
            PathBuf::from("scenarios/grid_fixed_goals.toml"),
        )),
        (None, Some(SweepTask::Epuck)) => Ok((
            SweepTask::Epuck,
            BUILT_IN_EPUCK.to_string(),
            PathBuf::from("scenarios/mexico_to_pisa.toml"),
        )),
        (None, None) => Err(SimError::Sweep(format!(
            "give {} FILE.toml, or {} grid|epuck for its built-in scenario",
            names.scenario, names.task
        ))),
    }
}

/// The scenario keys a sweep of `task` sets whatever its levels: the grid
/// reads its epochs from a bank unless `stream` is asked for (`eeg`:
/// `Some(true)` streams, `Some(false)` or none uses the bank); the e-puck
/// always streams, so an `eeg` choice is refused.
pub fn sweep_fixed(
    task: SweepTask,
    stream: Option<bool>,
    names: InputNames,
) -> Result<Vec<(String, Value)>> {
    match (task, stream) {
        (SweepTask::Grid, stream) => Ok(vec![(
            "eeg".to_string(),
            Value::String(
                if stream == Some(true) {
                    "stream"
                } else {
                    "bank"
                }
                .into(),
            ),
        )]),
        (SweepTask::Epuck, Some(_)) => Err(SimError::Sweep(format!(
            "{} applies to the grid; the e-puck always streams its EEG",
            names.eeg
        ))),
        (SweepTask::Epuck, None) => Ok(Vec::new()),
    }
}
