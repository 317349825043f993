//! Figures: line-and-marker charts on log-log or linear axes (PNG and SVG) and micrographs with
//! contact edges.
//!
//! Everything here returns bytes or text; writing files (atomically) is the caller's job.
//!
//! Text is drawn with the bundled DejaVu Sans (`assets/DejaVuSans.ttf`, embedded at compile time)
//! so that plots render identically on machines without system fonts, including glyphs such as
//! `µ` and `²` in axis labels.
//!
//! Non-finite values are never drawn, and log axes cannot show zero or negative values either:
//! such points are skipped, and a chart with nothing left to draw is an [`Error::Plot`].

mod chart;
mod legend;
mod panels;

use std::io::Cursor;

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use crate::error::{Error, Result};

pub use chart::{Axes, Chart, Curve, PointSet};
pub use legend::Legend;
pub use panels::{edge_panels_png, overlay_png, thumbnail_png, Pixels};

fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let mut png = Vec::new();
    PngEncoder::new(Cursor::new(&mut png))
        .write_image(rgb, width, height, ExtendedColorType::Rgb8)
        .map_err(|e| Error::Plot(format!("PNG encoding failed: {e}")))?;
    Ok(png)
}

fn plot_err(e: impl std::fmt::Display) -> Error {
    Error::Plot(e.to_string())
}
