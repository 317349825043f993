//! The per-series options of a batch: the samplesheet columns that are not metadata. Each is an
//! option of `analyze` or `fit-hardening`, written as on their command lines (`pixel_size` is
//! `--pixel-size 200nm`), parsed by the same parsers into the same requests; a series' options
//! also give the exact command lines that would make its folders on their own, which its
//! outputs record.
//!
//! A column may carry a unit in its name, as the output columns do: the cells of `pixel_size_nm`
//! or `forces_mN` are bare numbers in that unit (`200`, `4,10,40`); a cell that states its own
//! unit keeps it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use contactscope::solver::gpu::DeviceChoice;
use contactscope::surface::fill::FillInvalid;
use contactscope::surface::Detrend;
use contactscope::threshold::Method;
use contactscope_formats::microscopy::select::{ChannelChoice, LoadAxis, Selection};
use contactscope_formats::ranges::Quantity;
use contactscope_formats::units::{self, Dimension};

use crate::analyze::{AnalyzeRequest, HertzParams};
use crate::fit_hardening::{
    families_from_text, parse_hardness_range, parse_k_range, searches, BodyRequest, FitRequest,
    MeasuredInput,
};
use crate::heights::{HeightInput, TopographySource};
use crate::series::{Micrographs, SeriesSpec};

/// The command an option belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// `analyze`.
    Analyze,
    /// `fit-hardening`.
    Fit,
    /// Both (the sphere radius and E*: Hertz columns in `analyze`, the body of the fit).
    Both,
}

macro_rules! options {
    ($($(#[$doc:meta])* $variant:ident: $column:literal, $command:ident, $analyze:literal, $fit:literal, $unit:expr;)*) => {
        /// A per-series option: a samplesheet column with the flag it stands for.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum Opt {
            $($(#[$doc])* $variant,)*
        }

        impl Opt {
            /// Every option, in the order of the samplesheet's documentation.
            pub const ALL: &'static [Opt] = &[$(Opt::$variant,)*];

            /// The samplesheet column (snake case).
            pub fn column(self) -> &'static str {
                match self { $(Opt::$variant => $column,)* }
            }

            /// The command it belongs to.
            pub fn command(self) -> Command {
                match self { $(Opt::$variant => Command::$command,)* }
            }

            /// Its flag on `analyze`'s command line (empty when it has none).
            pub fn analyze_flag(self) -> &'static str {
                match self { $(Opt::$variant => $analyze,)* }
            }

            /// Its flag on `fit-hardening`'s command line (empty when it has none).
            pub fn fit_flag(self) -> &'static str {
                match self { $(Opt::$variant => $fit,)* }
            }

            /// The dimension of a unit its column name may carry (`pixel_size_nm`).
            pub fn dimension(self) -> Option<Dimension> {
                match self { $(Opt::$variant => $unit,)* }
            }
        }
    };
}

