//! Turning an [`Analysis`] of a series into the table, the summary and the plot. No computation
//! beyond unit conversion, the area–load fits ([`contactscope::analysis::fit`]) and the Hertz reference
//! ([`contactscope::mechanics::hertz`]) lives here.

use serde::Serialize;
use serde_json::{json, Value};

use crate::error::{Error, Result};
use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::series::Series;
use contactscope::analysis::fit::{fit_power_law, fit_proportional, PowerLawFit};
use contactscope::analysis::Analysis;
use contactscope::mechanics::hertz;

/// Sphere radius and contact modulus for the Hertz reference columns.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HertzParams {
    /// Sphere radius, metres.
    pub radius_m: f64,
    /// Contact modulus E*, pascals.
    pub modulus_pa: f64,
}

/// One row of `areas.csv`, in physical units where a pixel size is known.
#[derive(Debug, Clone, PartialEq, Serialize)]
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
    /// Contact area in µm² (or pixels without a pixel size).
    pub area: f64,
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
    /// √(A/π), µm (or pixels).
    pub equivalent_radius: f64,
    /// Friction force, mN.
    pub friction_mn: Option<f64>,
    /// Hertz contact radius, µm.
    pub hertz_radius_um: Option<f64>,
    /// Hertz contact area, µm².
    pub hertz_area_um2: Option<f64>,
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
    fn area_suffix(self) -> &'static str {
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

    fn axis_label(self) -> &'static str {
        match self {
            AreaUnit::SquareMicrometre => "contact area A (µm²)",
            AreaUnit::Pixel => "contact area A (pixels)",
        }
    }
}

/// Rows and fits of an analysis.
#[derive(Debug, Clone)]
pub struct Report {
    /// One row per image, in input order.
    pub rows: Vec<Row>,
    /// Unit of the area columns.
    pub unit: AreaUnit,
    /// A = c·N^β with N in mN and A in the area unit.
    pub power_law: Option<PowerLawFit>,
    /// p of A = N/p, MPa, with the number of points (only with a pixel size).
    pub proportional_mpa: Option<(f64, usize)>,
    /// Whether any image has a friction force.
    pub has_friction: bool,
    /// Hertz parameters, if given.
    pub hertz: Option<HertzParams>,
}

