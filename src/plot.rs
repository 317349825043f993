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

use std::io::Cursor;
use std::sync::OnceLock;

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle, Palette, Palette99};

use crate::error::{Error, Result};

/// Size of [`Chart`] images in pixels.
const PLOT_SIZE: (u32, u32) = (900, 650);

/// Registered font name. It doubles as the SVG `font-family` attribute, so it is a CSS font
/// list: viewers without DejaVu Sans fall back to another sans-serif face rather than to serif.
const FONT: &str = "DejaVu Sans, sans-serif";

static FONT_BYTES: &[u8] = include_bytes!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/DejaVuSans.ttf"
));

/// Colour-blind-safe colours (Okabe & Ito) for the first series; yellow is left out because it
/// is unreadable on white.
const COLOURS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// Pure green for contact edges, as in Fig. 2a of Weber et al. 2018.
const EDGE_GREEN: [u8; 3] = [0, 255, 0];

/// Upper bound on overlay output pixels, so that an absurd `scale` becomes an error instead of
/// an allocation failure (which aborts the process).
const MAX_OVERLAY_PIXELS: usize = 1 << 28;

/// One set of measured points (drawn as markers).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointSet {
    /// Legend label.
    pub label: String,
    /// Data points `(x, y)`; non-positive or non-finite points are skipped.
    pub xy: Vec<(f64, f64)>,
}

/// One curve (drawn as a line), e.g. a fit evaluated on a grid.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// Vertices `(x, y)` in drawing order; the line is broken where a vertex is skipped
    /// (non-positive or non-finite), rather than bridging the gap.
    pub xy: Vec<(f64, f64)>,
}

/// Axis scales of a [`Chart`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Axes {
    /// Both axes logarithmic (area–load curves, power laws).
    #[default]
    LogLog,
    /// Both axes linear (profiles, autocorrelations).
    Linear,
}

impl Axes {
    fn shows(self, (x, y): (f64, f64)) -> bool {
        x.is_finite() && y.is_finite() && (self == Axes::Linear || (x > 0.0 && y > 0.0))
    }
}

/// Corner of a [`Chart`]'s legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// Top left (default; suits rising curves).
    #[default]
    UpperLeft,
    /// Top right (suits decaying curves).
    UpperRight,
}

/// A chart: title, axis labels with units, point sets and curves; the legend shows all
/// non-empty labels.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Chart {
    /// Title above the chart.
    pub title: String,
    /// Description of the x axis, with unit, e.g. `"normal force F (mN)"`.
    pub x_label: String,
    /// Description of the y axis, with unit, e.g. `"contact area A (µm²)"`.
    pub y_label: String,
    /// Log-log (default) or linear axes.
    pub axes: Axes,
    /// Corner of the legend, chosen where the data leaves room.
    pub legend: Legend,
    /// Measured points, drawn as filled circles.
    pub points: Vec<PointSet>,
    /// Curves, drawn as 2 px solid lines.
    pub curves: Vec<Curve>,
}

/// What is left of a [`Chart`] after dropping points that log axes cannot show.
struct Prepared {
    points: Vec<Vec<(f64, f64)>>,
    /// Per curve, its unbroken runs of drawable vertices.
    curves: Vec<Vec<Vec<(f64, f64)>>>,
    x_range: (f64, f64),
    y_range: (f64, f64),
}

