//! Figures of a recording: the paper's Fig. 5 (the arena from above: the
//! cities, every run's path faint, one run's path in blue with a red mark at
//! each detected error, its start and goal) and Fig. 4 (the grid's visit
//! frequencies, with the paths).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::chart::Chart;
use super::render::{Figure, PlotError, draw_error, render_png, render_svg, titled};
use super::style::{AXIS_DESC_SIZE, HEIGHT, TICK_SIZE, font};

/// A path in the plane of the figure, with its run's detections.
#[derive(Debug, Clone, PartialEq)]
pub struct RunPath {
    /// The points of the path, in order (cm for the arena, cells for the
    /// grid).
    pub points: Vec<[f64; 2]>,
    /// Where errors were detected.
    pub detections: Vec<[f64; 2]>,
}

/// The arena from above, as Fig. 5.
#[derive(Debug, Clone, PartialEq)]
pub struct ArenaPlot {
    /// Title above the figure.
    pub title: String,
    /// Side of the square arena (cm).
    pub size_cm: f64,
    /// Obstacle outlines (cm).
    pub obstacles: Vec<Vec<[f64; 2]>>,
    /// The cities: name and position (cm).
    pub cities: Vec<(String, [f64; 2])>,
    /// The user's goal (index into `cities`).
    pub goal: usize,
    /// Every run's path.
    pub runs: Vec<RunPath>,
    /// The run drawn in full (index into `runs`).
    pub highlight: usize,
}

/// The grid's visit frequencies, as Fig. 4.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPlot {
    /// Title above the figure.
    pub title: String,
    /// Columns and rows.
    pub size: (usize, usize),
    /// Share of visits per cell, row-major from row 0 (the bottom row of
    /// the figure is the last row), in [0, 1].
    pub visits: Vec<f64>,
    /// Every episode's cursor path, in cell centres (x, y as on the grid).
    pub runs: Vec<RunPath>,
    /// The episode drawn in full.
    pub highlight: usize,
    /// Start and goal of the highlighted episode (x, y).
    pub start: [f64; 2],
    /// Goal of the highlighted episode (x, y).
    pub goal: [f64; 2],
}

/// Height and width of a recording's figure, pixels.
const SIDE: u32 = HEIGHT;

impl Figure for ArenaPlot {
    fn width(&self) -> u32 {
        SIDE + 60
    }
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw_arena(root, self)
    }
}

impl Figure for GridPlot {
    fn width(&self) -> u32 {
        SIDE + 60
    }
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw_grid(root, self)
    }
}

/// Renders Fig. 5 of a recording as an SVG document.
pub fn arena_svg(plot: &ArenaPlot) -> Result<String, PlotError> {
    render_svg(plot)
}

/// Renders Fig. 5 of a recording as a PNG file.
pub fn arena_png(plot: &ArenaPlot) -> Result<Vec<u8>, PlotError> {
    render_png(plot)
}

/// Renders Fig. 4 of a recording as an SVG document.
pub fn grid_svg(plot: &GridPlot) -> Result<String, PlotError> {
    render_svg(plot)
}

/// Renders Fig. 4 of a recording as a PNG file.
pub fn grid_png(plot: &GridPlot) -> Result<Vec<u8>, PlotError> {
    render_png(plot)
}

const PATH_BLUE: RGBColor = RGBColor(40, 90, 200);
const MARK_RED: RGBColor = RGBColor(215, 30, 30);

fn square_chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    desc: &str,
) -> Result<Chart<'a, DB>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .margin_right(16)
        .x_label_area_size(40)
        .y_label_area_size(48)
        .build_cartesian_2d(x, y)
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .axis_style(BLACK.mix(0.8))
        .x_labels(5)
        .y_labels(5)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(font(TICK_SIZE - 2.0))
        .axis_desc_style(font(AXIS_DESC_SIZE - 2.0))
        .x_desc(desc)
        .draw()
        .map_err(draw_error)?;
    Ok(chart)
}

fn draw_paths<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    runs: &[RunPath],
    highlight: usize,
    width: u32,
) -> Result<(), PlotError> {
    for (k, run) in runs.iter().enumerate() {
        if k == highlight {
            continue;
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                run.points.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>(),
                PATH_BLUE.mix(0.18).stroke_width(1),
            )))
            .map_err(draw_error)?;
    }
    if let Some(run) = runs.get(highlight) {
        chart
            .draw_series(std::iter::once(PathElement::new(
                run.points.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>(),
                PATH_BLUE.stroke_width(width),
            )))
            .map_err(draw_error)?;
        chart
            .draw_series(
                run.detections
                    .iter()
                    .map(|p| Cross::new((p[0], p[1]), 6, MARK_RED.stroke_width(3))),
            )
            .map_err(draw_error)?;
    }
    Ok(())
}

