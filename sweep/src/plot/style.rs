//! How every figure looks: the embedded font, the sizes, the colours.

use plotters::prelude::*;

/// DejaVu Sans (Bitstream Vera licence), used for every piece of text.
pub(super) static FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// The font family name the text styles ask for, and that the SVG's text
/// elements carry.
pub(super) const FONT_FAMILY: &str = "sans-serif";

/// Width of the figure, pixels.
pub(super) const WIDTH: u32 = 1200;

/// Height of the figure, pixels.
pub(super) const HEIGHT: u32 = 520;

/// Height of the band holding the figure's title, pixels.
pub(super) const TITLE_BAND: u32 = 40;

/// Font sizes, in plotters' units (the line height in pixels for the PNG;
/// the SVG's `font-size` is plotters' 1/1.24 of it).
pub(super) const TITLE_SIZE: f64 = 22.0;

/// Panel captions.
pub(super) const CAPTION_SIZE: f64 = 18.0;

/// Axis descriptions.
pub(super) const AXIS_DESC_SIZE: f64 = 18.0;

/// Tick labels.
pub(super) const TICK_SIZE: f64 = 16.0;

/// Legend entries.
pub(super) const LEGEND_SIZE: f64 = 16.0;

/// Inner margin of a legend box, pixels (plotters' default).
pub(super) const LEGEND_MARGIN: i32 = 10;

/// Width reserved for a legend's glyph, pixels (plotters' default).
pub(super) const LEGEND_GLYPH: i32 = 30;

/// Series colours, cycled: the Tableau 10 palette less its grey.
pub(super) const PALETTE: [RGBColor; 9] = [
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
pub(super) const PAPER_COLOUR: RGBColor = RGBColor(0, 0, 0);

/// A text style in the embedded font.
pub(super) fn font(size: f64) -> TextStyle<'static> {
    (FONT_FAMILY, size).into_font().color(&BLACK)
}

/// Colour of the `i`th series.
pub(super) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}