impl Chart {
    /// PNG bytes (RGB8), 900×650 px.
    ///
    /// Errors with [`Error::Plot`] if no point or curve vertex is positive and finite, or if
    /// drawing or encoding fails.
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let data = self.prepare()?;
        let (w, h) = PLOT_SIZE;
        let mut rgb = vec![0u8; w as usize * h as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, PLOT_SIZE).into_drawing_area();
            self.render(&root, &data)?;
            root.present().map_err(plot_err)?;
        }
        encode_png(&rgb, w, h)
    }

    /// SVG document text, with the same layout as [`Chart::to_png`].
    ///
    /// Errors as [`Chart::to_png`] does.
    pub fn to_svg(&self) -> Result<String> {
        let data = self.prepare()?;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, PLOT_SIZE).into_drawing_area();
            self.render(&root, &data)?;
            root.present().map_err(plot_err)?;
        }
        Ok(svg)
    }

    fn prepare(&self) -> Result<Prepared> {
        let shows = |p: &(f64, f64)| self.axes.shows(*p);
        let points: Vec<Vec<(f64, f64)>> = self
            .points
            .iter()
            .map(|set| set.xy.iter().copied().filter(shows).collect())
            .collect();
        let curves: Vec<Vec<Vec<(f64, f64)>>> = self
            .curves
            .iter()
            .map(|c| drawable_runs(&c.xy, self.axes))
            .collect();
        let all = points
            .iter()
            .flatten()
            .chain(curves.iter().flatten().flatten());
        let (x_range, y_range) = padded_ranges(all, self.axes)?;
        Ok(Prepared {
            points,
            curves,
            x_range,
            y_range,
        })
    }

    fn render<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        data: &Prepared,
    ) -> Result<()> {
        ensure_font()?;
        root.fill(&WHITE).map_err(plot_err)?;
        let (x0, x1) = data.x_range;
        let (y0, y1) = data.y_range;
        let mut builder = ChartBuilder::on(root);
        builder
            .caption(&self.title, (FONT, 24))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(80);
        match self.axes {
            Axes::LogLog => {
                let chart = builder
                    .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                    .map_err(plot_err)?;
                self.draw(chart, data)
            }
            Axes::Linear => {
                let chart = builder
                    .build_cartesian_2d(x0..x1, y0..y1)
                    .map_err(plot_err)?;
                self.draw(chart, data)
            }
        }
    }

    /// Mesh, series and legend on a chart with either axis type.
    fn draw<'a, DB, X, Y>(
        &self,
        mut chart: ChartContext<'a, DB, Cartesian2d<X, Y>>,
        data: &Prepared,
    ) -> Result<()>
    where
        DB: DrawingBackend + 'a,
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 18))
            .x_label_formatter(&|v| tick_label(snap_zero(*v, data.x_range)))
            .y_label_formatter(&|v| tick_label(snap_zero(*v, data.y_range)))
            .draw()
            .map_err(plot_err)?;

        let mut labelled = false;
        for (i, (set, xy)) in self.points.iter().zip(&data.points).enumerate() {
            let colour = series_colour(i);
            let series = chart
                .draw_series(xy.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(plot_err)?;
            if !set.label.is_empty() {
                labelled = true;
                series
                    .label(set.label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
            }
        }
        for (j, (curve, runs)) in self.curves.iter().zip(&data.curves).enumerate() {
            let style = series_colour(self.points.len() + j).stroke_width(2);
            let series = chart
                .draw_series(runs.iter().map(|run| PathElement::new(run.clone(), style)))
                .map_err(plot_err)?;
            if !curve.label.is_empty() {
                labelled = true;
                series
                    .label(curve.label.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            }
        }

        if labelled {
            chart
                .configure_series_labels()
                .position(match self.legend {
                    Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
                    Legend::UpperRight => SeriesLabelPosition::UpperRight,
                })
                .background_style(WHITE)
                .border_style(BLACK)
                .label_font((FONT, 15))
                .draw()
                .map_err(plot_err)?;
        }
        Ok(())
    }
}

/// Micrograph with contact edges in green, as in Fig. 2a of Weber et al. 2018; PNG bytes (RGB8).
///
/// `values` and `mask` are row-major, `height` rows of `width` (`true` = contact). Grey levels
/// are stretched between the 0.5th and 99.5th percentiles of the finite values (min..max if
/// those coincide, mid-grey if all values are equal); NaN and infinite pixels are black.
///
/// An edge pixel is a contact pixel with at least one 4-neighbour that is not contact; pixels
/// outside the image do not count as non-contact. Edge pixels are pure green (0, 255, 0).
/// Each pixel becomes a `scale`×`scale` block (nearest neighbour), edge pixels included: whole
/// green blocks stand out far better than 1-pixel lines at large scales, and the picture stays
/// the `scale == 1` overlay magnified, so every green block is exactly one edge pixel.
///
/// Errors with [`Error::Plot`] on zero sizes or `scale`, lengths that do not match
/// `width × height`, or an output that would be unreasonably large (over 2²⁸ pixels).
pub fn overlay_png(
    values: &[f64],
    width: usize,
    height: usize,
    mask: &[bool],
    scale: usize,
) -> Result<Vec<u8>> {
    edge_panels_png(&[values], width, height, mask, scale)
}

/// Several images of one scene side by side (left to right, 2 white pixels apart before
/// scaling), each with the same contact edges in green, as in Fig. 2 of Weber et al. 2018
/// (micrograph, then simulations). All panels share the grey scale of the first one, so a
/// simulated image put on the micrograph's intensity scale looks comparable; otherwise as
/// [`overlay_png`], which is the one-panel case.
pub fn edge_panels_png(
    panels: &[&[f64]],
    width: usize,
    height: usize,
    mask: &[bool],
    scale: usize,
) -> Result<Vec<u8>> {
    let Some(first) = panels.first() else {
        return Err(Error::Plot("no panels to draw".into()));
    };
    for p in panels {
        overlay_size(p.len(), width, height, mask.len(), scale)?;
    }
    let gap = if panels.len() > 1 { 2 * scale } else { 0 };
    let panel_w = width * scale;
    let total_w = panels.len() * panel_w + (panels.len() - 1) * gap;
    let out_h = height * scale;
    if total_w
        .checked_mul(out_h)
        .is_none_or(|n| n > MAX_OVERLAY_PIXELS)
    {
        return Err(Error::Plot(format!(
            "{} panels of {width}×{height} at scale {scale} exceed {MAX_OVERLAY_PIXELS} pixels",
            panels.len()
        )));
    }
    let range = stretch_range(first);
    let greys: Vec<Vec<u8>> = panels.iter().map(|p| grey_levels(p, range)).collect();
    let mut rgb = Vec::with_capacity(total_w * out_h * 3);
    let mut row = Vec::with_capacity(total_w * 3);
    for y in 0..height {
        row.clear();
        for (k, grey) in greys.iter().enumerate() {
            if k > 0 {
                row.extend(std::iter::repeat_n(255u8, gap * 3));
            }
            for x in 0..width {
                let colour = if is_edge(mask, width, height, x, y) {
                    EDGE_GREEN
                } else {
                    [grey[y * width + x]; 3]
                };
                for _ in 0..scale {
                    row.extend_from_slice(&colour);
                }
            }
        }
        for _ in 0..scale {
            rgb.extend_from_slice(&row);
        }
    }
    let dim = |n: usize| u32::try_from(n).map_err(|_| Error::Plot("overlay too large".into()));
    encode_png(&rgb, dim(total_w)?, dim(out_h)?)
}

/// Checks the overlay inputs; returns the output size in pixels.
fn overlay_size(
    n_values: usize,
    width: usize,
    height: usize,
    n_mask: usize,
    scale: usize,
) -> Result<(usize, usize)> {
    if width == 0 || height == 0 || scale == 0 {
        return Err(Error::Plot(format!(
            "overlay needs non-zero sizes, got {width}×{height} at scale {scale}"
        )));
    }
    let n = width
        .checked_mul(height)
        .ok_or_else(|| Error::Plot(format!("overlay size {width}×{height} overflows")))?;
    if n_values != n || n_mask != n {
        return Err(Error::Plot(format!(
            "overlay of {width}×{height} = {n} pixels got {n_values} values and {n_mask} mask entries"
        )));
    }
    let out = (width.checked_mul(scale), height.checked_mul(scale));
    match out {
        (Some(w), Some(h)) if w.checked_mul(h).is_some_and(|p| p <= MAX_OVERLAY_PIXELS) => {
            Ok((w, h))
        }
        _ => Err(Error::Plot(format!(
            "overlay of {width}×{height} at scale {scale} exceeds {MAX_OVERLAY_PIXELS} pixels"
        ))),
    }
}

/// Whether contact pixel `(x, y)` has a non-contact 4-neighbour inside the image.
fn is_edge(mask: &[bool], width: usize, height: usize, x: usize, y: usize) -> bool {
    let not_contact = |x: usize, y: usize| !mask[y * width + x];
    mask[y * width + x]
        && ((x > 0 && not_contact(x - 1, y))
            || (x + 1 < width && not_contact(x + 1, y))
            || (y > 0 && not_contact(x, y - 1))
            || (y + 1 < height && not_contact(x, y + 1)))
}

/// Grey-scale limits of an image: its 0.5th and 99.5th percentiles of the finite values (min and
/// max if those coincide); `None` without finite values.
fn stretch_range(values: &[f64]) -> Option<(f64, f64)> {
    let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    finite.sort_unstable_by(f64::total_cmp);
    let (&min, &max) = finite.first().zip(finite.last())?;
    let (lo, hi) = (percentile(&finite, 0.005), percentile(&finite, 0.995));
    Some(if lo < hi { (lo, hi) } else { (min, max) })
}

/// Contrast-stretched 8-bit grey level per pixel between `range`; non-finite values become 0
/// (black), everything is mid-grey when the range is empty.
fn grey_levels(values: &[f64], range: Option<(f64, f64)>) -> Vec<u8> {
    let Some((lo, hi)) = range else {
        return vec![0; values.len()];
    };
    values
        .iter()
        .map(|&v| match v {
            v if !v.is_finite() => 0,
            _ if lo >= hi => 128,
            // The clamp keeps the cast in 0..=255.
            v => (255.0 * (v.clamp(lo, hi) - lo) / (hi - lo)).round() as u8,
        })
        .collect()
}

/// Linearly interpolated percentile `p` (0..=1) of sorted, non-empty `sorted`.
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let pos = p * (sorted.len() - 1) as f64;
    let (i, frac) = (pos.floor() as usize, pos.fract());
    match sorted.get(i + 1) {
        Some(&next) => sorted[i] + frac * (next - sorted[i]),
        None => sorted[i],
    }
}

