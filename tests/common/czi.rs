//! A small CZI writer for tests (documented in `docs/formats.md`): uncompressed Gray16
//! subblocks with X, Y, C, S (scene), M (mosaic), T and Z coordinates, a
//! subblock directory and no metadata segment (so no pixel size). Written from the ZISRAW
//! layout our reader (`crates/formats/src/microscopy/czi.rs`) implements; used by `formats/synthetic.rs`
//! and `series/vendor.rs`. Never a copy of a real sample (the real CZI samples are GPL-3.0).

/// A 32-byte segment header.
pub fn segment(id: &str, used: usize) -> Vec<u8> {
    let mut v = id.as_bytes().to_vec();
    v.resize(16, 0);
    v.extend((used as i64).to_le_bytes());
    v.extend((used as i64).to_le_bytes());
    v
}

/// One subblock: scene, channel, time point, focal plane, mosaic index, x, y, 16-bit samples (w × h).
pub struct Tile {
    pub s: i32,
    pub t: i32,
    pub z: i32,
    pub c: i32,
    pub m: i32,
    pub x: i32,
    pub y: i32,
    pub w: i32,
    pub h: i32,
    pub values: Vec<u16>,
}

pub fn entry(t: &Tile, position: usize) -> Vec<u8> {
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
        ("T", t.t, 1),
        ("Z", t.z, 1),
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
pub fn czi(tiles: &[Tile]) -> Vec<u8> {
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

pub fn tile(s: i32, c: i32, m: i32, (x, y): (i32, i32), value: u16) -> Tile {
    Tile {
        s,
        t: 0,
        z: 0,
        c,
        m,
        x,
        y,
        w: 3,
        h: 2,
        values: (0..6).map(|i| value + i).collect(),
    }
}
