//! Scenario files of either task: reading, TOML parsing with errors that
//! name the file, dotted-key overrides, and dispatch on the `task` field.

use std::path::Path;

use serde::Deserialize;
use serde::de::DeserializeOwned;
use toml::{Table, Value};

use crate::epuck::scenario::EpuckScenario;
use crate::error::{Result, SimError};
use crate::grid::scenario::GridScenario;

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
    let mut table: toml::Table = parse_toml(&read_scenario(path)?, path)?;
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
    let text = toml::to_string(&table)
        .map_err(|e| SimError::Scenario(format!("{}: {e}", path.display())))?;
    parse_scenario(&text, path)
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

/// The text of the scenario file at `path`.
pub fn read_scenario(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| {
        SimError::Scenario(format!("{}: cannot read the scenario: {e}", path.display()))
    })
}

/// Scenario text parsed as TOML into `T`; errors name `path`.
pub fn parse_toml<T: DeserializeOwned>(text: &str, path: &Path) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        SimError::Scenario(format!("{}: {}", path.display(), e.to_string().trim_end()))
    })
}

/// Sets `key` (dotted) in `table` to `value`, creating tables on the way.
pub fn set_key(table: &mut Table, key: &str, value: Value) -> std::result::Result<(), String> {
    let mut parts = key.split('.').peekable();
    let mut t = table;
    while let Some(part) = parts.next() {
        if parts.peek().is_none() {
            t.insert(part.to_string(), value);
            return Ok(());
        }
        let entry = t
            .entry(part.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        t = entry
            .as_table_mut()
            .ok_or_else(|| format!("`{part}` in `{key}` is not a table in the scenario"))?;
    }
    Err(format!("`{key}` is empty"))
}

/// The error for a bad `field` of the scenario at `path`.
pub(crate) fn field_error(path: &Path, field: &str, value: String, expected: &str) -> SimError {
    SimError::Scenario(format!(
        "{}: field `{field}` = {value} is invalid: expected {expected}",
        path.display()
    ))
}

/// The scenario's `name`, or its file name without the extension.
pub(crate) fn scenario_name(name: Option<String>, path: &Path) -> String {
    name.unwrap_or_else(|| {
        path.file_stem()
            .map_or("scenario".into(), |s| s.to_string_lossy().into())
    })
}

/// A robot parameter error of the scenario at `path`, named as the file
/// spells it: `control.tau` for `tau` under `[control]`.
pub(crate) fn robot_error(path: &Path, table: &str, e: errp_robot::RobotError) -> SimError {
    match e {
        errp_robot::RobotError::InvalidParameter {
            name,
            value,
            expected,
        } => field_error(path, &format!("{table}.{name}"), value, &expected),
        other => SimError::Scenario(format!("{}: [{table}] {other}", path.display())),
    }
}
