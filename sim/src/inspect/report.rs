//! What `errp inspect` prints of recordings, as `Display` types: one
//! recording described with its runs recomputed ([`RecordingReport`]), a
//! line on each ([`RecordingHeadline`]), and several side by side
//! ([`Comparison`]).

use std::fmt;

use crate::epuck::{EpuckRunsTable, EpuckSummaryReport, summarise};
use crate::grid::{GridEpisodeHeader, GridEpisodeRow, GridRunReport};
use crate::inspect::{Recording, Runs, phase_secs};
use crate::stats::{fixed_or_dash, median};
use crate::task_kind::TaskKind;

/// One line on a recording: its file, task, scenario, runs and maker.
pub struct RecordingHeadline<'a>(pub &'a Recording);

impl fmt::Display for RecordingHeadline<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&headline(self.0))
    }
}

/// The full description of one recording: provenance, how to run it
/// again, and what `errp run` printed, recomputed from the recording.
pub struct RecordingReport<'a>(pub &'a Recording);

impl fmt::Display for RecordingReport<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        describe(f, self.0)
    }
}

/// The recordings' summaries side by side.
pub struct Comparison<'a>(pub &'a [Recording]);

impl fmt::Display for Comparison<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        compare(f, self.0)
    }
}

/// One line on a recording: its file, task, scenario, runs and maker.
fn headline(r: &Recording) -> String {
    let p = &r.provenance;
    format!(
        "{}: {} recording of `{}`, {} run(s), seed {}, by errp {} (commit {})",
        r.path.display(),
        p.task.label(),
        p.scenario_name,
        p.runs,
        p.seed,
        p.errp_version,
        p.commit
    )
}

/// The full description of one recording: provenance, how to run it again,
/// and what `errp run` printed, recomputed from the recording.
fn describe(f: &mut fmt::Formatter<'_>, r: &Recording) -> fmt::Result {
    let p = &r.provenance;
    writeln!(f, "{}", headline(r))?;
    writeln!(f, "  made by:  {}", p.command.join(" "))?;
    let runs = if p.task == TaskKind::Epuck {
        format!(" --runs {}", p.runs)
    } else {
        String::new()
    };
    match (&p.agent, &r.live) {
        (_, Some(live)) => writeln!(
            f,
            "  live:     errp stream at speed {}, decisions from {}; replay them offline: errp \
             inspect {} --replay",
            live.speed,
            live.decoder,
            r.path.display()
        )?,
        (Some(agent), None) => writeln!(
            f,
            "  driven by: {agent}; each episode's seed is in the runs table \
             (--csv), the actions in the trajectory"
        )?,
        (None, None) => writeln!(
            f,
            "  run again: errp inspect {} --scenario > scenario.toml && errp run scenario.toml \
             --seed {}{runs}",
            r.path.display(),
            p.seed
        )?,
    }
    writeln!(f, "Recomputed from the recording:")?;
    write!(f, "{}", p.decoder_summary)?;
    match &r.runs {
        Runs::Epuck { scenario, results } => {
            let layout = &scenario.layout;
            write!(f, "{}", EpuckRunsTable { results, layout })?;
            let summary = summarise(results);
            let t_e = crate::record::schema::EpuckRunsView::or_empty(&r.tables)
                .t_e
                .first()
                .copied()
                .unwrap_or(f64::NAN);
            write!(
                f,
                "{}",
                EpuckSummaryReport {
                    summary: &summary,
                    scenario: &scenario.name,
                    goal: &layout.goals()[scenario.episode.goal].name,
                    t_e,
                }
            )?;
            writeln!(f)?;
            writeln!(
                f,
                "{:>4}  {:>8}  {:>11} {:>11} {:>11}",
                "run", "path (m)", "turning (s)", "driving (s)", "stopped (s)"
            )?;
            for (k, (result, [turning, driving, stopped])) in
                results.iter().zip(phase_secs(r)).enumerate()
            {
                writeln!(
                    f,
                    "{:>4}  {:>8.2}  {:>11.1} {:>11.1} {:>11.1}",
                    k + 1,
                    result.path_m,
                    turning,
                    driving,
                    stopped
                )?;
            }
        }
        Runs::Grid { scenario, results } => {
            writeln!(f, "{GridEpisodeHeader}")?;
            for (k, e) in results.iter().enumerate() {
                writeln!(f, "{}", GridEpisodeRow(k, e))?;
            }
            let report = GridRunReport {
                scenario: (**scenario).clone(),
                calibration: None,
                own_eeg: None,
                episodes: results.clone(),
            };
            write!(f, "{report}")?;
        }
    }
    if let Some(live) = &r.live {
        let windows = r.runs.kind() == TaskKind::Epuck;
        writeln!(f)?;
        writeln!(
            f,
            "Decisions from the online decoder, as received (latencies on its clock):"
        )?;
        for (k, run) in live.runs.iter().enumerate() {
            writeln!(f, "{:>4}  {}", k + 1, run.timing(windows, None))?;
        }
        let all = crate::live::LiveRunStats::merged(&live.runs);
        writeln!(f, "{:>4}  {}", "all", all.timing(windows, Some(live.speed)))?;
    }
    Ok(())
}

