//! Line-and-marker charts with units on both axes, drawn with plotters to PNG or SVG.

use std::sync::OnceLock;

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle, Palette, Palette99};

use super::legend::Legend;
use super::{encode_png, plot_err};
use crate::error::{Error, Result};

/// Size of [`Chart`] images in pixels.
pub(super) const PLOT_SIZE: (u32, u32) = (900, 650);

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

/// One set of measured points (drawn as markers).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointSet {
    /// Legend label.
    pub label: String,
    /// Data points `(x, y)`; non-positive or non-finite points are skipped.
    pub xy: Vec<(f64, f64)>,
    /// Drawn as open circles with a cross: points shown but left out of the fits.
    pub hollow: bool,
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
    /// Curve `j` takes the colour of point set `j` (a fit drawn in its data's colour) instead
    /// of colours after the point sets'.
    pub curves_follow_points: bool,
    /// Points and lines half transparent, so that where many sets overlap none hides another
    /// (the batch's plot of every series); the legend stays opaque.
    pub translucent: bool,
}

/// What is left of a [`Chart`] after dropping points that log axes cannot show.
pub(super) struct Prepared {
    pub(super) points: Vec<Vec<(f64, f64)>>,
    /// Per curve, its unbroken runs of drawable vertices.
    pub(super) curves: Vec<Vec<Vec<(f64, f64)>>>,
    pub(super) x_range: (f64, f64),
    pub(super) y_range: (f64, f64),
    /// The corner the legend is drawn in ([`super::legend::place`]).
    pub(super) legend: Legend,
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

    pub(super) fn prepare(&self) -> Result<Prepared> {
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
        let mut data = Prepared {
            points,
            curves,
            x_range,
            y_range,
            legend: self.legend,
        };
        super::legend::place(self, &mut data);
        Ok(data)
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
                // Our own ticks: plotters' log key points start at the first power of ten
                // inside the range, leaving the lowest points of an axis unlabelled.
                let x = (x0..x1).log_scale().with_key_points(log_ticks(x0, x1));
                let y = (y0..y1).log_scale().with_key_points(log_ticks(y0, y1));
                let chart = builder.build_cartesian_2d(x, y).map_err(plot_err)?;
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
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 18));
        let log = matches!(self.axes, Axes::LogLog);
        let x_label = |v: &f64| match log {
            true => tick_label(*v),
            false => tick_label(snap_zero(*v, data.x_range)),
        };
        let y_label = |v: &f64| match log {
            true => tick_label(*v),
            false => tick_label(snap_zero(*v, data.y_range)),
        };
        if log {
            // The key points are `log_ticks`, every one labelled, with a light grid line.
            mesh.max_light_lines(0).bold_line_style(BLACK.mix(0.15));
        }
        mesh.x_label_formatter(&x_label)
            .y_label_formatter(&y_label)
            .draw()
            .map_err(plot_err)?;

        let mut labelled = false;
        for (i, (set, xy)) in self.points.iter().zip(&data.points).enumerate() {
            let colour = series_colour(i);
            if set.hollow {
                // Open circle and cross: a point shown but left out of the fits.
                let style = colour.stroke_width(2);
                chart
                    .draw_series(xy.iter().map(|&p| Circle::new(p, 6, style)))
                    .map_err(plot_err)?;
                let series = chart
                    .draw_series(xy.iter().map(|&p| Cross::new(p, 4, style)))
                    .map_err(plot_err)?;
                if !set.label.is_empty() {
                    labelled = true;
                    series
                        .label(set.label.as_str())
                        .legend(move |(x, y)| Cross::new((x + 10, y), 4, style));
                }
                continue;
            }
            let fill = match self.translucent {
                true => colour.mix(0.4).filled(),
                false => colour.filled(),
            };
            let series = chart
                .draw_series(xy.iter().map(|&p| Circle::new(p, 4, fill)))
                .map_err(plot_err)?;
            if !set.label.is_empty() {
                labelled = true;
                series
                    .label(set.label.as_str())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
            }
        }
        for (j, (curve, runs)) in self.curves.iter().zip(&data.curves).enumerate() {
            let colour = match self.curves_follow_points {
                true => series_colour(j),
                false => series_colour(self.points.len() + j),
            };
            let style = colour.stroke_width(2);
            let line = match self.translucent {
                true => colour.mix(0.55).stroke_width(2),
                false => style,
            };
            let series = chart
                .draw_series(runs.iter().map(|run| PathElement::new(run.clone(), line)))
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
                .position(match data.legend {
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

/// Pads `lo..hi` by ×0.8 / ×1.25, so that markers are not cut by the frame, and each end out to
/// a 1, 2 or 5 × 10^k within a further factor 1.3 (so that the axis starts and ends at a label
/// where that costs little room). A range too narrow for two [`log_ticks`] is widened out to
/// the nearest 1…9 × 10^k on either side, so that every log axis has at least two labels.
fn pad_log(lo: f64, hi: f64) -> Result<(f64, f64)> {
    let (mut a, mut b) = (lo * 0.8, hi * 1.25);
    let (a125, b125) = (snap_125(a, false), snap_125(b, true));
    if a125 > 0.0 && a125 * 1.3 >= a {
        a = a125;
    }
    if b125.is_finite() && b125 <= b * 1.3 {
        b = b125;
    }
    if a > 0.0 && b.is_finite() && a < b && log_ticks(a, b).len() < 2 {
        (a, b) = (round_mantissa(a, f64::floor), round_mantissa(b, f64::ceil));
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

/// Decades beyond which a log axis is labelled at powers of ten only.
const LOG_DECADES_125: f64 = 4.0;
/// Most labels on a log axis spanning many decades (every n-th power of ten beyond).
const LOG_MAX_DECADE_LABELS: usize = 12;

/// The labelled ticks of a log axis over `lo..hi` (both positive), increasing: 1, 2 and
/// 5 × 10^k in every decade the range touches (10^k only when it spans more than four
/// decades, every n-th of them beyond a dozen), or every integer mantissa 1…9 × 10^k when
/// 1-2-5 leaves fewer than two inside the range. Empty for an empty or non-positive range.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && hi.is_finite() && lo < hi) {
        return Vec::new();
    }
    let decades = (hi / lo).log10();
    let ladder = |mantissas: &[f64], every: i32| -> Vec<f64> {
        let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        let tolerance = 1e-9;
        (k0..=k1)
            .filter(|k| k.rem_euclid(every) == 0)
            .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| *v >= lo * (1.0 - tolerance) && *v <= hi * (1.0 + tolerance))
            .collect()
    };
    if decades > LOG_DECADES_125 {
        let every = (decades / LOG_MAX_DECADE_LABELS as f64).ceil().max(1.0) as i32;
        return ladder(&[1.0], every);
    }
    let ticks = ladder(&[1.0, 2.0, 5.0], 1);
    if ticks.len() >= 2 {
        return ticks;
    }
    ladder(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1)
}

/// The nearest 1, 2 or 5 × 10^k at or below `v` (`up` false) or at or above it.
fn snap_125(v: f64, up: bool) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    let steps = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0].map(|m| m * decade);
    let near = |t: f64| (t - v).abs() <= 1e-9 * v;
    if up {
        steps.into_iter().find(|&t| t >= v || near(t))
    } else {
        steps.into_iter().rev().find(|&t| t <= v || near(t))
    }
    .unwrap_or(v)
}

