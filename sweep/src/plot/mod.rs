//! Figures of a Monte Carlo sweep over decoder accuracy.
//!
//! A [`SweepPlot`] is drawn as one figure with two panels sharing the x axis
//! (the decoder's accuracy): on the left the success rate with its 95% Wilson
//! interval, on the right the mean cost of the successful episodes with ±1 sd,
//! with the paper's own results overlaid. The same drawing code serves both
//! outputs, [`svg()`] (an in-memory SVG document) and [`png()`] (in-memory PNG
//! file bytes); both are deterministic, the same input giving the same bytes.
//!
//! Text is set in DejaVu Sans, embedded in the binary and registered with
//! plotters' `ab_glyph` font registry under the name `"sans-serif"`, so no
//! system font library is needed.

mod chart;
mod fit;
mod glyph_text;
mod legend;
mod panels;
mod recording;
mod render;
mod series;
mod style;
mod sweep;

/// A point from the paper to overlay on the cost panel (Table 1 subjects, or
/// the paper's e-puck runs).
pub use errp_sim::task::PaperPoint;
pub use fit::{Curve, CurvePoint, FitPanel, FitPlot, fit_png, fit_svg};
pub use panels::{png, svg};
pub use recording::{ArenaPlot, GridPlot, RunPath, arena_png, arena_svg, grid_png, grid_svg};
pub use render::PlotError;
pub use sweep::{LevelPoint, Series, SweepPlot};
