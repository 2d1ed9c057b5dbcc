//! The grid task as a [`Task`]: what a sweep runs at one level.

use std::sync::Arc;

use errp_bci::GoalSet;
use errp_robot::{Cell, Grid, GridControlParams, QTable};

use crate::calibration::TargetingCache;
use crate::error::Result;
use crate::grid::decoder::AssessmentDecoder;
use crate::grid::episode::run_grid_episode;
use crate::grid::p_error::PErrorChoice;
use crate::grid::plant::GridEpisodeResult;
use crate::grid::run::{GridShared, prepare_grid_decoder};
use crate::grid::scenario::{DecoderChoice, EegMode, GridAccuracy, GridScenario};
use crate::key::StableKey;
use crate::task_kind::TaskKind;

/// About the memory of one epoch in a bank: 312 features and the FCz
/// trace, as f64.
const BANK_EPOCH_BYTES: usize = 5_000;
use crate::paper::PAPER;
use crate::task::{
    ColumnKind, DecoderInfo, EpisodeColumn, EpisodeRow, FieldError, FigureText, PaperPoint, Task,
    TaskInfo, format_number, overall,
};

/// One grid episode as the task's row of `episodes.csv`: its
/// [`TaskInfo::columns`], success and online accuracy.
pub fn grid_row(r: &GridEpisodeResult) -> EpisodeRow {
    let cell = |c: Option<Cell>| match c {
        Some(c) => [c.x.to_string(), c.y.to_string()],
        None => [String::new(), String::new()],
    };
    let (detected, hits_correct, _) = overall(&r.online);
    let mut fields = Vec::with_capacity(GridTask::INFO.columns.len());
    fields.extend(cell(Some(r.start)));
    fields.extend(cell(Some(r.goal)));
    fields.extend(cell(r.committed));
    fields.extend([
        r.actions.to_string(),
        format_number(r.net_secs),
        format_number(r.total_secs),
        r.online.n_error.to_string(),
        detected.to_string(),
        (r.online.n_correct - hits_correct).to_string(),
        (r.online.n_error - detected).to_string(),
    ]);
    EpisodeRow {
        success: r.reached(),
        fields,
        online: r.online,
    }
}

/// The discrete 5x5 grid (sec. 4): the cost is actions to convergence.
#[derive(Debug, Clone, Copy)]
pub struct GridTask;

/// A grid level: its scenario, decoder and Q-table.
#[derive(Debug)]
pub struct GridRunner {
    scenario: GridScenario,
    decoder: Arc<AssessmentDecoder>,
    table: QTable,
}

impl Task for GridTask {
    const INFO: TaskInfo = TaskInfo {
        kind: TaskKind::Grid,
        columns: &[
            EpisodeColumn::new("start_x", ColumnKind::Cell),
            EpisodeColumn::new("start_y", ColumnKind::Cell),
            EpisodeColumn::new("goal_x", ColumnKind::Cell),
            EpisodeColumn::new("goal_y", ColumnKind::Cell),
            EpisodeColumn::new("committed_x", ColumnKind::OptCell),
            EpisodeColumn::new("committed_y", ColumnKind::OptCell),
            EpisodeColumn::new("actions", ColumnKind::Count),
            EpisodeColumn::new("net_secs", ColumnKind::NonNegative),
            EpisodeColumn::new("total_secs", ColumnKind::NonNegative),
            EpisodeColumn::new("errors", ColumnKind::Count),
            EpisodeColumn::new("detected", ColumnKind::Count),
            EpisodeColumn::new("false_alarms", ColumnKind::Count),
            EpisodeColumn::new("missed", ColumnKind::Count),
        ],
        cost_column: "actions",
        cost_label: "actions",
        committed_column: "committed_x",
        detector_columns: None,
        rows_per_sync: 256,
        sweepable: &[
            ("tau", "control.tau"),
            ("epsilon", "control.epsilon"),
            ("p_c", "control.p_c"),
            ("discount", "control.discount"),
            ("goal_reward", "control.goal_reward"),
            ("wrong_goal_reward", "control.wrong_goal_reward"),
            ("strategy", "control.strategy"),
            ("interval_min_secs", "timing.interval_min_secs"),
            ("interval_max_secs", "timing.interval_max_secs"),
            ("epoch_secs", "timing.epoch_secs"),
            ("max_actions", "timing.max_actions"),
            ("decoder", "decoder"),
            ("p_error", "p_error"),
            ("eeg", "eeg"),
            ("bank_per_class", "bank_per_class"),
        ],
    };
    type Scenario = GridScenario;
    type Shared = GridShared;
    type Decoder = AssessmentDecoder;
    type Runner = GridRunner;

    fn decoder_key(s: &GridScenario) -> String {
        let p_error = match s.p_error {
            PErrorChoice::Sigmoid => "sigmoid",
            PErrorChoice::Platt => "platt",
        };
        let key = StableKey::new("grid-decoder", 1);
        let key = match &s.accuracy {
            GridAccuracy::Requested(a) => key.float("accuracy", a.get()),
            GridAccuracy::OwnEeg(r) => key
                .text("recording", &r.file.display().to_string())
                .text("calibration", &format!("{:?}", r.part))
                .text("error", &r.names.error)
                .text("correct", &r.names.correct)
                .value("draw", &r.draw),
        };
        key.int("seed", s.seed)
            .text("decoder", s.decoder.key())
            .text("p_error", p_error)
            .text("eeg", s.eeg.key())
            .int("bank_per_class", s.bank_per_class as u64)
            .float("interval_min_secs", s.params.interval_min_secs)
            .float("interval_max_secs", s.params.interval_max_secs)
            .realism(&s.realism)
            .finish()
    }

