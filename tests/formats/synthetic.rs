//! Small files written here (no shared data needed) for what the real samples do not show: CZI
//! mosaic tiles placed at their stage offsets (overlaps drawn in increasing M), scenes as
//! series, the checks on a directory that promises more than the file holds, and scans without a
//! y axis (LIF and CZI X–Z sections, LIF X–T line scans) read as one image per channel and t.

use crate::common::czi::{czi, tile, Tile};
use crate::common::lif::lif;
use crate::common::{run_ok, stdout};
use contactscope_formats::microscopy::{MicroscopyFile, PlaneIndex, Rows};

#[test]
fn czi_tiles_are_placed_at_their_offsets_and_scenes_are_series() {
    let tiles = [
        // Scene 0, channel 0: two overlapping tiles, M = 1 drawn over M = 0.
        tile(0, 0, 1, (12, 6), 100),
        tile(0, 0, 0, (10, 5), 10),
        tile(0, 1, 0, (10, 5), 50),
        tile(0, 1, 1, (12, 6), 200),
        // Scene 1: one tile far away.
        tile(1, 0, 0, (1000, 2000), 7),
        tile(1, 1, 0, (1000, 2000), 8),
    ];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mosaic.czi");
    std::fs::write(&path, czi(&tiles)).unwrap();
    let mut f = MicroscopyFile::open(&path).unwrap();
    assert_eq!(f.series.len(), 2);
    let a = &f.series[0].axes;
    assert_eq!((a.c, a.y, a.x), (2, 3, 5));
    assert!(f.series[0].pixel_size.x_m.is_none());
    let p = f.read_plane(0, &PlaneIndex::tzc(0, 0, 0)).unwrap();
    #[rustfmt::skip]
    let expected = [
        10.0, 11.0, 12.0, 0.0, 0.0,
        13.0, 14.0, 100.0, 101.0, 102.0,
        0.0, 0.0, 103.0, 104.0, 105.0,
    ];
    assert_eq!(p.to_f64(), expected);
    let c1 = f.read_plane(0, &PlaneIndex::tzc(0, 0, 1)).unwrap();
    assert_eq!(c1.value(7), 200.0);
    let far = f.read_plane(1, &PlaneIndex::tzc(0, 0, 1)).unwrap();
    assert_eq!((far.width, far.height, far.value(0)), (3, 2, 8.0));
    assert!(f.read_plane(0, &PlaneIndex::tzc(0, 0, 2)).is_err());
    assert!(f.read_plane(2, &PlaneIndex::tzc(0, 0, 0)).is_err());
}

#[test]
fn a_directory_promising_more_than_the_file_holds_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("liar.czi");
    let mut bytes = czi(&[tile(0, 0, 0, (0, 0), 1)]);
    let dir_pos = i64::from_le_bytes(bytes[84..92].try_into().unwrap()) as usize;
    // 2^31 − 1 entries of at least 32 bytes.
    bytes[dir_pos + 32..dir_pos + 36].copy_from_slice(&i32::MAX.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let err = MicroscopyFile::open(&path).unwrap_err().to_string();
    assert!(
        err.contains("liar.czi") && err.contains("more than the file can hold"),
        "{err}"
    );
    // A tile whose stored size claims a huge plane: refused by the size limit or the tile check.
    let mut huge = czi(&[tile(0, 0, 0, (0, 0), 1)]);
    let entry_x = dir_pos + 160 + 32;
    huge[entry_x + 8..entry_x + 12].copy_from_slice(&(1i32 << 30).to_le_bytes());
    huge[entry_x + 16..entry_x + 20].copy_from_slice(&(1i32 << 30).to_le_bytes());
    std::fs::write(&path, &huge).unwrap();
    let result = MicroscopyFile::open(&path)
        .and_then(|mut f| f.read_plane(0, &PlaneIndex::tzc(0, 0, 0)).map(|_| ()));
    let err = result.unwrap_err().to_string();
    assert!(err.contains("liar.czi"), "{err}");
}

/// A LIF X–Z–T scan (DimIDs 1, 3, 4; no y): 4 pixels along x (1 µm), 3 focal planes (0.5 µm
/// apart), 2 time points, 2 channels; the value at (c, t, z, x) is 100c + 50t + 10z + x.
fn xzt_lif() -> Vec<u8> {
    let mut data = Vec::new();
    for t in 0..2u8 {
        for c in 0..2u8 {
            for z in 0..3u8 {
                data.extend((0..4u8).map(|x| 100 * c + 50 * t + 10 * z + x));
            }
        }
    }
    let dims = [(1, 4, 3e-6, 1), (3, 3, 1e-6, 4), (4, 2, 1.0, 24)];
    lif("XZ scan", &dims, &[0, 12], &data)
}

