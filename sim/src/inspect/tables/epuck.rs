//! The e-puck recording's tidy tables: runs, trajectory, detections, belief, ErrPs and events.

#[allow(clippy::wildcard_imports, unused_imports)]
use super::*;

pub(super) fn epuck_tables(
    rec: &Recording,
    results: &[EpuckEpisodeResult],
    names: &[String],
) -> Vec<CsvTable> {
    let empty = Table::default();
    let frames = get(rec, paths::FRAMES).unwrap_or(&empty);
    let windows = get(rec, paths::WINDOWS).unwrap_or(&empty);
    vec![
        epuck_runs_table(rec, results, names),
        trajectory_table(frames, windows, names),
        detections_table(windows, results),
        belief_table(windows, names),
        errps_table(get(rec, paths::ERRPS).unwrap_or(&empty)),
        events_table(get(rec, paths::EVENTS).unwrap_or(&empty)),
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
pub(super) fn trajectory_table(frames: &Table, windows: &Table, names: &[String]) -> CsvTable {
    // p(error) and the evidence of the latest window at each frame.
    let (w_run, w_t) = (i64s(windows, "run"), f64s(windows, "t_s"));
    let (w_p, w_ev) = (f64s(windows, "p_error"), f64s(windows, "evidence"));
    let (f_run, f_t) = (i64s(frames, "run"), f64s(frames, "t_s"));
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
            ("x_cm", Column::F64(f64s(frames, "x_cm").to_vec())),
            ("y_cm", Column::F64(f64s(frames, "y_cm").to_vec())),
            (
                "heading_deg",
                Column::F64(f64s(frames, "heading_deg").to_vec()),
            ),
            (
                "tracked_x_cm",
                Column::F64(f64s(frames, "tracked_x_cm").to_vec()),
            ),
            (
                "tracked_y_cm",
                Column::F64(f64s(frames, "tracked_y_cm").to_vec()),
            ),
            (
                "phase",
                Column::Str(
                    i64s(frames, "phase")
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
                Column::Str(
                    i64s(frames, "target")
                        .iter()
                        .map(|&k| name_of(names, k))
                        .collect(),
                ),
            ),
            ("p_error", Column::F64(p)),
            ("evidence", Column::F64(ev)),
        ],
    }
}

/// One row per detection, where the robot was and the controller's step.
pub(super) fn detections_table(windows: &Table, results: &[EpuckEpisodeResult]) -> CsvTable {
    let (w_run, w_t) = (i64s(windows, "run"), f64s(windows, "t_s"));
    let (w_p, w_ev) = (f64s(windows, "p_error"), f64s(windows, "evidence"));
    // Detections, with where the robot was and whether an ErrP explains it.
    let mut d = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    let detected = bools(windows, "detected");
    let steps = i64s(windows, "step");
    let mut per_run = vec![0usize; results.len()];
    for i in 0..w_t.len() {
        if !detected.get(i).copied().unwrap_or(false) {
            continue;
        }
        let r = w_run[i];
        let Some(result) = usize::try_from(r).ok().and_then(|k| results.get(k)) else {
            continue;
        };
        let j = per_run[r as usize];
        per_run[r as usize] += 1;
        let xy = result.detections.get(j).copied().unwrap_or([f64::NAN; 2]);
        d.0.push(r + 1);
        d.1.push(w_t[i]);
        d.2.push(100.0 * xy[0]);
        d.3.push(100.0 * xy[1]);
        d.4.push(w_p[i]);
        d.5.push(w_ev[i]);
        d.6.push(
            STEP_NAMES
                .get(steps[i] as usize)
                .map_or(String::new(), |s| s.to_string()),
        );
    }
    CsvTable {
        name: "detections",
        columns: vec![
            ("run", Column::I64(d.0)),
            ("t_s", Column::F64(d.1)),
            ("x_cm", Column::F64(d.2)),
            ("y_cm", Column::F64(d.3)),
            ("p_error", Column::F64(d.4)),
            ("evidence", Column::F64(d.5)),
            ("step", Column::Str(d.6)),
        ],
    }
}

/// The belief per goal after each window, long.
pub(super) fn belief_table(windows: &Table, names: &[String]) -> CsvTable {
    let (w_run, w_t) = (i64s(windows, "run"), f64s(windows, "t_s"));
    // Belief per goal, long.
    let (belief, width) = match windows.column("belief") {
        Some(Column::F64Rows(v, w)) => (&v[..], *w),
        _ => (&[][..], 0),
    };
    let rows = w_t.len() * width;
    let mut b = (
        Vec::with_capacity(rows),
        Vec::with_capacity(rows),
        Vec::with_capacity(rows),
        Vec::with_capacity(rows),
    );
    for i in 0..w_t.len() {
        for g in 0..width {
            b.0.push(w_run[i] + 1);
            b.1.push(w_t[i]);
            b.2.push(name_of(names, g as i64));
            b.3.push(belief[i * width + g]);
        }
    }
    CsvTable {
        name: "belief",
        columns: vec![
            ("run", Column::I64(b.0)),
            ("t_s", Column::F64(b.1)),
            ("goal", Column::Str(b.2)),
            ("p", Column::F64(b.3)),
        ],
    }
}

/// One row per ErrP of the user.
pub(super) fn errps_table(errps: &Table) -> CsvTable {
    CsvTable {
        name: "errps",
        columns: vec![
            ("run", run1(i64s(errps, "run"))),
            ("t_s", Column::F64(f64s(errps, "t_s").to_vec())),
            ("onset_s", Column::F64(f64s(errps, "onset_s").to_vec())),
            (
                "judged_phase",
                Column::Str(
                    i64s(errps, "phase")
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
pub(super) fn events_table(events: &Table) -> CsvTable {
    CsvTable {
        name: "events",
        columns: vec![
            ("run", run1(i64s(events, "run"))),
            ("t_s", Column::F64(f64s(events, "t_s").to_vec())),
            (
                "level",
                Column::Str(
                    bools(events, "warn")
                        .iter()
                        .map(|&w| if w { "WARN" } else { "INFO" }.to_string())
                        .collect(),
                ),
            ),
            (
                "text",
                match events.column("text") {
                    Some(Column::Str(v)) => Column::Str(v.clone()),
                    _ => Column::Str(Vec::new()),
                },
            ),
        ],
    }
}
