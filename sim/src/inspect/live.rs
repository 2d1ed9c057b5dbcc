//! A live session's recording (`errp stream --save`) read back: each run's
//! decisions as received ([`LiveDecisionLog`]), and the runs replayed offline
//! with the decisions they applied ([`Recording::replay_live`]).

use std::collections::BTreeMap;

use crate::epuck::EpuckRunRow;
use crate::error::SimError;
use crate::grid::GridEpisodeRow;
use crate::inspect::rows::{check_run_order, index, run_rows};
use crate::inspect::{Recording, Runs, Table};
use crate::live::{Fate, LiveRunStats, LoggedDecision, Received};
use crate::pace::Speed;
use crate::record::schema::{ActionsView, LiveDecisions, LiveDecisionsView, WindowsView};
use crate::task_kind::TaskKind;

/// The decisions of a live session, per run.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveDecisionLog {
    /// Simulated seconds per second of the link's clock.
    pub speed: Speed,
    /// The decoder's stream, as found (`name=...`).
    pub decoder: String,
    /// Each run's decisions (arrivals on the run's clock over `speed`:
    /// origin 0) and what was missed.
    pub runs: Vec<LiveRunStats>,
    /// Each run's p(error)s as applied, per action (grid: none or one) or
    /// per device window (e-puck), in order of arrival.
    pub applied: Vec<Vec<Vec<f64>>>,
}

/// The session in `tables` of `runs` runs of `task`, live at `speed` from
/// `decoder` (the grid's decisions apply to actions, the e-puck's to
/// windows).
pub(super) fn decision_log(
    tables: &BTreeMap<String, Table>,
    runs: usize,
    (speed, decoder): (Speed, &str),
    task: TaskKind,
) -> Result<LiveDecisionLog, String> {
    let d = LiveDecisionsView::of_or_empty(tables)?;
    check_run_order(LiveDecisions::ENTITY, d.run)?;
    // What each run's decisions apply to: its actions or its windows.
    let (slots_run, slot_name) = match task {
        TaskKind::Grid => (ActionsView::of_or_empty(tables)?.run, "action"),
        TaskKind::Epuck => (WindowsView::of(tables)?.run, "window"),
    };
    let mut session = LiveDecisionLog {
        speed,
        decoder: decoder.to_string(),
        runs: Vec::with_capacity(runs),
        applied: Vec::with_capacity(runs),
    };
    for k in 0..runs {
        let slots = run_rows(slots_run, k).len();
        let mut applied = vec![Vec::new(); slots];
        let mut stats = LiveRunStats::default();
        for i in run_rows(d.run, k) {
            let fate = match (d.fate[i].as_str(), d.applied_to[i]) {
                ("applied", a) => Fate::Applied(index(a, slots, slot_name)?),
                ("late", -1) => Fate::Late,
                ("stray", -1) => Fate::Stray,
                (f, a) => {
                    return Err(format!(
                        "its table {} has a decision `{f}` applied to {a} (expected applied \
                         to an {slot_name} from 0, or late or stray with -1)",
                        LiveDecisions::ENTITY
                    ));
                }
            };
            let p = d.p_error[i];
            if let Fate::Applied(a) = fate {
                if !(0.0..=1.0).contains(&p) {
                    return Err(format!(
                        "its table {} applies p(error) = {p}, not a probability",
                        LiveDecisions::ENTITY
                    ));
                }
                applied[a].push(p);
            }
            stats.decisions.push(LoggedDecision {
                received: Received {
                    id: d.id[i],
                    p_error: p,
                    arrived: speed.to_link(d.t_s[i]),
                },
                latency_secs: d.latency_s[i],
                fate,
            });
        }
        if task == TaskKind::Grid && applied.iter().any(|a| a.len() > 1) {
            return Err(format!(
                "its table {} applies two decisions to one action",
                LiveDecisions::ENTITY
            ));
        }
        stats.missed = applied.iter().filter(|a| a.is_empty()).count();
        session.runs.push(stats);
        session.applied.push(applied);
    }
    if d.run.last().is_some_and(|&r| r >= runs as i64) {
        return Err(format!(
            "its table {} has decisions of a run it does not hold",
            LiveDecisions::ENTITY
        ));
    }
    Ok(session)
}

/// A live session's runs replayed offline: each run's row of the task's
/// table, as recorded and as replayed.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveReplay {
    /// The rows recomputed from the recording.
    pub recorded: Vec<String>,
    /// The rows of the runs run again with the decisions applied.
    pub replayed: Vec<String>,
}

impl LiveReplay {
    /// The rows of `recorded` and `replayed` results, each run `k` as
    /// `row(k, result)` prints it.
    fn of<T>(recorded: &[T], replayed: &[T], row: impl Fn(usize, &T) -> String) -> Self {
        let rows = |results: &[T]| results.iter().enumerate().map(|(k, r)| row(k, r)).collect();
        Self {
            recorded: rows(recorded),
            replayed: rows(replayed),
        }
    }

    /// The first run (from 0) whose rows differ, if any.
    pub fn first_difference(&self) -> Option<usize> {
        (0..self.recorded.len().max(self.replayed.len()))
            .find(|&k| self.recorded.get(k) != self.replayed.get(k))
    }
}

impl Recording {
    /// Runs a live session's runs again, offline, each decided by the
    /// decisions the session applied (the e-puck's decoder prepared again
    /// from the scenario: its detection spans and EEG model), and returns
    /// both tables' rows. Not a live recording: an error saying so.
    pub fn replay_live(&self) -> Result<LiveReplay, SimError> {
        let Some(live) = &self.live else {
            return Err(SimError::Scenario(format!(
                "{}: not a live session's recording (errp stream --save), so it holds no \
                 decisions of a decoder outside to replay; `errp inspect` shows how to run it \
                 again",
                self.path.display()
            )));
        };
        match &self.runs {
            Runs::Grid { scenario, results } => {
                let decisions: Vec<Vec<Option<f64>>> = live
                    .applied
                    .iter()
                    .map(|run| run.iter().map(|a| a.first().copied()).collect())
                    .collect();
                let replayed = crate::live::grid::replay_grid(scenario, &decisions)?;
                let row = |k, r: &_| GridEpisodeRow(k, r).to_string();
                Ok(LiveReplay::of(results, &replayed, row))
            }
            Runs::Epuck { scenario, results } => {
                let decoder = crate::live::epuck::prepare_live_epuck(scenario, &())?;
                let replayed = crate::live::epuck::replay_epuck(scenario, &decoder, &live.applied)?;
                let layout = &scenario.layout;
                let row = |index, result: &_| {
                    EpuckRunRow {
                        index,
                        result,
                        layout,
                    }
                    .to_string()
                };
                Ok(LiveReplay::of(results, &replayed, row))
            }
        }
    }
}