options! {
    /// Normal forces, one per image (`4,10,40mN`, `1mN..100mN:8`).
    Forces: "forces", Analyze, "--forces", "", Some(Dimension::Force);
    /// Series of a CZI or LIF file.
    Series: "series", Analyze, "--series", "", None;
    /// Channel of the micrographs.
    Channel: "channel", Analyze, "--channel", "", None;
    /// Focal plane.
    Z: "z", Analyze, "--z", "", None;
    /// Time point.
    T: "t", Analyze, "--t", "", None;
    /// Indices along other axes, `NAME=INDEX` separated by spaces or semicolons.
    Axis: "axis", Analyze, "--axis", "", None;
    /// The axis of a CZI, ND2 or LIF file whose planes are the loads.
    LoadAxis: "load_axis", Analyze, "--load-axis", "", None;
    /// `otsu`, `per-image` or a grey value.
    Threshold: "threshold", Analyze, "--threshold", "", None;
    /// Pixel size overriding the files' metadata.
    PixelSize: "pixel_size", Analyze, "--pixel-size", "", Some(Dimension::Length);
    /// Relative uncertainty of the pixel size (`1%`), given or the files'.
    PixelSizeUncertainty: "pixel_size_uncertainty", Analyze, "--pixel-size-uncertainty", "", None;
    /// Pixel size for files that state none (the batch's `--pixel-size` becomes this for rows
    /// without their own `pixel_size`).
    PixelSizeDefault: "pixel_size_default", Analyze, "--pixel-size-default", "", Some(Dimension::Length);
    /// The PSF's FWHM for the area intervals.
    PsfFwhm: "psf_fwhm", Analyze, "--psf-fwhm", "", Some(Dimension::Length);
    /// `psf.json` written by `contactscope psf`, whose FWHM the area intervals take.
    Psf: "psf", Analyze, "--psf", "", None;
    /// Sphere radius (Hertz columns; the sphere of the fit).
    Radius: "radius", Both, "--radius", "--radius", Some(Dimension::Length);
    /// Contact modulus E* (Hertz columns; the fit's material).
    Modulus: "modulus", Both, "--modulus", "--modulus", Some(Dimension::Pressure);
    /// The height map of the sphere: fits k (and p_Y) to the series' areas.
    Topography: "topography", Fit, "", "--topography", None;
    /// Pixel size of the height map (files without one, or overriding it).
    TopographyPixelSize: "topography_pixel_size", Fit, "", "--pixel-size", Some(Dimension::Length);
    /// Height unit of a height map that states none.
    HeightUnit: "height_unit", Fit, "", "--height-unit", Some(Dimension::Length);
    /// Detrending of the height map (`none`, `mean`, `plane`).
    Detrend: "detrend", Fit, "", "--detrend", None;
    /// Channel of a multi-channel height map, by name.
    TopographyChannel: "topography_channel", Fit, "", "--channel", None;
    /// Filling of a height map's invalid points (`mean`, `nearest`, `harmonic`).
    FillInvalid: "fill_invalid", Fit, "", "--fill-invalid", None;
    /// The measurement of a contact.engineering surface container, by index or name.
    TopographyMeasurement: "topography_measurement", Fit, "", "--measurement", None;
    /// Models fitted or scored (`gt,elastic,hardness,hardening`).
    Models: "models", Fit, "", "--models", None;
    /// Search range of k.
    KRange: "k_range", Fit, "", "--k-range", None;
    /// Search range of the hardness p_Y.
    HardnessRange: "hardness_range", Fit, "", "--hardness-range", None;
}

/// `fit-hardening`'s defaults for the options that have one (as its `--help` shows them).
pub const FIT_DEFAULTS: &[(Opt, &str)] = &[
    (Opt::Detrend, "plane"),
    (Opt::Models, "gt,elastic,hardness,hardening"),
    (Opt::KRange, "0.1..100MPa/nm"),
    (Opt::HardnessRange, "10MPa..10GPa"),
];

impl Opt {
    /// The option a column name stands for, and the unit its name carries: `pixel_size`,
    /// `pixel-size`, `Pixel Size`, `pixel_size_nm` (unit `nm`). `None` for metadata.
    pub fn of_column(name: &str) -> Option<(Opt, Option<String>)> {
        let normal: String = name
            .trim()
            .chars()
            .map(|c| if c == '-' || c == ' ' { '_' } else { c })
            .collect();
        let lower = normal.to_ascii_lowercase();
        if let Some(opt) = Opt::ALL.iter().find(|o| o.column() == lower) {
            return Some((*opt, None));
        }
        // `<column>_<unit>`, the unit in its own case (mN is not MN).
        Opt::ALL.iter().find_map(|&opt| {
            let dim = opt.dimension()?;
            let unit = normal
                .get(opt.column().len() + 1..)
                .filter(|_| lower.starts_with(&format!("{}_", opt.column())))?;
            units::parse_positive(&format!("1{unit}"), dim)
                .is_ok()
                .then(|| (opt, Some(unit.to_string())))
        })
    }

    /// Takes one number (with its unit), not a list or a range: a decimal comma in it can be
    /// read as a point.
    pub fn single_number(self) -> bool {
        matches!(
            self,
            Opt::PixelSize
                | Opt::PixelSizeDefault
                | Opt::PsfFwhm
                | Opt::PixelSizeUncertainty
                | Opt::Radius
                | Opt::Modulus
                | Opt::TopographyPixelSize
        )
    }

