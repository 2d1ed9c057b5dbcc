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

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, ScaleFont, point};
use plotters::backend::RGBPixel;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::element::{Drawable, MultiLineText, PointCollection};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters_backend::{BackendColor, BackendCoord, DrawingErrorKind, FontTransform};

/// DejaVu Sans (Bitstream Vera licence), used for every piece of text.
static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The font family name the text styles ask for, and that the SVG's text
/// elements carry.
const FONT_FAMILY: &str = "sans-serif";

/// Width of the figure, pixels.
const WIDTH: u32 = 1200;
/// Height of the figure, pixels.
const HEIGHT: u32 = 520;
/// Height of the band holding the figure's title, pixels.
const TITLE_BAND: u32 = 40;

/// Font sizes, in plotters' units (the line height in pixels for the PNG;
/// the SVG's `font-size` is plotters' 1/1.24 of it).
const TITLE_SIZE: f64 = 22.0;
/// Panel captions.
const CAPTION_SIZE: f64 = 18.0;
/// Axis descriptions.
const AXIS_DESC_SIZE: f64 = 18.0;
/// Tick labels.
const TICK_SIZE: f64 = 16.0;
/// Legend entries.
const LEGEND_SIZE: f64 = 16.0;

/// Inner margin of a legend box, pixels (plotters' default).
const LEGEND_MARGIN: i32 = 10;
/// Width reserved for a legend's glyph, pixels (plotters' default).
const LEGEND_GLYPH: i32 = 30;

/// Series colours, cycled: the Tableau 10 palette less its grey.
const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colour of the paper's points.
const PAPER_COLOUR: RGBColor = RGBColor(0, 0, 0);

/// One point of a sweep series: one level of decoder accuracy.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelPoint {
    /// x: the decoder's mean accuracy at this level (0.5..1).
    pub accuracy: f64,
    /// Fraction of episodes that converged on the user's goal, 0..1.
    pub success_rate: f64,
    /// Lower end of the 95% Wilson interval of the success rate.
    pub success_lo: f64,
    /// Upper end of the 95% Wilson interval of the success rate.
    pub success_hi: f64,
    /// Mean cost (actions or seconds) over successful episodes; NaN if none,
    /// and the point is then left out of the cost panel.
    pub mean: f64,
    /// Standard deviation of the cost over successful episodes (NaN if none).
    pub sd: f64,
    /// Median cost over successful episodes (NaN if none).
    pub median: f64,
    /// Episodes at this level.
    pub n: usize,
}

/// A line: one combination of the swept parameters (e.g. "strategy=greedy",
/// "tau=0.3", or "" when only accuracy is swept).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry; an empty label draws the series without a legend entry.
    pub label: String,
    /// The levels, in any order (they are drawn sorted by accuracy).
    pub points: Vec<LevelPoint>,
}

/// A point from the paper to overlay on the cost panel (Table 1 subjects, or
/// the paper's e-puck runs).
#[derive(Debug, Clone, PartialEq)]
pub struct PaperPoint {
    /// What the point is (e.g. "S1, goal set A"); not drawn, all paper points
    /// share the one legend entry [`SweepPlot::paper_label`].
    pub label: String,
    /// The decoder accuracy the paper reports.
    pub accuracy: f64,
    /// The cost the paper reports, in the unit of [`SweepPlot::cost_label`].
    pub value: f64,
    /// Its standard deviation, drawn as an error bar when given.
    pub sd: Option<f64>,
}

/// Everything one sweep figure shows.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPlot {
    /// Title over the figure, e.g. "Grid task, 11 levels x 200 episodes,
    /// EEG decoder (bank), seed 1".
    pub title: String,
    /// What the cost is, e.g. "actions to convergence" or "time to
    /// convergence (s)": the right panel's y axis.
    pub cost_label: String,
    /// The lines, one per combination of the swept parameters.
    pub series: Vec<Series>,
    /// The paper's results, overlaid on the cost panel.
    pub paper: Vec<PaperPoint>,
    /// Legend entry of the paper's points, e.g. "paper, Table 1 (4 subjects x
    /// 2 goal sets)".
    pub paper_label: String,
}

/// Why a figure could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The embedded font could not be parsed or registered.
    #[error("the embedded font could not be registered with plotters")]
    Font,
    /// The drawing backend failed.
    #[error("drawing the figure failed: {0}")]
    Draw(String),
    /// The rendered bitmap could not be encoded as PNG.
    #[error("encoding the PNG failed: {0}")]
    Png(#[from] png::EncodingError),
}

