//! The `analyze` job: one global Otsu threshold over a load series, contact area, intensities
//! and patches per image, the area–load fits. Every front-end builds an [`AnalyzeRequest`] (the
//! command line from files and flags, Python from files or arrays in their stored sample
//! type), [`AnalyzeRequest::check`] applies the same range checks, and [`run`] returns an
//! [`AnalyzeOutcome`]: its serialisation is `summary.json` with the rows of `areas.csv`
//! (`rows`), in lab units, and the Python result in SI units. [`files`] writes the folder.

pub mod files;
pub mod report;
pub mod zarr_out;

use serde::Serialize;

use contactscope::analysis::{self, Analysis, AnalysisOptions, ImageSink, Progress};
use contactscope::optics::blur::FWHM_PER_SIGMA;
use contactscope::threshold::Method;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::{short, Quantity};

pub use report::{AreaTable, AreaUnit, Fits, HertzParams, InputFacts, Row, ThresholdFacts};

use crate::error::Result;
use crate::fits::{self, Source};
use crate::lab;
use crate::series::{self, Micrographs, OpenSeries, Series, DEFAULT_MEMORY_BUDGET};
use report::IntervalModel;

/// Everything `analyze` needs. SI units.
#[derive(Debug, Clone)]
pub struct AnalyzeRequest {
    /// The series (files or planes in memory) with its forces.
    pub micrographs: Micrographs,
    /// Threshold method: one Otsu threshold for the series (the paper's rule, the default),
    /// one per image, or a fixed value.
    pub method: Method,
    /// Pixel size (x, y), m, overriding the files' metadata (needed for areas in µm² of
    /// planes in memory).
    pub pixel_size_m: Option<(f64, f64)>,
    /// Pixel size (x, y), m, for files whose metadata states none (a stated one is kept).
    pub pixel_size_default_m: Option<(f64, f64)>,
    /// Relative uncertainty of the pixel size (given or from the files), as bounds: 0.01 for
    /// ±1 %. 0 takes it as exact. Widens the area intervals and the fit intervals.
    pub pixel_size_uncertainty: f64,
    /// The PSF's full width at half maximum, m, for the area intervals (`None`: not known, and
    /// [`contactscope::analysis::corrected::UNKNOWN_PSF_FWHM_M`] is taken).
    pub psf_fwhm_m: Option<f64>,
    /// Hertz reference columns.
    pub hertz: Option<HertzParams>,
    /// Bytes of decoded planes of compressed files kept between the two passes.
    pub memory_budget: usize,
}

impl AnalyzeRequest {
    /// A request with the defaults: global Otsu, the files' pixel size, no Hertz columns.
    pub fn new(micrographs: Micrographs) -> Self {
        AnalyzeRequest {
            micrographs,
            method: Method::GlobalOtsu,
            pixel_size_m: None,
            pixel_size_default_m: None,
            pixel_size_uncertainty: 0.0,
            psf_fwhm_m: None,
            hertz: None,
            memory_budget: DEFAULT_MEMORY_BUDGET,
        }
    }

    /// Every range check, the same for every front-end.
    pub fn check(&self) -> Result<()> {
        self.micrographs.check()?;
        if let Some((x, y)) = self.pixel_size_m {
            Quantity::PixelSize.check(x, Param::PixelSize)?;
            Quantity::PixelSize.check(y, Param::PixelSize)?;
        }
        if let Some((x, y)) = self.pixel_size_default_m {
            Quantity::PixelSize.check(x, Param::PixelSizeDefault)?;
            Quantity::PixelSize.check(y, Param::PixelSizeDefault)?;
        }
        check_pixel_size_uncertainty(self.pixel_size_uncertainty)?;
        if let Some(f) = self.psf_fwhm_m {
            Quantity::Fwhm.check(f, Param::PsfFwhm)?;
        }
        if let Some(h) = self.hertz {
            Quantity::Radius.check(h.radius_m, Param::Radius)?;
            Quantity::Modulus.check(h.modulus_pa, Param::Modulus)?;
        }
        Ok(())
    }
}

pub use crate::fits::IMPLAUSIBLE_PRESSURE_PA;