    /// The cell's text as the flag takes it: a bare number (or list) in a column whose name
    /// carries a unit gets that unit (`200` in `pixel_size_nm` is `200nm`).
    pub fn with_unit(text: &str, unit: Option<&str>) -> String {
        let text = text.trim();
        let Some(unit) = unit else {
            return text.to_string();
        };
        let bare = text
            .chars()
            .all(|c| c.is_ascii_digit() || ".,+-eEx: ".contains(c));
        match (bare, text.split_once(':')) {
            (false, _) => text.to_string(),
            // A range `1..100:8` takes the unit before its count.
            (true, Some((range, count))) if range.contains("..") => {
                format!("{}{unit}:{}", range.trim(), count.trim())
            }
            (true, _) => format!("{text}{unit}"),
        }
    }

    /// Parse a value and check its range, as the command's own flag does; the value in SI
    /// units as JSON (what decides whether a series must be analysed again).
    pub fn parse(self, text: &str) -> Result<Value, String> {
        let err = |e: &dyn std::fmt::Display| e.to_string();
        let index = |t: &str| {
            t.trim()
                .parse::<usize>()
                .map(Value::from)
                .map_err(|_| format!("'{t}' is not a non-negative integer"))
        };
        Ok(match self {
            Opt::Forces => json!(units::parse_forces(text).map_err(|e| err(&e))?),
            Opt::Series | Opt::Z | Opt::T => index(text)?,
            Opt::Channel => json!(text.parse::<ChannelChoice>()?),
            Opt::Axis => json!(parse_axes(text)?),
            Opt::LoadAxis => json!(load_axis(text)?.name()),
            Opt::Threshold => match Method::parse(text).map_err(|e| err(&e))? {
                Method::Manual(t) => json!(t),
                m => json!(m.name()),
            },
            Opt::PixelSizeUncertainty => {
                let u = units::parse_relative_uncertainty(text, None).map_err(|e| err(&e))?;
                crate::analyze::check_pixel_size_uncertainty(u).map_err(|e| e.to_string())?;
                json!(u)
            }
            Opt::PixelSize | Opt::PixelSizeDefault | Opt::TopographyPixelSize => {
                if let Ok((_, Some(_))) = units::parse_pixel_size_uncertain(text) {
                    return Err(format!(
                        "'{text}': give the pixel size's uncertainty on its own, as \
                         pixel_size_uncertainty (a column, or --pixel-size-uncertainty)"
                    ));
                }
                let (x, y) = units::parse_pixel_size(text).map_err(|e| err(&e))?;
                json!([x, y])
            }
            Opt::Radius => json!(checked(text, Dimension::Length, Quantity::Radius)?),
            Opt::PsfFwhm => json!(checked(text, Dimension::Length, Quantity::Fwhm)?),
            Opt::Modulus => json!(checked(text, Dimension::Pressure, Quantity::Modulus)?),
            Opt::HeightUnit => json!(checked(text, Dimension::Length, Quantity::Height)?),
            Opt::Topography | Opt::TopographyChannel | Opt::TopographyMeasurement | Opt::Psf => {
                json!(text.trim())
            }
            Opt::Detrend => json!(Detrend::from_name(text.trim())
                .ok_or_else(|| format!("'{text}' is not none, mean or plane"))?
                .name()),
            Opt::FillInvalid => json!(FillInvalid::from_name(text.trim())
                .ok_or_else(|| format!("'{text}' is not mean, nearest or harmonic"))?
                .name()),
            Opt::Models => json!(families_from_text(text)?
                .iter()
                .map(|f| f.name())
                .collect::<Vec<_>>()),
            Opt::KRange => json!(parse_k_range(text)?),
            Opt::HardnessRange => json!(parse_hardness_range(text)?),
        })
    }
}

fn checked(text: &str, dim: Dimension, quantity: Quantity) -> Result<f64, String> {
    let v = units::parse_positive(text, dim).map_err(|e| e.to_string())?;
    quantity
        .check_text(v, &format!("'{}'", text.trim()))
        .map_err(|e| e.to_string())
}

fn load_axis(text: &str) -> Result<LoadAxis, String> {
    match text.trim() {
        "t" => Ok(LoadAxis::T),
        "z" => Ok(LoadAxis::Z),
        "series" => Ok(LoadAxis::Series),
        other => Err(format!("'{other}' is not t, z or series")),
    }
}

