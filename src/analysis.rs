//! The load-series analysis: read → one threshold → measure, streaming with bounded memory.
//!
//! Pass 1 reads every image once, checks it against the series' first image, and accumulates the
//! series histogram (per-image histograms merged into one; for float data the finite range first,
//! then a second histogram pass). The threshold is chosen from the pooled histogram. Pass 2
//! classifies and measures each image. Decoded planes of compressed files are kept between passes
//! up to a memory budget; the rest are decoded again (re-reading an uncompressed page costs less
//! than keeping it), so a 500-image series never needs 500 images in memory. Work is split into
//! runs of images of one file, each with its own decoder, processed in parallel (rayon).

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::error::{Error, Location, Result};
use crate::image::{PixelSize, PixelSizeSource, Plane, Samples};
use crate::io::series::{ImageRef, Series};
use crate::io::tiff::TiffReader;
use crate::measure::{measure, Mask, Measurement};
use crate::threshold::{
    histogram, Binning, FloatBinning, Histogram, Method, Threshold, FLOAT_BINS,
};

/// Default budget for decoded planes of compressed files kept between the two passes.
pub const DEFAULT_MEMORY_BUDGET: usize = 128 << 20;

/// Sphere radius and contact modulus for the Hertz reference columns.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HertzParams {
    /// Sphere radius, metres.
    pub radius_m: f64,
    /// Contact modulus E*, pascals.
    pub modulus_pa: f64,
}

/// What to do, beyond the series itself.
#[derive(Debug, Clone)]
pub struct AnalysisOptions {
    /// Threshold method.
    pub method: Method,
    /// Pixel size (x, y) in metres that overrides the files' metadata.
    pub pixel_size_override: Option<(f64, f64)>,
    /// Hertz reference parameters.
    pub hertz: Option<HertzParams>,
    /// Bytes of decoded planes of compressed files to keep between passes.
    pub memory_budget: usize,
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        AnalysisOptions {
            method: Method::GlobalOtsu,
            pixel_size_override: None,
            hertz: None,
            memory_budget: DEFAULT_MEMORY_BUDGET,
        }
    }
}

