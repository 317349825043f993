//! Layer (b), input and output: every reader and writer of a file format, the quantities typed on
//! the command line and in manifests, and the staging of output folders. Nothing here computes
//! science; readers return the in-memory types of the algorithm layer ([`crate::image::Plane`],
//! [`crate::surface::Topography`], …) in SI units, and every error names the file (and page or
//! line).
//!
//! | module | what |
//! |---|---|
//! | [`units`] | quantities as text: `290um`, `3.7GPa`, `4,10,20mN`, ranges and ratios |
//! | [`ranges`] | plausible ranges of forces, pixel sizes, radii, moduli, hardness, k, wavelengths, FWHMs |
//! | [`staging`] | output folders written to a staging folder and renamed into place atomically |
//! | [`table`] | small CSV tables whose column names carry the unit (`force_mN`), `areas.csv` |
//! | [`tiff`] | TIFF reading (pages, channels, pixel-size metadata) and writing |
//! | [`series`] | files, folders and manifests (TIFF, CZI, ND2, LIF) → which page or plane is which load; the file-backed plane source of the series analysis |
//! | [`topography`] | height maps: `.npy`, float TIFF, `.gsf`, text, WSxM, Nanoscope, and vendor AFM/profilometer formats (`.ibw`, `.nid`, `.mi`, Park TIFF, `.gwy`, `.x3p`, `.sdf`, `.opd`, `.plu`, `.sur`, `.frt`) |
//! | [`microscopy`] | confocal files: Zeiss CZI, Nikon ND2, Leica LIF, and TIFF described the same way |
//! | [`plot`] | charts (PNG/SVG) and micrograph panels (PNG) |
//! | [`mechanics`] | the mechanics CSVs: friction traces, squeeze tests |
//! | [`results`] | one command's outputs read by another: `areas.csv`, a `simulate` folder, `psf.json` |

pub(crate) mod binary;
pub mod mechanics;
pub mod microscopy;
pub mod plot;
pub mod ranges;
pub mod results;
pub mod series;
pub mod staging;
pub mod table;
pub mod tiff;
pub mod topography;
pub mod units;
