//! A TIFF's pages read by the axes its metadata states (issue: "no wrong number from a file's
//! axes"): an OME-TIFF's channels are not pooled into one series, an ImageJ hyperstack's focal
//! planes are not taken for loads, a z stack is not a load series unless told so, a multi-file
//! OME set is read whole (once) from any of its files, also when its metadata is kept in a
//! companion file, and each image of a multi-image OME-TIFF is a series of its own.
//!
//! The files are written here page by page with the ImageDescription each writer would give
//! (OME-XML as tifffile writes it for axes TCYX; ImageJ's `channels/slices/frames`), and each
//! result is compared with the same planes written as a plain single-channel TIFF.

use std::path::{Path, PathBuf};

use tiff::encoder::{colortype, TiffEncoder};
use tiff::tags::Tag;

use crate::common::{run, run_ok, stderr};

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

const W: usize = 48;

/// A 48² plane: background 300 + a small ripple, a disk of radius `r` at `level` above it.
fn disk(r: f64, level: u16, shift: u16) -> Vec<u16> {
    (0..W * W)
        .map(|i| {
            let (x, y) = ((i % W) as f64 - 23.5, (i / W) as f64 - 23.5);
            let ripple = ((i * 7919) % 23) as u16;
            300 + shift + ripple + if x * x + y * y < r * r { level } else { 0 }
        })
        .collect()
}

