//! SurfaceTopography's own reader tests, as ours: every two-dimensional map of its
//! `test/file_format_examples` that it reads is read by `topography` with the same grid, pixel
//! size (x and y), valid points and heights (min, max, rms, mean) to 1e-9, and the same channel
//! names, with no option where the file carries the value.
//!
//! Reference: `tests/data/surface_topography_maps.csv`, written by
//! `tests/data/surface_topography_reference.py` with SurfaceTopography 1.27.1 (every channel of
//! every file). Files: the subset committed in `fixtures/surface-topography` (binary ones stored
//! gzip-compressed, decompressed here to their own name; `fixtures/README.md`), and the whole
//! folder when `CONTACTSCOPE_ST_EXAMPLES` names a checkout of it (run by hand: the 67 files of
//! the snapshot used take 51 MB).
//!
//! Where we read a file differently on purpose, the row is listed in [`DIFFERENT`] with the
//! reason and what the file itself states; channel names we give where SurfaceTopography says
//! "Default" are in [`NAMED`].

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use contactscope_jobs::topography::topography_summary;

/// Channel names SurfaceTopography does not take from the file (it says "Default" or numbers
/// the channel): file, its name, ours (from the file).
const NAMED: &[(&str, &str, &str)] = &[
    ("nc-1.nc", "Default", "heights"),
    ("nms-1.nms", "Default", "Confocal Height Image"),
    ("stp-1.stp", "Default", "Topography"),
    ("top-1.top", "Default", "Topography"),
    ("sdf-1.sdf", "Default", "Height"),
    ("sur-2.sur", "Default", "Z"),
    ("sur-3.sur", "Default", "Z"),
    (
        "10x10-one_channel_without_name.ibw",
        "no name (1)",
        "layer 0",
    ),
    ("mi-1.mi", "Topography", "Topography (Trace)"),
];

/// Files read differently from SurfaceTopography on purpose: file and why. Their numbers are
/// checked against what the file states (in [`stated_differently`]).
const DIFFERENT: &[(&str, &str)] = &[(
    "nms-1.nms",
    "the lateral spacings are stored in nm (312.5 nm, a 160 µm field); SurfaceTopography reads \
     mm (0.3125 m pixels); heights span the header's raw range 0…65535 onto its stated \
     2.689…6.007 µm, where SurfaceTopography divides by 65534",
)];

/// Channels SurfaceTopography reads as heights that are not lengths (refused here): file and
/// channel.
const NOT_HEIGHTS: &[(&str, &str)] = &[("mi-1.mi", "Deflection"), ("mi-1.mi", "Friction")];

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// One row of the reference table.
#[derive(Debug, Clone)]
struct Row(HashMap<String, String>);

impl Row {
    fn get(&self, key: &str) -> &str {
        self.0.get(key).map_or("", String::as_str)
    }

    fn number(&self, key: &str) -> f64 {
        self.get(key)
            .parse()
            .unwrap_or_else(|_| panic!("{key} of {:?}", self.0))
    }
}

fn reference() -> Vec<Row> {
    let path = crate::common::root().join("tests/data/surface_topography_maps.csv");
    let mut reader = csv::Reader::from_path(path).unwrap();
    reader
        .deserialize::<HashMap<String, String>>()
        .map(|r| Row(r.unwrap()))
        .collect()
}

/// The file `name` of `dir`, or its `.gz` copy decompressed into `tmp` under its own name.
fn materialise(dir: &Path, name: &str, tmp: &Path) -> Option<PathBuf> {
    let plain = dir.join(name);
    if plain.exists() {
        return Some(plain);
    }
    let zipped = dir.join(format!("{name}.gz"));
    let file = std::fs::File::open(zipped).ok()?;
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(file)
        .read_to_end(&mut bytes)
        .unwrap();
    let out = tmp.join(name);
    std::fs::write(&out, bytes).unwrap();
    Some(out)
}

/// Our channel for SurfaceTopography's channel `index` of a file: its name; the k-th of a name
/// used k times is the k-th of ours that starts with it (we add the line direction).
fn our_channel(row: &Row, ours: &[String]) -> Option<String> {
    let names: Vec<&str> = row.get("channels").split(';').collect();
    let index: usize = row.get("channel_index").parse().unwrap();
    let name = names[index];
    let k = names[..index].iter().filter(|n| **n == name).count();
    ours.iter().filter(|o| o.starts_with(name)).nth(k).cloned()
}

