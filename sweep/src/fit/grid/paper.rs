//! Table 1's rows, as the grid fit compares its simulated subjects with them.

use errp_bci::{GoalSet, subjects};
use errp_sim::PAPER;
use serde::Serialize;

/// One subject on one goal set, as the paper reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaperRow {
    /// S1..S4.
    pub subject: String,
    /// Mean online accuracy (fraction): what the decoder is calibrated to.
    pub accuracy: f64,
    /// Mean actions over the five runs.
    pub actions_mean: f64,
    /// Their sd.
    pub actions_sd: f64,
}

/// The paper's rows of a goal set, in subject order.
pub fn paper_rows(goals: GoalSet) -> Vec<PaperRow> {
    subjects()
        .iter()
        .map(|s| {
            let (_, _, v) = PAPER
                .iter()
                .find(|(n, g, _)| *n == s.name && *g == goals)
                .expect("Table 1 has every subject and goal set");
            PaperRow {
                subject: s.name.clone(),
                accuracy: s.accuracy(goals),
                actions_mean: v[0],
                actions_sd: v[1],
            }
        })
        .collect()
}
