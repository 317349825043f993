//! Which planes of a confocal file a command uses: the `--series`, `--channel`, `--z` and `--t`
//! selection shared by every command that reads confocal images, and the load axis
//! (`--load-axis t|z|series`) along which one file holds a whole load series (`docs/formats.md`).
//!
//! Rules ([`Selection::planes`]): an axis of length 1 defaults to 0; an axis longer than 1 must
//! be selected unless it is the load axis, otherwise one error names every such axis, its length
//! and its flag ("FILE: 2 channels and 10 z planes; choose one of each with --channel 0..1 or a
//! name (0 'TL', 1 'AF488') and --z 0..9"). A channel is chosen by index or by the name the
//! file's metadata gives it ([`ChannelChoice`], case-insensitive). Extra axes (Airyscan phases
//! `H`, colour samples `S`, spectral sweeps, …) are chosen by name (`--axis H=0`,
//! [`Selection::extra`]); one longer than 1 and not chosen is named in the same error (`info`
//! lists them).
//!
//! TIFF files have the same axes, from their OME-XML or ImageJ description
//! ([`crate::tiff::axes`]); a TIFF's load axis, when none is named, is its time points, else its
//! focal planes, and a z stack is refused ([`super::LoadDefault`]).

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

use serde::Serialize;

use super::{ChannelInfo, LoadDefault, MicroscopyFile, MicroscopyFormat, PlaneIndex, SeriesInfo};
use crate::error::{Error, Location, Result};
use crate::image::{pixel_size_or, Image, PixelSize, PixelSizeSource};
use crate::param::Param;

/// The selection flags: each `None` when not given.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct Selection {
    /// `--series`: CZI scene, LIF image, image of a multi-image OME-TIFF (ND2 has one series).
    pub series: Option<usize>,
    /// `--channel`: an index or a name.
    pub channel: Option<ChannelChoice>,
    /// `--z`: focal plane.
    pub z: Option<usize>,
    /// `--t`: time point.
    pub t: Option<usize>,
    /// `--axis NAME=INDEX`: indices along extra axes (`H`, `S`, `lambda_emission`, …).
    pub extra: BTreeMap<String, usize>,
}

/// `--channel`: an index, or a channel's name as the file's metadata gives it (`AF488`, `TL
/// Brightfield`; compared without regard to case).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum ChannelChoice {
    /// Zero-based index.
    Index(usize),
    /// Name.
    Name(String),
}

impl FromStr for ChannelChoice {
    type Err = String;

    /// Digits are an index, anything else a name.
    fn from_str(text: &str) -> std::result::Result<Self, String> {
        let t = text.trim();
        if t.is_empty() {
            return Err("the channel is empty: give an index (0, 1, …) or a name".into());
        }
        if t.parse::<i64>().is_ok_and(|i| i < 0) {
            return Err(format!("channel index {t} is negative"));
        }
        if t.bytes().all(|b| b.is_ascii_digit()) {
            return t
                .parse()
                .map(ChannelChoice::Index)
                .map_err(|_| format!("channel index {t} is too large"));
        }
        Ok(ChannelChoice::Name(t.to_string()))
    }
}

impl fmt::Display for ChannelChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ChannelChoice::Index(i) => write!(f, "{i}"),
            ChannelChoice::Name(n) => write!(f, "{n:?}"),
        }
    }
}

impl From<usize> for ChannelChoice {
    fn from(i: usize) -> Self {
        ChannelChoice::Index(i)
    }
}

impl ChannelChoice {
    /// The index this choice names among `channels` (names compared without regard to case).
    pub fn resolve(&self, path: &Path, channels: &[ChannelInfo]) -> Result<usize> {
        match self {
            ChannelChoice::Index(i) => Ok(*i),
            ChannelChoice::Name(name) => {
                let found = channels.iter().position(|c| {
                    c.name
                        .as_deref()
                        .is_some_and(|n| n.trim().eq_ignore_ascii_case(name))
                });
                found.ok_or_else(|| {
                    let listed = channel_names(channels);
                    Error::bad_input(
                        Location::file(path),
                        match listed {
                            Some(names) => format!(
                                "{}: no channel has that name; the channels are {names}",
                                Param::Channel.with_value(name)
                            ),
                            None => format!(
                                "{}: the file's {} channel(s) have no names; choose by index (0..{})",
                                Param::Channel.with_value(name),
                                channels.len(),
                                channels.len().saturating_sub(1)
                            ),
                        },
                    )
                })
            }
        }
    }
}

