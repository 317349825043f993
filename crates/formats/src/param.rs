//! The parameters a person sets, named in the terms of the front-end they use. A message about a
//! parameter names it through [`Param`], whose `Display` follows the process's front-end
//! ([`set_front_end`]): `--pixel-size` on the command line, `pixel_size=` in Python, "pixel size"
//! for a Rust caller of the library. The command line and the Python package each set theirs
//! once at start-up; the names themselves are listed here, once, so that a test can check that
//! every name is a flag (or keyword) its front-end really has.

use std::fmt;
use std::sync::atomic::{AtomicU8, AtomicUsize, Ordering};

/// Who is asking: decides how a [`Param`] is written in messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontEnd {
    /// A Rust program using the library: plain words.
    Library,
    /// The `contactscope` command line: `--flag`.
    CommandLine,
    /// The Python package: `keyword=`.
    Python,
}

static FRONT_END: AtomicU8 = AtomicU8::new(0);

/// Set the front-end whose names messages use (once, at start-up).
pub fn set_front_end(front_end: FrontEnd) {
    FRONT_END.store(front_end as u8, Ordering::Relaxed);
}

/// Sections of work (anywhere in the process) that must be worded as the command line words
/// them, whatever the front-end: a batch's series, whose folders are exactly what
/// `contactscope analyze` writes, in every front-end.
static COMMAND_LINE_SECTIONS: AtomicUsize = AtomicUsize::new(0);

/// While alive, messages name parameters as the command line does ([`FrontEnd::CommandLine`]).
/// Counted, so that overlapping sections on several threads end only when the last does.
#[must_use = "the wording holds while the guard lives"]
pub struct CommandLineWords(());

impl CommandLineWords {
    /// Start a section worded as the command line.
    pub fn begin() -> Self {
        COMMAND_LINE_SECTIONS.fetch_add(1, Ordering::SeqCst);
        CommandLineWords(())
    }
}

