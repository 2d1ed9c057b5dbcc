//! The fit's files: `fit.json`, `surface.csv` and the figure.

use std::path::{Path, PathBuf};

use errp_sim::Result;

use super::paper::PaperRow;
use super::result::{CellStats, GridFit, REACHED_LEVEL};
use crate::fit::files;
use crate::plot::{Curve, CurvePoint, FitPanel, FitPlot};

pub(super) fn write_fit(fit: &GridFit, out: &Path) -> Result<Vec<PathBuf>> {
    files::write_fit_files(out, fit, grid_surface_csv(fit), &grid_fit_plot(fit))
}

/// One row per grid point: the total and each subject's log-likelihood on
/// the fixed goals, the held-out free goals' total, and each subject's mean
/// actions, reached share and online accuracy on both goal sets.
pub fn grid_surface_csv(fit: &GridFit) -> String {
    let s = &fit.surface;
    let mut header = vec![
        "goal_reward".to_string(),
        "log_lik".into(),
        "log_lik_mc_sd".into(),
        "free_log_lik".into(),
    ];
    for (set, rows) in [("fixed", &fit.fixed), ("free", &fit.free)] {
        for row in rows.iter() {
            let k = format!("{}_{set}", row.subject.to_lowercase());
            if set == "fixed" {
                header.push(format!("{k}_log_lik"));
            }
            for c in [
                "p_reached",
                "actions_mean",
                "actions_sd",
                "z",
                "online_accuracy",
            ] {
                header.push(format!("{k}_{c}"));
            }
        }
    }
    header.push("p_all_40_reached".into());
    for set in ["fixed", "free"] {
        header.push(format!("{set}_tables_all_reached"));
        header.push(format!("{set}_tables_r_negative"));
        header.push(format!("{set}_median_r"));
    }
    let mut out = header.join(",") + "\n";
    let num = |v: f64| errp_sim::task::format_number(v);
    for j in 0..s.grid.len() {
        let mut row = vec![
            num(s.grid[j]),
            num(s.total[j]),
            num(s.total_sd[j]),
            num(fit.free_log_lik[j]),
        ];
        for (fixed, stats) in [(true, &fit.fixed_stats), (false, &fit.free_stats)] {
            for (i, per_point) in stats.iter().enumerate() {
                let st = &per_point[j];
                if fixed {
                    row.push(num(s.log_lik[i][j]));
                }
                row.extend([
                    num(st.reached as f64 / st.runs.max(1) as f64),
                    num(st.actions.0),
                    num(st.actions.1),
                    num(st.z),
                    num(st.online_accuracy),
                ]);
            }
        }
        row.push(num(fit.p_all_reached[j]));
        for t in [&fit.fixed_tables[j], &fit.free_tables[j]] {
            row.extend([
                num(t.all_reached as f64 / t.tables.max(1) as f64),
                num(t.r_negative as f64 / t.tables.max(1) as f64),
                num(t.median_r),
            ]);
        }
        out += &(row.join(",") + "\n");
    }
    out
}

/// The figure: the log-likelihood of each subject's fixed-goal row and of
/// all four, then the mean actions on the fixed goals (fitted) and on the
/// free goals (held out) against the goal reward, the paper's values as
/// reference lines.
pub fn grid_fit_plot(fit: &GridFit) -> FitPlot {
    let s = &fit.surface;
    let labels: Vec<String> = fit.fixed.iter().map(|r| r.subject.clone()).collect();
    let ll = files::log_lik_curves(s, &labels, "all four");
    let actions =
        |rows: &[PaperRow], stats: &[Vec<CellStats>]| -> (Vec<Curve>, Vec<(String, f64, usize)>) {
            let curves = rows
                .iter()
                .zip(stats)
                .map(|(row, per_point)| Curve {
                    label: format!("{} ({:.1} %)", row.subject, 100.0 * row.accuracy),
                    points: per_point
                        .iter()
                        .zip(&s.grid)
                        .map(|(st, &x)| CurvePoint {
                            x,
                            y: st.group_mean[0],
                            lo: st.group_mean[1],
                            hi: st.group_mean[2],
                        })
                        .collect(),
                })
                .collect();
            let refs = rows
                .iter()
                .enumerate()
                .map(|(i, row)| {
                    (
                        format!("paper, {}: {}", row.subject, row.actions_mean),
                        row.actions_mean,
                        i,
                    )
                })
                .collect();
            (curves, refs)
        };
    let (fixed_curves, fixed_refs) = actions(&fit.fixed, &fit.fixed_stats);
    let (free_curves, free_refs) = actions(&fit.free, &fit.free_stats);
    let (lo, hi) = fit.estimate.interval_95;
    FitPlot {
        title: format!(
            "Grid fit to Table 1's fixed goals: goal reward {} (95 % LR {lo}-{hi}), {} keeps \
             the paper's 40/40 (P >= {REACHED_LEVEL}){}",
            errp_sim::task::format_number(fit.estimate.value),
            fit.reached_estimate
                .map_or("none".into(), errp_sim::task::format_number),
            fit.pairs.as_ref().map_or(String::new(), |p| format!(
                "; at the fixed pairs' length {} (estimate {}, 95 % LR {}-{})",
                p.chosen, p.estimate, p.interval_95.0, p.interval_95.1
            ))
        ),
        x_desc: "goal reward (Q-value scale at tau = 0.3)".into(),
        estimate: fit.estimate.value,
        interval: fit.estimate.interval_95,
        panels: vec![
            FitPanel {
                caption: "Log-likelihood, fixed goals (± Monte Carlo sd)".into(),
                y_desc: "log-likelihood - its maximum".into(),
                curves: ll,
                references: Vec::new(),
                y_floor: Some(-20.0),
            },
            FitPanel {
                caption: "Mean actions of 5 runs, fixed goals (fitted; median, 10-90 %)".into(),
                y_desc: "actions".into(),
                curves: fixed_curves,
                references: fixed_refs,
                y_floor: Some(0.0),
            },
            FitPanel {
                caption: "Mean actions of 5 runs, free goals (held out)".into(),
                y_desc: "actions".into(),
                curves: free_curves,
                references: free_refs,
                y_floor: Some(0.0),
            },
        ],
    }
}