/// Pages with `description` on the first one (uncompressed, 16-bit grey).
fn write_tiff(path: &Path, pages: &[Vec<u16>], description: &str) {
    let file = std::fs::File::create(path).unwrap();
    let mut enc = TiffEncoder::new(file).unwrap();
    for (k, page) in pages.iter().enumerate() {
        let mut image = enc
            .new_image::<colortype::Gray16>(W as u32, W as u32)
            .unwrap();
        if k == 0 {
            image
                .encoder()
                .write_tag(Tag::ImageDescription, description)
                .unwrap();
        }
        image.write_data(page).unwrap();
    }
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

fn threshold(dir: &Path) -> f64 {
    summary(dir)["threshold"]["value"].as_f64().unwrap()
}

fn areas(dir: &Path) -> Vec<f64> {
    let (header, rows) = crate::common::read_csv(&dir.join("areas.csv"));
    crate::common::column(&header, &rows, "contact_pixels")
}

/// analyze into `out`; the command must succeed.
fn analyze(file: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec!["analyze", s(file), "--pixel-size", "200nm", "--out", s(out)];
    args.extend_from_slice(extra);
    run_ok(&args);
}

fn refused(args: &[&str]) -> String {
    let out = run(args);
    assert!(!out.status.success(), "{args:?} should fail");
    stderr(&out)
}

#[test]
fn ome_tiff_channels_are_channels_not_pages() {
    let tmp = tempfile::tempdir().unwrap();
    let radii = [4.0, 7.0, 10.0, 13.0];
    // TCYX: channel 0 fluorescence (disks growing with the load), channel 1 a bright reflection.
    let fluo: Vec<Vec<u16>> = radii.iter().map(|&r| disk(r, 2000, 0)).collect();
    let refl: Vec<Vec<u16>> = radii.iter().map(|_| disk(20.0, 800, 1200)).collect();
    let pages: Vec<Vec<u16>> = (0..4)
        .flat_map(|t| [fluo[t].clone(), refl[t].clone()])
        .collect();
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06" Creator="tifffile.py 2026.3.3"><Image ID="Image:0" Name="Image0"><Pixels ID="Pixels:0" DimensionOrder="XYCZT" Type="uint16" SizeX="{W}" SizeY="{W}" SizeC="2" SizeZ="1" SizeT="4" PhysicalSizeX="0.2" PhysicalSizeXUnit="um" PhysicalSizeY="0.2" PhysicalSizeYUnit="um"><Channel ID="Channel:0:0" Name="fluo" SamplesPerPixel="1"/><Channel ID="Channel:0:1" Name="refl" SamplesPerPixel="1"/><TiffData IFD="0" PlaneCount="8"/></Pixels></Image></OME>"#
    );
    let ome = tmp.path().join("tcyx.ome.tif");
    write_tiff(&ome, &pages, &xml);
    let plain = tmp.path().join("fluo.tif");
    write_tiff(&plain, &fluo, "plain pages");

    // info names the axes and the channels.
    let info = run_ok(&["info", s(&ome), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let series = &info["series"][0];
    assert_eq!(series["axes"]["C"], 2);
    assert_eq!(series["axes"]["T"], 4);
    assert_eq!(series["channels"][1]["name"], "refl");
    assert_eq!(series["axes_from"], "ome");
    assert!(info.get("metadata_file").is_none(), "{info}");

    // Without a channel: one refusal naming both channels.
    let forces = "4,10,20,40mN";
    let e = refused(&["analyze", s(&ome), "--forces", forces]);
    assert!(e.contains("2 channels") && e.contains("'fluo'"), "{e}");
    // By name and by index: the fluorescence alone, as the plain file gives it.
    let (by_name, by_index, alone) = (
        tmp.path().join("name"),
        tmp.path().join("index"),
        tmp.path().join("alone"),
    );
    analyze(&ome, &by_name, &["--channel", "fluo", "--forces", forces]);
    analyze(&ome, &by_index, &["--channel", "0", "--forces", forces]);
    analyze(&plain, &alone, &["--forces", forces]);
    assert_eq!(threshold(&by_name), threshold(&alone));
    assert_eq!(areas(&by_name), areas(&alone));
    assert_eq!(areas(&by_index), areas(&alone));
    // The reflection channel is a channel of its own, chosen by index.
    let refl_dir = tmp.path().join("refl");
    analyze(&ome, &refl_dir, &["--channel", "1", "--forces", forces]);
    assert_ne!(threshold(&refl_dir), threshold(&alone));
}

#[test]
fn imagej_hyperstack_focal_planes_are_not_loads() {
    let tmp = tempfile::tempdir().unwrap();
    let radii = [4.0, 7.0, 10.0, 13.0];
    // 4 time points × 2 focal planes (ImageJ order: slice fastest here, one channel).
    let focus: Vec<Vec<u16>> = radii.iter().map(|&r| disk(r, 2000, 0)).collect();
    let blurred: Vec<Vec<u16>> = radii.iter().map(|_| disk(18.0, 150, 0)).collect();
    let pages: Vec<Vec<u16>> = (0..4)
        .flat_map(|t| [focus[t].clone(), blurred[t].clone()])
        .collect();
    let hyper = tmp.path().join("tzyx.tif");
    write_tiff(
        &hyper,
        &pages,
        "ImageJ=1.54f\nimages=8\nslices=2\nframes=4\nhyperstack=true\nunit=micron\nspacing=0.5\nloop=false\n",
    );
    let plain = tmp.path().join("focus.tif");
    write_tiff(&plain, &focus, "plain pages");
    let forces = "4,10,20,40mN";
    let e = refused(&["analyze", s(&hyper), "--forces", forces]);
    assert!(e.contains("2 z planes") && e.contains("--z 0..1"), "{e}");
    let (z0, z1, alone) = (
        tmp.path().join("z0"),
        tmp.path().join("z1"),
        tmp.path().join("alone"),
    );
    analyze(
        &hyper,
        &z0,
        &["--load-axis", "t", "--z", "0", "--forces", forces],
    );
    analyze(&plain, &alone, &["--forces", forces]);
    assert_eq!(threshold(&z0), threshold(&alone));
    assert_eq!(areas(&z0), areas(&alone));
    // The other focal plane is there too, and is another image.
    analyze(&hyper, &z1, &["--z", "1", "--forces", forces]);
    assert_ne!(areas(&z1), areas(&alone));
}

#[test]
fn a_z_stack_is_a_load_series_only_when_told() {
    let tmp = tempfile::tempdir().unwrap();
    let pages: Vec<Vec<u16>> = [4.0, 7.0, 10.0, 13.0]
        .iter()
        .map(|&r| disk(r, 2000, 0))
        .collect();
    let stack = tmp.path().join("zstack.tif");
    write_tiff(
        &stack,
        &pages,
        "ImageJ=1.53f\nimages=4\nslices=4\nunit=micron\nspacing=0.5\nloop=false\n",
    );
    let forces = "4,10,20,40mN";
    let e = refused(&["analyze", s(&stack), "--forces", forces]);
    assert!(
        e.contains("zstack.tif")
            && e.contains("z stack (4 focal planes 0.5 µm apart")
            && e.contains("--load-axis z"),
        "{e}"
    );
    let out = tmp.path().join("z");
    analyze(&stack, &out, &["--load-axis", "z", "--forces", forces]);
    assert_eq!(areas(&out).len(), 4);
    // ImageJ slices without a spacing (how contactscope itself has written series) stay a
    // series.
    let slices = tmp.path().join("slices.tif");
    write_tiff(
        &slices,
        &pages,
        "ImageJ=1.11a\nimages=4\nslices=4\nloop=false\n",
    );
    analyze(&slices, &tmp.path().join("s"), &["--forces", forces]);
}

/// Decimal forces in file names: read as numbers (1.25 before 1.5 before 10), and the order
/// used is printed above the table and kept in `summary.json`.
#[test]
fn decimal_names_load_in_numeric_order_and_the_order_is_said() {
    let dir = tempfile::tempdir().unwrap();
    let synth = dir.path().join("synth");
    let o = crate::common::run(&[
        "synth-series",
        "--out",
        synth.to_str().unwrap(),
        "--size",
        "192",
        "--forces",
        "1,2,4,8mN",
        "--seed",
        "3",
        "--layout",
        "files",
    ]);
    assert!(o.status.success(), "{}", crate::common::stderr(&o));
    let folder = dir.path().join("decimal");
    std::fs::create_dir(&folder).unwrap();
    // Written out of order on purpose; each file a larger load than the one before.
    for (k, name) in ["load_10mN", "load_1.0mN", "load_1.5mN", "load_1.25mN"]
        .iter()
        .enumerate()
    {
        let source = ["load_04.tif", "load_01.tif", "load_03.tif", "load_02.tif"][k];
        std::fs::copy(synth.join(source), folder.join(format!("{name}.tif"))).unwrap();
    }
    let out = dir.path().join("out");
    let o = crate::common::run_ok(&[
        "analyze",
        folder.to_str().unwrap(),
        "--forces",
        "1,1.25,1.5,10mN",
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("images: 4 in load order by file names in natural order"),
        "{text}"
    );
    let names: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().rev().nth(1))
        .filter(|w| w.starts_with("load_"))
        .collect();
    assert_eq!(
        names,
        [
            "load_1.0mN.tif",
            "load_1.25mN.tif",
            "load_1.5mN.tif",
            "load_10mN.tif"
        ]
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["inputs"]["order"]
        .as_str()
        .unwrap()
        .starts_with("file names in natural order"));
    // The areas grow with the load: no physics warning.
    assert!(!String::from_utf8_lossy(&o.stderr).contains("wrong order"));
}

/// Each of `inputs` analysed (into `tmp/NAME-k`) gives the areas and threshold of the plain
/// file's analysis in `alone`; the output folders, in order.
fn each_reads_as(
    tmp: &Path,
    name: &str,
    inputs: &[PathBuf],
    alone: &Path,
    forces: &str,
) -> Vec<PathBuf> {
    inputs
        .iter()
        .enumerate()
        .map(|(k, input)| {
            let out = tmp.join(format!("{name}-{k}"));
            analyze(input, &out, &["--forces", forces]);
            assert_eq!(areas(&out), areas(alone), "{}", input.display());
            assert_eq!(threshold(&out), threshold(alone));
            out
        })
        .collect()
}

/// The first image of `out`'s areas.csv came from `first`, the fourth from `fourth`.
fn images_come_from(out: &Path, first: &str, fourth: &str) {
    let (header, rows) = crate::common::read_csv(&out.join("areas.csv"));
    let image = header.iter().position(|h| h == "image").unwrap();
    assert!(rows[0][image].contains(first), "{:?}", rows[0]);
    assert!(rows[3][image].contains(fourth), "{:?}", rows[3]);
}

/// `batch ARCHIVE --out OUT --pattern *.ome.tif --forces FORCES` must succeed and say `what`.
fn batch_says(archive: &Path, out: &Path, forces: &str, what: &str) {
    let o = run_ok(&[
        "batch",
        s(archive),
        "--out",
        s(out),
        "--pattern",
        "*.ome.tif",
        "--forces",
        forces,
        "--pixel-size",
        "200nm",
    ]);
    let said = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(said.contains(what), "{what}: {said}");
}

/// The OME-XML of a set of two files, `names[0]` holding time points 0–1 and `names[1]` time
/// points 2–3 (OME-TIFF specification, multi-file datasets: every file carries the same XML).
fn set_xml(names: [&str; 2]) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06" UUID="urn:uuid:00000000-0000-0000-0000-00000000000a"><Image ID="Image:0"><Pixels ID="Pixels:0" DimensionOrder="XYCZT" Type="uint16" SizeX="{W}" SizeY="{W}" SizeC="1" SizeZ="1" SizeT="4" PhysicalSizeX="0.2" PhysicalSizeXUnit="um" PhysicalSizeY="0.2" PhysicalSizeYUnit="um"><Channel ID="Channel:0:0" SamplesPerPixel="1"/><TiffData FirstT="0" IFD="0" PlaneCount="2"><UUID FileName="{}">urn:uuid:00000000-0000-0000-0000-00000000000a</UUID></TiffData><TiffData FirstT="2" IFD="0" PlaneCount="2"><UUID FileName="{}">urn:uuid:00000000-0000-0000-0000-00000000000b</UUID></TiffData></Pixels></Image></OME>"#,
        names[0], names[1]
    )
}

