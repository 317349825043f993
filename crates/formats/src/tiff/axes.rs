//! What the pages of a TIFF are: channels, focal planes and time points, read from the file's
//! own metadata, so that a multi-page TIFF is never taken for a flat list of images when it
//! says otherwise.
//!
//! Three sources, in this order of priority (`docs/formats.md`, TIFF axes):
//! 1. **OME-XML** in the first ImageDescription (OME-TIFF specification, "The OME-TIFF format",
//!    and the OME schema's `Pixels` and `TiffData` elements): `SizeC`, `SizeZ`, `SizeT` and
//!    `DimensionOrder` (`XYZCT`: z fastest, then c, then t) place the planes on the pages;
//!    `TiffData` elements (`IFD`, `FirstC`, `FirstZ`, `FirstT`, `PlaneCount`, a `UUID` naming the
//!    file) override that order; `Channel Name`, `PhysicalSizeZ` and `TimeIncrement` are read.
//! 2. **ImageJ** descriptions (`channels=`, `slices=`, `frames=`, `spacing=`, `finterval=`):
//!    hyperstack pages go channel fastest, then slice, then frame (ImageJ's `CZT` order).
//! 3. **Plain pages**: every full-resolution page one plane, along no named axis
//!    ([`AxesSource::Pages`]); the samples of a pixel (RGB, two interleaved or planar samples)
//!    are channels.
//!
//! Metadata whose plane count disagrees with the pages is not guessed at: the pages are read as
//! plain pages and a note says why.

use std::path::Path;

use serde::Serialize;

use super::metadata::{length_unit_factor, ImageJDescription};

/// The most planes an OME-XML description may state (the table of their pages is allocated).
const MAX_PLANES: usize = 1 << 22;

/// Where a TIFF's axes come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AxesSource {
    /// OME-XML (`SizeC/Z/T`, `DimensionOrder`, `TiffData`).
    Ome,
    /// An ImageJ description (`channels`, `slices`, `frames`).
    ImageJ,
    /// No axis metadata: the pages are planes in file order.
    Pages,
}

impl AxesSource {
    /// For `info` and messages.
    pub fn describe(self) -> &'static str {
        match self {
            AxesSource::Ome => "OME-XML",
            AxesSource::ImageJ => "ImageJ description",
            AxesSource::Pages => "pages in file order (no axis metadata)",
        }
    }
}

/// Channels, focal planes and time points of a TIFF, and the page holding each plane.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TiffAxes {
    /// Time points (plain pages: the pages of one channel).
    pub t: usize,
    /// Focal planes.
    pub z: usize,
    /// Channels (pages or samples of a pixel).
    pub c: usize,
    /// Samples per pixel: channel `c` is sample `c % samples` of its page.
    pub samples: usize,
    /// Where the axes come from.
    pub source: AxesSource,
    /// Channel names (OME `Channel Name`), one per channel, `None` where absent.
    pub channel_names: Vec<Option<String>>,
    /// Distance between focal planes, m (OME `PhysicalSizeZ`, ImageJ `spacing`).
    pub z_step_m: Option<f64>,
    /// Time between time points, s (OME `TimeIncrement`, ImageJ `finterval`).
    pub time_increment_s: Option<f64>,
    /// Where every (t, z, page channel) is, t slowest.
    #[serde(skip)]
    table: Vec<Place>,
    /// Files of an OME set that hold the planes this file does not, as its `UUID FileName`s
    /// name them (relative to this file's folder).
    pub other_files: Vec<String>,
}

/// One image of a multi-image OME-TIFF (an OME `Image` element: a stage position, a scene, a
/// separate acquisition in one file), read as a series of its own.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OmeImage {
    /// OME `Image Name`, `None` where absent.
    pub name: Option<String>,
    /// `SizeX`, pixels.
    pub width: usize,
    /// `SizeY`, pixels.
    pub height: usize,
    /// `PhysicalSizeX` and `PhysicalSizeY` (Y defaults to X), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// Its planes and the page of each.
    pub axes: TiffAxes,
}

/// Where a plane of a TIFF's axes is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// Page (IFD) `0` of this file.
    Here(usize),
    /// IFD `ifd` of [`TiffAxes::other_files`]`[file]` (a multi-file OME set).
    There {
        /// Index into `other_files`.
        file: usize,
        /// The IFD in that file.
        ifd: usize,
    },
}

