//! The load-series analysis: planes → one threshold → measure, in two passes over a
//! [`PlaneSource`], and the area–load fits ([`fit`]).
//!
//! Pass 1 visits every image once and accumulates the series histogram (per-image histograms
//! merged into one; for float data the finite range first, then a second histogram pass). The
//! threshold is chosen from the pooled histogram. Pass 2 classifies and measures each image
//! (with its light budget or its edge band: [`ImageResult`]); a series with light budgets whose
//! fields leave an image without one gets a third pass for every image's edge band
//! ([`needs_bands`]).
//!
//! The analysis never opens a file: it asks its source for planes. A slice of in-memory
//! [`Plane`]s is a source; the file-backed source of a load series
//! (`contactscope_jobs::series::SeriesPlanes`) decodes pages on demand, in parallel runs of images of one
//! file, and keeps decoded planes of compressed files between the passes up to a memory budget,
//! so a 500-image series never needs 500 images in memory.

pub mod bootstrap;
pub mod corrected;
pub mod fit;
pub mod interval;
pub mod light;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::image::{PixelSize, Plane, SampleType, Samples};
use crate::measure::{measure, measure_with_tiles, Mask, Measurement};
use crate::threshold::{
    histogram, Binning, FloatBinning, Histogram, Method, Threshold, FLOAT_BINS,
};

/// How to analyse a series.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AnalysisOptions {
    /// Threshold method.
    pub method: Method,
    /// The series' pixel size (recorded with the result; areas are in pixels without one).
    pub pixel_size: Option<PixelSize>,
    /// The PSF's standard deviation in pixels, for each image's light budget ([`light`]);
    /// `None`: not known, and [`UNKNOWN_PSF_SIGMA_PX`] (or the widest PSF of a confocal
    /// microscope, [`corrected::UNKNOWN_PSF_FWHM_M`], with a pixel size) is used.
    pub psf_sigma_px: Option<f64>,
    /// Whether each image's light budget is measured ([`ImageResult::light`]; about 1 ms of one
    /// core per 1024² image, the tile sums and the budget); off by default.
    pub light_budgets: bool,
}

/// The PSF's standard deviation taken when neither the PSF nor the pixel size is known, pixels.
pub const UNKNOWN_PSF_SIGMA_PX: f64 = 2.5;

impl AnalysisOptions {
    /// The PSF's standard deviation the light budgets use, pixels (field docs).
    pub fn light_sigma_px(&self) -> f64 {
        match (self.psf_sigma_px, self.pixel_size) {
            (Some(s), _) => s,
            (None, Some(p)) => {
                corrected::UNKNOWN_PSF_FWHM_M
                    / crate::optics::blur::FWHM_PER_SIGMA
                    / p.x_m.min(p.y_m)
            }
            (None, None) => UNKNOWN_PSF_SIGMA_PX,
        }
    }
}

/// A load series' planes as the analysis sees them: a number of images that share one sample
/// type and size, visited in parallel.
pub trait PlaneSource: Sync {
    /// Number of images.
    fn len(&self) -> usize;

    /// Whether there are no images.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sample type every image has.
    fn sample_type(&self) -> SampleType;

    /// Image `index` as messages name it (e.g. `a.tif (page 3)`).
    fn label(&self, index: usize) -> String;

    /// `f` applied to every image, possibly in parallel and in any order. Results come back in
    /// image order; the first error in image order is returned. A plane that does not match the
    /// series' first image (size, sample type) is an error.
    fn scan<T: Send, F: Fn(usize, &Plane) -> Result<T> + Sync>(&self, f: F) -> Result<Vec<T>>;
}

/// In-memory planes, in load order.
impl PlaneSource for [Plane] {
    fn len(&self) -> usize {
        <[Plane]>::len(self)
    }

    fn sample_type(&self) -> SampleType {
        self.first().map_or(SampleType::U16, |p| p.sample_type)
    }

    fn label(&self, index: usize) -> String {
        format!("image {index}")
    }

