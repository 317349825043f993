//! Small files written here (no shared data needed) for what the real samples do not show: CZI
//! mosaic tiles placed at their stage offsets (overlaps drawn in increasing M), scenes as
//! series, and the checks on a directory that promises more than the file holds.

use contactscope::io::microscopy::{MicroscopyFile, PlaneIndex};

/// A 32-byte segment header.
fn segment(id: &str, used: usize) -> Vec<u8> {
    let mut v = id.as_bytes().to_vec();
    v.resize(16, 0);
    v.extend((used as i64).to_le_bytes());
    v.extend((used as i64).to_le_bytes());
    v
}

/// One subblock: scene, channel, mosaic index, x, y, 16-bit samples (w × h).
struct Tile {
    s: i32,
    c: i32,
    m: i32,
    x: i32,
    y: i32,
    w: i32,
    h: i32,
    values: Vec<u16>,
}

fn entry(t: &Tile, position: usize) -> Vec<u8> {
    let mut e = b"DV".to_vec();
    e.extend(1i32.to_le_bytes()); // Gray16
    e.extend((position as i64).to_le_bytes());
    e.extend(0i32.to_le_bytes()); // file part
    e.extend(0i32.to_le_bytes()); // uncompressed
    e.push(0); // pyramid type
    e.extend([0u8; 5]);
    let dims = [
        ("X", t.x, t.w),
        ("Y", t.y, t.h),
        ("C", t.c, 1),
        ("S", t.s, 1),
        ("M", t.m, 1),
    ];
    e.extend((dims.len() as i32).to_le_bytes());
    for (name, start, size) in dims {
        let mut n = name.as_bytes().to_vec();
        n.resize(4, 0);
        e.extend(n);
        e.extend(start.to_le_bytes());
        e.extend(size.to_le_bytes());
        e.extend(0f32.to_le_bytes());
        e.extend(size.to_le_bytes()); // stored = logical: layer 0
    }
    e
}

/// A CZI file of the given tiles (no metadata segment).
fn czi(tiles: &[Tile]) -> Vec<u8> {
    let mut file = segment("ZISRAWFILE", 512);
    file.resize(32 + 512, 0);
    let mut entries = Vec::new();
    for t in tiles {
        let position = file.len();
        let e = entry(t, position);
        let data: Vec<u8> = t.values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut block = Vec::new();
        block.extend(0i32.to_le_bytes());
        block.extend(0i32.to_le_bytes());
        block.extend((data.len() as i64).to_le_bytes());
        block.extend(&e);
        block.resize(256, 0);
        block.extend(&data);
        file.extend(segment("ZISRAWSUBBLOCK", block.len()));
        file.extend(block);
        entries.push(e);
    }
    let dir_pos = file.len();
    let mut dir = (entries.len() as i32).to_le_bytes().to_vec();
    dir.resize(128, 0);
    for e in &entries {
        dir.extend(e);
    }
    file.extend(segment("ZISRAWDIRECTORY", dir.len()));
    file.extend(dir);
    file[32..36].copy_from_slice(&1i32.to_le_bytes());
    file[32 + 52..32 + 60].copy_from_slice(&(dir_pos as i64).to_le_bytes());
    file
}

fn tile(s: i32, c: i32, m: i32, (x, y): (i32, i32), value: u16) -> Tile {
    Tile {
        s,
        c,
        m,
        x,
        y,
        w: 3,
        h: 2,
        values: (0..6).map(|i| value + i).collect(),
    }
}

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
