//! The command line as a user meets it: usage and help, one-line errors, range checks on
//! every physical value, signals, and the hostile-file corpus.

mod hostile;
mod plausible;
mod ranges;
mod signals;
mod usage;
