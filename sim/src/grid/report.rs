//! The tables `errp run` and `errp table1` print for the grid task, as
//! `Display` types so that what users read is tested.

use std::fmt;

use errp_bci::GoalSet;
use errp_robot::Grid;

use crate::grid::plant::GridEpisodeResult;
use crate::grid::run::GridRunReport;
use crate::grid::table1::{Table1Cell, accuracy_time_correlation};
use crate::paper::{PAPER, PAPER_POOLED};
use crate::stats::mean_sd;

/// The header line of the per-episode table ([`GridEpisodeRow`]).
pub struct GridEpisodeHeader;

impl fmt::Display for GridEpisodeHeader {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:>3}  {:>6} {:>6}  {:>13}  {:>7}  {:>8}  {:>9}  {:>8} {:>8} {:>8}",
            "#",
            "start",
            "goal",
            "committed",
            "actions",
            "net (s)",
            "total (s)",
            "acc corr",
            "acc err",
            "acc mean"
        )
    }
}

/// One episode's line of the table: episode `index` (from 0) and its result.
pub struct GridEpisodeRow<'a>(pub usize, pub &'a GridEpisodeResult);

impl fmt::Display for GridEpisodeRow<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let GridEpisodeRow(k, r) = *self;
        let committed = match r.committed {
            Some(c) if c == r.goal => format!("{c} ok"),
            Some(c) => format!("{c} WRONG"),
            None => "none".to_string(),
        };
        let pct = |v: f64| {
            if v.is_nan() {
                "-".to_string()
            } else {
                format!("{:.1}", 100.0 * v)
            }
        };
        write!(
            f,
            "{:>3}  {:>6} {:>6}  {:>13}  {:>7}  {:>8.2}  {:>9.2}  {:>8} {:>8} {:>8}",
            k + 1,
            r.start.to_string(),
            r.goal.to_string(),
            committed,
            r.actions,
            r.net_secs,
            r.total_secs,
            pct(r.online.correct),
            pct(r.online.error),
            pct(r.online.mean())
        )
    }
}

/// The summary of a grid run: goals reached, actions and times (mean +- sd)
/// and the pooled online accuracy.
impl fmt::Display for GridRunReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.episodes.len();
        let reached = self.episodes.iter().filter(|r| r.reached()).count();
        let col = |g: fn(&GridEpisodeResult) -> f64| {
            mean_sd(&self.episodes.iter().map(g).collect::<Vec<_>>())
        };
        let (am, asd) = col(|r| r.actions as f64);
        let (nm, nsd) = col(|r| r.net_secs);
        let (tm, tsd) = col(|r| r.total_secs);
        let online = self.online_accuracy();
        writeln!(f, "Summary over {n} episodes:")?;
        writeln!(f, "  goals reached    {reached} / {n}")?;
        writeln!(f, "  actions          {am:.1} +- {asd:.1}")?;
        writeln!(f, "  net time (s)     {nm:.2} +- {nsd:.2}")?;
        writeln!(f, "  total time (s)   {tm:.2} +- {tsd:.2}")?;
        writeln!(
            f,
            "  online accuracy  correct {} %, error {} %, mean {} % over {} actions",
            crate::fixed_or_dash(100.0 * online.correct, 2),
            crate::fixed_or_dash(100.0 * online.error, 2),
            crate::fixed_or_dash(100.0 * online.mean(), 2),
            online.n_correct + online.n_error
        )
    }
}

/// Calibration against online for each subject of a goal set: what an
/// experimenter sees as the gap between the calibration session and the
/// closed loop (nothing for the oracle, which has no calibration).
fn calibration_gaps(f: &mut fmt::Formatter<'_>, cells: &[Table1Cell], set: GoalSet) -> fmt::Result {
    let gaps: Vec<String> = cells
        .iter()
        .filter(|c| c.goals == set)
        .filter_map(|c| {
            c.calibration.map(|(cv, online)| {
                format!(
                    "{} {:.2}/{:.2} ({:+.2})",
                    c.subject,
                    100.0 * cv,
                    100.0 * online,
                    100.0 * (cv - online)
                )
            })
        })
        .collect();
    if gaps.is_empty() {
        return Ok(());
    }
    writeln!(
        f,
        "           calibration cross-validated / online held-out accuracy (%): {}",
        gaps.join(", ")
    )
}

