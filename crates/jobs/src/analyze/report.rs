//! The outcome of `analyze` as the outputs show it: one [`Row`] per image (`areas.csv`, the
//! Python result's rows), the fits, and the facts of the inputs and the threshold
//! (`summary.json`). No computation beyond unit conversion, the area–load fits
//! ([`contactscope::analysis::fit`]) and the Hertz reference ([`contactscope::mechanics::hertz`])
//! lives here. Area columns are in µm² with a pixel size and in pixels without one; the column
//! names say which.

use serde::ser::{SerializeMap, SerializeSeq};
use serde::{Serialize, Serializer};

use contactscope::analysis::bootstrap::{
    calibration_bounds, fit_intervals, joint_fit_intervals, FitIntervals,
};
use contactscope::analysis::corrected::{correct_series, Assumptions, SeriesLight};
use contactscope::analysis::fit::{fit_power_law, fit_proportional, PowerLawFit};
use contactscope::analysis::Analysis;
use contactscope::mechanics::hertz;
use contactscope_formats::microscopy::select::{LoadAxis, Selection};

use crate::fits::{fit_points, Exclusion, LoadPoint};
use crate::lab::{self, Interval, OptQ, Unit, Q};
use crate::series::Series;

/// Sphere radius and contact modulus for the Hertz reference columns.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HertzParams {
    /// Sphere radius, m.
    #[serde(rename = "sphere_radius_um", serialize_with = "lab::m_as_um")]
    pub radius_m: f64,
    /// Contact modulus E*, Pa.
    #[serde(rename = "contact_modulus_GPa", serialize_with = "lab::pa_as_gpa")]
    pub modulus_pa: f64,
}

/// One row of `areas.csv`, in µm² where a pixel size is known (pixels otherwise). Its own
/// serialisation (field names as here) is the batch's record of an image; `areas.csv` and the
/// outcome name the columns with their units ([`AreaTable`]).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Row {
    /// Image file.
    pub image: String,
    /// Zero-based page.
    pub page: usize,
    /// Normal force, mN.
    pub force_mn: Option<f64>,
    /// Threshold applied (contact is value > threshold).
    pub threshold: f64,
    /// Contact pixels.
    pub contact_pixels: u64,
    /// Contact area in µm² (or pixels without a pixel size): the contact pixels (the paper's
    /// measure, biased where patches are near the PSF's size).
    pub area: f64,
    /// The true contact area estimated from the image's light (`docs/methods.md`, "Area
    /// intervals"), µm² (or pixels); NaN without contact light or in an older batch record.
    #[serde(default = "not_recorded", deserialize_with = "nan_if_null")]
    pub area_corrected: f64,
    /// Lower end of the 95 % interval on the true contact area (`docs/methods.md`, "Area
    /// intervals"), µm² (or pixels); NaN in a batch record written before intervals existed.
    #[serde(default = "not_recorded", deserialize_with = "nan_if_null")]
    pub area_lo: f64,
    /// Upper end of the interval, µm² (or pixels).
    #[serde(default = "not_recorded", deserialize_with = "nan_if_null")]
    pub area_hi: f64,
    /// Mean intensity over contact pixels.
    pub mean_intensity: Option<f64>,
    /// Sum of intensities over contact pixels.
    pub integrated_intensity: f64,
    /// Mean intensity over non-contact pixels.
    pub background_mean: Option<f64>,
    /// 8-connected contact patches.
    pub patches: u64,
    /// Largest patch, µm² (or pixels).
    pub largest_patch: f64,
    /// Force / area, MPa (only with a pixel size).
    pub mean_pressure_mpa: Option<f64>,
    /// Force / `area_hi`: the interval's lower end on the mean pressure, MPa.
    #[serde(default)]
    pub mean_pressure_mpa_lo: Option<f64>,
    /// Force / `area_lo`, MPa (`None` when `area_lo` is 0).
    #[serde(default)]
    pub mean_pressure_mpa_hi: Option<f64>,
    /// √(A/π), µm (or pixels).
    pub equivalent_radius: f64,
    /// Friction force, mN.
    pub friction_mn: Option<f64>,
    /// Hertz contact radius, µm.
    pub hertz_radius_um: Option<f64>,
    /// Hertz contact area, µm².
    pub hertz_area_um2: Option<f64>,
    /// The contact is cut off by the image border (`Mask::edge_contact`): the image is left out
    /// of the fits ([`crate::fits`]).
    #[serde(default)]
    pub edge_contact: bool,
}

