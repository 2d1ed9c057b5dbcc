//! The tables `errp run` prints for the e-puck task, as `Display` types so
//! that what users read is tested.

use std::fmt;

use errp_robot::GoalLayout;

use crate::epuck::episode::EpuckEpisodeResult;
use crate::epuck::run::EpuckSummary;
use crate::paper::PAPER_EPUCK;
use crate::stats::{fixed_or_dash, percentile_of, quantile};
use crate::task::ordinal_percent;

/// The header line of the per-run table ([`EpuckRunRow`]).
pub struct EpuckRunHeader;

impl fmt::Display for EpuckRunHeader {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:>4}  {:<16} {:>8}  {:>8} {:>6} {:>6} {:>6}  {:>8} {:>8}  {:>5} {:>6}",
            "run",
            "converged on",
            "time (s)",
            "detected",
            "false",
            "missed",
            "ErrPs",
            "acc corr",
            "acc err",
            "hit %",
            "FA/min"
        )
    }
}

/// One run's line of the table: run `index` (from 0), its result, and the
/// layout that names its goals.
pub struct EpuckRunRow<'a> {
    /// The run's index, from 0.
    pub index: usize,
    /// Its result.
    pub result: &'a EpuckEpisodeResult,
    /// The goal layout, for the city names.
    pub layout: &'a GoalLayout,
}

impl fmt::Display for EpuckRunRow<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = self.result;
        let name = |c: usize| self.layout.goals()[c].name.clone();
        let on = match r.committed {
            Some(c) if c == r.goal => name(c),
            Some(c) => format!("{} WRONG", name(c)),
            None => "time-out".into(),
        };
        write!(
            f,
            "{:>4}  {:<16} {:>8.1}  {:>8} {:>6} {:>6} {:>6}  {:>8} {:>8}  {:>5} {:>6}",
            self.index + 1,
            on,
            r.time_secs,
            r.detected_errors,
            r.false_detections,
            r.missed_errors,
            r.errps,
            fixed_or_dash(100.0 * r.online.correct, 1),
            fixed_or_dash(100.0 * r.online.error, 1),
            fixed_or_dash(100.0 * r.hit_rate(), 0),
            fixed_or_dash(r.false_alarms_per_min(), 2)
        )
    }
}

/// The per-run table: the header, then one line per run.
pub struct EpuckRunsTable<'a> {
    /// The runs' results, in run order.
    pub results: &'a [EpuckEpisodeResult],
    /// The goal layout, for the city names.
    pub layout: &'a GoalLayout,
}

impl fmt::Display for EpuckRunsTable<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{EpuckRunHeader}")?;
        for (index, result) in self.results.iter().enumerate() {
            writeln!(
                f,
                "{}",
                EpuckRunRow {
                    index,
                    result,
                    layout: self.layout
                }
            )?;
        }
        Ok(())
    }
}

/// The fewest runs reaching the goal whose central 80 % (10th to 90th
/// percentile) and percentiles of the paper's run the summary prints:
/// below it the 10th and 90th percentiles are the extreme runs themselves,
/// and a percentile of the paper's run moves by more than ten points with
/// one run more.
pub const MIN_RUNS_FOR_PERCENTILES: usize = 10;

/// The summary of an e-puck scenario's runs, beside the paper's run of the
/// same name if it has one.
pub struct EpuckSummaryReport<'a> {
    /// The summary.
    pub summary: &'a EpuckSummary,
    /// The scenario's name (the paper's runs are found by it).
    pub scenario: &'a str,
    /// The user's goal.
    pub goal: &'a str,
    /// The decision threshold in force.
    pub t_e: f64,
}