/// `v` rounded down (`f64::floor`) or up (`f64::ceil`) to a one-digit mantissa: 1…9 × 10^k.
fn round_mantissa(v: f64, round: fn(f64) -> f64) -> f64 {
    let decade = 10f64.powf(v.log10().floor());
    let mantissa = v / decade;
    // A mantissa that is an integer up to rounding (300 / 100 = 2.9999…) stays that integer.
    let nearest = mantissa.round();
    let digit = if (mantissa - nearest).abs() < 1e-9 {
        nearest
    } else {
        round(mantissa)
    };
    digit * decade
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
                hollow: false,
            }],
            curves: vec![Curve {
                label: "fit A = 120 F^0.9".into(),
                xy: (0..50)
                    .map(|i| 0.4 * 1.08f64.powi(i))
                    .map(|f| (f, 120.0 * f.powf(0.9)))
                    .collect(),
            }],
            ..Chart::default()
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
                hollow: false,
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
                hollow: false,
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
                hollow: false,
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

    #[test]
    fn ranges_are_padded_and_keep_two_labels() {
        assert_eq!(pad_log(1.0, 100.0).unwrap(), (0.8, 125.0));
        // 2…4e-10 padded to 1.6…5e-10 holds 2e-10 and 5e-10: nothing more to do.
        let (a, b) = pad_log(2.0e-10, 4.0e-10).unwrap();
        assert!(
            (a - 1.6e-10).abs() < 1e-22 && (b - 5e-10).abs() < 1e-22,
            "{a} {b}"
        );
        // 1.1…1.15 padded to 0.88…1.44 holds only 0.9 and 1: two labels, no widening.
        assert_eq!(log_ticks(0.88, 1.4375).len(), 2);
        // 11.5…12 padded to 9.2…15 holds 10 alone: widened to 9…20.
        let (a, b) = pad_log(11.5, 12.0).unwrap();
        assert!(
            (a - 9.0).abs() < 1e-12 && (b - 20.0).abs() < 1e-12,
            "{a} {b}"
        );
        // Every padded range holds its data and has at least two labelled ticks.
        for i in 0..400 {
            let lo = 10f64.powf(f64::from(i) * 0.037 - 6.0);
            for ratio in [1.0, 1.01, 1.3, 2.5, 9.0, 40.0, 1e3, 1e7] {
                let hi = lo * ratio;
                let (a, b) = pad_log(lo, hi).unwrap();
                assert!(a <= lo && b >= hi, "{lo} {hi}: {a} {b}");
                let ticks = log_ticks(a, b);
                assert!(ticks.len() >= 2, "{lo}…{hi} padded to {a}…{b}: {ticks:?}");
                assert!(ticks.windows(2).all(|w| w[0] < w[1]), "{ticks:?}");
            }
        }
        // Ends within a factor 1.3 of a 1-2-5 tick move out to it: 20.9…775 → 20…1000.
        let (a, b) = pad_log(26.1, 620.0).unwrap();
        assert!(
            (a - 20.0).abs() < 1e-12 && (b - 1000.0).abs() < 1e-9,
            "{a} {b}"
        );
        assert_eq!(snap_125(0.3, true), 0.5);
        assert_eq!(snap_125(0.3, false), 0.2);
        assert_eq!(snap_125(200.0, false), 200.0);
        assert!(pad_log(1.0, f64::MAX).is_err());
        assert_eq!(pad_linear(0.0, 10.0).unwrap(), (-0.5, 10.5));
        assert_eq!(pad_linear(0.0, 0.0).unwrap(), (-1.0, 1.0));
        assert!(pad_linear(-f64::MAX, f64::MAX).is_err());
    }

    fn labels(lo: f64, hi: f64) -> Vec<String> {
        log_ticks(lo, hi).into_iter().map(tick_label).collect()
    }

    #[test]
    fn log_ticks_are_one_two_five_in_every_decade_the_data_cover() {
        // The areas of the synthetic series, 37…620 µm²: 50 is labelled, below 100.
        assert_eq!(labels(37.0, 620.0), ["50", "100", "200", "500"]);
        assert_eq!(labels(4.0, 400.0), ["5", "10", "20", "50", "100", "200"]);
        assert_eq!(labels(3.2, 125.0), ["5", "10", "20", "50", "100"]);
        assert_eq!(
            labels(0.0015, 0.3),
            ["0.002", "0.005", "0.01", "0.02", "0.05", "0.1", "0.2"]
        );
        // Ends that are ticks are kept despite rounding.
        assert_eq!(labels(1.0, 10.0), ["1", "2", "5", "10"]);
        // Within less than a factor of 2.5: every integer mantissa.
        assert_eq!(labels(30.0, 70.0), ["30", "40", "50", "60", "70"]);
        // Over more than four decades, powers of ten only; over very many, every n-th.
        assert_eq!(labels(0.5, 2e5), ["1", "10", "100", "1000", "10000", "1e5"]);
        assert_eq!(log_ticks(1e-9, 1e-2).len(), 8);
        let wide = log_ticks(1e-100, 1e100);
        assert!(wide.len() <= 13 && wide.len() >= 8, "{}", wide.len());
        // No ticks for a range no log axis shows.
        assert!(log_ticks(0.0, 1.0).is_empty());
        assert!(log_ticks(2.0, 1.0).is_empty());
        assert!(log_ticks(1.0, f64::INFINITY).is_empty());
        assert_eq!(round_mantissa(0.0123, f64::floor), 0.01);
        assert!((round_mantissa(0.0123, f64::ceil) - 0.02).abs() < 1e-15);
        assert_eq!(round_mantissa(300.0, f64::ceil), 300.0);
    }

    #[test]
    fn log_axis_labels_reach_below_the_first_power_of_ten() {
        // Areas 37…620 µm² (forces 4…100 mN): labels on both sides of 100 µm² and of 10 mN.
        let chart = Chart {
            axes: Axes::LogLog,
            points: vec![PointSet {
                label: String::new(),
                xy: vec![(4.0, 37.5), (10.0, 85.4), (100.0, 620.2)],
                hollow: false,
            }],
            ..Chart::default()
        };
        let svg = chart.to_svg().unwrap();
        let texts: Vec<&str> = svg.lines().filter(|l| !l.starts_with('<')).collect();
        for label in ["5", "10", "20", "50", "100", "200", "500"] {
            assert!(texts.contains(&label), "no tick label {label}: {texts:?}");
        }
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
