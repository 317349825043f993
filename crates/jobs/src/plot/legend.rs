//! Where a [`Chart`]'s legend goes: a corner where it covers no data, or room made above the data.

#[cfg(doc)]
use super::chart::PLOT_SIZE;
use super::chart::{Axes, Chart, Prepared};

/// Corner of a [`Chart`]'s legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// Top left (default; suits rising curves).
    #[default]
    UpperLeft,
    /// Top right (suits decaying curves).
    UpperRight,
}

/// The plotting area inside a [`PLOT_SIZE`] chart (margins, caption and axis labels taken off),
/// for placing the legend.
const PLOT_AREA_PX: (f64, f64) = (790.0, 520.0);
/// Height of one legend row and width of one label character at the legend's 15 px font.
const LEGEND_ROW_PX: f64 = 21.0;
const LEGEND_CHAR_PX: f64 = 8.5;
/// Space kept between the legend's box and the data, as a fraction of the plotting area.
const LEGEND_MARGIN: f64 = 0.03;

/// Keep the legend off the data: the preferred corner if no point or curve vertex lies
/// under the legend's box there, else the other upper corner, else the preferred corner with
/// the y axis extended upwards until every point lies below the box. The box's size is
/// estimated from the labels (rows of [`LEGEND_ROW_PX`], [`LEGEND_CHAR_PX`] per character)
/// against the plotting area of a [`PLOT_SIZE`] chart.
pub(super) fn place(chart: &Chart, data: &mut Prepared) {
    let labels: Vec<&str> = chart
        .points
        .iter()
        .map(|p| p.label.as_str())
        .chain(chart.curves.iter().map(|c| c.label.as_str()))
        .filter(|l| !l.is_empty())
        .collect();
    if labels.is_empty() {
        return;
    }
    let widest = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    let box_w = (40.0 + widest as f64 * LEGEND_CHAR_PX) / PLOT_AREA_PX.0;
    let box_h = (12.0 + labels.len() as f64 * LEGEND_ROW_PX) / PLOT_AREA_PX.1;
    let log = chart.axes == Axes::LogLog;
    let unit = |v: f64, (lo, hi): (f64, f64)| match log {
        true => (v.ln() - lo.ln()) / (hi.ln() - lo.ln()),
        false => (v - lo) / (hi - lo),
    };
    let vertices: Vec<(f64, f64)> = data
        .points
        .iter()
        .flatten()
        .chain(data.curves.iter().flatten().flatten())
        .map(|&(x, y)| (unit(x, data.x_range), unit(y, data.y_range)))
        .collect();
    let covers = |corner: Legend, (u, v): (f64, f64)| {
        let under_x = match corner {
            Legend::UpperLeft => u <= box_w + LEGEND_MARGIN,
            Legend::UpperRight => u >= 1.0 - box_w - LEGEND_MARGIN,
        };
        under_x && v >= 1.0 - box_h - LEGEND_MARGIN
    };
    let other = match chart.legend {
        Legend::UpperLeft => Legend::UpperRight,
        Legend::UpperRight => Legend::UpperLeft,
    };
    for corner in [chart.legend, other] {
        if !vertices.iter().any(|&p| covers(corner, p)) {
            data.legend = corner;
            return;
        }
    }
    // Room above the data: the highest vertex at 1 − box − margin of the new range.
    let top = vertices.iter().map(|p| p.1).fold(0.0, f64::max);
    let room = 1.0 - box_h - 2.0 * LEGEND_MARGIN;
    if room <= 0.1 {
        return;
    }
    let stretch = top / room;
    let (lo, hi) = data.y_range;
    data.y_range.1 = match log {
        true => (lo.ln() + (hi.ln() - lo.ln()) * stretch).exp(),
        false => lo + (hi - lo) * stretch,
    };
    data.legend = chart.legend;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::PointSet;

    /// The legend's corner and the y range chosen for points `xy` (labelled) on log axes.
    fn legend_for(xy: Vec<(f64, f64)>) -> (Legend, (f64, f64)) {
        let chart = Chart {
            points: vec![PointSet {
                label: "measured (Otsu contact pixels × pixel area)".into(),
                xy,
                hollow: false,
            }],
            ..Chart::default()
        };
        let data = chart.prepare().unwrap();
        (data.legend, data.y_range)
    }

    #[test]
    fn the_legend_keeps_off_the_data() {
        // A rising series leaves the upper left free.
        let rising: Vec<(f64, f64)> = (0..8)
            .map(|i| (4f64 * 2f64.powi(i), 10f64.powi(i)))
            .collect();
        let (corner, range) = legend_for(rising.clone());
        assert_eq!(corner, Legend::UpperLeft);
        // A point in the upper left sends it right.
        let mut high_left = rising[..7].to_vec();
        high_left[0].1 = 1e7;
        assert_eq!(legend_for(high_left).0, Legend::UpperRight);
        // Points in both upper corners: the range grows until the legend is above them all.
        let mut both = rising;
        both[0].1 = 1e7;
        let (corner, grown) = legend_for(both);
        assert_eq!(corner, Legend::UpperLeft);
        assert!(grown.1 > range.1 * 2.0, "{grown:?} vs {range:?}");
        let top = (1e7f64.ln() - grown.0.ln()) / (grown.1.ln() - grown.0.ln());
        assert!(top < 0.9, "highest point at {top} of the axis");
    }
}