/// `H=0 S=1` or `H=0;S=1`: indices along extra axes (`--axis`, repeated).
fn parse_axes(text: &str) -> Result<BTreeMap<String, usize>, String> {
    let mut axes = BTreeMap::new();
    for item in text.split([';', ' ']).filter(|s| !s.trim().is_empty()) {
        let (name, index) = item
            .split_once('=')
            .ok_or_else(|| format!("'{item}' is not NAME=INDEX (e.g. H=0)"))?;
        let index = index
            .trim()
            .parse::<usize>()
            .map_err(|_| format!("'{item}': the index must be a non-negative integer"))?;
        match name.trim() {
            "" => return Err(format!("'{item}': the axis name is empty")),
            n if ["T", "Z", "C", "X", "Y"].contains(&n) => {
                return Err(format!(
                    "'{item}': use the t, z or channel columns for T, Z and C"
                ))
            }
            n => axes.insert(n.to_string(), index),
        };
    }
    Ok(axes)
}

/// A series' options as text, the way the flags take them (units applied, defaults merged).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SeriesOptions(pub BTreeMap<Opt, String>);

/// Batch-wide settings that shape every series' outputs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OutputSettings {
    /// `analyze --overlays`.
    pub overlays: bool,
    /// `analyze --save-masks`.
    pub masks: bool,
    /// `analyze --memory-mib` (MiB of decoded compressed planes kept between the passes).
    pub memory_mib: usize,
    /// `fit-hardening --device`.
    #[serde(with = "device_name")]
    pub device: DeviceChoice,
}

mod device_name {
    use contactscope::solver::gpu::DeviceChoice;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(d: &DeviceChoice, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(super::device_text(*d))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<DeviceChoice, D::Error> {
        let name = String::deserialize(d)?;
        DeviceChoice::parse(&name).ok_or_else(|| serde::de::Error::custom("unknown device"))
    }
}

/// The flag value of a device choice.
pub fn device_text(d: DeviceChoice) -> &'static str {
    match d {
        DeviceChoice::Cpu => "cpu",
        DeviceChoice::Cuda => "cuda",
        DeviceChoice::Auto => "auto",
    }
}

impl Default for OutputSettings {
    fn default() -> Self {
        OutputSettings {
            overlays: false,
            masks: false,
            memory_mib: crate::series::DEFAULT_MEMORY_BUDGET >> 20,
            device: DeviceChoice::Cpu,
        }
    }
}

impl SeriesOptions {
    /// The text of an option, if given.
    pub fn get(&self, opt: Opt) -> Option<&str> {
        self.0.get(&opt).map(String::as_str)
    }

    /// The text of a `fit-hardening` option, or its default.
    fn fit_value(&self, opt: Opt) -> Option<&str> {
        self.get(opt).or_else(|| {
            FIT_DEFAULTS
                .iter()
                .find(|(o, _)| *o == opt)
                .map(|(_, v)| *v)
        })
    }

    /// Whether the series gets a `fit-hardening` (it names a height map).
    pub fn fits(&self) -> bool {
        self.get(Opt::Topography).is_some()
    }

    /// Check every value (and the combinations the commands refuse); the first problem as
    /// `(column, message)`.
    pub fn check(&self) -> Result<(), (Opt, String)> {
        for (&opt, text) in &self.0 {
            opt.parse(text).map_err(|m| (opt, m))?;
        }
        if self.get(Opt::Psf).is_some() && self.get(Opt::PsfFwhm).is_some() {
            return Err((
                Opt::Psf,
                "give the PSF once: psf (a psf.json) or psf_fwhm, not both".into(),
            ));
        }
        if self.fits() && self.get(Opt::Modulus).is_none() {
            return Err((
                Opt::Topography,
                "a fit needs the contact modulus E*: give the modulus column".into(),
            ));
        }
        if !self.fits() {
            if let Some(opt) = self.0.keys().find(|o| o.command() == Command::Fit) {
                return Err((
                    *opt,
                    "a fit-hardening option without a height map (topography column)".into(),
                ));
            }
        }
        Ok(())
    }

