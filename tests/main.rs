//! contactscope's integration tests, one binary (`autotests = false` in `Cargo.toml`, as ripgrep
//! keeps its tests): the commands end to end through the built `contactscope` binary, and the
//! layers' public APIs on real and generated files. A folder per concept:
//!
//! | module | what |
//! |---|---|
//! | [`batch`] | an archive in one command: folders equal to `analyze`'s, tables (Parquet, CSV), provenance, failures, kills and re-runs |
//! | [`cli`] | usage, one-line errors, range checks, signals, the hostile-file corpus |
//! | [`formats`] | every reader against trusted readers' numbers; `info`, `topography`; vendor files in the optics commands |
//! | [`series`] | load series: the global Otsu threshold, areas, ground truth, vendor load axes, real TIFFs |
//! | [`optics`] | PSF, Newton rings, autocorrelation, `compare` |
//! | [`mechanics`] | solver, `simulate`, surfaces, `fit-hardening`, friction and squeeze tests |
//! | [`demo`] | the whole method on a generated experiment |
//! | [`fuzz`] | the mutation fuzzer over every command (a short campaign; the long one is `--ignored`) |
//! | [`layers`] | the workspace's layering: no crate imports a layer above it |
//! | [`release`] | one version everywhere, licence files, the crates' registry metadata |
//!
//! Real files come from `../shared/data` (tests skip with a message when it is absent).
//! Run one folder with `cargo test --release --test integration optics::`.

mod common;

mod batch;
mod cli;
mod demo;
mod formats;
mod fuzz;
mod layers;
mod mechanics;
mod optics;
mod release;
mod series;
