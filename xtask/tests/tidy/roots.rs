//! Tidy check of the internal crates' roots (issue 46: "internal crates
//! ... keep their roots small").
//!
//! Every crate under `crates/` but the door (`tricept-ident`, whose root
//! is its own curated list, checked in `tidy.rs`) names at most
//! [`MAX_ROOT_NAMES`] public items at its root: each `pub mod`, each `pub`
//! item written in `lib.rs` and each name a root `pub use` brings in (a
//! function and a module of the same name count once). The rest lives in
//! public modules named for what they hold, and callers name the module:
//! `tricept_engine::fusion::fuse`, not `tricept_engine::fuse`. A glob
//! re-export at the root (`pub use x::*`) is refused: its names cannot be
//! counted.

use std::collections::BTreeSet;

use super::{public_names, strip, without_tests, workspace};

/// The most public names an internal crate's root may hold: its modules
/// and the handful of items a caller needs first (engine, diagnose and
/// data hold 16-17 today).
const MAX_ROOT_NAMES: usize = 20;

/// Every internal crate's root: `(crate directory, its lib.rs text)`.
fn internal_roots() -> Vec<(String, String)> {
    let crates = workspace().join("crates");
    let mut roots = Vec::new();
    for e in std::fs::read_dir(&crates).into_iter().flatten().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let lib = e.path().join("src/lib.rs");
        if name == "ident" || !lib.exists() {
            continue;
        }
        roots.push((name, std::fs::read_to_string(&lib).unwrap_or_default()));
    }
    roots.sort();
    roots
}

/// Whether a root's code re-exports a glob (`pub use a::*;`), tests aside.
fn has_glob_reexport(code: &str) -> bool {
    let code = without_tests(&strip(code));
    code.split("pub use ").skip(1).any(|rest| {
        let tree = rest.split(';').next().unwrap_or("");
        tree.contains('*')
    })
}

/// What is wrong with one root (`name`'s lib.rs text): too many names, or
/// a glob re-export.
fn root_problems(name: &str, code: &str) -> Vec<String> {
    let names = public_names(code);
    let mut wrong = Vec::new();
    if names.len() > MAX_ROOT_NAMES {
        wrong.push(format!(
            "crates/{name}/src/lib.rs: {} public names at the root, over {MAX_ROOT_NAMES}: {}",
            names.len(),
            names.iter().cloned().collect::<Vec<_>>().join(", ")
        ));
    }
    if has_glob_reexport(code) {
        wrong.push(format!(
            "crates/{name}/src/lib.rs: a glob `pub use` at the root (name what it re-exports)"
        ));
    }
    wrong
}

#[test]
fn internal_crate_roots_stay_small() {
    let roots = internal_roots();
    assert!(roots.len() >= 10, "only {} internal crates", roots.len());
    // The engine's root (86 names before issue 46) was read with its
    // modules.
    let engine = roots.iter().find(|(n, _)| n == "engine");
    assert!(
        engine.is_some_and(|(_, code)| public_names(code).contains("fusion")),
        "the engine's root was not read"
    );
    let wrong: Vec<String> = roots
        .iter()
        .flat_map(|(name, code)| root_problems(name, code))
        .collect();
    assert!(
        wrong.is_empty(),
        "internal crate roots over their cap (move items into public modules named for what \
         they hold, and name the module at the callers):\n{}",
        wrong.join("\n")
    );
}

/// The counter counts what a root makes public, once per name; the check
/// fails one name over the cap and on a glob.
#[test]
fn the_root_check_counts_modules_items_and_reexports() {
    let code = "pub mod identify;\nmod error;\npub use identify::{Identification, identify};\n\
                pub use error::IdentError;\npub const LIMIT: f64 = 1.0;\n\
                pub(crate) use error::Hidden;\nuse std::path::Path;\n";
    let names: BTreeSet<String> = public_names(code);
    let expected = ["identify", "Identification", "IdentError", "LIMIT"];
    assert_eq!(
        names,
        expected
            .iter()
            .map(|s| s.to_string())
            .collect::<BTreeSet<_>>()
    );
    assert!(root_problems("a", code).is_empty());
    assert!(has_glob_reexport("pub use a::{b::*, C};\n"));
    assert!(!has_glob_reexport("use a::*;\npub use b::C;\n"));
    assert_eq!(root_problems("a", "pub use a::*;\n").len(), 1);
    let items = |n: usize| -> String { (0..n).map(|k| format!("pub fn f{k}() {{}}\n")).collect() };
    assert!(root_problems("a", &items(MAX_ROOT_NAMES)).is_empty());
    assert_eq!(root_problems("a", &items(MAX_ROOT_NAMES + 1)).len(), 1);
}