/// The largest relative uncertainty of a pixel size that is taken (beyond it the calibration is
/// not a calibration).
pub const MAX_PIXEL_SIZE_UNCERTAINTY: f64 = 0.2;

/// A pixel size's relative uncertainty in [0, [`MAX_PIXEL_SIZE_UNCERTAINTY`]].
pub fn check_pixel_size_uncertainty(u: f64) -> Result<()> {
    if (0.0..=MAX_PIXEL_SIZE_UNCERTAINTY).contains(&u) {
        return Ok(());
    }
    Err(crate::error::Error::InvalidArgument(format!(
        "{}: the pixel size's uncertainty {} % must lie between 0 and {} %",
        Param::PixelSizeUncertainty,
        short(u * 100.0),
        short(MAX_PIXEL_SIZE_UNCERTAINTY * 100.0)
    )))
}

/// What `analyze` found: `summary.json` (without `rows`, which is `areas.csv`).
#[derive(Debug, Clone, Serialize)]
pub struct AnalyzeOutcome {
    /// The files (or arrays) and the pixel size used.
    pub inputs: InputFacts,
    /// The threshold and how it was found.
    pub threshold: ThresholdFacts,
    /// `um2` or `px`.
    pub area_unit: AreaUnit,
    /// Area–load fits.
    pub fits: Fits,
    /// How the intervals on each image's area (`area_*_lo`, `area_*_hi`) are made.
    pub area_interval: AreaIntervalFacts,
    /// Hertz reference parameters.
    pub hertz: Option<HertzParams>,
    /// Warnings (pixel size, metadata notes, non-finite pixels, implausible pressures).
    pub warnings: Vec<String>,
    /// One row per image: `areas.csv`.
    pub rows: AreaTable,
    /// The analysis itself (thresholds, measurements), for printing.
    #[serde(skip)]
    pub analysis: Analysis,
}

/// The PSF the light budgets took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Psf {
    /// FWHM, m; `None` without a pixel size.
    pub fwhm_m: Option<f64>,
    /// FWHM, pixels.
    pub fwhm_px: f64,
    /// Where it came from, in words.
    pub source: &'static str,
}

/// The definition of the per-image area intervals (`docs/methods.md`, "Area intervals").
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AreaIntervalFacts {
    /// `light_budget` or `edge_band` (the fallback where an image the fits use has no light
    /// budget).
    pub model: &'static str,
    /// The method, in words.
    pub method: &'static str,
    /// Why the edge band was used; `None` for the light budget.
    pub why_edge_band: Option<String>,
    /// The nominal coverage, percent.
    pub level_pct: f64,
    /// The PSF FWHM the light budgets took, µm; `None` without a pixel size (see `psf_fwhm_px`).
    #[serde(serialize_with = "lab::opt_m_as_um", rename = "psf_fwhm_um")]
    pub psf_fwhm_m: Option<f64>,
    /// The same in pixels, the width the light budgets used.
    pub psf_fwhm_px: f64,
    /// Where it came from.
    pub psf_source: &'static str,
    /// The range of γ in s ∝ N^γ (the contact signal's trend with load) the draws took: the
    /// assumption's, capped by what the series' interiors allow; `None` for the edge band.
    pub signal_trend_exponent: Option<(f64, f64)>,
    /// How far above the top reading of an interior the signal may lie, in units of the gap
    /// between its top and mean readings; `None` for the edge band.
    pub porosity: Option<f64>,
    /// The smallest correlation area of a contact interior's holes the signal's range allows
    /// for (the porosity a wide PSF hides), µm²; `None` for the edge band.
    pub hole_area_um2: Option<f64>,
    /// Joint draws behind each interval; `None` for the edge band.
    pub draws: Option<usize>,
    /// Half-width w of the edge band's levels, as a fraction of the contact signal; `None` for
    /// the light budget.
    pub band_half_width: Option<f64>,
    /// Standard deviations of the edge band's noise term; `None` for the light budget.
    pub noise_sd_multiple: Option<f64>,
    /// The pixel size's relative uncertainty (bounds) the interval carries, 0 when the pixel
    /// size is taken as exact (or areas are in pixels).
    #[serde(
        rename = "pixel_size_uncertainty_pct",
        serialize_with = "lab::fraction_as_pct"
    )]
    pub pixel_size_uncertainty: f64,
    /// How the pixel size's uncertainty enters.
    pub calibration: &'static str,
    /// What the interval does not carry.
    pub not_included: &'static str,
}

