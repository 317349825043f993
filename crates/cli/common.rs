//! What every command's printing shares: the progress bar, the list of files written, the
//! warnings on stderr, and the command line for the outputs' JSON. (The command line has one
//! file per command holding its clap arguments, their conversion into the job's request and its
//! printing; argument groups several commands share are in `args.rs`.)

use std::io::IsTerminal;
use std::path::Path;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How a command that ran to its end finished: its exit status (`docs/errors.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Finished {
    /// Everything asked for was done: 0.
    Complete,
    /// `batch`: the tables are written but some series failed: 3.
    SomeFailed,
    /// The outputs are written but no load is valid (edge contact or no contact in every
    /// one), so no fit rests on anything: 4.
    NothingValid,
}

impl Finished {
    /// [`Finished::NothingValid`] when `nothing_valid`, else [`Finished::Complete`].
    pub fn unless_nothing_valid(nothing_valid: bool) -> Self {
        match nothing_valid {
            true => Finished::NothingValid,
            false => Finished::Complete,
        }
    }
}

/// A progress bar on stderr, hidden with --quiet, when stderr is not a terminal, or when there
/// are fewer than `min_items` items (a short job needs none).
pub fn progress_bar(items: usize, min_items: usize, quiet: bool) -> ProgressBar {
    let visible = !quiet && items >= min_items && std::io::stderr().is_terminal();
    let bar = ProgressBar::with_draw_target(
        Some(items as u64),
        if visible {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    );
    bar.set_style(
        ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} images ({elapsed})")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// `wrote N files to DIR`.
pub fn print_written(files: usize, out: &Path) {
    println!("wrote {files} files to {}", out.display());
}

/// Each warning on stderr, one line each.
pub fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("contactscope: warning: {w}");
    }
}

/// The whole command line, for the outputs' JSON.
pub fn command_line() -> Vec<String> {
    std::env::args().collect()
}