    fn shared(scenarios: &[&GridScenario]) -> Result<GridShared> {
        GridShared::build(scenarios.iter().copied())
    }

    fn prepare(
        s: &GridScenario,
        shared: &GridShared,
        cache: &dyn TargetingCache,
    ) -> Result<(AssessmentDecoder, DecoderInfo)> {
        let prepared = prepare_grid_decoder(s, shared, cache, |_| {})?;
        let info = prepared.info(s);
        Ok((prepared.decoder, info))
    }

    fn runner(s: &GridScenario, decoder: Arc<AssessmentDecoder>) -> Result<GridRunner> {
        Ok(GridRunner {
            scenario: s.clone(),
            decoder,
            table: QTable::compute(Grid::paper(), &s.params.control.part(GridControlParams::q))?,
        })
    }

    fn run_episode(runner: &GridRunner, k: usize, seed: u64) -> Result<EpisodeRow> {
        let s = &runner.scenario;
        let (start, goal) = s.episodes[k % s.episodes.len()];
        let r = run_grid_episode(
            start,
            goal,
            &runner.table,
            &s.params,
            &runner.decoder,
            seed,
            false,
        )?;
        Ok(grid_row(&r))
    }

    /// The start and goal are the scenario's pair `k`; success is a
    /// commitment to the goal; the detections and misses add up to the
    /// errors.
    fn check_fields(
        s: &GridScenario,
        k: usize,
        success: bool,
        f: &[&str],
    ) -> std::result::Result<(), FieldError> {
        let (start, goal) = s.episodes[k % s.episodes.len()];
        let want = [start.x, start.y, goal.x, goal.y].map(|v| v.to_string());
        for (i, w) in want.iter().enumerate() {
            if f[i] != w {
                return Err(FieldError {
                    column: Self::INFO.columns[i].name,
                    expected: format!("{w}: episode {k} runs from cell {} to {}", start, goal),
                });
            }
        }
        let committed = (f[4], f[5]);
        if committed.0.is_empty() != committed.1.is_empty() {
            return Err(FieldError {
                column: "committed_y",
                expected: "empty exactly when committed_x is".into(),
            });
        }
        if success != (committed == (f[2], f[3])) {
            return Err(FieldError {
                column: "committed_x",
                expected: format!("the goal ({}, {}) exactly when success is 1", f[2], f[3]),
            });
        }
        let count = |i: usize| f[i].parse::<u64>().unwrap_or(0);
        if count(10) + count(12) != count(9) {
            return Err(FieldError {
                column: "missed",
                expected: format!("errors - detected = {}", count(9).saturating_sub(count(10))),
            });
        }
        Ok(())
    }

    /// An EEG decoder reading a bank holds `bank_per_class` epochs of each
    /// class (features and the FCz trace, about 5 KB each).
    fn decoder_bytes(s: &GridScenario) -> usize {
        match (s.decoder, s.eeg) {
            (DecoderChoice::Eeg, EegMode::Bank) => 2 * s.bank_per_class * BANK_EPOCH_BYTES,
            _ => 0,
        }
    }

    fn figure(s: &GridScenario) -> FigureText {
        FigureText {
            task: "Grid task".into(),
            decoder: match s.decoder {
                DecoderChoice::Oracle => "oracle decoder".into(),
                DecoderChoice::Eeg => format!("eeg decoder ({})", s.eeg.key().replace('_', " ")),
            },
            cost_label: "actions to convergence (successful episodes)".into(),
            paper: PAPER
                .iter()
                .map(|(name, set, row)| PaperPoint {
                    label: format!(
                        "{name} {}",
                        if *set == GoalSet::Fixed {
                            "fixed"
                        } else {
                            "free"
                        }
                    ),
                    accuracy: row[6] / 100.0,
                    value: row[0],
                    sd: Some(row[1]),
                })
                .collect(),
            paper_label: "paper, Table 1 (S1-S4, fixed and free goals)".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibration::NoCache;

    #[test]
    fn an_episode_row_fills_the_task_columns() {
        let text = include_str!("../../../scenarios/grid_fixed_goals.toml")
            .replace("decoder = \"eeg\"", "decoder = \"oracle\"");
        let scenario = GridScenario::parse(&text, "grid_fixed_goals.toml".as_ref()).unwrap();
        assert_eq!(scenario.decoder, DecoderChoice::Oracle);
        let shared = GridTask::shared(&[&scenario]).unwrap();
        let (decoder, info) = GridTask::prepare(&scenario, &shared, &NoCache).unwrap();
        assert_eq!(info.kind, "oracle");
        let runner = GridTask::runner(&scenario, Arc::new(decoder)).unwrap();
        let row = GridTask::run_episode(&runner, 0, 7).unwrap();
        assert_eq!(row.fields.len(), GridTask::INFO.columns.len());
        let (start, goal) = scenario.episodes[0];
        assert_eq!(
            row.fields[..4],
            [start.x, start.y, goal.x, goal.y].map(|v| v.to_string())
        );
        // The oracle at the scenario's accuracy still decides every action.
        assert!(row.online.n_error + row.online.n_correct > 0);
        let cost = GridTask::INFO
            .columns
            .iter()
            .position(|c| c.name == GridTask::INFO.cost_column)
            .unwrap();
        assert!(row.fields[cost].parse::<usize>().unwrap() > 0);
    }
}
