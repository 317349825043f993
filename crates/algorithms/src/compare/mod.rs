//! Simulated contact maps against micrographs, load by load (Weber et al. 2018, Fig. 2 and
//! "Comparison with experiments"; docs/methods.md §7.4 and §8).
//!
//! Per load present in both (matched by force): the simulated contact map (pixels with g = 0) is
//! blurred with the PSF and integrated onto the micrograph's pixels ([`crate::optics::blur`]),
//! placed at the centre of a canvas the size of the micrograph, and registered to it by phase
//! correlation once for the whole series: the sample does not move between loads, so one shift
//! (and one dihedral transform, when they are searched) comes from the mean cross-power spectrum
//! of all matched loads, and each load is then refined within ±[`REFINE_WINDOW_PX`] pixels of
//! it ([`crate::spectral::register::series`]; docs/methods.md §8). Both are thresholded: the
//! micrographs with one exact Otsu threshold over the whole experiment series (as `analyze`),
//! the simulated images with one Otsu threshold over all of them (the same procedure on the
//! simulated series). Scores are computed on the region the simulation covers after
//! registration: Dice, Jaccard, the area ratio, their sensitivity to ±10 % of the experiment's
//! threshold, and the RMS distance between the radially averaged intensity autocorrelations of
//! the two images.

//!
//! Everything here works on maps and images in memory; the `compare` command's reading of the
//! micrographs and of a `simulate` folder, and its outputs, are in `contactscope_jobs::compare`.

use std::path::PathBuf;

use crate::error::{Error, Location, Result};
use crate::image::Plane;
use crate::measure::distance::squared_distance;
use crate::optics::blur::{microscope_image, Grid, IntensityScale};
use crate::spectral::autocorrelation::AcfCurve;
use crate::spectral::register::{
    register_series, translate, Dihedral, LoadShift, Refinement, SeriesOptions,
};
use crate::threshold::otsu_of_values;
use contactscope_formats::ranges::short;

/// How simulated maps are imaged, registered and matched to micrographs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompareSettings {
    /// PSF FWHM, m.
    pub psf_fwhm_m: f64,
    /// Try the 8 dihedral transforms (mirror and 90° rotations) when registering.
    pub dihedral: bool,
    /// Sub-pixel resolution of the registration, 1/`upsample` px.
    pub upsample: usize,
    /// Largest relative force difference for two loads to match.
    pub force_tolerance: f64,
}

/// One micrograph of the experiment series, in memory.
#[derive(Debug, Clone)]
pub struct Micrograph {
    /// The decoded image.
    pub plane: Plane,
    /// Normal force, N, when known (images without one are not compared).
    pub force_n: Option<f64>,
    /// The file it came from (a label for tables and messages).
    pub path: PathBuf,
    /// Zero-based page in that file.
    pub page: usize,
}

/// The experiment side, read once: the micrographs, their global Otsu threshold and pixel size
/// (`contactscope_jobs::compare::load_micrographs` reads them from files).
#[derive(Debug, Clone)]
pub struct Micrographs {
    /// The micrographs in load order.
    pub images: Vec<Micrograph>,
    /// One exact Otsu threshold over the series (grey levels); contact is value > t.
    pub threshold: f64,
    /// Pixel size (x, y), m.
    pub pixel_m: (f64, f64),
    /// Notes from reading and thresholding.
    pub warnings: Vec<String>,
}

/// One simulated contact map (1 = contact) at one force, in memory.
#[derive(Debug, Clone)]
pub struct SimulatedMap {
    /// Normal force, N.
    pub force_n: f64,
    /// The map with its pixel size.
    pub map: Grid,
    /// Where it came from (a file, or a model and parameter), for tables.
    pub source: String,
}

