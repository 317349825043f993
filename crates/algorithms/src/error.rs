//! Typed errors of the algorithms. The algorithms open no file, but an image or a map carries
//! the file and page it came from ([`Location`]), and errors about it name them, so that a
//! front-end can print one self-explaining line. An error of a file source (a
//! [`crate::analysis::PlaneSource`] that decodes pages on demand) passes through as
//! [`Error::Format`].

/// Result alias used throughout the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

pub use contactscope_formats::error::Location;

/// Everything that can go wrong in the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Something about the input data or its description is wrong (manifest, forces, pages).
    #[error("{at}: {reason}")]
    BadInput {
        /// File (and page) concerned.
        at: Location,
        /// What is wrong.
        reason: String,
    },
    /// A number given to an algorithm that it cannot take (not positive, not finite, outside
    /// its interval), with the number.
    #[error("{what} {value} {unit} {requirement}")]
    Value {
        /// What it is (with the algorithm, where that helps: "Greenwood–Tripp: force").
        what: &'static str,
        /// The value given.
        value: f64,
        /// Its unit ("" for a pure number).
        unit: &'static str,
        /// What it must be ("must be positive and finite").
        requirement: &'static str,
    },
    /// Two sizes that must agree do not.
    #[error("{what}: {got} given for {expected}")]
    SizeMismatch {
        /// What was counted.
        what: &'static str,
        /// The size it must have.
        expected: usize,
        /// The size it has.
        got: usize,
    },
    /// Fewer items than an algorithm needs.
    #[error("{what} needs at least {needed} (got {got})")]
    TooFew {
        /// What needs them.
        what: &'static str,
        /// The minimum.
        needed: usize,
        /// How many there are.
        got: usize,
    },
    /// A load heavier than a penetration hardness can carry on the whole map.
    #[error(
        "load {load_n:.4e} N exceeds what the hardness can carry on the whole map \
         ({capacity_n:.4e} N): lower the load ({}) or raise the hardness ({})",
        contactscope_formats::param::Param::Loads,
        contactscope_formats::param::Param::Hardness
    )]
    ExceedsCapacity {
        /// The load, N.
        load_n: f64,
        /// Hardness × map area, N.
        capacity_n: f64,
    },
    /// A work size beyond the limits.
    #[error("{what}: {source}")]
    Limit {
        /// The work it was for.
        what: String,
        /// The size and the limit.
        #[source]
        source: contactscope_formats::limits::LimitError,
    },
    /// A name that is not one of the choices.
    #[error("unknown {what} '{name}': use {choices}")]
    UnknownName {
        /// What the name names.
        what: &'static str,
        /// The name given.
        name: String,
        /// The choices, in words.
        choices: &'static str,
    },
    /// An argument or value given by the caller is invalid; the message says why.
    #[error("{0}")]
    InvalidArgument(String),
    /// No threshold exists: all pixels have one value.
    #[error(
        "{what}: every pixel has the value {value}; no threshold separates contact from background"
    )]
    ConstantData {
        /// The series or image concerned.
        what: String,
        /// The one value.
        value: f64,
    },
    /// An iterative solver stopped at its iteration limit without meeting its tolerance.
    #[error("{what} did not converge in {iterations} iterations (residual {residual:.3e}, tolerance {tolerance:.1e})")]
    NotConverged {
        /// Which solver.
        what: String,
        /// Iterations done.
        iterations: usize,
        /// Final residual (relative).
        residual: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// The GPU asked for cannot be used, or failed (feature `cuda`; [`crate::solver::gpu`]).
    #[error("GPU ({}): {reason}", contactscope_formats::param::Param::Device.with_value("cuda"))]
    Device {
        /// What is missing or what failed.
        reason: String,
    },
    /// Too few line profiles through Newton rings could be measured (`optics::newton`).
    #[error(
        "{at}: only {usable} of {total} line profiles usable, at least {needed} needed: {reason}"
    )]
    TooFewProfiles {
        /// The reflection image.
        at: Location,
        /// Profiles that gave a detection gap.
        usable: usize,
        /// Profiles measured.
        total: usize,
        /// The stated minimum.
        needed: usize,
        /// Why the others were skipped.
        reason: String,
    },
    /// An error of a file read on the algorithms' behalf (a plane source decoding pages).
    #[error(transparent)]
    Format(#[from] contactscope_formats::Error),
    /// An error of the caller's own code run inside an algorithm (an image sink writing outputs,
    /// a plane source of the caller's), passed through unchanged; the caller's error type
    /// converts it back.
    #[error(transparent)]
    External(Box<dyn std::error::Error + Send + Sync + 'static>),
}

impl Error {
    /// [`Error::Value`] for a number that must be positive and finite.
    pub fn not_positive(what: &'static str, value: f64, unit: &'static str) -> Self {
        Error::Value {
            what,
            value,
            unit,
            requirement: "must be positive and finite",
        }
    }

    /// A bad-input error at a location.
    pub fn bad_input(at: Location, reason: impl Into<String>) -> Self {
        Error::BadInput {
            at,
            reason: reason.into(),
        }
    }
}
