//! The `analyze` job end to end: a validated request in, staged outputs committed, a summary
//! out. The command line only builds an [`AnalyzeRequest`] and prints the [`AnalyzeOutcome`].

use std::path::{Path, PathBuf};

use serde_json::json;

use crate::analysis::{self, Analysis, AnalysisOptions, ImageSink, Progress};
use crate::error::Result;
use crate::image::Plane;
use crate::io::plot::overlay_png;
use crate::io::series::{ImageRef, Series};
use crate::io::staging::Staging;
use crate::io::tiff::write::encode_u8_stack;
use crate::measure::Mask;
use crate::report::{inputs_json, threshold_json, Report};

/// Everything `analyze` needs, already validated.
#[derive(Debug, Clone)]
pub struct AnalyzeRequest {
    /// The series with forces.
    pub series: Series,
    /// Analysis options.
    pub options: AnalysisOptions,
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
    let sink = |i: usize, image: &ImageRef, plane: &Plane, mask: &Mask| -> Result<()> {
        write_image_outputs(&staging, request, i, image, plane, mask)
    };
    let sink: ImageSink = &sink;
    let analysis = analysis::analyze(&request.series, &request.options, progress, sink)?;
    let report = Report::new(&analysis, request.options.hertz);
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
            crate::report::AreaUnit::SquareMicrometre => "um2",
            crate::report::AreaUnit::Pixel => "px",
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
    image: &ImageRef,
    plane: &Plane,
    mask: &Mask,
) -> Result<()> {
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