impl AreaIntervalFacts {
    /// The facts of intervals from `model`, with the PSF taken, carrying the pixel size's relative uncertainty `u` (0: none).
    pub fn new(model: &IntervalModel, psf: Psf, u: f64) -> Self {
        use contactscope::analysis::interval::{EDGE_BAND_HALF_WIDTH, NOISE_WIDENING};
        let light = match model {
            IntervalModel::Light(l) => Some(l),
            IntervalModel::Band { .. } => None,
        };
        AreaIntervalFacts {
            model: if light.is_some() {
                "light_budget"
            } else {
                "edge_band"
            },
            method: if light.is_some() {
                "the light budget: each image's excess light over its fitted background, \
                 summed where the contact's light reaches, divided by the contact signal; \
                 the signal read in the contact interiors and carried to the other loads by \
                 s ∝ N^γ; signal, γ and the light's noise drawn jointly"
            } else {
                "edge band: pixels above b + (1/2 + w)·s (lo) and pixels above b + (1/2 − w)·s \
                 connected to the contact (hi), b and s the image's background and contact \
                 signal, widened by the pixel noise's spread; blind to the PSF"
            },
            why_edge_band: match model {
                IntervalModel::Band { why } => Some(why.clone()),
                IntervalModel::Light(_) => None,
            },
            level_pct: 95.0,
            psf_fwhm_m: psf.fwhm_m,
            psf_fwhm_px: psf.fwhm_px,
            psf_source: psf.source,
            signal_trend_exponent: light.map(|l| l.gamma_range()),
            porosity: light.map(|l| l.assumptions().porosity),
            hole_area_um2: light.map(|l| l.assumptions().hole_area_um2),
            draws: light.map(|_| contactscope::analysis::corrected::DRAWS),
            band_half_width: light.is_none().then_some(EDGE_BAND_HALF_WIDTH),
            noise_sd_multiple: light.is_none().then_some(NOISE_WIDENING),
            pixel_size_uncertainty: u,
            calibration: if u > 0.0 {
                "the pixel size within ±u of its value: lo × (1 − u)², hi × (1 + u)²; in the fit \
                 intervals one factor (1 + u·t)², t uniform on [−1, 1], shared by all images"
            } else {
                "none: the pixel size is taken as exact (give its uncertainty as \
                 --pixel-size 200nm±1% or --pixel-size-uncertainty 1%)"
            },
            not_included: match (light.is_some(), u > 0.0) {
                (true, true) => {
                    "the forces' calibration; a contact signal that varies over a contact by \
                     more than the illumination's 1 %; holes in a contact's interior finer than \
                     hole_area_um2; patches below the PSF at every load"
                }
                (true, false) => {
                    "the pixel size's calibration; the forces' calibration; a contact signal \
                     that varies over a contact by more than the illumination's 1 %; holes in a \
                     contact's interior finer than hole_area_um2; patches below the PSF at \
                     every load"
                }
                (false, true) => {
                    "the forces' calibration; what the PSF does to patches near its size \
                     (shrunk, vanished or bridged)"
                }
                (false, false) => {
                    "the pixel size's calibration; the forces' calibration; what the PSF does \
                     to patches near its size (shrunk, vanished or bridged)"
                }
            },
        }
    }
}

