//! The sweep figure's data: each series of levels, the paper's points and
//! the axis labels, from the summary.

use errp_sim::AnyScenario;
use errp_sim::epuck::EpuckTask;
use errp_sim::grid::GridTask;
use errp_sim::task::Task;
use errp_sim::wilson_interval;

use crate::plot::{LevelPoint, Series, SweepPlot};
use crate::spec::SweepSpec;
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
    let text = match scenario {
        AnyScenario::Grid(s) => GridTask::figure(s),
        AnyScenario::Epuck(s) => EpuckTask::figure(s),
    };
    SweepPlot {
        title: format!(
            "{}: {}{} x {} episodes, {}, seed {}",
            text.task,
            if spec.accuracies.is_empty() {
                "recorded EEG".to_string()
            } else {
                format!("{} accuracies", spec.accuracies.len())
            },
            if series.len() > 1 {
                format!(" x {} settings", series.len())
            } else {
                String::new()
            },
            spec.episodes,
            text.decoder,
            spec.seed
        ),
        cost_label: text.cost_label,
        series,
        paper: text.paper,
        paper_label: text.paper_label,
    }
}
