//! The `psf` job: the microscope's point-spread function from sub-resolution beads (Weber et al.
//! 2018, Methods: Microscopy; docs/methods.md §7.3; the measurement is
//! [`contactscope::optics::psf`]). Every front-end builds a [`PsfRequest`] (the command line
//! from a file and its selection flags, Python from a file or an array in its stored sample
//! type), [`PsfRequest::check`] applies the same range checks, and [`run`] returns a
//! [`PsfOutcome`]: its serialisation is `psf.json` with the rows of `beads.csv` (`beads`), in
//! lab units, and the Python result in SI units. [`files`] writes the folder.

pub mod files;

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use contactscope::image::{Image, SampleType};
use contactscope::numerics::stats::MeanSd;
use contactscope::optics::psf::{
    measure_psf, BeadMeasurement, PsfOptions, PsfReport, FWHM_PER_SIGMA,
};
use contactscope_formats::microscopy::select::{is_tiff, LoadAxis, Selection};
use contactscope_formats::microscopy::MicroscopyFile;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;
use contactscope_formats::tiff::TiffReader;

use crate::error::{Error, Result};
use crate::images::ImageInput;
use crate::lab::{self, Unit, Q};

/// Everything `psf` needs. SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct PsfRequest {
    /// Bead image or z stack: a file (TIFF: every page of the chosen channel; CZI, ND2, LIF:
    /// every z plane of the selection, or the one plane its `z` names) or planes in memory.
    pub beads: ImageInput,
    /// Which planes of the file.
    pub selection: Selection,
    /// Pixel size (x, y), m, overriding the file's metadata (needed for planes in memory).
    pub pixel_size_m: Option<(f64, f64)>,
    /// Bead diameter, m: turns on the finite-bead correction σ² − a²/5.
    pub bead_diameter_m: Option<f64>,
    /// The detector's saturation level in the data's units; `None`: from the sample type
    /// ([`saturation_level`]).
    pub saturation_level: Option<f64>,
}

impl PsfRequest {
    /// A request with the defaults: the file's pixel size, no bead correction, the saturation
    /// level of the sample type.
    pub fn new(beads: ImageInput) -> Self {
        PsfRequest {
            beads,
            selection: Selection::default(),
            pixel_size_m: None,
            bead_diameter_m: None,
            saturation_level: None,
        }
    }

    /// Every range check, the same for every front-end.
    pub fn check(&self) -> Result<()> {
        self.beads.check(&self.selection, self.pixel_size_m)?;
        if let Some((x, y)) = self.pixel_size_m {
            Quantity::PixelSize.check(x, Param::PixelSize)?;
            Quantity::PixelSize.check(y, Param::PixelSize)?;
        }
        if let Some(d) = self.bead_diameter_m {
            Quantity::Length.check(d, Param::BeadDiameter)?;
        }
        if let Some(s) = self.saturation_level {
            if !s.is_finite() {
                return Err(Error::InvalidArgument(format!(
                    "{}: the saturation level {s} is not a finite number",
                    Param::SaturationLevel
                )));
            }
        }
        Ok(())
    }
}

/// One candidate bead and what became of it: a row of `beads.csv` (`beads` of the outcome).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BeadRow {
    /// Index among the candidates (brightest first).
    pub bead: usize,
    /// Centre of the 2-D fit, else the detected pixel: column.
    pub x_px: f64,
    /// Row of the same.
    pub y_px: f64,
    /// Best-focus plane within the stack.
    pub plane: usize,
    /// TIFF page (or plane along z) of that plane.
    pub page: usize,
    /// The centre's x, m.
    #[serde(rename = "x_um", serialize_with = "lab::m_as_um")]
    pub x_m: f64,
    /// The centre's y (with the x pixel size, as the PSF takes square pixels), m.
    #[serde(rename = "y_um", serialize_with = "lab::m_as_um")]
    pub y_m: f64,
    /// Highest raw value in the 3 × 3 pixels around the candidate.
    pub peak: f64,
    /// Border-median background of the window.
    pub background: Option<f64>,
    /// Centre of intensity, column.
    pub centroid_x_px: Option<f64>,
    /// Centre of intensity, row.
    pub centroid_y_px: Option<f64>,
    /// Reported σ (bead-corrected when a diameter was given), m.
    #[serde(rename = "sigma_nm", serialize_with = "lab::opt_m_as_nm")]
    pub sigma_m: Option<f64>,
    /// FWHM of the same, m.
    #[serde(rename = "fwhm_nm", serialize_with = "lab::opt_m_as_nm")]
    pub fwhm_m: Option<f64>,
    /// Radial σ of the image spot (no correction), m.
    #[serde(rename = "sigma_raw_nm", serialize_with = "lab::opt_m_as_nm")]
    pub sigma_raw_m: Option<f64>,
    /// 2-D fit σ along x, m.
    #[serde(rename = "sigma_x_nm", serialize_with = "lab::opt_m_as_nm")]
    pub sigma_x_m: Option<f64>,
    /// 2-D fit σ along y, m.
    #[serde(rename = "sigma_y_nm", serialize_with = "lab::opt_m_as_nm")]
    pub sigma_y_m: Option<f64>,
    /// 1 − σ_min/σ_max of the 2-D fit.
    pub ellipticity: Option<f64>,
    /// Relative rms residual of the radial fit.
    pub fit_rms_rel: Option<f64>,
    /// Whether the bead enters the summary.
    pub used: bool,
    /// Why not, in words.
    pub skip_reason: Option<String>,
}

