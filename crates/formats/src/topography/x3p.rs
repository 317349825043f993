//! ISO 25178-72 XML 3D surface profile (`.x3p`): a zip archive (read with the `zip` crate) with
//! `main.xml` at its root (ISO 5436-2 `Record1`–`Record4`) and the binary points it links
//! (`Record3/DataLink/PointDataLink`, usually `bindata/data.bin`). `Record1/FeatureType` must
//! be `SUR` (an areal surface); `Record1/Axes/CX|CY/Increment` give the pixel size (m);
//! `CZ/DataType` the point type (`I` int16, `L` int32, `F` float32, `D` float64,
//! little-endian) and `CZ/Increment`, `CZ/Offset` the scaling `h = raw · Increment + Offset`
//! (defaults 1 and 0); `Record3/MatrixDimension/SizeX|SizeY` the grid, x fastest. Invalid
//! points are NaN (float data) or the 0 bits of the optional `ValidPointsLink` file (one bit per
//! point, least significant bit first). Some writers put `main.xml` and the data in one
//! sub-folder of the archive (`name/main.xml`, `name/bindata/data.bin`): when exactly one
//! `main.xml` is found, the links are taken relative to its folder. A zip archive without one
//! is refused, saying what it holds (an Office workbook, or its first entries).

use std::io::Read;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, unsupported, MAX_PLANE_BYTES};
use crate::error::Result;