/// A value an older record does not hold.
fn not_recorded() -> f64 {
    f64::NAN
}

/// A number, or NaN for `null` (how JSON writes a NaN back).
fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(<Option<f64> as serde::Deserialize>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Row {
    /// Whether the image can be drawn on the log–log plot: a positive force and some contact (a
    /// 0 mN reference frame or an image without contact cannot).
    pub fn on_log_axes(&self) -> bool {
        self.force_mn.is_some_and(|f| f > 0.0) && self.area > 0.0
    }

    /// The image as a load of the fits: left out without contact or with contact at the border.
    pub fn load_point(&self) -> LoadPoint {
        LoadPoint {
            force_mn: self.force_mn.unwrap_or(f64::NAN),
            area: self.area,
            excluded: if self.contact_pixels == 0 {
                Some(Exclusion::NoContact)
            } else if self.edge_contact {
                Some(Exclusion::EdgeContact)
            } else {
                None
            },
        }
    }
}

/// Area unit of the outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AreaUnit {
    /// Square micrometres.
    SquareMicrometre,
    /// Pixels (no pixel size known).
    Pixel,
}

impl AreaUnit {
    /// Suffix of the area columns: `um2` or `px`.
    pub fn area_suffix(self) -> &'static str {
        match self {
            AreaUnit::SquareMicrometre => "um2",
            AreaUnit::Pixel => "px",
        }
    }

    fn length_suffix(self) -> &'static str {
        match self {
            AreaUnit::SquareMicrometre => "um",
            AreaUnit::Pixel => "px",
        }
    }

    fn area(self) -> Unit {
        match self {
            AreaUnit::SquareMicrometre => Unit::Um2,
            AreaUnit::Pixel => Unit::None,
        }
    }

    fn length(self) -> Unit {
        match self {
            AreaUnit::SquareMicrometre => Unit::Um,
            AreaUnit::Pixel => Unit::None,
        }
    }

    /// The label of an area axis.
    pub fn axis_label(self) -> &'static str {
        match self {
            AreaUnit::SquareMicrometre => "contact area A (µm²)",
            AreaUnit::Pixel => "contact area A (pixels)",
        }
    }
}

impl Serialize for AreaUnit {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(match (self, lab::si()) {
            (AreaUnit::SquareMicrometre, true) => "m2",
            (unit, _) => unit.area_suffix(),
        })
    }
}

/// The rows with the columns the table has: mean pressure with a pixel size, friction when a
/// manifest gave any, Hertz columns when asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct AreaTable {
    /// Unit of the area columns.
    pub unit: AreaUnit,
    /// Whether any image has a friction force (the column is written).
    pub has_friction: bool,
    /// Whether the Hertz columns are written.
    pub has_hertz: bool,
    /// Relative uncertainty (bounds) of the pixel size, carried by `area_*_lo`/`_hi`; written
    /// as the column `pixel_size_uncertainty_pct` when it is not 0 (so that `fit-hardening`
    /// can tell the part every image shares from each image's own).
    pub pixel_size_uncertainty: f64,
    /// One row per image, in input order.
    pub rows: Vec<Row>,
}

/// One row with its table's columns.
struct RowOf<'a>(&'a AreaTable, &'a Row);

