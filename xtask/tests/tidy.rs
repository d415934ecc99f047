//! Tidy checks of the workspace's structure, in the spirit of
//! rust-analyzer's tidy tests: the import graph between the files of every
//! crate (`crates/*/src`, `xtask/src`, `examples/*/src`, `fuzz/src`).
//!
//! - **Layers.** A crate root may declare layers: `// Layer N: job` comment
//!   lines in `lib.rs`, each followed by the `mod` declarations of its
//!   layer, bottom (1) to top. A file imports only from its own layer or
//!   those below: any `crate::` (or `super::`, or child) path that runs
//!   upward fails, and every module must be in a layer.
//! - **No circles.** No two files of a crate import each other, directly
//!   or through others, except the pairs listed in [`ALLOWED_CIRCLES`].
//! - **The map.** ARCHITECTURE.md names every crate directory, and every
//!   repository path it names exists.
//! - **Dependencies** (`tidy/deps.rs`): the binary, the Python package and
//!   the examples depend on the door alone; no dependency goes unused.
//! - **Small roots** (`tidy/roots.rs`): an internal crate's root names at
//!   most 20 public items; the rest is in modules named for what they hold.
//! - **No flags in the libraries** (`tidy/flags.rs`): no string literal of
//!   a library crate or the Python package names a command-line flag.
//! - **The door's docs** (`tidy/docs.rs`): every public item of
//!   tricept-ident has an example, in door paths only; its signatures name
//!   types it exports.
//!
//! An edge is a path in a file's code outside its tests (`#[cfg(test)]`
//! items) that resolves to another file's module; a path to an item that a
//! module re-exports from a child (`pub use child::Item`) resolves to the
//! child. A module's re-export of its own children is its facade, not a
//! dependency. Paths that macros build are not seen.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

#[path = "tidy/deps.rs"]
mod deps;
#[path = "tidy/docs.rs"]
mod docs;
#[path = "tidy/docs_reader.rs"]
mod docs_reader;
#[path = "tidy/flags.rs"]
mod flags;
#[path = "tidy/roots.rs"]
mod roots;

/// Circles that may stay: `(crate directory, files)`, with why.
const ALLOWED_CIRCLES: &[(&str, &[&str])] = &[
    // One type's impl split over two files: the 2-DOF head's methods of
    // `Machine` live beside the head.
    ("crates/kinematics", &["head", "machine"]),
];

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

/// The source directories checked, relative to the workspace.
fn source_dirs(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for parent in ["crates", "examples"] {
        let Ok(entries) = std::fs::read_dir(root.join(parent)) else {
            continue;
        };
        let mut dirs: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path().join("src")))
            .filter(|p| p.is_dir())
            .collect();
        dirs.sort();
        out.extend(dirs);
    }
    out.push(root.join("xtask/src"));
    out.push(root.join("fuzz/src"));
    out.into_iter().filter(|p| p.is_dir()).collect()
}

/// A module: its path below the crate root (`["fusion", "estimate"]`).
type Module = Vec<String>;

fn label(m: &Module) -> String {
    if m.is_empty() {
        "(root)".into()
    } else {
        m.join("::")
    }
}

/// Every `.rs` file of `src` with its module path.
fn modules(src: &Path) -> BTreeMap<Module, PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    walk(src, &mut files);
    let mut out = BTreeMap::new();
    for f in files {
        let Ok(rel) = f.strip_prefix(src) else {
            continue;
        };
        let mut parts: Module = rel
            .iter()
            .map(|s| s.to_string_lossy().trim_end_matches(".rs").to_string())
            .collect();
        if parts.last().is_some_and(|l| l == "mod") {
            parts.pop();
        }
        if parts.len() == 1 && (parts[0] == "lib" || parts[0] == "main") {
            parts.clear();
        }
        out.insert(parts, f);
    }
    out
}

/// The code of a file without comments, string and character literals
/// (each replaced by a space, so that nothing inside them reads as a
/// path).
fn strip(text: &str) -> String {
    strip_keeping(text, false)
}

/// The code of a file without comments (doc comments and their examples
/// included), string literals kept.
fn without_comments(text: &str) -> String {
    strip_keeping(text, true)
}

/// The code of a file without comments, every string literal kept (raw
/// strings too).
fn without_comments_keeping_raw(text: &str) -> String {
    strip_with(text, true, true)
}

/// [`strip`], keeping the string literals when `strings` (character
/// literals and raw strings are dropped either way).
fn strip_keeping(text: &str, strings: bool) -> String {
    strip_with(text, strings, false)
}

