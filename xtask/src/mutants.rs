//! `cargo xtask mutants [FILE...]`: mutation testing of the code that
//! decides whether a result can be trusted (issue 32), with
//! [cargo-mutants](https://mutants.rs) at a pinned version.
//!
//! Each decision file is mutated and every mutant run against the tests
//! of the packages that exercise it ([`TARGETS`]); a mutant the tests do
//! not notice ("missed") is a branch no test asserts. Equivalent mutants
//! (a change no input can observe) are excluded in `.cargo/mutants.toml`,
//! each with its reason. The run is in place (`--in-place`): a copy of
//! the tree would rebuild every dependency for each file; do not edit the
//! tree while it runs (cargo-mutants restores each file after its
//! mutants, and on Ctrl-C). The per-file counts are recorded in
//! docs/testing.md.

use std::path::{Path, PathBuf};
use std::process::Command;

use clap::Args;

/// The cargo-mutants version the counts of docs/testing.md were made with
/// (a newer one generates other mutants).
pub const PINNED: &str = "27.1.0";

/// Decision files, each with the package it is in and the packages whose
/// tests exercise it.
struct Target {
    /// Short name (the output directory under `target/mutants`).
    name: &'static str,
    /// Files mutated, relative to the workspace root.
    files: &'static [&'static str],
    /// The package the files belong to.
    package: &'static str,
    /// Packages whose tests run against every mutant.
    tests: &'static [&'static str],
}

/// The decision files mutated by default, in the order of docs/testing.md.
const TARGETS: &[Target] = &[
    Target {
        name: "verdict",
        files: &["crates/engine/src/verdict.rs"],
        package: "tricept-engine",
        tests: &["tricept-engine"],
    },
    Target {
        name: "atomic",
        files: &["crates/data/src/atomic.rs"],
        package: "tricept-data",
        tests: &["tricept-data"],
    },
    Target {
        name: "check",
        files: &[
            "crates/check/src/check.rs",
            "crates/check/src/parts.rs",
            "crates/check/src/changes.rs",
            "crates/check/src/noise.rs",
            "crates/check/src/screen.rs",
            "crates/check/src/design.rs",
            "crates/check/src/report.rs",
        ],
        package: "tricept-check",
        tests: &["tricept-check"],
    },
    Target {
        name: "diagnose",
        files: &[
            "crates/diagnose/src/select.rs",
            "crates/diagnose/src/plausibility.rs",
        ],
        package: "tricept-diagnose",
        tests: &["tricept-diagnose"],
    },
    Target {
        name: "deploy",
        files: &[
            "crates/diagnose/src/deploy.rs",
            "crates/diagnose/src/holdout.rs",
        ],
        package: "tricept-diagnose",
        tests: &["tricept-diagnose", "tricept-example-deploy"],
    },
    // The controller export writers (every file of the crate).
    Target {
        name: "export",
        files: &["crates/export/src/*.rs"],
        package: "tricept-export",
        tests: &["tricept-export"],
    },
    Target {
        name: "stats",
        files: &["crates/numerics/src/stats.rs"],
        package: "tricept-numerics",
        tests: &["tricept-numerics"],
    },
];

/// The part `.ci/run` runs: the identification verdict and the atomic
/// writes (80 s and 78 s in the last clean-clone CI run; the rest, hours, is
/// left to `cargo xtask mutants`, docs/testing.md).
pub const CI_TARGETS: [&str; 2] = ["verdict", "atomic"];

/// Arguments of `cargo xtask mutants`.
#[derive(Debug, Args)]
pub struct MutantsArgs {
    /// Files to mutate (a default decision file, or any `crates/*/src`
    /// file: tested with its own package); every default target when none.
    files: Vec<PathBuf>,
    /// Only the part CI runs ([`CI_TARGETS`]: the verdict and the atomic
    /// writes).
    #[arg(long, conflicts_with = "files")]
    ci: bool,
    /// List the mutants instead of testing them.
    #[arg(long)]
    list: bool,
    /// Parallel jobs of cargo-mutants with `--copy` (each builds and tests
    /// a mutant in its own copy of the tree).
    #[arg(short, long, default_value_t = 1)]
    jobs: usize,
    /// Run in a copy of the tree instead of in place (slower: the copy
    /// rebuilds every dependency).
    #[arg(long)]
    copy: bool,
    /// Build the mutated package at opt-level 0 without debug info (its
    /// dependencies as usual): about 8 times faster builds of each mutant,
    /// for a package whose tests are light (`tricept-numerics`: 11 s a
    /// mutant instead of 81 s on the loaded 2-core machine).
    #[arg(long)]
    fast_build: bool,
    /// Extra arguments passed to every cargo-mutants run (after `--`).
    #[arg(last = true)]
    extra: Vec<String>,
}

/// The workspace root (xtask's parent directory).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from(".."), Path::to_path_buf)
}

/// `cargo` as the one running this xtask.
fn cargo() -> Command {
    Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
}