impl Serialize for RowOf<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let (t, r) = (self.0, self.1);
        let (a, l) = (t.unit.area_suffix(), t.unit.length_suffix());
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("image", &r.image)?;
        m.serialize_entry("page", &r.page)?;
        m.serialize_entry("force_mN", &OptQ(r.force_mn, Unit::Mn))?;
        m.serialize_entry("threshold", &r.threshold)?;
        m.serialize_entry("contact_pixels", &r.contact_pixels)?;
        m.serialize_entry(&format!("area_{a}"), &Q(r.area, t.unit.area()))?;
        m.serialize_entry(
            &format!("area_corrected_{a}"),
            &Q(r.area_corrected, t.unit.area()),
        )?;
        m.serialize_entry(&format!("area_{a}_lo"), &Q(r.area_lo, t.unit.area()))?;
        m.serialize_entry(&format!("area_{a}_hi"), &Q(r.area_hi, t.unit.area()))?;
        if t.pixel_size_uncertainty > 0.0 {
            m.serialize_entry(
                "pixel_size_uncertainty_pct",
                &Q(t.pixel_size_uncertainty, Unit::FractionAsPct),
            )?;
        }
        m.serialize_entry("mean_intensity", &r.mean_intensity)?;
        m.serialize_entry("integrated_intensity", &r.integrated_intensity)?;
        m.serialize_entry("background_mean", &r.background_mean)?;
        m.serialize_entry("patches", &r.patches)?;
        m.serialize_entry(
            &format!("largest_patch_{a}"),
            &Q(r.largest_patch, t.unit.area()),
        )?;
        if t.unit == AreaUnit::SquareMicrometre {
            m.serialize_entry("mean_pressure_MPa", &OptQ(r.mean_pressure_mpa, Unit::Mpa))?;
            m.serialize_entry(
                "mean_pressure_MPa_lo",
                &OptQ(r.mean_pressure_mpa_lo, Unit::Mpa),
            )?;
            m.serialize_entry(
                "mean_pressure_MPa_hi",
                &OptQ(r.mean_pressure_mpa_hi, Unit::Mpa),
            )?;
        }
        m.serialize_entry(
            &format!("equivalent_radius_{l}"),
            &Q(r.equivalent_radius, t.unit.length()),
        )?;
        if t.has_friction {
            m.serialize_entry("friction_mN", &OptQ(r.friction_mn, Unit::Mn))?;
        }
        if t.has_hertz {
            m.serialize_entry("hertz_radius_um", &OptQ(r.hertz_radius_um, Unit::Um))?;
            m.serialize_entry("hertz_area_um2", &OptQ(r.hertz_area_um2, Unit::Um2))?;
        }
        m.serialize_entry("edge_contact", &r.edge_contact)?;
        m.end()
    }
}

impl Serialize for AreaTable {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.rows.len()))?;
        for r in &self.rows {
            seq.serialize_element(&RowOf(self, r))?;
        }
        seq.end()
    }
}

/// The area–load fits over the images with a positive force and area.
#[derive(Debug, Clone, PartialEq)]
pub struct Fits {
    /// Unit of the areas.
    pub unit: AreaUnit,
    /// A = c·N^β with N in mN and A in the area unit.
    pub power_law: Option<PowerLawFit>,
    /// p of A = N/p, MPa, with the number of points (only with a pixel size).
    pub proportional_mpa: Option<(f64, usize)>,
    /// Smallest and largest mean pressure, MPa.
    pub pressure_range_mpa: Option<(f64, f64)>,
    /// 95 % intervals on the true law's parameters by a bootstrap over the images and the joint
    /// draws of their true areas ([`contactscope::analysis::bootstrap`]).
    pub intervals: Option<FitIntervals>,
    /// The power law fitted to the corrected areas (the estimate the intervals are about).
    pub power_law_corrected: Option<PowerLawFit>,
    /// The proportional law's pressure from the corrected areas, MPa (the estimate its interval
    /// is about).
    pub proportional_corrected_mpa: Option<f64>,
}

impl Serialize for Fits {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let si = lab::si();
        let mut m = s.serialize_map(Some(3))?;
        m.serialize_entry(
            "power_law",
            &self.power_law.map(|f| {
                PowerLawOf(
                    self.unit,
                    f,
                    si,
                    self.intervals.as_ref(),
                    self.power_law_corrected,
                )
            }),
        )?;
        let pressure_ci = self
            .intervals
            .as_ref()
            .and_then(|i| i.proportional_slope)
            .filter(|(lo, _)| *lo > 0.0)
            .map(|(lo, hi)| (1e3 / hi, 1e3 / lo));
        m.serialize_entry(
            "proportional",
            &self
                .proportional_mpa
                .map(|(p, n)| Proportional(p, n, pressure_ci, self.proportional_corrected_mpa)),
        )?;
        m.serialize_entry(
            "mean_pressure_MPa",
            &self.pressure_range_mpa.map(|(lo, hi)| MinMax(lo, hi)),
        )?;
        m.end()
    }
}

