//! Tidy checks of the crates' dependencies, from `cargo metadata
//! --format-version 1 --no-deps` (the workspace's packages and the
//! dependencies their manifests declare) and, for the Python package
//! (outside the workspace), the same command on `python/Cargo.toml`:
//!
//! - **One door.** The `tricept` binary, the Python package and the
//!   examples depend on `tricept-ident` alone among the workspace's
//!   crates ([dev-dependencies] aside: tests bring their own independent
//!   readers).
//! - **No unused dependency.** Every `[dependencies]` entry of every crate
//!   is used in the sources of its library, binaries, benches or examples
//!   (`crate_name::` or `use crate_name`), like `cargo machete`. The
//!   workspace hack is exempt: its dependencies are there to unify
//!   features, not to be used.
//! - **The map's graph.** ARCHITECTURE.md's crate graph is `cargo
//!   metadata`'s: every arrow a dependency, every dependency an arrow
//!   pointing down; the map at most 250 lines.
//! - **Internal crates say so** in their first doc line.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use super::{strip, workspace};

/// `cargo metadata --format-version 1 --no-deps` of `manifest`.
fn metadata(manifest: &Path) -> Value {
    let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .arg("--manifest-path")
        .arg(manifest)
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "cargo metadata: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON")
}

/// Every package of the workspace and the Python package.
fn packages() -> Vec<Value> {
    let root = workspace();
    let mut all = Vec::new();
    for manifest in [root.join("Cargo.toml"), root.join("python/Cargo.toml")] {
        let m = metadata(&manifest);
        all.extend(m["packages"].as_array().cloned().unwrap_or_default());
    }
    all
}

/// The names of the workspace's own crates (`crates/*`).
fn workspace_crates(packages: &[Value]) -> BTreeSet<String> {
    let crates = workspace().join("crates");
    packages
        .iter()
        .filter(|p| Path::new(p["manifest_path"].as_str().unwrap_or("")).starts_with(&crates))
        .filter_map(|p| p["name"].as_str().map(String::from))
        .collect()
}

/// A package's normal (`[dependencies]`) entries: the name the code uses
/// (a rename, or the package's name with `-` as `_`) and the package.
fn normal_dependencies(package: &Value) -> Vec<(String, String)> {
    package["dependencies"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|d| d["kind"].is_null())
        .filter_map(|d| {
            let name = d["name"].as_str()?.to_string();
            let used_as = d["rename"].as_str().unwrap_or(&name).replace('-', "_");
            Some((used_as, name))
        })
        .collect()
}

/// A package's name, for messages.
fn name(package: &Value) -> &str {
    package["name"].as_str().unwrap_or("?")
}

#[test]
fn the_cli_python_and_examples_depend_on_the_door_alone() {
    let root = workspace();
    let packages = packages();
    let ours = workspace_crates(&packages);
    let mut checked = Vec::new();
    let mut wrong = Vec::new();
    for p in &packages {
        let manifest = PathBuf::from(p["manifest_path"].as_str().unwrap_or(""));
        let door_user = manifest == root.join("crates/cli/Cargo.toml")
            || manifest == root.join("python/Cargo.toml")
            || manifest.starts_with(root.join("examples"));
        if !door_user {
            continue;
        }
        checked.push(name(p).to_string());
        let internal: Vec<String> = normal_dependencies(p)
            .into_iter()
            .map(|(_, n)| n)
            .filter(|n| ours.contains(n) && n != "tricept-ident")
            .collect();
        if !internal.is_empty() {
            wrong.push(format!("{}: {}", name(p), internal.join(", ")));
        }
    }
    // The binary, the Python package and at least one example were seen.
    assert!(checked.contains(&"tricept-cli".to_string()), "{checked:?}");
    assert!(
        checked
            .iter()
            .any(|n| n == "tricept-python" || n.contains("py")),
        "{checked:?}"
    );
    assert!(checked.len() >= 3, "{checked:?}");
    assert!(
        wrong.is_empty(),
        "depend on internal crates besides tricept-ident (re-export what they need through the door):\n{}",
        wrong.join("\n")
    );
}