/// `0 'TL', 1 'AF488'` (at most eight, then a count), or `None` when no channel has a name.
fn channel_names(channels: &[ChannelInfo]) -> Option<String> {
    if channels
        .iter()
        .all(|c| c.name.as_deref().is_none_or(|n| n.trim().is_empty()))
    {
        return None;
    }
    Some(listing(channels.iter().map(|c| c.name.as_deref())))
}

/// `0 'a', 1 'b', 2` for labelled items (at most eight, names cut at 40 characters).
fn listing<'a>(names: impl ExactSizeIterator<Item = Option<&'a str>>) -> String {
    let n = names.len();
    let mut parts: Vec<String> = names
        .take(8)
        .enumerate()
        .map(
            |(i, name)| match name.map(str::trim).filter(|t| !t.is_empty()) {
                Some(t) if t.chars().count() > 40 => {
                    format!("{i} '{}…'", t.chars().take(40).collect::<String>())
                }
                Some(t) => format!("{i} '{t}'"),
                None => i.to_string(),
            },
        )
        .collect();
    if n > 8 {
        parts.push(format!("… ({} more)", n - 8));
    }
    parts.join(", ")
}

/// The axis along which one file holds the loads of a series, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LoadAxis {
    /// Time points.
    T,
    /// Focal planes.
    Z,
    /// Series (CZI scenes, LIF images, OME-TIFF images).
    Series,
}

impl LoadAxis {
    /// The flag value (`t`, `z`, `series`).
    pub fn name(self) -> &'static str {
        match self {
            LoadAxis::T => "t",
            LoadAxis::Z => "z",
            LoadAxis::Series => "series",
        }
    }
}

/// One selected plane of a file: its series, its index, and its position along the load axis
/// (0 without one).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SelectedPlane {
    /// Series index in the file.
    pub series: usize,
    /// The plane within the series.
    pub index: PlaneIndex,
    /// Position along the load axis.
    pub load_index: usize,
}

impl SelectedPlane {
    /// `series 0, t 2, z 0, c 1` for labels.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "series {}, t {}, z {}, c {}",
            self.series, self.index.t, self.index.z, self.index.c
        );
        for (axis, i) in &self.index.extra {
            s.push_str(&format!(", {axis} {i}"));
        }
        s
    }
}

impl Selection {
    /// Only a channel index (the older `--channel` of TIFF commands).
    pub fn channel(channel: Option<usize>) -> Self {
        Selection {
            channel: channel.map(ChannelChoice::Index),
            ..Selection::default()
        }
    }

    /// The planes of `file` this selection names, in load order: one plane without a load axis,
    /// every plane along `along` otherwise.
    pub fn planes(
        &self,
        file: &MicroscopyFile,
        along: Option<LoadAxis>,
    ) -> Result<Vec<SelectedPlane>> {
        if let Some(info) = file.tiff_info() {
            return Ok(self
                .tiff_planes(info, along, LoadDefault::None)?
                .1
                .into_iter()
                .map(|(plane, _)| plane)
                .collect());
        }
        self.planes_in(&file.path, &file.series, along)
    }

    /// [`Selection::planes`] over the series of a file at `path`.
    pub(crate) fn planes_in(
        &self,
        path: &Path,
        all_series: &[SeriesInfo],
        along: Option<LoadAxis>,
    ) -> Result<Vec<SelectedPlane>> {
        let bad = |reason: String| Error::bad_input(Location::file(path), reason);
        let n_series = all_series.len();
        if n_series == 0 {
            return Err(bad("the file holds no image series".into()));
        }
        if let Some(reason) = self.unchosen(all_series, along) {
            return Err(bad(reason));
        }
        let series: Vec<usize> = if along == Some(LoadAxis::Series) {
            if self.series.is_some() {
                return Err(Error::InvalidArgument(format!(
                    "{} cannot be combined with {}",
                    Param::Series,
                    Param::LoadAxis.with_value("series")
                )));
            }
            (0..n_series).collect()
        } else {
            vec![pick(path, "series", Param::Series, self.series, n_series)?]
        };
        let mut out = Vec::new();
        for (k, &s) in series.iter().enumerate() {
            let info = &all_series[s];
            let extra = self.extra_index(path, info)?;
            let a = &info.axes;
            let what = |axis: &'static str| match n_series {
                1 => axis.to_string(),
                _ => format!("{axis} in series {s}"),
            };
            let channel = match &self.channel {
                Some(choice) => Some(choice.resolve(path, &info.channels)?),
                None => None,
            };
            let c = pick(path, &what("channels"), Param::Channel, channel, a.c)?;
            let zs = along_or_pick(
                path,
                &what("z planes"),
                Param::Z,
                self.z,
                a.z,
                along,
                LoadAxis::Z,
            )?;
            let ts = along_or_pick(
                path,
                &what("time points"),
                Param::T,
                self.t,
                a.t,
                along,
                LoadAxis::T,
            )?;
            for &t in &ts {
                for &z in &zs {
                    let load_index = match along {
                        Some(LoadAxis::T) => t,
                        Some(LoadAxis::Z) => z,
                        Some(LoadAxis::Series) => k,
                        None => 0,
                    };
                    let mut index = PlaneIndex::tzc(t, z, c);
                    index.extra = extra.clone();
                    out.push(SelectedPlane {
                        series: s,
                        index,
                        load_index,
                    });
                }
            }
        }
        Ok(out)
    }
}