struct PowerLawOf<'a>(
    AreaUnit,
    PowerLawFit,
    bool,
    Option<&'a FitIntervals>,
    Option<PowerLawFit>,
);

impl Serialize for PowerLawOf<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let (unit, f, si) = (self.0, &self.1, self.2);
        let a = unit.area_suffix();
        let mut m = s.serialize_map(None)?;
        // In SI units (Python): A in m² (or pixels) and N in newtons.
        let (model, prefactor) = match (si, unit) {
            (false, _) => (
                format!("area_{a} = prefactor * force_mN^exponent"),
                f.prefactor,
            ),
            (true, AreaUnit::SquareMicrometre) => (
                "area_m2 = prefactor * force_n^exponent".to_string(),
                f.prefactor * 1e-12 * 1e3f64.powf(f.exponent),
            ),
            (true, AreaUnit::Pixel) => (
                "area_px = prefactor * force_n^exponent".to_string(),
                f.prefactor * 1e3f64.powf(f.exponent),
            ),
        };
        m.serialize_entry("model", &model)?;
        m.serialize_entry(&format!("prefactor_{a}_per_mN_pow_exponent"), &prefactor)?;
        m.serialize_entry("exponent", &f.exponent)?;
        m.serialize_entry("exponent_se", &f.exponent_se)?;
        // The same conversion of the prefactor, resample by resample (it depends on each β).
        let to_output = |c: f64, b: f64| match (si, unit) {
            (false, _) => c,
            (true, AreaUnit::SquareMicrometre) => c * 1e-12 * 1e3f64.powf(b),
            (true, AreaUnit::Pixel) => c * 1e3f64.powf(b),
        };
        let intervals = self.3;
        m.serialize_entry("exponent_corrected", &self.4.map(|c| c.exponent))?;
        m.serialize_entry(
            &format!("prefactor_corrected_{a}_per_mN_pow_exponent"),
            &self.4.map(|c| to_output(c.prefactor, c.exponent)),
        )?;
        m.serialize_entry(
            "exponent_ci95",
            &intervals.map(|i| Interval(i.exponent.0, i.exponent.1, Unit::None)),
        )?;
        m.serialize_entry(
            &format!("prefactor_{a}_per_mN_pow_exponent_ci95"),
            &intervals
                .and_then(|i| i.prefactor_in(to_output))
                .map(|(lo, hi)| Interval(lo, hi, Unit::None)),
        )?;
        m.serialize_entry("r_squared", &f.r_squared)?;
        m.serialize_entry("points", &f.points)?;
        m.serialize_entry("distinct_forces", &f.distinct_forces)?;
        m.end()
    }
}

struct Proportional(f64, usize, Option<(f64, f64)>, Option<f64>);

impl Serialize for Proportional {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(5))?;
        m.serialize_entry("model", "area = force / pressure")?;
        m.serialize_entry("pressure_MPa", &Q(self.0, Unit::Mpa))?;
        m.serialize_entry("pressure_corrected_MPa", &self.3.map(|p| Q(p, Unit::Mpa)))?;
        m.serialize_entry(
            "pressure_MPa_ci95",
            &self.2.map(|(lo, hi)| Interval(lo, hi, Unit::Mpa)),
        )?;
        m.serialize_entry("points", &self.1)?;
        m.end()
    }
}

struct MinMax(f64, f64);

impl Serialize for MinMax {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(2))?;
        m.serialize_entry("min", &Q(self.0, Unit::Mpa))?;
        m.serialize_entry("max", &Q(self.1, Unit::Mpa))?;
        m.end()
    }
}