impl TiffAxes {
    /// Pages in file order, the samples of a pixel as channels.
    pub fn plain(pages: &[usize], samples: usize) -> Self {
        TiffAxes {
            t: pages.len(),
            z: 1,
            c: samples,
            samples,
            source: AxesSource::Pages,
            channel_names: vec![None; samples],
            z_step_m: None,
            time_increment_s: None,
            table: pages.iter().map(|&p| Place::Here(p)).collect(),
            other_files: Vec::new(),
        }
    }

    /// Channels stored as pages (not as samples of a pixel).
    fn page_channels(&self) -> usize {
        self.c / self.samples
    }

    /// The IFD and the sample of plane (t, z, c); `None` outside the axes or for a plane stored
    /// in another file of an OME set.
    pub fn page_of(&self, t: usize, z: usize, c: usize) -> Option<(usize, usize)> {
        match self.place_of(t, z, c)? {
            (Place::Here(ifd), sample) => Some((ifd, sample)),
            (Place::There { .. }, _) => None,
        }
    }

    /// Where plane (t, z, c) is stored, and its sample; `None` outside the axes.
    pub fn place_of(&self, t: usize, z: usize, c: usize) -> Option<(Place, usize)> {
        if t >= self.t || z >= self.z || c >= self.c {
            return None;
        }
        let pc = self.page_channels();
        let place = *self.table.get((t * self.z + z) * pc + c / self.samples)?;
        Some((place, c % self.samples))
    }

    /// The IFDs of channel `c`, time points slowest, then focal planes (planes stored in other
    /// files left out).
    pub fn pages_of_channel(&self, c: usize) -> Vec<usize> {
        (0..self.t)
            .flat_map(|t| (0..self.z).map(move |z| (t, z)))
            .filter_map(|(t, z)| self.page_of(t, z, c).map(|(ifd, _)| ifd))
            .collect()
    }

    /// A z stack: focal planes with a known step and no time points. Its planes are never
    /// taken for a load series unless the z axis is named the load axis.
    pub fn is_z_stack(&self) -> bool {
        self.z > 1 && self.t == 1 && self.z_step_m.is_some()
    }

    /// `T 4 × Z 2 × C 2 (OME-XML)` for notes.
    pub fn describe(&self) -> String {
        format!(
            "T {} × Z {} × C {} ({})",
            self.t,
            self.z,
            self.c,
            self.source.describe()
        )
    }

    /// The axes the metadata state, checked against the pages (`pages`: IFD indices of the
    /// full-resolution pages; `samples`: samples per pixel); plain pages with a note when the
    /// metadata disagree with the file. The axes are those of the first image; an OME-XML
    /// describing several images gives every image too (image 0 first; empty for one image).
    pub fn from_metadata(
        path: &Path,
        pages: &[usize],
        samples: usize,
        description: Option<&str>,
        imagej: Option<&ImageJDescription>,
        notes: &mut Vec<String>,
    ) -> (Self, Vec<OmeImage>) {
        let samples = samples.max(1);
        if let Some(xml) = description.filter(|d| d.contains("<OME")) {
            match ome_images(path, xml, pages, samples, notes) {
                Ok(mut images) if images.len() == 1 => return (images.remove(0).axes, images),
                Ok(images) => return (images[0].axes.clone(), images),
                Err(why) => notes.push(format!(
                    "OME-XML axes ignored ({why}); the pages are read in file order"
                )),
            }
        }
        if let Some(meta) = imagej {
            match imagej_axes(meta, pages, samples) {
                Ok(Some(axes)) => return (axes, Vec::new()),
                Ok(None) => {}
                Err(why) => notes.push(format!(
                    "ImageJ hyperstack axes ignored ({why}); the pages are read in file order"
                )),
            }
        }
        (TiffAxes::plain(pages, samples), Vec::new())
    }
}