impl Selection {
    /// Every axis longer than 1 that is neither chosen nor the load axis, in one message
    /// (`None` when there is none): the series, then the channels (with their names), z, t and
    /// the extra axes of the chosen series (series 0 when the series is not chosen either).
    fn unchosen(&self, all_series: &[SeriesInfo], along: Option<LoadAxis>) -> Option<String> {
        let n_series = all_series.len();
        // (what, flag and values)
        let mut items: Vec<(String, String)> = Vec::new();
        if n_series > 1 && self.series.is_none() && along != Some(LoadAxis::Series) {
            let names = listing(all_series.iter().map(|s| Some(s.name.as_str())));
            let names = if all_series.iter().any(|s| !s.name.trim().is_empty()) {
                format!(" ({names})")
            } else {
                String::new()
            };
            items.push((
                format!("{n_series} series"),
                format!(
                    "{}{names}",
                    Param::Series.with_value(format!("0..{}", n_series - 1))
                ),
            ));
        }
        if self.series.is_some_and(|s| s >= n_series) {
            // An index beyond the file: the range error says so first.
            return None;
        }
        let index = self.series.unwrap_or(0);
        let info = all_series.get(index)?;
        let a = &info.axes;
        let of = if n_series > 1 && self.series.is_none() {
            format!(" in series {index}")
        } else {
            String::new()
        };
        if a.c > 1 && self.channel.is_none() {
            let flag = Param::Channel.with_value(format!("0..{}", a.c - 1));
            let flag = match channel_names(&info.channels) {
                Some(names) => format!("{flag} or a name ({names})"),
                None => flag,
            };
            items.push((format!("{} channels{of}", a.c), flag));
        }
        for (n, chosen, axis, what, flag) in [
            (a.z, self.z, LoadAxis::Z, "z planes", Param::Z),
            (a.t, self.t, LoadAxis::T, "time points", Param::T),
        ] {
            if n > 1 && chosen.is_none() && along != Some(axis) {
                items.push((
                    format!("{n} {what}{of}"),
                    flag.with_value(format!("0..{}", n - 1)),
                ));
            }
        }
        for (axis, &n) in &info.axes.extra {
            if n > 1 && !self.extra.contains_key(axis) {
                let meaning = axis_meaning(axis);
                items.push((
                    format!("{n} planes along axis {axis}{meaning}{of}"),
                    Param::axis_value(axis, format!("0..{}", n - 1)),
                ));
            }
        }
        let and = |parts: Vec<&str>| match parts.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            Some((last, _)) => last.to_string(),
            None => String::new(),
        };
        let whats = and(items.iter().map(|(w, _)| w.as_str()).collect());
        let flags = and(items.iter().map(|(_, f)| f.as_str()).collect());
        match items.len() {
            0 => None,
            1 => Some(format!("{whats}; choose one with {flags}")),
            _ => Some(format!("{whats}; choose one of each with {flags}")),
        }
    }
}

/// What an extra axis holds, for messages (` (Airyscan detector phases)`), or nothing.
fn axis_meaning(axis: &str) -> &'static str {
    match axis {
        "H" => " (Airyscan detector phases)",
        "S" => " (colour samples of an RGB pixel: 0 blue, 1 green, 2 red)",
        "P" => " (stage positions)",
        _ => "",
    }
}

