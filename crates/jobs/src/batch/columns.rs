//! The columns of the batch's tables, from the series' records, the samplesheet's metadata and
//! the flags (`docs/outputs.md` describes every column). Both tables start with `series_id` and
//! the metadata columns, so that either can be grouped and filtered by them alone.
//!
//! Every absent value is a null (an empty CSV cell), an empty list of flags or warnings too, so
//! that the CSV and the Parquet file say the same.
//!
//! Area columns follow `areas.csv`: `_um2` (and `_um`) for series with a pixel size, `_px` for
//! series without one; the `_px` columns exist only when some series is in pixels, and the
//! `friction_mN` and Hertz columns only when some series has them.

use contactscope_formats::units;

use super::flags::Flag;
use super::options::Command;
use super::record::{ImageResult, Record, SeriesResult};
use super::sheet::{MetaColumn, MetaKind, Row};
use super::tables::{Table, Values};
use super::terms::in_batch_terms;

/// One series as the tables see it.
pub struct Entry<'a> {
    /// Its samplesheet row (id, input, metadata).
    pub row: &'a Row,
    /// Its record.
    pub record: &'a Record,
    /// Its flags.
    pub flags: &'a [Flag],
}

fn metadata_columns(table: &mut Table, metadata: &[MetaColumn], per_row: &[&Row]) {
    for (k, column) in metadata.iter().enumerate() {
        let cells = per_row.iter().map(|r| r.metadata[k].as_str());
        let values = match column.kind {
            MetaKind::Number => Values::Float(
                cells
                    .map(|c| c.parse::<f64>().ok().filter(|v| v.is_finite()))
                    .collect(),
            ),
            MetaKind::Text => Values::Text(
                cells
                    .map(|c| (!c.is_empty()).then(|| c.to_string()))
                    .collect(),
            ),
        };
        table.push(column.name.clone(), values);
    }
}