#[test]
fn a_multi_file_ome_set_is_read_whole_from_any_of_its_files() {
    let tmp = tempfile::tempdir().unwrap();
    let radii = [4.0, 7.0, 10.0, 13.0];
    let planes: Vec<Vec<u16>> = radii.iter().map(|&r| disk(r, 2000, 0)).collect();
    let set = tmp.path().join("set");
    std::fs::create_dir(&set).unwrap();
    let names = ["load_0.ome.tif", "load_1.ome.tif"];
    let xml = set_xml(names);
    write_tiff(&set.join(names[0]), &planes[..2], &xml);
    write_tiff(&set.join(names[1]), &planes[2..], &xml);
    let plain = tmp.path().join("plain.tif");
    write_tiff(&plain, &planes, "plain pages");
    let forces = "4,10,20,40mN";
    let alone = tmp.path().join("alone");
    analyze(&plain, &alone, &["--forces", forces]);

    // Either file gives the four time points; the folder of both gives them once.
    let inputs = [set.join(names[0]), set.join(names[1]), set.clone()];
    let outs = each_reads_as(tmp.path(), "set", &inputs, &alone, forces);
    // The images read from the other file say so.
    images_come_from(&outs[0], names[0], names[1]);

    // A set whose first file only points to the master's XML (BinaryOnly), in a folder where
    // it sorts first: read once (the pointer followed to the master's XML).
    let pointer = tmp.path().join("pointer");
    std::fs::create_dir(&pointer).unwrap();
    let (a, b) = ("a.ome.tif", "b.ome.tif");
    write_tiff(
        &pointer.join(a),
        &planes[..2],
        &format!(
            r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06" UUID="urn:uuid:00000000-0000-0000-0000-00000000000a"><BinaryOnly MetadataFile="{b}" UUID="urn:uuid:00000000-0000-0000-0000-00000000000b"/></OME>"#
        ),
    );
    write_tiff(&pointer.join(b), &planes[2..], &set_xml([a, b]));
    let out = tmp.path().join("pointer-out");
    analyze(&pointer, &out, &["--forces", forces]);
    assert_eq!(areas(&out), areas(&alone));

    // A file of the set without the other: one line naming the missing file.
    let lone = tmp.path().join("lone");
    std::fs::create_dir(&lone).unwrap();
    std::fs::copy(set.join(names[0]), lone.join(names[0])).unwrap();
    let e = refused(&["analyze", s(&lone.join(names[0])), "--forces", forces]);
    assert!(e.contains(names[1]) && e.contains("not in"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    // A set that names a file outside its folder is refused.
    let escape = tmp.path().join("escape");
    std::fs::create_dir(&escape).unwrap();
    write_tiff(
        &escape.join("a.ome.tif"),
        &planes[..2],
        &set_xml(["a.ome.tif", "../plain.tif"]),
    );
    let e = refused(&["analyze", s(&escape.join("a.ome.tif")), "--forces", forces]);
    assert!(e.contains("leaves the file's folder"), "{e}");
    // A file of the set whose pages are another size.
    let odd = tmp.path().join("odd");
    std::fs::create_dir(&odd).unwrap();
    write_tiff(&odd.join(names[0]), &planes[..2], &xml);
    {
        let file = std::fs::File::create(odd.join(names[1])).unwrap();
        let mut enc = TiffEncoder::new(file).unwrap();
        for _ in 0..2 {
            enc.write_image::<colortype::Gray16>(8, 8, &[300u16; 64])
                .unwrap();
        }
    }
    let e = refused(&["analyze", s(&odd.join(names[0])), "--forces", forces]);
    assert!(e.contains(names[1]) && e.contains("8×8"), "{e}");

    // A batch whose pattern takes both files: one series, four images, and a change to the
    // second file alone makes it stale.
    let archive = tmp.path().join("archive");
    std::fs::create_dir(&archive).unwrap();
    for n in names {
        std::fs::copy(set.join(n), archive.join(n)).unwrap();
    }
    let out = tmp.path().join("batch");
    let batch = |what: &str| batch_says(&archive, &out, forces, what);
    batch("1 series: 1 ok");
    let (_, rows) = crate::common::read_csv(&out.join("images.csv"));
    assert_eq!(rows.len(), 4);
    batch("0 analysed, 1 reused");
    write_tiff(&archive.join(names[1]), &planes[..2], &xml);
    batch("1 analysed, 0 reused");
    // The pointer first: one series too.
    std::fs::remove_dir_all(&out).unwrap();
    for n in names {
        std::fs::remove_file(archive.join(n)).unwrap();
    }
    for n in [a, b] {
        std::fs::copy(pointer.join(n), archive.join(n)).unwrap();
    }
    batch("1 series: 1 ok");
}

/// A `BinaryOnly` OME-XML: the file's metadata are kept in `metadata_file`.
fn binary_only(metadata_file: &str, uuid: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06" UUID="urn:uuid:00000000-0000-0000-0000-0000000000f0"><BinaryOnly MetadataFile="{metadata_file}" UUID="{uuid}"/></OME>"#
    )
}

#[test]
fn an_ome_set_with_a_companion_file_is_read_from_any_of_its_files_and_from_the_companion() {
    let tmp = tempfile::tempdir().unwrap();
    let radii = [4.0, 7.0, 10.0, 13.0];
    let planes: Vec<Vec<u16>> = radii.iter().map(|&r| disk(r, 2000, 0)).collect();
    let plain = tmp.path().join("plain.tif");
    write_tiff(&plain, &planes, "plain pages");
    let forces = "4,10,20,40mN";
    let alone = tmp.path().join("alone");
    analyze(&plain, &alone, &["--forces", forces]);

    // The set: two TIFFs whose XML points to `set.companion.ome`, which holds the set's XML
    // (as Bio-Formats writes a companion file: the OME document, its UUID, TiffData per file).
    let set = tmp.path().join("set");
    std::fs::create_dir(&set).unwrap();
    let names = ["load_0.ome.tif", "load_1.ome.tif"];
    let companion = set.join("set.companion.ome");
    std::fs::write(&companion, set_xml(names)).unwrap();
    let uuid = "urn:uuid:00000000-0000-0000-0000-00000000000a";
    write_tiff(
        &set.join(names[0]),
        &planes[..2],
        &binary_only("set.companion.ome", uuid),
    );
    write_tiff(
        &set.join(names[1]),
        &planes[2..],
        &binary_only("set.companion.ome", uuid),
    );
    let inputs = [
        set.join(names[0]),
        set.join(names[1]),
        set.clone(),
        companion.clone(),
    ];
    let outs = each_reads_as(tmp.path(), "set", &inputs, &alone, forces);
    // Through the companion the images name the TIFFs they came from.
    images_come_from(&outs[3], names[0], names[1]);
    // `info` says where the axes came from.
    let o = run_ok(&["info", s(&set.join(names[1]))]);
    let said = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(said.contains("set.companion.ome"), "{said}");
    assert!(said.contains("T 4"), "{said}");
    let o = run_ok(&["info", s(&set.join(names[1])), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let file = json["metadata_file"].as_str().unwrap_or_default();
    assert!(file.ends_with("set.companion.ome"), "{json}");

    // The companion missing, or another set's: each file is read alone, in file order, and
    // says why (not the four time points of a set it cannot see).
    let lone = tmp.path().join("lone");
    std::fs::create_dir(&lone).unwrap();
    std::fs::copy(set.join(names[0]), lone.join(names[0])).unwrap();
    let o = run_ok(&["info", s(&lone.join(names[0]))]);
    let said = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(
        said.contains("only points to") && said.contains("not there"),
        "{said}"
    );
    assert!(said.contains("T 2"), "{said}");
    std::fs::write(
        lone.join("set.companion.ome"),
        set_xml(names).replace(uuid, "urn:uuid:00000000-0000-0000-0000-0000000000ee"),
    )
    .unwrap();
    let o = run_ok(&["info", s(&lone.join(names[0]))]);
    let said = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(said.contains("0000000000ee"), "{said}");
    // A companion whose TIFFs are not beside it: one line naming the file.
    let e = refused(&[
        "analyze",
        s(&lone.join("set.companion.ome")),
        "--forces",
        forces,
    ]);
    assert!(e.contains("0000000000ee") || e.contains(names[1]), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    std::fs::remove_file(lone.join(names[0])).unwrap();
    let e = refused(&[
        "analyze",
        s(&lone.join("set.companion.ome")),
        "--forces",
        forces,
    ]);
    assert!(e.contains(names[0]) && e.contains("not beside"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");

    // A batch over the set's folder: one series of four images; a changed companion (the
    // axes come from it) makes the series stale.
    let out = tmp.path().join("batch");
    let batch = |what: &str| batch_says(&set, &out, forces, what);
    batch("1 series: 1 ok");
    let (_, rows) = crate::common::read_csv(&out.join("images.csv"));
    assert_eq!(rows.len(), 4);
    batch("0 analysed, 1 reused");
    let mut xml = set_xml(names);
    xml = xml.replace("SizeT=\"4\"", "SizeT=\"4\" Name=\"edited\"");
    std::fs::write(&companion, xml).unwrap();
    batch("1 analysed, 0 reused");
}

/// OME-XML of `images` images as tifffile writes one series after another in one file: each
/// `(name, size_t, pixel size µm)`, its planes on the pages after the images before it.
fn images_xml(images: &[(&str, usize, f64)]) -> String {
    let mut ifd = 0;
    let body: String = images
        .iter()
        .enumerate()
        .map(|(k, (name, t, um))| {
            let block = format!(
                r#"<Image ID="Image:{k}" Name="{name}"><Pixels ID="Pixels:{k}" DimensionOrder="XYCZT" Type="uint16" SizeX="{W}" SizeY="{W}" SizeC="1" SizeZ="1" SizeT="{t}" PhysicalSizeX="{um}" PhysicalSizeY="{um}"><Channel ID="Channel:{k}:0" SamplesPerPixel="1"/><TiffData IFD="{ifd}" PlaneCount="{t}"/></Pixels></Image>"#
            );
            ifd += t;
            block
        })
        .collect();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06" Creator="tifffile.py 2026.3.3">{body}</OME>"#
    )
}

#[test]
fn each_image_of_a_multi_image_ome_tiff_is_a_series() {
    let tmp = tempfile::tempdir().unwrap();
    let forces = "4,10,20,40mN";
    // Two stage positions of four time points each; the second at 0.1 µm pixels.
    let first: Vec<Vec<u16>> = [4.0, 7.0, 10.0, 13.0]
        .iter()
        .map(|&r| disk(r, 2000, 0))
        .collect();
    let second: Vec<Vec<u16>> = [5.0, 9.0, 12.0, 16.0]
        .iter()
        .map(|&r| disk(r, 1500, 50))
        .collect();
    let ome = tmp.path().join("positions.ome.tif");
    let pages: Vec<Vec<u16>> = first.iter().chain(&second).cloned().collect();
    write_tiff(
        &ome,
        &pages,
        &images_xml(&[("left", 4, 0.2), ("right", 4, 0.1)]),
    );
    let plain = tmp.path().join("right.tif");
    write_tiff(&plain, &second, "plain pages");

    let info = run_ok(&["info", s(&ome), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(info["series"].as_array().map(Vec::len), Some(2), "{info}");
    assert_eq!(info["series"][1]["name"], "right");
    assert_eq!(info["series"][1]["pixel_size_um"]["x"], 0.1);
    let text = String::from_utf8_lossy(&run_ok(&["info", s(&ome)]).stdout).to_string();
    assert!(text.contains("series 1 'right'"), "{text}");

    // Not pooled into one series of eight pages: a refusal naming both images.
    let e = refused(&["analyze", s(&ome), "--forces", forces]);
    assert!(e.contains("2 series") && e.contains("'right'"), "{e}");
    // The second image alone: its planes and its own pixel size.
    let (chosen, alone) = (tmp.path().join("chosen"), tmp.path().join("alone"));
    let args = ["--series", "1", "--forces", forces];
    run_ok(&[&["analyze", s(&ome), "--out", s(&chosen)][..], &args].concat());
    run_ok(&[
        "analyze",
        s(&plain),
        "--pixel-size",
        "100nm",
        "--out",
        s(&alone),
        "--forces",
        forces,
    ]);
    assert_eq!(threshold(&chosen), threshold(&alone));
    assert_eq!(areas(&chosen), areas(&alone));
    let (header, rows) = crate::common::read_csv(&chosen.join("areas.csv"));
    let um2 = crate::common::column(&header, &rows, "area_um2");
    for (a, px) in um2.iter().zip(areas(&alone)) {
        assert!(
            (a - px * 0.01).abs() < 1e-9,
            "{a} µm² for {px} px of 0.1 µm"
        );
    }

    // One plane per image, the images the loads: read in image order...
    let one_each = tmp.path().join("one_each.ome.tif");
    let each: Vec<(&str, usize, f64)> = ["a", "b", "c", "d"].map(|n| (n, 1, 0.2)).to_vec();
    write_tiff(&one_each, &first, &images_xml(&each));
    let plain = tmp.path().join("first.tif");
    write_tiff(&plain, &first, "plain pages");
    let (loads, alone) = (tmp.path().join("loads"), tmp.path().join("first"));
    analyze(
        &one_each,
        &loads,
        &["--load-axis", "series", "--forces", forces],
    );
    analyze(&plain, &alone, &["--forces", forces]);
    assert_eq!(areas(&loads), areas(&alone));
    // ... and refused when the images differ in pixel size.
    let mixed = tmp.path().join("mixed.ome.tif");
    let sizes = [("a", 1, 0.2), ("b", 1, 0.2), ("c", 1, 0.1), ("d", 1, 0.2)];
    write_tiff(&mixed, &first, &images_xml(&sizes));
    let e = refused(&[
        "analyze",
        s(&mixed),
        "--load-axis",
        "series",
        "--forces",
        forces,
    ]);
    assert!(e.contains("image 2") && e.contains("0.1000"), "{e}");
}

#[test]
fn a_file_of_a_set_with_planes_of_another_size_is_refused_by_every_reader() {
    use tiff::encoder::{colortype, TiffEncoder};
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = ("a.ome.tif", "b.ome.tif");
    let xml = set_xml([a, b]);
    write_tiff(
        &tmp.path().join(a),
        &[disk(4.0, 2000, 0), disk(7.0, 2000, 0)],
        &xml,
    );
    // The second file's pages are 40² where the set says 48².
    let mut enc = TiffEncoder::new(std::fs::File::create(tmp.path().join(b)).unwrap()).unwrap();
    for k in 0..2 {
        let mut image = enc.new_image::<colortype::Gray16>(40, 40).unwrap();
        if k == 0 {
            image
                .encoder()
                .write_tag(Tag::ImageDescription, xml.as_str())
                .unwrap();
        }
        image.write_data(&vec![300u16; 40 * 40]).unwrap();
    }
    let (file, out) = (tmp.path().join(a), tmp.path().join("out"));
    // The analysis, the plane reader of `threshold`, and `info --stats` (every plane decoded).
    for args in [
        vec![
            "analyze",
            s(&file),
            "--forces",
            "4,10,20,40mN",
            "--out",
            s(&out),
        ],
        vec!["threshold", s(&file)],
        vec!["info", s(&file), "--stats"],
    ] {
        let e = refused(&args);
        assert!(e.contains(b) && e.contains("40×40"), "{args:?}: {e}");
        assert_eq!(e.trim().lines().count(), 1, "{e}");
    }
}

#[test]
fn an_image_kept_in_a_file_whose_first_page_is_another_image_s_reads() {
    use tiff::encoder::{colortype, TiffEncoder};
    let tmp = tempfile::tempdir().unwrap();
    // Image 0 (48²) in a.ome.tif; images 1 (48²) and 2 (40²) on pages 0 and 1 of b.ome.tif.
    let image = |k: usize, size: usize, file: &str, ifd: usize| {
        format!(
            r#"<Image ID="Image:{k}" Name="p{k}"><Pixels ID="Pixels:{k}" DimensionOrder="XYCZT" Type="uint16" SizeX="{size}" SizeY="{size}" SizeC="1" SizeZ="1" SizeT="1"><Channel ID="Channel:{k}:0" SamplesPerPixel="1"/><TiffData IFD="{ifd}" PlaneCount="1"><UUID FileName="{file}">urn:uuid:00000000-0000-0000-0000-00000000000{k}</UUID></TiffData></Pixels></Image>"#
        )
    };
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06">{}{}{}</OME>"#,
        image(0, W, "a.ome.tif", 0),
        image(1, W, "b.ome.tif", 0),
        image(2, 40, "b.ome.tif", 1)
    );
    write_tiff(&tmp.path().join("a.ome.tif"), &[disk(4.0, 2000, 0)], &xml);
    let small: Vec<u16> = (0..40 * 40)
        .map(|i| if i % 40 < 20 { 300 } else { 2300 })
        .collect();
    let mut enc =
        TiffEncoder::new(std::fs::File::create(tmp.path().join("b.ome.tif")).unwrap()).unwrap();
    let mut first = enc
        .new_image::<colortype::Gray16>(W as u32, W as u32)
        .unwrap();
    first
        .encoder()
        .write_tag(Tag::ImageDescription, xml.as_str())
        .unwrap();
    first.write_data(&disk(7.0, 2000, 0)).unwrap();
    enc.new_image::<colortype::Gray16>(40, 40)
        .unwrap()
        .write_data(&small)
        .unwrap();
    // Image 2 read through a.ome.tif: b.ome.tif's first page (image 1's, 48²) does not make
    // its 40² plane another size than the series.
    let a = tmp.path().join("a.ome.tif");
    for args in [
        vec!["threshold", s(&a), "--series", "2"],
        vec!["info", s(&a), "--series", "2", "--stats"],
    ] {
        let o = run_ok(&args);
        let said = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(
            said.contains("1600") || said.contains("2300"),
            "{args:?}: {said}"
        );
    }
}
