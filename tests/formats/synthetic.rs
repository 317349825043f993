//! Small files written here (no shared data needed) for what the real samples do not show: CZI
//! mosaic tiles placed at their stage offsets (overlaps drawn in increasing M), scenes as
//! series, and the checks on a directory that promises more than the file holds.

use crate::common::czi::{czi, tile};
use contactscope_formats::microscopy::{MicroscopyFile, PlaneIndex};

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