/// Installs cargo-mutants at [`PINNED`] when `cargo mutants --version`
/// reports another version or none.
fn ensure_installed() -> Result<(), String> {
    let installed = cargo()
        .args(["mutants", "--version"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    let wanted = format!("cargo-mutants {PINNED}");
    if installed.as_deref() == Some(wanted.as_str()) {
        return Ok(());
    }
    eprintln!(
        "installing {wanted} (found {}): a few minutes",
        installed.as_deref().unwrap_or("none")
    );
    let status = cargo()
        .args(["install", "--locked", "cargo-mutants", "--version", PINNED])
        .status()
        .map_err(|e| format!("cargo install cargo-mutants: {e}"))?;
    if !status.success() {
        return Err(format!("cargo install cargo-mutants {PINNED} failed"));
    }
    Ok(())
}

/// The package a `crates/*/src` file belongs to (the `name` of the
/// nearest Cargo.toml above it).
fn package_of(file: &Path) -> Result<String, String> {
    let root = root();
    let mut dir = root.join(file);
    while dir.pop() && dir.starts_with(&root) {
        let Ok(manifest) = std::fs::read_to_string(dir.join("Cargo.toml")) else {
            continue;
        };
        let name = manifest
            .lines()
            .skip_while(|l| l.trim() != "[package]")
            .find_map(|l| l.trim().strip_prefix("name = "))
            .map(|n| n.trim_matches('"').to_string());
        if let Some(name) = name {
            return Ok(name);
        }
    }
    Err(format!("{}: not in a package", file.display()))
}

/// One cargo-mutants run: its name, files, package and test packages.
type Run = (String, Vec<String>, String, Vec<String>);

/// The runs for `args`: the default targets (those whose files exist), or
/// each named file with its target's test packages (its own package for a
/// file no target lists).
fn runs(args: &MutantsArgs) -> Result<Vec<Run>, String> {
    let owned = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let root = root();
    if args.files.is_empty() {
        return Ok(TARGETS
            .iter()
            .filter(|t| !args.ci || CI_TARGETS.contains(&t.name))
            .filter(|t| {
                // A glob's directory, or the file itself, must exist.
                t.files.iter().any(|f| {
                    let path = root.join(f);
                    path.exists() || (f.contains('*') && path.parent().is_some_and(Path::is_dir))
                })
            })
            .map(|t| {
                (
                    t.name.to_string(),
                    owned(t.files),
                    t.package.to_string(),
                    owned(t.tests),
                )
            })
            .collect());
    }
    args.files
        .iter()
        .map(|file| {
            let text = file.to_string_lossy().replace('\\', "/");
            if !root.join(file).is_file() {
                return Err(format!("{text}: no such file"));
            }
            let stem = file
                .file_stem()
                .map_or_else(|| "file".into(), |s| s.to_string_lossy().into_owned());
            Ok(
                match TARGETS.iter().find(|t| t.files.contains(&text.as_str())) {
                    Some(t) => (stem, vec![text], t.package.to_string(), owned(t.tests)),
                    None => {
                        let package = package_of(file)?;
                        (stem, vec![text], package.clone(), vec![package])
                    }
                },
            )
        })
        .collect()
}

/// The cargo-mutants arguments of one run.
fn mutants_args(run: &Run, args: &MutantsArgs, out: &Path) -> Vec<String> {
    let (_, files, package, tests) = run;
    let mut v = vec!["mutants".to_string()];
    for f in files {
        v.extend(["--file".into(), f.clone()]);
    }
    v.extend(["--package".into(), package.clone()]);
    for t in tests {
        v.extend(["--test-package".into(), t.clone()]);
    }
    if args.list {
        v.push("--list".into());
    } else {
        v.extend(["--output".into(), out.display().to_string()]);
        if args.copy {
            v.extend(["--jobs".into(), args.jobs.to_string()]);
        } else {
            // One tree: one mutant at a time.
            v.push("--in-place".into());
        }
    }
    if args.fast_build {
        for setting in ["opt-level=0", "debug=0"] {
            v.push(format!(
                "--cargo-arg=--config=profile.dev.package.\"{package}\".{setting}"
            ));
        }
    }
    v.extend(args.extra.iter().cloned());
    v
}

/// Lines of one of cargo-mutants' outcome lists (0 when absent).
fn count(out: &Path, list: &str) -> usize {
    std::fs::read_to_string(out.join("mutants.out").join(list))
        .map(|s| s.lines().filter(|l| !l.trim().is_empty()).count())
        .unwrap_or(0)
}

/// `cargo xtask mutants`: every run in turn, then a table of the outcomes;
/// fails when a mutant is missed or times out.
pub fn run(args: MutantsArgs) -> Result<(), String> {
    ensure_installed()?;
    let root = root();
    let mut rows = Vec::new();
    for r in runs(&args)? {
        let out = root.join("target").join("mutants").join(&r.0);
        std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
        let argv = mutants_args(&r, &args, &out);
        eprintln!("cargo {}", argv.join(" "));
        let started = std::time::Instant::now();
        let status = cargo()
            .current_dir(&root)
            .args(&argv)
            .status()
            .map_err(|e| format!("cargo mutants: {e}"))?;
        if args.list {
            continue;
        }
        // cargo-mutants exits 2 when mutants were missed, 3 on timeouts.
        if !matches!(status.code(), Some(0 | 2 | 3)) {
            return Err(format!("cargo mutants on {}: {status}", r.0));
        }
        rows.push((
            r.0.clone(),
            count(&out, "caught.txt"),
            count(&out, "missed.txt"),
            count(&out, "timeout.txt"),
            count(&out, "unviable.txt"),
            started.elapsed().as_secs(),
        ));
    }
    if args.list {
        return Ok(());
    }
    println!(
        "{:<10} {:>7} {:>7} {:>8} {:>9} {:>7}",
        "target", "caught", "missed", "timeout", "unviable", "time s"
    );
    for (name, caught, missed, timeout, unviable, secs) in &rows {
        println!("{name:<10} {caught:>7} {missed:>7} {timeout:>8} {unviable:>9} {secs:>7}");
    }
    let missed: usize = rows.iter().map(|r| r.2 + r.3).sum();
    if missed > 0 {
        return Err(format!(
            "{missed} mutants missed or timed out: see target/mutants/*/mutants.out/missed.txt"
        ));
    }
    Ok(())
}