fn draw_arena<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &ArenaPlot,
) -> Result<(), PlotError> {
    let body = titled(root, &plot.title)?;
    let s = plot.size_cm;
    let mut chart = square_chart(&body, 0.0..s, 0.0..s, "cm")?;
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(0.0, 0.0), (s, 0.0), (s, s), (0.0, s), (0.0, 0.0)],
            BLACK.mix(0.7).stroke_width(2),
        )))
        .map_err(draw_error)?;
    for o in &plot.obstacles {
        let mut ring: Vec<(f64, f64)> = o.iter().map(|p| (p[0], p[1])).collect();
        if let Some(&first) = ring.first() {
            ring.push(first);
        }
        chart
            .draw_series(std::iter::once(Polygon::new(
                ring.clone(),
                RGBColor(110, 80, 50).mix(0.35).filled(),
            )))
            .map_err(draw_error)?;
    }
    // The cities: a grey disc each, the goal ringed in green, names below.
    for (k, (name, p)) in plot.cities.iter().enumerate() {
        let goal = k == plot.goal;
        chart
            .draw_series(std::iter::once(Circle::new(
                (p[0], p[1]),
                if goal { 9 } else { 6 },
                if goal {
                    RGBColor(30, 150, 60).filled()
                } else {
                    RGBColor(150, 150, 150).filled()
                },
            )))
            .map_err(draw_error)?;
        chart
            .draw_series(std::iter::once(Text::new(
                name.clone(),
                (p[0], p[1] - 0.045 * s),
                font(11.0).pos(Pos::new(HPos::Center, VPos::Center)),
            )))
            .map_err(draw_error)?;
    }
    draw_paths(&mut chart, &plot.runs, plot.highlight, 2)?;
    if let Some(first) = plot.runs.get(plot.highlight).and_then(|r| r.points.first()) {
        chart
            .draw_series(std::iter::once(TriangleMarker::new(
                (first[0], first[1]),
                9,
                BLACK.filled(),
            )))
            .map_err(draw_error)?;
    }
    Ok(())
}

fn draw_grid<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &GridPlot,
) -> Result<(), PlotError> {
    let body = titled(root, &plot.title)?;
    let (w, h) = (plot.size.0 as f64, plot.size.1 as f64);
    let mut chart = square_chart(&body, 0.0..w, 0.0..h, "visit frequency (darker: more)")?;
    for y in 0..plot.size.1 {
        for x in 0..plot.size.0 {
            let v = plot
                .visits
                .get(y * plot.size.0 + x)
                .copied()
                .unwrap_or(0.0)
                .clamp(0.0, 1.0);
            let shade = |lo: f64| (255.0 - v * (255.0 - lo)) as u8;
            // Row 0 at the top, as the grid is drawn in the paper.
            let top = h - y as f64;
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x as f64, top - 1.0), (x as f64 + 1.0, top)],
                    RGBColor(shade(20.0), shade(60.0), shade(140.0)).filled(),
                )))
                .map_err(draw_error)?;
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x as f64, top - 1.0), (x as f64 + 1.0, top)],
                    BLACK.mix(0.3).stroke_width(1),
                )))
                .map_err(draw_error)?;
        }
    }
    let flip = |p: &[f64; 2]| [p[0] + 0.5, h - p[1] - 0.5];
    let runs: Vec<RunPath> = plot
        .runs
        .iter()
        .map(|r| RunPath {
            points: r.points.iter().map(flip).collect(),
            detections: r.detections.iter().map(flip).collect(),
        })
        .collect();
    draw_paths(&mut chart, &runs, plot.highlight, 3)?;
    for (p, label, c) in [
        (flip(&plot.start), "S", RGBColor(40, 160, 40)),
        (flip(&plot.goal), "G", RGBColor(220, 40, 40)),
    ] {
        chart
            .draw_series(std::iter::once(Text::new(
                label,
                (p[0] + 0.3, p[1] + 0.3),
                font(18.0)
                    .color(&c)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            )))
            .map_err(draw_error)?;
    }
    Ok(())
}