    /// What decides whether a series' results still hold: every option's value in SI units,
    /// numbers to 12 significant digits (so that `200nm` and `0.2um`, which differ in the last
    /// bit after their unit conversions, are the same value).
    pub fn fingerprint(&self) -> Value {
        fn round(v: Value) -> Value {
            match v {
                Value::Number(n) if n.is_f64() => {
                    let x = n.as_f64().unwrap_or(f64::NAN);
                    json!(format!("{x:.11e}").parse::<f64>().unwrap_or(x))
                }
                Value::Array(a) => Value::Array(a.into_iter().map(round).collect()),
                Value::Object(m) => {
                    Value::Object(m.into_iter().map(|(k, v)| (k, round(v))).collect())
                }
                other => other,
            }
        }
        // Defaults count as given: `otsu` is the same threshold as none.
        let mut all: BTreeMap<Opt, &str> = BTreeMap::new();
        all.insert(Opt::Threshold, "otsu");
        if self.fits() {
            all.extend(FIT_DEFAULTS.iter().copied());
        }
        all.extend(self.0.iter().map(|(o, t)| (*o, t.as_str())));
        let mut map = serde_json::Map::new();
        for (opt, text) in all {
            let value = opt.parse(text).unwrap_or_else(|e| json!({ "invalid": e }));
            map.insert(opt.column().to_string(), round(value));
        }
        Value::Object(map)
    }

    /// The `analyze` request of `input` (resolved path).
    pub fn analyze_request(&self, input: &Path, settings: &OutputSettings) -> AnalyzeRequest {
        let parsed = |opt: Opt| self.get(opt).map(|t| opt.parse(t));
        let index = |opt: Opt| {
            parsed(opt)
                .and_then(Result::ok)
                .and_then(|v| v.as_u64())
                .map(|v| v as usize)
        };
        let selection = Selection {
            series: index(Opt::Series),
            channel: self.get(Opt::Channel).and_then(|t| t.parse().ok()),
            z: index(Opt::Z),
            t: index(Opt::T),
            extra: self
                .get(Opt::Axis)
                .and_then(|t| parse_axes(t).ok())
                .unwrap_or_default(),
        };
        let forces_n = self
            .get(Opt::Forces)
            .and_then(|t| units::parse_forces(t).ok());
        let hertz = match (self.value(Opt::Radius), self.value(Opt::Modulus)) {
            (Some(radius_m), Some(modulus_pa)) => Some(HertzParams {
                radius_m,
                modulus_pa,
            }),
            _ => None,
        };
        AnalyzeRequest {
            method: self
                .get(Opt::Threshold)
                .and_then(|t| Method::parse(t).ok())
                .unwrap_or(Method::GlobalOtsu),
            pixel_size_m: self
                .get(Opt::PixelSize)
                .and_then(|t| units::parse_pixel_size(t).ok()),
            pixel_size_default_m: self
                .get(Opt::PixelSizeDefault)
                .and_then(|t| units::parse_pixel_size(t).ok()),
            pixel_size_uncertainty: self
                .get(Opt::PixelSizeUncertainty)
                .and_then(|t| units::parse_relative_uncertainty(t, None).ok())
                .unwrap_or(0.0),
            hertz,
            psf_fwhm_m: self.value(Opt::PsfFwhm),
            memory_budget: settings.memory_mib << 20,
            ..AnalyzeRequest::new(Micrographs::Files(SeriesSpec {
                inputs: vec![input.to_path_buf()],
                manifest: None,
                selection,
                load_axis: self.get(Opt::LoadAxis).and_then(|t| load_axis(t).ok()),
                forces_n,
            }))
        }
    }

    /// A positive quantity's value in SI units, if given and valid.
    fn value(&self, opt: Opt) -> Option<f64> {
        self.get(opt)
            .map(|t| opt.parse(t))
            .and_then(Result::ok)
            .and_then(|v| v.as_f64())
    }

    /// `analyze`'s arguments (after the program name) that make the series' folder `out` on
    /// their own; `input` as the batch names it.
    pub fn analyze_args(&self, input: &Path, out: &Path, settings: &OutputSettings) -> Vec<String> {
        let mut args = vec!["analyze".to_string(), input.display().to_string()];
        for (&opt, text) in &self.0 {
            // The Hertz columns need both; fit-only options have no analyze flag.
            let hertz_pair = self.get(Opt::Radius).is_some() && self.get(Opt::Modulus).is_some();
            let wanted = match opt.command() {
                Command::Analyze => true,
                Command::Both => hertz_pair,
                Command::Fit => false,
            };
            if !wanted {
                continue;
            }
            if opt == Opt::Axis {
                for (name, index) in parse_axes(text).unwrap_or_default() {
                    args.extend(["--axis".to_string(), format!("{name}={index}")]);
                }
                continue;
            }
            args.extend([opt.analyze_flag().to_string(), text.clone()]);
        }
        args.extend(["--out".to_string(), out.display().to_string()]);
        if settings.overlays {
            args.push("--overlays".into());
        }
        if settings.masks {
            args.push("--save-masks".into());
        }
        if settings.memory_mib != OutputSettings::default().memory_mib {
            args.extend(["--memory-mib".into(), settings.memory_mib.to_string()]);
        }
        args
    }