/// `images`: one row per image of every series that was analysed.
pub fn images_table(metadata: &[MetaColumn], entries: &[Entry]) -> Table {
    let rows: Vec<(&Entry, &SeriesResult, usize, &ImageResult)> = entries
        .iter()
        .filter_map(|e| e.record.result.as_ref().map(|r| (e, r)))
        .flat_map(|(e, r)| {
            r.images
                .iter()
                .enumerate()
                .map(move |(i, image)| (e, r, i, image))
        })
        .collect();
    let mut t = Table::new(rows.len());
    t.text("series_id", rows.iter().map(|r| Some(r.0.row.id.clone())));
    let sheet_rows: Vec<&Row> = rows.iter().map(|r| r.0.row).collect();
    metadata_columns(&mut t, metadata, &sheet_rows);
    let um = |r: &SeriesResult| r.area_unit == "um2";
    let any_px = rows.iter().any(|r| !um(r.1));
    t.int("image_index", rows.iter().map(|r| Some(r.2 as i64)));
    t.text("image", rows.iter().map(|r| Some(r.3.image.clone())));
    t.int("page", rows.iter().map(|r| Some(r.3.page as i64)));
    t.float("force_mN", rows.iter().map(|r| r.3.force_mn));
    t.float("threshold", rows.iter().map(|r| Some(r.3.threshold)));
    t.int(
        "contact_pixels",
        rows.iter().map(|r| Some(r.3.contact_pixels as i64)),
    );
    let in_unit = |want_um: bool, value: fn(&ImageResult) -> f64| {
        rows.iter()
            .map(move |r| (um(r.1) == want_um).then(|| value(r.3)))
            .collect::<Vec<_>>()
    };
    t.float("area_um2", in_unit(true, |i| i.area));
    if any_px {
        t.float("area_px", in_unit(false, |i| i.area));
    }
    // The corrected area and the interval on the true area (empty for a series analysed
    // before they existed, or an image without contact light).
    let finite = |v: Vec<Option<f64>>| v.into_iter().map(|x| x.filter(|x| x.is_finite()));
    t.float(
        "area_corrected_um2",
        finite(in_unit(true, |i| i.area_corrected)),
    );
    if any_px {
        t.float(
            "area_corrected_px",
            finite(in_unit(false, |i| i.area_corrected)),
        );
    }
    t.float("area_um2_lo", finite(in_unit(true, |i| i.area_lo)));
    t.float("area_um2_hi", finite(in_unit(true, |i| i.area_hi)));
    if any_px {
        t.float("area_px_lo", finite(in_unit(false, |i| i.area_lo)));
        t.float("area_px_hi", finite(in_unit(false, |i| i.area_hi)));
    }
    t.float("mean_intensity", rows.iter().map(|r| r.3.mean_intensity));
    t.float(
        "integrated_intensity",
        rows.iter().map(|r| Some(r.3.integrated_intensity)),
    );
    t.float("background_mean", rows.iter().map(|r| r.3.background_mean));
    t.int("patches", rows.iter().map(|r| Some(r.3.patches as i64)));
    t.float("largest_patch_um2", in_unit(true, |i| i.largest_patch));
    if any_px {
        t.float("largest_patch_px", in_unit(false, |i| i.largest_patch));
    }
    t.float(
        "mean_pressure_MPa",
        rows.iter().map(|r| r.3.mean_pressure_mpa),
    );
    t.float(
        "mean_pressure_MPa_lo",
        rows.iter().map(|r| r.3.mean_pressure_mpa_lo),
    );
    t.float(
        "mean_pressure_MPa_hi",
        rows.iter().map(|r| r.3.mean_pressure_mpa_hi),
    );
    t.float(
        "equivalent_radius_um",
        in_unit(true, |i| i.equivalent_radius),
    );
    if any_px {
        t.float(
            "equivalent_radius_px",
            in_unit(false, |i| i.equivalent_radius),
        );
    }
    if rows.iter().any(|r| r.3.friction_mn.is_some()) {
        t.float("friction_mN", rows.iter().map(|r| r.3.friction_mn));
    }
    if rows.iter().any(|r| r.3.hertz_radius_um.is_some()) {
        t.float("hertz_radius_um", rows.iter().map(|r| r.3.hertz_radius_um));
        t.float("hertz_area_um2", rows.iter().map(|r| r.3.hertz_area_um2));
    }
    // As areas.csv has it (there only when not 0): the relative uncertainty of the pixel size
    // that the area intervals carry.
    t.float(
        "pixel_size_uncertainty_pct",
        rows.iter()
            .map(|r| Some(units::in_unit(r.1.pixel_size_uncertainty, 100.0))),
    );
    t.bool("edge_contact", rows.iter().map(|r| Some(r.3.edge_contact)));
    t
}

