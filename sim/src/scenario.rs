//! A scenario of either task: loading a file, with command-line overrides
//! set as its own keys, and dispatch on its `task` field.

use std::path::Path;

use serde::Deserialize;

use crate::epuck::EpuckTask;
use crate::epuck::scenario::EpuckScenario;
use crate::error::Result;
use crate::grid::GridTask;
use crate::grid::scenario::GridScenario;
use crate::scenario_file::{key_parts, parse_toml};
use crate::task::{Task, TaskInfo};
use crate::task_kind::TaskKind;

impl TaskKind {
    /// The task's columns, labels and sweepable parameters.
    pub fn info(self) -> &'static TaskInfo {
        match self {
            TaskKind::Grid => &GridTask::INFO,
            TaskKind::Epuck => &EpuckTask::INFO,
        }
    }
}

/// A scenario of either task, as `errp run` takes it.
#[derive(Debug, Clone)]
pub enum AnyScenario {
    /// The discrete 5x5 grid task (sec. 4).
    Grid(Box<GridScenario>),
    /// The continuous e-puck task (sec. 5).
    Epuck(Box<EpuckScenario>),
}

impl AnyScenario {
    /// Its task.
    pub fn kind(&self) -> TaskKind {
        match self {
            AnyScenario::Grid(_) => TaskKind::Grid,
            AnyScenario::Epuck(_) => TaskKind::Epuck,
        }
    }

    /// The scenario, if it is an `S` (a task's
    /// [`Task::Scenario`](crate::task::Task::Scenario)).
    pub fn get<S: 'static>(&self) -> Option<&S> {
        let any: &dyn std::any::Any = match self {
            AnyScenario::Grid(s) => &**s,
            AnyScenario::Epuck(s) => &**s,
        };
        any.downcast_ref()
    }

    /// The grid scenario, if it is one.
    pub fn into_grid(self) -> Option<GridScenario> {
        match self {
            AnyScenario::Grid(s) => Some(*s),
            AnyScenario::Epuck(_) => None,
        }
    }

    /// The e-puck scenario, if it is one.
    pub fn into_epuck(self) -> Option<EpuckScenario> {
        match self {
            AnyScenario::Epuck(s) => Some(*s),
            AnyScenario::Grid(_) => None,
        }
    }

    /// The scenario's simulated user (its `[realism]` table; the ideal
    /// user if it has none).
    pub fn realism(&self) -> &errp_bci::Realism {
        match self {
            AnyScenario::Grid(s) => &s.realism,
            AnyScenario::Epuck(s) => &s.realism,
        }
    }
}

/// Sets `overrides` in a scenario's TOML `text`, in order, and returns the
/// text with its comments and layout kept: the one place where a value from
/// outside the file (`errp run`'s flags, the Python package's keywords, a
/// sweep's level) enters a scenario, before anything is derived from it.
/// Two keys take with them what they replace: `user.accuracy` drops the
/// file's other ways of giving the decoder (`[user]` `subject`, `goals`,
/// `hit_rate`, `false_alarms_per_min`), and `seed` drops `[user] seed`, so
/// that a new seed is a new simulated user with new runs and new free
/// goals. The error names the key.
pub fn apply_overrides(
    text: &str,
    overrides: &[(&str, toml::Value)],
) -> std::result::Result<String, String> {
    let mut doc: toml_edit::DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| format!("not valid TOML: {}", e.message()))?;
    for (key, value) in overrides {
        let replaced: &[&str] = match *key {
            "user.accuracy" => &["subject", "goals", "hit_rate", "false_alarms_per_min"],
            "seed" => &["seed"],
            _ => &[],
        };
        if let Some(user) = doc.get_mut("user").and_then(|u| u.as_table_like_mut()) {
            for other in replaced {
                user.remove(other);
            }
        }
        set_edit_key(&mut doc, key, value).map_err(|e| format!("{key}: {e}"))?;
    }
    Ok(doc.to_string())
}

/// Sets dotted `key` ([`crate::key_parts`]) to `value` in `doc`, creating
/// the tables on the way.
fn set_edit_key(
    doc: &mut toml_edit::DocumentMut,
    key: &str,
    value: &toml::Value,
) -> std::result::Result<(), String> {
    let (tables, last) = key_parts(key)?;
    let item: toml_edit::Value = value
        .to_string()
        .parse()
        .map_err(|_| format!("{value} cannot be written in a scenario"))?;
    let mut t: &mut dyn toml_edit::TableLike = doc.as_table_mut();
    for part in tables {
        let entry = t
            .entry(part)
            .or_insert(toml_edit::Item::Table(toml_edit::Table::new()));
        t = entry
            .as_table_like_mut()
            .ok_or_else(|| format!("`{part}` in `{key}` is not a table in the scenario"))?;
    }
    t.insert(last, toml_edit::Item::Value(item));
    Ok(())
}

/// Validates a scenario of either task given as a TOML table (a file's with
/// values set from the command line or a sweep). Errors name `path` and the
/// field, but no line: the table is not the file as written.
pub fn parse_scenario_table(table: &toml::Table, path: &Path) -> Result<AnyScenario> {
    Ok(match TaskKind::of_table(table) {
        TaskKind::Epuck => AnyScenario::Epuck(Box::new(EpuckScenario::from_table(table, path)?)),
        TaskKind::Grid => AnyScenario::Grid(Box::new(GridScenario::from_table(table, path)?)),
    })
}

/// Validates scenario text of either task; `path` names it in errors.
pub fn parse_scenario(text: &str, path: &Path) -> Result<AnyScenario> {
    Ok(match scenario_kind(text, path)? {
        TaskKind::Epuck => AnyScenario::Epuck(Box::new(EpuckScenario::parse(text, path)?)),
        TaskKind::Grid => AnyScenario::Grid(Box::new(GridScenario::parse(text, path)?)),
    })
}

/// The task scenario text selects ([`TaskKind::of_field`]): the e-puck
/// for `task = "epuck"`; any other task is left to the grid loader, which
/// names the accepted values.
pub fn scenario_kind(text: &str, path: &Path) -> Result<TaskKind> {
    #[derive(Deserialize)]
    struct Task {
        task: Option<String>,
    }
    let task: Task = parse_toml(text, path)?;
    Ok(TaskKind::of_field(task.task.as_deref()))
}