/// The rows and fits of an analysis of `series`, image by image. `pixel_size_uncertainty` (the
/// pixel size's relative uncertainty, as bounds) widens each area's interval by the factors
/// (1 ∓ u)² and enters the fit intervals as a factor shared by all images; it is ignored for
/// areas in pixels.
pub fn table_and_fits(
    series: &Series,
    analysis: &Analysis,
    hertz: Option<HertzParams>,
    pixel_size_uncertainty: f64,
) -> (AreaTable, Fits, IntervalModel) {
    let unit = match analysis.pixel_size {
        Some(_) => AreaUnit::SquareMicrometre,
        None => AreaUnit::Pixel,
    };
    let u = match unit {
        AreaUnit::SquareMicrometre => pixel_size_uncertainty,
        AreaUnit::Pixel => 0.0,
    };
    let (shrink, grow) = calibration_bounds(u);
    let pixel_area = analysis.pixel_size.map_or(1.0, |p| p.area_um2());
    let forces_n: Vec<Option<f64>> = series.images.iter().map(|i| i.force_n).collect();
    let correction = correct_series(analysis, &forces_n, Assumptions::default());
    let model = interval_model(series, analysis, &correction);
    let light = matches!(model, IntervalModel::Light(_));
    let rows: Vec<Row> = series
        .images
        .iter()
        .zip(&analysis.images)
        .zip(&correction.areas)
        .map(|((image, r), corrected)| {
            let m = &r.measurement;
            let area = m.contact_pixels as f64 * pixel_area;
            // The edge band where the light budget cannot be used (no contact light, or a
            // series whose fits would need an image without one).
            let (area_corrected, area_lo, area_hi) = match corrected.filter(|_| light) {
                Some(c) => (
                    c.area_px * pixel_area,
                    c.lo_px * pixel_area * shrink,
                    c.hi_px * pixel_area * grow,
                ),
                // The analysis measured a band wherever this can happen
                // (`analysis::needs_bands`).
                None => r.band.map_or((f64::NAN, f64::NAN, f64::NAN), |b| {
                    (
                        f64::NAN,
                        b.lo_pixels as f64 * pixel_area * shrink,
                        b.hi_pixels as f64 * pixel_area * grow,
                    )
                }),
            };
            let force_mn = image.force_n.map(|f| f * 1e3);
            let pressure = |a: f64| match (unit, force_mn) {
                (AreaUnit::SquareMicrometre, Some(f)) if a > 0.0 => Some(f / a * 1e3),
                _ => None,
            };
            let hertz_radius = match (hertz, image.force_n) {
                (Some(h), Some(f)) => Some(hertz::contact_radius(f, h.radius_m, h.modulus_pa)),
                _ => None,
            };
            Row {
                image: image.path.display().to_string(),
                page: image.page,
                force_mn,
                threshold: r.threshold.value,
                contact_pixels: m.contact_pixels,
                area,
                area_corrected,
                area_lo,
                area_hi,
                mean_intensity: m.mean_intensity,
                integrated_intensity: m.integrated_intensity,
                background_mean: m.background_mean,
                patches: m.patches,
                largest_patch: m.largest_patch_pixels as f64 * pixel_area,
                mean_pressure_mpa: pressure(area),
                mean_pressure_mpa_lo: pressure(area_hi),
                mean_pressure_mpa_hi: pressure(area_lo),
                equivalent_radius: (area / std::f64::consts::PI).sqrt(),
                friction_mn: image.friction_n.map(|f| f * 1e3),
                hertz_radius_um: hertz_radius.map(|a| a * 1e6),
                hertz_area_um2: hertz_radius.map(|a| std::f64::consts::PI * a * a * 1e12),
                edge_contact: m.edge_contact,
            }
        })
        .collect();
    let points: Vec<LoadPoint> = rows.iter().map(Row::load_point).collect();
    let (forces, areas) = fit_points(&points);
    // The same images as the fits, each with its joint draws (the calibration enters the
    // bootstrap as one factor for all images).
    let in_fit: Vec<usize> = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.load_point().in_fit())
        .map(|(i, _)| i)
        .collect();
    let fit_forces: Vec<f64> = in_fit.iter().filter_map(|&i| rows[i].force_mn).collect();
    let corrected_areas: Vec<f64> = in_fit.iter().map(|&i| rows[i].area_corrected).collect();
    let (intervals, power_law_corrected) = if fit_forces.len() != in_fit.len() {
        (None, None)
    } else if light {
        let draws: Vec<Vec<f64>> = correction
            .draws
            .iter()
            .map(|d| in_fit.iter().map(|&i| d[i] * pixel_area).collect())
            .collect();
        (
            joint_fit_intervals(&fit_forces, &draws, u),
            fit_power_law(&fit_forces, &corrected_areas),
        )
    } else {
        // The bands alone: the calibration enters the bootstrap as one factor for all images.
        let band = |f: fn(&Row) -> f64, by: f64| -> Vec<f64> {
            in_fit.iter().map(|&i| f(&rows[i]) / by).collect()
        };
        (
            fit_intervals(
                &fit_forces,
                &band(|r| r.area_lo, shrink),
                &band(|r| r.area_hi, grow),
                u,
            ),
            None,
        )
    };
    // As `proportional_mpa` below, from the corrected areas of the same images.
    let proportional_corrected_mpa = match (unit, &power_law_corrected) {
        (AreaUnit::SquareMicrometre, Some(_)) => fit_proportional(&fit_forces, &corrected_areas)
            .filter(|(s, _)| *s > 0.0)
            .map(|(slope, _)| 1e3 / slope),
        _ => None,
    };
    let proportional_mpa = match unit {
        AreaUnit::SquareMicrometre => fit_proportional(&forces, &areas)
            .filter(|(s, _)| *s > 0.0)
            .map(|(slope, n)| (1e3 / slope, n)),
        AreaUnit::Pixel => None,
    };
    let pressures: Vec<f64> = rows
        .iter()
        .filter(|r| r.load_point().in_fit())
        .filter_map(|r| r.mean_pressure_mpa)
        .collect();
    let fits = Fits {
        unit,
        power_law: fit_power_law(&forces, &areas),
        proportional_mpa,
        intervals,
        power_law_corrected,
        proportional_corrected_mpa,
        pressure_range_mpa: (!pressures.is_empty()).then(|| {
            (
                pressures.iter().copied().fold(f64::INFINITY, f64::min),
                pressures.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            )
        }),
    };
    let table = AreaTable {
        unit,
        has_friction: rows.iter().any(|r| r.friction_mn.is_some()),
        has_hertz: hertz.is_some(),
        pixel_size_uncertainty: u,
        rows,
    };
    (table, fits, model)
}

