//! Which reader a height-map file goes to, decided from its content: magic bytes and headers
//! first ([`super::detect_file`], NumPy, TIFF, Gwyddion Simple Field, gzip), then text; the
//! extension only names what the file was expected to be in an error. A file in a format
//! contactscope knows but does not read (Keyence, old Gwyddion, Createc's older layouts,
//! pictures, …) is refused
//! saying what it is.

use std::io::Read;
use std::path::Path;

use super::{
    bad, detect_file, read, read_gsf, read_npy, read_tiff, text, HeightMap, ReadOptions,
    TopographyFormat, MAX_FILE_BYTES,
};
use crate::binary::unsupported;
use crate::error::Result;

/// Bytes looked at to recognise a file.
const HEAD_BYTES: usize = 4096;

/// Formats recognised by their first bytes that no reader here reads, with what to say.
fn known_unread(head: &[u8]) -> Option<&'static str> {
    let starts = |m: &[u8]| head.starts_with(m);
    Some(if starts(b"GWYO") {
        "an old-format Gwyddion file (GWYO, before Gwyddion 2): open it in Gwyddion and save it \
         again (.gwy) to read it"
    } else if starts(b"VK4_") || starts(b"VK3_") {
        "a Keyence VK3/VK4 file: not read by contactscope (no sample file to test a reader on); \
         export the map as .gsf or a text matrix"
    } else if starts(b"KPK") {
        "a Keyence ZON file of a version contactscope does not read (KPK0 and KPK1 are read); \
         export the map as .gsf or a text matrix"
    } else if starts(b"[Parameter]") || starts(b"[Paramet32]") {
        "a Createc image of the older uncompressed layout ([Parameter], [Paramet32]): not read \
         by contactscope (no sample file to test a reader on; the compressed [Paramco32] layout \
         is read)"
    } else if starts(b"Experiment\t") {
        "a Nanonis spectroscopy or sweep file (a .dat of curves), not a height map; Nanonis \
         images are .sxm files"
    } else if starts(b"MATLAB 5.0 MAT-file") {
        "a MATLAB .mat file: not read by contactscope; save the array with numpy.save (.npy)"
    } else if starts(b"OLYMPUSRAWFORMAT") {
        "an Olympus OIR file: not read by contactscope"
    } else if starts(b"\x89PNG\r\n\x1a\n") || starts(b"\xff\xd8\xff") || starts(b"BM") {
        "a picture (PNG/JPEG/BMP) without heights: export the height map itself"
    } else if starts(b"%PDF") {
        "a PDF document, not a height map"
    } else {
        return None;
    })
}

/// Read a height map of any format (the module docs of [`super`]).
pub fn read_height_map(path: &Path, options: &ReadOptions) -> Result<HeightMap> {
    if detect_file(path)?.is_some() {
        let mut map = read(path, options.channel.as_deref())?;
        // The format read, which may be more specific than the one detected (an HDF5 file that
        // is a TopoStats file or a JPK export states its unit).
        let format = map.format;
        if !format.states_height_unit() {
            let convert = super::to_metres(super::unitless_scale(options.height_unit_m)?);
            map.heights.mapv_inplace(&convert);
        } else if options.height_unit_m.is_some() {
            return Err(bad(
                path,
                format!(
                    "the {} file states its height unit; do not give another one",
                    format.name()
                ),
            ));
        }
        if let Some(pixel) = options.pixel_size_m {
            map.replace_pixel_size(pixel);
        } else if map.dx_m.is_nan() || map.dy_m.is_nan() {
            // NaN: the file states no pixel size.
            return Err(bad(
                path,
                format!(
                    "the {} file states no pixel size; give it with {}",
                    format.name(),
                    crate::param::Param::PixelSize
                ),
            ));
        }
        return Ok(map);
    }
    let head = super::vendor::open_limited(path)?.read_up_to(0, HEAD_BYTES)?;
    let single = |map: Result<HeightMap>| -> Result<HeightMap> {
        let map = map?;
        match &options.channel {
            // Its one channel by name, or as channel 0.
            Some(want)
                if !map.channel.eq_ignore_ascii_case(want)
                    && want.trim().parse::<usize>() != Ok(0) =>
            {
                Err(bad(
                    path,
                    format!(
                        "no channel '{want}': this {} file holds one height map",
                        map.format.name()
                    ),
                ))
            }
            _ => Ok(map),
        }
    };
    if head.starts_with(b"\x93NUMPY") {
        return single(read_npy(path, options.pixel_size_m, options.height_unit_m));
    }
    if let Some(reason) = known_unread(&head) {
        return Err(unsupported(path, reason));
    }
    if crate::microscopy::detect(&head) == Some(crate::microscopy::MicroscopyFormat::Tiff) {
        // A float TIFF reads whatever wrote it; a JPK Instruments TIFF (integer channels with
        // JPK's own scaling tags) that does not is named as such.
        let jpk = head.windows(3).any(|w| w.eq_ignore_ascii_case(b"jpk"));
        return match read_tiff(path, options.pixel_size_m, options.height_unit_m) {
            Err(_) if jpk => Err(unsupported(
                path,
                "a JPK Instruments TIFF without JPK's scan tags (32768, 32834, 32838): not read by \
                 contactscope; export the map as .gsf",
            )),
            read => single(read),
        };
    }
    if head.starts_with(b"Gwyddion Simple Field") {
        return single(read_gsf(path, options.pixel_size_m, options.height_unit_m));
    }
    if let Some(format) = crate::microscopy::detect(&head) {
        // "an ND2", "an OME-ZARR": N is spoken "en"; "a CZI", "a LIF", "a TIFF".
        let name = format.name().to_uppercase();
        let article = if name.starts_with(['N', 'O']) {
            "an"
        } else {
            "a"
        };
        return Err(unsupported(
            path,
            format!(
                "{article} {name} micrograph, not a height map (info, threshold and analyze \
                 read it)"
            ),
        ));
    }
    if head.starts_with(&[0x1f, 0x8b]) {
        let bytes = gunzip(path)?;
        let text = text::decode(&bytes).ok_or_else(|| {
            unsupported(
                path,
                "gzip-compressed binary data: only compressed text is read; decompress the file \
                 first",
            )
        })?;
        return text::read_str(path, &text, options, TopographyFormat::Text);
    }
    if text::looks_like_text(&head) {
        let bytes = super::read_bytes(path)?;
        if let Some(text) = text::decode(&bytes) {
            return text::read_str(path, &text, options, TopographyFormat::Text);
        }
    }
    let ext = path
        .extension()
        .map(|e| format!(" (named .{})", e.to_string_lossy()))
        .unwrap_or_default();
    Err(unsupported(
        path,
        format!(
            "not a height-map format contactscope recognises from its content{ext}; read: {}",
            READ_FORMATS
        ),
    ))
}

