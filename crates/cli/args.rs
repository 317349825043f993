//! Argument groups shared by several commands, defined once: the pixel-size override, the output
//! folder, `--quiet`, the height-map options and the rough sphere (`--topography`, `--radius`,
//! `--modulus`); and the conversions of their text into library types (SI units).

use std::marker::PhantomData;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::ValueEnum;

use contactscope::surface::fill::FillInvalid;
use contactscope::surface::Detrend;
use contactscope_formats::microscopy::select::{ChannelChoice, LoadAxis, Selection};
use contactscope_formats::ranges::Quantity;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::heights::TopographySource;

/// `--pixel-size`: overrides the files' calibration.
#[derive(clap::Args, Clone, Debug)]
pub struct PixelSizeArg {
    /// Pixel size overriding the files' metadata: 200nm, 0.2um, or 200x210nm (x × y);
    /// `analyze` also takes its uncertainty, 200nm±1%.
    #[arg(long)]
    pub pixel_size: Option<String>,
}

impl PixelSizeArg {
    /// (x, y) in metres, if given.
    pub fn metres(&self) -> Result<Option<(f64, f64)>> {
        optional_pixel_size(&self.pixel_size, "--pixel-size")
    }

    /// (x, y) in metres, if given, and the relative uncertainty from `--pixel-size 200nm±1%`
    /// or from `uncertainty` (`--pixel-size-uncertainty 1%`, which also serves the files' pixel
    /// sizes); 0 without either, an error with both.
    pub fn metres_and_uncertainty(
        &self,
        uncertainty: &Option<String>,
    ) -> Result<(Option<(f64, f64)>, f64)> {
        let (size, inline) = match self.pixel_size.as_deref() {
            Some(text) => {
                let (size, u) = units::parse_pixel_size_uncertain(text).context("--pixel-size")?;
                (Some(size), u)
            }
            None => (None, None),
        };
        let flag = uncertainty
            .as_deref()
            .map(|t| units::parse_relative_uncertainty(t, size.map(|(x, y): (f64, f64)| x.max(y))))
            .transpose()
            .context("--pixel-size-uncertainty")?;
        let (u, from) = match (inline, flag) {
            (Some(_), Some(_)) => bail!(
                "the pixel size's uncertainty is given twice: in --pixel-size and in \
                 --pixel-size-uncertainty; give it once"
            ),
            (Some(u), None) => (u, "--pixel-size"),
            (None, Some(u)) => (u, "--pixel-size-uncertainty"),
            (None, None) => (0.0, ""),
        };
        if u > contactscope_jobs::analyze::MAX_PIXEL_SIZE_UNCERTAINTY {
            bail!(
                "{from}: the pixel size's uncertainty {} % must lie between 0 and {} %",
                contactscope_formats::ranges::short(u * 100.0),
                contactscope_formats::ranges::short(
                    contactscope_jobs::analyze::MAX_PIXEL_SIZE_UNCERTAINTY * 100.0
                )
            );
        }
        Ok((size, u))
    }
}

/// Normal forces as every command takes them (`--forces`), N: a list `4,10,40mN` or a
/// log-spaced range `4mN..400mN:12` (`contactscope_formats::units`), with the text as given
/// (which `batch` hands on to its samplesheet and its command lines).
#[derive(Clone, Debug, PartialEq)]
pub struct Forces(pub Vec<f64>, pub String);

/// Forces of micrographs: a 0 in a list is a reference frame (analysed, left out of fits).
pub fn frame_forces(text: &str) -> std::result::Result<Forces, contactscope_formats::Error> {
    units::parse_forces(text).map(|f| Forces(f, text.trim().to_string()))
}

/// Forces of simulated loads and predictions: every value positive.
pub fn load_forces(text: &str) -> std::result::Result<Forces, contactscope_formats::Error> {
    units::parse_loads(text).map(|f| Forces(f, text.trim().to_string()))
}

/// The default output folder of one command.
pub trait DefaultOut: Clone + Send + Sync + 'static {
    /// Folder used without `--out`.
    const PATH: &'static str;
}

/// `--out`: the output folder, written all or nothing (`contactscope_jobs::staging`).
#[derive(clap::Args, Clone, Debug)]
pub struct OutputFolder<D: DefaultOut> {
    /// Output folder.
    #[arg(long, default_value = D::PATH)]
    pub out: PathBuf,
    #[arg(skip)]
    default: PhantomData<D>,
}

/// Declares the marker type of a command's default output folder.
macro_rules! default_out {
    ($name:ident, $path:literal) => {
        #[derive(Clone, Debug)]
        pub struct $name;
        impl $crate::args::DefaultOut for $name {
            const PATH: &'static str = $path;
        }
    };
}
pub(crate) use default_out;

/// The contact solver's stopping rule (`simulate`, `fit-hardening`).
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct SolverArgs {
    /// Relative CG tolerance.
    #[arg(long, default_value_t = 1e-8)]
    pub tolerance: f64,
    /// Most CG iterations per load.
    #[arg(long, default_value_t = 5000)]
    pub max_iterations: usize,
    /// Where the contact solver runs: `cpu`, `cuda` (an NVIDIA GPU; an error when none is
    /// usable) or `auto` (a GPU when one is usable, else the CPU). The GPU needs a build with
    /// `--features cuda`; summary.json names the device that ran.
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    pub device: DeviceArg,
}