/// Scores of one matched load.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadComparison {
    /// Experimental normal force, N.
    pub force_n: f64,
    /// Simulated normal force, N.
    pub simulated_force_n: f64,
    /// Micrograph file and page.
    pub micrograph: (PathBuf, usize),
    /// Where the simulated map came from.
    pub simulated_map: String,
    /// Transform applied to the simulated image (the series').
    pub transform: Dihedral,
    /// Translation applied after the transform, micrograph pixels (x, y): the series shift
    /// refined for this load.
    pub shift_px: (f64, f64),
    /// The same translation, m (x, y).
    pub shift_m: (f64, f64),
    /// This load's normalised phase correlation at its shift (1 = perfect).
    pub correlation_peak: f64,
    /// Where the shift comes from: the load's own peak near the series shift, or the series
    /// shift itself (the load's peak too weak, or on the window's edge).
    pub refinement: Refinement,
    /// Experimental contact area inside the compared region, m².
    pub experiment_area_m2: f64,
    /// Blurred-and-thresholded simulated contact area inside the region, m².
    pub simulated_area_m2: f64,
    /// Raw simulated contact area (g = 0 pixels on the simulation grid), m².
    pub simulated_raw_area_m2: f64,
    /// Dice coefficient 2|A∩B|/(|A|+|B|).
    pub dice: f64,
    /// Jaccard index |A∩B|/|A∪B|.
    pub jaccard: f64,
    /// Dice with the experiment's threshold lowered and raised by 10 %.
    pub dice_threshold_pm10: (f64, f64),
    /// Mean distance between the two contact edges (symmetric: the average of the mean distance
    /// from each edge pixel of one map to the nearest edge pixel of the other), m.
    pub edge_distance_m: Option<f64>,
    /// RMS difference of the radially averaged autocorrelations over common lags.
    pub acf_rms_distance: Option<f64>,
    /// Correlation lengths ξ_1/e of experiment and simulation, m.
    pub xi_1e_m: (Option<f64>, Option<f64>),
    /// Simulated intensity put on the micrograph's grey scale.
    pub intensity: IntensityScale,
}

/// A matched pair, registered, before thresholding.
#[derive(Debug, Clone)]
pub struct Prepared {
    force_n: f64,
    simulated_force_n: f64,
    source: String,
    micrograph: (PathBuf, usize),
    /// Micrograph (width, height), pixels.
    size: (usize, usize),
    experiment: Vec<f64>,
    simulated: Vec<f64>,
    footprint: Vec<bool>,
    transform: Dihedral,
    shift: LoadShift,
    raw_area_m2: f64,
}

impl Prepared {
    /// Micrograph (width, height), pixels.
    pub fn size(&self) -> (usize, usize) {
        self.size
    }

    /// The micrograph's values, row-major.
    pub fn micrograph(&self) -> &[f64] {
        &self.experiment
    }

    /// The registered simulated image on the micrograph's grey scale of `load`, NaN outside the
    /// simulated region.
    pub fn simulated_on_scale(&self, load: &LoadComparison) -> Vec<f64> {
        self.simulated
            .iter()
            .zip(&self.footprint)
            .map(|(&v, &inside)| {
                if inside {
                    load.intensity.apply(v)
                } else {
                    f64::NAN
                }
            })
            .collect()
    }

    /// The experiment's contact (micrograph value > `t_exp`) inside the compared region, as
    /// the scores count it.
    pub fn experiment_contact(&self, t_exp: f64) -> Vec<bool> {
        contact_in_region(&self.experiment, &self.footprint, t_exp)
    }

    /// The simulation's contact (blurred, registered contact fraction > `t_sim`) inside the
    /// compared region, as the scores count it.
    pub fn simulated_contact(&self, t_sim: f64) -> Vec<bool> {
        contact_in_region(&self.simulated, &self.footprint, t_sim)
    }

    /// Micrograph values inside the simulated region, NaN outside.
    pub fn micrograph_in_region(&self) -> Vec<f64> {
        self.experiment
            .iter()
            .zip(&self.footprint)
            .map(|(&v, &inside)| if inside { v } else { f64::NAN })
            .collect()
    }
}

/// Below this peak of the series' mean correlation surface the registration is reported as
/// doubtful; below it, a load's own peak does not move the load away from the series shift (on
/// the demo's 432² micrographs, the highest point of a load whose map matches nowhere is 0.011).
const WEAK_PEAK: f64 = 0.05;

/// Half-width, micrograph pixels, of the window around the series shift within which each load's
/// registration is refined (a load cannot move further from the others).
pub const REFINE_WINDOW_PX: usize = 3;

/// The series registration: one transform and one shift for every load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeriesShift {
    /// Transform applied to every simulated image.
    pub transform: Dihedral,
    /// The series shift applied to the simulated images, micrograph pixels (x, y).
    pub shift_px: (f64, f64),
    /// The same, m (x, y).
    pub shift_m: (f64, f64),
    /// Peak of the mean phase-correlation surface of the matched loads (the mean of their
    /// normalised correlations at the series shift; 1 = perfect).
    pub correlation_peak: f64,
    /// Half-width of the per-load refinement window, micrograph pixels.
    pub window_px: usize,
}

