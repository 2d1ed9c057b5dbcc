//! The subjects of Table 1 and their decoder accuracies.

use serde::Deserialize;

use crate::error::{BciError, Result};

const SUBJECTS_TOML: &str = include_str!("../../assets/subjects.toml");

/// Which goal set of the grid task an accuracy belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalSet {
    /// The five goals shared by all subjects (Fig. 4).
    Fixed,
    /// Goals the subjects chose themselves.
    Free,
}

/// One subject of Table 1.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Subject {
    /// `S1` .. `S4`.
    pub name: String,
    /// Mean accuracy with the fixed goals (%).
    pub fixed_goals_pct: f64,
    /// Mean accuracy with the free goals (%).
    pub free_goals_pct: f64,
}

impl Subject {
    /// The subject's mean accuracy (fraction) for a goal set.
    pub fn accuracy(&self, goals: GoalSet) -> f64 {
        match goals {
            GoalSet::Fixed => self.fixed_goals_pct / 100.0,
            GoalSet::Free => self.free_goals_pct / 100.0,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SubjectsFile {
    subject: Vec<Subject>,
}

/// All subjects of Table 1, from `assets/subjects.toml`.
pub fn subjects() -> Vec<Subject> {
    let file: SubjectsFile = toml::from_str(SUBJECTS_TOML).expect("assets/subjects.toml is valid");
    file.subject
}

/// The subject called `name` (case-insensitive).
pub fn subject(name: &str) -> Result<Subject> {
    let all = subjects();
    let known = all
        .iter()
        .map(|s| s.name.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    all.iter()
        .find(|s| s.name.eq_ignore_ascii_case(name))
        .cloned()
        .ok_or(BciError::UnknownSubject {
            name: name.to_string(),
            known,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table1_subjects_average_to_the_papers_means() {
        let s = subjects();
        assert_eq!(s.len(), 4);
        let mean = |g| s.iter().map(|x| x.accuracy(g)).sum::<f64>() / 4.0;
        // The per-subject means of Table 1 average to 75.37 % and 82.02 %; the
        // paper's mean column says 74.38 % and 77.67 % (it does not say how
        // that column was pooled). The asset keeps the per-subject values.
        assert!((mean(GoalSet::Fixed) - 0.7538).abs() < 0.01);
        assert!((mean(GoalSet::Free) - 0.8202).abs() < 0.01);
        assert_eq!(subject("s2").unwrap().accuracy(GoalSet::Fixed), 0.6949);
        let err = subject("S9").unwrap_err().to_string();
        assert!(err.contains("S1, S2, S3, S4"), "{err}");
    }
}