/// `series`: one row per series of the samplesheet.
pub fn series_table(metadata: &[MetaColumn], entries: &[Entry]) -> Table {
    let mut t = Table::new(entries.len());
    let result = |e: &Entry| e.record.result.clone();
    let results: Vec<Option<SeriesResult>> = entries.iter().map(result).collect();
    let r = || results.iter().map(Option::as_ref);
    t.text("series_id", entries.iter().map(|e| Some(e.row.id.clone())));
    let sheet_rows: Vec<&Row> = entries.iter().map(|e| e.row).collect();
    metadata_columns(&mut t, metadata, &sheet_rows);
    t.text(
        "status",
        entries
            .iter()
            .map(|e| Some(e.record.status.name().to_string())),
    );
    t.text(
        "failed_stage",
        entries.iter().map(|e| e.record.failed_stage.clone()),
    );
    t.text(
        "error",
        entries.iter().map(|e| {
            let stage = match e.record.failed_stage.as_deref() {
                Some("fit-hardening") => Command::Fit,
                _ => Command::Analyze,
            };
            e.record.error.as_deref().map(|m| in_batch_terms(m, stage))
        }),
    );
    t.text(
        "input",
        entries.iter().map(|e| Some(e.row.input_text.clone())),
    );
    t.int("images", r().map(|x| x.map(|x| x.images.len() as i64)));
    t.int("width_px", r().map(|x| x.map(|x| x.width_px as i64)));
    t.int("height_px", r().map(|x| x.map(|x| x.height_px as i64)));
    t.text("sample_type", r().map(|x| x.map(|x| x.sample_type.clone())));
    t.text(
        "threshold_method",
        r().map(|x| x.map(|x| x.threshold_method.clone())),
    );
    t.float("threshold", r().map(|x| x.and_then(|x| x.threshold)));
    t.float(
        "pixel_size_x_um",
        r().map(|x| x.and_then(|x| x.pixel_size_um).map(|p| p.0)),
    );
    t.float(
        "pixel_size_y_um",
        r().map(|x| x.and_then(|x| x.pixel_size_um).map(|p| p.1)),
    );
    t.text(
        "pixel_size_source",
        r().map(|x| {
            x.and_then(|x| match (x.pixel_size_from_default, x.pixel_size_given) {
                (true, _) => Some("batch default for files without one".to_string()),
                (false, true) => Some("samplesheet (pixel_size)".to_string()),
                (false, false) => x.pixel_size_source.clone(),
            })
        }),
    );
    t.float(
        "pixel_size_uncertainty_pct",
        r().map(|x| x.map(|x| units::in_unit(x.pixel_size_uncertainty, 100.0))),
    );
    t.text("area_unit", r().map(|x| x.map(|x| x.area_unit.clone())));
    fn max_force(x: &SeriesResult) -> Option<(f64, &ImageResult)> {
        x.images
            .iter()
            .filter_map(|i| i.force_mn.map(|f| (f, i)))
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }
    t.float(
        "max_force_mN",
        r().map(|x| x.and_then(max_force).map(|(f, _)| f)),
    );
    let any_px = r().flatten().any(|x| x.area_unit != "um2");
    let at_max = |want_um: bool| {
        r().map(move |x| {
            x.filter(|x| (x.area_unit == "um2") == want_um)
                .and_then(max_force)
                .map(|(_, i)| i.area)
        })
        .collect::<Vec<_>>()
    };
    t.float("area_at_max_force_um2", at_max(true));
    if any_px {
        t.float("area_at_max_force_px", at_max(false));
    }
    let law = || r().map(|x| x.and_then(|x| x.power_law));
    t.float("power_law_exponent", law().map(|p| p.map(|p| p.exponent)));
    t.float(
        "power_law_exponent_se",
        law().map(|p| p.and_then(|p| p.exponent_se)),
    );
    t.float(
        "power_law_exponent_lo",
        law().map(|p| p.and_then(|p| p.exponent_ci95).map(|c| c.0)),
    );
    t.float(
        "power_law_exponent_hi",
        law().map(|p| p.and_then(|p| p.exponent_ci95).map(|c| c.1)),
    );
    let prefactor = |want_um: bool| {
        r().map(move |x| {
            x.filter(|x| (x.area_unit == "um2") == want_um)
                .and_then(|x| x.power_law)
                .map(|p| p.prefactor)
        })
        .collect::<Vec<_>>()
    };
    t.float(
        "power_law_prefactor_um2_per_mN_pow_exponent",
        prefactor(true),
    );
    if any_px {
        t.float(
            "power_law_prefactor_px_per_mN_pow_exponent",
            prefactor(false),
        );
    }
    t.float(
        "power_law_r_squared",
        law().map(|p| p.and_then(|p| p.r_squared)),
    );
    t.int(
        "power_law_points",
        law().map(|p| p.map(|p| p.points as i64)),
    );
    t.float(
        "proportional_pressure_MPa",
        r().map(|x| x.and_then(|x| x.proportional_mpa).map(|p| p.0)),
    );
    t.float(
        "mean_pressure_min_MPa",
        r().map(|x| x.and_then(|x| x.mean_pressure_range_mpa).map(|p| p.0)),
    );
    t.float(
        "mean_pressure_max_MPa",
        r().map(|x| x.and_then(|x| x.mean_pressure_range_mpa).map(|p| p.1)),
    );
    if entries
        .iter()
        .any(|e| e.record.command_lines.fit_hardening.is_some())
    {
        let fit = || entries.iter().map(|e| e.record.fit.as_ref());
        t.float(
            "k_MPa_per_nm",
            fit().map(|f| f.and_then(|f| f.k_pa_per_m).map(|k| k * 1e-15)),
        );
        t.float(
            "k_se_MPa_per_nm",
            fit().map(|f| f.and_then(|f| f.k_se_pa_per_m).map(|k| k * 1e-15)),
        );
        t.float(
            "k_MPa_per_nm_lo",
            fit().map(|f| f.and_then(|f| f.k_ci95_pa_per_m).map(|k| k.0 * 1e-15)),
        );
        t.float(
            "k_MPa_per_nm_hi",
            fit().map(|f| f.and_then(|f| f.k_ci95_pa_per_m).map(|k| k.1 * 1e-15)),
        );
        t.float(
            "hardening_misfit",
            fit().map(|f| f.and_then(|f| f.k_misfit)),
        );
        t.float(
            "hardness_MPa",
            fit().map(|f| f.and_then(|f| f.hardness_pa).map(|p| p * 1e-6)),
        );
        t.float(
            "hardness_se_MPa",
            fit().map(|f| f.and_then(|f| f.hardness_se_pa).map(|p| p * 1e-6)),
        );
        t.float(
            "hardness_MPa_lo",
            fit().map(|f| f.and_then(|f| f.hardness_ci95_pa).map(|p| p.0 * 1e-6)),
        );
        t.float(
            "hardness_MPa_hi",
            fit().map(|f| f.and_then(|f| f.hardness_ci95_pa).map(|p| p.1 * 1e-6)),
        );
        t.float(
            "hardness_misfit",
            fit().map(|f| f.and_then(|f| f.hardness_misfit)),
        );
        t.float(
            "elastic_misfit",
            fit().map(|f| f.and_then(|f| f.elastic_misfit)),
        );
        t.float("gt_misfit", fit().map(|f| f.and_then(|f| f.gt_misfit)));
        t.text(
            "best_model",
            fit().map(|f| f.and_then(|f| f.best_model.clone())),
        );
    }
    t.text(
        "flags",
        entries.iter().map(|e| {
            let codes: Vec<&str> = e.flags.iter().map(|f| f.code).collect();
            (!codes.is_empty()).then(|| codes.join(","))
        }),
    );
    t.text(
        "flag_notes",
        entries.iter().map(|e| {
            let notes: Vec<String> = e
                .flags
                .iter()
                .map(|f| format!("{}: {}", f.code, f.text))
                .collect();
            (!notes.is_empty()).then(|| notes.join(" | "))
        }),
    );
    t.text(
        "warnings",
        entries.iter().map(|e| {
            let mut all: Vec<String> = e
                .record
                .result
                .iter()
                .flat_map(|r| {
                    r.warnings
                        .iter()
                        .map(|w| in_batch_terms(w, Command::Analyze))
                })
                .collect();
            all.extend(e.record.fit.iter().flat_map(|f| {
                f.warnings
                    .iter()
                    .map(|w| format!("fit-hardening: {}", in_batch_terms(w, Command::Fit)))
            }));
            (!all.is_empty()).then(|| all.join(" | "))
        }),
    );
    t.text(
        "folder",
        entries.iter().map(|e| {
            e.record
                .result
                .is_some()
                .then(|| format!("series/{}", e.row.id))
        }),
    );
    if entries
        .iter()
        .any(|e| e.record.command_lines.fit_hardening.is_some())
    {
        t.text(
            "fit_folder",
            entries
                .iter()
                .map(|e| e.record.fit.is_some().then(|| format!("fit/{}", e.row.id))),
        );
    }
    t
}
