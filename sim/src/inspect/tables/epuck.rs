//! The e-puck recording's tidy tables: runs, trajectory, detections, belief, ErrPs and events.

use crate::epuck::{EpuckEpisodeResult, PHASE_NAMES, STEP_NAMES};
use crate::inspect::Recording;
use crate::inspect::tables::{CsvTable, name_of, phase_secs};
use crate::record::data::Column;
use crate::record::schema::{ErrpsView, EventsView, FramesView, WindowsView};

pub(super) fn epuck_tables(
    rec: &Recording,
    results: &[EpuckEpisodeResult],
    names: &[String],
) -> Vec<CsvTable> {
    let frames = FramesView::or_empty(&rec.tables);
    let windows = WindowsView::or_empty(&rec.tables);
    vec![
        epuck_runs_table(rec, results, names),
        trajectory_table(&frames, &windows, names),
        detections_table(&windows, results),
        belief_table(&windows, names),
        errps_table(&ErrpsView::or_empty(&rec.tables)),
        events_table(&EventsView::or_empty(&rec.tables)),
    ]
}

/// A run index column, numbered from 1.
pub(super) fn run1(v: &[i64]) -> Column {
    Column::I64(v.iter().map(|r| r + 1).collect())
}

/// One row per run: the result recomputed, and the time in each phase.
pub(super) fn epuck_runs_table(
    rec: &Recording,
    results: &[EpuckEpisodeResult],
    names: &[String],
) -> CsvTable {
    let n = results.len();
    let phases = phase_secs(rec);
    CsvTable {
        name: "runs",
        columns: vec![
            ("run", Column::I64((1..=n as i64).collect())),
            (
                "goal",
                Column::Str(results.iter().map(|r| names[r.goal].clone()).collect()),
            ),
            (
                "converged_on",
                Column::Str(
                    results
                        .iter()
                        .map(|r| r.committed.map_or(String::new(), |c| names[c].clone()))
                        .collect(),
                ),
            ),
            (
                "reached",
                Column::Bool(results.iter().map(EpuckEpisodeResult::reached).collect()),
            ),
            (
                "time_s",
                Column::F64(results.iter().map(|r| r.time_secs).collect()),
            ),
            (
                "detected",
                Column::I64(results.iter().map(|r| r.detected_errors as i64).collect()),
            ),
            (
                "false",
                Column::I64(results.iter().map(|r| r.false_detections as i64).collect()),
            ),
            (
                "missed",
                Column::I64(results.iter().map(|r| r.missed_errors as i64).collect()),
            ),
            (
                "errps",
                Column::I64(results.iter().map(|r| r.errps as i64).collect()),
            ),
            (
                "acc_correct",
                Column::F64(results.iter().map(|r| r.online.correct).collect()),
            ),
            (
                "acc_error",
                Column::F64(results.iter().map(|r| r.online.error).collect()),
            ),
            (
                "hit_rate",
                Column::F64(results.iter().map(EpuckEpisodeResult::hit_rate).collect()),
            ),
            (
                "false_alarms_per_min",
                Column::F64(
                    results
                        .iter()
                        .map(EpuckEpisodeResult::false_alarms_per_min)
                        .collect(),
                ),
            ),
            (
                "path_m",
                Column::F64(results.iter().map(|r| r.path_m).collect()),
            ),
            (
                "turning_s",
                Column::F64(phases.iter().map(|p| p[0]).collect()),
            ),
            (
                "driving_s",
                Column::F64(phases.iter().map(|p| p[1]).collect()),
            ),
            (
                "stopped_s",
                Column::F64(phases.iter().map(|p| p[2]).collect()),
            ),
        ],
    }
}

/// One row per physics step, with p(error) and the evidence of the
/// latest window.
pub(super) fn trajectory_table(
    frames: &FramesView<'_>,
    windows: &WindowsView<'_>,
    names: &[String],
) -> CsvTable {
    // p(error) and the evidence of the latest window at each frame.
    let (w_run, w_t) = (windows.run, windows.t_s);
    let (w_p, w_ev) = (windows.p_error, windows.evidence);
    let (f_run, f_t) = (frames.run, frames.t_s);
    let mut p = Vec::with_capacity(f_t.len());
    let mut ev = Vec::with_capacity(f_t.len());
    let mut w = 0usize;
    let mut latest: Option<usize> = None;
    for (r, t) in f_run.iter().zip(f_t) {
        while w < w_t.len() && (w_run[w] < *r || (w_run[w] == *r && w_t[w] <= *t)) {
            latest = (w_run[w] == *r).then_some(w);
            w += 1;
        }
        if latest.is_some_and(|l| w_run[l] != *r) {
            latest = None;
        }
        p.push(latest.map_or(f64::NAN, |l| w_p[l]));
        ev.push(latest.map_or(f64::NAN, |l| w_ev[l]));
    }
    CsvTable {
        name: "trajectory",
        columns: vec![
            ("run", run1(f_run)),
            ("t_s", Column::F64(f_t.to_vec())),
            ("x_cm", Column::F64(frames.x_cm.to_vec())),
            ("y_cm", Column::F64(frames.y_cm.to_vec())),
            ("heading_deg", Column::F64(frames.heading_deg.to_vec())),
            ("tracked_x_cm", Column::F64(frames.tracked_x_cm.to_vec())),
            ("tracked_y_cm", Column::F64(frames.tracked_y_cm.to_vec())),
            (
                "phase",
                Column::Str(
                    frames
                        .phase
                        .iter()
                        .map(|&k| {
                            PHASE_NAMES
                                .get(k as usize)
                                .map_or(String::new(), |s| s.to_string())
                        })
                        .collect(),
                ),
            ),
            (
                "current_goal",
                Column::Str(frames.target.iter().map(|&k| name_of(names, k)).collect()),
            ),
            ("p_error", Column::F64(p)),
            ("evidence", Column::F64(ev)),
        ],
    }
}

