//! A scenario of either task: loading a file, with command-line overrides
//! set as its own keys, and dispatch on its `task` field.

use std::path::Path;

use serde::Deserialize;

use crate::epuck::scenario::EpuckScenario;
use crate::error::{Result, SimError};
use crate::grid::scenario::GridScenario;
use crate::scenario_file::{parse_toml, read_scenario, set_key};

/// A scenario of either task, as `errp run` takes it.
#[derive(Debug, Clone)]
pub enum AnyScenario {
    /// The discrete 5x5 grid task (sec. 4).
    Grid(Box<GridScenario>),
    /// The continuous e-puck task (sec. 5).
    Epuck(Box<EpuckScenario>),
}

/// Reads a scenario file and validates it according to its `task` field.
pub fn load_scenario(path: impl AsRef<Path>) -> Result<AnyScenario> {
    let path = path.as_ref();
    parse_scenario(&read_scenario(path)?, path)
}

/// Reads a scenario file, sets `overrides` (dotted keys, as the file spells
/// them: `user.accuracy`, `decoder`, ...) in its TOML, and validates the
/// result: command-line overrides are parsed and checked exactly as if the
/// file said them, so nothing derived from a value (the accuracy the device
/// assumes, say) can be left behind. Setting `user.accuracy` drops the
/// file's other ways of giving the decoder (`subject`, `goals`, `hit_rate`,
/// `false_alarms_per_min`).
pub fn load_scenario_with(
    path: impl AsRef<Path>,
    overrides: &[(&str, toml::Value)],
) -> Result<AnyScenario> {
    let path = path.as_ref();
    if overrides.is_empty() {
        return load_scenario(path);
    }
    parse_scenario_with(&read_scenario(path)?, path, overrides)
}

/// [`load_scenario_with`] for a scenario's text (`path` names it in
/// errors).
pub fn parse_scenario_with(
    text: &str,
    path: &Path,
    overrides: &[(&str, toml::Value)],
) -> Result<AnyScenario> {
    if overrides.is_empty() {
        return parse_scenario(text, path);
    }
    parse_scenario_table(&overridden(text, path, overrides)?, path)
}

/// A scenario's text as run: `text` with `overrides` set as
/// [`parse_scenario_with`] sets them (the text itself when there are none),
/// for recordings that say how they were made.
pub fn scenario_text_with(
    text: &str,
    path: &Path,
    overrides: &[(&str, toml::Value)],
) -> Result<String> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    toml::to_string(&overridden(text, path, overrides)?)
        .map_err(|e| SimError::Scenario(format!("{}: {e}", path.display())))
}

/// The TOML table of `text` with `overrides` set.
fn overridden(text: &str, path: &Path, overrides: &[(&str, toml::Value)]) -> Result<toml::Table> {
    let mut table: toml::Table = parse_toml(text, path)?;
    for (key, value) in overrides {
        if *key == "user.accuracy"
            && let Some(user) = table.get_mut("user").and_then(toml::Value::as_table_mut)
        {
            for other in ["subject", "goals", "hit_rate", "false_alarms_per_min"] {
                user.remove(other);
            }
        }
        set_key(&mut table, key, value.clone())
            .map_err(|e| SimError::Scenario(format!("{}: {key}: {e}", path.display())))?;
    }
    Ok(table)
}

/// Validates a scenario of either task given as a TOML table (a file's with
/// values set from the command line or a sweep). Errors name `path` and the
/// field, but no line: the table is not the file as written.
pub fn parse_scenario_table(table: &toml::Table, path: &Path) -> Result<AnyScenario> {
    if table.get("task").and_then(toml::Value::as_str) == Some("epuck") {
        Ok(AnyScenario::Epuck(Box::new(EpuckScenario::from_table(
            table, path,
        )?)))
    } else {
        Ok(AnyScenario::Grid(Box::new(GridScenario::from_table(
            table, path,
        )?)))
    }
}

/// Validates scenario text of either task; `path` names it in errors.
pub fn parse_scenario(text: &str, path: &Path) -> Result<AnyScenario> {
    if is_epuck(text, path)? {
        Ok(AnyScenario::Epuck(Box::new(EpuckScenario::parse(
            text, path,
        )?)))
    } else {
        Ok(AnyScenario::Grid(Box::new(GridScenario::parse(
            text, path,
        )?)))
    }
}

/// True if the scenario text says `task = "epuck"`; any other task is left
/// to the grid loader, which names the accepted values.
pub fn is_epuck(text: &str, path: &Path) -> Result<bool> {
    #[derive(Deserialize)]
    struct Task {
        task: Option<String>,
    }
    let task: Task = parse_toml(text, path)?;
    Ok(task.task.as_deref() == Some("epuck"))
}
