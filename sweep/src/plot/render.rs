//! Any figure drawn to SVG or PNG by the same code: the drawing area, the
//! title band, the PNG encoding, the errors.

use std::sync::OnceLock;

use ab_glyph::FontRef;
use plotters::backend::RGBPixel;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::glyph_text::GlyphText;
use super::style::{FONT_BYTES, FONT_FAMILY, HEIGHT, TITLE_BAND, TITLE_SIZE, font};

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
pub(super) trait Figure {
    /// Width of the figure, pixels.
    fn width(&self) -> u32;
    /// Draws the whole figure on `root`.
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// Renders `figure` as an SVG document: text is left as `<text>` elements
/// with `font-family="sans-serif"`, so the viewer's sans-serif font sets it.
pub(super) fn render_svg(figure: &impl Figure) -> Result<String, PlotError> {
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
pub(super) fn render_png(figure: &impl Figure) -> Result<Vec<u8>, PlotError> {
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

/// Encodes RGB `pixels`, `width` wide and [`HEIGHT`] high, as a PNG file.
pub(super) fn encode_png(pixels: &[u8], width: u32) -> Result<Vec<u8>, PlotError> {
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
pub(super) fn register_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// Maps any plotters drawing error to [`PlotError::Draw`].
pub(super) fn draw_error(e: impl std::fmt::Display) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// Clears `root` to white and sets `title` in its top band; the area below
/// it, for the panels.
pub(super) fn titled<DB: DrawingBackend>(
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
