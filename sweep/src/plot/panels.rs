//! The figure of a sweep drawn: its two panels (axes, ticks, the success
//! and cost series), to SVG or PNG.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{Bar, Chart, TickFormat};
use super::legend::{LegendCorner, draw_legend, legend_labels};
use super::render::{Figure, PlotError, draw_error, render_png, render_svg, titled};
use super::series::{draw_paper, draw_series, sorted};
use super::style::{AXIS_DESC_SIZE, CAPTION_SIZE, TICK_SIZE, WIDTH, font};
use super::sweep::SweepPlot;

/// The x axis of a sweep's panels.
const ACCURACY_DESC: &str = "decoder accuracy (mean of per-class rates)";

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

impl Figure for SweepPlot {
    fn width(&self) -> u32 {
        WIDTH
    }
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw(root, self)
    }
}

/// Renders the figure as an SVG document.
///
/// Text is left as `<text>` elements with `font-family="sans-serif"`, so the
/// viewer's sans-serif font sets it.
pub fn svg(plot: &SweepPlot) -> Result<String, PlotError> {
    render_svg(plot)
}

/// Renders the figure as a PNG file (8-bit RGB), text set in the embedded
/// DejaVu Sans.
pub fn png(plot: &SweepPlot) -> Result<Vec<u8>, PlotError> {
    render_png(plot)
}

/// Draws the whole figure on `root`.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &SweepPlot,
) -> Result<(), PlotError> {
    let body = titled(root, &plot.title)?;

    let (left, right) = body.split_horizontally(WIDTH / 2);
    let x_range = x_range(plot);
    draw_success_panel(&left, plot, x_range.clone())?;
    draw_cost_panel(&right, plot, x_range)?;
    Ok(())
}

/// The shared x range: [0.5, 1] widened to hold every point.
fn x_range(plot: &SweepPlot) -> std::ops::Range<f64> {
    let xs = plot
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.accuracy))
        .chain(plot.paper.iter().map(|p| p.accuracy))
        .filter(|x| x.is_finite());
    let (lo, hi) = xs.fold((0.5f64, 1.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    let pad = 0.02 * (hi - lo);
    (lo - pad)..(hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::style::TITLE_BAND;
    use crate::plot::sweep::{LevelPoint, Series};
    use errp_sim::task::PaperPoint;

    fn level(accuracy: f64, rate: f64, mean: f64) -> LevelPoint {
        LevelPoint {
            accuracy,
            success_rate: rate,
            success_lo: (rate - 0.1).max(0.0),
            success_hi: (rate + 0.1).min(1.0),
            mean,
            sd: 0.2 * mean,
            median: mean,
            n: 100,
        }
    }

    fn example() -> SweepPlot {
        SweepPlot {
            title: "test".to_string(),
            cost_label: "actions to convergence".to_string(),
            series: vec![
                Series {
                    label: "a".to_string(),
                    points: vec![level(0.6, 0.4, 80.0), level(0.8, 0.9, 20.0)],
                },
                Series {
                    label: String::new(),
                    points: vec![level(0.7, 0.0, f64::NAN), level(0.9, 1.0, 10.0)],
                },
            ],
            paper: vec![PaperPoint {
                label: "S1".to_string(),
                accuracy: 0.83,
                value: 16.0,
                sd: Some(2.0),
            }],
            paper_label: "paper".to_string(),
        }
    }

    #[test]
    fn svg_is_deterministic_and_names_the_font_family() {
        let plot = example();
        let a = svg(&plot).unwrap();
        assert_eq!(a, svg(&plot).unwrap());
        assert!(a.starts_with("<svg"));
        assert!(a.contains("font-family=\"sans-serif\""));
        assert!(a.contains("actions to convergence"));
    }

    #[test]
    fn png_is_deterministic_and_has_text() {
        let plot = example();
        let a = png(&plot).unwrap();
        assert_eq!(a, png(&plot).unwrap());
        assert_eq!(&a[..8], b"\x89PNG\r\n\x1a\n");
        // The title band holds nothing but the title: some pixel there must
        // be dark if text was rendered.
        let mut reader = png::Decoder::new(std::io::Cursor::new(&a))
            .read_info()
            .unwrap();
        let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut pixels).unwrap();
        let band = &pixels[..(WIDTH * TITLE_BAND * 3) as usize];
        assert!(band.iter().any(|&v| v < 100));
    }

    #[test]
    fn empty_and_degenerate_plots_render() {
        let mut plot = example();
        plot.series.clear();
        plot.paper.clear();
        svg(&plot).unwrap();
        png(&plot).unwrap();
        plot.series = vec![Series {
            label: "only failures".to_string(),
            points: vec![level(0.55, 0.0, f64::NAN)],
        }];
        svg(&plot).unwrap();
        png(&plot).unwrap();
    }

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(34.4), 50.0);
        assert_eq!(nice_step(0.3), 0.5);
        assert_eq!(nice_step(2.0), 2.0);
        assert_eq!(format_tick(150.0), "150");
        assert_eq!(format_tick(0.25), "0.25");
    }
}
