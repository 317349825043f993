//! Messages of a series' `analyze` and `fit-hardening` (worded as those commands' flags) in the
//! batch's terms: where a batch sets what the message names.

use super::options::{Command, Opt};

/// A message of a series' `analyze` (`stage` [`Command::Analyze`]) or `fit-hardening`
/// ([`Command::Fit`]), which names the command's flags, in the batch's terms: the first mention
/// of each flag is followed by where a batch sets it (`--pixel-size (in a batch: the
/// topography_pixel_size column, or --topography-pixel-size)` for a height map's pixel size).
pub fn in_batch_terms(message: &str, stage: Command) -> String {
    let mut out = message.to_string();
    for &opt in Opt::ALL {
        let flag = match (stage, opt.command()) {
            (Command::Fit, Command::Fit | Command::Both) => opt.fit_flag(),
            (Command::Analyze | Command::Both, Command::Analyze | Command::Both) => {
                opt.analyze_flag()
            }
            _ => continue,
        };
        if flag.is_empty() {
            continue;
        }
        // The flag as a whole word (`--pixel-size`, not the start of `--pixel-size-uncertainty`).
        let whole = |at: usize| {
            !out[at + flag.len()..]
                .starts_with(|c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        };
        let Some(at) = out.match_indices(flag).map(|(i, _)| i).find(|&i| whole(i)) else {
            continue;
        };
        let batch_flag = super::default_flag(opt);
        let place = match opt {
            Opt::PixelSize => format!(
                "the {} column; the batch's {batch_flag} fills only files without one",
                opt.column()
            ),
            _ => format!("the {} column, or the batch's {batch_flag}", opt.column()),
        };
        let note = format!(" (in a batch: {place})");
        if out[at + flag.len()..].starts_with(&note) {
            continue;
        }
        out.insert_str(at + flag.len(), &note);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_where_a_batch_sets_a_flag() {
        let fit = in_batch_terms(
            "map.npy: no pixel size; give it with --pixel-size (e.g. 1um)",
            Command::Fit,
        );
        assert_eq!(
            fit,
            "map.npy: no pixel size; give it with --pixel-size (in a batch: the \
             topography_pixel_size column, or the batch's --topography-pixel-size) (e.g. 1um)"
        );
        let analyze = in_batch_terms(
            "--pixel-size-uncertainty 1% and --pixel-size 20 nm",
            Command::Analyze,
        );
        assert!(
            analyze.starts_with("--pixel-size-uncertainty (in a batch: the pixel_size_uncertainty")
                && analyze.contains(
                    "--pixel-size (in a batch: the pixel_size column; the batch's \
                 --pixel-size fills only files without one) 20 nm"
                ),
            "{analyze}"
        );
        assert_eq!(in_batch_terms("nothing", Command::Analyze), "nothing");
    }
}