/// A bead left out of the summary (`skipped` of `psf.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkippedBead {
    /// Index among the candidates.
    pub bead: usize,
    /// Column of its centre.
    pub x_px: f64,
    /// Row of its centre.
    pub y_px: f64,
    /// Best-focus plane.
    pub plane: usize,
    /// Why, as a key (`crowded`, `saturated`, …).
    pub reason: &'static str,
    /// Why, in words.
    pub detail: String,
}

/// Detection statistics (`detection` of `psf.json`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DetectionFacts {
    /// Median of the (projected) smoothed image.
    pub background: f64,
    /// 1.4826 × MAD of the same.
    pub noise: f64,
    /// Detection level.
    pub threshold: f64,
    /// First σ estimate from the half-maximum areas, pixels.
    pub sigma_guess_px: f64,
}

/// The method as `psf.json` records it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PsfMethod {
    /// Where it comes from.
    pub reference: &'static str,
    /// Window width, pixels.
    pub window_px: usize,
    /// Background estimate.
    pub background: &'static str,
    /// Centre estimate.
    pub centre: &'static str,
    /// Radial bin width, pixels.
    pub radial_bin_px: f64,
    /// The radial fit (the summary's).
    pub radial_fit: &'static str,
    /// The 2-D cross-check.
    pub fit_2d: &'static str,
    /// 2√(2 ln 2).
    pub fwhm_per_sigma: f64,
}

/// Mean and sd over the used beads of σ and of the FWHM it gives, m: the `sigma_nm_mean`,
/// `fwhm_nm_sd`, … entries of `psf.json`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PsfSpreads {
    /// Reported σ (bead-corrected when asked).
    pub sigma_m: MeanSd,
    /// σ of the image spots.
    pub sigma_raw_m: MeanSd,
    /// 2-D fit σ along x.
    pub sigma_x_m: MeanSd,
    /// 2-D fit σ along y.
    pub sigma_y_m: MeanSd,
}

/// A σ written as the FWHM it gives: in nm as `σ·(1e9·FWHM_PER_SIGMA)` (the product the files
/// always used), in SI as `σ·FWHM_PER_SIGMA`.
struct FwhmOfSigma(f64);

impl Serialize for FwhmOfSigma {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_f64(if lab::si() {
            self.0 * FWHM_PER_SIGMA
        } else {
            self.0 * (1e9 * FWHM_PER_SIGMA)
        })
    }
}

impl Serialize for PsfSpreads {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(12))?;
        for (name, v, fwhm) in [
            ("sigma_nm", self.sigma_m, false),
            ("fwhm_nm", self.sigma_m, true),
            ("sigma_raw_nm", self.sigma_raw_m, false),
            ("fwhm_raw_nm", self.sigma_raw_m, true),
            ("sigma_x_2d_nm", self.sigma_x_m, false),
            ("sigma_y_2d_nm", self.sigma_y_m, false),
        ] {
            if fwhm {
                m.serialize_entry(&format!("{name}_mean"), &FwhmOfSigma(v.mean))?;
                m.serialize_entry(&format!("{name}_sd"), &v.sd.map(FwhmOfSigma))?;
            } else {
                m.serialize_entry(&format!("{name}_mean"), &Q(v.mean, Unit::MAsNm))?;
                m.serialize_entry(&format!("{name}_sd"), &v.sd.map(|sd| Q(sd, Unit::MAsNm)))?;
            }
        }
        m.end()
    }
}

