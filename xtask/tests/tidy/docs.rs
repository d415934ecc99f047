//! Tidy checks of the door's docs (issue 49), read from the sources:
//!
//! - **Examples.** Every public item of tricept-ident has an example in
//!   its docs: its own items (public in a public module, or re-exported),
//!   the items it re-exports from internal crates (their docs are its
//!   pages) and its modules. Those still without one are listed in
//!   `tidy/without-example.txt`, a list that only shrinks.
//! - **Door paths.** No example on a door page names an internal crate:
//!   none of tricept-ident's (hidden lines included), no visible line of
//!   the re-exported items'. An internal item's example that needs its
//!   crate's paths is shown in that crate's docs only
//!   (`#[cfg_attr(any(doc, doctest), doc = ...)]`: dependents read its
//!   docs without `cfg(doc)`), and is not counted as the door's example.
//! - **Signatures.** The types the door's own public signatures name
//!   (`crates/ident/public-api.txt`, the items a user can reach) are the
//!   door's, std's, `serde_json`'s or generic parameters: each has a page
//!   under the door, and no signature spells an internal crate's path.
//!   The signatures of the re-exported internal items are not read here
//!   (their field and method types were checked on `cargo doc`'s pages).
//! - **Not only in `advanced`.** A type a signature outside `advanced`
//!   returns is exported outside `advanced` too (`advanced` "may change";
//!   what a stable call returns may not).

use std::collections::BTreeSet;

use super::docs_reader::{
    KINDS, door, door_items, example_lines, ident, internal_items, names_internal_crate, reexports,
};
use super::workspace;

#[test]
fn every_public_door_item_has_an_example_or_is_listed() {
    let has_example = |doc: &[String]| doc.iter().any(|l| l.trim().starts_with("```"));
    let mut missing = BTreeSet::new();
    for (item, doc) in door_items() {
        if !has_example(&doc) {
            missing.insert(item);
        }
    }
    for (item, docs) in internal_items() {
        if !docs.is_some_and(|(own, _)| has_example(&own)) {
            missing.insert(item);
        }
    }
    let list_file = workspace().join("xtask/tests/tidy/without-example.txt");
    let list = std::fs::read_to_string(&list_file).unwrap_or_default();
    let listed: BTreeSet<String> = list
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(str::to_string)
        .collect();
    let new: Vec<&String> = missing.difference(&listed).collect();
    let stale: Vec<&String> = listed.difference(&missing).collect();
    assert!(
        new.is_empty(),
        "door items without an example in their docs: {new:#?}"
    );
    assert!(
        stale.is_empty(),
        "{} lists items with an example now (or gone): {stale:#?}",
        list_file.display()
    );
}

#[test]
fn door_doc_examples_name_no_internal_crate() {
    let mut found = Vec::new();
    for (file, code) in door().0 {
        let doc: Vec<String> = code
            .lines()
            .map(str::trim)
            .filter_map(|l| l.strip_prefix("///").or(l.strip_prefix("//!")))
            .map(str::to_string)
            .collect();
        let lines = example_lines(&doc).into_iter().map(|(l, _)| l);
        found.extend(
            lines
                .filter(|l| names_internal_crate(l))
                .map(|l| format!("{}: {l}", file.display())),
        );
    }
    let md = std::fs::read_to_string(workspace().join("crates/ident/src/first_example.md"))
        .unwrap_or_default();
    found.extend(
        md.lines()
            .filter(|l| names_internal_crate(l))
            .map(|l| format!("first_example.md: {l}")),
    );
    let items = internal_items();
    for (item, docs) in &items {
        let (_, all) = docs.clone().unwrap_or_default();
        let visible = example_lines(&all)
            .into_iter()
            .filter(|(l, hidden)| !hidden && names_internal_crate(l));
        found.extend(visible.map(|(l, _)| format!("{item}: {l}")));
    }
    assert!(
        items.iter().filter(|(_, d)| d.is_some()).count() > 150,
        "too few internal docs read"
    );
    assert!(
        found.is_empty(),
        "door doc examples naming an internal crate: {found:#?}"
    );
}

#[test]
fn the_docs_reader_finds_examples_and_internal_paths() {
    let doc: Vec<String> = [
        "a",
        "```",
        "# use tricept_model::X;",
        "use tricept_ident::Y;",
        "tricept_data::f()",
        "```",
    ]
    .map(String::from)
    .to_vec();
    let lines = example_lines(&doc);
    assert_eq!(lines.len(), 3);
    assert!(lines[0].1 && !lines[1].1 && !lines[2].1);
    let flagged: Vec<bool> = lines.iter().map(|(l, _)| names_internal_crate(l)).collect();
    assert_eq!(flagged, [true, false, true]);
    let r = reexports("pub use tricept_kinematics::{Machine as GeometricMachine, batch::Verb};");
    assert_eq!(
        r[0],
        (
            vec!["tricept_kinematics".into(), "Machine".into()],
            "GeometricMachine".into()
        )
    );
    assert_eq!(r[1].1, "Verb");
}

