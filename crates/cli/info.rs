//! `contactscope info`: describe a micrograph file: TIFF in detail; Zeiss CZI, Nikon ND2 and
//! Leica LIF (and TIFF with `--json`/`--stats`) by series, axes, sample type and pixel size.

use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::Result;

use contactscope_formats::microscopy::summary::InfoSummary;
use contactscope_formats::microscopy::Rows;
use contactscope_formats::units;
use contactscope_jobs::info::{self as job, tiff_details, InfoRequest};

use super::args::SelectionArgs;

#[derive(clap::Args)]
pub struct Args {
    /// A TIFF, CZI, ND2, LIF or OME-Zarr file.
    file: PathBuf,
    /// Print JSON: {"file", "format", "series": [{"index", "name", "axes", "dtype",
    /// "pixel_size_um": {"x", "y", "z"}, "pixel_size_source", "rows" (X–Z/X–T scans), "planes"}]} (docs/formats.md).
    #[arg(long)]
    json: bool,
    /// Decode every plane and add its min, max, mean and sum ("planes").
    #[arg(long)]
    stats: bool,
    /// Restrict the listing: --series keeps one series, --channel/--z/--t the planes of --stats.
    #[command(flatten)]
    select: SelectionArgs,
}

pub fn run(args: Args) -> Result<()> {
    let selection = args.select.selection();
    let selected = selection != Default::default();
    if args.json || args.stats || selected || !is_tiff(&args.file) {
        let outcome = job::run(&InfoRequest {
            file: args.file.clone(),
            stats: args.stats,
            selection,
        })?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&outcome)?);
        } else {
            print_summary(&outcome.summary);
        }
        return Ok(());
    }
    let i = tiff_details(&args.file)?;
    println!("file:         {}", i.path.display());
    println!("pages:        {}", i.pages.len());
    println!(
        "shape:        {} × {} px (width × height)",
        i.width, i.height
    );
    println!(
        "sample type:  {} ({} bits)",
        i.sample_type.name(),
        i.bits_per_sample
    );
    println!(
        "channels:     {} ({})",
        i.channels,
        i.channel_layout.describe()
    );
    if i.images.len() > 1 {
        println!(
            "images:       {} in its OME-XML, each a series: choose one with --series 0..{}, or \
             read them as the loads with --load-axis series",
            i.images.len(),
            i.images.len() - 1
        );
        for series in contactscope_formats::microscopy::tiff_series(&i) {
            let name = match series.name.as_str() {
                "" => String::new(),
                n => format!(" '{n}'"),
            };
            let size = match (series.pixel_size.x_m, series.pixel_size.y_m) {
                (Some(x), Some(y)) => format!(
                    ", {} × {} pixels",
                    units::format_length(x),
                    units::format_length(y)
                ),
                _ => ", no pixel size".into(),
            };
            let a = &series.axes;
            println!(
                "  series {}{name}: T {} × Z {} × C {}, {} × {} px{size}",
                series.index, a.t, a.z, a.c, a.x, a.y
            );
        }
        println!("axes:         series 0: {}", tiff_axes(&i.axes));
    } else {
        println!("axes:         {}", tiff_axes(&i.axes));
    }
    println!(
        "compression:  {} (predictor: {}), {}{}, {}-endian",
        i.compression,
        i.predictor,
        if i.tiled { "tiled" } else { "strips" },
        if i.bigtiff { ", BigTIFF" } else { "" },
        i.byte_order
    );
    match &i.metadata_file {
        Some(file) => println!(
            "description:  {}, read from the set's metadata file {}",
            i.description_kind,
            file.display()
        ),
        None => println!("description:  {}", i.description_kind),
    }
    if let Some(q) = &i.quantity {
        let unit = i
            .value_unit
            .as_deref()
            .map_or(String::new(), |u| format!(" in {u}"));
        println!("values:       {}{unit}", q.replace('_', " "));
    }
    match i.pixel_size {
        Some(p) => println!(
            "pixel size:   {} × {} from {}",
            units::format_length(p.x_m),
            units::format_length(p.y_m),
            p.source.describe()
        ),
        None => println!("pixel size:   none in the metadata (use --pixel-size)"),
    }
    for note in &i.notes {
        println!("note:         {note}");
    }
    Ok(())
}