    fn scan<T: Send, F: Fn(usize, &Plane) -> Result<T> + Sync>(&self, f: F) -> Result<Vec<T>> {
        let first = self.first();
        self.par_iter()
            .enumerate()
            .map(|(i, plane)| {
                if let Some(first) = first.filter(|p| {
                    (p.width, p.height, p.sample_type)
                        != (plane.width, plane.height, plane.sample_type)
                }) {
                    return Err(Error::InvalidArgument(format!(
                        "image {i} is {}×{} {}; the series started with {}×{} {}",
                        plane.width,
                        plane.height,
                        plane.sample_type.name(),
                        first.width,
                        first.height,
                        first.sample_type.name()
                    )));
                }
                f(i, plane)
            })
            .collect()
    }
}

/// The result for one image.
#[derive(Debug, Clone)]
pub struct ImageResult {
    /// The threshold applied to it.
    pub threshold: Threshold,
    /// What was measured.
    pub measurement: Measurement,
    /// The edge band on its contact area ([`interval`]): every image without light budgets;
    /// with them, an image without one, or every image of a series where an image with contact
    /// clear of the border has none ([`Analysis::needs_bands`]); else `None`.
    pub band: Option<interval::AreaBand>,
    /// Its light budget ([`light`]); `None` without light or without background blocks far
    /// from the contact.
    pub light: Option<light::LightBudget>,
}

/// The result for a series.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// Per-image results in input order.
    pub images: Vec<ImageResult>,
    /// The method used.
    pub method: Method,
    /// The series threshold (global Otsu or manual); `None` for per-image thresholds.
    pub series_threshold: Option<Threshold>,
    /// Pixels in the histogram the threshold came from (all finite pixels of the series).
    pub histogram_pixels: u64,
    /// The pixel size used for areas; `None` means areas are in pixels.
    pub pixel_size: Option<PixelSize>,
    /// The series' sample type (integer data have a ceiling: [`corrected`]).
    pub sample_type: SampleType,
    /// The PSF's standard deviation the light budgets used, pixels
    /// ([`AnalysisOptions::light_sigma_px`]).
    pub light_sigma_px: f64,
    /// Things the user should know (missing pixel size, non-finite pixels, …).
    pub warnings: Vec<String>,
}

/// Which pass is running, for progress reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pass {
    /// Reading and histogramming.
    Histogram,
    /// Classifying and measuring.
    Measure,
}

/// Progress callback: (pass, images done, images in the series).
pub type Progress<'a> = &'a (dyn Fn(Pass, usize, usize) + Sync);

/// Called in pass 2 for each image with its index, plane and mask (for overlays and saved
/// masks). Calls may come from several threads and in any order.
pub type ImageSink<'a> = &'a (dyn Fn(usize, &Plane, &Mask) -> Result<()> + Sync);

/// Analyse a series: one threshold by `options.method`, then every image measured.
pub fn analyze<S: PlaneSource + ?Sized>(
    source: &S,
    options: &AnalysisOptions,
    progress: Progress,
    sink: ImageSink,
) -> Result<Analysis> {
    if source.is_empty() {
        return Err(Error::InvalidArgument("the series has no images".into()));
    }
    let mut warnings = Vec::new();
    let (thresholds, series_threshold, histogram_pixels) =
        choose_thresholds(source, options.method, progress, &mut warnings)?;
    let done = AtomicUsize::new(0);
    let sigma_px = options.light_sigma_px();
    let measurements = source.scan(|i, plane| {
        // The tile sums the light budget needs come from the same pass as the classification.
        let (m, mask, light) = if options.light_budgets {
            let (m, mask, tiles) = measure_with_tiles(plane, &thresholds[i])?;
            let light = light::light_budget(plane, &tiles, sigma_px);
            (m, mask, light)
        } else {
            let (m, mask) = measure(plane, &thresholds[i])?;
            (m, mask, None)
        };
        // The band costs several times the rest of the pass: only where no light budget
        // stands in for it.
        let band = (!light.is_some_and(|l| l.has_light())).then(|| edge_band(plane, &mask));
        sink(i, plane, &mask)?;
        progress(
            Pass::Measure,
            done.fetch_add(1, Ordering::Relaxed) + 1,
            source.len(),
        );
        Ok((m, band, light))
    })?;
    let mut images: Vec<ImageResult> = thresholds
        .into_iter()
        .zip(measurements)
        .map(|(threshold, (measurement, band, light))| ImageResult {
            threshold,
            measurement,
            band,
            light,
        })
        .collect();
    if options.light_budgets && needs_bands(&images) {
        // A third pass, for the few series whose fields leave no background beyond the light.
        let bands = source.scan(|i, plane| {
            Ok(match images[i].band {
                Some(b) => b,
                None => edge_band(plane, &classify(plane, &images[i].threshold)?),
            })
        })?;
        for (r, b) in images.iter_mut().zip(bands) {
            r.band = Some(b);
        }
    }
    Ok(Analysis {
        images,
        method: options.method,
        series_threshold,
        histogram_pixels,
        pixel_size: options.pixel_size,
        sample_type: source.sample_type(),
        light_sigma_px: sigma_px,
        warnings,
    })
}