/// The result for one image.
#[derive(Debug, Clone)]
pub struct ImageResult {
    /// Which image.
    pub image: ImageRef,
    /// The threshold applied to it.
    pub threshold: Threshold,
    /// What was measured.
    pub measurement: Measurement,
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

/// Called in pass 2 for each image with its plane and mask (for overlays and saved masks).
/// Calls may come from several threads and in any order.
pub type ImageSink<'a> = &'a (dyn Fn(usize, &ImageRef, &Plane, &Mask) -> Result<()> + Sync);

/// Analyse a series.
pub fn analyze(
    series: &Series,
    options: &AnalysisOptions,
    progress: Progress,
    sink: ImageSink,
) -> Result<Analysis> {
    if series.images.is_empty() {
        return Err(Error::InvalidArgument("the series has no images".into()));
    }
    let mut warnings = Vec::new();
    let pixel_size = series_pixel_size(series, options, &mut warnings)?;
    let reader = PlaneReader::new(series, options.memory_budget);
    let (thresholds, series_threshold, histogram_pixels) =
        choose_thresholds(series, &reader, options.method, progress, &mut warnings)?;
    let done = AtomicUsize::new(0);
    let measurements = reader.scan(|i, plane| {
        let image = &series.images[i];
        let (m, mask) = measure(plane, &thresholds[i])?;
        sink(i, image, plane, &mask)?;
        progress(
            Pass::Measure,
            done.fetch_add(1, Ordering::Relaxed) + 1,
            series.images.len(),
        );
        Ok(m)
    })?;
    let images = series
        .images
        .iter()
        .zip(thresholds)
        .zip(measurements)
        .map(|((image, threshold), measurement)| ImageResult {
            image: image.clone(),
            threshold,
            measurement,
        })
        .collect();
    Ok(Analysis {
        images,
        method: options.method,
        series_threshold,
        histogram_pixels,
        pixel_size,
        warnings,
    })
}

/// The global Otsu threshold of a series without measuring (`contactscope threshold`): the
/// threshold, the number of pixels in the pooled histogram, and warnings.
pub fn global_threshold(
    series: &Series,
    progress: Progress,
) -> Result<(Threshold, u64, Vec<String>)> {
    if series.images.is_empty() {
        return Err(Error::InvalidArgument("the series has no images".into()));
    }
    let mut warnings = Vec::new();
    let reader = PlaneReader::new(series, 0);
    let (_, threshold, pixels) =
        choose_thresholds(series, &reader, Method::GlobalOtsu, progress, &mut warnings)?;
    Ok((threshold.expect("global Otsu sets it"), pixels, warnings))
}

/// What pass 1 learns about one image: its own threshold (per-image method) and, for float
/// data, its finite value range.
type FirstPass = (Option<Threshold>, Option<(f64, f64)>);

type Chosen = (Vec<Threshold>, Option<Threshold>, u64);

fn choose_thresholds(
    series: &Series,
    reader: &PlaneReader,
    method: Method,
    progress: Progress,
    warnings: &mut Vec<String>,
) -> Result<Chosen> {
    let n = series.images.len();
    let done = AtomicUsize::new(0);
    let tick = || progress(Pass::Histogram, done.fetch_add(1, Ordering::Relaxed) + 1, n);
    let integer = series.files[0].sample_type.is_integer();
    let pooled = Mutex::new(Histogram::new(Binning::Integer {
        offset: integer_offset(series),
    }));
    let per_image = reader.scan(|i, plane| {
        let own = if integer {
            let mut h = Histogram::new(pooled.lock().expect("lock").binning());
            h.add_plane(plane)?;
            let own = per_image_otsu(method, &h, &series.images[i])?;
            pooled.lock().expect("lock").merge(&h)?;
            own
        } else {
            let range = histogram::finite_range(plane);
            let own = match (method, range) {
                (Method::PerImageOtsu, Some((lo, hi))) if hi > lo => {
                    let mut h =
                        Histogram::new(Binning::Float(FloatBinning::new(lo, hi, FLOAT_BINS)?));
                    h.add_plane(plane)?;
                    per_image_otsu(method, &h, &series.images[i])?
                }
                (Method::PerImageOtsu, r) => {
                    return Err(Error::ConstantData {
                        what: image_name(&series.images[i]),
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
        pooled = float_series_histogram(reader, &per_image, &tick)?;
        if pooled.non_finite() > 0 {
            warnings.push(format!(
                "{} NaN or infinite pixels were ignored (never contact)",
                pooled.non_finite()
            ));
        }
    }
    let pixels = pooled.total();
    let series_threshold = match method {
        Method::GlobalOtsu => Some(Threshold::otsu(&pooled, "the series")?),
        Method::Manual(t) => Some(Threshold::manual(t, &empty_samples(series))),
        Method::PerImageOtsu => None,
    };
    let thresholds = per_image
        .into_iter()
        .map(|(own, _)| own.or(series_threshold).expect("one of the two is set"))
        .collect();
    Ok((thresholds, series_threshold, pixels))
}

fn float_series_histogram(
    reader: &PlaneReader,
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
            what: "the series".into(),
            value: if lo.is_finite() { lo } else { f64::NAN },
        });
    }
    let binning = Binning::Float(FloatBinning::new(lo, hi, FLOAT_BINS)?);
    let pooled = Mutex::new(Histogram::new(binning));
    reader.scan(|_, plane| {
        let mut h = Histogram::new(binning);
        h.add_plane(plane)?;
        pooled.lock().expect("lock").merge(&h)?;
        tick();
        Ok(())
    })?;
    Ok(pooled.into_inner().expect("lock"))
}

fn per_image_otsu(method: Method, hist: &Histogram, image: &ImageRef) -> Result<Option<Threshold>> {
    match method {
        Method::PerImageOtsu => Threshold::otsu(hist, &image_name(image)).map(Some),
        _ => Ok(None),
    }
}

fn image_name(image: &ImageRef) -> String {
    Location::page(&image.path, image.page).to_string()
}

/// No pixels, but the series' kind of samples (what a manual threshold needs to know).
fn empty_samples(series: &Series) -> Samples {
    if series.files[0].sample_type.is_integer() {
        Samples::Int {
            codes: Vec::new(),
            offset: integer_offset(series),
        }
    } else {
        Samples::Float(Vec::new())
    }
}

fn integer_offset(series: &Series) -> i32 {
    match series.files[0].sample_type {
        crate::image::SampleType::I16 => -32768,
        _ => 0,
    }
}

/// The pixel size for the whole series: the override, or the files' metadata if they agree.
fn series_pixel_size(
    series: &Series,
    options: &AnalysisOptions,
    warnings: &mut Vec<String>,
) -> Result<Option<PixelSize>> {
    if let Some((x_m, y_m)) = options.pixel_size_override {
        return Ok(Some(PixelSize {
            x_m,
            y_m,
            source: PixelSizeSource::CommandLine,
        }));
    }
    let first = &series.files[0];
    for other in &series.files[1..] {
        let agree = match (&first.pixel_size, &other.pixel_size) {
            (Some(a), Some(b)) => a.same_size(b),
            (None, None) => true,
            _ => false,
        };
        if !agree {
            let show = |p: &Option<PixelSize>| {
                p.map_or("no pixel size".to_string(), |p| {
                    format!("{:.6}×{:.6} µm", p.x_m * 1e6, p.y_m * 1e6)
                })
            };
            return Err(Error::SeriesMismatch {
                at: Location::file(&other.path),
                reason: format!("pixel size is {}", show(&other.pixel_size)),
                expected: format!("{}; give --pixel-size to override", show(&first.pixel_size)),
            });
        }
    }
    for f in &series.files {
        warnings.extend(f.notes.iter().map(|n| format!("{}: {n}", f.path.display())));
    }
    if first.pixel_size.is_none() {
        warnings.push(
            "no pixel size in the files' metadata and no --pixel-size: areas are in pixels".into(),
        );
    }
    Ok(first.pixel_size)
}

/// Reads the series' planes, keeping decoded planes of compressed files up to a budget.
struct PlaneReader<'a> {
    series: &'a Series,
    cache: Mutex<Vec<Option<Arc<Plane>>>>,
    cacheable: Vec<bool>,
    budget_left: Mutex<usize>,
}

impl<'a> PlaneReader<'a> {
    fn new(series: &'a Series, budget: usize) -> Self {
        let compressed = |path: &Path| {
            series
                .info_of(path)
                .is_some_and(|info| info.compression != "none")
        };
        PlaneReader {
            series,
            cache: Mutex::new(vec![None; series.images.len()]),
            cacheable: series.images.iter().map(|i| compressed(&i.path)).collect(),
            budget_left: Mutex::new(budget),
        }
    }

    /// Apply `f` to every image, in parallel over runs of images of one file. Results come back
    /// in image order; the first error in image order is returned.
    fn scan<T: Send>(&self, f: impl Fn(usize, &Plane) -> Result<T> + Sync) -> Result<Vec<T>> {
        let groups = work_units(&self.series.images, rayon::current_num_threads());
        let results: Vec<Vec<(usize, Result<T>)>> = groups
            .par_iter()
            .map(|indices| {
                let mut reader = None;
                let mut out = Vec::with_capacity(indices.len());
                for &i in indices {
                    let r = self.plane(&mut reader, i).and_then(|p| f(i, &p));
                    let failed = r.is_err();
                    out.push((i, r));
                    if failed {
                        break;
                    }
                }
                out
            })
            .collect();
        let mut flat: Vec<(usize, Result<T>)> = results.into_iter().flatten().collect();
        flat.sort_by_key(|(i, _)| *i);
        if let Some(pos) = flat.iter().position(|(_, r)| r.is_err()) {
            return Err(flat.swap_remove(pos).1.err().expect("is an error"));
        }
        Ok(flat.into_iter().map(|(_, r)| r.expect("checked")).collect())
    }

    fn plane(&self, reader: &mut Option<TiffReader>, i: usize) -> Result<Arc<Plane>> {
        if let Some(p) = self.cache.lock().expect("lock")[i].clone() {
            return Ok(p);
        }
        let plane = Arc::new(self.read(reader, &self.series.images[i])?);
        let mut left = self.budget_left.lock().expect("lock");
        if self.cacheable[i] && plane.heap_bytes() <= *left {
            *left -= plane.heap_bytes();
            self.cache.lock().expect("lock")[i] = Some(plane.clone());
        }
        Ok(plane)
    }

    fn read(&self, reader: &mut Option<TiffReader>, image: &ImageRef) -> Result<Plane> {
        if reader.as_ref().is_none_or(|r| r.info().path != image.path) {
            *reader = Some(TiffReader::open(&image.path)?);
        }
        let reader = reader.as_mut().expect("just opened");
        let plane = reader.read_page(image.page, self.series.channel)?;
        check_plane(&plane, self.series, &image.path, image.page)?;
        Ok(plane)
    }
}

fn check_plane(plane: &Plane, series: &Series, path: &Path, page: usize) -> Result<()> {
    let first = &series.files[0];
    if (plane.width, plane.height, plane.sample_type)
        != (first.width, first.height, first.sample_type)
    {
        return Err(Error::SeriesMismatch {
            at: Location::page(path, page),
            reason: format!(
                "page is {}×{} {}",
                plane.width,
                plane.height,
                plane.sample_type.name()
            ),
            expected: format!(
                "{}×{} {}",
                first.width,
                first.height,
                first.sample_type.name()
            ),
        });
    }
    Ok(())
}

/// Units of parallel work: the image indices of each file (files in first-use order), split into
/// runs short enough that a single multi-page file keeps every thread busy. Each unit opens its
/// own decoder.
fn work_units(images: &[ImageRef], threads: usize) -> Vec<Vec<usize>> {
    let mut by_file: HashMap<&Path, usize> = HashMap::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, image) in images.iter().enumerate() {
        let g = *by_file.entry(&image.path).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(i);
    }
    let run = images.len().div_ceil(4 * threads.max(1)).max(1);
    groups
        .iter()
        .flat_map(|g| g.chunks(run).map(<[usize]>::to_vec))
        .collect()
}