/// Read an X3P file.
pub fn read(path: &Path, channel: Option<&str>) -> Result<HeightMap> {
    crate::inputs::note_input(path);
    let file = std::fs::File::open(path).map_err(|e| crate::Error::io(path, e))?;
    let mut zip = zip::ZipArchive::new(file)
        .map_err(|e| bad(path, format!("not a readable zip archive: {e}")))?;
    let folder = main_folder(path, &zip)?;
    let mut member = |name: &str, limit: usize| -> Result<Vec<u8>> {
        let entry = zip
            .by_name(&format!("{folder}{name}"))
            .map_err(|_| bad(path, format!("the X3P archive has no '{name}'")))?;
        if entry.size() > limit as u64 {
            return Err(unsupported(
                path,
                format!("'{name}' of {} bytes exceeds the limit", entry.size()),
            ));
        }
        let mut out = Vec::with_capacity(entry.size() as usize);
        entry
            .take(limit as u64)
            .read_to_end(&mut out)
            .map_err(|e| bad(path, format!("'{name}' does not decompress: {e}")))?;
        Ok(out)
    };
    let xml = member("main.xml", 16 << 20)?;
    let xml = String::from_utf8(xml).map_err(|_| bad(path, "main.xml is not UTF-8"))?;
    let doc = roxmltree::Document::parse(&xml)
        .map_err(|e| bad(path, format!("main.xml does not parse: {e}")))?;
    let find = |names: &[&str]| -> Option<String> {
        let mut node = doc.root_element();
        for n in names {
            node = node.children().find(|c| c.has_tag_name(*n))?;
        }
        node.text().map(|t| t.trim().to_string())
    };
    let feature = find(&["Record1", "FeatureType"]).unwrap_or_default();
    if feature != "SUR" {
        return Err(unsupported(
            path,
            format!("X3P feature type '{feature}' (an areal surface is SUR)"),
        ));
    }
    let number = |names: &[&str]| find(names).and_then(|t| t.parse::<f64>().ok());
    let nx = count(
        path,
        "SizeX",
        number(&["Record3", "MatrixDimension", "SizeX"]).unwrap_or(0.0),
    )?;
    let ny = count(
        path,
        "SizeY",
        number(&["Record3", "MatrixDimension", "SizeY"]).unwrap_or(0.0),
    )?;
    let kind = find(&["Record1", "Axes", "CZ", "DataType"]).unwrap_or_else(|| "D".into());
    let (width, float) = match kind.as_str() {
        "I" => (2, false),
        "L" => (4, false),
        "F" => (4, true),
        "D" => (8, true),
        other => return Err(unsupported(path, format!("X3P point type '{other}'"))),
    };
    let bytes = grid_bytes(path, nx, ny, width)?;
    let link = find(&["Record3", "DataLink", "PointDataLink"]).ok_or_else(|| {
        bad(
            path,
            "main.xml has no PointDataLink (points inside the XML are not supported)",
        )
    })?;
    let raw = member(&link, MAX_PLANE_BYTES)?;
    if raw.len() < bytes {
        return Err(bad(
            path,
            format!(
                "'{link}' holds {} bytes, {nx}×{ny} points need {bytes}",
                raw.len()
            ),
        ));
    }
    let inc = number(&["Record1", "Axes", "CZ", "Increment"]).unwrap_or(1.0);
    let off = number(&["Record1", "Axes", "CZ", "Offset"]).unwrap_or(0.0);
    let mut heights: Vec<f64> = decode_values(&raw[..bytes], width, float, true, false)
        .into_iter()
        .map(|v| v * inc + off)
        .collect();
    if let Some(valid) = find(&["Record3", "DataLink", "ValidPointsLink"]) {
        let bits = member(&valid, MAX_PLANE_BYTES)?;
        for (i, h) in heights.iter_mut().enumerate() {
            if bits.get(i / 8).is_none_or(|b| b >> (i % 8) & 1 == 0) {
                *h = f64::NAN;
            }
        }
    }
    let channels = [ChannelEntry {
        name: "Default".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let dx = positive(
        path,
        "CX increment",
        number(&["Record1", "Axes", "CX", "Increment"]).unwrap_or(f64::NAN),
    )?;
    let dy = positive(
        path,
        "CY increment",
        number(&["Record1", "Axes", "CY", "Increment"]).unwrap_or(f64::NAN),
    )?;
    height_map(
        path,
        TopographyFormat::X3p,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}

/// The folder (`""` or `"name/"`) of the archive's one `main.xml`, or an error saying what the
/// archive holds instead.
fn main_folder<R: std::io::Read + std::io::Seek>(
    path: &Path,
    zip: &zip::ZipArchive<R>,
) -> Result<String> {
    let names: Vec<&str> = zip.file_names().collect();
    if names.contains(&"main.xml") {
        return Ok(String::new());
    }
    let nested: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| n.ends_with("/main.xml"))
        .collect();
    if let [one] = nested.as_slice() {
        return Ok(one.trim_end_matches("main.xml").to_string());
    }
    // Sensofar's PLUX (as surfalize documents it): `index.xml` with the layers `LAYER_0.raw`, ….
    let what = if names.contains(&"index.xml") && names.contains(&"LAYER_0.raw") {
        "a Sensofar PLUX file: not read by contactscope (no sample file to test a reader on); \
         export the map from SensoView as .plu, .gsf or a text matrix"
            .to_string()
    } else if names.contains(&"[Content_Types].xml") {
        let kind = if names.iter().any(|n| n.starts_with("xl/")) {
            "an Excel workbook (.xlsx)"
        } else if names.iter().any(|n| n.starts_with("word/")) {
            "a Word document (.docx)"
        } else {
            "an Office Open XML document"
        };
        format!("{kind}, not a height map")
    } else {
        let mut shown: Vec<String> = names.iter().take(5).map(|n| format!("'{n}'")).collect();
        if names.len() > 5 {
            shown.push(format!("… ({} entries)", names.len()));
        }
        format!(
            "a zip archive that is not ISO 25178-72 X3P ({}; it holds {})",
            if nested.is_empty() {
                "no main.xml"
            } else {
                "several main.xml"
            },
            if shown.is_empty() {
                "nothing".to_string()
            } else {
                shown.join(", ")
            }
        )
    };
    Err(unsupported(path, what))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn x3p(dir: &Path, with_valid: bool) -> std::path::PathBuf {
        archive(dir, "", with_valid)
    }

    fn archive(dir: &Path, folder: &str, with_valid: bool) -> std::path::PathBuf {
        let path = dir.join(format!("t{with_valid}{}.x3p", folder.len()));
        let mut zip = zip::ZipWriter::new(std::fs::File::create(&path).unwrap());
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        let valid = if with_valid {
            "<ValidPointsLink>bindata/valid.bin</ValidPointsLink>"
        } else {
            ""
        };
        let xml = format!(
            "<p:ISO5436_2 xmlns:p=\"x\"><Record1><FeatureType>SUR</FeatureType><Axes>\
             <CX><Increment>1e-6</Increment></CX><CY><Increment>2e-6</Increment></CY>\
             <CZ><DataType>I</DataType><Increment>1e-9</Increment><Offset>1e-6</Offset></CZ>\
             </Axes></Record1><Record3><MatrixDimension><SizeX>3</SizeX><SizeY>2</SizeY>\
             <SizeZ>1</SizeZ></MatrixDimension><DataLink><PointDataLink>bindata/data.bin\
             </PointDataLink>{valid}</DataLink></Record3></p:ISO5436_2>"
        );
        zip.start_file(format!("{folder}main.xml"), opts).unwrap();
        zip.write_all(xml.as_bytes()).unwrap();
        zip.start_file(format!("{folder}bindata/data.bin"), opts)
            .unwrap();
        for v in [0i16, 1, 2, 3, 4, -5] {
            zip.write_all(&v.to_le_bytes()).unwrap();
        }
        zip.start_file(format!("{folder}bindata/valid.bin"), opts)
            .unwrap();
        zip.write_all(&[0b0011_1011]).unwrap();
        zip.finish().unwrap();
        path
    }

    #[test]
    fn scales_integer_points_and_reads_the_validity_bits() {
        let dir = tempfile::tempdir().unwrap();
        let m = read(&x3p(dir.path(), false), None).unwrap();
        assert_eq!((m.nx(), m.ny(), m.invalid_points), (3, 2, 0));
        assert!((m.heights[[1, 2]] - (1e-6 - 5e-9)).abs() < 1e-18);
        assert_eq!((m.dx_m, m.dy_m), (1e-6, 2e-6));
        // Bit 2 (point 2) is 0: invalid.
        let v = read(&x3p(dir.path(), true), None).unwrap();
        assert_eq!(v.invalid_points, 1);
        assert!(v.heights[[0, 2]].is_nan());
    }

    #[test]
    fn main_xml_in_a_sub_folder_reads_and_other_zips_say_what_they_are() {
        let dir = tempfile::tempdir().unwrap();
        let top = read(&x3p(dir.path(), true), None).unwrap();
        let nested = read(&archive(dir.path(), "scan 1/", true), None).unwrap();
        assert_eq!(top.heights.iter().filter(|h| h.is_nan()).count(), 1);
        assert_eq!(
            format!("{:?}", top.heights),
            format!("{:?}", nested.heights)
        );
        let other = |name: &str, entries: &[&str]| {
            let path = dir.path().join(name);
            let mut zip = zip::ZipWriter::new(std::fs::File::create(&path).unwrap());
            for e in entries {
                zip.start_file(*e, zip::write::SimpleFileOptions::default())
                    .unwrap();
            }
            zip.finish().unwrap();
            read(&path, None).unwrap_err().to_string()
        };
        let err = other("a.xlsx", &["[Content_Types].xml", "xl/workbook.xml"]);
        assert!(
            err.contains("Excel workbook") && err.contains("a.xlsx"),
            "{err}"
        );
        let err = other("b.zip", &["index.xml", "LAYER_0.raw"]);
        assert!(
            err.contains("Sensofar PLUX") && err.contains("b.zip"),
            "{err}"
        );
        let err = other("c.zip", &["index.xml", "data.bin"]);
        assert!(
            err.contains("no main.xml") && err.contains("'data.bin'"),
            "{err}"
        );
    }
}