/// The information per action of each subject's decoder on a goal set,
/// between what a binary symmetric channel and an erasure channel at the
/// same accuracy carry (the least and the most at that accuracy), and the
/// fewest actions that much information allows for singling out one goal
/// of the grid's 25: log2(25) / bits (about: the closed loop's verdicts are
/// not exactly half errors, and no action tells more of the goal than of
/// the verdict).
fn information(f: &mut fmt::Formatter<'_>, cells: &[Table1Cell], set: GoalSet) -> fmt::Result {
    let goals = Grid::paper().n_cells() as f64;
    let bits: Vec<String> = cells
        .iter()
        .filter(|c| c.goals == set)
        .map(|c| {
            let i = &c.information;
            format!(
                "{} {:.3} [{:.3}-{:.3}] {:.1}",
                c.subject,
                i.bits,
                i.binary_symmetric_bits(),
                i.erasure_bits(),
                goals.log2() / i.bits
            )
        })
        .collect();
    writeln!(
        f,
        "           information per action (bits, equal priors) [binary symmetric-erasure channel at its accuracy] and the fewest actions it allows (log2 25 / bits): {}",
        bits.join(", ")
    )
}

/// The two header lines of [`Table1Report`].
fn table1_header(f: &mut fmt::Formatter<'_>) -> fmt::Result {
    writeln!(
        f,
        "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}  {:>8}",
        "", "reached", "actions", "net time (s)", "total time (s)", "mean accuracy (%)", "pooled"
    )?;
    writeln!(
        f,
        "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}  {:>8}",
        "", "", "ours [paper]", "ours [paper]", "ours [paper]", "ours [paper]", "(%)"
    )
}

/// Table 1 as `errp table1` prints it: one row per subject and goal set,
/// ours beside the paper's, the pooled rows and the accuracy-time
/// correlations.
pub struct Table1Report<'a>(pub &'a [Table1Cell]);