impl Report {
    /// Derive rows and fits; `analysis` is the analysis of `series`, image by image.
    pub fn new(series: &Series, analysis: &Analysis, hertz: Option<HertzParams>) -> Self {
        let unit = match analysis.pixel_size {
            Some(_) => AreaUnit::SquareMicrometre,
            None => AreaUnit::Pixel,
        };
        let pixel_area = analysis.pixel_size.map_or(1.0, |p| p.area_um2());
        let rows: Vec<Row> = series
            .images
            .iter()
            .zip(&analysis.images)
            .map(|(image, r)| {
                let m = &r.measurement;
                let area = m.contact_pixels as f64 * pixel_area;
                let force_mn = image.force_n.map(|f| f * 1e3);
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
                    mean_intensity: m.mean_intensity,
                    integrated_intensity: m.integrated_intensity,
                    background_mean: m.background_mean,
                    patches: m.patches,
                    largest_patch: m.largest_patch_pixels as f64 * pixel_area,
                    mean_pressure_mpa: match (unit, force_mn) {
                        (AreaUnit::SquareMicrometre, Some(f)) if area > 0.0 => Some(f / area * 1e3),
                        _ => None,
                    },
                    equivalent_radius: (area / std::f64::consts::PI).sqrt(),
                    friction_mn: image.friction_n.map(|f| f * 1e3),
                    hertz_radius_um: hertz_radius.map(|a| a * 1e6),
                    hertz_area_um2: hertz_radius.map(|a| std::f64::consts::PI * a * a * 1e12),
                }
            })
            .collect();
        let (forces, areas): (Vec<f64>, Vec<f64>) = rows
            .iter()
            .filter_map(|r| r.force_mn.map(|f| (f, r.area)))
            .filter(|(f, a)| *f > 0.0 && *a > 0.0)
            .unzip();
        let proportional_mpa = match unit {
            AreaUnit::SquareMicrometre => fit_proportional(&forces, &areas)
                .filter(|(s, _)| *s > 0.0)
                .map(|(slope, n)| (1e3 / slope, n)),
            AreaUnit::Pixel => None,
        };
        Report {
            power_law: fit_power_law(&forces, &areas),
            proportional_mpa,
            has_friction: rows.iter().any(|r| r.friction_mn.is_some()),
            hertz,
            rows,
            unit,
        }
    }

    /// `areas.csv`: one row per image, every column named with its unit.
    pub fn areas_csv(&self) -> Result<Vec<u8>> {
        let (a, l) = (self.unit.area_suffix(), self.unit.length_suffix());
        let mut header: Vec<String> = [
            "image",
            "page",
            "force_mN",
            "threshold",
            "contact_pixels",
            &format!("area_{a}"),
            "mean_intensity",
            "integrated_intensity",
            "background_mean",
            "patches",
            &format!("largest_patch_{a}"),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        if self.unit == AreaUnit::SquareMicrometre {
            header.push("mean_pressure_MPa".into());
        }
        header.push(format!("equivalent_radius_{l}"));
        if self.has_friction {
            header.push("friction_mN".into());
        }
        if self.hertz.is_some() {
            header.extend(["hertz_radius_um".into(), "hertz_area_um2".into()]);
        }
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer.write_record(&header).map_err(csv_error)?;
        for r in &self.rows {
            let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
            let mut record = vec![
                r.image.clone(),
                r.page.to_string(),
                opt(r.force_mn),
                r.threshold.to_string(),
                r.contact_pixels.to_string(),
                r.area.to_string(),
                opt(r.mean_intensity),
                r.integrated_intensity.to_string(),
                opt(r.background_mean),
                r.patches.to_string(),
                r.largest_patch.to_string(),
            ];
            if self.unit == AreaUnit::SquareMicrometre {
                record.push(opt(r.mean_pressure_mpa));
            }
            record.push(r.equivalent_radius.to_string());
            if self.has_friction {
                record.push(opt(r.friction_mn));
            }
            if self.hertz.is_some() {
                record.extend([opt(r.hertz_radius_um), opt(r.hertz_area_um2)]);
            }
            writer.write_record(&record).map_err(csv_error)?;
        }
        writer
            .into_inner()
            .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
    }

    /// The fits as a JSON object with units in the field names.
    pub fn fits_json(&self) -> Value {
        let a = self.unit.area_suffix();
        let pressures: Vec<f64> = self
            .rows
            .iter()
            .filter_map(|r| r.mean_pressure_mpa)
            .collect();
        let pressure_range = (!pressures.is_empty()).then(|| {
            json!({
                "min": pressures.iter().copied().fold(f64::INFINITY, f64::min),
                "max": pressures.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            })
        });
        json!({
            "power_law": self.power_law.map(|f| json!({
                "model": format!("area_{a} = prefactor * force_mN^exponent"),
                format!("prefactor_{a}_per_mN_pow_exponent"): f.prefactor,
                "exponent": f.exponent,
                "exponent_se": f.exponent_se,
                "r_squared": f.r_squared,
                "points": f.points,
            })),
            "proportional": self.proportional_mpa.map(|(p, n)| json!({
                "model": "area = force / pressure",
                "pressure_MPa": p,
                "points": n,
            })),
            "mean_pressure_MPa": pressure_range,
        })
    }

    /// Log–log plot of area against force with both fits (and the Hertz area if known).
    pub fn area_plot(&self, title: &str) -> Chart {
        let measured: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter_map(|r| r.force_mn.map(|f| (f, r.area)))
            .collect();
        let forces: Vec<f64> = measured.iter().map(|p| p.0).filter(|f| *f > 0.0).collect();
        let (lo, hi) = forces
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &f| {
                (a.min(f), b.max(f))
            });
        let grid: Vec<f64> = if lo < hi {
            (0..=40)
                .map(|i| lo * (hi / lo).powf(f64::from(i) / 40.0))
                .collect()
        } else {
            forces.clone()
        };
        let mut curves = Vec::new();
        if let Some(f) = self.power_law {
            curves.push(Curve {
                label: format!(
                    "power law A ∝ N^β, β = {:.3}{}",
                    f.exponent,
                    f.exponent_se
                        .map_or(String::new(), |s| format!(" ± {s:.3}"))
                ),
                xy: grid.iter().map(|&n| (n, f.eval(n))).collect(),
            });
        }
        if let Some((p, _)) = self.proportional_mpa {
            curves.push(Curve {
                label: format!("proportional A = N/p, p = {p:.1} MPa"),
                xy: grid.iter().map(|&n| (n, n / p * 1e3)).collect(),
            });
        }
        if let (Some(h), AreaUnit::SquareMicrometre) = (self.hertz, self.unit) {
            curves.push(Curve {
                label: "Hertz area πa²".into(),
                xy: grid
                    .iter()
                    .map(|&n| {
                        (
                            n,
                            hertz::contact_area(n * 1e-3, h.radius_m, h.modulus_pa) * 1e12,
                        )
                    })
                    .collect(),
            });
        }
        Chart {
            title: title.to_string(),
            x_label: "normal force N (mN)".into(),
            y_label: self.unit.axis_label().into(),
            axes: Axes::LogLog,
            legend: Legend::UpperLeft,
            points: vec![PointSet {
                label: "measured (Otsu contact pixels × pixel area)".into(),
                xy: measured,
            }],
            curves,
        }
    }
}

