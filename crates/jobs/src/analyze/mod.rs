//! The `analyze` job end to end: a validated request in, staged outputs committed, a summary
//! out. The command line only builds an [`AnalyzeRequest`] and prints the [`AnalyzeOutcome`].
//! [`analyze_series`] is the analysis of a series of files without the outputs.

pub mod report;

use std::path::{Path, PathBuf};

use serde_json::json;

pub use report::{AreaUnit, HertzParams, Report, Row};

use crate::error::Result;
use crate::plot::overlay_png;
use crate::series::{self, ImageRef, Series, DEFAULT_MEMORY_BUDGET};
use crate::staging::Staging;
use contactscope::analysis::{self, Analysis, AnalysisOptions, ImageSink, Progress};
use contactscope::image::Plane;
use contactscope::measure::Mask;
use contactscope::threshold::Method;
use contactscope_formats::tiff::write::encode_u8_stack;
use report::{inputs_json, threshold_json};

/// What to do with a series of files, beyond the series itself.
#[derive(Debug, Clone)]
pub struct AnalyzeOptions {
    /// Threshold method.
    pub method: Method,
    /// Pixel size (x, y) in metres that overrides the files' metadata.
    pub pixel_size_override: Option<(f64, f64)>,
    /// Hertz reference parameters.
    pub hertz: Option<HertzParams>,
    /// Bytes of decoded planes of compressed files to keep between passes.
    pub memory_budget: usize,
}

impl Default for AnalyzeOptions {
    fn default() -> Self {
        AnalyzeOptions {
            method: Method::GlobalOtsu,
            pixel_size_override: None,
            hertz: None,
            memory_budget: DEFAULT_MEMORY_BUDGET,
        }
    }
}

/// Analyse a series of files: the pixel size from the override or the files' metadata (they
/// must agree), then [`analysis::analyze`] over the files' planes. Warnings about the pixel size
/// come first in the result's warnings.
pub fn analyze_series(
    series: &Series,
    options: &AnalyzeOptions,
    progress: Progress,
    sink: ImageSink,
) -> Result<Analysis> {
    if series.images.is_empty() {
        return Err(crate::error::Error::InvalidArgument(
            "the series has no images".into(),
        ));
    }
    let mut warnings = Vec::new();
    let pixel_size = series::pixel_size(series, options.pixel_size_override, &mut warnings)?;
    let analysis_options = AnalysisOptions {
        method: options.method,
        pixel_size,
    };
    let mut analysis = analysis::analyze(
        &series.planes(options.memory_budget),
        &analysis_options,
        progress,
        sink,
    )?;
    warnings.append(&mut analysis.warnings);
    analysis.warnings = warnings;
    Ok(analysis)
}

/// Everything `analyze` needs, already validated.
#[derive(Debug, Clone)]
pub struct AnalyzeRequest {
    /// The series with forces.
    pub series: Series,
    /// Analysis options.
    pub options: AnalyzeOptions,
    /// Output folder.
    pub out_dir: PathBuf,
    /// Write one overlay PNG per image.
    pub overlays: bool,
    /// Write one mask TIFF per image.
    pub save_masks: bool,
    /// The command line, for the summary.
    pub command_line: Vec<String>,
}

/// What `analyze` produced.
#[derive(Debug, Clone)]
pub struct AnalyzeOutcome {
    /// The analysis.
    pub analysis: Analysis,
    /// Table, fits and units.
    pub report: Report,
    /// Files written, final paths.
    pub written: Vec<PathBuf>,
}

/// Output file stem for image `index`: `003_name_p2`.
fn image_stem(index: usize, image: &ImageRef) -> String {
    let stem = image
        .path
        .file_stem()
        .map_or("image".into(), |s| s.to_string_lossy().into_owned());
    let clean: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{:03}_{clean}_p{}", index + 1, image.page)
}

/// Scale factor that makes small micrographs legible in overlays.
fn overlay_scale(width: usize) -> usize {
    (512 / width.max(1)).clamp(1, 4)
}

/// Run the analysis and write `areas.csv`, `summary.json`, `area_vs_load.png/.svg` and, on
/// request, overlays and masks. Nothing appears in `out_dir` unless everything succeeded.
pub fn run_analyze(request: &AnalyzeRequest, progress: Progress) -> Result<AnalyzeOutcome> {
    let inputs: Vec<PathBuf> = request
        .series
        .files
        .iter()
        .map(|f| f.path.clone())
        .chain(request.series.manifest.clone())
        .collect();
    let staging = Staging::new(&request.out_dir, &inputs)?;
    let sink = |i: usize, plane: &Plane, mask: &Mask| -> contactscope::Result<()> {
        Ok(write_image_outputs(&staging, request, i, plane, mask)?)
    };
    let sink: ImageSink = &sink;
    let analysis = analyze_series(&request.series, &request.options, progress, sink)?;
    let report = Report::new(&request.series, &analysis, request.options.hertz);
    staging.write("areas.csv", &report.areas_csv()?)?;
    let plot = report.area_plot("Contact area versus normal force");
    staging.write("area_vs_load.png", &plot.to_png()?)?;
    staging.write("area_vs_load.svg", plot.to_svg()?.as_bytes())?;
    let integer = request.series.files[0].sample_type.is_integer();
    let summary = json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "inputs": inputs_json(&request.series, &analysis),
        "threshold": threshold_json(&analysis, integer),
        "area_unit": match report.unit {
            AreaUnit::SquareMicrometre => "um2",
            AreaUnit::Pixel => "px",
        },
        "fits": report.fits_json(),
        "hertz": request.options.hertz.map(|h| json!({
            "sphere_radius_um": h.radius_m * 1e6,
            "contact_modulus_GPa": h.modulus_pa * 1e-9,
        })),
        "warnings": analysis.warnings,
    });
    let text = serde_json::to_string_pretty(&summary).expect("JSON values serialise");
    staging.write("summary.json", text.as_bytes())?;
    let written = staging.commit()?;
    Ok(AnalyzeOutcome {
        analysis,
        report,
        written,
    })
}

fn write_image_outputs(
    staging: &Staging,
    request: &AnalyzeRequest,
    index: usize,
    plane: &Plane,
    mask: &Mask,
) -> Result<()> {
    let image = &request.series.images[index];
    let stem = image_stem(index, image);
    if request.overlays {
        let png = overlay_png(
            &plane.to_f64(),
            plane.width,
            plane.height,
            &mask.as_bools(),
            overlay_scale(plane.width),
        )?;
        staging.write(&format!("overlay_{stem}.png"), &png)?;
    }
    if request.save_masks {
        let bytes: Vec<u8> = mask.data.iter().map(|&m| m * 255).collect();
        let size = request.options.pixel_size_override.or_else(|| {
            request
                .series
                .info_of(&image.path)?
                .pixel_size
                .map(|p| (p.x_m, p.y_m))
        });
        let tiff = encode_u8_stack(&[&bytes], mask.width, mask.height, size)?;
        staging.write(&format!("mask_{stem}.tif"), &tiff)?;
    }
    Ok(())
}

/// Relative display of a path under a base folder, for messages.
pub fn display_relative(path: &Path, base: &Path) -> String {
    path.strip_prefix(base)
        .unwrap_or(path)
        .display()
        .to_string()
}