#[test]
fn a_lif_xz_scan_is_one_xz_image_per_channel_and_t() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("xz.lif");
    std::fs::write(&path, xzt_lif()).unwrap();
    let mut f = MicroscopyFile::open(&path).unwrap();
    let s = &f.series[0];
    let a = &s.axes;
    // Not 12 planes of 4 × 1 pixels: 4 images (2 t × 2 c) of 4 × 3, rows the focal planes.
    assert_eq!((a.t, a.z, a.c, a.y, a.x), (2, 1, 2, 3, 4));
    assert_eq!((s.rows, a.planes()), (Rows::Z, 4));
    let p = &s.pixel_size;
    assert!((p.x_m.unwrap() - 1e-6).abs() < 1e-15);
    assert!((p.y_m.unwrap() - 0.5e-6).abs() < 1e-15, "{p:?}");
    assert_eq!(p.z_m, None);
    let plane = f.read_plane(0, &PlaneIndex::tzc(1, 0, 1)).unwrap();
    assert_eq!((plane.width, plane.height), (4, 3));
    #[rustfmt::skip]
    let expected = [
        150.0, 151.0, 152.0, 153.0,
        160.0, 161.0, 162.0, 163.0,
        170.0, 171.0, 172.0, 173.0,
    ];
    assert_eq!(plane.to_f64(), expected);
    assert_eq!(
        f.read_plane(0, &PlaneIndex::tzc(0, 0, 0))
            .unwrap()
            .value(11),
        23.0
    );
    // z is no longer an axis of its own.
    let err = f
        .read_plane(0, &PlaneIndex::tzc(0, 1, 0))
        .unwrap_err()
        .to_string();
    assert!(err.contains("Z = 1 requested, the series has 1"), "{err}");

    // `info` says what the image is.
    let text = stdout(&run_ok(&["info", path.to_str().unwrap()]));
    assert!(text.contains("T 2 × Z 1 × C 2 × Y 3 × X 4"), "{text}");
    assert!(text.contains("X–Z section"), "{text}");
    assert!(text.contains("1.00000 µm × 500.0000 nm from LIF"), "{text}");
    assert!(text.contains("y: the z step of the X–Z scan"), "{text}");
    let json = stdout(&run_ok(&["info", path.to_str().unwrap(), "--json"]));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let series = &v["series"][0];
    assert_eq!(series["rows"], "Z");
    assert_eq!(series["axes"]["Y"], 3);
    assert!((series["pixel_size_um"]["y"].as_f64().unwrap() - 0.5).abs() < 1e-9);
}

#[test]
fn a_lif_xt_line_scan_has_time_as_rows_and_no_y_size() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("xt.lif");
    let data: Vec<u8> = (0..15).collect();
    let dims = [(1, 3, 2e-6, 1), (4, 5, 0.01, 3)];
    std::fs::write(&path, lif("XT scan", &dims, &[0], &data)).unwrap();
    let mut f = MicroscopyFile::open(&path).unwrap();
    let s = &f.series[0];
    assert_eq!((s.rows, s.axes.t, s.axes.y, s.axes.x), (Rows::T, 1, 5, 3));
    assert_eq!(s.pixel_size.y_m, None);
    let plane = f.read_plane(0, &PlaneIndex::tzc(0, 0, 0)).unwrap();
    assert_eq!((plane.width, plane.height, plane.value(14)), (3, 5, 14.0));
    let text = stdout(&run_ok(&["info", path.to_str().unwrap()]));
    assert!(text.contains("X–T line scan"), "{text}");
    assert!(text.contains("rows are time points (no length)"), "{text}");
}

#[test]
fn a_czi_of_one_line_per_focal_plane_is_an_xz_image() {
    let tiles: Vec<Tile> = (0..3)
        .map(|z| Tile {
            z,
            h: 1,
            w: 4,
            values: (0..4).map(|x| 10 * z as u16 + x).collect(),
            ..tile(0, 0, 0, (0, 0), 0)
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("xz.czi");
    std::fs::write(&path, czi(&tiles)).unwrap();
    let mut f = MicroscopyFile::open(&path).unwrap();
    let s = &f.series[0];
    assert_eq!((s.rows, s.axes.z, s.axes.y, s.axes.x), (Rows::Z, 1, 3, 4));
    let plane = f.read_plane(0, &PlaneIndex::tzc(0, 0, 0)).unwrap();
    assert_eq!(
        plane.to_f64(),
        [0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0, 20.0, 21.0, 22.0, 23.0]
    );
}
