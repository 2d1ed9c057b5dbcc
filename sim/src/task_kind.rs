//! Which task a scenario, a sweep, a recording or a live session is of: the
//! one type every front end parses the word into and prints it from.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// The task: the discrete 5x5 grid (sec. 3-4) or the continuous e-puck
/// (sec. 5). Spelled `grid` and `epuck` in scenario files (`task = ...`),
/// `--task`, `sweep.json`, a recording's provenance, the stream's
/// description and Python.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TaskKind {
    /// The discrete 5x5 grid task.
    Grid,
    /// The continuous e-puck task.
    Epuck,
}

impl TaskKind {
    /// Both tasks, in the order they are listed.
    pub const ALL: [TaskKind; 2] = [TaskKind::Grid, TaskKind::Epuck];

    /// The accepted spellings, as an error lists them.
    pub const EXPECTED: &'static str = "\"grid\" or \"epuck\"";

    /// As files, flags and Python spell it: `grid` or `epuck`.
    pub const fn as_str(self) -> &'static str {
        match self {
            TaskKind::Grid => "grid",
            TaskKind::Epuck => "epuck",
        }
    }

    /// In prose: `grid` or `e-puck`.
    pub const fn label(self) -> &'static str {
        match self {
            TaskKind::Grid => "grid",
            TaskKind::Epuck => "e-puck",
        }
    }

    /// The built-in scenario's path in the repository: what a front end
    /// runs when it is given the task but no scenario file.
    pub const fn built_in_path(self) -> &'static str {
        match self {
            TaskKind::Grid => "scenarios/grid_fixed_goals.toml",
            TaskKind::Epuck => "scenarios/mexico_to_pisa.toml",
        }
    }

    /// The task a scenario's `task` field selects: the e-puck for exactly
    /// `"epuck"`; anything else goes to the grid's loader, which names a
    /// value it does not accept.
    pub fn of_field(task: Option<&str>) -> TaskKind {
        if task == Some(TaskKind::Epuck.as_str()) {
            TaskKind::Epuck
        } else {
            TaskKind::Grid
        }
    }

    /// The task of a scenario read as a TOML table ([`TaskKind::of_field`]
    /// of its `task`).
    pub fn of_table(table: &toml::Table) -> TaskKind {
        Self::of_field(table.get("task").and_then(toml::Value::as_str))
    }
}

impl fmt::Display for TaskKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A word that names no task.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownTask(pub String);

impl fmt::Display for UnknownTask {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}: expected {}", self.0, TaskKind::EXPECTED)
    }
}

impl std::error::Error for UnknownTask {}

impl FromStr for TaskKind {
    type Err = UnknownTask;

    /// `grid` or `epuck`, exactly (no other case, no spaces).
    fn from_str(s: &str) -> Result<Self, UnknownTask> {
        TaskKind::ALL
            .into_iter()
            .find(|k| k.as_str() == s)
            .ok_or_else(|| UnknownTask(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_task_reads_back_as_it_prints_and_nothing_else_reads() {
        for k in TaskKind::ALL {
            assert_eq!(k.as_str().parse::<TaskKind>(), Ok(k));
            assert_eq!(k.to_string(), k.as_str());
            let json = serde_json::to_string(&k).unwrap();
            assert_eq!(json, format!("{:?}", k.as_str()));
            assert_eq!(serde_json::from_str::<TaskKind>(&json).unwrap(), k);
        }
        for bad in ["Grid", "e-puck", " epuck", ""] {
            let e = bad.parse::<TaskKind>().unwrap_err();
            assert_eq!(
                e.to_string(),
                format!("{bad:?}: expected \"grid\" or \"epuck\"")
            );
        }
    }

    #[test]
    fn only_an_exact_epuck_field_selects_the_epuck() {
        assert_eq!(TaskKind::of_field(Some("epuck")), TaskKind::Epuck);
        for other in [Some("grid"), Some("Epuck"), Some("maze"), None] {
            assert_eq!(TaskKind::of_field(other), TaskKind::Grid);
        }
    }
}
