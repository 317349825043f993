//! Small shared numerics kept on purpose rather than taken from a crate, each with its reason
//! beside it ([`stats`]: mean ± sample sd and the median).

pub mod stats;
