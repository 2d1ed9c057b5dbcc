//! Legends: their entries, and the corner where they cover the fewest marks.

use plotters::element::MultiLineText;
use plotters::prelude::*;

use super::chart::Chart;
use super::render::{PlotError, draw_error};
use super::style::{LEGEND_GLYPH, LEGEND_MARGIN, LEGEND_SIZE, font};
use super::sweep::SweepPlot;

/// The non-empty legend entries of a panel: the series' labels, then the
/// paper's if `with_paper`.
pub(super) fn legend_labels(plot: &SweepPlot, with_paper: bool) -> Vec<&str> {
    let series = plot.series.iter().map(|s| s.label.as_str());
    let paper = with_paper.then_some(plot.paper_label.as_str());
    series.chain(paper).filter(|l| !l.is_empty()).collect()
}

/// The corners a legend may go in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum LegendCorner {
    UpperLeft,
    UpperRight,
    LowerLeft,
    LowerRight,
}

impl LegendCorner {
    const ALL: [LegendCorner; 4] = [
        LegendCorner::UpperRight,
        LegendCorner::LowerRight,
        LegendCorner::UpperLeft,
        LegendCorner::LowerLeft,
    ];

    /// Plotters' name for the corner.
    fn position(self) -> SeriesLabelPosition {
        match self {
            LegendCorner::UpperLeft => SeriesLabelPosition::UpperLeft,
            LegendCorner::UpperRight => SeriesLabelPosition::UpperRight,
            LegendCorner::LowerLeft => SeriesLabelPosition::LowerLeft,
            LegendCorner::LowerRight => SeriesLabelPosition::LowerRight,
        }
    }

    /// The legend box of size `(w, h)` in this corner of the plotting area
    /// spanning backend pixels `x0..x1`, `y0..y1` (as plotters lays it out).
    fn rect(self, (w, h): (i32, i32), (x0, x1): (i32, i32), (y0, y1): (i32, i32)) -> [i32; 4] {
        let left = matches!(self, LegendCorner::UpperLeft | LegendCorner::LowerLeft);
        let upper = matches!(self, LegendCorner::UpperLeft | LegendCorner::UpperRight);
        let x = if left { x0 + 5 } else { x1 - w - 5 };
        let y = if upper { y0 + 5 } else { y1 - h - 5 };
        [x, y, x + w, y + h]
    }
}

/// Draws the panel's legend of `labels` (the entries already attached to the
/// drawn series), if there are any, in the corner of the plotting area that
/// hides the fewest drawn pixels, trying the `preferred` corners first.
pub(super) fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    labels: &[&str],
    obstacles: &[(i32, i32)],
    preferred: &[LegendCorner],
) -> Result<(), PlotError> {
    if labels.is_empty() {
        return Ok(());
    }
    let style = font(LEGEND_SIZE);
    let mut text = MultiLineText::<_, &str>::new((0, 0), &style);
    for l in labels {
        text.push_line(*l);
    }
    let (tw, th) = text.estimate_dimension().map_err(draw_error)?;
    let size = (
        tw + LEGEND_GLYPH + 2 * LEGEND_MARGIN,
        th + 2 * LEGEND_MARGIN,
    );
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let (xs, ys) = ((xr.start, xr.end), (yr.start, yr.end));
    let corners = preferred.iter().copied().chain(
        LegendCorner::ALL
            .into_iter()
            .filter(|c| !preferred.contains(c)),
    );
    let mut best = (usize::MAX, LegendCorner::UpperRight);
    for corner in corners {
        let [x0, y0, x1, y1] = corner.rect(size, xs, ys);
        let hidden = obstacles
            .iter()
            .filter(|(x, y)| (x0 - 4..=x1 + 4).contains(x) && (y0 - 4..=y1 + 4).contains(y))
            .count();
        if hidden < best.0 {
            best = (hidden, corner);
        }
    }
    chart
        .configure_series_labels()
        .position(best.1.position())
        .margin(LEGEND_MARGIN)
        .legend_area_size(LEGEND_GLYPH)
        .label_font(style.clone())
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.35))
        .draw()
        .map_err(draw_error)?;
    Ok(())
}