/// Splits a polyline into runs of vertices the axes can show, dropping runs that are empty.
fn drawable_runs(xy: &[(f64, f64)], axes: Axes) -> Vec<Vec<(f64, f64)>> {
    xy.split(|&p| !axes.shows(p))
        .filter(|run| !run.is_empty())
        .map(<[_]>::to_vec)
        .collect()
}

/// `(x_min, x_max), (y_min, y_max)` of a chart.
type Ranges = ((f64, f64), (f64, f64));

/// Axis ranges covering all points, padded so that markers are not cut by the frame.
fn padded_ranges<'a>(points: impl Iterator<Item = &'a (f64, f64)>, axes: Axes) -> Result<Ranges> {
    let mut bounds: Option<[f64; 4]> = None;
    for &(x, y) in points {
        let b = bounds.get_or_insert([x, x, y, y]);
        *b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
    }
    let [x0, x1, y0, y1] = bounds.ok_or_else(|| {
        Error::Plot(match axes {
            Axes::LogLog => "no positive data to plot on log axes".into(),
            Axes::Linear => "no finite data to plot".into(),
        })
    })?;
    let pad = match axes {
        Axes::LogLog => pad_log,
        Axes::Linear => pad_linear,
    };
    Ok((pad(x0, x1)?, pad(y0, y1)?))
}