/// The edge band of an image with its contact mask at the default width and noise widening.
fn edge_band(plane: &Plane, mask: &Mask) -> interval::AreaBand {
    interval::area_band(
        plane,
        mask,
        interval::EDGE_BAND_HALF_WIDTH,
        interval::NOISE_WIDENING,
    )
}

/// The contact mask of `plane` at `threshold`.
fn classify(plane: &Plane, threshold: &Threshold) -> Result<Mask> {
    Ok(measure(plane, threshold)?.1)
}

/// Whether a series with light budgets needs every image's edge band: an image with contact
/// clear of the border (one an area–load fit would use) has no light budget, so the series'
/// intervals cannot all come from the light.
pub fn needs_bands(images: &[ImageResult]) -> bool {
    images.iter().any(|r| {
        let m = &r.measurement;
        m.contact_pixels > 0 && !m.edge_contact && !r.light.is_some_and(|l| l.has_light())
    })
}

/// The global Otsu threshold of a series without measuring (`contactscope threshold`): the
/// threshold, the number of pixels in the pooled histogram, and warnings.
pub fn global_threshold<S: PlaneSource + ?Sized>(
    source: &S,
    progress: Progress,
) -> Result<(Threshold, u64, Vec<String>)> {
    if source.is_empty() {
        return Err(Error::InvalidArgument("the series has no images".into()));
    }
    let mut warnings = Vec::new();
    let (_, threshold, pixels) =
        choose_thresholds(source, Method::GlobalOtsu, progress, &mut warnings)?;
    Ok((threshold.expect("global Otsu sets it"), pixels, warnings))
}

/// What pass 1 learns about one image: its own threshold (per-image method) and, for float
/// data, its finite value range.
type FirstPass = (Option<Threshold>, Option<(f64, f64)>);

type Chosen = (Vec<Threshold>, Option<Threshold>, u64);

