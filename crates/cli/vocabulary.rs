//! The command line's vocabulary, checked over every subcommand: one flag name and one syntax
//! per quantity (old names kept only as hidden aliases), and the examples at the end of every
//! `--help` parse as written.

use clap::CommandFactory;

use super::args::Forces;

/// Flag names that were once used for a quantity that now has another name: they may remain as
/// hidden aliases, never as a command's own flag.
const RETIRED: &[(&str, &str)] = &[
    ("loads", "forces"),
    ("normal-force", "forces"),
    ("experiment", "micrographs (images) or areas (areas.csv)"),
];

fn commands() -> Vec<clap::Command> {
    super::grammar().get_subcommands().cloned().collect()
}

/// The value `--forces TEXT` of `command` parses to (through the flag's own parser).
fn forces_of(command: &clap::Command, text: &str) -> Result<Vec<f64>, String> {
    let arg = command
        .get_arguments()
        .find(|a| a.get_long() == Some("forces"))
        .expect("the command has --forces");
    let matches = clap::Command::new("one-flag")
        .no_binary_name(true)
        .arg(arg.clone().required(false).allow_hyphen_values(true))
        .try_get_matches_from(["--forces", text])
        .map_err(|e| e.to_string())?;
    Ok(matches
        .get_one::<Forces>(arg.get_id().as_str())
        .expect("--forces parses to Forces")
        .0
        .clone())
}

#[test]
fn retired_names_are_only_hidden_aliases() {
    for command in commands() {
        for arg in command.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            if let Some((_, now)) = RETIRED.iter().find(|(old, _)| *old == long) {
                panic!("{} --{long}: call it --{now}", command.get_name());
            }
            let shown = arg.get_visible_aliases().unwrap_or_default();
            assert!(
                shown.is_empty(),
                "{} --{long}: aliases {shown:?} are shown in --help",
                command.get_name()
            );
        }
    }
    // The old names still work where they were used.
    let parses = |line: &str| {
        super::grammar()
            .try_get_matches_from(line.split_whitespace())
            .map_err(|e| e.to_string())
    };
    for line in [
        "contactscope simulate --topography a.npy --modulus 1GPa --model elastic --loads 4mN",
        "contactscope hertz s.csv --radius 290um --loads 4mN",
        "contactscope friction t.csv --normal-force 40mN",
        "contactscope synth-series --out s --loads 4,8mN",
        "contactscope compare --experiment m.csv --simulation sim --psf-fwhm 450nm",
        "contactscope fit-hardening --experiment a.csv --topography a.npy --modulus 1GPa",
    ] {
        parses(line).unwrap_or_else(|e| panic!("{line}: {e}"));
    }
}

#[test]
fn every_force_flag_takes_lists_and_ranges_in_one_syntax() {
    let mut seen = Vec::new();
    for command in commands() {
        let name = command.get_name().to_string();
        if !command
            .get_arguments()
            .any(|a| a.get_long() == Some("forces"))
        {
            continue;
        }
        let range = forces_of(&command, "1mN..100mN:3").unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(range.len(), 3, "{name}");
        assert!((range[1] - 0.01).abs() < 1e-12, "{name}: {range:?}");
        let list = forces_of(&command, "4,10,40mN").unwrap();
        assert_eq!(list, [4e-3, 10e-3, 40e-3], "{name}");
        assert!(forces_of(&command, "4,10,40").is_err(), "{name}: no unit");
        assert!(forces_of(&command, "400000mN").is_err(), "{name}: 400 N");
        // A 0 mN reference frame is a micrograph's force, never a simulated one.
        let zero = forces_of(&command, "0,4mN");
        let micrographs = ["analyze", "batch", "compare"].contains(&name.as_str());
        assert_eq!(zero.is_ok(), micrographs, "{name}: {zero:?}");
        seen.push(name);
    }
    seen.sort();
    assert_eq!(
        seen,
        [
            "analyze",
            "batch",
            "compare",
            "friction",
            "hertz",
            "simulate",
            "synth-series"
        ]
    );
}

#[test]
fn one_name_per_quantity() {
    for command in commands() {
        let name = command.get_name();
        let longs: Vec<&str> = command
            .get_arguments()
            .filter_map(|a| a.get_long())
            .collect();
        // A PSF is given the same ways wherever one is used.
        if longs.contains(&"psf-fwhm") {
            assert!(
                longs.contains(&"psf"),
                "{name} takes --psf-fwhm but not --psf"
            );
        }
        // Micrographs and measured areas have one name each.
        for long in &longs {
            assert!(
                !["images", "micrograph", "area", "force", "load"].contains(long),
                "{name} --{long}"
            );
        }
    }
}

#[test]
fn every_help_ends_with_examples_that_parse() {
    for command in commands() {
        let name = command.get_name().to_string();
        let help = command
            .get_after_help()
            .unwrap_or_else(|| panic!("{name}: no examples in --help"))
            .to_string();
        let lines: Vec<&str> = help
            .lines()
            .skip_while(|l| !l.starts_with("Examples:"))
            .skip(1)
            .collect();
        assert!(!lines.is_empty(), "{name}: {help}");
        assert!(
            lines
                .iter()
                .any(|l| l.trim_start().starts_with(&format!("contactscope {name}"))),
            "{name}: no example of the command itself"
        );
        for line in lines {
            // A remark in parentheses after two spaces is not part of the command.
            let line = line.trim().split("   (").next().unwrap_or_default();
            super::grammar()
                .try_get_matches_from(line.split_whitespace())
                .unwrap_or_else(|e| panic!("{name}: example `{line}` does not parse: {e}"));
        }
    }
}

#[test]
fn the_top_level_help_lists_every_command_with_a_summary() {
    let cli = super::Cli::command();
    for command in cli.get_subcommands() {
        let about = command
            .get_about()
            .map(|a| a.to_string())
            .unwrap_or_default();
        assert!(about.len() > 20, "{}: {about:?}", command.get_name());
        assert!(
            !about.contains("TIFF file"),
            "{}: every reader is meant, not only TIFF: {about}",
            command.get_name()
        );
    }
}