/// Renders the figure as an SVG document.
///
/// Text is left as `<text>` elements with `font-family="sans-serif"`, so the
/// viewer's sans-serif font sets it.
pub fn svg(plot: &SweepPlot) -> Result<String, PlotError> {
    register_font()?;
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (WIDTH, HEIGHT)).into_drawing_area();
        draw(&root, plot)?;
        root.present().map_err(draw_error)?;
    }
    Ok(out)
}

/// Renders the figure as a PNG file (8-bit RGB), text set in the embedded
/// DejaVu Sans.
///
/// Text is rasterised by this module (`GlyphText`) rather than by plotters' own
/// `ab_glyph` renderer, which drops each glyph's left side bearing and so
/// spaces letters unevenly.
pub fn png(plot: &SweepPlot) -> Result<Vec<u8>, PlotError> {
    register_font()?;
    let mut pixels = vec![0u8; WIDTH as usize * HEIGHT as usize * 3];
    {
        let bitmap =
            BitMapBackend::<RGBPixel>::with_buffer_and_format(&mut pixels, (WIDTH, HEIGHT))
                .map_err(draw_error)?;
        let font = FontRef::try_from_slice(FONT_BYTES).map_err(|_| PlotError::Font)?;
        let root = GlyphText {
            inner: bitmap,
            font,
        }
        .into_drawing_area();
        draw(&root, plot)?;
        root.present().map_err(draw_error)?;
    }
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, WIDTH, HEIGHT);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&pixels)?;
        writer.finish()?;
    }
    Ok(out)
}

/// Registers the embedded font as `"sans-serif"`, once per process.
fn register_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// Maps any plotters drawing error to [`PlotError::Draw`].
fn draw_error(e: impl std::fmt::Display) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// A text style in the embedded font.
fn font(size: f64) -> TextStyle<'static> {
    (FONT_FAMILY, size).into_font().color(&BLACK)
}

/// Colour of the `i`th series.
fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Draws the whole figure on `root`.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &SweepPlot,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(draw_error)?;
    let (title_area, body) = root.split_vertically(TITLE_BAND);
    let (w, h) = title_area.dim_in_pixel();
    title_area
        .draw_text(
            &plot.title,
            &font(TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Center)),
            (w as i32 / 2, h as i32 / 2 + 2),
        )
        .map_err(draw_error)?;

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

/// A panel's chart type: accuracy against a real-valued y.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Builds a panel's axes, grid and labels.
fn panel<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    x_range: std::ops::Range<f64>,
    y_range: std::ops::Range<f64>,
    y_desc: &str,
    y_format: &dyn Fn(&f64) -> String,
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
        .x_label_formatter(&|x| format!("{x:.1}"))
        .y_label_formatter(y_format)
        .label_style(font(TICK_SIZE))
        .axis_desc_style(font(AXIS_DESC_SIZE))
        .x_desc("decoder accuracy (mean of per-class rates)")
        .y_desc(y_desc)
        .draw()
        .map_err(draw_error)?;
    Ok(chart)
}