impl Drop for CommandLineWords {
    fn drop(&mut self) {
        COMMAND_LINE_SECTIONS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The front-end set by [`set_front_end`] ([`FrontEnd::Library`] by default), or the command
/// line inside a [`CommandLineWords`] section.
pub fn front_end() -> FrontEnd {
    if COMMAND_LINE_SECTIONS.load(Ordering::SeqCst) > 0 {
        return FrontEnd::CommandLine;
    }
    match FRONT_END.load(Ordering::Relaxed) {
        1 => FrontEnd::CommandLine,
        2 => FrontEnd::Python,
        _ => FrontEnd::Library,
    }
}

macro_rules! params {
    ($($(#[$doc:meta])* $variant:ident: $flag:literal, $python:literal, $plain:literal;)*) => {
        /// A parameter a person sets (a flag on the command line, a keyword in Python).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[non_exhaustive]
        pub enum Param {
            $($(#[$doc])* $variant,)*
        }

        impl Param {
            /// Every parameter.
            pub const ALL: &'static [Param] = &[$(Param::$variant,)*];

            /// The command line's flag, with its dashes.
            pub fn flag(self) -> &'static str {
                match self { $(Param::$variant => $flag,)* }
            }

            /// The Python keyword (empty where Python has no such parameter).
            pub fn keyword(self) -> &'static str {
                match self { $(Param::$variant => $python,)* }
            }

            /// In plain words.
            pub fn words(self) -> &'static str {
                match self { $(Param::$variant => $plain,)* }
            }
        }
    };
}

params! {
    /// Pixel size overriding the files' metadata.
    PixelSize: "--pixel-size", "pixel_size", "the pixel size";
    /// Pixel size for files whose metadata states none (never replacing a stated one).
    PixelSizeDefault: "--pixel-size-default", "", "the pixel size for files without one";
    /// Relative uncertainty of the pixel size (as bounds).
    PixelSizeUncertainty: "--pixel-size-uncertainty", "pixel_size_uncertainty", "the pixel size's uncertainty";
    /// Metres per stored height unit.
    HeightUnit: "--height-unit", "height_unit", "the height unit";
    /// Detrending of a height map.
    Detrend: "--detrend", "detrend", "the detrending";
    /// Channel of a file (index for images, name for height maps).
    Channel: "--channel", "channel", "the channel";
    /// Series (CZI scene, LIF image, OME-TIFF image) of a file.
    Series: "--series", "series", "the series";
    /// Focal plane.
    Z: "--z", "z", "the focal plane (z)";
    /// Time point.
    T: "--t", "t", "the time point (t)";
    /// Index along another axis, by name.
    Axis: "--axis", "axes", "the index along another axis";
    /// Axis whose planes are the loads.
    LoadAxis: "--load-axis", "load_axis", "the load axis";
    /// How to fill a height map's invalid points.
    FillInvalid: "--fill-invalid", "fill_invalid", "the filling of invalid points";
    /// The measurement of a surface container.
    Measurement: "--measurement", "measurement", "the measurement";
    /// Normal forces, one per image.
    Forces: "--forces", "forces", "the forces";
    /// Normal forces of a simulated ramp (Python's `loads=`).
    Loads: "--forces", "loads", "the loads";
    /// Manifest CSV of a series.
    Manifest: "--manifest", "manifest", "the manifest";
    /// Threshold method or value.
    Threshold: "--threshold", "method", "the threshold";
    /// Sphere radius.
    Radius: "--radius", "radius", "the sphere radius";
    /// Contact modulus E*.
    Modulus: "--modulus", "modulus", "the contact modulus";
    /// Contact model.
    Model: "--model", "model", "the model";
    /// Penetration hardness p_Y.
    Hardness: "--hardness", "hardness", "the hardness";
    /// Hardening coefficient k.
    Hardening: "--hardening", "k", "the hardening coefficient";
    /// Initial yield pressure p_Y0.
    InitialHardness: "--initial-hardness", "initial_hardness", "the initial hardness";
    /// Relaxation of the volume-conserving plastic increment.
    VolumeConserving: "--volume-conserving", "alpha", "the volume-conserving relaxation";
    /// Relative solver tolerance.
    Tolerance: "--tolerance", "tolerance", "the solver tolerance";
    /// Most solver iterations per load.
    MaxIterations: "--max-iterations", "max_iterations", "the iteration limit";
    /// Where the solver runs (cpu, cuda, auto).
    Device: "--device", "device", "the device";
    /// Height map of a simulation.
    Topography: "--topography", "heights", "the height map";
    /// Micrographs of a measured load series.
    Experiment: "--micrographs", "micrographs", "the micrographs";
    /// Folder of simulated maps.
    Simulation: "--simulation", "maps", "the simulated maps";
    /// PSF measured by `psf` (psf.json).
    Psf: "--psf", "psf", "the PSF";
    /// PSF full width at half maximum.
    PsfFwhm: "--psf-fwhm", "psf_fwhm", "the PSF FWHM";
    /// Sub-pixel registration upsampling.
    Upsample: "--upsample", "upsample", "the registration upsampling";
    /// Relative tolerance when matching forces.
    ForceTolerance: "--force-tolerance", "force_tolerance", "the force tolerance";
    /// Wavelength of the illumination.
    Wavelength: "--wavelength", "wavelength", "the wavelength";
    /// Refractive index of the medium in the gap.
    MediumIndex: "--medium-index", "medium_index", "the medium's refractive index";
    /// Line profiles through Newton rings.
    Profiles: "--profiles", "profiles", "the number of profiles";
    /// Bead diameter.
    BeadDiameter: "--bead-diameter", "bead_diameter", "the bead diameter";
    /// Largest autocorrelation lag.
    MaxLag: "--max-lag", "max_lag", "the largest lag";
    /// Normal force of friction traces.
    NormalForce: "--forces", "normal_force", "the normal force";
    /// Rotation radius of a rheometer.
    RotationRadius: "--rotation-radius", "rotation_radius", "the rotation radius";
    /// Measured areas (areas.csv).
    Areas: "--areas", "areas", "the measured areas";
    /// Output folder or file.
    Out: "--out", "out", "the output";
    /// Hurst exponent of a self-affine surface.
    Hurst: "--hurst", "hurst", "the Hurst exponent";
    /// rms height a generated surface is scaled to.
    RmsHeight: "--rms-height", "rms_height", "the rms height";
    /// rms slope a generated surface is scaled to.
    RmsSlope: "--rms-slope", "rms_slope", "the rms slope";
    /// Roll-off wavelength of a generated surface.
    Rolloff: "--rolloff", "rolloff", "the roll-off wavelength";
    /// Short-wavelength cutoff of a generated surface.
    Cutoff: "--cutoff", "cutoff", "the short-wavelength cutoff";
    /// Saturation level of the detector (`psf`).
    SaturationLevel: "--saturation-level", "saturation_level", "the saturation level";
    /// Size in pixels of a generated map or series (Python: its `nx`, `ny` or `width`, `height`).
    Size: "--size", "", "the size in pixels";
    /// Phase of the Newton-ring maxima.
    Phase: "--phase", "phase", "the phase of the ring maxima";
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match front_end() {
            FrontEnd::CommandLine => f.write_str(self.flag()),
            FrontEnd::Python if !self.keyword().is_empty() => write!(f, "{}=", self.keyword()),
            _ => f.write_str(self.words()),
        }
    }
}

impl Param {
    /// The plausible range a value of this parameter is checked against
    /// ([`crate::ranges::Quantity`]), for parameters that are physical quantities.
    pub fn quantity(self) -> Option<crate::ranges::Quantity> {
        use crate::ranges::Quantity;
        Some(match self {
            Param::PixelSize => Quantity::PixelSize,
            Param::HeightUnit => Quantity::Height,
            Param::Forces | Param::Loads | Param::NormalForce => Quantity::Force,
            Param::Radius => Quantity::Radius,
            Param::Modulus => Quantity::Modulus,
            Param::Hardness | Param::InitialHardness => Quantity::Hardness,
            Param::Hardening => Quantity::Hardening,
            Param::PsfFwhm => Quantity::Fwhm,
            Param::Wavelength => Quantity::Wavelength,
            Param::BeadDiameter | Param::MaxLag | Param::RotationRadius => Quantity::Length,
            _ => return None,
        })
    }
}

impl Param {
    /// The parameter with a value as a person would write it in the front-end: `--channel 2`,
    /// `channel=2`, "the channel 2".
    pub fn with_value(self, value: impl fmt::Display) -> String {
        match front_end() {
            FrontEnd::CommandLine => format!("{} {value}", self.flag()),
            FrontEnd::Python if !self.keyword().is_empty() => {
                format!("{}={value}", self.keyword())
            }
            _ => format!("{} {value}", self.words()),
        }
    }

    /// An index along a named extra axis as the front-end writes it: `--axis H=0`,
    /// `axes={'H': 0}`.
    pub fn axis_value(name: &str, value: impl fmt::Display) -> String {
        match front_end() {
            FrontEnd::CommandLine => format!("--axis {name}={value}"),
            FrontEnd::Python => format!("axes={{'{name}': {value}}}"),
            FrontEnd::Library => format!("axis {name} = {value}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_per_front_end() {
        // One flag per quantity on the command line: the normal forces are `--forces` in every
        // command, though Python names them `forces=`, `loads=` or `normal_force=`.
        let same_quantity = [Param::Forces, Param::Loads, Param::NormalForce];
        let mut flags: Vec<_> = Param::ALL
            .iter()
            .filter(|p| !same_quantity[1..].contains(p))
            .map(|p| p.flag())
            .collect();
        flags.sort_unstable();
        let n = flags.len();
        flags.dedup();
        assert_eq!(flags.len(), n);
        assert!(Param::ALL.iter().all(|p| p.flag().starts_with("--")));
        assert!(same_quantity.iter().all(|p| p.flag() == "--forces"));
        let mut keywords: Vec<_> = Param::ALL
            .iter()
            .map(|p| p.keyword())
            .filter(|k| !k.is_empty())
            .collect();
        keywords.sort_unstable();
        let n = keywords.len();
        keywords.dedup();
        assert_eq!(keywords.len(), n);
    }
}