/// Compare every readable 2-D row whose file is in `dir`; returns the rows compared.
fn compare_folder(dir: &Path) -> usize {
    let tmp = tempfile::tempdir().unwrap();
    let mut compared = 0;
    for row in reference() {
        let file = row.get("file").to_string();
        if !row.get("status").starts_with("ok") || row.get("dim") != "2" {
            continue;
        }
        let Some(path) = materialise(dir, &file, tmp.path()) else {
            continue;
        };
        let first = topography_summary(&path, None).unwrap_or_else(|e| panic!("{file}: {e}"));
        let st_name = row.get("channel");
        let index = row.get("channel_index");
        let channel = if index == "0" {
            let renamed = NAMED.iter().find(|(f, _, _)| *f == file);
            let want = renamed.map_or(st_name, |(_, theirs, ours)| {
                assert_eq!(*theirs, st_name, "{file}: NAMED is out of date");
                ours
            });
            // Case aside: SurfaceTopography says "default" for x y z files, "Default" elsewhere.
            assert_eq!(
                first.channel.to_lowercase(),
                want.to_lowercase(),
                "{file}: default channel"
            );
            None
        } else {
            Some(our_channel(&row, &first.channels).unwrap_or_else(|| {
                panic!("{file}: no channel '{st_name}' in {:?}", first.channels)
            }))
        };
        if let Some((_, channel_name)) = NOT_HEIGHTS
            .iter()
            .find(|(f, c)| *f == file && st_name.starts_with(c))
        {
            let err = topography_summary(&path, channel.as_deref()).unwrap_err();
            assert!(
                err.to_string().contains("not a length"),
                "{file} {channel_name}: {err}"
            );
            continue;
        }
        let s = topography_summary(&path, channel.as_deref())
            .unwrap_or_else(|e| panic!("{file} {channel:?}: {e}"));
        compared += 1;
        if DIFFERENT.iter().any(|(f, _)| *f == file) {
            stated_differently(&file, &s);
            continue;
        }
        let what = format!("{file} channel {index} ({st_name})");
        assert_eq!(
            (s.nx, s.ny, s.valid_points),
            (
                row.number("nx") as usize,
                row.number("ny") as usize,
                row.number("valid") as usize
            ),
            "{what}: grid and valid points"
        );
        for (name, got, want) in [
            ("dx", s.pixel_size.x_m, row.number("dx_m")),
            ("dy", s.pixel_size.y_m, row.number("dy_m")),
            ("min", s.height_min_m, row.number("min_m")),
            ("max", s.height_max_m, row.number("max_m")),
            ("rms", s.h_rms_m, row.number("rms_m")),
        ] {
            assert!(rel(got, want) < 1e-9, "{what}: {name} {got:e} vs {want:e}");
        }
        let rms = row.number("rms_m");
        assert!(
            (s.height_mean_m - row.number("mean_m")).abs() <= 1e-9 * rms,
            "{what}: mean {:e} vs {}",
            s.height_mean_m,
            row.get("mean_m")
        );
    }
    compared
}

/// The files of [`DIFFERENT`] against what they state.
fn stated_differently(file: &str, s: &contactscope_jobs::topography::TopographySummary) {
    match file {
        "nms-1.nms" => {
            // Spacing 312.4999911618964 nm (f64 at byte 1376); stated height range 2.689124584…
            // to 6.007402420… µm (f64 at bytes 16 and 24).
            assert!(rel(s.pixel_size.x_m, 312.4999911618964e-9) < 1e-12, "{s:?}");
            assert!(rel(s.height_min_m, 2.689124584197998e-6) < 1e-12, "{s:?}");
            assert!(rel(s.height_max_m, 6.007402420043945e-6) < 1e-12, "{s:?}");
            assert_eq!((s.nx, s.ny, s.valid_points), (512, 512, 262144));
        }
        other => panic!("{other}: no stated values"),
    }
}

#[test]
fn surface_topography_examples_read_the_same() {
    let fixtures = crate::common::root().join("fixtures/surface-topography");
    let compared = compare_folder(&fixtures);
    // Every committed map and channel (al3d, tmd, stp, sur, MetroPro, Nanoscope ×3 channels,
    // nms, NetCDF, Gwyddion ASCII ×2, matrices ×2, x y z ×3, Igor).
    assert_eq!(compared, 19, "rows compared");
}

/// The whole folder, when a checkout of it is named (`CONTACTSCOPE_ST_EXAMPLES`).
#[test]
fn surface_topography_examples_whole_folder() {
    let Ok(dir) = std::env::var("CONTACTSCOPE_ST_EXAMPLES") else {
        eprintln!("SKIPPED: set CONTACTSCOPE_ST_EXAMPLES to SurfaceTopography's test/file_format_examples");
        return;
    };
    let compared = compare_folder(Path::new(&dir));
    eprintln!("compared {compared} channels");
    assert!(compared > 0);
}

/// SurfaceTopography does not read gzip-compressed text; its uncompressed twin is the reference.
#[test]
fn gzip_text_reads_as_its_uncompressed_twin() {
    let path = crate::common::root().join("fixtures/surface-topography/matrix-4.txt.gz");
    let s = topography_summary(&path, None).unwrap();
    let rows = reference();
    let row = rows
        .iter()
        .find(|r| r.get("file") == "matrix-4.txt")
        .unwrap();
    assert_eq!((s.nx, s.ny), (75, 305));
    for (got, want) in [
        (s.pixel_size.x_m, row.number("dx_m")),
        (s.height_min_m, row.number("min_m")),
        (s.height_max_m, row.number("max_m")),
        (s.h_rms_m, row.number("rms_m")),
    ] {
        assert!(rel(got, want) < 1e-9, "{got:e} vs {want:e}");
    }
}