    /// The `fit-hardening` request on the measured `areas` (the series' `areas.csv`), with the
    /// height map resolved against `base`.
    pub fn fit_request(
        &self,
        areas: &Path,
        topography: &Path,
        settings: &OutputSettings,
    ) -> Result<FitRequest, String> {
        let parse = |opt: Opt| self.fit_value(opt).map(|t| opt.parse(t)).transpose();
        let source = TopographySource {
            path: topography.to_path_buf(),
            pixel_size_m: self
                .get(Opt::TopographyPixelSize)
                .map(units::parse_pixel_size)
                .transpose()
                .map_err(|e| e.to_string())?,
            height_unit_m: parse(Opt::HeightUnit)?.and_then(|v| v.as_f64()),
            detrend: self
                .fit_value(Opt::Detrend)
                .and_then(|t| Detrend::from_name(t.trim()))
                .unwrap_or(Detrend::Plane),
            channel: self
                .get(Opt::TopographyChannel)
                .map(|t| t.trim().to_string()),
            fill_invalid: self
                .get(Opt::FillInvalid)
                .and_then(|t| FillInvalid::from_name(t.trim())),
            measurement: self
                .get(Opt::TopographyMeasurement)
                .map(|t| t.trim().to_string()),
        };
        let modulus = self
            .value(Opt::Modulus)
            .ok_or("a fit needs the contact modulus E* (modulus column)")?;
        let families = families_from_text(self.fit_value(Opt::Models).unwrap_or_default())?;
        let searches = searches(
            parse_k_range(self.fit_value(Opt::KRange).unwrap_or_default())?,
            parse_hardness_range(self.fit_value(Opt::HardnessRange).unwrap_or_default())?,
        );
        Ok(FitRequest {
            families,
            searches,
            ..FitRequest::new(
                MeasuredInput::File(areas.to_path_buf()),
                BodyRequest {
                    radius_m: self.value(Opt::Radius),
                    device: settings.device,
                    ..BodyRequest::new(HeightInput::File(source), modulus)
                },
            )
        })
    }

    /// `fit-hardening`'s arguments (after the program name) that make the series' fit folder
    /// `out` from `areas` on their own.
    pub fn fit_args(
        &self,
        areas: &Path,
        topography: &Path,
        out: &Path,
        settings: &OutputSettings,
    ) -> Vec<String> {
        let mut args = vec![
            "fit-hardening".to_string(),
            "--areas".into(),
            areas.display().to_string(),
            "--topography".into(),
            topography.display().to_string(),
        ];
        for (&opt, text) in &self.0 {
            if opt == Opt::Topography || opt.command() == Command::Analyze {
                continue;
            }
            args.extend([opt.fit_flag().to_string(), text.clone()]);
        }
        if settings.device != DeviceChoice::Cpu {
            args.extend(["--device".into(), device_text(settings.device).into()]);
        }
        args.extend(["--out".to_string(), out.display().to_string()]);
        args
    }
}