/// `--device`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum DeviceArg {
    /// The CPU.
    Cpu,
    /// The first NVIDIA GPU.
    Cuda,
    /// A GPU when one is usable, else the CPU.
    Auto,
}

impl From<DeviceArg> for contactscope_jobs::simulate::DeviceChoice {
    fn from(d: DeviceArg) -> Self {
        use contactscope_jobs::simulate::DeviceChoice;
        match d {
            DeviceArg::Cpu => DeviceChoice::Cpu,
            DeviceArg::Cuda => DeviceChoice::Cuda,
            DeviceArg::Auto => DeviceChoice::Auto,
        }
    }
}

/// `--quiet`, `-q`.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct Quiet {
    /// No progress output (bar or stage messages).
    #[arg(long, short)]
    pub quiet: bool,
}

/// Detrending of a height map.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum DetrendArg {
    /// Keep the heights as read.
    None,
    /// Subtract the mean height.
    Mean,
    /// Subtract the least-squares plane.
    Plane,
}

impl DetrendArg {
    /// The library's detrending.
    pub fn detrend(self) -> Detrend {
        match self {
            DetrendArg::None => Detrend::None,
            DetrendArg::Mean => Detrend::Mean,
            DetrendArg::Plane => Detrend::Plane,
        }
    }
}

/// How to read and level a height map.
#[derive(clap::Args, Clone, Debug)]
pub struct HeightMapOptions {
    /// Pixel size (needed for .npy and text; overrides metadata): 32nm or 32x40nm.
    #[arg(long)]
    pub pixel_size: Option<String>,
    /// Height unit of files that do not state one (.npy, text, TIFF), e.g. 1nm; default metres.
    #[arg(long)]
    pub height_unit: Option<String>,
    /// Detrending before anything else.
    #[arg(long, value_enum, default_value = "plane")]
    pub detrend: DetrendArg,
}

impl HeightMapOptions {
    /// The height map at `path`, read with these options.
    pub fn source(&self, path: PathBuf) -> Result<TopographySource> {
        Ok(TopographySource {
            path,
            pixel_size_m: optional_pixel_size(&self.pixel_size, "--pixel-size")?,
            height_unit_m: optional_quantity(&self.height_unit, "--height-unit", Quantity::Height)?,
            detrend: self.detrend.detrend(),
            channel: None,
            fill_invalid: None,
            measurement: None,
        })
    }
}

/// `--fill-invalid`: how to fill a vendor height map's invalid points.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FillInvalidArg {
    /// The mean of the valid heights.
    Mean,
    /// The height of the nearest valid point (city-block distance).
    Nearest,
    /// The harmonic (Laplace) interpolation of the valid heights.
    Harmonic,
}

/// `--topography FILE` with its reading options.
#[derive(clap::Args, Clone, Debug)]
pub struct TopographyInput {
    /// Height map: .npy, float TIFF, .gsf, text matrix (.txt/.csv/.dat), WSxM .top, Nanoscope
    /// .di, Nanonis .sxm, or a vendor AFM/profilometer file recognised by content (docs/formats.md).
    #[arg(long = "topography")]
    pub path: PathBuf,
    #[command(flatten)]
    pub options: HeightMapOptions,
    /// Channel of a multi-channel vendor height map, by name (e.g. Height) or by its place in
    /// the list `topography` prints (0, 1, …); default: the file's height channel.
    #[arg(long)]
    pub channel: Option<String>,
    /// Fill a vendor map's invalid (unmeasured, masked) points instead of refusing the map:
    /// mean (of the valid heights), nearest (valid point, city-block distance) or harmonic
    /// (Laplace interpolation, as SurfaceTopography's `harmonic`).
    #[arg(long, value_enum)]
    pub fill_invalid: Option<FillInvalidArg>,
    /// The measurement of a contact.engineering surface container (ZIP or folder), by index
    /// (0, 1, …) or name (`name` or `surface/name`); default: its only one.
    #[arg(long)]
    pub measurement: Option<String>,
}

impl TopographyInput {
    /// The height map to read, with channel and filling.
    pub fn source(&self) -> Result<TopographySource> {
        Ok(TopographySource {
            channel: self.channel.clone(),
            fill_invalid: self.fill_invalid.map(|f| match f {
                FillInvalidArg::Mean => FillInvalid::Mean,
                FillInvalidArg::Nearest => FillInvalid::Nearest,
                FillInvalidArg::Harmonic => FillInvalid::Harmonic,
            }),
            measurement: self.measurement.clone(),
            ..self.options.source(self.path.clone())?
        })
    }
}

/// The rough sphere and its material, as `simulate` and `fit-hardening` take them.
#[derive(clap::Args, Clone, Debug)]
pub struct BodyArgs {
    #[command(flatten)]
    pub input: TopographyInput,
    /// Sphere radius added to a flattened map (and the GT sphere), e.g. 290um; centred at
    /// ((N−1)/2, (N−1)/2) pixels.
    #[arg(long)]
    pub radius: Option<String>,
    /// Contact modulus E*, e.g. 3.7GPa.
    #[arg(long)]
    pub modulus: String,
}

