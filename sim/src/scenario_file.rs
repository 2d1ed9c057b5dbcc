//! Reading scenario files: the text, TOML parsing with errors that name the
//! file and the field, and dotted-key overrides.

use std::path::Path;

use serde::de::DeserializeOwned;
use toml::{Table, Value};

use crate::error::{Result, SimError};

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