/// Pads `lo..hi` by ×0.8 / ×1.25. A range inside one decade is widened down to the power of ten
/// below it, because plotters puts log-axis ticks only from a power of ten upwards and would
/// otherwise leave the axis without any labels.
fn pad_log(lo: f64, hi: f64) -> Result<(f64, f64)> {
    let (mut a, b) = (lo * 0.8, hi * 1.25);
    let decade = 10f64.powf(a.log10().floor());
    if decade > 0.0 && decade * 10.0 > b {
        a = decade;
    }
    if a > 0.0 && b.is_finite() && a < b {
        Ok((a, b))
    } else {
        Err(Error::Plot(format!(
            "data range {lo:e}..{hi:e} cannot be shown on log axes"
        )))
    }
}

/// Pads `lo..hi` by 5 % of its span on each side; a single value gets a span of 10 % of its
/// magnitude (or ±1 at zero).
fn pad_linear(lo: f64, hi: f64) -> Result<(f64, f64)> {
    let span = hi - lo;
    let margin = if span > 0.0 {
        0.05 * span
    } else if lo != 0.0 {
        0.05 * lo.abs()
    } else {
        1.0
    };
    let (a, b) = (lo - margin, hi + margin);
    if a.is_finite() && b.is_finite() && a < b {
        Ok((a, b))
    } else {
        Err(Error::Plot(format!(
            "data range {lo:e}..{hi:e} cannot be shown on linear axes"
        )))
    }
}