/// Where a series' height map is: its path resolved against the samplesheet's folder.
pub fn resolve(base: &Path, text: &str) -> PathBuf {
    let path = Path::new(text.trim());
    if path.is_absolute() || base.as_os_str().is_empty() {
        path.to_path_buf()
    } else {
        base.join(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_name_options_in_any_spelling_with_units() {
        assert_eq!(Opt::of_column("pixel_size"), Some((Opt::PixelSize, None)));
        assert_eq!(Opt::of_column("Pixel-Size"), Some((Opt::PixelSize, None)));
        assert_eq!(Opt::of_column("load axis"), Some((Opt::LoadAxis, None)));
        assert_eq!(
            Opt::of_column("pixel_size_nm"),
            Some((Opt::PixelSize, Some("nm".into())))
        );
        assert_eq!(
            Opt::of_column("forces_mN"),
            Some((Opt::Forces, Some("mN".into())))
        );
        // A unit of another dimension, or none at all: metadata.
        assert_eq!(Opt::of_column("forces_nm"), None);
        assert_eq!(Opt::of_column("sample"), None);
        assert_eq!(Opt::of_column("radius_of_curvature"), None);
    }

    #[test]
    fn bare_cells_take_the_column_unit() {
        assert_eq!(Opt::with_unit("200", Some("nm")), "200nm");
        assert_eq!(Opt::with_unit("200x210", Some("nm")), "200x210nm");
        assert_eq!(Opt::with_unit("4,10,40", Some("mN")), "4,10,40mN");
        assert_eq!(Opt::with_unit("1..100:8", Some("mN")), "1..100mN:8");
        assert_eq!(Opt::with_unit("0.2um", Some("nm")), "0.2um");
        assert_eq!(Opt::with_unit(" otsu ", None), "otsu");
        assert_eq!(
            Opt::Forces.parse(&Opt::with_unit("1..100:3", Some("mN"))),
            Ok(json!([0.001, 0.01, 0.1]))
        );
    }

    #[test]
    fn values_are_checked_as_the_flags_check_them() {
        assert!(Opt::PixelSize.parse("200").unwrap_err().contains("no unit"));
        assert!(Opt::PixelSize.parse("200mm").is_err(), "out of range");
        assert!(Opt::PixelSize
            .parse("200nm±1%")
            .unwrap_err()
            .contains("pixel_size_uncertainty"));
        assert_eq!(Opt::PixelSizeUncertainty.parse("1%"), Ok(json!(0.01)));
        assert!(Opt::PixelSizeUncertainty.parse("30%").is_err());
        assert!(Opt::Channel.parse("-1").is_err());
        assert!(Opt::LoadAxis.parse("c").is_err());
        assert_eq!(
            Opt::Threshold.parse("per-image"),
            Ok(json!("otsu-per-image"))
        );
        assert_eq!(Opt::Threshold.parse("1200"), Ok(json!(1200.0)));
        assert!(Opt::Models.parse("hardening,plastic").is_err());
        assert_eq!(Opt::Axis.parse("H=0; S=1"), Ok(json!({"H": 0, "S": 1})));
        assert!(Opt::Axis.parse("T=1").is_err());
        // The same value in other words is the same fingerprint.
        let a = SeriesOptions([(Opt::PixelSize, "200nm".to_string())].into());
        let b = SeriesOptions([(Opt::PixelSize, "0.2um".to_string())].into());
        assert_eq!(a.fingerprint(), b.fingerprint());
    }

    #[test]
    fn fit_options_need_a_height_map_and_a_modulus() {
        let only_models = SeriesOptions([(Opt::Models, "hardening".to_string())].into());
        assert_eq!(only_models.check().unwrap_err().0, Opt::Models);
        let no_modulus = SeriesOptions([(Opt::Topography, "a.npy".to_string())].into());
        assert_eq!(no_modulus.check().unwrap_err().0, Opt::Topography);
    }

    #[test]
    fn command_lines_list_every_option_once() {
        let options = SeriesOptions(
            [
                (Opt::Forces, "4,10mN".to_string()),
                (Opt::Axis, "H=0;S=1".to_string()),
                (Opt::Radius, "290um".to_string()),
                (Opt::Modulus, "3.7GPa".to_string()),
                (Opt::Topography, "map.npy".to_string()),
                (Opt::Models, "hardening".to_string()),
            ]
            .into(),
        );
        let settings = OutputSettings::default();
        let args = options.analyze_args(Path::new("a/s1"), Path::new("o/series/s1"), &settings);
        assert_eq!(
            args.join(" "),
            "analyze a/s1 --forces 4,10mN --axis H=0 --axis S=1 --radius 290um --modulus 3.7GPa \
             --out o/series/s1"
        );
        let fit = options.fit_args(
            Path::new("o/series/s1/areas.csv"),
            Path::new("a/map.npy"),
            Path::new("o/fit/s1"),
            &settings,
        );
        assert_eq!(
            fit.join(" "),
            "fit-hardening --areas o/series/s1/areas.csv --topography a/map.npy --radius 290um \
             --modulus 3.7GPa --models hardening --out o/fit/s1"
        );
    }
}
