//! The reader of `tidy/docs.rs`: the door's items and re-exports, the
//! docs of the internal items it re-exports, the code blocks of docs.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::{expand, workspace};

/// A re-export: its path, the name it is public under, its file.
type Reexport = (Vec<String>, String, PathBuf);
/// An item's own docs, and those with its `impl` blocks' docs.
pub(super) type Docs = (Vec<String>, Vec<String>);

pub(super) const KINDS: [&str; 8] = [
    "fn", "struct", "enum", "trait", "type", "const", "static", "mod",
];

/// The `.rs` files under `dir`, each with its code before its unit tests.
pub(super) fn sources(dir: &Path) -> BTreeMap<PathBuf, String> {
    let (mut out, mut stack) = (BTreeMap::new(), vec![dir.to_path_buf()]);
    while let Some(d) = stack.pop() {
        for p in std::fs::read_dir(&d)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
        {
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).unwrap_or_default();
                let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or("");
                out.insert(p, code.to_string());
            }
        }
    }
    out
}

/// The identifier `s` starts with.
pub(super) fn ident(s: &str) -> &str {
    let end = s.find(|c: char| !(c.is_alphanumeric() || c == '_'));
    &s[..end.unwrap_or(s.len())]
}

/// The `//!` lines of a file: a module's docs.
pub(super) fn module_doc(code: &str) -> Vec<String> {
    code.lines()
        .filter_map(|l| l.strip_prefix("//!"))
        .map(str::to_string)
        .collect()
}

/// The doc lines (`///`) above line `i`, through attributes and comments.
pub(super) fn doc_above(lines: &[&str], i: usize) -> Vec<String> {
    let mut doc = Vec::new();
    for line in lines[..i].iter().rev().map(|l| l.trim()) {
        if let Some(d) = line.strip_prefix("///") {
            doc.push(d.to_string());
        } else if !(line.starts_with("#[") || line.starts_with("//") || line.starts_with(')')) {
            break;
        }
    }
    doc.reverse();
    doc
}

/// Every `pub use` path of `code` with the name it is public under.
pub(super) fn reexports(code: &str) -> Vec<(Vec<String>, String)> {
    let mut out = Vec::new();
    for part in code.split("pub use ").skip(1) {
        let tree = part.split(';').next().unwrap_or("").replace(" as ", "@");
        for mut path in expand(&tree) {
            let last = path.pop().unwrap_or_default();
            let (name, alias) = last.split_once('@').unwrap_or((&last, &last));
            path.push(name.trim().to_string());
            out.push((path, alias.trim().to_string()));
        }
    }
    out
}

/// The door's files, and its re-exports: `(path, name, file)`.
pub(super) fn door() -> (BTreeMap<PathBuf, String>, Vec<Reexport>) {
    let files = sources(&workspace().join("crates/ident/src"));
    let reexports = files
        .iter()
        .flat_map(|(f, code)| reexports(code).into_iter().map(|(p, n)| (p, n, f.clone())))
        .collect();
    (files, reexports)
}

/// Every item of the door (`file: kind name`) with its docs.
pub(super) fn door_items() -> Vec<(String, Vec<String>)> {
    let (files, reexported) = door();
    let src = workspace().join("crates/ident/src");
    let lib = files.get(&src.join("lib.rs")).cloned().unwrap_or_default();
    let mut public = BTreeSet::from([src.join("lib.rs")]);
    for m in lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(ident)
    {
        public.extend([src.join(format!("{m}.rs")), src.join(m).join("mod.rs")]);
    }
    let exported: BTreeSet<&str> = reexported.iter().map(|(_, n, _)| n.as_str()).collect();
    let mut items = Vec::new();
    for (file, code) in &files {
        let lines: Vec<&str> = code.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            // Top-level items: a method is its type's part.
            let words: Vec<&str> = line.split(' ').collect();
            if words[0] != "pub" || !words.get(1).is_some_and(|k| KINDS.contains(k)) {
                continue;
            }
            let name = ident(words.get(2).unwrap_or(&""));
            if !public.contains(file) && !exported.contains(name) {
                continue;
            }
            let mut doc = doc_above(&lines, i);
            if words[1] == "mod" && line.ends_with(';') {
                let dir = file.parent().unwrap_or(&src);
                let child = [
                    dir.join(format!("{name}.rs")),
                    dir.join(name).join("mod.rs"),
                ];
                doc = module_doc(child.iter().find_map(|c| files.get(c)).map_or("", |s| s));
            }
            let at = file.strip_prefix(&src).unwrap_or(file).display();
            items.push((format!("{at}: {} {name}", words[1]), doc));
        }
    }
    assert!(items.len() > 90, "only {} door items found", items.len());
    items
}

