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
    /// An argument or value given by the caller is invalid (unit, count, range).
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
    /// A bad-input error at a location.
    pub fn bad_input(at: Location, reason: impl Into<String>) -> Self {
        Error::BadInput {
            at,
            reason: reason.into(),
        }
    }
}
