//! Mutation fuzzer over every command (`docs/errors.md`), on the stable toolchain: each case copies valid
//! seed inputs (made fresh by `seeds`) into a folder of its own, mutates one of them (bytes, header
//! numbers, sizes, truncation, lines; `mutate`) and/or the numbers of its option values, runs the
//! release binary under a time and memory limit (`run`) and classifies the result: a panic, hang,
//! abort, partial output, overwritten input, left-over work folder or non-finite number in the
//! output fails the campaign, and so do more than 0.5 % unclean error messages and more than
//! 0.5 % of runs ending in an error that names neither an input file nor a flag.
//!
//! * `cargo test --release --test integration fuzz_short` runs the short campaign (600 cases, seed 1; about a minute
//!   on 2 cores) that CI runs.
//! * The long run is documented in `docs/errors.md`:
//!   `FUZZ_CASES=30000 FUZZ_SEED=7 cargo test --release --test integration fuzz_long -- --ignored --nocapture`.
//!
//! Environment: `FUZZ_CASES`, `FUZZ_SEED`, `FUZZ_JOBS` (parallel cases, default 2),
//! `FUZZ_TIMEOUT_S` (default 20), `FUZZ_MEMORY_MIB` (address-space limit, default 4096),
//! `FUZZ_KEEP` (folder for failing cases, default `target/fuzz-failures`), `FUZZ_ONLY` (only the
//! templates whose name starts with it, e.g. `batch`).

mod cases;
mod mutate;
mod pipes;
mod run;
mod seeds;
mod vendor;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use cases::Template;
use run::{run_case, Class, Limits};

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn copy_tree(from: &Path, to: &Path) {
    if from.is_dir() {
        fs::create_dir_all(to).unwrap();
        for e in fs::read_dir(from).unwrap().flatten() {
            copy_tree(&e.path(), &to.join(e.file_name()));
        }
    } else {
        fs::create_dir_all(to.parent().unwrap()).unwrap();
        fs::copy(from, to).unwrap();
    }
}

/// One case: the template, its arguments after mutation, and what was mutated.
struct Case {
    template: &'static Template,
    args: Vec<String>,
    mutation: String,
}

/// Copy the template's inputs into `dir` and mutate them; deterministic in (seed, index).
fn prepare(
    templates: &[&'static Template],
    seeds: &Path,
    dir: &Path,
    seed: u64,
    index: usize,
) -> Case {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1_000_003).wrapping_add(index as u64));
    let template = *templates.choose(&mut rng).unwrap();
    fs::create_dir_all(dir).unwrap();
    for c in template.copies {
        copy_tree(&seeds.join(c), &dir.join(c));
    }
    let mut mutation = Vec::new();
    let mutate_file = !template.mutable.is_empty() && rng.random_bool(0.75);
    if mutate_file {
        let target = template.mutable.choose(&mut rng).unwrap();
        let path = dir.join(target);
        let mut data = fs::read(&path).unwrap();
        let what = mutate::mutate_file(&mut rng, &mut data);
        fs::write(&path, data).unwrap();
        mutation.push(format!("{target}: {what}"));
    }
    let mut args: Vec<String> = template.args.iter().map(|s| s.to_string()).collect();
    if !mutate_file || rng.random_bool(0.3) {
        // Values of options that are not paths: the token after a `--flag`.
        let eligible: Vec<usize> = (1..args.len())
            .filter(|&i| {
                args[i - 1].starts_with("--")
                    && !args[i].starts_with("--")
                    && !args[i].starts_with("OUT")
                    && !dir.join(&args[i]).exists()
            })
            .collect();
        for _ in 0..rng.random_range(1..=2) {
            if let Some(&i) = eligible.choose(&mut rng) {
                let new = mutate::mutate_value(&mut rng, &args[i]);
                mutation.push(format!("{} {} → {new}", args[i - 1], args[i]));
                args[i] = new;
            }
        }
    }
    Case {
        template,
        args,
        mutation: mutation.join("; "),
    }
}