/// How a series' area intervals are made (`docs/methods.md`, "Area intervals").
#[derive(Debug, Clone)]
pub enum IntervalModel {
    /// From the light budgets: every image the fits use has one.
    Light(SeriesLight),
    /// The edge band around the threshold, for a series where an image the fits use has no
    /// light budget; `why` says which and why.
    Band {
        /// The image and the reason, in words.
        why: String,
    },
}

/// The light model where every image the fits use (contact, none at the border) has a light
/// budget, else the edge band with the first image that has none (the rule of
/// [`contactscope::analysis::needs_bands`], under which the analysis measured every band).
fn interval_model(
    series: &Series,
    analysis: &Analysis,
    correction: &contactscope::analysis::corrected::SeriesCorrection,
) -> IntervalModel {
    let missing = analysis.images.iter().enumerate().find(|(i, r)| {
        let m = &r.measurement;
        m.contact_pixels > 0 && !m.edge_contact && correction.areas[*i].is_none()
    });
    match missing {
        None => IntervalModel::Light(correction.model.clone()),
        Some((i, r)) => IntervalModel::Band {
            why: format!(
                "{} has no light budget: {}",
                crate::series::image_location(&series.images[i]),
                if r.light.is_none() {
                    "no 16 × 16-pixel block of background lies beyond the contact's light \
                     (a field too small around the contact)"
                } else {
                    "its contact light does not stand out from the noise"
                }
            ),
        },
    }
}

/// One file of the series as `summary.json` records it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileFacts {
    /// The file.
    pub path: String,
    /// Its format.
    pub format: &'static str,
    /// Images of the series in it.
    pub pages_used: usize,
    /// The planes used of a CZI, ND2 or LIF file.
    pub planes_used: Option<Vec<String>>,
    /// Plane width.
    pub width_px: usize,
    /// Plane height.
    pub height_px: usize,
    /// Sample type (numpy's name).
    pub sample_type: &'static str,
    /// Compression.
    pub compression: String,
    /// Channels.
    pub channels: usize,
    /// Pixel size along x from the metadata, m.
    #[serde(rename = "pixel_size_x_um", serialize_with = "lab::opt_m_as_um")]
    pub pixel_size_x_m: Option<f64>,
    /// Pixel size along y from the metadata, m.
    #[serde(rename = "pixel_size_y_um", serialize_with = "lab::opt_m_as_um")]
    pub pixel_size_y_m: Option<f64>,
    /// Where the metadata's pixel size came from.
    pub pixel_size_source: Option<&'static str>,
}

