//! The `autocorr` job: radially averaged intensity autocorrelations of several images (an
//! experiment and a simulation, say) with their correlation lengths, so they can be compared as
//! in Weber et al. 2018 (patch scale ≈ 5 µm). The estimator and its choices are in
//! [`contactscope::spectral::autocorrelation`]. Every front-end builds an [`AutocorrRequest`]
//! (the command line from files, Python from files or an array stack), [`AutocorrRequest::check`]
//! applies the same range checks, and [`run`] returns an [`AutocorrOutcome`]: its serialisation
//! is `autocorr.json` (lab units) and the Python result (SI units); the curves themselves
//! (`autocorr.csv`, numpy arrays in Python) travel beside it. [`files`] writes the folder.

pub mod files;

#[cfg(feature = "plots")]
pub use files::acf_chart;

use serde::Serialize;

use contactscope::image::Image;
use contactscope::spectral::autocorrelation::AcfCurve;
use contactscope_formats::microscopy::select::Selection;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use crate::error::{Error, Location, Result};
use crate::images::ImageInput;
use crate::lab;

/// Everything `autocorr` needs. SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct AutocorrRequest {
    /// The images: files (every page of a multi-page TIFF is one image; a CZI, ND2 or LIF file
    /// gives the one plane the selection names) or planes in memory (each plane one image).
    pub inputs: Vec<ImageInput>,
    /// Which plane of confocal files (and the channel of TIFFs).
    pub selection: Selection,
    /// Pixel size (x, y), m, overriding the files' metadata (needed for planes in memory).
    pub pixel_size_m: Option<(f64, f64)>,
    /// Largest lag, m; by default (and at most) half the smaller side of each image.
    pub max_lag_m: Option<f64>,
}

impl AutocorrRequest {
    /// A request with the defaults: the files' pixel size, lags up to half the smaller side.
    pub fn new(inputs: Vec<ImageInput>) -> Self {
        AutocorrRequest {
            inputs,
            selection: Selection::default(),
            pixel_size_m: None,
            max_lag_m: None,
        }
    }

    /// Every range check, the same for every front-end.
    pub fn check(&self) -> Result<()> {
        if self.inputs.is_empty() {
            return Err(Error::InvalidArgument("no input images given".into()));
        }
        for input in &self.inputs {
            input.check(&self.selection, self.pixel_size_m)?;
        }
        if let Some((x, y)) = self.pixel_size_m {
            Quantity::PixelSize.check(x, Param::PixelSize)?;
            Quantity::PixelSize.check(y, Param::PixelSize)?;
        }
        if let Some(lag) = self.max_lag_m {
            Quantity::Length.check(lag, Param::MaxLag)?;
        }
        Ok(())
    }
}

/// The estimator as `autocorr.json` records it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcfMethod {
    /// The estimator.
    pub estimator: &'static str,
    /// The radial average.
    pub radial_average: &'static str,
    /// How the 1/e correlation length is read off.
    pub correlation_length_um_1e: &'static str,
    /// How the first zero is read off.
    pub first_zero_um: &'static str,
}

/// One image and its correlation lengths (`images` of `autocorr.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AcfImage {
    /// Name of its curve: the file name, with `:page N` for multi-page files.
    pub image: String,
    /// The file (or the label of the planes in memory).
    pub file: String,
    /// Its page (or plane).
    pub page: usize,
    /// Columns.
    pub width_px: usize,
    /// Rows.
    pub height_px: usize,
    /// Pixel size along x, m.
    #[serde(rename = "pixel_size_x_nm", serialize_with = "lab::m_as_nm")]
    pub pixel_size_x_m: f64,
    /// Pixel size along y, m.
    #[serde(rename = "pixel_size_y_nm", serialize_with = "lab::m_as_nm")]
    pub pixel_size_y_m: f64,
    /// Largest lag used, m.
    #[serde(rename = "max_lag_um", serialize_with = "lab::m_as_um")]
    pub max_lag_m: f64,
    /// First lag with C ≤ 1/e, m.
    #[serde(
        rename = "correlation_length_um_1e",
        serialize_with = "lab::opt_m_as_um"
    )]
    pub correlation_length_m_1e: Option<f64>,
    /// First lag with C ≤ 0, m.
    #[serde(rename = "first_zero_um", serialize_with = "lab::opt_m_as_um")]
    pub first_zero_m: Option<f64>,
}

