//! The parameters a sweep varies: one axis per `--param NAME=VALUES`, by a
//! task's short names or a dotted key of its scenario.

use errp_sim::{Names, Result, SimError, TaskKind};
use serde::{Deserialize, Serialize};
use toml::Value;

use super::values::parse_values;

/// One swept scenario parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    /// The name as given (`tau`), used for the CSV column.
    pub name: String,
    /// Where it goes in the scenario file (`control.tau`).
    pub key: String,
    /// Its values, in sweep order.
    pub values: Vec<Value>,
}

/// The sweepable parameters of `task`: (short name, dotted key). Any other
/// parameter is named by its dotted path.
pub fn sweepable(task: TaskKind) -> &'static [(&'static str, &'static str)] {
    task.info().sweepable
}

/// The dotted key of short name `name` for `task`.
pub(super) fn alias(task: TaskKind, name: &str) -> Option<&'static str> {
    sweepable(task)
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, k)| *k)
}

/// The short names accepted for `task`, for error messages and help.
pub fn aliases(task: TaskKind) -> String {
    let names: Vec<&str> = sweepable(task).iter().map(|(n, _)| *n).collect();
    names.join(", ")
}

/// Parses one `--param NAME=VALUES` for `task`. Errors name it as `names`
/// does.
pub fn parse_axis(task: TaskKind, text: &str, names: &Names) -> Result<Axis> {
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
