//! The fit's files: `fit.json`, `surface.csv` and the figure.

use std::path::{Path, PathBuf};

use errp_sim::Result;

use super::result::{EpuckFit, RunStats};
use crate::fit::files;
use crate::plot::{Curve, CurvePoint, FitPanel, FitPlot};

/// Writes [`FIT_FILES`](crate::fit::FIT_FILES) into `out`.
pub(super) fn write_fit(fit: &EpuckFit, out: &Path) -> Result<Vec<PathBuf>> {
    files::write_fit_files(out, fit, surface_csv(fit), &fit_plot(fit))
}

/// One row per grid point: the total and each run's log-likelihood with
/// its Monte Carlo sd, P(reached), and the medians and percentiles.
pub fn surface_csv(fit: &EpuckFit) -> String {
    let s = &fit.surface;
    let mut header = vec![
        "accuracy".to_string(),
        "log_lik".into(),
        "log_lik_mc_sd".into(),
    ];
    for (name, ..) in &fit.observations {
        let k = name.to_lowercase().replace(' ', "_");
        for c in [
            "log_lik",
            "log_lik_mc_sd",
            "p_reached",
            "median_time_secs",
            "median_detections",
            "time_percentile",
            "detections_percentile",
        ] {
            header.push(format!("{k}_{c}"));
        }
    }
    let mut out = header.join(",") + "\n";
    let num = |v: f64| errp_sim::task::format_number(v);
    for j in 0..s.grid.len() {
        let mut row = vec![num(s.grid[j]), num(s.total[j]), num(s.total_sd[j])];
        for i in 0..fit.observations.len() {
            let st = &fit.stats[i][j];
            row.extend([
                num(s.log_lik[i][j]),
                num(s.mc_sd[i][j]),
                num(st.p_reached()),
                num(st.time_secs[0]),
                num(st.detections[0]),
                num(st.time_percentile),
                num(st.detections_percentile),
            ]);
        }
        out += &(row.join(",") + "\n");
    }
    out
}

/// The figure: the log-likelihood surface, and time and detections against
/// accuracy with the paper's runs as reference lines.
pub fn fit_plot(fit: &EpuckFit) -> FitPlot {
    let s = &fit.surface;
    let labels: Vec<String> = fit.observations.iter().map(|(n, ..)| n.clone()).collect();
    let ll_curves = files::log_lik_curves(s, &labels, "both runs");
    let spread = |k: usize, pick: &dyn Fn(&RunStats) -> [f64; 3]| -> Vec<Curve> {
        let _ = k;
        fit.observations
            .iter()
            .enumerate()
            .map(|(i, (name, ..))| Curve {
                label: format!("{name} (median, 10-90 %)"),
                points: (0..s.grid.len())
                    .map(|j| {
                        let [m, lo, hi] = pick(&fit.stats[i][j]);
                        CurvePoint {
                            x: s.grid[j],
                            y: m,
                            lo,
                            hi,
                        }
                    })
                    .collect(),
            })
            .collect()
    };
    let refs = |unit: &str, pick: &dyn Fn(f64, f64) -> f64| -> Vec<(String, f64, usize)> {
        fit.observations
            .iter()
            .enumerate()
            .map(|(i, (name, _, t, d))| {
                let v = pick(*t, *d);
                (
                    format!("paper, {name}: {} {unit}", errp_sim::task::format_number(v)),
                    v,
                    i,
                )
            })
            .collect()
    };
    let (lo, hi) = fit.estimate.interval_95;
    FitPlot {
        title: format!(
            "E-puck decoder fitted to the paper's two runs: accuracy {:.3} (95 % LR interval \
             {lo:.3}-{hi:.3}); {} calibrations x {} runs per point",
            fit.estimate.value, fit.spec.calibrations, fit.spec.runs
        ),
        x_desc: "decoder accuracy (cross-validated mean of per-class rates)".into(),
        estimate: fit.estimate.value,
        interval: fit.estimate.interval_95,
        panels: vec![
            FitPanel {
                caption: "Log-likelihood (± Monte Carlo sd)".into(),
                y_desc: "log-likelihood - its maximum".into(),
                curves: ll_curves,
                references: Vec::new(),
                y_floor: Some(-12.0),
            },
            FitPanel {
                caption: "Time to the goal (runs that reached it)".into(),
                y_desc: "time (s)".into(),
                curves: spread(0, &|st| st.time_secs),
                references: refs("s", &|t, _| t),
                y_floor: Some(0.0),
            },
            FitPanel {
                caption: "Detected errors (runs that reached it)".into(),
                y_desc: "detections".into(),
                curves: spread(1, &|st| st.detections),
                references: refs("detections", &|_, d| d),
                y_floor: Some(0.0),
            },
        ],
    }
}
