//! What the commands' figures share: a [`Figure`] is drawn once, generically, and written as
//! SVG text ([`svg`]) or PNG bytes ([`png()`]); all text uses an embedded typeface, so a PNG needs
//! no system font library.

use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

/// The typeface for all text (DejaVu Sans; its licence is beside it in `assets/fonts`).
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// A picture that can be drawn on any plotters backend.
pub trait Figure {
    /// Its size in pixels (SVG user units and PNG pixels alike).
    fn size(&self) -> (u32, u32);

    /// Draws it on `root`, which is white and `size()` large.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// `figure` as SVG text.
pub fn svg(figure: &impl Figure) -> Result<String, String> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, figure.size()).into_drawing_area();
        start(&root)?;
        figure.draw(&root)?;
        root.present().map_err(err)?;
    }
    Ok(text)
}

/// `figure` as PNG bytes.
pub fn png(figure: &impl Figure) -> Result<Vec<u8>, String> {
    let (width, height) = figure.size();
    let mut rgb = vec![0u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        start(&root)?;
        figure.draw(&root)?;
        root.present().map_err(err)?;
    }
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&rgb).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Registers the typeface (once per process) and paints the background.
fn start<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>) -> Result<(), String> {
    static FONTS: Once = Once::new();
    FONTS.call_once(|| {
        let parsed = register_font("sans-serif", FontStyle::Normal, FONT).is_ok();
        assert!(parsed, "the embedded font parses");
    });
    root.fill(&WHITE).map_err(err)
}

/// Text of `size` pixels in the embedded typeface.
pub fn font(size: u32) -> TextStyle<'static> {
    ("sans-serif", size).into_font().color(&BLACK)
}

/// A drawing error as text.
pub fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The whole decades around the positive `values`: `(10^floor(log min), 10^ceil(log max))`,
/// at least one decade apart; `None` when there are none.
pub fn decades(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return None;
    }
    let lo = lo.log10().floor();
    let hi = hi.log10().ceil().max(lo + 1.0);
    Some((10f64.powf(lo), 10f64.powf(hi)))
}
