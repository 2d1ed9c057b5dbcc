//! What a sweep's summary looks like: `summary.csv` and the printed table.

use std::fmt;

use errp_sim::wilson_interval;

use crate::spec::{SweepSpec, value_text};
use crate::summary::SweepReport;
use errp_sim::task::format_number;

/// A statistic in the summary: 6 decimals, empty when undefined.
fn stat(x: f64) -> String {
    if x.is_finite() {
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.to_string() }
    } else {
        String::new()
    }
}

/// The text of `summary.csv`.
pub fn summary_csv(spec: &SweepSpec, report: &SweepReport) -> String {
    let info = spec.task.info();
    let cost = info.cost_column;
    let mut cols = vec!["level".to_string(), "accuracy".into()];
    cols.extend(spec.axes.iter().map(|a| a.name.clone()));
    cols.extend(
        [
            "episodes",
            "success_rate",
            "success_lo95",
            "success_hi95",
            "wrong_goal_rate",
            "no_commit_rate",
        ]
        .map(String::from),
    );
    cols.extend(["mean", "sd", "median"].map(|s| format!("{cost}_{s}")));
    cols.push("online_accuracy".into());
    cols.push(format!("r_online_{cost}"));
    cols.push(format!("p_online_{cost}"));
    let detector = info.detector_columns.is_some();
    if let Some((hits, false_alarms)) = info.detector_columns {
        cols.extend([hits, false_alarms].map(String::from));
    }
    let mut out = cols.join(",");
    out.push('\n');
    for l in &report.levels {
        let (_, values) = spec.level_values(l.level);
        let n = l.episodes as f64;
        let (lo, hi) = wilson_interval(l.successes, l.episodes);
        let mut f = vec![l.level.to_string(), format_number(l.accuracy)];
        f.extend(values.iter().map(value_text));
        f.extend([
            l.episodes.to_string(),
            stat(l.success_rate()),
            stat(lo),
            stat(hi),
            stat(l.wrong as f64 / n),
            stat(l.no_commit as f64 / n),
            stat(l.cost.0),
            stat(l.cost.1),
            stat(l.cost.2),
            stat(l.online_accuracy),
            stat(l.r_p.0),
            stat(l.r_p.1),
        ]);
        if detector {
            f.extend([stat(l.detector.0), stat(l.detector.1)]);
        }
        out.push_str(&f.join(","));
        out.push('\n');
    }
    out
}

impl fmt::Display for SweepReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let cost = self.task.info().cost_label;
        let width = self
            .levels
            .iter()
            .map(|l| l.series.len())
            .max()
            .unwrap_or(0)
            .max(6);
        let with_series = self.levels.iter().any(|l| !l.series.is_empty());
        if with_series {
            write!(f, "{:<width$}  ", "series")?;
        }
        let detector = self.task.info().detector_columns.is_some();
        write!(
            f,
            "{:>8} {:>6} {:>8} {:>15} {:>17} {:>7} {:>7} {:>6} {:>7}",
            "accuracy",
            "n",
            "success",
            "95% CI",
            format!("{cost} mean ± sd"),
            "median",
            "online",
            "r",
            "p"
        )?;
        if detector {
            write!(f, " {:>6} {:>8}", "hits", "FA/min")?;
        }
        writeln!(f)?;
        for l in &self.levels {
            let (lo, hi) = wilson_interval(l.successes, l.episodes);
            if with_series {
                write!(f, "{:<width$}  ", l.series)?;
            }
            let num = |x: f64, d: usize| {
                if x.is_finite() {
                    format!("{x:.d$}")
                } else {
                    "-".into()
                }
            };
            write!(
                f,
                "{:>8} {:>6} {:>7.1}% {:>15} {:>17} {:>7} {:>7} {:>6} {:>7}",
                // A recording's accuracy is measured: four places.
                Some(format_number(l.accuracy))
                    .filter(|a| a.len() <= 8)
                    .unwrap_or_else(|| format!("{:.4}", l.accuracy)),
                l.episodes,
                100.0 * l.success_rate(),
                format!("[{:.1}, {:.1}]", 100.0 * lo, 100.0 * hi),
                format!("{} ± {}", num(l.cost.0, 1), num(l.cost.1, 1)),
                num(l.cost.2, 1),
                num(l.online_accuracy, 3),
                num(l.r_p.0, 2),
                num(l.r_p.1, 3),
            )?;
            if detector {
                write!(
                    f,
                    " {:>6} {:>8}",
                    num(l.detector.0, 3),
                    num(l.detector.1, 2)
                )?;
            }
            writeln!(f)?;
        }
        for (label, n, (r, p)) in &self.series {
            let name = if label.is_empty() {
                "all levels".to_string()
            } else {
                label.clone()
            };
            writeln!(
                f,
                "{name}: online accuracy vs {cost} over {n} successful episodes: r = {}, p = {}",
                errp_sim::fixed_or_dash(*r, 3),
                if p.is_finite() {
                    format!("{p:.3e}")
                } else {
                    "-".into()
                }
            )?;
        }
        Ok(())
    }
}
