//! Markers, error bars and lines of the series and the paper's points.

use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::{BackendCoord, DrawingErrorKind};

use super::chart::{Bar, Chart, record_obstacles};
use super::render::{PlotError, draw_error};
use super::style::{PAPER_COLOUR, colour};
use super::sweep::LevelPoint;

/// The points of a series sorted by accuracy.
pub(super) fn sorted(points: &[LevelPoint]) -> impl Iterator<Item = &LevelPoint> {
    let mut v: Vec<&LevelPoint> = points.iter().collect();
    v.sort_by(|a, b| a.accuracy.total_cmp(&b.accuracy));
    v.into_iter()
}

/// Marker shapes, cycled over the series so that they differ in more than
/// colour.
#[derive(Debug, Clone, Copy)]
pub(super) enum Marker {
    Circle,
    Square,
    Triangle,
    Diamond,
}

impl Marker {
    /// The marker of the `i`th series.
    fn of(i: usize) -> Self {
        [Self::Circle, Self::Square, Self::Triangle][i % 3]
    }

    /// The marker centred on `at` (data or backend coordinates).
    fn at<C>(self, at: C, style: ShapeStyle) -> MarkerElement<C> {
        MarkerElement {
            at,
            shape: self,
            style,
        }
    }
}

/// A marker drawn centred on one point, with a fixed size in pixels.
pub(super) struct MarkerElement<C> {
    at: C,
    shape: Marker,
    style: ShapeStyle,
}

impl<'a, C> PointCollection<'a, C> for &'a MarkerElement<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for MarkerElement<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _parent_dim: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = points.next() else {
            return Ok(());
        };
        let style = &self.style;
        match self.shape {
            Marker::Circle => backend.draw_circle((x, y), 4, style, style.filled),
            Marker::Square => {
                backend.draw_rect((x - 4, y - 4), (x + 4, y + 4), style, style.filled)
            }
            Marker::Triangle => {
                let corners = [(x, y - 5), (x + 5, y + 4), (x - 5, y + 4)];
                if style.filled {
                    backend.fill_polygon(corners, style)
                } else {
                    backend.draw_path(corners.into_iter().chain([corners[0]]), style)
                }
            }
            Marker::Diamond => {
                // Outlined diamonds get a white face, so lines behind them
                // do not show through.
                let corners = [(x, y - 6), (x + 6, y), (x, y + 6), (x - 6, y), (x, y - 6)];
                if !style.filled {
                    backend.fill_polygon(corners, &WHITE)?;
                }
                backend.draw_path(corners, style)
            }
        }
    }
}

/// Draws series `i` of `count`: error bars, a line and markers, with a legend
/// entry if `label` is not empty. Records the pixels it covers in `obstacles`.
pub(super) fn draw_series<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    bars: &[Bar],
    (i, count): (usize, usize),
    label: &str,
    obstacles: &mut Vec<(i32, i32)>,
) -> Result<(), PlotError> {
    let c = colour(i);
    let marker = Marker::of(i);
    draw_error_bars(chart, bars, c.mix(0.7).stroke_width(1), dodge(i, count))?;
    let line = chart
        .draw_series(LineSeries::new(
            bars.iter().map(|b| (b.x, b.y)),
            c.stroke_width(2),
        ))
        .map_err(draw_error)?;
    if !label.is_empty() {
        line.label(label).legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (24, 0)], c.stroke_width(2))
                + marker.at((12, 0), c.filled())
        });
    }
    chart
        .draw_series(bars.iter().map(|b| marker.at((b.x, b.y), c.filled())))
        .map_err(draw_error)?;
    record_obstacles(chart, bars, obstacles);
    Ok(())
}

/// Draws the paper's points as black diamonds with their error bars.
pub(super) fn draw_paper<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    bars: &[Bar],
    label: &str,
    obstacles: &mut Vec<(i32, i32)>,
) -> Result<(), PlotError> {
    let style = PAPER_COLOUR.stroke_width(2);
    draw_error_bars(chart, bars, PAPER_COLOUR.stroke_width(1), 0)?;
    let drawn = chart
        .draw_series(bars.iter().map(|b| Marker::Diamond.at((b.x, b.y), style)))
        .map_err(draw_error)?;
    if !label.is_empty() {
        drawn.label(label).legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(12, -8), (12, 8)], PAPER_COLOUR.stroke_width(1))
                + Marker::Diamond.at((12, 0), style)
        });
    }
    record_obstacles(chart, bars, obstacles);
    Ok(())
}

/// Draws vertical error bars with short caps, shifted `dx` pixels sideways
/// so that the bars of series sharing an accuracy stay apart.
pub(super) fn draw_error_bars<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    bars: &[Bar],
    style: ShapeStyle,
    dx: i32,
) -> Result<(), PlotError> {
    let ends: Vec<((f64, f64), i32)> = bars
        .iter()
        .filter(|b| b.lo.is_finite() && b.hi.is_finite() && b.hi > b.lo)
        .map(|b| {
            let lo = chart.backend_coord(&(b.x, b.lo));
            let hi = chart.backend_coord(&(b.x, b.hi));
            ((b.x, b.lo), hi.1 - lo.1)
        })
        .collect();
    chart
        .draw_series(ends.into_iter().map(|(lo, rise)| {
            EmptyElement::at(lo)
                + PathElement::new(
                    vec![
                        (dx - 4, 0),
                        (dx + 4, 0),
                        (dx, 0),
                        (dx, rise),
                        (dx - 4, rise),
                        (dx + 4, rise),
                    ],
                    style,
                )
        }))
        .map_err(draw_error)?;
    Ok(())
}

/// Sideways shift, in pixels, of the error bars of series `i` of `count`.
pub(super) fn dodge(i: usize, count: usize) -> i32 {
    if count < 2 {
        return 0;
    }
    let spacing = (12.0 / (count - 1) as f64).min(4.0);
    ((i as f64 - (count - 1) as f64 / 2.0) * spacing).round() as i32
}
