//! The two panels of a sweep figure: axes, ticks, the success and cost series.

use super::*;

/// How an axis writes its tick labels.
pub(super) type TickFormat<'a> = &'a dyn Fn(&f64) -> String;

/// The x axis of a sweep's panels.
const ACCURACY_DESC: &str = "decoder accuracy (mean of per-class rates)";

/// A panel's chart type: accuracy (or another parameter) against a
/// real-valued y.
pub(super) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Builds a panel's axes, grid and labels.
pub(super) fn panel<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    x_range: std::ops::Range<f64>,
    y_range: std::ops::Range<f64>,
    (x_desc, y_desc): (&str, &str),
    (x_format, y_format): (TickFormat, TickFormat),
) -> Result<Chart<'a, DB>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, font(CAPTION_SIZE))
        .margin_top(6)
        .margin_bottom(8)
        .margin_left(10)
        .margin_right(24)
        .x_label_area_size(52)
        .y_label_area_size(68)
        .build_cartesian_2d(x_range, y_range)
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.12))
        .axis_style(BLACK.mix(0.8))
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(x_format)
        .y_label_formatter(y_format)
        .label_style(font(TICK_SIZE))
        .axis_desc_style(font(AXIS_DESC_SIZE))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()
        .map_err(draw_error)?;
    Ok(chart)
}

/// Left panel: success rate with its Wilson interval.
pub(super) fn draw_success_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &SweepPlot,
    x_range: std::ops::Range<f64>,
) -> Result<(), PlotError> {
    let mut chart = panel(
        area,
        "Success rate (95% Wilson interval)",
        x_range,
        -0.02..1.04,
        (ACCURACY_DESC, "success rate"),
        (&|x| format!("{x:.1}"), &|y| format!("{y:.1}")),
    )?;
    let mut obstacles = Vec::new();
    for (i, series) in plot.series.iter().enumerate() {
        let points: Vec<Bar> = sorted(&series.points)
            .filter(|p| p.accuracy.is_finite() && p.success_rate.is_finite())
            .map(|p| Bar {
                x: p.accuracy,
                y: p.success_rate,
                lo: p.success_lo,
                hi: p.success_hi,
            })
            .collect();
        draw_series(
            &mut chart,
            &points,
            (i, plot.series.len()),
            &series.label,
            &mut obstacles,
        )?;
    }
    let labels = legend_labels(plot, false);
    draw_legend(
        &mut chart,
        &labels,
        &obstacles,
        &[LegendCorner::LowerRight, LegendCorner::UpperLeft],
    )
}

/// Right panel: mean cost ±1 sd, and the paper's points.
pub(super) fn draw_cost_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &SweepPlot,
    x_range: std::ops::Range<f64>,
) -> Result<(), PlotError> {
    let bars: Vec<Vec<Bar>> = plot
        .series
        .iter()
        .map(|s| {
            sorted(&s.points)
                .filter(|p| p.accuracy.is_finite() && p.mean.is_finite())
                .map(|p| {
                    let sd = if p.sd.is_finite() { p.sd } else { 0.0 };
                    Bar {
                        x: p.accuracy,
                        y: p.mean,
                        lo: p.mean - sd,
                        hi: p.mean + sd,
                    }
                })
                .collect()
        })
        .collect();
    let paper: Vec<Bar> = plot
        .paper
        .iter()
        .filter(|p| p.accuracy.is_finite() && p.value.is_finite())
        .map(|p| {
            let sd = p.sd.filter(|sd| sd.is_finite()).unwrap_or(0.0);
            Bar {
                x: p.accuracy,
                y: p.value,
                lo: p.value - sd,
                hi: p.value + sd,
            }
        })
        .collect();
    let y_max = bars
        .iter()
        .flatten()
        .chain(&paper)
        .map(|b| b.hi.max(b.y))
        .fold(0.0f64, f64::max);
    let y_top = if y_max > 0.0 {
        let step = nice_step(y_max / 5.0);
        (y_max * 1.04 / step).ceil() * step
    } else {
        1.0
    };

    let mut chart = panel(
        area,
        "Cost of successful episodes (mean ± 1 sd)",
        x_range,
        0.0..y_top,
        (ACCURACY_DESC, &plot.cost_label),
        (&|x| format!("{x:.1}"), &|y| format_tick(*y)),
    )?;
    let mut obstacles = Vec::new();
    for (i, (series, bars)) in plot.series.iter().zip(&bars).enumerate() {
        draw_series(
            &mut chart,
            bars,
            (i, plot.series.len()),
            &series.label,
            &mut obstacles,
        )?;
    }
    if !paper.is_empty() {
        draw_paper(&mut chart, &paper, &plot.paper_label, &mut obstacles)?;
    }
    let labels = legend_labels(plot, !paper.is_empty());
    draw_legend(
        &mut chart,
        &labels,
        &obstacles,
        &[LegendCorner::UpperRight, LegendCorner::LowerLeft],
    )
}

/// The smallest of 1, 2, 2.5, 5 times a power of ten that is at least `v`
/// (`v` > 0).
pub(super) fn nice_step(v: f64) -> f64 {
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 2.5, 5.0]
        .into_iter()
        .map(|m| m * p)
        .find(|c| *c >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// A y tick label: integers without decimals, else up to two.
pub(super) fn format_tick(y: f64) -> String {
    if (y - y.round()).abs() < 1e-9 {
        format!("{y:.0}")
    } else {
        let s = format!("{y:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}