/// Zero for a tick that is zero up to rounding (linear ticks are accumulated in steps, so the
/// zero tick can come out as 1e-16); other values unchanged.
fn snap_zero(v: f64, (lo, hi): (f64, f64)) -> f64 {
    if v.abs() <= 1e-9 * (hi - lo) {
        0.0
    } else {
        v
    }
}

/// Tick text without floating-point noise: plain decimals for moderate magnitudes, otherwise
/// scientific notation (e.g. `2e-5`).
fn tick_label(v: f64) -> String {
    let mag = v.abs();
    if v == 0.0 || (1e-3..1e5).contains(&mag) {
        let decimals = (-mag.log10().floor()).max(0.0) as usize;
        // Ticks sit at 1, 2, 5 × 10^k; one extra digit covers finer steps.
        let s = format!("{v:.prec$}", prec = decimals + 1);
        trim_zeros(&s)
    } else {
        let s = format!("{v:.1e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim_zeros(m)),
            None => s,
        }
    }
}

fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

fn series_colour(i: usize) -> RGBColor {
    COLOURS.get(i).copied().unwrap_or_else(|| {
        let (r, g, b) = Palette99::COLORS[i % Palette99::COLORS.len()];
        RGBColor(r, g, b)
    })
}

/// Registers the bundled font once per process.
fn ensure_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok());
    if ok {
        Ok(())
    } else {
        Err(Error::Plot(
            "the bundled font assets/DejaVuSans.ttf is not a readable font".into(),
        ))
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    fn area_load_plot() -> Chart {
        let forces = [0.5, 1.0, 2.0, 5.0, 10.0];
        Chart {
            title: "Contact area vs load".into(),
            x_label: "normal force F (mN)".into(),
            y_label: "contact area A (µm²)".into(),
            axes: Axes::LogLog,
            legend: Legend::UpperLeft,
            points: vec![PointSet {
                label: "measured".into(),
                xy: forces
                    .iter()
                    .map(|&f| (f, 120.0 * f64::powf(f, 0.9)))
                    .collect(),
            }],
            curves: vec![Curve {
                label: "fit A = 120 F^0.9".into(),
                xy: (0..50)
                    .map(|i| 0.4 * 1.08f64.powi(i))
                    .map(|f| (f, 120.0 * f.powf(0.9)))
                    .collect(),
            }],
        }
    }

    #[test]
    fn png_is_900_by_650_and_not_blank() {
        let png = area_load_plot().to_png().unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (900, 650));
        let first = img.get_pixel(0, 0);
        assert!(img.pixels().any(|p| p != first));
    }

    #[test]
    fn svg_has_axis_and_legend_labels() {
        let svg = area_load_plot().to_svg().unwrap();
        assert!(svg.starts_with("<svg"));
        for text in [
            "contact area A (µm²)",
            "normal force F (mN)",
            "measured",
            "fit A = 120 F^0.9",
            "Contact area vs load",
        ] {
            assert!(svg.contains(text), "SVG lacks {text:?}");
        }
    }

    #[test]
    fn nothing_positive_is_an_error() {
        let plot = Chart {
            points: vec![PointSet {
                label: "bad".into(),
                xy: vec![(0.0, 1.0), (-1.0, 2.0), (1.0, -3.0), (f64::NAN, 1.0)],
            }],
            curves: vec![Curve {
                label: "zero".into(),
                xy: vec![(0.0, 0.0), (f64::INFINITY, 1.0)],
            }],
            ..Chart::default()
        };
        assert!(matches!(plot.to_png(), Err(Error::Plot(_))));
        assert!(matches!(plot.to_svg(), Err(Error::Plot(_))));
        assert!(matches!(Chart::default().to_png(), Err(Error::Plot(_))));
    }

    #[test]
    fn bad_points_are_skipped_and_single_point_plots() {
        let mut plot = area_load_plot();
        plot.points[0]
            .xy
            .extend([(0.0, 5.0), (f64::NAN, 1.0), (3.0, -1.0)]);
        plot.curves[0].xy.insert(10, (f64::NAN, f64::NAN));
        plot.points.push(PointSet::default());
        assert!(plot.to_png().is_ok());
        let single = Chart {
            points: vec![PointSet {
                label: String::new(),
                xy: vec![(1.0, 1.0)],
            }],
            ..Chart::default()
        };
        assert!(single.to_svg().is_ok());
    }

    #[test]
    fn linear_chart_shows_zero_and_negative_values() {
        let chart = Chart {
            title: "Autocorrelation".into(),
            x_label: "lag r (µm)".into(),
            y_label: "C(r)".into(),
            axes: Axes::Linear,
            legend: Legend::UpperRight,
            curves: vec![Curve {
                label: "cosine".into(),
                xy: (0..=40)
                    .map(|i| f64::from(i) * 0.25)
                    .map(|r| (r, r.cos()))
                    .collect(),
            }],
            ..Chart::default()
        };
        let svg = chart.to_svg().unwrap();
        assert!(svg.contains("cosine") && svg.contains("lag r (µm)"));
        let ticks: Vec<&str> = svg.lines().filter(|l| !l.starts_with('<')).collect();
        assert!(
            ticks.iter().any(|t| t.starts_with('-')),
            "negative tick expected"
        );
        assert!(ticks.contains(&"0"), "zero tick expected: {ticks:?}");
        assert!(!svg.contains("e-16"), "rounding noise in a tick label");
        let only_zero = Chart {
            axes: Axes::Linear,
            points: vec![PointSet {
                label: String::new(),
                xy: vec![(0.0, 0.0)],
            }],
            ..Chart::default()
        };
        assert!(only_zero.to_png().is_ok());
        let log = Chart {
            axes: Axes::LogLog,
            ..only_zero
        };
        assert!(matches!(log.to_png(), Err(Error::Plot(_))));
    }

    /// 20×10 image, contact rectangle x in 5..11, y in 3..7, on a background gradient.
    fn rectangle_scene() -> (Vec<f64>, Vec<bool>) {
        let (w, h) = (20, 10);
        let inside = |x: usize, y: usize| (5..11).contains(&x) && (3..7).contains(&y);
        let mut values = Vec::new();
        let mut mask = Vec::new();
        for y in 0..h {
            for x in 0..w {
                values.push(if inside(x, y) { 200.0 } else { (x + y) as f64 });
                mask.push(inside(x, y));
            }
        }
        values[0] = f64::NAN;
        (values, mask)
    }

    #[test]
    fn overlay_green_exactly_on_rectangle_boundary() {
        let (values, mask) = rectangle_scene();
        for scale in [1, 3] {
            let png = overlay_png(&values, 20, 10, &mask, scale).unwrap();
            let img = image::load_from_memory(&png).unwrap().to_rgb8();
            let s = scale as u32;
            assert_eq!(img.dimensions(), (20 * s, 10 * s));
            for (x, y, p) in img.enumerate_pixels() {
                let (sx, sy) = (x / s, y / s);
                let inside = (5..11).contains(&sx) && (3..7).contains(&sy);
                let ring = inside && (sx == 5 || sx == 10 || sy == 3 || sy == 6);
                assert_eq!(p.0 == EDGE_GREEN, ring, "pixel ({x}, {y}) at scale {scale}");
            }
            // Corner and side of the rectangle, an interior pixel, a background pixel.
            assert_eq!(img.get_pixel(5 * s, 3 * s).0, EDGE_GREEN);
            assert_eq!(img.get_pixel(8 * s, 7 * s - 1).0, EDGE_GREEN);
            let interior = img.get_pixel(6 * s, 4 * s).0;
            assert_eq!(interior, [255, 255, 255], "contact is the brightest grey");
            let bg = img.get_pixel(15 * s, s).0;
            assert!(bg[0] == bg[1] && bg[1] == bg[2] && bg[0] > 0, "{bg:?}");
            assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0], "NaN pixel is black");
        }
    }

    #[test]
    fn overlay_edge_at_image_border_is_not_an_edge() {
        let png = overlay_png(&[1.0, 2.0, 3.0, 4.0], 2, 2, &[true; 4], 2).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert!(img.pixels().all(|p| p.0 != EDGE_GREEN));
    }

    #[test]
    fn overlay_constant_image_is_mid_grey() {
        let png = overlay_png(&[7.0; 6], 3, 2, &[false; 6], 1).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert!(img.pixels().all(|p| p.0 == [128, 128, 128]));
    }

    #[test]
    fn panels_share_the_first_panels_grey_scale() {
        let (values, mask) = rectangle_scene();
        let dimmer: Vec<f64> = values.iter().map(|v| v * 0.5).collect();
        let png = edge_panels_png(&[&values, &dimmer], 20, 10, &mask, 2).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (2 * 40 + 4, 20));
        // Same interior pixel: full white in panel 1, about half grey in panel 2.
        let left = img.get_pixel(12, 8).0[0];
        let right = img.get_pixel(44 + 12, 8).0[0];
        assert_eq!(left, 255);
        assert!((100..=160).contains(&right), "{right}");
        assert_eq!(img.get_pixel(41, 8).0, [255, 255, 255], "white gap");
        assert_eq!(
            img.get_pixel(44 + 10, 6).0,
            EDGE_GREEN,
            "edges on both panels"
        );
        assert!(edge_panels_png(&[], 20, 10, &mask, 1).is_err());
    }

    #[test]
    fn overlay_rejects_bad_shapes() {
        let (values, mask) = rectangle_scene();
        let short = &mask[..mask.len() - 1];
        assert!(matches!(
            overlay_png(&values, 20, 10, short, 1),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&values, 10, 10, &mask, 1),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&[], 0, 0, &[], 1),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&values, 20, 10, &mask, 0),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&values, 20, 10, &mask, usize::MAX),
            Err(Error::Plot(_))
        ));
    }

    #[test]
    fn ranges_are_padded_and_reach_a_power_of_ten() {
        assert_eq!(pad_log(1.0, 100.0).unwrap(), (0.8, 125.0));
        let (a, b) = pad_log(2.0e-10, 4.0e-10).unwrap();
        assert!(
            (a - 1e-10).abs() < 1e-22 && (b - 5e-10).abs() < 1e-22,
            "{a} {b}"
        );
        assert!(pad_log(1.0, f64::MAX).is_err());
        assert_eq!(pad_linear(0.0, 10.0).unwrap(), (-0.5, 10.5));
        assert_eq!(pad_linear(0.0, 0.0).unwrap(), (-1.0, 1.0));
        assert!(pad_linear(-f64::MAX, f64::MAX).is_err());
    }

    #[test]
    fn tick_labels_are_clean() {
        assert_eq!(tick_label(1.0), "1");
        assert_eq!(tick_label(20.0), "20");
        assert_eq!(tick_label(0.05), "0.05");
        assert_eq!(tick_label(0.30000000000000004), "0.3");
        assert_eq!(tick_label(2e-5), "2e-5");
        assert_eq!(tick_label(1e6), "1e6");
    }
}