/// [`strip_keeping`], keeping raw strings too when `strings && raw`.
fn strip_with(text: &str, strings: bool, raw: bool) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < c.len() {
        let next = c.get(i + 1).copied();
        if c[i] == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && next == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c[i] == 'r' && (next == Some('#') || next == Some('"')) && !ident_before(&c, i) {
            // A raw string: r"..." or r#"..."#.
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            j += 1;
            while j < c.len() {
                if c[j] == '"' && (0..hashes).all(|h| c.get(j + 1 + h) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            if strings && raw {
                out.extend(&c[i..j.min(c.len())]);
            } else {
                out.push(' ');
            }
            i = j;
        } else if c[i] == '"' {
            let start = i;
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            if strings {
                out.extend(&c[start..i.min(c.len())]);
            } else {
                out.push(' ');
            }
        } else if c[i] == '\'' {
            // A character literal ('x', '\n', '\u{..}') or a lifetime.
            if next == Some('\\') {
                let mut j = i + 2;
                while j < c.len() && c[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
                out.push(' ');
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
                out.push(' ');
            } else {
                out.push(c[i]);
                i += 1;
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

fn ident_before(c: &[char], i: usize) -> bool {
    i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_')
}

/// The code without the items under `#[cfg(test)]` (a test module, a
/// test-only `use`).
fn without_tests(code: &str) -> String {
    let mut out = String::new();
    let mut rest = code;
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let after = &rest[at + "#[cfg(test)]".len()..];
        // The item ends at its first `;` outside braces, or its closing
        // brace.
        let mut depth = 0usize;
        let mut end = after.len();
        for (k, ch) in after.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                ';' if depth == 0 => {
                    end = k + 1;
                    break;
                }
                _ => {}
            }
        }
        rest = &after[end..];
    }
    out.push_str(rest);
    out
}

/// A path found in a file: whether it is a re-export (`pub use`), and
/// whether the file's own code uses the name it re-exports.
struct Found {
    path: Vec<String>,
    reexport: bool,
    used: bool,
}

/// Splits a use tree (`crate::{a::B, c::*}`) into its paths.
fn expand(tree: &str) -> Vec<Vec<String>> {
    let tree = tree.trim();
    if let Some(inner) = tree.strip_prefix('{') {
        let inner = inner.strip_suffix('}').unwrap_or(inner);
        let mut parts = Vec::new();
        let (mut depth, mut start) = (0usize, 0usize);
        for (k, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth = depth.saturating_sub(1),
                ',' if depth == 0 => {
                    parts.push(&inner[start..k]);
                    start = k + 1;
                }
                _ => {}
            }
        }
        parts.push(&inner[start..]);
        return parts
            .into_iter()
            .filter(|p| !p.trim().is_empty())
            .flat_map(expand)
            .collect();
    }
    match tree.find("::") {
        Some(k) => {
            let head = tree[..k].trim().to_string();
            expand(&tree[k + 2..])
                .into_iter()
                .map(|mut t| {
                    t.insert(0, head.clone());
                    t
                })
                .collect()
        }
        None => {
            let name = tree.split(" as ").next().unwrap_or("").trim().to_string();
            vec![vec![name]]
        }
    }
}

fn is_ident(ch: char) -> bool {
    ch.is_alphanumeric() || ch == '_'
}

/// Every `use` path and every `a::b` path in the code. A re-export whose
/// name the module's own code uses is a dependency too.
fn paths(code: &str) -> Vec<Found> {
    let mut out = Vec::new();
    let mut rest = String::new();
    // Use statements first (blanked out of the code scanned for inline
    // paths).
    let mut i = 0;
    while let Some(ch) = code[i..].chars().next() {
        let at_word = !code[..i].chars().next_back().is_some_and(is_ident);
        if at_word && code[i..].starts_with("use ") {
            let end = code[i..].find(';').map_or(code.len(), |e| i + e);
            let before = code[..i].trim_end();
            let reexport = before.ends_with("pub") || before.ends_with(')');
            for path in expand(&code[i + 4..end]) {
                out.push(Found {
                    path,
                    reexport,
                    used: !reexport,
                });
            }
            rest.push(' ');
            i = (end + 1).min(code.len());
        } else {
            rest.push(ch);
            i += ch.len_utf8();
        }
    }
    // Inline paths: runs of `ident::ident::...`; and the words of the code.
    let mut words = BTreeSet::new();
    let chars: Vec<char> = rest.chars().collect();
    let mut k = 0;
    while k < chars.len() {
        if is_ident(chars[k]) && (k == 0 || !(is_ident(chars[k - 1]) || chars[k - 1] == ':')) {
            let mut segments = Vec::new();
            let mut j = k;
            loop {
                let start = j;
                while j < chars.len() && is_ident(chars[j]) {
                    j += 1;
                }
                segments.push(chars[start..j].iter().collect::<String>());
                if chars.get(j) == Some(&':') && chars.get(j + 1) == Some(&':') {
                    j += 2;
                    if chars.get(j).is_some_and(|c| is_ident(*c)) {
                        continue;
                    }
                }
                break;
            }
            if segments.len() > 1 {
                out.push(Found {
                    path: segments,
                    reexport: false,
                    used: true,
                });
            } else {
                words.insert(segments.remove(0));
            }
            k = j.max(k + 1);
        } else {
            k += 1;
        }
    }
    for f in out.iter_mut().filter(|f| f.reexport) {
        f.used = f.path.last().is_some_and(|name| words.contains(name));
    }
    out
}

/// A crate's files, what each re-exports from its children, and the
/// edges between them.
struct Graph {
    modules: BTreeMap<Module, PathBuf>,
    edges: BTreeMap<Module, BTreeSet<Module>>,
}

fn graph(src: &Path) -> Graph {
    let modules = modules(src);
    let mut found: BTreeMap<Module, Vec<Found>> = BTreeMap::new();
    for (m, file) in &modules {
        let text = std::fs::read_to_string(file).unwrap_or_default();
        found.insert(m.clone(), paths(&without_tests(&strip(&text))));
    }
    // Items each module re-exports from a child: name -> child.
    let mut reexports: BTreeMap<Module, BTreeMap<String, Module>> = BTreeMap::new();
    for (m, list) in &found {
        for f in list.iter().filter(|f| f.reexport) {
            let mut target = m.clone();
            let mut p = f.path.as_slice();
            if p.first().is_some_and(|s| s == "self") {
                p = &p[1..];
            }
            let mut child = target.clone();
            child.extend(p.first().cloned());
            if p.len() < 2 || !modules.contains_key(&child) {
                continue;
            }
            target = child;
            if let Some(name) = p.last() {
                reexports
                    .entry(m.clone())
                    .or_default()
                    .insert(name.clone(), target);
            }
        }
    }
    let resolve = |from: &Module, path: &[String]| -> Option<Module> {
        let mut at: Module;
        let mut p = path;
        match p.first().map(String::as_str) {
            Some("crate") => {
                at = Vec::new();
                p = &p[1..];
            }
            Some("super") => {
                at = from.clone();
                while p.first().is_some_and(|s| s == "super") {
                    at.pop()?;
                    p = &p[1..];
                }
            }
            Some("self") => {
                at = from.clone();
                p = &p[1..];
            }
            Some(first) => {
                // A path relative to the module: a child module's only.
                let mut child = from.clone();
                child.push(first.to_string());
                if !modules.contains_key(&child) {
                    return None;
                }
                at = from.clone();
            }
            None => return None,
        }
        for s in p {
            let mut child = at.clone();
            child.push(s.clone());
            if modules.contains_key(&child) {
                at = child;
                continue;
            }
            // An item: through the module's re-exports to its file.
            while let Some(target) = reexports.get(&at).and_then(|r| r.get(s)) {
                if *target == at {
                    break;
                }
                at = target.clone();
            }
            break;
        }
        Some(at)
    };
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (m, list) in &found {
        for f in list {
            let Some(target) = resolve(m, &f.path) else {
                continue;
            };
            // A facade re-exporting its own children.
            let own_child = target.len() > m.len() && target.starts_with(m);
            if target == *m || (f.reexport && !f.used && own_child) {
                continue;
            }
            edges.entry(m.clone()).or_default().insert(target);
        }
    }
    Graph { modules, edges }
}

/// Strongly connected components with more than one module.
fn circles(g: &Graph) -> Vec<BTreeSet<Module>> {
    struct State<'a> {
        g: &'a Graph,
        index: BTreeMap<Module, usize>,
        low: BTreeMap<Module, usize>,
        stack: Vec<Module>,
        on: BTreeSet<Module>,
        out: Vec<BTreeSet<Module>>,
    }
    fn visit(s: &mut State<'_>, v: &Module) {
        let i = s.index.len();
        s.index.insert(v.clone(), i);
        s.low.insert(v.clone(), i);
        s.stack.push(v.clone());
        s.on.insert(v.clone());
        let next: Vec<Module> = s.g.edges.get(v).into_iter().flatten().cloned().collect();
        for w in next {
            if !s.index.contains_key(&w) {
                visit(s, &w);
                let lw = s.low[&w];
                let lv = s.low.get_mut(v).map_or(0, |x| {
                    *x = (*x).min(lw);
                    *x
                });
                let _ = lv;
            } else if s.on.contains(&w) {
                let iw = s.index[&w];
                if let Some(x) = s.low.get_mut(v) {
                    *x = (*x).min(iw);
                }
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = BTreeSet::new();
            while let Some(w) = s.stack.pop() {
                s.on.remove(&w);
                let done = w == *v;
                comp.insert(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in g.modules.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The layers a crate root declares: top-level module -> (layer, job).
fn layers(root_file: &Path) -> BTreeMap<String, (usize, String)> {
    let text = std::fs::read_to_string(root_file).unwrap_or_default();
    let mut out = BTreeMap::new();
    let mut current: Option<(usize, String)> = None;
    for line in text.lines() {
        let line = line.trim();
        if let Some(rest) = line.strip_prefix("// Layer ") {
            let (n, job) = rest.split_once(':').unwrap_or((rest, ""));
            current = n.trim().parse().ok().map(|n| (n, job.trim().to_string()));
            continue;
        }
        let decl = line
            .strip_prefix("pub mod ")
            .or_else(|| line.strip_prefix("pub(crate) mod "))
            .or_else(|| line.strip_prefix("mod "));
        if let (Some(name), Some(layer)) = (decl.and_then(|d| d.strip_suffix(';')), &current) {
            out.insert(name.trim().to_string(), layer.clone());
        }
    }
    out
}

fn relative(root: &Path, p: &Path) -> String {
    p.strip_prefix(root).unwrap_or(p).display().to_string()
}

#[test]
fn no_import_runs_up_a_crate_s_layers() {
    let root = workspace();
    let mut problems = Vec::new();
    let mut layered = 0;
    for src in source_dirs(&root) {
        let declared = layers(&src.join("lib.rs"));
        if declared.is_empty() {
            continue;
        }
        layered += 1;
        let g = graph(&src);
        let layer_of = |m: &Module| m.first().and_then(|top| declared.get(top));
        for m in g.modules.keys().filter(|m| !m.is_empty()) {
            if layer_of(m).is_none() {
                problems.push(format!(
                    "{}: module `{}` is in no layer of its crate's lib.rs",
                    relative(&root, &src),
                    label(m)
                ));
            }
        }
        for (from, targets) in &g.edges {
            let Some((lf, jf)) = layer_of(from) else {
                continue;
            };
            for to in targets {
                // The crate root is the top: its items are not below anyone.
                let upward = match layer_of(to) {
                    Some((lt, jt)) if lt > lf => Some(format!("layer {lt}, {jt}")),
                    Some(_) => None,
                    None => Some("the crate root".to_string()),
                };
                if let Some(up) = upward {
                    problems.push(format!(
                        "{}: `{}` (layer {lf}, {jf}) imports `{}` ({up}): upward",
                        relative(&root, &src),
                        label(from),
                        label(to)
                    ));
                }
            }
        }
    }
    assert!(layered >= 2, "the layered crates were not found");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn no_import_circles_between_files() {
    let root = workspace();
    let mut problems = Vec::new();
    let mut allowed_seen = BTreeSet::new();
    for src in source_dirs(&root) {
        let g = graph(&src);
        let krate = relative(&root, src.parent().unwrap_or(&src));
        for circle in circles(&g) {
            let names: BTreeSet<String> = circle.iter().map(label).collect();
            let allowed = ALLOWED_CIRCLES.iter().position(|(c, files)| {
                *c == krate && files.iter().map(|f| f.to_string()).collect::<BTreeSet<_>>() == names
            });
            if let Some(i) = allowed {
                allowed_seen.insert(i);
                continue;
            }
            let edges: Vec<String> = circle
                .iter()
                .flat_map(|a| {
                    g.edges
                        .get(a)
                        .into_iter()
                        .flatten()
                        .filter(|b| circle.contains(*b))
                        .map(move |b| format!("{} -> {}", label(a), label(b)))
                })
                .collect();
            problems.push(format!("{krate}: import circle: {}", edges.join(", ")));
        }
    }
    // An allowed circle that is gone leaves the list.
    for (i, (krate, files)) in ALLOWED_CIRCLES.iter().enumerate() {
        if !allowed_seen.contains(&i) {
            problems.push(format!(
                "{krate}: the allowed circle {files:?} is gone: remove it from ALLOWED_CIRCLES"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The longest a file of `crates/*/src` may be (ARCHITECTURE.md): a file
/// that grows is split by job into a module directory.
const MAX_FILE_LINES: usize = 900;

/// The headroom kept under [`MAX_FILE_LINES`]: a file at the cap breaks at
/// its next edit, so none may come within this many lines of it.
const HEADROOM_LINES: usize = 50;

#[test]
fn no_crate_source_file_comes_within_50_lines_of_the_900_line_cap() {
    let root = workspace();
    let mut problems = Vec::new();
    let mut files = 0;
    for src in source_dirs(&root)
        .iter()
        .filter(|s| s.starts_with(root.join("crates")))
    {
        for path in modules(src).values() {
            files += 1;
            let lines = std::fs::read_to_string(path).map_or(0, |t| t.lines().count());
            if lines > MAX_FILE_LINES - HEADROOM_LINES {
                problems.push(format!(
                    "{}: {lines} lines, within {HEADROOM_LINES} of the cap {MAX_FILE_LINES}: split it by job into a module directory",
                    relative(&root, path)
                ));
            }
        }
    }
    assert!(files > 100, "only {files} crate source files were found");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The parser itself: paths in use trees, inline paths, strings and
/// comments ignored, tests cut.
#[test]
fn the_parser_reads_paths() {
    let code = r#"
use crate::{a::B, c::{d::E, F as G}};
pub use child::Thing;
// use crate::commented::Out;
fn f() { let s = "crate::in_string::X"; crate::inline::call(); 'a'; }
#[cfg(test)]
mod tests { use crate::only_tests::T; }
"#;
    let found: Vec<(String, bool)> = paths(&without_tests(&strip(code)))
        .into_iter()
        .map(|f| (f.path.join("::"), f.reexport))
        .collect();
    let want = [
        ("crate::a::B", false),
        ("crate::c::d::E", false),
        ("crate::c::F", false),
        ("child::Thing", true),
        ("crate::inline::call", false),
    ];
    for (p, r) in want {
        assert!(found.contains(&(p.to_string(), r)), "{p}: {found:?}");
    }
    assert!(!found.iter().any(|(p, _)| p.contains("commented")
        || p.contains("in_string")
        || p.contains("only_tests")));
}

/// The repository paths ARCHITECTURE.md names: backquoted text that starts
/// with a top-level directory of the repository (`crates/...`,
/// `docs/...`, ...), without patterns (`*`, `<name>`).
fn named_paths(map: &str) -> Vec<String> {
    const TOP: &[&str] = &[
        "crates/",
        "xtask/",
        "benches/",
        "examples/",
        "fixtures/",
        "docs/",
        "fuzz/",
        ".ci/",
    ];
    map.split('`')
        .skip(1)
        .step_by(2)
        .filter(|s| TOP.iter().any(|t| s.starts_with(t)))
        .filter(|s| !s.contains(['*', '<', ' ']))
        .map(str::to_string)
        .collect()
}

/// ARCHITECTURE.md is the map of the crates: every crate directory of the
/// workspace (`crates/*`, `examples/*`, `xtask`, `benches`) is named in
/// it, and every repository path it names exists.
#[test]
fn the_architecture_map_names_every_crate_and_only_paths_that_exist() {
    let root = workspace();
    let map = std::fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap_or_default();
    assert!(!map.is_empty(), "ARCHITECTURE.md is missing");
    let mut problems = Vec::new();
    let mut crates = vec!["xtask".to_string(), "benches".to_string()];
    for parent in ["crates", "examples"] {
        let Ok(entries) = std::fs::read_dir(root.join(parent)) else {
            problems.push(format!("no {parent}/ directory"));
            continue;
        };
        for e in entries.flatten() {
            if e.path().join("Cargo.toml").is_file() {
                crates.push(format!("{parent}/{}", e.file_name().to_string_lossy()));
            }
        }
    }
    for c in &crates {
        if !map.contains(&format!("`{c}`")) && !map.contains(&format!("`{c}/")) {
            problems.push(format!("ARCHITECTURE.md does not name `{c}`"));
        }
    }
    let paths = named_paths(&map);
    for p in &paths {
        if !root.join(p).exists() {
            problems.push(format!("ARCHITECTURE.md names `{p}`, which does not exist"));
        }
    }
    assert!(crates.len() >= 15, "the crates were not found: {crates:?}");
    assert!(paths.len() >= 10, "too few paths found: {paths:?}");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The path reader itself: top-level paths only, patterns left out.
#[test]
fn the_map_reader_finds_repository_paths() {
    let found = named_paths(
        "a `crates/x/src/lib.rs` and `docs/` but not `lib.rs`, `crates/*/src`, \
         `tests/<crate>/main.rs` or `crates/a b`; `.ci/run`",
    );
    assert_eq!(found, ["crates/x/src/lib.rs", "docs/", ".ci/run"]);
}

// One vocabulary of effects (issue 27): an effect of the registry is named
// in its own file and its registry line, nowhere else in the libraries'
// code; every other file reaches it through the registry.

/// The effects checked, each with its report name and its variant
/// (`EffectName::TubeTwist`, the simulator's input `TubeTwist`).
const ONE_FILE_EFFECTS: &[(&str, &str)] = &[
    ("tube-twist", "TubeTwist"),
    ("encoder-eccentricity", "EncoderEccentricity"),
    ("compliance", "Compliance"),
];

/// Whether `code` names the effect: its report name quoted, or its variant
/// as a whole identifier.
fn names_effect(code: &str, name: &str, variant: &str) -> bool {
    if code.contains(&format!("\"{name}\"")) {
        return true;
    }
    code.match_indices(variant).any(|(at, _)| {
        let before = code[..at].chars().next_back();
        let after = code[at + variant.len()..].chars().next();
        !before.is_some_and(is_ident) && !after.is_some_and(is_ident)
    })
}

/// The files of `crates/*/src` whose code outside tests names the effect.
fn files_naming(root: &Path, name: &str, variant: &str) -> Vec<String> {
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir(root.join("crates")) else {
        return found;
    };
    let mut stack: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path().join("src")))
        .collect();
    while let Some(p) = stack.pop() {
        if p.is_dir() {
            if let Ok(entries) = std::fs::read_dir(&p) {
                stack.extend(entries.filter_map(|e| e.ok().map(|e| e.path())));
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            let text = std::fs::read_to_string(&p).unwrap_or_default();
            if names_effect(&without_tests(&without_comments(&text)), name, variant) {
                found.push(relative(root, &p));
            }
        }
    }
    found.sort();
    found
}

/// `tube-twist`, `encoder-eccentricity` and `compliance` are each named in
/// at most 2 files of the libraries' code: the effect's own file and the
/// registry line (`crates/model/src/effects/mod.rs`).
#[test]
fn an_effect_is_named_in_its_file_and_the_registry_only() {
    let root = workspace();
    let registry = "crates/model/src/effects/mod.rs".to_string();
    for (name, variant) in ONE_FILE_EFFECTS {
        let files = files_naming(&root, name, variant);
        let own = format!("crates/model/src/effects/{}.rs", name.replace('-', "_"));
        assert!(
            files.contains(&own) && files.contains(&registry),
            "{name}: not found in its file and the registry: {files:?}"
        );
        assert!(
            files.len() <= 2,
            "{name} is named in {} files (at most 2: its file and the registry line): {files:?}",
            files.len()
        );
    }
}

/// The counter itself: a name in a comment or a test does not count, a
/// quoted name or a whole variant does.
#[test]
fn the_effect_counter_reads_code_only() {
    let code = "// \"tube-twist\" and TubeTwist in a comment\n/// TubeTwist in a doc\nfn f() {}\n#[cfg(test)]\nmod tests { const X: &str = \"tube-twist\"; }\n";
    assert!(!names_effect(
        &without_tests(&without_comments(code)),
        "tube-twist",
        "TubeTwist"
    ));
    for named in [
        "const X: &str = \"tube-twist\";",
        "let e = EffectName::TubeTwist;",
    ] {
        assert!(
            names_effect(&without_comments(named), "tube-twist", "TubeTwist"),
            "{named}"
        );
    }
    assert!(!names_effect(
        "TubeTwister; tube-twist-ish",
        "tube-twist",
        "TubeTwist"
    ));
}

// The door's root (issue 27): `tricept-ident`'s root is a curated list,
// like grep-searcher's. A new public item goes into its workflow's module
// or into `tricept_ident::advanced` unless it is one of these kinds; then
// it is added here.

/// Every name `crates/ident/src/lib.rs` makes public at the crate root,
/// by kind.
const DOOR_ROOT: &[&str] = &[
    // The workflows: one module each (its function, request and result).
    "calibrate",
    "check",
    "compensate",
    "detectability",
    "diagnosis",
    "effects",
    "export",
    "fleet",
    "identifiability",
    "kinematics",
    "plan",
    "report",
    "simulate",
    // The error and the exit codes.
    "EXIT_INADEQUATE",
    "EXIT_INPUT",
    "EXIT_NOT_CONVERGED",
    "EXIT_OK",
    "EXIT_OTHER",
    "Error",
    "ErrorCause",
    "ErrorKind",
    "Setting",
    // The file-system failure under an error (`Error::file_failure`).
    "FileFailure",
    // The two inputs every request is made of, and what they load into:
    // the machine `MachineInput::load` returns and the data set
    // `DataInput::load` returns (a door signature's type is the door's,
    // not `advanced`'s).
    "DataInput",
    "Dataset",
    "LoadedMachine",
    "MachineInput",
    // The one shape of every workflow's result (issue 49): a program that
    // handles any result names these, whichever workflow it calls.
    "Outcome",
    "WriteOptions",
    "WritesMachine",
    "Written",
    // Everything else, behind one module.
    "advanced",
];

/// `tree` with every `name as alias` replaced by `alias`.
fn renamed(tree: &str) -> String {
    let mut parts = tree.split(" as ");
    let mut out = parts.next().unwrap_or_default().to_string();
    for part in parts {
        let kept = out.trim_end_matches(is_ident).len();
        out.truncate(kept);
        out.push_str(part);
    }
    out
}

/// The names a crate root's code makes public: the last segment (or the
/// alias) of every `pub use` path, and every `pub` item's name.
fn public_names(code: &str) -> BTreeSet<String> {
    let code = without_tests(&strip(code));
    let mut names = BTreeSet::new();
    let words: Vec<&str> = code.split_whitespace().collect();
    for (k, w) in words.iter().enumerate() {
        if *w != "pub" {
            continue;
        }
        let item = [
            "mod", "fn", "struct", "enum", "const", "static", "type", "trait", "macro",
        ];
        if words.get(k + 1).is_some_and(|w| item.contains(w))
            && let Some(name) = words.get(k + 2)
        {
            names.insert(name.chars().take_while(|c| is_ident(*c)).collect());
        }
    }
    let mut rest = code.as_str();
    while let Some(at) = rest.find("pub use ") {
        let before = &rest[..at];
        let after = &rest[at + "pub use ".len()..];
        let end = after.find(';').unwrap_or(after.len());
        if !before.ends_with(|c: char| is_ident(c)) {
            for path in expand(&renamed(&after[..end])) {
                if let Some(name) = path.last() {
                    names.insert(name.clone());
                }
            }
        }
        rest = &after[end..];
    }
    names
}

/// The door's root is the curated list: nothing more (a new item goes into
/// `advanced` or into [`DOOR_ROOT`] with its kind), nothing less (the list
/// stays true).
#[test]
fn the_door_s_root_is_its_curated_list() {
    let lib = workspace().join("crates/ident/src/lib.rs");
    let code = std::fs::read_to_string(&lib).unwrap_or_default();
    assert!(!code.is_empty(), "{} is missing", lib.display());
    let root = public_names(&code);
    let curated: BTreeSet<String> = DOOR_ROOT.iter().map(|s| s.to_string()).collect();
    let extra: Vec<&String> = root.difference(&curated).collect();
    let missing: Vec<&String> = curated.difference(&root).collect();
    assert!(
        extra.is_empty(),
        "tricept-ident's root grew past its curated list (xtask/tests/tidy.rs DOOR_ROOT): {extra:?}; \
         put them in `tricept_ident::advanced`, or add them to the list with their kind"
    );
    assert!(
        missing.is_empty(),
        "DOOR_ROOT names what tricept-ident's root no longer has: {missing:?}"
    );
    // 24: `ErrorCause` (issue 49), which every program that handles an
    // error matches on, beside `Error` and `ErrorKind`; 25: `Setting`,
    // which `Error::setting` returns (the request setting an error is
    // about, named by each program its own way); 30: the result's
    // shape (`Outcome`, `WritesMachine`), how a result writes its file
    // (`WriteOptions`, `Written`), shared by calibrate, diagnosis and fleet,
    // and `LoadedMachine`, which the root's `MachineInput::load` returns;
    // 32: `Dataset` (what `DataInput::load` returns) and `FileFailure`
    // (what `Error::file_failure` returns), out of `advanced`.
    assert!(root.len() <= 32, "{} names at the root", root.len());
}

/// One result shape (issue 49): every workflow function of the door (a
/// top-level `pub fn` whose `Ok` type is a `pub struct` of its own file)
/// returns a result that implements `tricept_ident::Outcome`, through the
/// door's `outcome!` macro, which implements the trait from the result's
/// own methods (so the compiler checks their signatures).
#[test]
fn every_workflow_result_has_the_one_shape() {
    let src = workspace().join("crates/ident/src");
    let mut results = Vec::new();
    let mut missing = Vec::new();
    // The workflows' modules: the lower-case names of the root's list.
    let workflow = |m: &Module| {
        m.first().is_some_and(|name| {
            name != "advanced"
                && DOOR_ROOT.contains(&name.as_str())
                && name.starts_with(char::is_lowercase)
        })
    };
    let files = modules(&src);
    for path in files.iter().filter(|(m, _)| workflow(m)).map(|(_, p)| p) {
        let code = without_tests(&strip(&std::fs::read_to_string(path).unwrap_or_default()));
        let flat = code.split_whitespace().collect::<Vec<_>>().join(" ");
        // Top-level functions only: methods are indented.
        let mut lines = code.lines();
        while let Some(line) = lines.next() {
            if !line.starts_with("pub fn ") {
                continue;
            }
            let mut signature = line.to_string();
            while !signature.contains('{') {
                match lines.next() {
                    Some(next) => signature.push_str(next.trim()),
                    None => break,
                }
            }
            let Some(ok) = signature
                .split("-> Result<")
                .nth(1)
                .and_then(|r| r.split(',').next())
                .map(str::trim)
            else {
                continue;
            };
            let declared = flat.contains(&format!("pub struct {ok} {{"));
            if !declared {
                continue;
            }
            results.push(ok.to_string());
            let shaped = flat.contains(&format!("outcome!({ok})"))
                || flat.contains(&format!("outcome!(writes {ok})"));
            if !shaped {
                missing.push(format!("{}: {ok}", path.display()));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "workflow results without the one shape (`crate::outcome::outcome!(RESULT);`): {missing:?}"
    );
    // calibrate, check, compensate, detectability, diagnose, effects,
    // export, fleet, identifiability, plan, report, simulate, solve_point.
    results.sort();
    results.dedup();
    assert!(results.len() >= 13, "only {results:?} found");
}

/// One machine input (issue 27): every request field that holds a machine
/// is a `MachineInput`, so a downstream user learns one way to give it.
#[test]
fn every_request_takes_the_one_machine_input() {
    let src = workspace().join("crates/ident/src");
    let files = modules(&src);
    assert!(files.len() > 10, "{} holds too few files", src.display());
    let mut fields = 0;
    let mut other = Vec::new();
    for (module, path) in &files {
        let code = without_tests(&strip(&std::fs::read_to_string(path).unwrap_or_default()));
        for line in code.lines().map(str::trim) {
            if let Some(ty) = line.strip_prefix("pub machine:") {
                fields += 1;
                if ty.trim().trim_end_matches(',') != "MachineInput" {
                    other.push(format!("{}: {line}", label(module)));
                }
            }
        }
    }
    assert!(
        other.is_empty(),
        "requests with their own machine type: {other:?}"
    );
    // calibrate, identifiability, plan, check, diagnose, detectability,
    // simulate and export.
    assert!(
        fields >= 8,
        "only {fields} request fields `pub machine:` found"
    );
}

/// The root reader itself: re-exports with braces and renames, public
/// items, and not `pub(crate)` re-exports nor test items.
#[test]
fn the_root_reader_finds_public_names() {
    let names = public_names(
        "mod a;\npub mod b;\npub use a::{C, d::{E, F as G}};\npub use h::I as J;\n\
         pub(crate) use a::K;\npub fn l() {}\npub struct M;\npub const N: u8 = 0;\n\
         // pub use a::Commented;\npub use nalgebra;\n#[cfg(test)]\npub use a::T;\n",
    );
    let expected = ["C", "E", "G", "J", "b", "l", "M", "N", "nalgebra"];
    assert_eq!(
        names,
        expected
            .iter()
            .map(|s| s.to_string())
            .collect::<BTreeSet<_>>()
    );
}

/// tricept-ident's public API, as text: every public item of its sources
/// (`pub fn`, `struct`, `enum`, `trait`, `type`, `const`, `mod`, `use`
/// and public fields, each with its signature up to its body and the item
/// it belongs to), the setters `request::setters!` generates, and the
/// items the door re-exports from internal crates (their fields and
/// methods, listed under their crate: a field of a re-exported `Gain` is
/// the door's API as much as its own), sorted. Not read: items of a whole
/// crate re-exported as a module (`advanced::plot`) and trait methods
/// given by a derive. A stand-in for `cargo semver-checks`, which
/// needs a published baseline: the listing is kept in
/// `crates/ident/public-api.txt`, and a change of the door's API fails
/// until the listing is updated with it (`BLESS=1 cargo test -p xtask
/// --test tidy public_api`), so that every change is declared in review
/// (and in CHANGELOG.md).
fn public_api(root: &Path) -> Vec<String> {
    let mut items = BTreeSet::new();
    let (door_files, door_reexports) = docs_reader::door();
    for text in door_files.values() {
        items.extend(api_items(text));
        items.extend(generated_setters(text));
    }
    // The internal items the door re-exports are its API too: their
    // fields and methods, listed under their crate.
    let mut reexported: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (path, _, _) in door_reexports {
        if let (Some(krate), Some(name)) = (path.first(), path.last())
            && krate.starts_with("tricept_")
            && path.len() > 1
        {
            reexported
                .entry(krate.clone())
                .or_default()
                .insert(name.clone());
        }
    }
    for (krate, names) in &reexported {
        let dir = root
            .join("crates")
            .join(krate.trim_start_matches("tricept_"))
            .join("src");
        for text in docs_reader::sources(&dir).values() {
            let of_door = api_items(text)
                .into_iter()
                .filter(|i| names.contains(subject(i)));
            items.extend(of_door.map(|i| format!("{krate}: {i}")));
        }
    }
    items.into_iter().collect()
}

/// The type or item a listing line is about: the implemented type of an
/// `impl ... for T` or `impl T`, the declared name otherwise.
fn subject(line: &str) -> &str {
    let head = line.split(" :: ").next().unwrap_or(line);
    let head = head.rsplit(" for ").next().unwrap_or(head);
    let words = head
        .split([' ', '<', '(', ':', '=', ';'])
        .filter(|w| !w.is_empty());
    let keyword = [
        "pub", "impl", "struct", "enum", "trait", "type", "fn", "const", "static",
    ];
    words
        .filter(|w| !keyword.contains(w) && !w.starts_with("impl<") && !w.starts_with('\''))
        .find(|w| w.starts_with(|c: char| c.is_alphabetic() || c == '_'))
        .unwrap_or("")
}

/// The public items of one source file, its unit tests cut off as
/// `docs_reader::sources` reads it (unit tests are not API): top-level
/// items, and the public fields and methods of public types as
/// `OWNER :: ITEM`.
fn api_items(text: &str) -> Vec<String> {
    let mut items = Vec::new();
    let mut owner = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let trimmed = line.trim_start();
        let top = trimmed.len() == line.len();
        let declares = |k: &&str| trimmed.starts_with(k) || trimmed.contains(&format!(" {k}"));
        if top && ["struct ", "enum ", "trait ", "impl"].iter().any(declares) {
            owner = trimmed.trim_end_matches(['{', ' ']).to_string();
        }
        // Items of a private type, and private items, are not API.
        let private_owner = !top && !owner.starts_with("pub ") && !owner.starts_with("impl");
        if !trimmed.starts_with("pub ") || private_owner {
            continue;
        }
        let mut item = trimmed.to_string();
        let signature = item.starts_with("pub fn ") || item.starts_with("pub const fn ");
        // A grouped re-export (`pub use a::{\n b,\n c,\n};`) runs to its `;`.
        let reexport = item.starts_with("pub use ");
        let ends = |s: &str| {
            s.ends_with(';')
                || (!reexport && s.ends_with('{'))
                || (!signature && !reexport && s.ends_with(','))
        };
        while !ends(item.trim_end()) {
            match lines.next() {
                Some(next) => {
                    item.push(' ');
                    item.push_str(next.trim());
                }
                None => break,
            }
        }
        let item = item
            .trim_end_matches(['{', ' '])
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        items.push(if top {
            item
        } else {
            format!("{owner} :: {item}")
        });
    }
    items
}

/// The setters `request::setters!` generates, one line each as the listing
/// writes a method (the macro's arms: `field: [some] [into] Type`).
fn generated_setters(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for call in text.split("setters!(").skip(1) {
        let Some((request, body)) = call.split_once('{') else {
            continue;
        };
        let request = request.trim();
        if request.starts_with('$') || request.contains(':') {
            continue; // the macro's own rules
        }
        let body = body.split("});").next().unwrap_or("");
        for field in body.split(",\n").map(str::trim).filter(|f| !f.is_empty()) {
            let Some((name, ty)) = field.trim_end_matches(',').split_once(':') else {
                continue;
            };
            let ty = ty.trim();
            let ty = ty.strip_prefix("some ").unwrap_or(ty);
            let param = match ty.strip_prefix("into ") {
                Some(ty) => format!("impl Into<{ty}>"),
                None => ty.to_string(),
            };
            out.push(format!(
                "impl {request} :: pub fn {}(mut self, value: {param}) -> {request}",
                name.trim()
            ));
        }
    }
    out
}

#[test]
fn public_api_of_the_door_changes_only_with_its_listing() {
    let root = workspace();
    let listing = root.join("crates/ident/public-api.txt");
    let now = public_api(&root).join("\n") + "\n";
    assert!(now.lines().count() > 100, "too few items found: {now}");
    if std::env::var_os("BLESS").is_some() {
        std::fs::write(&listing, &now).unwrap();
        return;
    }
    let kept = std::fs::read_to_string(&listing).unwrap_or_default();
    let kept_set: BTreeSet<&str> = kept.lines().collect();
    let now_set: BTreeSet<&str> = now.lines().collect();
    let added: Vec<&&str> = now_set.difference(&kept_set).collect();
    let removed: Vec<&&str> = kept_set.difference(&now_set).collect();
    assert!(
        added.is_empty() && removed.is_empty(),
        "tricept-ident's public API changed without its listing (crates/ident/public-api.txt): \
         added {added:#?}, removed {removed:#?}; declare it with \
         `BLESS=1 cargo test -p xtask --test tidy public_api` and a line in CHANGELOG.md"
    );
}
