//! Digital Surf `.sur` (MountainsMap; written by many profilometers): a packed 512-byte
//! little-endian header (`DIGITAL SURF` magic, …, special-points flag at 86, bits per point at
//! 98, z min at 100, x and y sizes at 108 and 112, grid spacings (f32) at 120 and 124, the
//! height scale (f32) at 128, units (16 bytes each) of the x/y/z steps at 180, 196, 212,
//! inversion at 290, comment and private sizes at 334 and 336), the comment and private zones,
//! then int16 or int32 points row by row. Height = raw · scale in the z step unit, negated when
//! the inversion code is 1, 2 or 3; with the special-points flag set, `zmin − 2` marks a
//! non-measured point. Grid spacing is in the x/y step units. (As SurfaceTopography, the
//! header's data offset is not added.)

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, length_factor, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

/// Read a Digital Surf SUR file (first object).
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let h = slice(path, data, 0, 512, "the SUR header")?;
    let at = |o: usize| Reader::new(path, h, o);
    let text = |o: usize, n: usize| -> String {
        h[o..o + n]
            .iter()
            .map(|&b| char::from(b))
            .collect::<String>()
            .trim_end_matches('\0')
            .trim()
            .to_string()
    };
    let special = at(86).u16()? == 1;
    let bits = at(98).u16()?;
    let width = match bits {
        16 => 2,
        32 => 4,
        b => return Err(unsupported(path, format!("SUR points of {b} bits"))),
    };
    let zmin = f64::from(at(100).i32()?);
    let nx = count(path, "x size", f64::from(at(108).i32()?))?;
    let ny = count(path, "y size", f64::from(at(112).i32()?))?;
    let (sx, sy, scale) = (
        f64::from(at(120).f32()?),
        f64::from(at(124).f32()?),
        f64::from(at(128).f32()?),
    );
    let unit = |o: usize| {
        let u = text(o, 16);
        length_factor(&u).ok_or_else(|| bad(path, format!("SUR unit '{u}' is not a length")))
    };
    let (ux, uy, uz) = (unit(180)?, unit(196)?, unit(212)?);
    let sign = if (1..=3).contains(&at(290).u16()?) {
        -1.0
    } else {
        1.0
    };
    let skip = usize::from(at(334).u16()?) + usize::from(at(336).u16()?);
    let name = text(164, 16);
    let channels = [ChannelEntry {
        name: if name.is_empty() {
            "Default".into()
        } else {
            name
        },
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let bytes = grid_bytes(path, nx, ny, width)?;
    let raw = decode_values(
        slice(path, data, 512 + skip, bytes, "the SUR points")?,
        width,
        false,
        true,
        false,
    );
    let heights = raw
        .into_iter()
        .map(|v| {
            if special && v == zmin - 2.0 {
                f64::NAN
            } else {
                sign * v * scale * uz
            }
        })
        .collect();
    height_map(
        path,
        TopographyFormat::Sur,
        (&channels, index),
        (ny, nx),
        heights,
        (sx * ux, sy * uy),
    )
}