#[test]
fn profiles_and_other_files_are_refused_in_one_line() {
    let fixtures = crate::common::root().join("fixtures/surface-topography");
    for (file, needle) in [
        ("xy-5.txt", "line scan (one profile of 4 points)"),
        ("csv-1.csv", "line scan (one profile of 8 points)"),
        ("single_column.txt", "line scan (one profile of 9 points)"),
        (
            "opdx-3.opdx",
            "line scan (one profile of 3001 points spaced 1.6655562954266104e-8 m)",
        ),
        ("matrix-5.txt", "states no pixel size"),
        ("example-2d.npy", "no pixel size"),
    ] {
        let err = topography_summary(&fixtures.join(file), None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(needle) && err.contains(file) && !err.contains('\n'),
            "{file}: {err}"
        );
    }
}

/// `simulate` runs on the peer's maps with no option beyond the mechanics: the grid and pixel
/// size it records are the file's, and its roughness is `topography`'s (both plane-detrended).
#[test]
fn simulate_reads_the_maps_with_their_own_calibration() {
    use crate::common::run_ok;
    let tmp = tempfile::tempdir().unwrap();
    let fixtures = crate::common::root().join("fixtures/surface-topography");
    for name in ["al3d-1.al3d", "stp-1.stp"] {
        let path = materialise(&fixtures, name, tmp.path()).unwrap();
        let out = tmp.path().join(format!("sim-{name}"));
        let p = |p: &Path| p.to_str().unwrap().to_string();
        let topo = run_ok(&["topography", &p(&path), "--json"]);
        let t: serde_json::Value = serde_json::from_slice(&topo.stdout).unwrap();
        // The map is what is tested: whether the contact stays off the map's border (exit 0)
        // or not (exit 4, results written and marked) does not matter here.
        let o = crate::common::run(&[
            "simulate",
            "-q",
            "--topography",
            &p(&path),
            "--modulus",
            "3GPa",
            "--model",
            "elastic",
            "--radius",
            "290um",
            "--forces",
            "0.001mN,0.002mN",
            "--out",
            &p(&out),
        ]);
        assert!(
            matches!(o.status.code(), Some(0 | 4)),
            "{name}: {}",
            crate::common::stderr(&o)
        );
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let m = &summary["topography"];
        assert_eq!((&m["nx"], &m["ny"]), (&t["nx"], &t["ny"]), "{name}");
        let dx_nm = t["pixel_size_um"]["x"].as_f64().unwrap() * 1e3;
        assert!(
            rel(m["pixel_size_x_nm"].as_f64().unwrap(), dx_nm) < 1e-12,
            "{name}: {m}"
        );
        let h = t["detrended"]["h_rms_nm"].as_f64().unwrap();
        assert!(
            rel(m["h_rms_nm"].as_f64().unwrap(), h) < 1e-9,
            "{name}: {m}"
        );
    }
}

/// `info` on a height map says which command reads it and lists its channels.
#[test]
fn info_on_a_height_map_names_its_channels_and_the_command() {
    let tmp = tempfile::tempdir().unwrap();
    let fixtures = crate::common::root().join("fixtures/surface-topography");
    let path = materialise(&fixtures, "di-2.di", tmp.path()).unwrap();
    let o = crate::common::run(&["info", path.to_str().unwrap()]);
    let err = crate::common::stderr(&o);
    assert!(
        !o.status.success()
            && err.contains("'Height', 'Height (Retrace)', 'Deflection'")
            && err.contains("contactscope topography"),
        "{err}"
    );
}

/// A pixel size given beside one the file states replaces it, and `topography` and `simulate` say
/// so, naming both.
#[test]
fn a_pixel_size_given_beside_the_files_own_is_named() {
    let fixtures = crate::common::root().join("fixtures/surface-topography");
    let path = fixtures.join("matrix-6.txt");
    let o = crate::common::run_ok(&[
        "topography",
        path.to_str().unwrap(),
        "--pixel-size",
        "2um",
        "--json",
    ]);
    let err = crate::common::stderr(&o);
    assert!(
        err.contains("--pixel-size 2.00000 µm × 2.00000 µm replaces the pixel size the file states, 2.50000 µm × 3.33333 µm"),
        "{err}"
    );
    let t: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(t["pixel_size_um"]["x"], 2.0);
    // Without the flag, nothing is said of the pixel size (this toy matrix of heights 1…16 m
    // is named by the physics check instead).
    let o = crate::common::run_ok(&["topography", path.to_str().unwrap(), "--json"]);
    let err = crate::common::stderr(&o);
    assert!(
        !err.contains("pixel size") && err.contains("rms height"),
        "{err}"
    );
}