impl AnalyzeOutcome {
    /// The measured curve as `fit-hardening` reads it from this analysis's `areas.csv`: the
    /// images the fits use (a positive force, contact, none at the border), each contact-pixel
    /// area with its interval less the pixel size's calibration, widened to hold the pixel count
    /// (the interval is on the true area, and a model counted as imaged is compared with the
    /// count: [`crate::results::read_measured`]), and that calibration; `None` for areas in
    /// pixels or with fewer than two such images.
    pub fn measured_curve(&self) -> Option<contactscope::model_fit::Measured> {
        if self.area_unit != AreaUnit::SquareMicrometre {
            return None;
        }
        let u = self.rows.pixel_size_uncertainty;
        let (shrink, grow) = contactscope::analysis::bootstrap::calibration_bounds(u);
        let points = self
            .rows
            .rows
            .iter()
            .filter(|r| r.load_point().in_fit() && r.force_mn.is_some_and(|f| f > 0.0))
            .map(|r| {
                let (lo, hi) =
                    crate::results::interval_holding(r.area, r.area_lo / shrink, r.area_hi / grow);
                (
                    r.force_mn.unwrap_or(f64::NAN) * 1e-3,
                    r.area * 1e-12,
                    lo * 1e-12,
                    hi * 1e-12,
                )
            })
            .collect();
        contactscope::model_fit::Measured::with_intervals(points, u).ok()
    }

    /// Whether the series has loaded images and none of them can enter a fit (no contact, or
    /// contact cut off by the border, in every one): the command line exits with status 4.
    pub fn nothing_valid(&self) -> bool {
        let points: Vec<_> = self.rows.rows.iter().map(Row::load_point).collect();
        fits::nothing_valid(&points)
    }
}

/// Images given twice (the same page of the same file), and images with contact whose
/// measurements are identical to the last digit (the same image under two names): a series that
/// repeats an image fits the same point twice.
fn duplicate_warnings(series: &Series, rows: &[Row]) -> Vec<String> {
    let mut out = Vec::new();
    let name = |i: usize| {
        let image = &series.images[i];
        format!("{} (page {})", image.path.display(), image.page)
    };
    let mut seen: std::collections::HashMap<(&std::path::Path, usize), usize> =
        std::collections::HashMap::new();
    let mut measured: std::collections::HashMap<(u64, u64, u64, u64), usize> =
        std::collections::HashMap::new();
    for (i, (image, row)) in series.images.iter().zip(rows).enumerate() {
        if let Some(&first) = seen.get(&(image.path.as_path(), image.page)) {
            out.push(format!(
                "{} is given twice (images {} and {}): the fits count it twice",
                name(i),
                first + 1,
                i + 1
            ));
            continue;
        }
        seen.insert((image.path.as_path(), image.page), i);
        if row.contact_pixels == 0 {
            continue;
        }
        let key = (
            row.contact_pixels,
            row.integrated_intensity.to_bits(),
            row.background_mean.unwrap_or(f64::NAN).to_bits(),
            row.patches,
        );
        if let Some(&first) = measured.get(&key) {
            out.push(format!(
                "{} and {} give identical measurements (the same image twice?)",
                name(first),
                name(i)
            ));
        } else {
            measured.insert(key, i);
        }
    }
    out
}

/// Run `analyze` in memory. `sink` receives each image's plane and contact mask in pass 2
/// (overlays, saved masks, layers of a viewer); calls may come from several threads.
pub fn run(
    request: &AnalyzeRequest,
    progress: Progress,
    sink: ImageSink,
) -> Result<AnalyzeOutcome> {
    request.check()?;
    let open = request.micrographs.open()?;
    run_open(request, &open, progress, sink)
}