/// One row per detection, where the robot was and the controller's step.
pub(super) fn detections_table(
    windows: &WindowsView<'_>,
    results: &[EpuckEpisodeResult],
) -> CsvTable {
    let w = windows;
    // Detections, with where the robot was and the controller's step.
    let (mut run, mut t_s, mut x_cm, mut y_cm) = (vec![], vec![], vec![], vec![]);
    let (mut p_error, mut evidence, mut step) = (vec![], vec![], vec![]);
    let mut per_run = vec![0usize; results.len()];
    for i in 0..w.rows {
        if !w.detected[i] {
            continue;
        }
        let r = w.run[i];
        let Some(result) = usize::try_from(r).ok().and_then(|k| results.get(k)) else {
            continue;
        };
        let j = per_run[r as usize];
        per_run[r as usize] += 1;
        let xy = result.detections.get(j).copied().unwrap_or([f64::NAN; 2]);
        run.push(r + 1);
        t_s.push(w.t_s[i]);
        x_cm.push(100.0 * xy[0]);
        y_cm.push(100.0 * xy[1]);
        p_error.push(w.p_error[i]);
        evidence.push(w.evidence[i]);
        step.push(
            STEP_NAMES
                .get(w.step[i] as usize)
                .map_or(String::new(), |s| s.to_string()),
        );
    }
    CsvTable {
        name: "detections",
        columns: vec![
            ("run", Column::I64(run)),
            ("t_s", Column::F64(t_s)),
            ("x_cm", Column::F64(x_cm)),
            ("y_cm", Column::F64(y_cm)),
            ("p_error", Column::F64(p_error)),
            ("evidence", Column::F64(evidence)),
            ("step", Column::Str(step)),
        ],
    }
}

/// The belief per goal after each window, long.
pub(super) fn belief_table(windows: &WindowsView<'_>, names: &[String]) -> CsvTable {
    let (belief, width) = windows.belief;
    let rows = windows.rows * width;
    let mut run = Vec::with_capacity(rows);
    let mut t_s = Vec::with_capacity(rows);
    let mut goal = Vec::with_capacity(rows);
    let mut p = Vec::with_capacity(rows);
    for i in 0..windows.rows {
        for g in 0..width {
            run.push(windows.run[i] + 1);
            t_s.push(windows.t_s[i]);
            goal.push(name_of(names, g as i64));
            p.push(belief[i * width + g]);
        }
    }
    CsvTable {
        name: "belief",
        columns: vec![
            ("run", Column::I64(run)),
            ("t_s", Column::F64(t_s)),
            ("goal", Column::Str(goal)),
            ("p", Column::F64(p)),
        ],
    }
}

/// One row per ErrP of the user.
pub(super) fn errps_table(errps: &ErrpsView<'_>) -> CsvTable {
    CsvTable {
        name: "errps",
        columns: vec![
            ("run", run1(errps.run)),
            ("t_s", Column::F64(errps.t_s.to_vec())),
            ("onset_s", Column::F64(errps.onset_s.to_vec())),
            (
                "judged_phase",
                Column::Str(
                    errps
                        .phase
                        .iter()
                        .map(|&k| {
                            PHASE_NAMES
                                .get(k as usize)
                                .map_or(String::new(), |s| s.to_string())
                        })
                        .collect(),
                ),
            ),
        ],
    }
}

/// The event log.
pub(super) fn events_table(events: &EventsView<'_>) -> CsvTable {
    CsvTable {
        name: "events",
        columns: vec![
            ("run", run1(events.run)),
            ("t_s", Column::F64(events.t_s.to_vec())),
            (
                "level",
                Column::Str(
                    events
                        .warn
                        .iter()
                        .map(|&w| if w { "WARN" } else { "INFO" }.to_string())
                        .collect(),
                ),
            ),
            ("text", Column::Str(events.text.to_vec())),
        ],
    }
}