/// The result of [`compare_maps`].
#[derive(Debug, Clone)]
pub struct Comparison {
    /// Scores per matched load, in experiment order.
    pub loads: Vec<LoadComparison>,
    /// The registered pairs, for panels.
    pub prepared: Vec<Prepared>,
    /// The series registration.
    pub registration: SeriesShift,
    /// Otsu threshold of the blurred simulated maps (covered fraction).
    pub simulated_threshold: f64,
    /// The micrographs' series threshold (grey levels); contact is value > t.
    pub experiment_threshold: f64,
    /// Notes for the user.
    pub warnings: Vec<String>,
}

/// Match, render, register (once for the series), threshold and score. Errors when no load
/// matches or the matched micrographs differ in size.
pub fn compare_maps(
    micrographs: &Micrographs,
    simulated: &[SimulatedMap],
    settings: &CompareSettings,
) -> Result<Comparison> {
    let pairs = match_loads(&micrographs.images, simulated, settings.force_tolerance)?;
    let mut warnings = micrographs.warnings.clone();
    let rendered: Vec<Rendered> = pairs
        .into_iter()
        .map(|(image, sim)| render(settings, micrographs, image, sim))
        .collect::<Result<_>>()?;
    let size = rendered[0].size;
    let inputs: Vec<(&[f64], &[f64])> = rendered
        .iter()
        .map(|r| (r.experiment.as_slice(), r.canvas.as_slice()))
        .collect();
    let options = SeriesOptions {
        upsample: settings.upsample,
        dihedral: settings.dihedral,
        window_px: REFINE_WINDOW_PX,
        min_load_peak: WEAK_PEAK,
    };
    let registration = register_series(&inputs, size, &options)?;
    let pixel = micrographs.pixel_m;
    let series = registration.series;
    let registration_summary = SeriesShift {
        transform: registration.transform,
        shift_px: (-series.dx, -series.dy),
        shift_m: (-series.dx * pixel.0, -series.dy * pixel.1),
        correlation_peak: series.peak,
        window_px: registration.window_px,
    };
    let prepared: Vec<Prepared> = rendered
        .into_iter()
        .zip(&registration.loads)
        .map(|(r, &shift)| r.align(registration.transform, shift))
        .collect();
    let sim_sets: Vec<Vec<f64>> = prepared.iter().map(inside_footprint).collect();
    let refs: Vec<&[f64]> = sim_sets.iter().map(Vec::as_slice).collect();
    let what = format!(
        "the simulated maps blurred onto the micrographs' pixels (check {} and the PSF)",
        contactscope_formats::param::Param::PixelSize
    );
    let sim_threshold = otsu_of_values(&refs, &what)?;
    let loads: Vec<LoadComparison> = prepared
        .iter()
        .map(|p| score(p, micrographs.threshold, sim_threshold, pixel))
        .collect::<Result<_>>()?;
    if series.peak < WEAK_PEAK {
        warnings.push(format!(
            "weak registration of the series (mean correlation peak {:.3} over {} loads, shift ({:.2}, {:.2}) px); check the overlay panels",
            series.peak,
            loads.len(),
            registration_summary.shift_px.0,
            registration_summary.shift_px.1,
        ));
    }
    for l in loads
        .iter()
        .filter(|l| l.refinement == Refinement::WindowEdge)
    {
        warnings.push(format!(
            "{:.3} mN: this load's registration peak lies on the edge of the ±{} px window around the series shift; the series shift is used (correlation {:.3} there); check the overlay panel",
            l.force_n * 1e3,
            registration.window_px,
            l.correlation_peak
        ));
    }
    Ok(Comparison {
        loads,
        prepared,
        registration: registration_summary,
        simulated_threshold: sim_threshold,
        experiment_threshold: micrographs.threshold,
        warnings,
    })
}

