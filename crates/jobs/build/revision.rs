// The source revision a front-end is built from, for the provenance records of its outputs
// (`contactscope_jobs::provenance`). Included by the build scripts of the command line (the
// repository root's `build.rs`) and of the Python package (`python/build.rs`): each sets the
// environment variable `CONTACTSCOPE_SOURCE_REVISION` of its crate to the git commit it is built
// from, with ` (modified)` when tracked files differ from that commit, or to `unknown` outside a
// checkout of this repository (a source archive or sdist, a crate from a registry, even when
// unpacked inside some other git repository), and `CONTACTSCOPE_LONG_VERSION` to what
// `--version` prints: `0.2.0 (source <commit>)`, or the version alone when the commit is unknown.
//
// `workspace` is the repository root relative to the build script's crate; the script reruns when
// the commit, the index or any source file changes, so that the recorded revision is never stale.

fn emit_source_revision(workspace: &str) {
    use std::process::Command;
    let git = |args: &[&str]| -> Option<String> {
        let out = Command::new("git")
            .arg("-C")
            .arg(workspace)
            .args(args)
            .output()
            .ok()?;
        out.status
            .success()
            .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
    };
    // Only a checkout whose top level is this workspace: an sdist unpacked inside another
    // repository must not record that repository's commit.
    let ours = match (
        git(&["rev-parse", "--show-toplevel"]),
        std::fs::canonicalize(workspace),
    ) {
        (Some(top), Ok(here)) => std::fs::canonicalize(top).is_ok_and(|top| top == here),
        _ => false,
    };
    let head = if ours {
        git(&["rev-parse", "HEAD"])
    } else {
        None
    };
    let revision = match head {
        Some(commit) if commit.len() == 40 => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty {
                format!("{commit} (modified)")
            } else {
                commit
            }
        }
        _ => "unknown".to_string(),
    };
    if let Some(git_dir) = git(&["rev-parse", "--absolute-git-dir"]).filter(|_| ours) {
        for name in ["HEAD", "index", "packed-refs", "refs/heads"] {
            println!("cargo:rerun-if-changed={git_dir}/{name}");
        }
    }
    for dir in ["crates", "python/src", "python/python", "Cargo.toml", "tests", "benches"] {
        println!("cargo:rerun-if-changed={workspace}/{dir}");
    }
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rustc-env=CONTACTSCOPE_SOURCE_REVISION={revision}");
    let version = std::env::var("CARGO_PKG_VERSION").unwrap_or_default();
    let long = if revision == "unknown" {
        version
    } else {
        format!("{version} (source {revision})")
    };
    println!("cargo:rustc-env=CONTACTSCOPE_LONG_VERSION={long}");
}