impl EpuckSummaryReport<'_> {
    /// The central 80 % of the runs that reached the goal and the paper's
    /// run's percentiles among them, or how many runs they need.
    fn spread(
        &self,
        f: &mut fmt::Formatter<'_>,
        paper: Option<&(&str, f64, usize)>,
    ) -> fmt::Result {
        let s = self.summary;
        let q = |v: &[f64], d: usize| {
            let (lo, hi) = (quantile(v, 0.1), quantile(v, 0.9));
            if lo.is_finite() && hi.is_finite() {
                format!("{lo:.d$}-{hi:.d$}")
            } else {
                "-".to_string()
            }
        };
        let reached = s.reached_secs.len();
        if reached < MIN_RUNS_FOR_PERCENTILES {
            writeln!(
                f,
                "  central 80 %         needs at least {MIN_RUNS_FOR_PERCENTILES} runs that reach \
                 {} ({reached} did here): run more",
                self.goal
            )?;
            if paper.is_some() {
                writeln!(f, "  the paper's run      its percentiles need as many")?;
            }
        } else {
            writeln!(
                f,
                "  central 80 %         time {} s, detected {}",
                q(&s.reached_secs, 1),
                q(&s.reached_detected, 0)
            )?;
            if let Some(&(_, secs, det)) = paper {
                writeln!(
                    f,
                    "  the paper's run      at the {} percentile of time and the {} of \
                     detections",
                    ordinal_percent(percentile_of(&s.reached_secs, secs)),
                    ordinal_percent(percentile_of(&s.reached_detected, det as f64))
                )?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for EpuckSummaryReport<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.summary;
        let paper = PAPER_EPUCK.iter().find(|p| p.0 == self.scenario);
        let note = |v: Option<String>| v.map(|v| format!("   [paper: {v}]")).unwrap_or_default();
        writeln!(f, "Summary over {} run(s):", s.runs)?;
        writeln!(
            f,
            "  reached {}      {} / {} ({} converged on a wrong city)",
            self.goal, s.reached, s.runs, s.wrong
        )?;
        let medians = [
            (
                "median time (s)",
                s.median_secs,
                paper.map(|p| format!("{:.0}", p.1)),
            ),
            (
                "median detected",
                s.median_detected,
                paper.map(|p| p.2.to_string()),
            ),
        ];
        for (label, value, paper) in medians {
            writeln!(
                f,
                "  {label:<20} {}{}",
                fixed_or_dash(value, 1),
                note(paper)
            )?;
        }
        self.spread(f, paper)?;
        writeln!(
            f,
            "  median time to goal  {}   (a run on a wrong city never reaches it)",
            if s.median_secs_to_goal.is_finite() {
                format!("{:.1} s", s.median_secs_to_goal)
            } else {
                "never: fewer than half the runs reach it".to_string()
            }
        )?;
        writeln!(
            f,
            "  median false         {}",
            fixed_or_dash(s.median_false, 1)
        )?;
        let [turning, driving, on_goal] = s.phase_shares.map(|x| fixed_or_dash(100.0 * x, 0));
        writeln!(
            f,
            "  detections           {} per second of run; {turning} % turning, \
             {driving} % driving, {on_goal} % on a goal   [paper: 0.18 and 0.21, mostly \
             during turns]",
            fixed_or_dash(s.detections_per_sec, 3)
        )?;
        let [turn, drive, stop] = s.judged_shares.map(|x| fixed_or_dash(100.0 * x, 0));
        writeln!(
            f,
            "  true detections      of ErrPs judging a turn {turn} %, a drive {drive} %, a \
             stop {stop} %"
        )?;
        writeln!(
            f,
            "  online detector      hit rate {} % per ErrP, {} false alarms per error-free minute",
            fixed_or_dash(100.0 * s.hit_rate, 1),
            fixed_or_dash(s.false_alarms_per_min, 2)
        )?;
        writeln!(
            f,
            "  window accuracy      correct {} %, error {} % at T_e = {} ({} clean / {} ErrP windows)",
            fixed_or_dash(100.0 * s.online.correct, 2),
            fixed_or_dash(100.0 * s.online.error, 2),
            self.t_e,
            s.online.n_correct,
            s.online.n_error
        )
    }
}

#[cfg(test)]
mod tests {
    use errp_bci::Accuracy;

    use super::*;
    use crate::epuck::run::summarise;
    use crate::snapshot::assert_snapshot;

    fn result(committed: Option<usize>, time_secs: f64, detected: usize) -> EpuckEpisodeResult {
        EpuckEpisodeResult {
            goal: 24,
            committed,
            time_secs,
            detected_errors: detected,
            detected_by_phase: [
                detected / 3,
                detected / 2,
                detected - detected / 3 - detected / 2,
            ],
            true_by_judged_phase: [2, 1, 3],
            false_detections: 1,
            missed_errors: 2,
            errps: detected + 1,
            errps_scored: detected,
            clean_secs: 0.8 * time_secs,
            online: Accuracy {
                correct: 0.997,
                error: 0.81,
                n_correct: 900,
                n_error: 60,
            },
            path_m: 3.1,
            max_lateral_m_per_s: 0.0,
            detections: Vec::new(),
        }
    }

    #[test]
    fn the_run_table_and_summary_read_as_printed() {
        let layout = GoalLayout::cities();
        let results = [
            result(Some(24), 61.25, 15),
            result(Some(23), 48.0, 9),
            result(None, 600.0, 120),
        ];
        let mut text = format!("{EpuckRunHeader}\n");
        for (index, result) in results.iter().enumerate() {
            let row = EpuckRunRow {
                index,
                result,
                layout: &layout,
            };
            text.push_str(&format!("{row}\n"));
        }
        let summary = summarise(&results);
        let report = EpuckSummaryReport {
            summary: &summary,
            scenario: "Mexico to Pisa",
            goal: "Pisa",
            t_e: 0.8,
        };
        text.push_str(&report.to_string());
        assert_snapshot("epuck_report", &text);
    }
}
