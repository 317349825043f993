//! Typed library errors. Every variant that concerns a file names it, and the page where it
//! matters, so that the command line can print one self-explaining line.

use std::path::PathBuf;

/// Result alias used throughout the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Where in the input an error was found: a file and, for multi-page files, a page.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file as the user named it (or as found in a directory or manifest).
    pub path: PathBuf,
    /// Zero-based TIFF page (IFD index), when the error concerns one page.
    pub page: Option<usize>,
}

impl Location {
    /// A whole file.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Location {
            path: path.into(),
            page: None,
        }
    }

    /// One page of a file.
    pub fn page(path: impl Into<PathBuf>, page: usize) -> Self {
        Location {
            path: path.into(),
            page: Some(page),
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.page {
            Some(p) => write!(f, "{} (page {p})", self.path.display()),
            None => write!(f, "{}", self.path.display()),
        }
    }
}

/// Everything that can go wrong in the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file could not be opened, read or written.
    #[error("{at}: {source}")]
    Io {
        /// File concerned.
        at: Location,
        /// Underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a TIFF, or its structure is broken (truncated, bad offsets, bad tags).
    #[error("{at}: not a readable TIFF: {reason}")]
    BadTiff {
        /// File and page concerned.
        at: Location,
        /// What the decoder reported.
        reason: String,
    },
    /// A valid TIFF that uses a feature contactscope does not read.
    #[error("{at}: unsupported: {reason}")]
    Unsupported {
        /// File and page concerned.
        at: Location,
        /// What is unsupported and, where there is one, the way out.
        reason: String,
    },
    /// The images of a series do not agree (shape, sample type, channels).
    #[error("{at}: {reason} (the series started with {expected})")]
    SeriesMismatch {
        /// First offending file and page.
        at: Location,
        /// What differs.
        reason: String,
        /// What the first image of the series had.
        expected: String,
    },
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
    /// A plot could not be drawn.
    #[error("plot: {0}")]
    Plot(String),
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
    /// Writing an output file failed.
    #[error("cannot write {path}: {reason}")]
    Output {
        /// Output file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
}

impl Error {
    /// An I/O error on a file.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            at: Location::file(path),
            source,
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