/// The docs of an internal item (`tricept_x::...::Name`), in its crate or
/// those it re-exports from: its own, and those with its `impl` blocks'.
pub(super) fn internal_docs(path: &[String], crates: &BTreeMap<PathBuf, String>) -> Option<Docs> {
    let home = workspace()
        .join("crates")
        .join(path[0].trim_start_matches("tricept_").replace('_', "-"));
    if path.len() == 1 {
        // A crate re-exported as a module: every item of it is a page.
        let doc = module_doc(crates.get(&home.join("src/lib.rs"))?);
        let all = crates
            .iter()
            .filter(|(f, _)| f.starts_with(&home))
            .flat_map(|(_, c)| c.lines());
        let all = all.filter_map(|l| l.trim().strip_prefix("///").or(l.strip_prefix("//!")));
        return Some((doc, all.map(str::to_string).collect()));
    }
    let name = path.last()?.as_str();
    let order = crates
        .iter()
        .filter(|(f, _)| f.starts_with(&home))
        .chain(crates.iter());
    let (mut own, mut all) = (None, Vec::new());
    for (file, code) in order {
        if own.is_some() && !file.starts_with(&home) {
            break;
        }
        let lines: Vec<&str> = code.lines().collect();
        let mut in_impl = false;
        for (i, line) in lines.iter().enumerate() {
            let words: Vec<&str> = line
                .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .collect();
            let t: Vec<&str> = line.trim_start().splitn(3, ' ').collect();
            if own.is_none()
                && t[0] == "pub"
                && t.len() == 3
                && KINDS.contains(&t[1])
                && ident(t[2]) == name
            {
                own = Some(doc_above(&lines, i));
            }
            if line.starts_with("impl") && words.contains(&name) {
                in_impl = true;
            } else if *line == "}" {
                in_impl = false;
            } else if let Some(d) = line.trim_start().strip_prefix("///").filter(|_| in_impl) {
                all.push(d.to_string());
            }
        }
    }
    let own = own?;
    all.extend(own.iter().cloned());
    Some((own, all))
}

/// The lines of the code blocks of `doc`, each with whether it is hidden.
pub(super) fn example_lines(doc: &[String]) -> Vec<(String, bool)> {
    let (mut inside, mut out) = (false, Vec::new());
    for l in doc.iter().map(|l| l.trim()) {
        if l.starts_with("```") {
            inside = !inside;
        } else if inside {
            out.push((l.to_string(), l == "#" || l.starts_with("# ")));
        }
    }
    out
}

/// Whether `line` names a `tricept_` crate other than the door.
pub(super) fn names_internal_crate(line: &str) -> bool {
    line.split("tricept_")
        .skip(1)
        .any(|rest| !ident(rest).is_empty() && ident(rest) != "ident")
}

/// The door's re-exports of internal items, with their docs: the docs
/// on a one-line `pub use` (rustdoc shows them first) and the item's.
pub(super) fn internal_items() -> Vec<(String, Option<Docs>)> {
    let mut crates = sources(&workspace().join("crates"));
    crates.retain(|p, _| p.components().any(|c| c.as_os_str() == "src"));
    let (files, reexported) = door();
    let mut door_docs = BTreeMap::new();
    for (file, code) in &files {
        let lines: Vec<&str> = code.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            if line.trim_start().starts_with("pub use ") && line.ends_with(';') {
                for (_, name) in reexports(line) {
                    door_docs.insert((file.clone(), name), doc_above(&lines, i));
                }
            }
        }
    }
    let internal = reexported
        .into_iter()
        .filter(|(p, _, _)| p[0].starts_with("tricept_") && p[0] != "tricept_ident");
    let items: Vec<_> = internal
        .map(|(path, name, file)| {
            let at = file.file_name().unwrap_or_default().to_string_lossy();
            let mut docs = internal_docs(&path, &crates);
            if let (Some((own, _)), Some(door)) =
                (&mut docs, door_docs.get(&(file.clone(), name.clone())))
            {
                own.splice(0..0, door.iter().cloned());
            }
            (format!("{at}: {name} ({})", path.join("::")), docs)
        })
        .collect();
    assert!(
        items.len() > 150,
        "only {} re-exported internal items",
        items.len()
    );
    items
}
