//! The figure of a parameter fit (`errp fit`): panels side by side over the
//! fitted parameter, each with curves (a marker per grid point, an error
//! bar), the estimate as a vertical line, its interval shaded, and the
//! paper's values as horizontal reference lines.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{Bar, record_obstacles};
use super::legend::{LegendCorner, draw_legend};
use super::panels::{format_tick, nice_step, panel};
use super::render::{Figure, PlotError, draw_error, render_png, render_svg, titled};
use super::series::draw_series;
use super::style::colour;

/// One grid point of a curve: y with an error bar from `lo` to `hi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// The parameter's value.
    pub x: f64,
    /// The value drawn (NaN: left out).
    pub y: f64,
    /// Lower end of the error bar.
    pub lo: f64,
    /// Upper end of the error bar.
    pub hi: f64,
}

/// A line over the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Legend entry (empty: none).
    pub label: String,
    /// The points, in any order (drawn sorted by x).
    pub points: Vec<CurvePoint>,
}

/// One panel of a fit figure.
#[derive(Debug, Clone, PartialEq)]
pub struct FitPanel {
    /// Caption over the panel.
    pub caption: String,
    /// The y axis.
    pub y_desc: String,
    /// The curves, coloured in order (the same colour means the same
    /// observation across panels).
    pub curves: Vec<Curve>,
    /// Horizontal reference lines: a label, the value and the index of the
    /// curve whose colour they take.
    pub references: Vec<(String, f64, usize)>,
    /// Lowest y shown, if the data should not set it (e.g. a floor under a
    /// log-likelihood that falls steeply).
    pub y_floor: Option<f64>,
}

/// A fit figure: the panels share the x axis (the fitted parameter).
#[derive(Debug, Clone, PartialEq)]
pub struct FitPlot {
    /// Title over the figure.
    pub title: String,
    /// The x axis: what was fitted.
    pub x_desc: String,
    /// The estimate, drawn as a vertical line in every panel.
    pub estimate: f64,
    /// Its interval, shaded in every panel.
    pub interval: (f64, f64),
    /// The panels, left to right.
    pub panels: Vec<FitPanel>,
}

/// Width of one panel, pixels.
const PANEL_WIDTH: u32 = 520;

impl Figure for FitPlot {
    fn width(&self) -> u32 {
        PANEL_WIDTH * self.panels.len().max(1) as u32
    }
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw_fit(root, self)
    }
}

/// Renders a fit figure as an SVG document (text as `<text>` elements in
/// the viewer's sans-serif font, as a sweep's figure).
pub fn fit_svg(plot: &FitPlot) -> Result<String, PlotError> {
    render_svg(plot)
}

/// Renders a fit figure as a PNG file (8-bit RGB, text set in the embedded
/// DejaVu Sans, as a sweep's figure).
pub fn fit_png(plot: &FitPlot) -> Result<Vec<u8>, PlotError> {
    render_png(plot)
}

fn draw_fit<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &FitPlot,
) -> Result<(), PlotError> {
    let body = titled(root, &plot.title)?;
    let n = plot.panels.len().max(1);
    let areas = body.split_evenly((1, n));
    let xs = plot
        .panels
        .iter()
        .flat_map(|p| p.curves.iter().flat_map(|c| c.points.iter().map(|q| q.x)))
        .chain([plot.estimate, plot.interval.0, plot.interval.1])
        .filter(|x| x.is_finite());
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    let (lo, hi) = if lo < hi { (lo, hi) } else { (0.0, 1.0) };
    let pad = 0.04 * (hi - lo);
    let x_range = (lo - pad)..(hi + pad);
    let x_step = nice_step((hi - lo) / 5.0);
    let x_decimals = (-x_step.log10().floor()).max(0.0) as usize;
    for (area, panel) in areas.iter().zip(&plot.panels) {
        draw_fit_panel(area, plot, panel, x_range.clone(), x_decimals)?;
    }
    Ok(())
}

/// Each curve's finite points as bars, in x order.
fn fit_bars(fit: &FitPanel) -> Vec<Vec<Bar>> {
    fit.curves
        .iter()
        .map(|c| {
            let mut v: Vec<Bar> = c
                .points
                .iter()
                .filter(|p| p.x.is_finite() && p.y.is_finite())
                .map(|p| Bar {
                    x: p.x,
                    y: p.y,
                    lo: p.lo,
                    hi: p.hi,
                })
                .collect();
            v.sort_by(|a, b| a.x.total_cmp(&b.x));
            v
        })
        .collect()
}

/// The y axis of a panel: every bar, interval and reference line, above
/// the panel's floor, with a margin.
fn fit_y_range(bars: &[Vec<Bar>], fit: &FitPanel) -> std::ops::Range<f64> {
    let ys = bars
        .iter()
        .flatten()
        .flat_map(|b| [b.y, b.lo, b.hi])
        .chain(fit.references.iter().map(|r| r.1))
        .filter(|y| y.is_finite());
    let (mut y_lo, mut y_hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
        (lo.min(y), hi.max(y))
    });
    if let Some(floor) = fit.y_floor {
        y_lo = y_lo.max(floor);
    }
    if y_lo.partial_cmp(&y_hi) != Some(std::cmp::Ordering::Less) {
        (y_lo, y_hi) = (y_lo.min(0.0) - 1.0, y_hi.max(0.0) + 1.0);
        if !y_lo.is_finite() || !y_hi.is_finite() {
            (y_lo, y_hi) = (0.0, 1.0);
        }
    }
    let pad = 0.06 * (y_hi - y_lo);
    (y_lo - pad)..(y_hi + pad)
}

