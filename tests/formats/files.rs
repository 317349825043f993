//! Every file of `../shared/data/synthetic-tiff-formats` decodes to the pixel sums of its
//! `manifest.csv`, or fails with a clear "unsupported" error where the manifest's format is one
//! we refuse (packed 12-bit).

use std::path::Path;

use contactscope::image::{PixelSizeSource, Plane};
use contactscope_formats::tiff::{ChannelLayout, TiffReader};
use contactscope_formats::Error;

struct Expected {
    file: String,
    pages: usize,
    dtype: String,
    samples: usize,
    n_values: u64,
    sum: f64,
    min: f64,
    max: f64,
}

fn manifest(dir: &Path) -> Vec<Expected> {
    let (header, rows) = crate::common::read_csv(&dir.join("manifest.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    rows.iter()
        .map(|r| Expected {
            file: r[col("file")].clone(),
            pages: r[col("pages")].parse().unwrap(),
            dtype: r[col("dtype")].clone(),
            samples: r[col("samples_per_pixel")].parse().unwrap(),
            n_values: r[col("n_values")].parse().unwrap(),
            sum: r[col("sum")].parse().unwrap(),
            min: r[col("min")].parse().unwrap(),
            max: r[col("max")].parse().unwrap(),
        })
        .collect()
}

fn stats(planes: &[Plane]) -> (u64, f64, f64, f64) {
    let values: Vec<f64> = planes.iter().flat_map(|p| p.to_f64()).collect();
    let sum = values.iter().sum();
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (values.len() as u64, sum, min, max)
}

#[test]
fn every_synthetic_format_gives_the_manifest_sums() {
    let Some(dir) = crate::common::shared_data("synthetic-tiff-formats") else {
        return;
    };
    let expected = manifest(&dir);
    assert_eq!(expected.len(), 21);
    for e in expected {
        let path = dir.join(&e.file);
        if e.file.starts_with("m_packed12") {
            match TiffReader::open(&path) {
                Err(Error::Unsupported { reason, at }) => {
                    assert!(reason.contains("12-bit"), "{reason}");
                    assert_eq!(at.path, path);
                }
                other => panic!("{}: expected unsupported, got {:?}", e.file, other.err()),
            }
            continue;
        }
        let mut reader = TiffReader::open(&path).unwrap_or_else(|err| panic!("{}: {err}", e.file));
        let info = reader.info().clone();
        assert_eq!(info.pages.len(), e.pages, "{}", e.file);
        assert_eq!(info.sample_type.name(), e.dtype, "{}", e.file);
        assert_eq!(info.channels, e.samples, "{}", e.file);
        let mut planes = Vec::new();
        for &page in &info.pages {
            for channel in 0..e.samples {
                planes.push(reader.read_page(page, channel).unwrap());
            }
        }
        let (n, sum, min, max) = stats(&planes);
        assert_eq!(n, e.n_values, "{}", e.file);
        let tolerance = if e.dtype == "float32" { 1e-3 } else { 0.0 };
        assert!(
            (sum - e.sum).abs() <= tolerance,
            "{}: sum {sum} vs {}",
            e.file,
            e.sum
        );
        assert!((min - e.min).abs() <= 1e-7, "{}: min {min}", e.file);
        assert!((max - e.max).abs() <= 1e-7, "{}: max {max}", e.file);
    }
}

#[test]
fn planar_and_contiguous_channels_agree() {
    let Some(dir) = crate::common::shared_data("synthetic-tiff-formats") else {
        return;
    };
    let mut planar = TiffReader::open(&dir.join("k_planar_2ch.tif")).unwrap();
    let mut contiguous = TiffReader::open(&dir.join("k2_contig_2ch.tif")).unwrap();
    assert_eq!(planar.info().channel_layout, ChannelLayout::Planar);
    assert_eq!(contiguous.info().channel_layout, ChannelLayout::Contiguous);
    for channel in 0..2 {
        assert_eq!(
            planar.read_page(0, channel).unwrap(),
            contiguous.read_page(0, channel).unwrap()
        );
    }
    assert_ne!(
        planar.read_page(0, 0).unwrap(),
        planar.read_page(0, 1).unwrap(),
        "the second plane must not be a copy of the first"
    );
}

#[test]
fn pixel_size_metadata_sources() {
    let Some(dir) = crate::common::shared_data("synthetic-tiff-formats") else {
        return;
    };
    let size = |f: &str| TiffReader::open(&dir.join(f)).unwrap().info().pixel_size;
    let imagej = size("a_imagej_hyperstack.tif").unwrap();
    assert_eq!(imagej.source, PixelSizeSource::ImageJ);
    assert!((imagej.x_m - 0.2e-6).abs() < 1e-12);
    let ome = size("b_ome.ome.tif").unwrap();
    assert_eq!(
        ome.source,
        PixelSizeSource::OmeXml,
        "OME-XML wins over 5 px/inch tags"
    );
    assert!((ome.x_m - 0.2e-6).abs() < 1e-12);
    let tags = size("j_single_desc.tif").unwrap();
    assert_eq!(tags.source, PixelSizeSource::ResolutionTags);
    assert!((tags.x_m - 2e-3).abs() < 1e-12, "5 px/cm");
    assert!(
        size("c_lzw_pred.tif").is_some(),
        "tifffile wrote 5 px/cm here too"
    );
    assert!(size("i_bigendian.tif").is_none());
}