/// Run a campaign of `cases` cases; returns the counts per class and the failures.
fn campaign(cases: usize, seed: u64) {
    let jobs: usize = env_or("FUZZ_JOBS", 2);
    let limits = Limits {
        time: Duration::from_secs_f64(env_or("FUZZ_TIMEOUT_S", 20.0)),
        memory_kib: env_or("FUZZ_MEMORY_MIB", 4096u64) * 1024,
    };
    let keep = std::env::var("FUZZ_KEEP")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/fuzz-failures"));
    let base = tempfile::tempdir().unwrap();
    let seeds_dir = base.path().join("seeds");
    fs::create_dir_all(&seeds_dir).unwrap();
    seeds::build(&seeds_dir);
    vendor::build(&seeds_dir);
    // Every template whose seeds exist (the real vendor samples may be absent).
    let templates: Vec<&'static Template> = cases::TEMPLATES
        .iter()
        .chain(vendor::TEMPLATES)
        .filter(|t| t.copies.iter().all(|c| seeds_dir.join(c).exists()))
        .filter(|t| std::env::var("FUZZ_ONLY").map_or(true, |p| t.name.starts_with(&p)))
        .collect();

    let next = AtomicUsize::new(0);
    let counts: Mutex<BTreeMap<(&str, Class), usize>> = Mutex::new(BTreeMap::new());
    let failures: Mutex<Vec<String>> = Mutex::new(Vec::new());
    let start = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= cases {
                    break;
                }
                let dir = base.path().join(format!("case-{i}"));
                let case = prepare(&templates, &seeds_dir, &dir, seed, i);
                let out = dir.join(
                    case.args
                        .iter()
                        .find(|a| a.starts_with("OUT"))
                        .map_or("OUT", String::as_str),
                );
                let outcome = run_case(&dir, &case.args, &out, &limits);
                *counts
                    .lock()
                    .unwrap()
                    .entry((case.template.name, outcome.class))
                    .or_default() += 1;
                let report = |class: Class| {
                    format!(
                        "case {i} [{}] {class:?}: {} | mutation: {} | contactscope {}",
                        case.template.name,
                        outcome.detail,
                        case.mutation,
                        case.args.join(" ")
                    )
                };
                if outcome.class.is_failure()
                    || matches!(outcome.class, Class::Unclean | Class::Unnamed)
                {
                    let kept = keep.join(format!("seed{seed}-case{i}"));
                    let _ = fs::remove_dir_all(&kept);
                    copy_tree(&dir, &kept);
                    let _ = fs::write(kept.join("CASE.txt"), report(outcome.class));
                    failures.lock().unwrap().push(report(outcome.class));
                }
                let _ = fs::remove_dir_all(&dir);
                let _ = fs::remove_file(dir.with_extension("stdout"));
                let _ = fs::remove_file(dir.with_extension("stderr"));
            });
        }
    });
    let counts = counts.into_inner().unwrap();
    let failures = failures.into_inner().unwrap();
    let mut by_class: BTreeMap<Class, usize> = BTreeMap::new();
    let mut by_template: BTreeMap<&str, [usize; 3]> = BTreeMap::new();
    for (&(t, c), &n) in &counts {
        *by_class.entry(c).or_default() += n;
        let row = by_template.entry(t).or_default();
        row[match c {
            Class::Ok => 0,
            Class::CleanError => 1,
            _ => 2,
        }] += n;
    }
    println!(
        "fuzz: {cases} cases over {} templates, seed {seed}, {jobs} jobs, {:.0} s",
        templates.len(),
        start.elapsed().as_secs_f64()
    );
    for (t, [ok, err, bad]) in &by_template {
        println!("  {t:<22} ok {ok:>6}  clean error {err:>6}  other {bad:>4}");
    }
    for (c, n) in &by_class {
        println!("  {c:?}: {n}");
    }
    for f in failures.iter().take(60) {
        println!("  {f}");
    }
    let failed: usize = by_class
        .iter()
        .filter(|(c, _)| c.is_failure())
        .map(|(_, n)| n)
        .sum();
    let unclean = by_class.get(&Class::Unclean).copied().unwrap_or(0);
    let unnamed = by_class.get(&Class::Unnamed).copied().unwrap_or(0);
    let errors = unclean + unnamed + by_class.get(&Class::CleanError).copied().unwrap_or(0);
    assert_eq!(
        failed,
        0,
        "{failed} failing cases (kept under {})",
        keep.display()
    );
    assert!(
        unclean as f64 <= 0.005 * errors.max(1) as f64,
        "{unclean} of {errors} error exits unclean (at most 0.5 %)"
    );
    assert!(
        unnamed as f64 <= 0.005 * cases as f64,
        "{unnamed} of {cases} runs end in an error naming neither an input nor a flag (at most \
         0.5 %)"
    );
}

/// The short campaign CI runs.
#[test]
fn fuzz_short() {
    campaign(env_or("FUZZ_CASES", 600), env_or("FUZZ_SEED", 1));
}

/// The long campaign (30 000 cases by default): `-- --ignored`.
#[test]
#[ignore]
fn fuzz_long() {
    campaign(env_or("FUZZ_CASES", 30_000), env_or("FUZZ_SEED", 7));
}
