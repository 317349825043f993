//! The machine-readable summary that `contactscope info FILE --json [--stats]` prints for every
//! confocal format (`docs/formats.md`, "Summaries"):
//!
//! ```json
//! {"file": "…", "format": "czi", "series": [{"index": 0, "name": "", "axes": {"T": 3, "Z": 5,
//!  "C": 2, "Y": 170, "X": 240}, "dtype": "uint16", "pixel_size_um": {"x": 0.0906, "y": 0.0906,
//!  "z": 0.32}, "pixel_size_source": "…", "planes": [{"t": 0, "z": 0, "c": 0, "min": 0.0,
//!  "max": 4186.0, "mean": 219.4, "sum": 8951607.0}, …]}]}
//! ```
//!
//! `planes` is present only when statistics are asked for; extra axes (`H`, `S`, …) appear in
//! `axes` and as further keys of each plane. A scan without a y axis has `"rows": "Z"` (an X–Z
//! section: `Y` counts focal planes, `pixel_size_um.y` is the z step) or `"rows": "T"` (an X–T
//! line scan: `Y` counts time points, no y size); other series have no `rows` key. A TIFF
//! whose OME-XML was read from another file (a companion `.companion.ome`, a set's master TIFF)
//! names it in `"metadata_file"`. Statistics are over finite values (NaN and ±∞ of float images
//! are left out); sums of integer images are exact.

use std::path::Path;

use serde::Serialize;

use super::select::Selection;
use super::{Axes, MicroscopyFile, PlaneIndex, Rows, VoxelSize};
use crate::binary::bad;
use crate::error::Result;
use crate::image::{Plane, Samples};
use crate::param::Param;

/// `info --json` for one file.
#[derive(Debug, Clone, Serialize)]
pub struct InfoSummary {
    /// The file as named.
    pub file: String,
    /// `czi`, `nd2`, `lif` or `tiff`.
    pub format: String,
    /// One entry per series.
    pub series: Vec<SeriesSummary>,
    /// The file a TIFF's OME-XML was read from when the TIFF only points to it (a companion
    /// `.companion.ome` or the master TIFF of a multi-file set); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub metadata_file: Option<String>,
}

/// One series of [`InfoSummary`].
#[derive(Debug, Clone, Serialize)]
pub struct SeriesSummary {
    /// Zero-based series index.
    pub index: usize,
    /// Series name (may be empty).
    pub name: String,
    /// Axis sizes.
    pub axes: Axes,
    /// Sample type (`uint8`, `uint16`, `int16`, `float32`).
    pub dtype: String,
    /// One entry per channel: its name (`null` where the file gives none), by which
    /// `--channel` can choose it.
    pub channels: Vec<ChannelSummary>,
    /// Voxel size in µm, `null` where the file does not state it.
    pub pixel_size_um: PixelSizeUm,
    /// The metadata element the x/y size came from (`null` when absent).
    pub pixel_size_source: Option<String>,
    /// What the image rows are: y, or the scanned axis of a scan without y (absent for y).
    #[serde(skip_serializing_if = "Rows::is_y")]
    pub rows: Rows,
    /// Where a TIFF's axes come from (`ome`, `imagej`, `pages`: no axis metadata); absent for
    /// other formats.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axes_from: Option<crate::tiff::AxesSource>,
    /// The voxel size in metres as the file states it (`pixel_size_um` is this in µm), for
    /// callers that write it in other units.
    #[serde(skip)]
    pub pixel_size_m: VoxelSize,
    /// Per-plane statistics, with `--stats` only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub planes: Option<Vec<PlaneStats>>,
}

/// One channel of [`SeriesSummary`].
#[derive(Debug, Clone, Serialize)]
pub struct ChannelSummary {
    /// Name as the acquisition software wrote it.
    pub name: Option<String>,
    /// Emission wavelength, m.
    pub emission_m: Option<f64>,
    /// Excitation wavelength, m.
    pub excitation_m: Option<f64>,
}

/// Voxel size in µm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PixelSizeUm {
    /// Along x.
    pub x: Option<f64>,
    /// Along y.
    pub y: Option<f64>,
    /// Between planes.
    pub z: Option<f64>,
}

/// Statistics of one plane.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlaneStats {
    /// Which plane.
    #[serde(flatten)]
    pub index: PlaneIndex,
    /// Smallest finite value.
    pub min: f64,
    /// Largest finite value.
    pub max: f64,
    /// Mean of the finite values.
    pub mean: f64,
    /// Sum of the finite values.
    pub sum: f64,
}