/// The index along an axis of length `n`: the requested one (checked), or 0 when `n` is 1.
fn pick(path: &Path, what: &str, flag: Param, requested: Option<usize>, n: usize) -> Result<usize> {
    let bad = |reason: String| Error::bad_input(Location::file(path), reason);
    match requested {
        Some(i) if i < n => Ok(i),
        Some(i) => Err(bad(format!(
            "{} requested; the file has {n} {what} (0..{})",
            flag.with_value(i),
            n.saturating_sub(1)
        ))),
        None if n == 1 => Ok(0),
        None => Err(bad(format!(
            "{n} {what}; choose one with {}",
            flag.with_value(format!("0..{}", n - 1))
        ))),
    }
}

/// Every index when the axis is the load axis (a selection of it is then refused), else one.
fn along_or_pick(
    path: &Path,
    what: &str,
    flag: Param,
    requested: Option<usize>,
    n: usize,
    along: Option<LoadAxis>,
    axis: LoadAxis,
) -> Result<Vec<usize>> {
    if along == Some(axis) {
        if requested.is_some() {
            return Err(Error::InvalidArgument(format!(
                "{flag} cannot be combined with {}",
                Param::LoadAxis.with_value(axis.name())
            )));
        }
        return Ok((0..n).collect());
    }
    Ok(vec![pick(path, what, flag, requested, n)?])
}

impl Selection {
    /// The indices along the series' extra axes: each axis longer than 1 must be chosen; a
    /// chosen axis the series does not have is an error (length-1 axes accept index 0).
    fn extra_index(&self, path: &Path, info: &SeriesInfo) -> Result<BTreeMap<String, usize>> {
        let bad = |reason: String| Error::bad_input(Location::file(path), reason);
        let mut out = BTreeMap::new();
        for (axis, &n) in &info.axes.extra {
            let meaning = axis_meaning(axis);
            match self.extra.get(axis) {
                Some(&i) if i < n => {
                    out.insert(axis.clone(), i);
                }
                Some(&i) => {
                    return Err(bad(format!(
                        "{} requested; series {} has {n} planes along {axis} (0..{})",
                        Param::axis_value(axis, i),
                        info.index,
                        n - 1
                    )))
                }
                None if n > 1 => {
                    return Err(bad(format!(
                        "series {} has {n} planes along axis {axis}{meaning}; choose one with {}",
                        info.index,
                        Param::axis_value(axis, format!("0..{}", n - 1))
                    )))
                }
                None => {}
            }
        }
        if let Some((axis, &i)) = self
            .extra
            .iter()
            .find(|(a, &i)| !info.axes.extra.contains_key(*a) && i > 0)
        {
            return Err(bad(format!(
                "{} requested; series {} has no axis {axis} longer than 1",
                Param::axis_value(axis, i),
                info.index
            )));
        }
        Ok(out)
    }
}

/// The lateral pixel size of a series from its metadata (both x and y needed), with the
/// metadata element as source.
pub fn series_pixel_size(format: MicroscopyFormat, info: &SeriesInfo) -> Option<PixelSize> {
    let source = match format {
        MicroscopyFormat::Czi => PixelSizeSource::CziScaling,
        MicroscopyFormat::Nd2 => PixelSizeSource::Nd2Calibration,
        MicroscopyFormat::Lif => PixelSizeSource::LifDimensions,
        MicroscopyFormat::OmeZarr => PixelSizeSource::OmeZarrScale,
        // TIFF files go through `crate::tiff`, which knows the finer source.
        MicroscopyFormat::Tiff => return None,
    };
    Some(PixelSize {
        x_m: info.pixel_size.x_m?,
        y_m: info.pixel_size.y_m?,
        source,
    })
}

/// Whether a file is a TIFF (by content; an unreadable file counts as TIFF so that the TIFF
/// reader reports the problem as before).
pub fn is_tiff(path: &Path) -> bool {
    if path.is_dir() || (crate::remote::is_url(path) && super::zarr::is_store(path)) {
        return false;
    }
    let mut head = [0u8; 16];
    let n = crate::remote::open_input(path)
        .ok()
        .and_then(|(mut f, _)| std::io::Read::read(&mut f, &mut head).ok())
        .unwrap_or(0);
    !matches!(
        super::detect(&head[..n]),
        Some(MicroscopyFormat::Czi | MicroscopyFormat::Nd2 | MicroscopyFormat::Lif)
    )
}