fn csv_error(e: csv::Error) -> Error {
    Error::InvalidArgument(format!("CSV: {e}"))
}

/// The `inputs` part of `summary.json`.
pub fn inputs_json(series: &Series, analysis: &Analysis) -> Value {
    json!({
        "images": series.images.len(),
        "manifest": series.manifest.as_ref().map(|m| m.display().to_string()),
        "channel": series.channel,
        "selection": series.selection,
        "load_axis": series.load_axis,
        "files": series.files.iter().map(|f| json!({
            "path": f.path.display().to_string(),
            "format": f.format.name(),
            "pages_used": series.images.iter().filter(|i| i.path == f.path).count(),
            "planes_used": (f.tiff.is_none()).then(|| series.images.iter()
                .filter(|i| i.path == f.path)
                .filter_map(|i| i.plane.as_ref().map(|p| p.describe()))
                .collect::<Vec<_>>()),
            "width_px": f.width,
            "height_px": f.height,
            "sample_type": f.sample_type.name(),
            "compression": f.compression,
            "channels": f.channels,
            "pixel_size_x_um": f.pixel_size.map(|p| p.x_m * 1e6),
            "pixel_size_y_um": f.pixel_size.map(|p| p.y_m * 1e6),
            "pixel_size_source": f.pixel_size.map(|p| p.source.describe()),
        })).collect::<Vec<_>>(),
        "pixel_size_used": analysis.pixel_size.map(|p| json!({
            "x_um": p.x_m * 1e6,
            "y_um": p.y_m * 1e6,
            "pixel_area_um2": p.area_um2(),
            "source": p.source.describe(),
        })),
    })
}

/// The `threshold` part of `summary.json`.
pub fn threshold_json(analysis: &Analysis, integer: bool) -> Value {
    json!({
        "method": analysis.method.name(),
        "value": analysis.series_threshold.map(|t| t.value),
        "per_image": analysis.series_threshold.is_none().then(|| {
            analysis.images.iter().map(|r| r.threshold.value).collect::<Vec<_>>()
        }),
        "contact_rule": "value > threshold",
        "histogram_pixels": analysis.histogram_pixels,
        "binning": if integer {
            "one bin per integer level (u64 counts, f64 arithmetic), first maximum wins".to_string()
        } else {
            format!("{} equal bins over the series' finite min..max; threshold = upper edge of the highest background bin", contactscope::threshold::FLOAT_BINS)
        },
    })
}