/// [`run`] on a series already opened (the folder writer needs its files first).
pub fn run_open(
    request: &AnalyzeRequest,
    open: &OpenSeries,
    progress: Progress,
    sink: ImageSink,
) -> Result<AnalyzeOutcome> {
    let series = &open.series;
    series::refuse_maps(series)?;
    let mut warnings = Vec::new();
    let pixel_size = series::pixel_size(
        series,
        request.pixel_size_m,
        request.pixel_size_default_m,
        &mut warnings,
    )?;
    let options = AnalysisOptions {
        method: request.method,
        pixel_size,
        psf_sigma_px: request
            .psf_fwhm_m
            .zip(pixel_size)
            .map(|(f, p)| f / FWHM_PER_SIGMA / p.x_m.min(p.y_m)),
        light_budgets: true,
    };
    // What the light budgets take (`AnalysisOptions::light_sigma_px`), in both units.
    let fwhm_px = options.light_sigma_px() * FWHM_PER_SIGMA;
    let psf = Psf {
        fwhm_m: pixel_size.map(|p| fwhm_px * p.x_m.min(p.y_m)),
        fwhm_px,
        source: match (request.psf_fwhm_m, pixel_size) {
            (Some(_), Some(_)) => "given",
            (None, Some(_)) => "not given: 1 µm, wider than a confocal microscope's",
            (_, None) => {
                "no pixel size: psf_fwhm_px taken, wider than a confocal \
                          microscope's at 200 nm pixels"
            }
        },
    };
    if request.psf_fwhm_m.is_some() && pixel_size.is_none() {
        warnings.push(format!(
            "{} is not used without a pixel size: the area intervals take a PSF of {} pixels",
            Param::PsfFwhm,
            short(fwhm_px)
        ));
    }
    let mut analysis = analysis::analyze(
        &open.planes(request.memory_budget),
        &options,
        progress,
        sink,
    )?;
    warnings.append(&mut analysis.warnings);
    let (rows, fits, model) = report::table_and_fits(
        series,
        &analysis,
        request.hertz,
        request.pixel_size_uncertainty,
    );
    if request.pixel_size_uncertainty > 0.0 && rows.unit == AreaUnit::Pixel {
        warnings.push(format!(
            "{} is ignored: without a pixel size the areas are in pixels",
            Param::PixelSizeUncertainty
        ));
    }
    for (row, image) in rows.rows.iter().zip(&series.images) {
        let (Some(p), Some(f)) = (row.mean_pressure_mpa, row.force_mn) else {
            continue;
        };
        if let Some(why) = fits::implausible_pressure(p * 1e6) {
            warnings.push(format!(
                "{} (page {}): mean pressure {} MPa at {} mN is {why}; are the forces ({}) or \
                 the pixel size ({}) in another unit?",
                image.path.display(),
                image.page,
                short(p),
                short(f),
                Param::Forces,
                Param::PixelSize
            ));
        }
    }
    if rows.rows.iter().all(|r| r.force_mn.is_none()) {
        warnings.push(format!(
            "no forces: areas, intensities and patches per image, but no area–load fits or plot \
             (give {} or {})",
            Param::Forces,
            Param::Manifest
        ));
    }
    let points: Vec<_> = rows.rows.iter().map(Row::load_point).collect();
    warnings.extend(fits::exclusion_warnings(&points, Source::Micrographs));
    warnings.extend(fits::power_law_warnings(fits.power_law.as_ref(), &points));
    if let IntervalModel::Band { why } = &model {
        warnings.push(format!(
            "the area intervals are the edge band's, which does not model the PSF (patches near \
             its size may lie outside them): {why}"
        ));
    }
    if let (Some(p), Some(i), IntervalModel::Light(_)) =
        (fits.power_law, fits.intervals.as_ref(), &model)
    {
        let (lo, hi) = i.exponent;
        if p.exponent < lo || p.exponent > hi {
            warnings.push(format!(
                "the contact pixels' exponent β = {:.3} lies outside the 95 % interval on the \
                 true exponent, {lo:.3}…{hi:.3}: the PSF biases the pixel count (patches near \
                 its size shrink at light loads and merge at heavy ones); the corrected areas \
                 give β = {}",
                p.exponent,
                fits.power_law_corrected
                    .map_or("—".to_string(), |c| format!("{:.3}", c.exponent))
            ));
        }
    }
    warnings.extend(duplicate_warnings(series, &rows.rows));
    if rows.rows.iter().all(|r| r.contact_pixels == 0) {
        warnings.push(format!(
            "no image has contact pixels at the threshold ({}): areas are 0, no fits or plot",
            Param::Threshold
        ));
    }
    analysis.warnings = warnings.clone();
    Ok(AnalyzeOutcome {
        inputs: InputFacts::of(series, &analysis),
        threshold: ThresholdFacts::of(&analysis, open.sample_type().is_integer()),
        area_unit: rows.unit,
        fits,
        area_interval: AreaIntervalFacts::new(&model, psf, rows.pixel_size_uncertainty),
        hertz: request.hertz,
        warnings,
        rows,
        analysis,
    })
}