/// What `psf` found: `psf.json` (without `beads`, which is `beads.csv`).
#[derive(Debug, Clone, Serialize)]
pub struct PsfOutcome {
    /// The file as given, or the label of the planes in memory.
    pub input: String,
    /// Planes analysed.
    pub planes: usize,
    /// Pixel size (square), m.
    #[serde(rename = "pixel_size_nm", serialize_with = "lab::m_as_nm")]
    pub pixel_size_m: f64,
    /// Where the pixel size came from.
    pub pixel_size_source: &'static str,
    /// Candidates found.
    pub beads_found: usize,
    /// Beads in the summary.
    pub beads_used: usize,
    /// Bead diameter of the correction, m.
    #[serde(rename = "bead_diameter_nm", serialize_with = "lab::opt_m_as_nm")]
    pub bead_diameter_m: Option<f64>,
    /// Whether the finite-bead correction was applied.
    pub bead_correction_applied: bool,
    /// The correction, as a formula.
    pub bead_correction: &'static str,
    /// Which fit the summary comes from.
    pub summary_from: &'static str,
    /// The method.
    pub method: PsfMethod,
    /// Detection statistics.
    pub detection: DetectionFacts,
    /// Saturation level checked against (`None`: float data, no check).
    pub saturation_level: Option<f64>,
    /// Beads left out, and why.
    pub skipped: Vec<SkippedBead>,
    /// σ and FWHM over the used beads.
    #[serde(flatten)]
    pub summary: PsfSpreads,
    /// Every candidate: `beads.csv`.
    pub beads: Vec<BeadRow>,
    /// The measurement itself (fits and profiles), for printing and plotting.
    #[serde(skip)]
    pub report: PsfReport,
}

/// Run `psf` in memory: check the request, read the beads, measure.
pub fn run(request: &PsfRequest) -> Result<PsfOutcome> {
    request.check()?;
    let along = request.selection.z.is_none().then_some(LoadAxis::Z);
    let images = request
        .beads
        .read(&request.selection, along, request.pixel_size_m)?;
    let saturation_level = match request.saturation_level {
        Some(level) => Some(level),
        None => saturation_level(stored_type(&request.beads, &request.selection)?, &images),
    };
    let options = PsfOptions {
        bead_diameter_m: request.bead_diameter_m,
        saturation_level,
        ..PsfOptions::default()
    };
    let report = measure_psf(&images, &options)?;
    Ok(outcome(request.beads.label(), report))
}

/// The sample type of the beads and its significant bits: a TIFF's own, a CZI, ND2 or LIF
/// series' type with all its bits, planes in memory with all the bits of their type.
fn stored_type(beads: &ImageInput, selection: &Selection) -> Result<(SampleType, u8)> {
    let path = match beads {
        ImageInput::Memory(m) => {
            let bits = match m.sample_type {
                SampleType::U8 => 8,
                _ => 16,
            };
            return Ok((m.sample_type, bits));
        }
        ImageInput::File(path) => path,
    };
    Ok(if is_tiff(path) {
        let info = TiffReader::open(path)?.info().clone();
        (info.sample_type, info.bits_per_sample)
    } else {
        let file = MicroscopyFile::open(path)?;
        let series = file
            .series
            .get(selection.series.unwrap_or(0))
            .ok_or_else(|| Error::InvalidArgument("no such series".into()))?;
        let bits = match series.dtype {
            SampleType::U8 => 8,
            _ => 16,
        };
        (series.dtype, bits)
    })
}

/// The detector's full-scale value: the sample type's maximum code, except that 16-bit data
/// whose maximum does not exceed 4095 is taken as 12-bit data in a 16-bit container (as the
/// paper's 4096-grey-level confocal images are), saturating at 4095. Floats: no check.
pub fn saturation_level(
    (sample_type, bits_per_sample): (SampleType, u8),
    images: &[Image],
) -> Option<f64> {
    let data_max = images
        .iter()
        .flat_map(|im| im.values.iter().copied())
        .fold(f64::NEG_INFINITY, f64::max);
    let full = |bits: u8| f64::from((1u32 << bits.min(16)) - 1);
    match sample_type {
        SampleType::U8 => Some(full(bits_per_sample.min(8))),
        SampleType::U16 if data_max <= 4095.0 => Some(4095.0),
        SampleType::U16 => Some(full(bits_per_sample)),
        SampleType::I16 => Some(32767.0),
        SampleType::F32 | SampleType::F64 => None,
    }
}

