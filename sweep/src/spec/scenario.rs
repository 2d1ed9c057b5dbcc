//! The scenario a sweep runs, its task, and the values it sets for every
//! level.

use std::path::{Path, PathBuf};

use errp_sim::grid::EegMode;
use errp_sim::rules::{self, Origin, TaskValue};
use errp_sim::{Names, Result, ScenarioSource, SimError, TaskKind, scenario_kind};
use toml::Value;

/// The task of the scenario file at `path` and its text.
pub fn read_task(path: &Path) -> Result<(TaskKind, String)> {
    let text = ScenarioSource::File(path.to_path_buf()).read()?;
    let task = scenario_kind(&text, path)?;
    Ok((task, text))
}

/// The scenario a sweep runs: the file at `path` (its task checked against
/// `task` when both are given), or the built-in scenario of `task`, as
/// (task, text, path).
pub fn sweep_scenario(
    path: Option<&Path>,
    task: Option<TaskKind>,
    names: Names,
) -> Result<(TaskKind, String, PathBuf)> {
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
        (None, Some(task)) => {
            let source = ScenarioSource::built_in(task);
            Ok((task, source.read()?, source.path().to_path_buf()))
        }
        (None, None) => Err(SimError::Sweep(format!(
            "give {} FILE.toml, or {} grid|epuck for its built-in scenario",
            names.scenario, names.task
        ))),
    }
}

/// The scenario keys a sweep of `task` (the scenario at `path`) sets
/// whatever its levels: the grid reads its EEG as `eeg` says (a mode as
/// the caller gave it, `per_action` or `bank`, checked with the levels),
/// from a bank by default; the e-puck takes no EEG mode
/// ([`rules::task_takes`]).
pub fn sweep_fixed(
    task: TaskKind,
    path: &Path,
    eeg: Option<&str>,
    names: &Names,
) -> Result<Vec<(String, Value)>> {
    if eeg.is_some() {
        rules::task_takes(task, path, &[(TaskValue::EegMode, Origin::Sweep(names))])?;
    }
    Ok(match task {
        TaskKind::Grid => {
            let mode = eeg.unwrap_or(EegMode::Bank.key());
            vec![("eeg".to_string(), Value::String(mode.into()))]
        }
        TaskKind::Epuck => Vec::new(),
    })
}
