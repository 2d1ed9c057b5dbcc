//! What the panels of every figure share: the chart type, tick formats,
//! and the points with error bars a legend must not cover.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// How an axis writes its tick labels.
pub(super) type TickFormat<'a> = &'a dyn Fn(&f64) -> String;

/// A panel's chart type: accuracy (or another parameter) against a
/// real-valued y.
pub(super) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A point with a vertical error bar, in data coordinates.
#[derive(Debug, Clone, Copy)]
pub(super) struct Bar {
    pub(super) x: f64,
    pub(super) y: f64,
    pub(super) lo: f64,
    pub(super) hi: f64,
}

/// Records the backend pixels covered by the markers, error bars and line
/// segments of `bars`, for choosing where the legend goes.
pub(super) fn record_obstacles<'a, DB: DrawingBackend + 'a>(
    chart: &Chart<'a, DB>,
    bars: &[Bar],
    obstacles: &mut Vec<(i32, i32)>,
) {
    const STEPS: usize = 24;
    for b in bars {
        for k in 0..=STEPS {
            let t = k as f64 / STEPS as f64;
            if b.lo.is_finite() && b.hi.is_finite() {
                obstacles.push(chart.backend_coord(&(b.x, b.lo + t * (b.hi - b.lo))));
            }
        }
    }
    for w in bars.windows(2) {
        for k in 0..=STEPS {
            let t = k as f64 / STEPS as f64;
            let x = w[0].x + t * (w[1].x - w[0].x);
            let y = w[0].y + t * (w[1].y - w[0].y);
            obstacles.push(chart.backend_coord(&(x, y)));
        }
    }
}
