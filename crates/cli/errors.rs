//! How a failed run is reported (`docs/errors.md`): one line on stderr,
//! `contactscope: error: FILE[:LINE]: what is wrong (what was expected)`, with `--verbose` adding
//! the chain of causes, one per line. Usage errors of the command line get the same one-line form
//! (clap's first line and a pointer to `--help`) and exit code 2.

use std::fmt::Write as _;

/// Longest error line printed without `--verbose`; the rest is cut with `…`.
const MAX_LINE: usize = 400;

/// `text` on one line: control characters (newlines, tabs, escapes from a hostile file) become
/// spaces, runs of spaces one, and the line is cut at `max` bytes (on a character boundary).
pub fn one_line(text: &str, max: usize) -> String {
    let mut out = String::with_capacity(text.len().min(max + 4));
    let mut space = false;
    for c in text.chars() {
        let c = if c.is_control() { ' ' } else { c };
        if c == ' ' {
            if space {
                continue;
            }
            space = true;
        } else {
            space = false;
        }
        if out.len() + c.len_utf8() > max {
            out.push('…');
            return out.trim().to_string();
        }
        out.push(c);
    }
    out.trim().to_string()
}

/// The error and its causes joined by `: `, leaving out a cause whose text the line already
/// holds (library errors print their source themselves; `anyhow`'s context adds one more level).
pub fn chain_line(error: &anyhow::Error) -> String {
    let mut line = error.to_string();
    for cause in error.chain().skip(1) {
        let text = cause.to_string();
        if !line.contains(&text) {
            let _ = write!(line, ": {text}");
        }
    }
    line
}

/// The report of a failed run: one line, or with `verbose` the whole chain and the debug form.
pub fn report(error: &anyhow::Error, verbose: bool) -> String {
    if verbose {
        let mut text = format!("contactscope: error: {error}");
        for cause in error.chain().skip(1) {
            let _ = write!(text, "\n  caused by: {cause}");
        }
        let _ = write!(text, "\n  debug: {error:?}");
        text
    } else {
        format!(
            "contactscope: error: {}",
            one_line(&chain_line(error), MAX_LINE)
        )
    }
}

/// A clap usage error as one line: its first line without clap's `error: ` prefix, and where to
/// look. Help and version requests are not errors and are printed as clap renders them.
pub fn usage_line(error: &clap::Error) -> String {
    let rendered = error.render().to_string();
    // The first paragraph: the message and, for missing arguments, their names below it.
    let paragraph: Vec<&str> = rendered
        .lines()
        .map(str::trim)
        .skip_while(|l| l.is_empty())
        .take_while(|l| !l.is_empty())
        .collect();
    let mut text = paragraph.join(" ");
    // clap's suggestions ("tip: a similar subcommand exists: 'analyze'") follow in their own
    // paragraph: kept, on the one line.
    for tip in rendered
        .lines()
        .filter_map(|l| l.trim().strip_prefix("tip: "))
    {
        if tip.contains("similar") || tip.contains("to pass") {
            text.push_str(&format!("; {tip}"));
        }
    }
    let text = text.strip_prefix("error: ").unwrap_or(&text);
    let text = if text.is_empty() {
        "invalid command line"
    } else {
        text
    };
    format!(
        "contactscope: error: {} (see --help)",
        one_line(text, MAX_LINE)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_flattens_and_cuts() {
        assert_eq!(one_line("a\nb\t\tc\r\n", 100), "a b c");
        let long = "é".repeat(300);
        let cut = one_line(&long, 11);
        assert!(
            cut.ends_with('…') && cut.len() <= 11 + '…'.len_utf8(),
            "{cut}"
        );
    }

    #[test]
    fn chain_leaves_out_repeated_causes() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let lib = contactscope_jobs::Error::from(contactscope_formats::Error::io("a.tif", io));
        let e = anyhow::Error::new(lib).context("reading the series");
        assert_eq!(chain_line(&e), "reading the series: a.tif: no such file");
    }
}
