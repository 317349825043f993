//! The seed corpus: small valid inputs of every kind a command reads, made fresh for each campaign
//! by the binary itself (series, surfaces, simulations, PSF JSON) and by the library's seeded
//! generators (beads, Newton rings, friction traces). Nothing is copied from elsewhere, so the
//! harness runs on a clean checkout without `../shared`.

use std::fs;
use std::path::Path;
use std::process::Command;

use contactscope::mechanics::friction::XAxis;
use contactscope::synth::beads::{synth_beads, BeadParams};
use contactscope::synth::rings::{synth_newton, NewtonSynthParams};
use contactscope::synth::traces::{synthetic_trace, trace_csv, CsvLayout, TraceParams};
use contactscope_formats::tiff::encode_u16_stack;

/// Run the binary in `dir` and insist that it wrote its outputs (success, or status 4: the tiny
/// seed simulation's contacts reach the border of its map).
fn cli(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("binary runs");
    assert!(
        out.status.success() || out.status.code() == Some(4),
        "seed {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A 32×32 map as a whitespace-separated text matrix (heights in nm, one row per line).
fn text_matrix(dir: &Path) {
    let mut text = String::from("# heights in nm\n");
    for y in 0..32 {
        let row: Vec<String> = (0..32)
            .map(|x| {
                format!(
                    "{:.3}",
                    20.0 * ((x as f64) * 0.4).sin() * ((y as f64) * 0.3).cos()
                )
            })
            .collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    fs::write(dir.join("t.txt"), text).unwrap();
}

/// A small Nanonis `.sxm` scan (`crates/formats/src/topography/sxm.rs`): a current channel saved
/// forward only and a height saved in both directions, 6 × 4 pixels, one point not scanned.
fn sxm(dir: &Path) {
    let (nx, ny) = (6, 4);
    let z: Vec<f32> = (0..nx * ny)
        .map(|i| (i as f32 * 0.7).sin() * 2e-9)
        .collect();
    let mut back = z.clone();
    back[5] = f32::NAN;
    let current = vec![1e-12f32; nx * ny];
    use contactscope_formats::topography::sxm::{encode_sxm, SxmSignal};
    let signals = [
        SxmSignal {
            name: "Current",
            unit: "A",
            forward: &current,
            backward: None,
        },
        SxmSignal {
            name: "Z",
            unit: "m",
            forward: &z,
            backward: Some(&back),
        },
    ];
    let bytes = encode_sxm((nx, ny), (6e-9, 4e-9), "up", &signals);
    fs::write(dir.join("t.sxm"), bytes).unwrap();
}

/// A multi-image OME-TIFF (`crates/formats/src/tiff/axes.rs`): two stage positions of three
/// time points each, 48² 16-bit pages, their OME-XML (image names, pixel sizes, `TiffData`) in
/// the first page's description, as tifffile writes one series after another.
fn ome_images(dir: &Path) {
    use tiff::encoder::{colortype, TiffEncoder};
    const W: usize = 48;
    let images: String = (0..2)
        .map(|k| {
            format!(
                r#"<Image ID="Image:{k}" Name="position {k}"><Pixels ID="Pixels:{k}" DimensionOrder="XYCZT" Type="uint16" SizeX="{W}" SizeY="{W}" SizeC="1" SizeZ="1" SizeT="3" PhysicalSizeX="0.2" PhysicalSizeY="0.2"><Channel ID="Channel:{k}:0" Name="fluo" SamplesPerPixel="1"/><TiffData IFD="{}" PlaneCount="3"/></Pixels></Image>"#,
                3 * k
            )
        })
        .collect();
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06">{images}</OME>"#
    );
    let mut enc = TiffEncoder::new(fs::File::create(dir.join("two.ome.tif")).unwrap()).unwrap();
    for page in 0..6 {
        let r = 4.0 + 3.0 * (page % 3) as f64;
        let pixels: Vec<u16> = (0..W * W)
            .map(|i| {
                let (x, y) = ((i % W) as f64 - 23.5, (i / W) as f64 - 23.5);
                300 + ((i * 7919) % 23) as u16 + if x * x + y * y < r * r { 2000 } else { 0 }
            })
            .collect();
        let mut image = enc
            .new_image::<colortype::Gray16>(W as u32, W as u32)
            .unwrap();
        if page == 0 {
            image
                .encoder()
                .write_tag(tiff::tags::Tag::ImageDescription, xml.as_str())
                .unwrap();
        }
        image.write_data(&pixels).unwrap();
    }
}

/// A small WSxM `.top` file as `crates/formats/src/topography/wsxm.rs` documents the format: three text lines,
/// an INI-like header, `[Header end]`, then int16 little-endian heights.
fn wsxm(dir: &Path) {
    let (nx, ny) = (24usize, 20usize);
    let body = "[Control]\r\n\
                X Amplitude: 4.8 \u{b5}m\r\n\
                Y Amplitude: 4 \u{b5}m\r\n\
                [General Info]\r\n\
                Number of columns: 24\r\n\
                Number of rows: 20\r\n\
                Z Amplitude: 30 nm\r\n\
                [Head Settings]\r\n\
                Z Calibration: 1 nm\r\n\
                [Miscellaneous]\r\n\
                Maximum: 1000\r\n\
                Minimum: -1000\r\n\
                [Header end]\r\n";
    // The header size line counts itself; iterate until the number is stable.
    let mut size = 0;
    let mut header = String::new();
    for _ in 0..4 {
        header = format!(
            "WSxM file copyright UAM\r\nSxM Image file\r\nImage header size: {size}\r\n\r\n{body}"
        );
        size = header.len();
    }
    let mut bytes: Vec<u8> = header.chars().map(|c| c as u8).collect();
    for k in 0..nx * ny {
        let v = ((k as f64 * 0.37).sin() * 900.0) as i16;
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    fs::write(dir.join("t.top"), bytes).unwrap();
}

/// A small Bruker Nanoscope file (`crates/formats/src/topography/nanoscope.rs`): a `\*File list` text header with a
/// scan list and one height image of int16 data at its data offset.
fn nanoscope(dir: &Path) {
    let n = 16usize;
    let offset = 2048usize;
    let header = format!(
        "\\*File list\r\n\\Data length: {offset}\r\n\\*Ciao scan list\r\n\
         \\Scan Size: 2 2 um\r\n\\@Sens. Zsens: V 20 nm/V\r\n\
         \\*Ciao image list\r\n\\Data offset: {offset}\r\n\\Data length: {}\r\n\
         \\Bytes/pixel: 2\r\n\\Samps/line: {n}\r\n\\Number of lines: {n}\r\n\
         \\Scan Size: 2 2 um\r\n\
         \\@2:Z scale: V [Sens. Zsens] (0.006713867 V/LSB) 440 V\r\n\
         \\@2:Image Data: S [Height] \"Height\"\r\n\
         \\*File list end\r\n",
        2 * n * n
    );
    // The same image in a force-volume file: `\*Force file list` and a force-curve channel
    // (whose curves are named, never read) beside the image.
    let force = header
        .replacen("\\*File list\r\n", "\\*Force file list\r\n", 1)
        .replacen(
            "\\*File list end",
            "\\*Ciao force image list\r\n\\Data offset: 4096\r\n\\Samps/line: 64\r\n\
             \\@4:Image Data: S [DeflectionError] \"Deflection Error\"\r\n\\*File list end",
            1,
        );
    for (name, mut header) in [("t.di", header), ("t-force.spm", force)] {
        assert!(header.len() < offset);
        header.push_str(&"\0".repeat(offset - header.len()));
        let mut bytes = header.into_bytes();
        for k in 0..n * n {
            let v = ((k as f64 * 0.21).cos() * 8000.0) as i16;
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        fs::write(dir.join(name), bytes).unwrap();
    }
}

/// A Hertzian squeeze test: 2δ from F for R = 290 µm, E* = 3.7 MPa (soft sphere).
fn squeeze(dir: &Path) {
    let (r, e) = (290e-6f64, 3.7e6f64);
    let mut text = String::from("force_mN,displacement_um\n");
    for i in 1..=12 {
        let f = 0.5e-3 * i as f64;
        let delta = (9.0 * f * f / (16.0 * r * e * e)).cbrt();
        text.push_str(&format!("{},{}\n", f * 1e3, 2.0 * delta * 1e6));
    }
    fs::write(dir.join("squeeze.csv"), text).unwrap();
}

/// Every seed file, in `dir`. Takes about a second.
pub fn build(dir: &Path) {
    // Confocal load series (12-bit in 16-bit TIFF, 200 nm pixels) with its manifest.
    cli(
        dir,
        &[
            "synth-series",
            "--size",
            "96",
            "--forces",
            "1,2,4mN",
            "--out",
            "series",
        ],
    );
    // Micrographs matching the simulation's loads, for compare.
    cli(
        dir,
        &[
            "synth-series",
            "--size",
            "128",
            "--forces",
            "0.05,0.1mN",
            "--out",
            "exp",
        ],
    );
    // Topographies: npy, gsf and a contact.engineering surface container (surface), text,
    // WSxM, Nanoscope (writers above); the container also unpacked (its metadata and NetCDF
    // file mutable one by one).
    for name in ["t.npy", "t.gsf", "t.zip"] {
        cli(
            dir,
            &[
                "surface",
                "--size",
                "32",
                "--pixel-size",
                "200nm",
                "--rms-height",
                "20nm",
                "--out",
                name,
            ],
        );
    }
    zip::ZipArchive::new(fs::File::open(dir.join("t.zip")).unwrap())
        .unwrap()
        .extract(dir.join("tc"))
        .unwrap();
    text_matrix(dir);
    ome_images(dir);
    wsxm(dir);
    nanoscope(dir);
    sxm(dir);
    // Committed fixtures of the vendor formats (fixtures/README.md says how each was made).
    for (fixture, seed) in [
        ("topostats/tiny.topostats", "t.topostats"),
        ("jpk/tiny.jpk", "t.jpk"),
        ("jpk/tiny.h5-jpk", "t.h5-jpk"),
        ("sflz/zlib_u4.sflz", "t.sflz"),
        ("sflz/lzma_f8.sflz", "t-lzma.sflz"),
        ("sflz/earlier_zlib_u4.sflz", "t-earlier.sflz"),
        ("createc/A250407.141806.dat", "t-createc.dat"),
        ("zon/tiny.zon", "t.zon"),
        ("zon/tiny-plain.zon", "t-plain.zon"),
    ] {
        fs::copy(
            crate::common::root().join("fixtures").join(fixture),
            dir.join(seed),
        )
        .unwrap();
    }
    // A simulation folder and an analysis of the series (areas.csv for fits and friction).
    cli(
        dir,
        &[
            "simulate",
            "--topography",
            "t.npy",
            "--pixel-size",
            "200nm",
            "--radius",
            "20um",
            "--modulus",
            "3.7GPa",
            "--model",
            "elastic",
            "--forces",
            "0.05,0.1mN",
            "--out",
            "sim",
            "-q",
        ],
    );
    cli(
        dir,
        &[
            "analyze",
            "series/series.tif",
            "--forces",
            "1,2,4mN",
            // Areas of a few µm², which the 6.4 µm maps of the fit templates can hold; an
            // uncertainty, so that the table has every interval column fit-hardening reads.
            "--pixel-size",
            "40nm±2%",
            "--out",
            "an",
            "-q",
        ],
    );
    // Beads at 100 nm pixels, and the PSF JSON measured on them.
    let beads = synth_beads(&BeadParams::default()).unwrap();
    let pages: Vec<&[u16]> = beads.planes.iter().map(Vec::as_slice).collect();
    let tiff = encode_u16_stack(
        &pages,
        beads.width,
        beads.height,
        Some((100e-9, 100e-9)),
        "",
    )
    .unwrap();
    fs::write(dir.join("beads.tif"), tiff).unwrap();
    cli(dir, &["psf", "beads.tif", "--out", "psf"]);
    // Newton rings: reflection and fluorescence at 200 nm, smaller than the default.
    let p = NewtonSynthParams {
        width: 160,
        height: 160,
        centre_px: (80.3, 79.6),
        contact_radius_m: 8e-6,
        ..NewtonSynthParams::default()
    };
    let rings = synth_newton(&p).unwrap();
    for (name, codes) in [
        ("reflection.tif", &rings.reflection),
        ("fluorescence.tif", &rings.fluorescence),
    ] {
        let bytes = encode_u16_stack(
            &[codes.as_slice()],
            p.width,
            p.height,
            Some((p.pixel_size_m, p.pixel_size_m)),
            "",
        )
        .unwrap();
        fs::write(dir.join(name), bytes).unwrap();
    }
    // A friction trace at 2 mN (normal force in a column), and a squeeze test.
    let trace = synthetic_trace(&TraceParams {
        static_friction_n: 2e-3,
        kinetic_friction_n: 1.6e-3,
        stiffness_n_per_m: 100.0,
        seed: 3,
        ..TraceParams::default()
    });
    let layout = CsvLayout {
        x_axis: XAxis::Displacement,
        torque: false,
        rotation_radius_m: 5e-3,
        normal_force_n: Some(2e-3),
    };
    fs::write(dir.join("trace.csv"), trace_csv(&trace, &layout)).unwrap();
    squeeze(dir);
    // A samplesheet of two series (the manifest folder, its TIFF with forces), metadata and a
    // fit row on the 6.4 µm map.
    fs::write(
        dir.join("sheet.csv"),
        "id,input,forces,pixel_size_nm,topography,topography_pixel_size,radius,modulus,models,sample\n\
         s1,series,,,,,,,,glass\n\
         s2,series/series.tif,\"1,2,4mN\",40,t.npy,200nm,20um,3.7GPa,hardening,steel\n",
    )
    .unwrap();
}