/// The pixel size the areas use.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PixelSizeUsed {
    /// Along x, m.
    #[serde(rename = "x_um", serialize_with = "lab::m_as_um")]
    pub x_m: f64,
    /// Along y, m.
    #[serde(rename = "y_um", serialize_with = "lab::m_as_um")]
    pub y_m: f64,
    /// Pixel area, µm².
    #[serde(serialize_with = "lab::um2")]
    pub pixel_area_um2: f64,
    /// Where it came from.
    pub source: &'static str,
}

/// The `inputs` of `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InputFacts {
    /// Images in the series.
    pub images: usize,
    /// How they were put in load order (the manifest's rows, natural file-name order, …).
    pub order: String,
    /// The manifest, if the series came from one.
    pub manifest: Option<String>,
    /// The channel read.
    pub channel: usize,
    /// The selection flags.
    pub selection: Selection,
    /// The load axis of CZI, ND2 or LIF files.
    pub load_axis: Option<LoadAxis>,
    /// Each distinct file (none for images handed over in memory).
    pub files: Vec<FileFacts>,
    /// The pixel size used, `null` when areas are in pixels.
    pub pixel_size_used: Option<PixelSizeUsed>,
}

impl InputFacts {
    /// The facts of `series` analysed as `analysis`.
    pub fn of(series: &Series, analysis: &Analysis) -> Self {
        InputFacts {
            images: series.images.len(),
            order: series.order.clone(),
            manifest: series.manifest.as_ref().map(|m| m.display().to_string()),
            channel: series.channel,
            selection: series.selection.clone(),
            load_axis: series.load_axis,
            files: series
                .files
                .iter()
                .map(|f| FileFacts {
                    path: f.path.display().to_string(),
                    format: f.format.name(),
                    pages_used: series.images.iter().filter(|i| i.path == f.path).count(),
                    planes_used: f.tiff.is_none().then(|| {
                        series
                            .images
                            .iter()
                            .filter(|i| i.path == f.path)
                            .filter_map(|i| i.plane.as_ref().map(|p| p.describe()))
                            .collect()
                    }),
                    width_px: f.width,
                    height_px: f.height,
                    sample_type: f.sample_type.name(),
                    compression: f.compression.clone(),
                    channels: f.channels,
                    pixel_size_x_m: f.pixel_size.map(|p| p.x_m),
                    pixel_size_y_m: f.pixel_size.map(|p| p.y_m),
                    pixel_size_source: f.pixel_size.map(|p| p.source.describe()),
                })
                .collect(),
            pixel_size_used: analysis.pixel_size.map(|p| PixelSizeUsed {
                x_m: p.x_m,
                y_m: p.y_m,
                pixel_area_um2: p.area_um2(),
                source: p.source.describe(),
            }),
        }
    }
}

/// The `threshold` of `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThresholdFacts {
    /// The method's name.
    pub method: &'static str,
    /// The series threshold (contact is value > t); `null` with one threshold per image.
    pub value: Option<f64>,
    /// One threshold per image, with `--threshold per-image`.
    pub per_image: Option<Vec<f64>>,
    /// Which side of the threshold is contact.
    pub contact_rule: &'static str,
    /// Pixels in the histogram.
    pub histogram_pixels: u64,
    /// How the histogram was binned.
    pub binning: String,
}

impl ThresholdFacts {
    /// The facts of `analysis` of integer (or float) data.
    pub fn of(analysis: &Analysis, integer: bool) -> Self {
        ThresholdFacts {
            method: analysis.method.name(),
            value: analysis.series_threshold.map(|t| t.value),
            per_image: analysis
                .series_threshold
                .is_none()
                .then(|| analysis.images.iter().map(|r| r.threshold.value).collect()),
            contact_rule: "value > threshold",
            histogram_pixels: analysis.histogram_pixels,
            binning: if integer {
                "one bin per integer level (u64 counts, f64 arithmetic), first maximum wins"
                    .to_string()
            } else {
                format!(
                    "{} equal bins over the series' finite min..max; threshold = upper edge of the highest background bin",
                    contactscope::threshold::FLOAT_BINS
                )
            },
        }
    }
}