impl fmt::Display for Table1Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let cells = self.0;
        table1_header(f)?;
        // The pooled accuracy: every action of the runs counted once, what
        // the decoder is calibrated to (the mean accuracy averages runs, as
        // the paper's row does, and so weighs short runs, where the decoder
        // did well, as much as long ones).
        let pooled = |runs: &mut dyn Iterator<Item = &GridEpisodeResult>| {
            let a = errp_bci::Accuracy::pooled(runs.map(|r| &r.online)).mean();
            if a.is_finite() {
                format!("{:.2}", 100.0 * a)
            } else {
                "-".to_string()
            }
        };
        // A statistic over no defined value (every run lacked a class) is
        // shown as "-", not NaN.
        let ours = |(m, sd): (f64, f64), (pm, psd): (f64, f64), d: usize| {
            if m.is_finite() {
                format!("{m:.d$}+-{sd:.d$} [{pm:.d$}+-{psd:.d$}]")
            } else {
                format!("- [{pm:.d$}+-{psd:.d$}]")
            }
        };
        for set in [GoalSet::Fixed, GoalSet::Free] {
            let set_name = if set == GoalSet::Fixed {
                "fixed"
            } else {
                "free"
            };
            let mut all: Vec<&GridEpisodeResult> = Vec::new();
            for c in cells.iter().filter(|c| c.goals == set) {
                let paper = PAPER
                    .iter()
                    .find(|p| p.0 == c.subject && p.1 == set)
                    .map_or([f64::NAN; 8], |p| p.2);
                let reached = c.runs.iter().filter(|r| r.reached()).count();
                writeln!(
                    f,
                    "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}  {:>8}",
                    format!("{} {set_name}", c.subject),
                    format!("{reached}/{}", c.runs.len()),
                    ours(c.stat(|r| r.actions as f64), (paper[0], paper[1]), 0),
                    ours(c.stat(|r| r.net_secs), (paper[2], paper[3]), 2),
                    ours(c.stat(|r| r.total_secs), (paper[4], paper[5]), 2),
                    ours(c.stat(|r| 100.0 * r.online.mean()), (paper[6], paper[7]), 2),
                    pooled(&mut c.runs.iter()),
                )?;
                all.extend(c.runs.iter());
            }
            let stat = |g: &dyn Fn(&GridEpisodeResult) -> f64| {
                mean_sd(
                    &all.iter()
                        .map(|r| g(r))
                        .filter(|v| v.is_finite())
                        .collect::<Vec<_>>(),
                )
            };
            let (paper_mean, paper_r, paper_p) = PAPER_POOLED
                .iter()
                .find(|p| p.0 == set)
                .map(|p| (p.1, p.2, p.3))
                .ok_or(fmt::Error)?;
            let reached = all.iter().filter(|r| r.reached()).count();
            writeln!(
                f,
                "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}  {:>8}",
                format!("mean {set_name}"),
                format!("{reached}/{}", all.len()),
                ours(
                    stat(&|r| r.actions as f64),
                    (paper_mean[0], paper_mean[1]),
                    0
                ),
                ours(stat(&|r| r.net_secs), (paper_mean[2], paper_mean[3]), 2),
                ours(stat(&|r| r.total_secs), (paper_mean[4], paper_mean[5]), 2),
                ours(
                    stat(&|r| 100.0 * r.online.mean()),
                    (paper_mean[6], paper_mean[7]),
                    2
                ),
                pooled(&mut all.iter().copied()),
            )?;
            let (r, p) = accuracy_time_correlation(cells, set);
            let ours_r = if r.is_finite() {
                format!("r = {r:.2}, p = {p:.2e}")
            } else {
                "r undefined (fewer than 3 runs with both classes)".to_string()
            };
            writeln!(
                f,
                "           accuracy vs total time ({set_name} goals): {ours_r}   [paper: r = {paper_r}, p = {paper_p:.2e}]"
            )?;
            calibration_gaps(f, cells, set)?;
            information(f, cells, set)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::grid::run::{prepare_decoder, run_grid_scenario};
    use crate::grid::scenario::{DecoderChoice, EegMode, GridScenario};
    use crate::grid::table1::{Table1Options, run_table1};
    use crate::snapshot::assert_snapshot;

    #[test]
    fn a_grid_run_reads_as_printed() {
        let text = r#"
task = "grid"
decoder = "oracle"
seed = 3
episode = [{ start = [0, 0], goal = [4, 4] }, { start = [2, 2], goal = [0, 4] }]
[user]
accuracy = 0.8
"#;
        let scenario = GridScenario::parse(text, Path::new("snapshot.toml")).unwrap();
        let (decoder, calibration) = prepare_decoder(&scenario, |_| {}).unwrap();
        let mut out = format!("{GridEpisodeHeader}\n");
        let episodes = run_grid_scenario(&scenario, &decoder, false, |k, r| {
            out.push_str(&format!("{}\n", GridEpisodeRow(k, r)));
        })
        .unwrap();
        let report = GridRunReport {
            scenario,
            calibration,
            own_eeg: None,
            episodes,
        };
        out.push_str(&report.to_string());
        assert_snapshot("grid_report", &out);
    }

    /// Table 1 with the oracle decoder, one run per pair (seed 1).
    fn oracle_table1() -> Vec<Table1Cell> {
        let options = Table1Options {
            repeats: 1,
            seed: 1,
            decoder: DecoderChoice::Oracle,
            eeg: EegMode::Bank,
            params: crate::grid::params::GridTaskParams::default(),
            realism: errp_bci::Realism::default(),
        };
        run_table1(&options, |_, _| {}).unwrap()
    }

    /// A run that took no action of one class has no mean accuracy; it is
    /// left out of that column's statistics and of the correlation instead
    /// of making them NaN (`errp table1 --episodes 3 --seed 5` once printed
    /// `NaN +- NaN`).
    #[test]
    fn a_run_without_errors_does_not_poison_table1() {
        let mut cells = oracle_table1();
        let before = cells[0].stat(|r| r.online.mean());
        // A sixth run of S1 on the fixed goals with no erroneous action.
        let mut clean = cells[0].runs[0].clone();
        clean.online.n_error = 0;
        clean.online.error = f64::NAN;
        assert!(clean.online.mean().is_nan());
        cells[0].runs.push(clean);
        assert_eq!(cells[0].stat(|r| r.online.mean()), before);
        let (r, _) = accuracy_time_correlation(&cells, GoalSet::Fixed);
        assert!(r.is_finite());
        let text = Table1Report(&cells).to_string();
        assert!(!text.contains("NaN"), "{text}");
        // With no run defining it, the column reads "-".
        for c in &mut cells {
            for run in &mut c.runs {
                run.online.error = f64::NAN;
            }
        }
        let text = Table1Report(&cells).to_string();
        assert!(
            !text.contains("NaN") && text.contains("r undefined"),
            "{text}"
        );
    }

    #[test]
    fn table1_reads_as_printed() {
        let cells = oracle_table1();
        assert_snapshot("table1_oracle", &Table1Report(&cells).to_string());
    }
}