/// The validated body: topography source, optional sphere radius (m), E* (Pa).
pub struct Body {
    pub topography: TopographySource,
    pub radius_m: Option<f64>,
    pub e_star_pa: f64,
}

impl BodyArgs {
    /// Parsed into library units.
    pub fn body(&self) -> Result<Body> {
        Ok(Body {
            topography: self.input.source()?,
            radius_m: optional_quantity(&self.radius, "--radius", Quantity::Radius)?,
            e_star_pa: Quantity::Modulus.check_text(
                units::parse_positive(&self.modulus, Dimension::Pressure).context("--modulus")?,
                "--modulus",
            )?,
        })
    }
}

/// An optional pixel size (x, y) in metres from `200nm` or `200x210nm`.
pub fn optional_pixel_size(text: &Option<String>, flag: &str) -> Result<Option<(f64, f64)>> {
    text.as_deref()
        .map(units::parse_pixel_size)
        .transpose()
        .with_context(|| flag.to_string())
}

/// A length-valued option checked against the plausible range of `quantity`.
pub fn optional_quantity(
    text: &Option<String>,
    flag: &str,
    quantity: Quantity,
) -> Result<Option<f64>> {
    text.as_deref()
        .map(|t| {
            let v =
                units::parse_positive(t, Dimension::Length).with_context(|| flag.to_string())?;
            Ok(quantity.check_text(v, flag)?)
        })
        .transpose()
}

/// A fraction in [0, 1) from `1%` or `0.01`.
pub fn fraction(text: &str, flag: &str) -> Result<f64> {
    let value = match text.trim().strip_suffix('%') {
        Some(pct) => pct.trim().parse::<f64>().map(|p| p / 100.0),
        None => text.trim().parse::<f64>(),
    };
    match value {
        Ok(v) if (0.0..1.0).contains(&v) => Ok(v),
        _ => bail!("{flag}: {text:?} is not a fraction in [0, 1) such as 1% or 0.01"),
    }
}

/// `--series`, `--channel`, `--z`, `--t`: which plane(s) of a confocal file, shared by every
/// command that reads micrographs (rules in `contactscope_formats::microscopy::select`).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct SelectionArgs {
    /// Series of a CZI (scene), LIF or OME-TIFF (image) file; needed when the file has several.
    #[arg(long)]
    pub series: Option<usize>,
    /// Channel, by index or by the name `info` shows (CZI, ND2, LIF: AF488, TL, …); needed
    /// when the file has several (TIFF: samples or ImageJ channels, by index).
    #[arg(long)]
    pub channel: Option<ChannelChoice>,
    /// Focal plane of a CZI, ND2, LIF or OME-Zarr file; needed when it has several.
    #[arg(long)]
    pub z: Option<usize>,
    /// Time point of a CZI, ND2, LIF or OME-Zarr file; needed when it has several.
    #[arg(long)]
    pub t: Option<usize>,
    /// Index along another axis of a CZI, ND2, LIF or OME-Zarr file, by the name `info` shows: H=0
    /// (Airyscan phase), S=1 (green of an RGB pixel), lambda_emission=3, … Repeatable.
    #[arg(long = "axis", value_name = "NAME=INDEX", value_parser = parse_axis)]
    pub axis: Vec<(String, usize)>,
}

/// `NAME=INDEX` of `--axis`.
fn parse_axis(text: &str) -> std::result::Result<(String, usize), String> {
    let (name, index) = text
        .split_once('=')
        .ok_or_else(|| format!("{text:?} is not NAME=INDEX (e.g. H=0)"))?;
    let index = index
        .trim()
        .parse::<usize>()
        .map_err(|_| format!("{text:?}: the index must be a non-negative integer"))?;
    match name.trim() {
        "" => Err(format!("{text:?}: the axis name is empty")),
        n if ["T", "Z", "C", "X", "Y"].contains(&n) => Err(format!(
            "{text:?}: use --t, --z or --channel for T, Z and C (X and Y are the plane)"
        )),
        n => Ok((n.to_string(), index)),
    }
}

impl SelectionArgs {
    /// The library's selection.
    pub fn selection(&self) -> Selection {
        Selection {
            series: self.series,
            channel: self.channel.clone(),
            z: self.z,
            t: self.t,
            extra: self.axis.iter().cloned().collect(),
        }
    }
}

/// `--load-axis`: the axis of one CZI, ND2, LIF or OME-Zarr file whose planes are the loads.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum LoadAxisArg {
    /// Time points.
    T,
    /// Focal planes.
    Z,
    /// Series (CZI scenes, LIF images, OME-TIFF images).
    Series,
}

impl LoadAxisArg {
    /// The library's load axis.
    pub fn axis(self) -> LoadAxis {
        match self {
            LoadAxisArg::T => LoadAxis::T,
            LoadAxisArg::Z => LoadAxis::Z,
            LoadAxisArg::Series => LoadAxis::Series,
        }
    }
}