/// The selected planes of any confocal file as [`Image`]s, in load order: the planes
/// [`Selection::planes`] names (a TIFF's along its time points, else its focal planes, when no
/// load axis is named: [`LoadDefault::AnyStack`]). `page` of each image is its IFD in a TIFF,
/// its position along the load axis in other files. Pixel size: the override, else the file's
/// metadata.
pub fn read_images(
    path: &Path,
    selection: &Selection,
    along: Option<LoadAxis>,
    pixel_size_m: Option<(f64, f64)>,
) -> Result<Vec<Image>> {
    if is_tiff(path) {
        return read_tiff_planes(path, selection, along, LoadDefault::AnyStack, pixel_size_m);
    }
    let mut file = MicroscopyFile::open(path)?;
    let planes = selection.planes(&file, along)?;
    let mut images = Vec::with_capacity(planes.len());
    for p in planes {
        let plane = file.read_plane(p.series, &p.index)?;
        let pixel_size = pixel_size_or(
            series_pixel_size(file.format, &file.series[p.series]),
            pixel_size_m,
        );
        images.push(Image::of_plane(&plane, pixel_size, path, p.load_index));
    }
    Ok(images)
}

/// The planes of a TIFF a selection names, as [`Image`]s whose `page` is the IFD.
fn read_tiff_planes(
    path: &Path,
    selection: &Selection,
    along: Option<LoadAxis>,
    default: LoadDefault,
    pixel_size_m: Option<(f64, f64)>,
) -> Result<Vec<Image>> {
    let mut reader = crate::tiff::TiffReader::open(path)?;
    let (info, planes) = selection.tiff_planes(reader.info(), along, default)?;
    let pixel_size = pixel_size_or(info.pixel_size, pixel_size_m);
    // The other file of a multi-file OME set last read from.
    let mut member: Option<crate::tiff::TiffReader> = None;
    let expect = (info.width, info.height, info.sample_type);
    planes
        .into_iter()
        .map(|(_, at)| {
            let plane = super::tiff::read_set_page(&mut reader, &mut member, &at, expect)?;
            Ok(Image::of_plane(&plane, pixel_size, &at.path, at.ifd))
        })
        .collect()
}

/// The one image a selection names (a TIFF of pages without axis metadata must have one page).
pub fn read_one_image(
    path: &Path,
    selection: &Selection,
    pixel_size_m: Option<(f64, f64)>,
) -> Result<Image> {
    if is_tiff(path) {
        let info = crate::tiff::TiffReader::open(path)?.info().clone();
        if info.axes.source == crate::tiff::AxesSource::Pages && selection.t.is_none() {
            return crate::tiff::read_image(
                path,
                selection
                    .channel
                    .as_ref()
                    .map(|c| c.resolve(path, &super::series_of_tiff(&info).channels))
                    .transpose()?,
                pixel_size_m,
            );
        }
        let mut images = read_tiff_planes(path, selection, None, LoadDefault::None, pixel_size_m)?;
        return Ok(images.remove(0));
    }
    let mut images = read_images(path, selection, None, pixel_size_m)?;
    Ok(images.remove(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pick_defaults_and_errors() {
        let p = Path::new("f.czi");
        crate::param::set_front_end(crate::param::FrontEnd::CommandLine);
        assert_eq!(pick(p, "channels", Param::Channel, None, 1).unwrap(), 0);
        assert_eq!(pick(p, "channels", Param::Channel, Some(2), 3).unwrap(), 2);
        let e = pick(p, "channels", Param::Channel, None, 3)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "f.czi: 3 channels; choose one with --channel 0..2");
        let e = pick(p, "channels", Param::Channel, Some(3), 3)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--channel 3") && e.contains("3 channels (0..2)"),
            "{e}"
        );
        let all = along_or_pick(
            p,
            "z planes",
            Param::Z,
            None,
            4,
            Some(LoadAxis::Z),
            LoadAxis::Z,
        );
        assert_eq!(all.unwrap(), vec![0, 1, 2, 3]);
        let both = along_or_pick(
            p,
            "z planes",
            Param::Z,
            Some(1),
            4,
            Some(LoadAxis::Z),
            LoadAxis::Z,
        );
        assert!(both.unwrap_err().to_string().contains("--load-axis z"));
    }
}