/// Min, max, mean and sum of the finite values of a plane (NaN for all four when none is
/// finite).
pub fn plane_statistics(plane: &Plane) -> (f64, f64, f64, f64) {
    let (mut min, mut max, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
    let mut add = |v: f64| {
        if v.is_finite() {
            min = min.min(v);
            max = max.max(v);
            sum += v;
            n += 1;
        }
    };
    match &plane.samples {
        Samples::Int { codes, offset } => {
            // Exact: integer sums stay below 2^53 for any plane under the size limit.
            let s: i64 = codes
                .iter()
                .map(|&c| i64::from(c) + i64::from(*offset))
                .sum();
            codes
                .iter()
                .for_each(|&c| add(f64::from(i32::from(c) + offset)));
            sum = s as f64;
        }
        Samples::Float(v) => v.iter().for_each(|&x| add(f64::from(x))),
    }
    if n == 0 {
        return (f64::NAN, f64::NAN, f64::NAN, f64::NAN);
    }
    (min, max, sum / n as f64, sum)
}

/// The summary of a file; with `stats`, every plane of every series is decoded (one at a time)
/// and summarised.
pub fn info_summary(path: &Path, stats: bool) -> Result<InfoSummary> {
    info_summary_selected(path, stats, &Selection::default())
}

/// The summary restricted by the selection flags: `--series` keeps one series, `--channel`,
/// `--z` and `--t` keep the planes (of `planes`) with that index. An index beyond an axis of a
/// listed series is an error naming the axis and its length.
pub fn info_summary_selected(
    path: &Path,
    stats: bool,
    selection: &Selection,
) -> Result<InfoSummary> {
    let mut file = MicroscopyFile::open(path)?;
    let mut series = Vec::with_capacity(file.series.len());
    let n_series = file.series.len();
    if let Some(s) = selection.series.filter(|s| *s >= n_series) {
        return Err(bad(
            path,
            format!(
                "{} {s} requested; the file has {n_series} series",
                Param::Series
            ),
        ));
    }
    for info in file.series.clone() {
        if selection.series.is_some_and(|s| s != info.index) {
            continue;
        }
        let a = &info.axes;
        let channel = match &selection.channel {
            Some(choice) => Some(choice.resolve(path, &info.channels)?),
            None => None,
        };
        for (flag, value, n) in [
            (Param::Channel, channel, a.c),
            (Param::Z, selection.z, a.z),
            (Param::T, selection.t, a.t),
        ] {
            if let Some(v) = value.filter(|v| *v >= n) {
                return Err(bad(
                    path,
                    format!(
                        "{flag} {v} requested; series {} has {n} (0..{})",
                        info.index,
                        n - 1
                    ),
                ));
            }
        }
        let wanted = |i: &PlaneIndex| {
            channel.is_none_or(|c| c == i.c)
                && selection.z.is_none_or(|z| z == i.z)
                && selection.t.is_none_or(|t| t == i.t)
                && selection.extra.iter().all(|(a, &k)| i.get(a) == k)
        };
        let um = |m: Option<f64>| m.map(|v| v * 1e6);
        let planes = if stats {
            let mut out = Vec::new();
            for index in PlaneIndex::all(&info.axes).into_iter().filter(wanted) {
                let plane = file.read_plane(info.index, &index)?;
                let (min, max, mean, sum) = plane_statistics(&plane);
                out.push(PlaneStats {
                    index,
                    min,
                    max,
                    mean,
                    sum,
                });
            }
            Some(out)
        } else {
            None
        };
        series.push(SeriesSummary {
            index: info.index,
            name: info.name.clone(),
            axes: info.axes.clone(),
            dtype: info.dtype.name().to_string(),
            channels: info
                .channels
                .iter()
                .map(|c| ChannelSummary {
                    name: c.name.clone(),
                    emission_m: c.emission_wavelength_m,
                    excitation_m: c.excitation_wavelength_m,
                })
                .collect(),
            pixel_size_um: PixelSizeUm {
                x: um(info.pixel_size.x_m),
                y: um(info.pixel_size.y_m),
                z: um(info.pixel_size.z_m),
            },
            pixel_size_source: info.pixel_size.source.clone(),
            rows: info.rows,
            axes_from: info.tiff_axes,
            pixel_size_m: info.pixel_size.clone(),
            planes,
        });
    }
    Ok(InfoSummary {
        file: path.display().to_string(),
        format: file.format.name().to_string(),
        series,
        metadata_file: file
            .tiff_info()
            .and_then(|i| i.metadata_file.as_ref())
            .map(|m| m.display().to_string()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_integer_and_float_planes() {
        let p = Plane::from_u16(2, 2, vec![1, 2, 3, 10]);
        assert_eq!(plane_statistics(&p), (1.0, 10.0, 4.0, 16.0));
        let f = Plane {
            width: 3,
            height: 1,
            sample_type: crate::image::SampleType::F32,
            samples: Samples::Float(vec![1.0, f32::NAN, 3.0]),
        };
        assert_eq!(plane_statistics(&f), (1.0, 3.0, 2.0, 4.0));
        let i = Plane {
            width: 2,
            height: 1,
            sample_type: crate::image::SampleType::I16,
            samples: Samples::Int {
                codes: vec![0, 32770],
                offset: -32768,
            },
        };
        assert_eq!(plane_statistics(&i), (-32768.0, 2.0, -16383.0, -32766.0));
    }
}