fn draw_fit_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &FitPlot,
    fit: &FitPanel,
    x_range: std::ops::Range<f64>,
    x_decimals: usize,
) -> Result<(), PlotError> {
    let bars = fit_bars(fit);
    let y_range = fit_y_range(&bars, fit);
    let (x0, x1) = (x_range.start, x_range.end);
    let mut chart = panel(
        area,
        &fit.caption,
        x_range,
        y_range.clone(),
        (&plot.x_desc, &fit.y_desc),
        (&|x| format!("{x:.x_decimals$}"), &|y| format_tick(*y)),
    )?;
    // The estimate's interval, shaded, and the estimate.
    let (a, b) = plot.interval;
    if a.is_finite() && b.is_finite() {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a, y_range.start), (b, y_range.end)],
                BLACK.mix(0.07).filled(),
            )))
            .map_err(draw_error)?;
    }
    if plot.estimate.is_finite() {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(plot.estimate, y_range.start), (plot.estimate, y_range.end)],
                BLACK.mix(0.6).stroke_width(1),
            )))
            .map_err(draw_error)?;
    }
    let mut obstacles = Vec::new();
    for (label, y, i) in &fit.references {
        let c = colour(*i);
        let dashes: Vec<PathElement<(f64, f64)>> = (0..40)
            .filter(|k| k % 2 == 0)
            .map(|k| {
                let t0 = x0 + (x1 - x0) * k as f64 / 40.0;
                let t1 = x0 + (x1 - x0) * (k + 1) as f64 / 40.0;
                PathElement::new(vec![(t0, *y), (t1, *y)], c.stroke_width(2))
            })
            .collect();
        let drawn = chart.draw_series(dashes).map_err(draw_error)?;
        if !label.is_empty() {
            drawn.label(label.as_str()).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (10, 0)], c.stroke_width(2))
                    + PathElement::new(vec![(14, 0), (24, 0)], c.stroke_width(2))
            });
        }
        record_obstacles(
            &chart,
            &[
                Bar {
                    x: x0,
                    y: *y,
                    lo: f64::NAN,
                    hi: f64::NAN,
                },
                Bar {
                    x: x1,
                    y: *y,
                    lo: f64::NAN,
                    hi: f64::NAN,
                },
            ],
            &mut obstacles,
        );
    }
    for (i, (curve, bars)) in fit.curves.iter().zip(&bars).enumerate() {
        draw_series(
            &mut chart,
            bars,
            (i, fit.curves.len()),
            &curve.label,
            &mut obstacles,
        )?;
    }
    let labels: Vec<&str> = fit
        .references
        .iter()
        .map(|r| r.0.as_str())
        .chain(fit.curves.iter().map(|c| c.label.as_str()))
        .filter(|l| !l.is_empty())
        .collect();
    draw_legend(
        &mut chart,
        &labels,
        &obstacles,
        &[LegendCorner::LowerRight, LegendCorner::UpperLeft],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> FitPlot {
        let curve = |label: &str, f: &dyn Fn(f64) -> f64| Curve {
            label: label.to_string(),
            points: (0..7)
                .map(|k| {
                    let x = 0.65 + 0.05 * k as f64;
                    CurvePoint {
                        x,
                        y: f(x),
                        lo: f(x) - 0.3,
                        hi: f(x) + 0.3,
                    }
                })
                .collect(),
        };
        FitPlot {
            title: "fit".into(),
            x_desc: "decoder accuracy".into(),
            estimate: 0.8,
            interval: (0.72, 0.88),
            panels: vec![
                FitPanel {
                    caption: "log-likelihood".into(),
                    y_desc: "log L - max".into(),
                    curves: vec![
                        curve("Mexico", &|x| -100.0 * (x - 0.8).powi(2)),
                        curve("both", &|x| -200.0 * (x - 0.8).powi(2)),
                    ],
                    references: vec![],
                    y_floor: Some(-8.0),
                },
                FitPanel {
                    caption: "time".into(),
                    y_desc: "s".into(),
                    curves: vec![curve("Mexico", &|x| 200.0 - 150.0 * x)],
                    references: vec![("paper, Mexico: 60 s".into(), 60.0, 0)],
                    y_floor: None,
                },
            ],
        }
    }

    #[test]
    fn fit_figures_are_deterministic_and_hold_their_text() {
        let p = example();
        let a = fit_svg(&p).unwrap();
        assert_eq!(a, fit_svg(&p).unwrap());
        assert!(a.contains("paper, Mexico: 60 s") && a.contains("log-likelihood"));
        let b = fit_png(&p).unwrap();
        assert_eq!(b, fit_png(&p).unwrap());
        assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n");
        // Degenerate: no points at all.
        let mut empty = p.clone();
        for panel in &mut empty.panels {
            panel.curves.clear();
            panel.references.clear();
        }
        empty.estimate = f64::NAN;
        fit_svg(&empty).unwrap();
        fit_png(&empty).unwrap();
    }
}
