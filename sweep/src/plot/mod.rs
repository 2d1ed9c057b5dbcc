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

mod fit;
mod glyph_text;
mod legend;
mod panels;
mod recording;
mod series;

use glyph_text::*;

/// A point from the paper to overlay on the cost panel (Table 1 subjects, or
/// the paper's e-puck runs).
pub use errp_sim::task::PaperPoint;
pub use fit::{Curve, CurvePoint, FitPanel, FitPlot, fit_png, fit_svg};
use legend::*;
use panels::*;
pub use recording::{ArenaPlot, GridPlot, RunPath, arena_png, arena_svg, grid_png, grid_svg};
use series::*;

/// DejaVu Sans (Bitstream Vera licence), used for every piece of text.
static FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

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

/// Something drawn on one drawing area, `width()` by [`HEIGHT`] pixels,
/// by the same code for the SVG and the PNG.
trait Figure {
    /// Width of the figure, pixels.
    fn width(&self) -> u32;
    /// Draws the whole figure on `root`.
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

impl Figure for SweepPlot {
    fn width(&self) -> u32 {
        WIDTH
    }
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw(root, self)
    }
}

/// Renders `figure` as an SVG document: text is left as `<text>` elements
/// with `font-family="sans-serif"`, so the viewer's sans-serif font sets it.
fn render_svg(figure: &impl Figure) -> Result<String, PlotError> {
    register_font()?;
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (figure.width(), HEIGHT)).into_drawing_area();
        figure.draw_on(&root)?;
        root.present().map_err(draw_error)?;
    }
    Ok(out)
}

/// Renders `figure` as a PNG file (8-bit RGB), text set in the embedded
/// DejaVu Sans by this module (`GlyphText`) rather than by plotters' own
/// `ab_glyph` renderer, which drops each glyph's left side bearing and so
/// spaces letters unevenly.
fn render_png(figure: &impl Figure) -> Result<Vec<u8>, PlotError> {
    register_font()?;
    let width = figure.width();
    let mut pixels = vec![0u8; width as usize * HEIGHT as usize * 3];
    {
        let bitmap =
            BitMapBackend::<RGBPixel>::with_buffer_and_format(&mut pixels, (width, HEIGHT))
                .map_err(draw_error)?;
        let font = FontRef::try_from_slice(FONT_BYTES).map_err(|_| PlotError::Font)?;
        let root = GlyphText {
            inner: bitmap,
            font,
        }
        .into_drawing_area();
        figure.draw_on(&root)?;
        root.present().map_err(draw_error)?;
    }
    encode_png(&pixels, width)
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

/// Encodes RGB `pixels`, `width` wide and [`HEIGHT`] high, as a PNG file.
fn encode_png(pixels: &[u8], width: u32) -> Result<Vec<u8>, PlotError> {
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width, HEIGHT);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(pixels)?;
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

/// Clears `root` to white and sets `title` in its top band; the area below
/// it, for the panels.
fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    root.fill(&WHITE).map_err(draw_error)?;
    let (title_area, body) = root.split_vertically(TITLE_BAND);
    let (w, h) = title_area.dim_in_pixel();
    title_area
        .draw_text(
            title,
            &font(TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Center)),
            (w as i32 / 2, h as i32 / 2 + 2),
        )
        .map_err(draw_error)?;
    Ok(body)
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