/// The recordings' summaries side by side.
fn compare(f: &mut fmt::Formatter<'_>, recs: &[Recording]) -> fmt::Result {
    let name = |r: &Recording| {
        r.path.file_name().map_or_else(
            || r.path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    };
    let mut rows: Vec<(String, Vec<String>)> = Vec::new();
    let mut add = |label: &str, values: Vec<String>| rows.push((label.to_string(), values));
    add(
        "scenario",
        recs.iter()
            .map(|r| r.provenance.scenario_name.clone())
            .collect(),
    );
    add(
        "runs",
        recs.iter().map(|r| r.n_runs().to_string()).collect(),
    );
    let stat = |of: &dyn Fn(&Recording) -> Option<String>| {
        recs.iter()
            .map(|r| of(r).unwrap_or_else(|| "-".into()))
            .collect::<Vec<_>>()
    };
    add(
        "goals reached",
        stat(&|r| match &r.runs {
            Runs::Epuck { results, .. } => Some(format!(
                "{} / {}",
                results.iter().filter(|x| x.reached()).count(),
                results.len()
            )),
            Runs::Grid { results, .. } => Some(format!(
                "{} / {}",
                results.iter().filter(|x| x.reached()).count(),
                results.len()
            )),
        }),
    );
    add(
        "median time (s)",
        stat(&|r| match &r.runs {
            Runs::Epuck { results, .. } => Some(fixed_or_dash(summarise(results).median_secs, 1)),
            Runs::Grid { results, .. } => Some(fixed_or_dash(
                median(&results.iter().map(|e| e.total_secs).collect::<Vec<_>>()),
                1,
            )),
        }),
    );
    add(
        "median detections",
        stat(&|r| match &r.runs {
            Runs::Epuck { results, .. } => {
                Some(fixed_or_dash(summarise(results).median_detected, 1))
            }
            Runs::Grid { .. } => None,
        }),
    );
    add(
        "median false",
        stat(&|r| match &r.runs {
            Runs::Epuck { results, .. } => Some(fixed_or_dash(summarise(results).median_false, 1)),
            Runs::Grid { .. } => None,
        }),
    );
    add(
        "hit rate (%)",
        stat(&|r| match &r.runs {
            Runs::Epuck { results, .. } => {
                Some(fixed_or_dash(100.0 * summarise(results).hit_rate, 1))
            }
            Runs::Grid { .. } => None,
        }),
    );
    add(
        "false alarms/min",
        stat(&|r| match &r.runs {
            Runs::Epuck { results, .. } => {
                Some(fixed_or_dash(summarise(results).false_alarms_per_min, 2))
            }
            Runs::Grid { .. } => None,
        }),
    );
    add(
        "median actions",
        stat(&|r| match &r.runs {
            Runs::Grid { results, .. } => Some(fixed_or_dash(
                median(&results.iter().map(|e| e.actions as f64).collect::<Vec<_>>()),
                1,
            )),
            Runs::Epuck { .. } => None,
        }),
    );
    let names: Vec<String> = recs.iter().map(name).collect();
    side_by_side(f, &names, &rows)
}

/// Rows of values under a column per recording (`names`), labels first.
fn side_by_side(
    f: &mut fmt::Formatter<'_>,
    names: &[String],
    rows: &[(String, Vec<String>)],
) -> fmt::Result {
    let widths: Vec<usize> = names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            rows.iter()
                .map(|(_, v)| v[k].len())
                .chain([name.len()])
                .max()
                .unwrap_or(8)
        })
        .collect();
    let mut line = format!("{:<18}", "");
    for (k, name) in names.iter().enumerate() {
        line.push_str(&format!("  {:>w$}", name, w = widths[k]));
    }
    writeln!(f, "{line}")?;
    for (label, values) in rows {
        let mut line = format!("{label:<18}");
        for (k, v) in values.iter().enumerate() {
            line.push_str(&format!("  {:>w$}", v, w = widths[k]));
        }
        writeln!(f, "{line}")?;
    }
    Ok(())
}