/// Left panel: success rate with its Wilson interval.
fn draw_success_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: &SweepPlot,
    x_range: std::ops::Range<f64>,
) -> Result<(), PlotError> {
    let mut chart = panel(
        area,
        "Success rate (95% Wilson interval)",
        x_range,
        -0.02..1.04,
        "success rate",
        &|y| format!("{y:.1}"),
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
fn draw_cost_panel<DB: DrawingBackend>(
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
        &plot.cost_label,
        &|y| format_tick(*y),
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

/// The non-empty legend entries of a panel: the series' labels, then the
/// paper's if `with_paper`.
fn legend_labels(plot: &SweepPlot, with_paper: bool) -> Vec<&str> {
    let series = plot.series.iter().map(|s| s.label.as_str());
    let paper = with_paper.then_some(plot.paper_label.as_str());
    series.chain(paper).filter(|l| !l.is_empty()).collect()
}

/// A point with a vertical error bar, in data coordinates.
#[derive(Debug, Clone, Copy)]
struct Bar {
    x: f64,
    y: f64,
    lo: f64,
    hi: f64,
}

/// The points of a series sorted by accuracy.
fn sorted(points: &[LevelPoint]) -> impl Iterator<Item = &LevelPoint> {
    let mut v: Vec<&LevelPoint> = points.iter().collect();
    v.sort_by(|a, b| a.accuracy.total_cmp(&b.accuracy));
    v.into_iter()
}

/// Marker shapes, cycled over the series so that they differ in more than
/// colour.
#[derive(Debug, Clone, Copy)]
enum Marker {
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
struct MarkerElement<C> {
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
fn draw_series<'a, DB: DrawingBackend + 'a>(
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
fn draw_paper<'a, DB: DrawingBackend + 'a>(
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
fn draw_error_bars<'a, DB: DrawingBackend + 'a>(
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
fn dodge(i: usize, count: usize) -> i32 {
    if count < 2 {
        return 0;
    }
    let spacing = (12.0 / (count - 1) as f64).min(4.0);
    ((i as f64 - (count - 1) as f64 / 2.0) * spacing).round() as i32
}

/// Records the backend pixels covered by the markers, error bars and line
/// segments of `bars`, for choosing where the legend goes.
fn record_obstacles<'a, DB: DrawingBackend + 'a>(
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

/// The corners a legend may go in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LegendCorner {
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
fn draw_legend<'a, DB: DrawingBackend + 'a>(
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

/// The smallest of 1, 2, 2.5, 5 times a power of ten that is at least `v`
/// (`v` > 0).
fn nice_step(v: f64) -> f64 {
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 2.5, 5.0]
        .into_iter()
        .map(|m| m * p)
        .find(|c| *c >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// A y tick label: integers without decimals, else up to two.
fn format_tick(y: f64) -> String {
    if (y - y.round()).abs() < 1e-9 {
        format!("{y:.0}")
    } else {
        let s = format!("{y:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// A bitmap backend that sets text itself with `ab_glyph`, glyph by glyph at
/// its advance, kerning and side bearing; everything else goes to `inner`.
///
/// The text's box is its advance width by the font's line height (ascent to
/// descent) at the requested pixel size, anchored as plotters anchors it;
/// rotations by quarter turns are honoured. Every style is set in the one
/// embedded font.
struct GlyphText<B> {
    inner: B,
    font: FontRef<'static>,
}

impl<B: DrawingBackend> DrawingBackend for GlyphText<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: plotters_backend::BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: plotters_backend::BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: plotters_backend::BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }

    fn draw_circle<S: plotters_backend::BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: plotters_backend::BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: plotters_backend::BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let font = self.font.as_scaled(style.size() as f32);
        // Lay the glyphs out along a baseline `ascent` below the box's top.
        let ascent = font.ascent();
        let mut caret = 0.0f32;
        let mut prev = None;
        let mut glyphs = Vec::with_capacity(text.len());
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                caret += font.kern(p, id);
            }
            glyphs.push(id.with_scale_and_position(font.scale(), point(caret, ascent)));
            caret += font.h_advance(id);
            prev = Some(id);
        }
        let width = caret.round() as i32;
        let height = (ascent - font.descent()).round() as i32;
        let anchor = style.anchor();
        let dx = match anchor.h_pos {
            HPos::Left => 0,
            HPos::Center => -width / 2,
            HPos::Right => -width,
        };
        let dy = match anchor.v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let transform: FontTransform = style.transform();
        let (w, h) = self.get_size();
        for glyph in glyphs {
            let Some(outline) = self.font.outline_glyph(glyph) else {
                continue;
            };
            let bounds = outline.px_bounds();
            let (x0, y0) = (bounds.min.x as i32, bounds.min.y as i32);
            let mut coverage = Vec::new();
            outline.draw(|x, y, c| coverage.push((x as i32, y as i32, c)));
            for (x, y, c) in coverage {
                if c <= 0.0 {
                    continue;
                }
                let (tx, ty) = transform.transform(x0 + x + dx, y0 + y + dy);
                let (px, py) = (pos.0 + tx, pos.1 + ty);
                if px >= 0 && py >= 0 && px < w as i32 && py < h as i32 {
                    let alpha = color.alpha * f64::from(c.min(1.0));
                    self.inner.draw_pixel(
                        (px, py),
                        BackendColor {
                            alpha,
                            rgb: color.rgb,
                        },
                    )?;
                }
            }
        }
        Ok(())
    }

    fn estimate_text_size<S: plotters_backend::BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        self.inner.estimate_text_size(text, style)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