/// Pairs (experiment image index, simulated load) whose forces agree within the tolerance; each
/// experiment image takes the nearest simulated force.
fn match_loads<'a>(
    images: &[Micrograph],
    simulated: &'a [SimulatedMap],
    tolerance: f64,
) -> Result<Vec<(usize, &'a SimulatedMap)>> {
    let mut pairs = Vec::new();
    for (i, image) in images.iter().enumerate() {
        let Some(f) = image.force_n else { continue };
        let nearest = simulated
            .iter()
            .min_by(|a, b| (a.force_n - f).abs().total_cmp(&(b.force_n - f).abs()));
        if let Some(s) = nearest.filter(|s| (s.force_n / f - 1.0).abs() <= tolerance) {
            pairs.push((i, s));
        }
    }
    if pairs.is_empty() {
        let list = |v: Vec<f64>| {
            v.iter()
                .map(|f| format!("{:.4}", f * 1e3))
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(Error::InvalidArgument(format!(
            "the simulation and the experiment have no common load within {:.1} % ({}): \
             experiment {} mN ({}), simulation {} mN",
            tolerance * 100.0,
            contactscope_formats::param::Param::ForceTolerance,
            list(images.iter().filter_map(|i| i.force_n).collect()),
            contactscope_formats::param::Param::Forces,
            list(simulated.iter().map(|s| s.force_n).collect()),
        )));
    }
    Ok(pairs)
}

/// A matched pair rendered on the micrograph's grid, before registration.
struct Rendered {
    force_n: f64,
    simulated_force_n: f64,
    source: String,
    micrograph: (PathBuf, usize),
    size: (usize, usize),
    experiment: Vec<f64>,
    /// The simulated image centred on a micrograph-sized canvas.
    canvas: Vec<f64>,
    /// 1 where the simulation lies on the canvas.
    frame: Vec<f64>,
    raw_area_m2: f64,
}

impl Rendered {
    /// The simulated image and its footprint transformed and shifted onto the micrograph.
    fn align(self, transform: Dihedral, shift: LoadShift) -> Prepared {
        let (w, h) = self.size;
        let align = |img: &[f64]| {
            let (t, _, _) = transform.apply(img, w, h);
            translate(&t, (w, h), (-shift.shift.dx, -shift.shift.dy), 0.0)
        };
        let simulated = align(&self.canvas);
        let footprint = align(&self.frame).iter().map(|&v| v > 0.999).collect();
        Prepared {
            force_n: self.force_n,
            simulated_force_n: self.simulated_force_n,
            source: self.source,
            micrograph: self.micrograph,
            size: self.size,
            experiment: self.experiment,
            simulated,
            footprint,
            transform,
            shift,
            raw_area_m2: self.raw_area_m2,
        }
    }
}

/// The simulated map blurred, resampled and centred on a canvas of the micrograph's size.
fn render(
    settings: &CompareSettings,
    micrographs: &Micrographs,
    index: usize,
    sim: &SimulatedMap,
) -> Result<Rendered> {
    let image = &micrographs.images[index];
    let plane = &image.plane;
    let (w, h) = (plane.width, plane.height);
    let first = &micrographs.images[0].plane;
    let side = 2 * REFINE_WINDOW_PX + 1;
    if (w, h) != (first.width, first.height) || w.min(h) < side {
        return Err(Error::bad_input(
            Location::page(&image.path, image.page),
            format!(
                "the micrograph is {w}×{h} pixels; registering a series needs micrographs of one size (the first is {}×{}) and at least {side}×{side} pixels",
                first.width, first.height
            ),
        ));
    }
    let at = || Location::file(&sim.source);
    let raw_area_m2 = sim.map.integral();
    // The rendered size is known before rendering: a simulation that would cover more than the
    // micrograph is refused before its (possibly huge) image on micrograph pixels is allocated.
    let (px, py) = micrographs.pixel_m;
    let at_least = (
        (sim.map.width as f64 * sim.map.dx_m / px).floor(),
        (sim.map.height as f64 * sim.map.dy_m / py).floor(),
    );
    if at_least.0 > w as f64 || at_least.1 > h as f64 {
        return Err(Error::bad_input(
            at(),
            format!(
                "the simulated region ({}×{} micrograph pixels of {}×{} nm) is larger than the micrograph ({w}×{h}); crop the simulation, or check the micrographs' pixel size",
                at_least.0, at_least.1, short(px * 1e9), short(py * 1e9)
            ),
        ));
    }
    let rendered = microscope_image(&sim.map, settings.psf_fwhm_m, micrographs.pixel_m)
        .map_err(|e| Error::bad_input(at(), e.to_string()))?;
    if rendered.width > w || rendered.height > h {
        return Err(Error::bad_input(
            at(),
            format!(
                "the simulated region ({}×{} micrograph pixels) is larger than the micrograph ({w}×{h}); crop the simulation",
                rendered.width, rendered.height
            ),
        ));
    }
    let (canvas, frame) = centred(&rendered, w, h);
    Ok(Rendered {
        force_n: image.force_n.unwrap_or(f64::NAN),
        simulated_force_n: sim.force_n,
        source: sim.source.clone(),
        micrograph: (image.path.clone(), image.page),
        size: (w, h),
        experiment: plane.to_f64(),
        canvas,
        frame,
        raw_area_m2,
    })
}

/// `grid` centred on a zero canvas of `w × h`, and the indicator of where it lies.
fn centred(grid: &Grid, w: usize, h: usize) -> (Vec<f64>, Vec<f64>) {
    let (x0, y0) = ((w - grid.width) / 2, (h - grid.height) / 2);
    let mut canvas = vec![0.0; w * h];
    let mut frame = vec![0.0; w * h];
    for y in 0..grid.height {
        for x in 0..grid.width {
            canvas[(y + y0) * w + x + x0] = grid.values[y * grid.width + x];
            frame[(y + y0) * w + x + x0] = 1.0;
        }
    }
    (canvas, frame)
}

fn inside_footprint(p: &Prepared) -> Vec<f64> {
    p.simulated
        .iter()
        .zip(&p.footprint)
        .filter(|(_, &inside)| inside)
        .map(|(&v, _)| v)
        .collect()
}

/// (|A|, |B|, |A∩B|) over the footprint.
fn overlap(p: &Prepared, t_exp: f64, t_sim: f64) -> (usize, usize, usize) {
    let mut counts = (0, 0, 0);
    for ((e, s), &inside) in p.experiment.iter().zip(&p.simulated).zip(&p.footprint) {
        if inside {
            let (a, b) = (*e > t_exp, *s > t_sim);
            counts.0 += usize::from(a);
            counts.1 += usize::from(b);
            counts.2 += usize::from(a && b);
        }
    }
    counts
}

/// Contact pixels of a thresholded image inside the compared region.
fn contact_in_region(img: &[f64], footprint: &[bool], t: f64) -> Vec<bool> {
    img.iter()
        .zip(footprint)
        .map(|(&v, &inside)| inside && v > t)
        .collect()
}

/// Contact pixels with a non-contact 4-neighbour inside the image.
fn edges(mask: &[bool], (w, h): (usize, usize)) -> Vec<bool> {
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            mask[i]
                && ((x > 0 && !mask[i - 1])
                    || (x + 1 < w && !mask[i + 1])
                    || (y > 0 && !mask[i - w])
                    || (y + 1 < h && !mask[i + w]))
        })
        .collect()
}

