//! The sweep figure's data: each series of levels, the paper's points and
//! the axis labels, from the summary.

use errp_bci::GoalSet;

use errp_sim::AnyScenario;
use errp_sim::wilson_interval;
use errp_sim::{PAPER, PAPER_EPUCK};

use crate::plot::{LevelPoint, PaperPoint, Series, SweepPlot};
use crate::spec::{SweepSpec, format_number};
use crate::summary::SweepReport;

/// The plot of a sweep, with the paper's figures where they apply.
pub fn sweep_plot(spec: &SweepSpec, report: &SweepReport, scenario: &AnyScenario) -> SweepPlot {
    let mut series: Vec<Series> = Vec::new();
    for l in &report.levels {
        let (lo, hi) = wilson_interval(l.successes, l.episodes);
        let point = LevelPoint {
            accuracy: l.accuracy,
            success_rate: l.success_rate(),
            success_lo: lo,
            success_hi: hi,
            mean: l.cost.0,
            sd: l.cost.1,
            median: l.cost.2,
            n: l.episodes,
        };
        match series.iter_mut().find(|s| s.label == l.series) {
            Some(s) => s.points.push(point),
            None => series.push(Series {
                label: l.series.clone(),
                points: vec![point],
            }),
        }
    }
    for s in &mut series {
        s.points.sort_by(|a, b| a.accuracy.total_cmp(&b.accuracy));
    }
    let decoder = match scenario {
        AnyScenario::Grid(s) => match s.decoder {
            errp_sim::grid::DecoderChoice::Oracle => "oracle decoder".to_string(),
            errp_sim::grid::DecoderChoice::Eeg => {
                format!("EEG decoder ({:?})", s.eeg).to_lowercase()
            }
        },
        AnyScenario::Epuck(_) => "sliding-window SVM decoder".to_string(),
    };
    let (task, cost_label, paper, paper_label) = match scenario {
        AnyScenario::Grid(_) => (
            "Grid task".to_string(),
            "actions to convergence (successful episodes)".to_string(),
            PAPER
                .iter()
                .map(|(name, set, row)| PaperPoint {
                    label: format!(
                        "{name} {}",
                        if *set == GoalSet::Fixed {
                            "fixed"
                        } else {
                            "free"
                        }
                    ),
                    accuracy: row[6] / 100.0,
                    value: row[0],
                    sd: Some(row[1]),
                })
                .collect::<Vec<_>>(),
            "paper, Table 1 (S1-S4, fixed and free goals)".to_string(),
        ),
        AnyScenario::Epuck(s) => {
            let paper: Vec<PaperPoint> = PAPER_EPUCK
                .iter()
                .filter(|(name, _, _)| *name == s.name)
                .map(|(name, secs, _)| PaperPoint {
                    label: name.to_string(),
                    // The paper gives no accuracy for its continuous
                    // decoder: drawn at the scenario's.
                    accuracy: s.accuracy,
                    value: *secs,
                    sd: None,
                })
                .collect();
            (
                format!("E-puck task, {}", s.name),
                "time to convergence, s (successful episodes)".to_string(),
                paper,
                format!(
                    "paper, {} (one run; drawn at the scenario's {})",
                    s.name,
                    format_number(s.accuracy)
                ),
            )
        }
    };
    SweepPlot {
        title: format!(
            "{task}: {} accuracies{} x {} episodes, {decoder}, seed {}",
            spec.accuracies.len(),
            if series.len() > 1 {
                format!(" x {} settings", series.len())
            } else {
                String::new()
            },
            spec.episodes,
            spec.seed
        ),
        cost_label,
        series,
        paper,
        paper_label,
    }
}
