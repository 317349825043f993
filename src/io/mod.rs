//! Vendor file formats: confocal microscopy files ([`microscopy`]: Zeiss CZI, Nikon ND2, Leica
//! LIF, and TIFF described the same way) and AFM/profilometer height maps ([`topography`]).

pub(crate) mod binary;
pub mod microscopy;
pub mod topography;
