//! The readers: every format against the numbers of trusted readers, `info` and `topography`
//! on real and generated files, and vendor files in the optics commands.

mod commands;
mod container;
mod files;
mod ome_zarr;
mod peer;
mod real;
mod reference_readers;
mod remote;
mod synthetic;
mod topography;
mod vendor_optics;