/// `T 4 × Z 2 × C 2 from OME-XML; z step 0.5 µm; channels 0 'fluo', 1 'refl'` and what a
/// load series takes from them.
fn tiff_axes(a: &contactscope_formats::tiff::TiffAxes) -> String {
    use contactscope_formats::tiff::AxesSource;
    let mut s = format!(
        "T {} × Z {} × C {} from {}",
        a.t,
        a.z,
        a.c,
        a.source.describe()
    );
    if let Some(step) = a.z_step_m {
        s.push_str(&format!("; z step {}", units::format_length(step)));
    }
    if let Some(dt) = a.time_increment_s {
        s.push_str(&format!("; {dt} s between time points"));
    }
    if a.channel_names.iter().any(Option::is_some) {
        let names: Vec<String> = a
            .channel_names
            .iter()
            .enumerate()
            .map(|(k, n)| match n {
                Some(n) => format!("{k} '{n}'"),
                None => k.to_string(),
            })
            .collect();
        s.push_str(&format!("; channels {}", names.join(", ")));
    }
    let loads = match (a.source, a.t > 1, a.z > 1) {
        (AxesSource::Pages, true, _) => "; a load series takes the pages in file order",
        (_, true, true) => "; a load series takes the time points of one --z",
        (_, true, false) => "; a load series takes the time points",
        (_, false, true) if a.is_z_stack() => "; a z stack: a load series only with --load-axis z",
        (_, false, true) => "; a load series takes the focal planes",
        _ => "",
    };
    s.push_str(loads);
    if !a.other_files.is_empty() {
        s.push_str(&format!(
            "; planes read from other files of its OME set: {}",
            a.other_files.join(", ")
        ));
    }
    s
}

/// A TIFF by its signature (classic or BigTIFF, either byte order); unreadable files are left to
/// the readers, whose errors name them.
fn is_tiff(path: &Path) -> bool {
    let mut head = [0u8; 4];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| matches!(&head, b"II*\0" | b"MM\0*" | b"II+\0" | b"MM\0+"))
}

fn print_summary(summary: &InfoSummary) {
    println!("file:         {}", summary.file);
    println!("format:       {}", summary.format);
    for s in &summary.series {
        let a = &s.axes;
        let name = if s.name.is_empty() {
            String::new()
        } else {
            format!(" '{}'", s.name)
        };
        let extra: String = a
            .extra
            .iter()
            .map(|(axis, n)| format!(" × {axis} {n}"))
            .collect();
        println!(
            "series {}{name}: T {} × Z {} × C {}{extra} × Y {} × X {}, {}",
            s.index, a.t, a.z, a.c, a.y, a.x, s.dtype
        );
        if !s.rows.is_y() {
            println!("  {}", s.rows.describe());
        }
        if s.channels.iter().any(|c| c.name.is_some()) {
            let names: Vec<String> = s
                .channels
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    let nm = c
                        .emission_m
                        .map_or(String::new(), |w| format!(", emission {:.0} nm", w * 1e9));
                    match &c.name {
                        Some(n) => format!("{i} '{n}'{nm}"),
                        None => format!("{i}{nm}"),
                    }
                })
                .collect();
            println!("  channels (--channel INDEX or NAME): {}", names.join("; "));
        }
        let p = &s.pixel_size_um;
        match (p.x, p.y) {
            (Some(x), Some(y)) => println!(
                "  pixel size: {} × {}{} from {}",
                units::format_length(x * 1e-6),
                units::format_length(y * 1e-6),
                p.z.map_or(String::new(), |z| format!(
                    ", z step {}",
                    units::format_length(z * 1e-6)
                )),
                s.pixel_size_source.as_deref().unwrap_or("the file")
            ),
            (Some(x), None) if s.rows == Rows::T => println!(
                "  pixel size: {} along x; rows are time points (no length)",
                units::format_length(x * 1e-6)
            ),
            _ => println!("  pixel size: none in the metadata (use --pixel-size)"),
        }
        for plane in s.planes.iter().flatten() {
            println!(
                "  t {} z {} c {}: min {} max {} mean {:.4} sum {}",
                plane.index.t,
                plane.index.z,
                plane.index.c,
                plane.min,
                plane.max,
                plane.mean,
                plane.sum
            );
        }
    }
}