fn outcome(input: String, report: PsfReport) -> PsfOutcome {
    let s = &report.summary;
    let px_m = report.pixel_size.x_m;
    let beads = report
        .beads
        .iter()
        .enumerate()
        .map(|(i, b)| bead_row(i, b, px_m))
        .collect();
    let skipped = report
        .beads
        .iter()
        .enumerate()
        .filter_map(|(i, b)| {
            let why = b.skip.as_ref()?;
            let (x, y) = bead_position(b);
            Some(SkippedBead {
                bead: i,
                x_px: x,
                y_px: y,
                plane: b.candidate.plane,
                reason: why.key(),
                detail: why.to_string(),
            })
        })
        .collect();
    PsfOutcome {
        input,
        planes: report.planes,
        pixel_size_m: px_m,
        pixel_size_source: report.pixel_size.source.describe(),
        beads_found: report.beads.len(),
        beads_used: s.beads_used,
        bead_diameter_m: report.bead_diameter_m,
        bead_correction_applied: report.bead_diameter_m.is_some(),
        bead_correction:
            "sigma_psf^2 = sigma_img^2 - a^2/5, a = diameter/2 (uniform sphere in projection)",
        summary_from:
            "radial-profile fit (paper-faithful); 2-D Gaussian fit reported as a cross-check",
        method: PsfMethod {
            reference:
                "Weber et al., Nat. Commun. 9, 888 (2018), Methods: Microscopy; docs/methods.md §7.3",
            window_px: 2 * report.half_window_px + 1,
            background: "median of the window border",
            centre: "centre of intensity over pixels above 0.2 of the peak, 3 re-centring passes",
            radial_bin_px: 0.5,
            radial_fit: "I0*exp(-r^2/(2 sigma^2)) + c, Levenberg-Marquardt, model averaged over each bin's pixels, bins weighted by sqrt(pixel count)",
            fit_2d: "axis-aligned elliptical Gaussian with free centre and offset, Levenberg-Marquardt over all window pixels",
            fwhm_per_sigma: FWHM_PER_SIGMA,
        },
        detection: DetectionFacts {
            background: report.detection.background,
            noise: report.detection.noise,
            threshold: report.detection.threshold,
            sigma_guess_px: report.detection.sigma_guess_px,
        },
        saturation_level: report.saturation_level,
        skipped,
        summary: PsfSpreads {
            sigma_m: s.sigma_m,
            sigma_raw_m: s.sigma_raw_m,
            sigma_x_m: s.sigma_x_m,
            sigma_y_m: s.sigma_y_m,
        },
        beads,
        report,
    }
}

fn bead_row(i: usize, b: &BeadMeasurement, px_m: f64) -> BeadRow {
    let fit = b.fit.as_ref();
    let (x, y) = bead_position(b);
    let g = fit.map(|f| &f.gauss2d);
    BeadRow {
        bead: i,
        x_px: x,
        y_px: y,
        plane: b.candidate.plane,
        page: b.page,
        x_m: x * px_m,
        y_m: y * px_m,
        peak: b.raw_peak,
        background: fit.map(|f| f.background),
        centroid_x_px: fit.map(|f| f.centroid_px.0),
        centroid_y_px: fit.map(|f| f.centroid_px.1),
        sigma_m: b.sigma_m,
        fwhm_m: b.sigma_m.map(|s| s * FWHM_PER_SIGMA),
        sigma_raw_m: b.sigma_raw_m,
        sigma_x_m: g.map(|g| g.sigma_x_px * px_m),
        sigma_y_m: g.map(|g| g.sigma_y_px * px_m),
        ellipticity: g
            .map(|g| 1.0 - g.sigma_x_px.min(g.sigma_y_px) / g.sigma_x_px.max(g.sigma_y_px)),
        fit_rms_rel: fit.map(|f| f.radial.rms_rel),
        used: b.skip.is_none(),
        skip_reason: b.skip.as_ref().map(|s| s.to_string()),
    }
}

/// The 2-D fit's centre when there is one, else the detected pixel.
fn bead_position(b: &BeadMeasurement) -> (f64, f64) {
    b.fit
        .as_ref()
        .map_or((b.candidate.x as f64, b.candidate.y as f64), |f| {
            (f.gauss2d.x_px, f.gauss2d.y_px)
        })
}

#[cfg(test)]
mod tests;