/// The formats read, for messages.
pub const READ_FORMATS: &str = "Igor .ibw, Nanosurf .nid, Agilent .mi, Park TIFF, Gwyddion .gwy \
     and .gsf, ISO 25178 .x3p and .sdf, Wyko .opd, Sensofar .plu, Digital Surf .sur, FRT .frt, \
     Nanoscope .di/.spm, WSxM .top/.stp, Nanonis .sxm, TopoStats .topostats, JPK .jpk and .h5-jpk, Alicona .al3d, TrueMap .tmd, NanoFocus .nms, surfalize .sflz, Createc .dat, Image \
     Metrology .bcr/.bcrf, Zygo MetroPro .dat, NetCDF .nc, HDF5 .h5, NumPy .npy, float TIFF, text matrices and x y z grids \
     (also gzip-compressed)";

/// The decompressed content of a gzip file, refused beyond [`MAX_FILE_BYTES`].
fn gunzip(path: &Path) -> Result<Vec<u8>> {
    crate::inputs::note_input(path);
    let file = std::fs::File::open(path).map_err(|e| crate::Error::io(path, e))?;
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(file)
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| bad(path, format!("gzip data do not decompress: {e}")))?;
    if out.len() as u64 > MAX_FILE_BYTES {
        return Err(unsupported(
            path,
            format!(
                "decompresses to more than the {} GiB limit",
                MAX_FILE_BYTES >> 30
            ),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn write(name: &str, bytes: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        (dir, path)
    }

    #[test]
    fn gzip_text_reads_as_the_text() {
        let text = "# Channel: Main\n# Width: 4 µm\n# Height: 3 µm\n# Value units: nm\n\
                    1 2 3 4\n5 6 7 8\n9 10 11 12\n";
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(text.as_bytes()).unwrap();
        let (_d, zipped) = write("m.txt.gz", &gz.finish().unwrap());
        let (_e, plain) = write("m.txt", text.as_bytes());
        let a = read_height_map(&zipped, &ReadOptions::default()).unwrap();
        let b = read_height_map(&plain, &ReadOptions::default()).unwrap();
        assert_eq!(a, b);
        assert_eq!((a.nx(), a.ny(), a.dx_m), (4, 3, 1e-6));
        let (_f, broken) = write("m.gz", &[0x1f, 0x8b, 8, 0, 1, 2, 3]);
        let err = read_height_map(&broken, &ReadOptions::default()).unwrap_err();
        assert!(err.to_string().contains("m.gz"), "{err}");
    }

    #[test]
    fn known_formats_that_are_not_read_say_what_they_are() {
        for (head, needle) in [
            (&b"GWYOxxxx"[..], "old-format Gwyddion"),
            (
                b"\\*Force file list\r\n\\*Ciao force image list\r\n\\@4:Image Data: S \
                  [DeflectionError] \"Deflection Error\"\r\n\\*File list end\r\n",
                "force-curve file without an image",
            ),
            (b"VK4_\0\0\0\0", "Keyence"),
            (b"KPK\0\0\0\0\0BM", "Keyence ZON file of a version"),
            (b"[Paramet32]\r\nNum.X=4\r\n", "Createc image of the older"),
            (
                b"Experiment\tbias spectroscopy\t\r\n",
                "Nanonis spectroscopy",
            ),
            (b"\x89PNG\r\n\x1a\n", "picture"),
        ] {
            let (_d, path) = write("a.dat", head);
            let err = read_height_map(&path, &ReadOptions::default())
                .unwrap_err()
                .to_string();
            assert!(err.contains(needle) && err.contains("a.dat"), "{err}");
        }
        // A TIFF that does not read as heights and says JPK is named as JPK's.
        let (_j, path) = write("m.jpk", b"II*\0\x08\0\0\0JPKInstruments");
        let err = read_height_map(&path, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("JPK Instruments TIFF") && err.contains("m.jpk"),
            "{err}"
        );
        let (_d, path) = write("a.npy", b"\x01\x02\x03\x00\x05binary");
        let err = read_height_map(&path, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("named .npy") && err.contains("recognises"),
            "{err}"
        );
    }

    #[test]
    fn a_file_is_read_as_what_it_holds_whatever_its_name() {
        let (_d, path) = write("heights.npy", b"1 2 3\n4 5 6\n7 8 9\n");
        let options = ReadOptions {
            pixel_size_m: Some((1e-6, 1e-6)),
            ..ReadOptions::default()
        };
        let map = read_height_map(&path, &options).unwrap();
        assert_eq!((map.format, map.nx()), (TopographyFormat::Text, 3));
    }
}