/// ImageJ hyperstack axes (`None` when the description names no axis longer than 1).
fn imagej_axes(
    meta: &ImageJDescription,
    pages: &[usize],
    samples: usize,
) -> Result<Option<TiffAxes>, String> {
    let (c, z, t) = (
        meta.channels.unwrap_or(1),
        meta.slices.unwrap_or(1),
        meta.frames.unwrap_or(1),
    );
    if c == 0 || z == 0 || t == 0 {
        return Err("a count of 0".into());
    }
    if c * z * t == 1 {
        return Ok(None);
    }
    // RGB ImageJ files keep their colours as samples; `channels=` then counts them.
    let page_channels = if samples > 1 && c == samples { 1 } else { c };
    let planes = page_channels
        .checked_mul(z)
        .and_then(|n| n.checked_mul(t))
        .ok_or("counts overflow")?;
    if planes != pages.len() {
        return Err(format!(
            "channels {c} × slices {z} × frames {t} = {planes} pages stated, the file has {}",
            pages.len()
        ));
    }
    let c_total = page_channels * samples;
    let z_step_m = match (meta.spacing, meta.unit_m) {
        (Some(s), Some(u)) if z > 1 && s.is_finite() && s > 0.0 => Some(s * u),
        _ => None,
    };
    Ok(Some(TiffAxes {
        t,
        z,
        c: c_total,
        samples,
        source: AxesSource::ImageJ,
        channel_names: vec![None; c_total],
        z_step_m,
        time_increment_s: meta
            .finterval
            .filter(|f| t > 1 && f.is_finite() && *f > 0.0),
        // ImageJ's order: channel fastest, then slice, then frame: the pages as they come.
        table: pages.iter().map(|&p| Place::Here(p)).collect(),
        other_files: Vec::new(),
    }))
}

/// A positive count attribute (absent: 1).
fn count(node: roxmltree::Node, name: &str) -> Result<usize, String> {
    match node.attribute(name) {
        None => Ok(1),
        Some(v) => match v.trim().parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(format!("{name}=\"{v}\" is not a positive count")),
        },
    }
}

/// A non-negative index attribute (absent: `default`).
fn index(node: roxmltree::Node, name: &str, default: usize) -> Result<usize, String> {
    match node.attribute(name) {
        None => Ok(default),
        Some(v) => v
            .trim()
            .parse()
            .map_err(|_| format!("TiffData {name}=\"{v}\" is not an index")),
    }
}

/// A positive length in metres (OME's default unit µm) or time in seconds (default s).
fn physical(node: roxmltree::Node, name: &str, time: bool) -> Option<f64> {
    let v: f64 = node.attribute(name)?.trim().parse().ok()?;
    let unit = node.attribute(format!("{name}Unit").as_str());
    let factor = if time {
        match unit.unwrap_or("s") {
            "s" => 1.0,
            "ms" => 1e-3,
            "µs" | "us" => 1e-6,
            "min" => 60.0,
            "h" => 3600.0,
            _ => return None,
        }
    } else {
        length_unit_factor(unit.unwrap_or("µm"))?
    };
    let x = v * factor;
    (x.is_finite() && x > 0.0).then_some(x)
}

fn is(n: &roxmltree::Node, tag: &str) -> bool {
    n.is_element() && n.tag_name().name() == tag
}

/// Every image the OME-XML describes (at least one; an error when the first cannot be read).
/// An image that cannot be read is named in a note and left out with the images after it, so
/// that an image's index is always its place in the file. Images without `TiffData` fill the
/// pages in order, each after the planes of the images before it.
fn ome_images(
    path: &Path,
    xml: &str,
    pages: &[usize],
    samples: usize,
    notes: &mut Vec<String>,
) -> Result<Vec<OmeImage>, String> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| format!("unreadable XML: {e}"))?;
    let mut elements: Vec<(Option<roxmltree::Node>, roxmltree::Node)> = doc
        .descendants()
        .filter(|n| is(n, "Image"))
        .filter_map(|image| {
            let pixels = image.children().find(|n| is(n, "Pixels"))?;
            Some((Some(image), pixels))
        })
        .collect();
    if elements.is_empty() {
        // A Pixels element outside any Image: read as the one image.
        let pixels = doc
            .descendants()
            .find(|n| is(n, "Pixels"))
            .ok_or("no Pixels element")?;
        elements.push((None, pixels));
    }
    let mut images = Vec::new();
    let mut start = 0usize;
    // The planes all images may state together (each image's table is allocated).
    let mut budget = (pages.len().max(1) * 4096).min(MAX_PLANES);
    for (k, (image, pixels)) in elements.into_iter().enumerate() {
        let name = image
            .and_then(|i| i.attribute("Name"))
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(str::to_string);
        let read = ome_axes(path, pixels, pages, samples, start, budget).and_then(|axes| {
            let width = count(pixels, "SizeX")?;
            let height = count(pixels, "SizeY")?;
            Ok((axes, width, height))
        });
        let (axes, width, height) = match read {
            Ok(r) => r,
            Err(why) if k == 0 => return Err(why),
            Err(why) => {
                notes.push(format!(
                    "OME-XML image {k}{} and the images after it are not read ({why})",
                    name.as_deref().map_or(String::new(), |n| format!(" '{n}'"))
                ));
                break;
            }
        };
        start = start.saturating_add(axes.table.len());
        budget = budget.saturating_sub(axes.table.len());
        let pixel_size_m = physical(pixels, "PhysicalSizeX", false).map(|x| {
            let y = physical(pixels, "PhysicalSizeY", false).unwrap_or(x);
            (x, y)
        });
        images.push(OmeImage {
            name,
            width,
            height,
            pixel_size_m,
            axes,
        });
    }
    Ok(images)
}