fn choose_thresholds<S: PlaneSource + ?Sized>(
    source: &S,
    method: Method,
    progress: Progress,
    warnings: &mut Vec<String>,
) -> Result<Chosen> {
    let n = source.len();
    let done = AtomicUsize::new(0);
    let tick = || progress(Pass::Histogram, done.fetch_add(1, Ordering::Relaxed) + 1, n);
    let integer = source.sample_type().is_integer();
    let pooled = Mutex::new(Histogram::new(Binning::Integer {
        offset: integer_offset(source.sample_type()),
    }));
    let per_image = source.scan(|i, plane| {
        let own = if integer {
            let mut h = Histogram::new(pooled.lock().expect("lock").binning());
            h.add_plane(plane)?;
            let own = per_image_otsu(method, &h, || source.label(i))?;
            pooled.lock().expect("lock").merge(&h)?;
            own
        } else {
            let range = histogram::finite_range(plane);
            let own = match (method, range) {
                (Method::PerImageOtsu, Some((lo, hi))) if hi > lo => {
                    let mut h =
                        Histogram::new(Binning::Float(FloatBinning::new(lo, hi, FLOAT_BINS)?));
                    h.add_plane(plane)?;
                    per_image_otsu(method, &h, || source.label(i))?
                }
                (Method::PerImageOtsu, r) => {
                    return Err(Error::ConstantData {
                        what: source.label(i),
                        value: r.map_or(f64::NAN, |r| r.0),
                    })
                }
                _ => None,
            };
            return Ok((own, range));
        };
        tick();
        Ok((own, None))
    })?;
    let mut pooled = pooled.into_inner().expect("lock");
    if !integer {
        pooled = float_series_histogram(source, &per_image, &tick)?;
        if pooled.non_finite() > 0 {
            warnings.push(format!(
                "{} NaN or infinite pixels were ignored (never contact)",
                pooled.non_finite()
            ));
        }
    }
    let pixels = pooled.total();
    let series_threshold = match method {
        Method::GlobalOtsu => Some(Threshold::otsu(&pooled, &series_label(source))?),
        Method::Manual(t) => Some(Threshold::manual(t, &empty_samples(source.sample_type()))),
        Method::PerImageOtsu => None,
    };
    let thresholds = per_image
        .into_iter()
        .map(|(own, _)| own.or(series_threshold).expect("one of the two is set"))
        .collect();
    Ok((thresholds, series_threshold, pixels))
}

/// The series in messages: its one image's label, or "the series of N images (LABEL … LABEL)".
fn series_label<S: PlaneSource + ?Sized>(source: &S) -> String {
    match source.len() {
        0 => "the series".into(),
        1 => source.label(0),
        n => format!(
            "the series of {n} images ({} … {})",
            source.label(0),
            source.label(n - 1)
        ),
    }
}

fn float_series_histogram<S: PlaneSource + ?Sized>(
    source: &S,
    per_image: &[FirstPass],
    tick: &(dyn Fn() + Sync),
) -> Result<Histogram> {
    let (lo, hi) = per_image
        .iter()
        .filter_map(|(_, r)| *r)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (lo, hi)| {
            (a.min(lo), b.max(hi))
        });
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::ConstantData {
            what: series_label(source),
            value: if lo.is_finite() { lo } else { f64::NAN },
        });
    }
    let binning = Binning::Float(FloatBinning::new(lo, hi, FLOAT_BINS)?);
    let pooled = Mutex::new(Histogram::new(binning));
    source.scan(|_, plane| {
        let mut h = Histogram::new(binning);
        h.add_plane(plane)?;
        pooled.lock().expect("lock").merge(&h)?;
        tick();
        Ok(())
    })?;
    Ok(pooled.into_inner().expect("lock"))
}

fn per_image_otsu(
    method: Method,
    hist: &Histogram,
    name: impl FnOnce() -> String,
) -> Result<Option<Threshold>> {
    match method {
        Method::PerImageOtsu => Threshold::otsu(hist, &name()).map(Some),
        _ => Ok(None),
    }
}

/// No pixels, but the series' kind of samples (what a manual threshold needs to know).
fn empty_samples(sample_type: SampleType) -> Samples {
    if sample_type.is_integer() {
        Samples::Int {
            codes: Vec::new(),
            offset: integer_offset(sample_type),
        }
    } else {
        Samples::Float(Vec::new())
    }
}

