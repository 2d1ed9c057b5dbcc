//! The columns of `episodes.csv`, and one episode's row.

use errp_robot::Cell;

use errp_sim::Result;
use errp_sim::epuck::run_epuck_episode;
use errp_sim::grid::run_grid_episode;

use crate::prepare::Runner;
use crate::spec::{Level, SweepSpec, SweepTask, format_number, value_text};

/// The header of `episodes.csv` for `spec`.
pub fn episodes_header(spec: &SweepSpec) -> String {
    let mut cols = vec!["level".to_string(), "accuracy".into()];
    cols.extend(spec.axes.iter().map(|a| a.name.clone()));
    cols.extend(["episode", "seed", "success"].map(String::from));
    let task_cols: &[&str] = match spec.task {
        SweepTask::Grid => &[
            "start_x",
            "start_y",
            "goal_x",
            "goal_y",
            "committed_x",
            "committed_y",
            "actions",
            "net_secs",
            "total_secs",
            "errors",
            "detected",
            "false_alarms",
            "missed",
        ],
        SweepTask::Epuck => &[
            "goal",
            "committed",
            "time_secs",
            "path_m",
            "errps",
            "detected",
            "false_alarms",
            "missed",
            "detected_turning",
            "detected_driving",
            "detected_on_goal",
            "hit_rate",
            "false_alarms_per_min",
        ],
    };
    cols.extend(task_cols.iter().map(|s| s.to_string()));
    cols.extend(["acc_correct", "acc_error", "online_accuracy"].map(String::from));
    cols.join(",")
}

/// The name of the cost column (what the sweep minimises) of `task`.
pub fn cost_column(task: SweepTask) -> &'static str {
    match task {
        SweepTask::Grid => "actions",
        SweepTask::Epuck => "time_secs",
    }
}

/// A rate as a CSV field: empty when undefined.
pub(crate) fn rate(x: f64) -> String {
    if x.is_finite() {
        format_number(x)
    } else {
        String::new()
    }
}

/// Correct decisions over all decisions of an accuracy's two classes.
pub(crate) fn overall(a: &errp_bci::Accuracy) -> (usize, usize, f64) {
    let hits_error = (a.error * a.n_error as f64).round() as usize;
    let hits_correct = (a.correct * a.n_correct as f64).round() as usize;
    let n = a.n_error + a.n_correct;
    let acc = if n == 0 {
        f64::NAN
    } else {
        (hits_error + hits_correct) as f64 / n as f64
    };
    (hits_error, hits_correct, acc)
}

/// Runs episode `k` of `level` and formats its CSV row.
pub(crate) fn run_row(
    spec: &SweepSpec,
    level: &Level,
    runner: &Runner,
    k: usize,
) -> Result<String> {
    let seed = spec.episode_seed(level.accuracy, k);
    let mut f = vec![level.index.to_string(), format_number(level.accuracy)];
    f.extend(level.values.iter().map(value_text));
    f.extend([k.to_string(), seed.to_string()]);
    let cell = |c: Option<Cell>| match c {
        Some(c) => [c.x.to_string(), c.y.to_string()],
        None => [String::new(), String::new()],
    };
    let online = match runner {
        Runner::Grid {
            scenario,
            decoder,
            table,
        } => {
            let (start, goal) = scenario.episodes[k % scenario.episodes.len()];
            let r = run_grid_episode(start, goal, table, &scenario.params, decoder, seed, false)?;
            let (detected, hits_correct, _) = overall(&r.online);
            f.push(u8::from(r.reached()).to_string());
            f.extend(cell(Some(start)));
            f.extend(cell(Some(goal)));
            f.extend(cell(r.committed));
            f.extend([
                r.actions.to_string(),
                format_number(r.net_secs),
                format_number(r.total_secs),
                r.online.n_error.to_string(),
                detected.to_string(),
                (r.online.n_correct - hits_correct).to_string(),
                (r.online.n_error - detected).to_string(),
            ]);
            r.online
        }
        Runner::Epuck { scenario, decoder } => {
            let r = run_epuck_episode(
                &scenario.params,
                &scenario.arena,
                &scenario.layout,
                scenario.episode,
                decoder,
                seed,
                &mut (),
            )?;
            let names = scenario.layout.names();
            f.push(u8::from(r.reached()).to_string());
            f.push(names[r.goal].to_string());
            f.push(r.committed.map_or(String::new(), |c| names[c].to_string()));
            f.extend([
                format_number(r.time_secs),
                format_number(r.path_m),
                r.errps.to_string(),
                r.detected_errors.to_string(),
                r.false_detections.to_string(),
                r.missed_errors.to_string(),
                r.detected_by_phase[0].to_string(),
                r.detected_by_phase[1].to_string(),
                r.detected_by_phase[2].to_string(),
                rate(r.hit_rate()),
                rate(r.false_alarms_per_min()),
            ]);
            r.online
        }
    };
    let (_, _, acc) = overall(&online);
    f.extend([rate(online.correct), rate(online.error), rate(acc)]);
    Ok(f.join(","))
}