/// Names a door signature may use besides the door's own.
const STD_NAMES: &[&str] = &[
    "AsRef", "Box", "BufRead", "Display", "Fn", "FnOnce", "Into", "Item", "Iterator", "Map",
    "Option", "Path", "PathBuf", "Read", "Result", "Self", "Send", "String", "Sync", "Value",
    "Vec", "Write",
];

#[test]
fn door_signatures_name_door_types_only() {
    let items = door_items();
    let (_, reexported) = door();
    let mut names: BTreeSet<String> = reexported.into_iter().map(|(_, n, _)| n).collect();
    names.extend(
        items
            .iter()
            .filter_map(|(i, _)| i.rsplit(' ').next().map(str::to_string)),
    );
    let listing = std::fs::read_to_string(workspace().join("crates/ident/public-api.txt"));
    let (mut read, mut wrong) = (0, Vec::new());
    // Lines `tricept_X: ...` are the re-exported internal items' (not read).
    for line in listing
        .unwrap_or_default()
        .lines()
        .filter(|l| !l.starts_with("tricept_"))
    {
        let (owner, item) = line.split_once(" :: ").unwrap_or(("", line));
        let owner = owner.rsplit(' ').next().unwrap_or("");
        let words: Vec<&str> = item.split(' ').collect();
        let mut after = words.iter().skip_while(|w| ["pub", "const"].contains(w));
        let first = after.next().unwrap_or(&"");
        let name = ident(if KINDS.contains(first) {
            after.next().unwrap_or(&"")
        } else {
            first
        });
        let reachable = if owner.is_empty() {
            names.contains(name)
        } else {
            names.contains(ident(owner))
        };
        if words.get(1).is_some_and(|k| ["use", "mod"].contains(k)) || !reachable {
            continue;
        }
        read += 1;
        // A constant's value is not shown on its page.
        let signature = item.split(" = ").next().unwrap_or("");
        let signature = &signature[signature.find(name).unwrap_or(0) + name.len()..];
        let mut rest = signature;
        while let Some(k) = rest.find(|c: char| c.is_ascii_uppercase()) {
            let word = ident(&rest[k..]);
            let preceded = rest[..k].ends_with(|c: char| c.is_alphanumeric() || c == '_');
            if !preceded && word.len() > 1 && !names.contains(word) && !STD_NAMES.contains(&word) {
                wrong.push(format!("{word} in `{line}`"));
            }
            rest = &rest[k + word.len().max(1)..];
        }
        if names_internal_crate(signature) {
            wrong.push(format!("an internal path in `{line}`"));
        }
    }
    assert!(read > 250, "only {read} signatures read");
    assert!(
        wrong.is_empty(),
        "door signatures naming what the door does not export: {wrong:#?}"
    );
}

#[test]
fn what_a_door_call_returns_is_not_only_in_advanced() {
    let (files, reexported) = door();
    let advanced = workspace().join("crates/ident/src/advanced.rs");
    let mut elsewhere: BTreeSet<String> = reexported
        .iter()
        .filter(|(_, _, f)| *f != advanced)
        .map(|(_, n, _)| n.clone())
        .collect();
    // Items written in a public module's own file (`calibrate/values.rs`
    // is private: its items are reachable where they are re-exported).
    let public_file = |file: &str| file == "lib.rs" || !file[..file.len() - 3].contains('/');
    elsewhere.extend(door_items().iter().filter_map(|(i, _)| {
        let (file, item) = i.split_once(": ")?;
        let own_file = file
            .strip_suffix("/mod.rs")
            .map_or(file.to_string(), |m| format!("{m}.rs"));
        (own_file != "advanced.rs" && public_file(&own_file))
            .then(|| item.rsplit(' ').next().unwrap_or("").to_string())
    }));
    // Types only (the foreign crates `advanced` re-exports are modules).
    let only_advanced: BTreeSet<&str> = reexported
        .iter()
        .filter(|(_, n, f)| *f == advanced && !elsewhere.contains(n))
        .filter(|(_, n, _)| n.starts_with(|c: char| c.is_ascii_uppercase()))
        .map(|(_, n, _)| n.as_str())
        .collect();
    assert!(files.contains_key(&advanced) && !only_advanced.is_empty());
    let listing = std::fs::read_to_string(workspace().join("crates/ident/public-api.txt"));
    let mut wrong = Vec::new();
    // Lines `tricept_X: ...` are the re-exported internal items' (not read).
    for line in listing
        .unwrap_or_default()
        .lines()
        .filter(|l| !l.starts_with("tricept_"))
    {
        let (owner, item) = line.split_once(" :: ").unwrap_or(("", line));
        let own = match owner.rsplit(' ').next().filter(|o| !o.is_empty()) {
            Some(owner) => ident(owner),
            None => ident(item.split("fn ").nth(1).unwrap_or("")),
        };
        let returned = item.split_once(") -> ").map_or("", |(_, r)| r);
        if own.is_empty() || only_advanced.contains(own) || !item.contains("fn ") {
            continue;
        }
        let named = returned
            .split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .find(|w| only_advanced.contains(w));
        if let Some(name) = named {
            wrong.push(format!("{name} in `{line}`"));
        }
    }
    assert!(
        wrong.is_empty(),
        "returned by a door call, exported only from `advanced`: {wrong:#?}"
    );
}