/// Symmetric mean distance between the contact edges of experiment and simulation (m), `None`
/// if either has no edge.
fn edge_distance(p: &Prepared, t_exp: f64, t_sim: f64, pixel: (f64, f64)) -> Option<f64> {
    let a = edges(
        &contact_in_region(&p.experiment, &p.footprint, t_exp),
        p.size,
    );
    let b = edges(
        &contact_in_region(&p.simulated, &p.footprint, t_sim),
        p.size,
    );
    let mean_to = |from: &[bool], to: &[bool]| -> Option<f64> {
        let d2 = squared_distance(to, p.size.0, p.size.1, pixel);
        let d: Vec<f64> = from
            .iter()
            .zip(&d2)
            .filter(|(&e, _)| e)
            .map(|(_, v)| v.sqrt())
            .collect();
        (!d.is_empty() && d.iter().all(|v| v.is_finite()))
            .then(|| d.iter().sum::<f64>() / d.len() as f64)
    };
    Some(0.5 * (mean_to(&a, &b)? + mean_to(&b, &a)?))
}

/// Dice from (|A|, |B|, |A∩B|); 1 when both are empty (identical empty maps).
fn dice((a, b, both): (usize, usize, usize)) -> f64 {
    if a + b == 0 {
        1.0
    } else {
        2.0 * both as f64 / (a + b) as f64
    }
}