/// What `autocorr` found: `autocorr.json`; the curves are `autocorr.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct AutocorrOutcome {
    /// The estimator.
    pub method: AcfMethod,
    /// One entry per image, in input order.
    pub images: Vec<AcfImage>,
    /// Notes for the user (lags clamped, no correlation length within the lags).
    pub warnings: Vec<String>,
    /// One curve per image, in input order: (lag in m, C).
    #[serde(skip)]
    pub curves: Vec<AcfCurve>,
}

/// Run `autocorr` in memory: check the request, read every image, compute its curve.
pub fn run(request: &AutocorrRequest) -> Result<AutocorrOutcome> {
    request.check()?;
    let mut images = Vec::new();
    for input in &request.inputs {
        let pages = input.read(&request.selection, None, request.pixel_size_m)?;
        let multi = pages.len() > 1;
        images.extend(pages.into_iter().map(|im| (label_of(&im, multi), im)));
    }
    let mut warnings = Vec::new();
    let mut curves = Vec::new();
    let mut facts = Vec::new();
    for (label, image) in &images {
        let (curve, fact) = image_curve(label, image, request.max_lag_m, &mut warnings)?;
        curves.push(curve);
        facts.push(fact);
    }
    Ok(AutocorrOutcome {
        method: AcfMethod {
            estimator: "mean-subtracted intensity, zero-padded FFT (no wrap-around), unbiased: divided by the pair count per lag, C(0) = 1",
            radial_average: "rings one pixel wide, weighted by pair counts; lags with under a quarter of the zero-lag pairs dropped",
            correlation_length_um_1e: "first lag with C <= 1/e, linear interpolation",
            first_zero_um: "first lag with C <= 0, linear interpolation; null if C stays positive",
        },
        images: facts,
        warnings,
        curves,
    })
}

fn label_of(image: &Image, multi_page: bool) -> String {
    let name = image.path.file_name().map_or_else(
        || image.path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    if multi_page {
        format!("{name}:page {}", image.page)
    } else {
        name
    }
}

fn image_curve(
    label: &str,
    image: &Image,
    max_lag_m: Option<f64>,
    warnings: &mut Vec<String>,
) -> Result<(AcfCurve, AcfImage)> {
    let px = image.require_pixel_size()?;
    let half_side = 0.5 * (image.width as f64 * px.x_m).min(image.height as f64 * px.y_m);
    let lag = match max_lag_m {
        Some(l) if l > half_side => {
            warnings.push(format!(
                "{label}: {} {:.3} µm exceeds half the image ({:.3} µm), where the estimate \
                 rests on few pixel pairs; using {:.3} µm",
                Param::MaxLag,
                l * 1e6,
                half_side * 1e6,
                half_side * 1e6
            ));
            half_side
        }
        Some(l) => l,
        None => half_side,
    };
    let at = Location::page(&image.path, image.page);
    let curve = AcfCurve::of_grid(
        label,
        &image.values,
        (image.width, image.height),
        (px.x_m, px.y_m),
        lag,
    )
    .map_err(|e| Error::bad_input(at, e.to_string()))?;
    if curve.xi_1e_m.is_none() {
        warnings.push(format!(
            "{label}: C(r) stays above 1/e up to {:.3} µm; no correlation length within the lags",
            lag * 1e6
        ));
    }
    let facts = AcfImage {
        image: curve.label.clone(),
        file: path_text(&image.path),
        page: image.page,
        width_px: image.width,
        height_px: image.height,
        pixel_size_x_m: px.x_m,
        pixel_size_y_m: px.y_m,
        max_lag_m: lag,
        correlation_length_m_1e: curve.xi_1e_m,
        first_zero_m: curve.first_zero_m,
    };
    Ok((curve, facts))
}

fn path_text(path: &std::path::Path) -> String {
    path.display().to_string()
}
