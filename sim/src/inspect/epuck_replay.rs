//! An e-puck recording's runs recomputed from its frames, windows and
//! ErrPs, scored as the episode scores them.

use std::collections::BTreeMap;

use errp_robot::Pose;

use crate::epuck::episode::Score;
use crate::epuck::plant::step_motion;
use crate::epuck::{EpuckEpisodeResult, EpuckScenario};
use crate::inspect::rows::{check_run_order, index, run_rows};
use crate::record::data::Table;
use crate::record::schema::{
    Ends, EndsView, EpuckRuns, EpuckRunsView, Errps, ErrpsView, EventsView, Frames, FramesView,
    Windows, WindowsView,
};

/// A pose from a recording's centimetres and degrees.
fn cm_deg(x: f64, y: f64, heading_deg: f64) -> Pose {
    Pose::new(x / 100.0, y / 100.0, heading_deg.to_radians())
}

/// The path driven (m), the largest sideways speed (m/s) and each frame's
/// time and true position (m).
type Replayed = (f64, f64, Vec<(f64, [f64; 2])>);

/// The frames `rows` of a run from `start`, measured as the episode measured
/// them.
fn replay_frames(frames: &FramesView<'_>, rows: std::ops::Range<usize>, start: Pose) -> Replayed {
    let (t, x, y, h) = (frames.t_s, frames.x_cm, frames.y_cm, frames.heading_deg);
    let mut pose = start;
    let mut path_m = 0.0;
    let mut max_lateral: f64 = 0.0;
    let mut frame_at = Vec::with_capacity(rows.len());
    for i in rows {
        let next = cm_deg(x[i], y[i], h[i]);
        let (distance, lateral) = step_motion(pose, next);
        max_lateral = max_lateral.max(lateral);
        path_m += distance;
        pose = next;
        frame_at.push((t[i], [pose.x_m, pose.y_m]));
    }
    (path_m, max_lateral, frame_at)
}

/// Refuses windows whose beliefs are not one value per goal.
fn check_belief_width(windows: &WindowsView<'_>, n_goals: usize) -> Result<(), String> {
    let (_, width) = windows.belief;
    if width != n_goals {
        return Err(format!(
            "its beliefs have {width} values, but the scenario has {n_goals} goals"
        ));
    }
    Ok(())
}

/// The e-puck runs recomputed as `run_epuck_episode` scores them.
pub(super) fn epuck_results(
    tables: &BTreeMap<String, Table>,
    scenario: &EpuckScenario,
) -> Result<Vec<EpuckEpisodeResult>, String> {
    let n_goals = scenario.layout.goals().len();
    let runs = EpuckRunsView::of(tables)?;
    let frames = FramesView::of(tables)?;
    let windows = WindowsView::of(tables)?;
    let ends = EndsView::of(tables)?;
    let errps = ErrpsView::of_or_empty(tables)?;
    // Not needed to recompute the runs, but read as tables: checked here.
    EventsView::of_or_empty(tables)?;
    let (run_col, f_run, w_run, e_run, end_run) =
        (runs.run, frames.run, windows.run, errps.run, ends.run);
    for (name, r) in [
        (EpuckRuns::ENTITY, run_col),
        (Frames::ENTITY, f_run),
        (Windows::ENTITY, w_run),
        (Errps::ENTITY, e_run),
        (Ends::ENTITY, end_run),
    ] {
        check_run_order(name, r)?;
    }
    check_belief_width(&windows, n_goals)?;
    let (e_t, e_onset, e_phase) = (errps.t_s, errps.onset_s, errps.phase);
    let (end_t, end_committed) = (ends.t_s, ends.committed);

    let mut out = Vec::new();
    for (k, &r) in run_col.iter().enumerate() {
        if r != k as i64 {
            return Err(format!("its table {} skips run {k}", EpuckRuns::ENTITY));
        }
        let Some(e) = end_run.iter().position(|&x| x == r) else {
            // A run without its end: the recording stopped in it.
            break;
        };
        let span = errp_bci::ResponseSpan {
            from_secs: runs.detection_from_s[k],
            to_secs: runs.detection_to_s[k],
        };
        let window_span = errp_bci::ResponseSpan {
            from_secs: runs.window_from_s[k],
            to_secs: runs.window_to_s[k],
        };
        let fr = run_rows(f_run, k);
        let wr = run_rows(w_run, k);
        let er = run_rows(e_run, k);
        let time_secs = end_t[e];
        let errps_run: Vec<(f64, f64, usize)> = er
            .clone()
            .map(|i| Ok((e_t[i], e_onset[i], index(e_phase[i], 3, "ErrP phase")?)))
            .collect::<Result<_, String>>()?;

        let start = cm_deg(runs.start_x[k], runs.start_y[k], runs.start_heading_deg[k]);
        let (path_m, max_lateral, frame_at) = replay_frames(&frames, fr, start);

        // The episode's own scoring, fed from the tables: each ErrP once the
        // user produced it (before the window that ends after it), each
        // window with the pose at its end.
        let mut score = Score::new(span, window_span, runs.t_e[k]);
        score_run(&mut score, &windows, wr, &errps_run, &frame_at)?;
        let committed = match end_committed[e] {
            -1 => None,
            c => Some(index(c, n_goals, "committed goal")?),
        };
        let goal = index(runs.goal[k], n_goals, "goal")?;
        out.push(score.finish(goal, committed, time_secs, path_m, max_lateral));
    }
    Ok(out)
}

/// Feeds `score` one run's windows (rows `rows` of `w`) and its ErrPs
/// `(seen at, onset, phase)`, with the poses of `frame_at`.
fn score_run(
    score: &mut Score,
    w: &WindowsView<'_>,
    rows: std::ops::Range<usize>,
    errps_run: &[(f64, f64, usize)],
    frame_at: &[(f64, [f64; 2])],
) -> Result<(), String> {
    let mut known = 0usize;
    let mut frame = 0usize;
    for i in rows {
        let t = w.t_s[i];
        while known < errps_run.len() && errps_run[known].0 < t {
            score.errp(errps_run[known].1, errps_run[known].2);
            known += 1;
        }
        let step = index(w.step[i], 4, "window step")?;
        let mut at = [f64::NAN; 2];
        if w.detected[i] {
            while frame + 1 < frame_at.len() && frame_at[frame + 1].0 <= t {
                frame += 1;
            }
            if let Some(&(_, xy)) = frame_at.get(frame) {
                at = xy;
            }
        }
        score.window(t, w.p_error[i], step, w.detected[i], at);
    }
    for &(_, onset, phase) in &errps_run[known..] {
        score.errp(onset, phase);
    }
    Ok(())
}