fn score(p: &Prepared, t_exp: f64, t_sim: f64, pixel: (f64, f64)) -> Result<LoadComparison> {
    let counts = overlap(p, t_exp, t_sim);
    let d = dice(counts);
    let pixel_area = pixel.0 * pixel.1;
    let masked = |img: &[f64]| -> Vec<f64> {
        img.iter()
            .zip(&p.footprint)
            .map(|(&v, &inside)| if inside { v } else { f64::NAN })
            .collect()
    };
    let (width, height) = p.size;
    let max_lag = 0.5 * (width as f64 * pixel.0).min(height as f64 * pixel.1);
    let acf = |label: &str, img: &[f64]| {
        AcfCurve::of_grid(label, &masked(img), (width, height), pixel, max_lag).ok()
    };
    let (acf_exp, acf_sim) = (
        acf("experiment", &p.experiment),
        acf("simulation", &p.simulated),
    );
    let inside = |img: &[f64]| -> Vec<f64> {
        img.iter()
            .zip(&p.footprint)
            .filter(|(_, &i)| i)
            .map(|(&v, _)| v)
            .collect()
    };
    let intensity = IntensityScale::fit(&inside(&p.simulated), &inside(&p.experiment)).unwrap_or(
        IntensityScale {
            gain: 1.0,
            offset: 0.0,
        },
    );
    Ok(LoadComparison {
        force_n: p.force_n,
        simulated_force_n: p.simulated_force_n,
        micrograph: p.micrograph.clone(),
        simulated_map: p.source.clone(),
        transform: p.transform,
        shift_px: (-p.shift.shift.dx, -p.shift.shift.dy),
        shift_m: (-p.shift.shift.dx * pixel.0, -p.shift.shift.dy * pixel.1),
        correlation_peak: p.shift.shift.peak,
        refinement: p.shift.refinement,
        experiment_area_m2: counts.0 as f64 * pixel_area,
        simulated_area_m2: counts.1 as f64 * pixel_area,
        simulated_raw_area_m2: p.raw_area_m2,
        dice: d,
        jaccard: d / (2.0 - d),
        dice_threshold_pm10: (
            dice(overlap(p, 0.9 * t_exp, t_sim)),
            dice(overlap(p, 1.1 * t_exp, t_sim)),
        ),
        edge_distance_m: edge_distance(p, t_exp, t_sim, pixel),
        acf_rms_distance: acf_exp
            .as_ref()
            .zip(acf_sim.as_ref())
            .and_then(|(a, b)| a.rms_distance(b)),
        xi_1e_m: (
            acf_exp.and_then(|c| c.xi_1e_m),
            acf_sim.and_then(|c| c.xi_1e_m),
        ),
        intensity,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::register::Shift;

    fn bands(a: std::ops::Range<usize>, b: std::ops::Range<usize>) -> Prepared {
        let (w, h) = (16, 6);
        let band = |r: &std::ops::Range<usize>| -> Vec<f64> {
            (0..w * h)
                .map(|i| f64::from(u8::from(r.contains(&(i % w)))))
                .collect()
        };
        Prepared {
            force_n: 1.0,
            simulated_force_n: 1.0,
            source: "test".into(),
            micrograph: (PathBuf::from("m.tif"), 0),
            size: (w, h),
            experiment: band(&a),
            simulated: band(&b),
            footprint: vec![true; w * h],
            transform: Dihedral::IDENTITY,
            shift: LoadShift {
                shift: Shift {
                    dx: 0.0,
                    dy: 0.0,
                    peak: 1.0,
                },
                refinement: Refinement::Refined,
            },
            raw_area_m2: 0.0,
        }
    }

    #[test]
    fn edge_distance_of_shifted_bands_is_the_shift() {
        // Full-height bands: the edges are the band's first and last columns only.
        let p = bands(5..10, 7..12);
        let d = edge_distance(&p, 0.5, 0.5, (0.5, 1.0)).unwrap();
        assert!((d - 1.0).abs() < 1e-12, "{d}"); // 2 px × 0.5 m
        let same = bands(5..10, 5..10);
        assert_eq!(edge_distance(&same, 0.5, 0.5, (1.0, 1.0)), Some(0.0));
        assert_eq!(
            edge_distance(&bands(5..10, 0..0), 0.5, 0.5, (1.0, 1.0)),
            None
        );
        let counts = overlap(&p, 0.5, 0.5);
        assert_eq!(counts, (30, 30, 18));
        assert!((dice(counts) - 0.6).abs() < 1e-12);
    }
}