fn integer_offset(sample_type: SampleType) -> i32 {
    match sample_type {
        SampleType::I16 => -32768,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(width: usize, codes: Vec<u16>) -> Plane {
        let height = codes.len() / width;
        Plane::from_u16(width, height, codes)
    }

    #[test]
    fn in_memory_planes_give_the_histogram_threshold() {
        // Two 4×2 planes, background 10 and contact 50; one pixel of contact in the first,
        // three in the second.
        let planes = [
            plane(4, vec![10, 10, 10, 50, 10, 10, 10, 10]),
            plane(4, vec![50, 50, 10, 50, 10, 10, 10, 10]),
        ];
        let seen = AtomicUsize::new(0);
        let sink = |_: usize, _: &Plane, _: &Mask| {
            seen.fetch_add(1, Ordering::Relaxed);
            Ok(())
        };
        let a = analyze(
            &planes[..],
            &AnalysisOptions::default(),
            &|_, _, _| {},
            &sink,
        )
        .unwrap();
        let t = a.series_threshold.unwrap().value;
        assert!((10.0..50.0).contains(&t), "{t}");
        let counts: Vec<u64> = a
            .images
            .iter()
            .map(|r| r.measurement.contact_pixels)
            .collect();
        assert_eq!(counts, vec![1, 3]);
        assert_eq!((a.histogram_pixels, seen.into_inner()), (16, 2));
    }

    #[test]
    fn in_memory_planes_must_agree_and_exist() {
        let planes = [plane(4, vec![1; 8]), plane(2, vec![2; 8])];
        let err = global_threshold(&planes[..], &|_, _, _| {})
            .unwrap_err()
            .to_string();
        assert!(err.contains("image 1 is 2×4"), "{err}");
        let none: [Plane; 0] = [];
        assert!(analyze(
            &none[..],
            &AnalysisOptions::default(),
            &|_, _, _| {},
            &|_, _, _| Ok(())
        )
        .is_err());
    }

    /// A disc of contact, signal 400 over a background of 100 with ±8 of deterministic
    /// texture, in a square field of `size` pixels.
    fn disc(size: usize, radius: f64) -> Plane {
        let c = size as f64 / 2.0;
        let codes = (0..size * size)
            .map(|k| {
                let (x, y) = ((k % size) as f64 + 0.5 - c, (k / size) as f64 + 0.5 - c);
                let noise = ((k * 7919) % 17) as f64 - 8.0;
                let signal = if x * x + y * y < radius * radius {
                    400.0
                } else {
                    0.0
                };
                (100.0 + signal + noise) as u16
            })
            .collect();
        Plane::from_u16(size, size, codes)
    }

    #[test]
    fn edge_bands_only_where_no_light_budget_stands_in() {
        let options = AnalysisOptions {
            psf_sigma_px: Some(1.0),
            light_budgets: true,
            ..AnalysisOptions::default()
        };
        let run = |planes: &[Plane], options: &AnalysisOptions| {
            analyze(planes, options, &|_, _, _| {}, &|_, _, _| Ok(())).unwrap()
        };
        // A wide field: background blocks far from the contact, a light budget, no band.
        let wide = [disc(256, 20.0), disc(256, 30.0)];
        let a = run(&wide, &options);
        assert!(!needs_bands(&a.images));
        for r in &a.images {
            assert!(r.light.is_some_and(|l| l.has_light()) && r.band.is_none());
        }
        // A field the contact fills: no background beyond its light, so every image's band.
        let small = [disc(40, 12.0), disc(40, 15.0)];
        let a = run(&small, &options);
        assert!(a
            .images
            .iter()
            .all(|r| r.light.is_none() && r.band.is_some()));
        // One image whose contact leaves no background beyond its light (a square 12 px from
        // the border), one with: the series needs every band, the third pass measures them.
        let mut filled = disc(256, 20.0);
        if let Samples::Int { codes, .. } = &mut filled.samples {
            for (k, v) in codes.iter_mut().enumerate() {
                let (x, y) = (k % 256, k / 256);
                if (12..244).contains(&x) && (12..244).contains(&y) {
                    *v = 500 + (k % 5) as u16;
                }
            }
        }
        let a = run(&[disc(256, 30.0), filled], &options);
        assert!(a.images[0].light.is_some_and(|l| l.has_light()));
        assert!(a.images[1].light.is_none() && !a.images[1].measurement.edge_contact);
        assert!(needs_bands(&a.images) && a.images.iter().all(|r| r.band.is_some()));
        let own = run(&[disc(256, 30.0)], &AnalysisOptions::default());
        assert_eq!(a.images[0].band, own.images[0].band);
        // Without light budgets, the band everywhere.
        let a = run(&wide, &AnalysisOptions::default());
        assert!(a
            .images
            .iter()
            .all(|r| r.light.is_none() && r.band.is_some()));
    }
}
