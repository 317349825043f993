//! Load series: one global Otsu threshold, contact areas, patches and fits, against ground
//! truth, on real TIFFs, and along the load axes of CZI, ND2 and LIF files.

mod analysis;
mod axes;
mod first_hour;
mod ground_truth;
mod intervals;
mod real_tiff;
mod vendor;