/// The code (comments and strings removed) of every `.rs` file under
/// `dir`, `tests` directories aside.
fn code_under(dir: &Path, out: &mut String) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "tests" && n != "target") {
                code_under(&p, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push_str(&strip(&std::fs::read_to_string(&p).unwrap_or_default()));
            out.push('\n');
        }
    }
}

/// Whether `code` uses the crate `krate`: `krate::` or `use krate` not
/// preceded by an identifier character (or `::`: a path inside another
/// crate).
fn uses(code: &str, krate: &str) -> bool {
    let bytes = code.as_bytes();
    let mut from = 0;
    while let Some(at) = code[from..].find(krate) {
        let start = from + at;
        let end = start + krate.len();
        from = end;
        let before_ok = start == 0 || {
            let b = bytes[start - 1];
            !(b.is_ascii_alphanumeric() || b == b'_' || b == b':')
        };
        if !before_ok {
            continue;
        }
        let after = &code[end..];
        if after.starts_with("::") {
            return true;
        }
        let head = code[..start].trim_end();
        if head.ends_with("use") || head.ends_with("extern crate") {
            let next = after.chars().next().unwrap_or(' ');
            if !(next.is_alphanumeric() || next == '_') {
                return true;
            }
        }
    }
    false
}

#[test]
fn every_dependency_is_used() {
    let mut unused = Vec::new();
    for p in packages() {
        if name(&p) == "tricept-workspace-hack" {
            continue;
        }
        let mut code = String::new();
        let mut dirs = BTreeSet::new();
        for t in p["targets"].as_array().into_iter().flatten() {
            let kinds: Vec<&str> = t["kind"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(Value::as_str)
                .collect();
            if kinds == ["test"] {
                continue;
            }
            if let Some(dir) = Path::new(t["src_path"].as_str().unwrap_or("")).parent() {
                dirs.insert(dir.to_path_buf());
            }
        }
        for dir in &dirs {
            code_under(dir, &mut code);
        }
        for (used_as, package) in normal_dependencies(&p) {
            if package == "tricept-workspace-hack" {
                continue;
            }
            if !uses(&code, &used_as) {
                unused.push(format!("{}: {package}", name(&p)));
            }
        }
    }
    assert!(
        unused.is_empty(),
        "[dependencies] entries no source uses (remove them, or make them dev-dependencies):\n{}",
        unused.join("\n")
    );
}

#[test]
fn the_use_finder_reads_paths_and_uses_only() {
    assert!(uses("fn f() { serde_json::to_string(&x) }", "serde_json"));
    assert!(uses("use rayon::prelude::*;", "rayon"));
    assert!(uses("use nalgebra;", "nalgebra"));
    assert!(!uses("use nalgebra_sparse::X;", "nalgebra"));
    assert!(!uses("let rayon_threads = 2;", "rayon"));
    assert!(!uses("use other::rayon::X;", "rayon"));
    assert!(!uses("my_serde_json::x()", "serde_json"));
}

#[test]
fn internal_crates_say_so_in_their_first_doc_line() {
    let crates = workspace().join("crates");
    let mut silent = Vec::new();
    let mut seen = 0;
    for e in std::fs::read_dir(&crates).unwrap().flatten() {
        let lib = e.path().join("src/lib.rs");
        let name = e.file_name().to_string_lossy().into_owned();
        if name == "ident" || !lib.exists() {
            continue;
        }
        seen += 1;
        let text = std::fs::read_to_string(&lib).unwrap_or_default();
        if !text.starts_with("//! internal: use tricept-ident") {
            silent.push(format!("crates/{name}/src/lib.rs"));
        }
    }
    assert!(seen >= 10, "{seen} internal crates");
    assert!(
        silent.is_empty(),
        "first doc line is not `//! internal: use tricept-ident`:\n{}",
        silent.join("\n")
    );
}

/// A drawn graph: its arrows and each crate's row.
type Drawn = (BTreeSet<(String, String)>, Vec<(String, usize)>);

/// The crate graph drawn in ARCHITECTURE.md (the fenced block after `##
/// Crate graph`): its arrows as `(from, to)` with full package names, and
/// each crate's row (the leaves' row last).
fn drawn_graph(map: &str) -> Drawn {
    let full = |short: &str| match short.trim() {
        "xtask" => "xtask".to_string(),
        s => format!("tricept-{s}"),
    };
    let after = map.split("## Crate graph").nth(1).unwrap_or("");
    let block = after.split("```").nth(1).unwrap_or("");
    let mut edges = BTreeSet::new();
    let mut rows = Vec::new();
    for (row, line) in block.lines().skip(1).enumerate() {
        if let Some(leaves) = line.strip_prefix("leaves:") {
            rows.extend(leaves.split(',').map(|c| (full(c), usize::MAX)));
        } else if let Some((from, to)) = line.split_once("->") {
            for f in from.split(',') {
                rows.push((full(f), row));
                for t in to.split(',') {
                    edges.insert((full(f), full(t)));
                }
            }
        }
    }
    (edges, rows)
}

#[test]
fn the_architecture_graph_is_cargo_metadata_s() {
    let map = std::fs::read_to_string(workspace().join("ARCHITECTURE.md")).unwrap();
    let (drawn, rows) = drawn_graph(&map);
    let packages = packages();
    let names: BTreeSet<String> = packages
        .iter()
        .filter_map(|p| p["name"].as_str().map(String::from))
        .collect();
    let hack = "tricept-workspace-hack";
    let mut real = BTreeSet::new();
    for p in &packages {
        for (_, dep) in normal_dependencies(p) {
            if names.contains(&dep) && dep != hack {
                real.insert((name(p).to_string(), dep));
            }
        }
    }
    let row_of = |c: &str| rows.iter().find(|(n, _)| n == c).map(|(_, r)| *r);
    let mut wrong = Vec::new();
    for (a, b) in drawn.difference(&real) {
        wrong.push(format!("drawn but not a dependency: {a} -> {b}"));
    }
    for (a, b) in real.difference(&drawn) {
        wrong.push(format!("a dependency not drawn: {a} -> {b}"));
    }
    for (a, b) in &real {
        if row_of(a) >= row_of(b) {
            wrong.push(format!("{b} is not drawn below {a}, which depends on it"));
        }
    }
    for n in &names {
        if row_of(n).is_none() {
            wrong.push(format!("{n} is not in the graph"));
        }
    }
    assert!(real.len() > 30, "only {} dependencies read", real.len());
    assert!(
        wrong.is_empty(),
        "ARCHITECTURE.md's crate graph against cargo metadata:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_graph_reader_expands_rows() {
    let map = "## Crate graph\n\n```text\na, b -> c, d\nc -> d\nleaves: d\n```\n";
    let (edges, rows) = drawn_graph(map);
    assert_eq!(edges.len(), 5);
    assert!(edges.contains(&("tricept-b".into(), "tricept-d".into())));
    assert_eq!(
        rows,
        vec![
            ("tricept-a".to_string(), 0),
            ("tricept-b".to_string(), 0),
            ("tricept-c".to_string(), 1),
            ("tricept-d".to_string(), usize::MAX)
        ]
    );
}

#[test]
fn the_architecture_map_is_at_most_250_lines() {
    let map = std::fs::read_to_string(workspace().join("ARCHITECTURE.md")).unwrap();
    let lines = map.lines().count();
    assert!(lines <= 250, "ARCHITECTURE.md: {lines} lines, over 250");
}