/// The axes of one OME `Pixels` element; without `TiffData` its planes fill the pages from
/// `start`.
fn ome_axes(
    path: &Path,
    pixels: roxmltree::Node,
    pages: &[usize],
    samples: usize,
    start: usize,
    budget: usize,
) -> Result<TiffAxes, String> {
    let (c, z, t) = (
        count(pixels, "SizeC")?,
        count(pixels, "SizeZ")?,
        count(pixels, "SizeT")?,
    );
    let order = pixels.attribute("DimensionOrder").unwrap_or("XYZCT");
    let order: Vec<char> = order.trim().chars().collect();
    if order.len() != 5 || order[..2] != ['X', 'Y'] || {
        let mut rest = order[2..].to_vec();
        rest.sort_unstable();
        rest != ['C', 'T', 'Z']
    } {
        return Err(format!(
            "DimensionOrder \"{}\" is not XY followed by C, Z and T",
            order.iter().collect::<String>()
        ));
    }
    // OME counts the samples of an RGB pixel as channels; pages hold whole pixels.
    let page_channels = if samples > 1 {
        if c % samples != 0 {
            return Err(format!("SizeC {c} with {samples} samples per pixel"));
        }
        c / samples
    } else {
        c
    };
    let planes = page_channels
        .checked_mul(z)
        .and_then(|n| n.checked_mul(t))
        .ok_or("counts overflow")?;
    // Checked before the plane table is allocated: a multi-file set may state more planes
    // than this file's pages, but not without bound (`budget`: what the images before this one
    // left of the file's bound).
    if planes > budget {
        return Err(format!("{planes} planes stated"));
    }
    // Linear plane index in DimensionOrder → (t, z, c), and back.
    let sizes = |axis: char| match axis {
        'C' => page_channels,
        'Z' => z,
        _ => t,
    };
    let position = |mut linear: usize| -> (usize, usize, usize) {
        let (mut pt, mut pz, mut pc) = (0, 0, 0);
        for &axis in &order[2..] {
            let n = sizes(axis);
            let i = linear % n;
            linear /= n;
            match axis {
                'C' => pc = i,
                'Z' => pz = i,
                _ => pt = i,
            }
        }
        (pt, pz, pc)
    };
    let linear_of = |(pt, pz, pc): (usize, usize, usize)| -> usize {
        let mut linear = 0;
        for &axis in order[2..].iter().rev() {
            let i = match axis {
                'C' => pc,
                'Z' => pz,
                _ => pt,
            };
            linear = linear * sizes(axis) + i;
        }
        linear
    };
    let own_name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let mut table: Vec<Place> = vec![Place::Here(0); planes];
    let mut assigned = vec![false; planes];
    let mut other_files: Vec<String> = Vec::new();
    let blocks: Vec<roxmltree::Node> = pixels.children().filter(|n| is(n, "TiffData")).collect();
    if blocks.is_empty() {
        // No TiffData: the planes fill the pages in DimensionOrder.
        for (linear, slot) in table.iter_mut().enumerate() {
            *slot = Place::Here(start.checked_add(linear).ok_or("an IFD overflows")?);
        }
        assigned.iter_mut().for_each(|a| *a = true);
    }
    for block in &blocks {
        let bare = ["IFD", "FirstC", "FirstZ", "FirstT", "PlaneCount"]
            .iter()
            .all(|a| block.attribute(*a).is_none());
        let ifd = index(*block, "IFD", 0)?;
        let first = (
            index(*block, "FirstT", 0)?,
            index(*block, "FirstZ", 0)?,
            index(*block, "FirstC", 0)?,
        );
        if first.0 >= t || first.1 >= z || first.2 >= page_channels {
            return Err("a TiffData block starts outside the axes".into());
        }
        let n = match block.attribute("PlaneCount") {
            Some(_) => index(*block, "PlaneCount", 1)?,
            None if bare => planes,
            None if block.attribute("IFD").is_some() => 1,
            None => planes,
        };
        let file = block
            .children()
            .find(|u| is(u, "UUID"))
            .and_then(|u| u.attribute("FileName"))
            .map(str::to_string);
        let elsewhere = match (&file, &own_name) {
            (Some(f), Some(own)) => {
                Path::new(f).file_name().map(|n| n.to_string_lossy()) != Some(own.as_str().into())
            }
            _ => false,
        };
        let foreign = match (elsewhere, file) {
            (true, Some(f)) => Some(match other_files.iter().position(|o| *o == f) {
                Some(i) => i,
                None => {
                    other_files.push(f);
                    other_files.len() - 1
                }
            }),
            _ => None,
        };
        let start = linear_of(first);
        for k in 0..n.min(planes.saturating_sub(start)) {
            let slot = start + k;
            assigned[slot] = true;
            let ifd = ifd.checked_add(k).ok_or("an IFD overflows")?;
            table[slot] = match foreign {
                Some(file) => Place::There { file, ifd },
                None => Place::Here(ifd),
            };
        }
    }
    if let Some(missing) = assigned.iter().position(|a| !a) {
        let (pt, pz, pc) = position(missing);
        return Err(format!(
            "no TiffData places the plane t {pt}, z {pz}, c {pc}"
        ));
    }
    // Every IFD named must be a full-resolution page of this file (`pages` is in IFD order).
    for place in &table {
        let Place::Here(ifd) = place else { continue };
        if pages.binary_search(ifd).is_err() {
            return Err(format!(
                "SizeC {c} × SizeZ {z} × SizeT {t} planes need page {ifd}; the file has {} pages",
                pages.len()
            ));
        }
    }
    // Reorder from DimensionOrder to (t, z, c) with t slowest.
    let mut ordered = vec![Place::Here(0); planes];
    for (linear, place) in table.into_iter().enumerate() {
        let (pt, pz, pc) = position(linear);
        ordered[(pt * z + pz) * page_channels + pc] = place;
    }
    let mut channel_names: Vec<Option<String>> = pixels
        .children()
        .filter(|n| is(n, "Channel"))
        .map(|n| {
            n.attribute("Name")
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(str::to_string)
        })
        .collect();
    // One Channel element per page channel holding several samples: name each sample after it.
    if samples > 1 && channel_names.len() == page_channels {
        channel_names = channel_names
            .into_iter()
            .flat_map(|n| std::iter::repeat_n(n, samples))
            .collect();
    }
    channel_names.resize(c, None);
    Ok(TiffAxes {
        t,
        z,
        c,
        samples,
        source: AxesSource::Ome,
        channel_names,
        z_step_m: physical(pixels, "PhysicalSizeZ", false).filter(|_| z > 1),
        time_increment_s: physical(pixels, "TimeIncrement", true).filter(|_| t > 1),
        table: ordered,
        other_files,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tiff::metadata::parse_imagej;

    fn ome(order: &str, c: usize, z: usize, t: usize, inner: &str) -> String {
        format!(
            r#"<?xml version="1.0"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06"><Image ID="Image:0"><Pixels ID="Pixels:0" DimensionOrder="{order}" Type="uint16" SizeX="4" SizeY="3" SizeC="{c}" SizeZ="{z}" SizeT="{t}" PhysicalSizeZ="500" PhysicalSizeZUnit="nm" TimeIncrement="2">{inner}</Pixels></Image></OME>"#
        )
    }

    fn axes(desc: &str, pages: usize, samples: usize) -> (TiffAxes, Vec<String>) {
        let pages: Vec<usize> = (0..pages).collect();
        let mut notes = Vec::new();
        let imagej = parse_imagej(desc);
        let (a, _) = TiffAxes::from_metadata(
            Path::new("/x/a.ome.tif"),
            &pages,
            samples,
            Some(desc),
            imagej.as_ref(),
            &mut notes,
        );
        (a, notes)
    }

    #[test]
    fn ome_dimension_orders_place_planes() {
        // XYZCT: z fastest, then c, then t.
        let (a, notes) = axes(&ome("XYZCT", 2, 3, 4, "<TiffData/>"), 24, 1);
        assert!(notes.is_empty(), "{notes:?}");
        assert_eq!((a.t, a.z, a.c, a.source), (4, 3, 2, AxesSource::Ome));
        assert_eq!(a.page_of(0, 1, 0), Some((1, 0)));
        assert_eq!(a.page_of(0, 0, 1), Some((3, 0)));
        assert_eq!(a.page_of(1, 0, 0), Some((6, 0)));
        assert_eq!(a.page_of(3, 2, 1), Some((23, 0)));
        assert!((a.z_step_m.unwrap() - 500e-9).abs() < 1e-20);
        assert_eq!(a.time_increment_s, Some(2.0));
        // XYCZT (tifffile's TCYX): c fastest.
        let (a, _) = axes(&ome("XYCZT", 2, 1, 4, ""), 8, 1);
        assert_eq!(a.pages_of_channel(1), vec![1, 3, 5, 7]);
        assert_eq!(a.pages_of_channel(0), vec![0, 2, 4, 6]);
        // XYTZC: t fastest, c slowest.
        let (a, _) = axes(&ome("XYTZC", 2, 2, 3, ""), 12, 1);
        assert_eq!(a.page_of(2, 0, 0), Some((2, 0)));
        assert_eq!(a.page_of(0, 1, 0), Some((3, 0)));
        assert_eq!(a.page_of(0, 0, 1), Some((6, 0)));
    }

    #[test]
    fn ome_tiffdata_blocks_and_other_files() {
        let inner = r#"<TiffData IFD="0" PlaneCount="2"><UUID FileName="a.ome.tif">urn:1</UUID></TiffData><TiffData FirstT="2" IFD="0" PlaneCount="2"><UUID FileName="b.ome.tif">urn:2</UUID></TiffData>"#;
        let (a, notes) = axes(&ome("XYCZT", 1, 1, 4, inner), 2, 1);
        assert!(notes.is_empty(), "{notes:?}");
        assert_eq!(a.page_of(1, 0, 0), Some((1, 0)));
        assert_eq!(a.page_of(2, 0, 0), None);
        assert_eq!(
            a.place_of(3, 0, 0),
            Some((Place::There { file: 0, ifd: 1 }, 0))
        );
        assert_eq!(a.other_files, vec!["b.ome.tif".to_string()]);
        // A plane no block places: the XML is not trusted.
        let inner = r#"<TiffData IFD="0" PlaneCount="1"/>"#;
        let (a, notes) = axes(&ome("XYCZT", 1, 1, 2, inner), 2, 1);
        assert_eq!(a.source, AxesSource::Pages);
        assert!(notes[0].contains("t 1, z 0, c 0"), "{notes:?}");
    }

    #[test]
    fn ome_disagreeing_with_the_pages_falls_back_with_a_note() {
        let (a, notes) = axes(&ome("XYCZT", 2, 1, 4, ""), 6, 1);
        assert_eq!((a.source, a.t, a.c), (AxesSource::Pages, 6, 1));
        assert!(
            notes[0].contains("page 6") || notes[0].contains("6 pages"),
            "{notes:?}"
        );
        let (_, notes) = axes(&ome("XYQZT", 1, 1, 1, ""), 1, 1);
        assert!(notes[0].contains("DimensionOrder"), "{notes:?}");
        // Absurd counts are refused before anything is allocated.
        let (a, notes) = axes(&ome("XYCZT", 4_000_000_000, 4_000_000_000, 9, ""), 1, 1);
        assert_eq!(a.source, AxesSource::Pages);
        assert!(
            notes[0].contains("overflow") || notes[0].contains("planes stated"),
            "{notes:?}"
        );
    }

    #[test]
    fn every_ome_image_is_read_each_on_its_own_pages() {
        let image = |k: usize, t: usize, extra: &str| {
            format!(
                r#"<Image ID="Image:{k}" Name="p{k}"><Pixels ID="Pixels:{k}" DimensionOrder="XYZCT" Type="uint16" SizeX="4" SizeY="3" SizeC="1" SizeZ="1" SizeT="{t}" {extra}></Pixels></Image>"#
            )
        };
        // No TiffData: each image's planes follow the planes of the images before it.
        let xml = format!(
            "<OME>{}{}{}</OME>",
            image(0, 2, ""),
            image(1, 3, r#"PhysicalSizeX="100" PhysicalSizeXUnit="nm""#),
            image(2, 1, "")
        );
        let pages: Vec<usize> = (0..6).collect();
        let mut notes = Vec::new();
        let (first, images) = TiffAxes::from_metadata(
            Path::new("a.ome.tif"),
            &pages,
            1,
            Some(&xml),
            None,
            &mut notes,
        );
        assert!(notes.is_empty(), "{notes:?}");
        assert_eq!(images.len(), 3);
        assert_eq!(first, images[0].axes);
        assert_eq!(images[1].axes.pages_of_channel(0), vec![2, 3, 4]);
        assert_eq!(images[2].axes.pages_of_channel(0), vec![5]);
        assert_eq!(images[1].name.as_deref(), Some("p1"));
        assert_eq!((images[1].width, images[1].height), (4, 3));
        let (x, y) = images[1].pixel_size_m.unwrap();
        assert!((x - 100e-9).abs() < 1e-20 && (y - 100e-9).abs() < 1e-20);
        assert_eq!(images[0].pixel_size_m, None);
        // An image the pages cannot hold: it and the images after it are left out, with a
        // note; the images before it keep their indices.
        let xml = format!(
            "<OME>{}{}{}</OME>",
            image(0, 2, ""),
            image(1, 9, ""),
            image(2, 1, "")
        );
        let (_, images) = TiffAxes::from_metadata(
            Path::new("a.ome.tif"),
            &pages,
            1,
            Some(&xml),
            None,
            &mut notes,
        );
        assert_eq!(images, Vec::new(), "one image left: no list");
        assert!(notes[0].contains("image 1 'p1'"), "{notes:?}");
        // The planes of all images together are bounded (each image's table is allocated):
        // a one-page file may state 4096 planes kept in other files, not 4096 per image.
        let elsewhere = |k: usize| {
            image(
                k,
                3000,
                "",
            )
            .replace(
                "></Pixels>",
                r#"><TiffData IFD="0" PlaneCount="3000"><UUID FileName="b.ome.tif">urn:2</UUID></TiffData></Pixels>"#,
            )
        };
        let xml = format!("<OME>{}{}</OME>", elsewhere(0), elsewhere(1));
        let mut notes = Vec::new();
        let (first, images) = TiffAxes::from_metadata(
            Path::new("a.ome.tif"),
            &[0],
            1,
            Some(&xml),
            None,
            &mut notes,
        );
        assert_eq!((first.t, images.len()), (3000, 0));
        assert!(notes[0].contains("3000 planes stated"), "{notes:?}");
    }

    #[test]
    fn imagej_hyperstacks_go_channel_then_slice_then_frame() {
        let d = "ImageJ=1.54f\nimages=16\nchannels=2\nslices=2\nframes=4\nhyperstack=true\nunit=micron\nspacing=0.5\nfinterval=3\n";
        let (a, notes) = axes(d, 16, 1);
        assert!(notes.is_empty());
        assert_eq!((a.t, a.z, a.c, a.source), (4, 2, 2, AxesSource::ImageJ));
        assert_eq!(a.page_of(0, 1, 0), Some((2, 0)));
        assert_eq!(a.page_of(1, 0, 1), Some((5, 0)));
        assert!((a.z_step_m.unwrap() - 0.5e-6).abs() < 1e-20);
        assert_eq!(a.time_increment_s, Some(3.0));
        assert!(!a.is_z_stack());
        // A z stack: slices with a spacing and no frames.
        let (a, _) = axes(
            "ImageJ=1.5\nimages=4\nslices=4\nunit=um\nspacing=0.5\n",
            4,
            1,
        );
        assert!(a.is_z_stack());
        // contactscope's own series: slices without a spacing are not a z stack.
        let (a, _) = axes("ImageJ=1.11a\nimages=3\nslices=3\nloop=false\n", 3, 1);
        assert_eq!((a.z, a.source), (3, AxesSource::ImageJ));
        assert!(!a.is_z_stack());
        // Counts that disagree with the pages.
        let (a, notes) = axes("ImageJ=1.5\nimages=8\nslices=4\nframes=3\n", 8, 1);
        assert_eq!(a.source, AxesSource::Pages);
        assert!(notes[0].contains("12 pages stated"), "{notes:?}");
        // Plain pages; RGB samples as channels.
        let (a, _) = axes("ImageJ=1.5\nimages=1\n", 1, 3);
        assert_eq!((a.t, a.c, a.samples), (1, 3, 3));
        assert_eq!(a.page_of(0, 0, 2), Some((0, 2)));
    }
}
