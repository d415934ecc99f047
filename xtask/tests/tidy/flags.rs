//! Tidy check of the libraries' messages (issue 49): no string literal in
//! the code of a library crate (`crates/*/src` but the binary's
//! `crates/cli`) or of the Python package (`python/src`) names a
//! command-line flag (`--tolerance-mm`). A library names the request
//! setting (`tolerance_mm`, [`tricept_ident::Setting`]) or the concept;
//! the `tricept` binary adds its flags (`crates/cli/src/flags.rs`).
//!
//! A flag is `--` then a lower-case letter, then letters, digits and
//! dashes, not preceded by a letter, digit, `_` or `-`, in a string
//! literal (plain, raw or byte) outside comments, doc comments and
//! `#[cfg(test)]` code (a test module inline or in its own file).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use super::{relative, without_comments_keeping_raw, without_tests, workspace};

/// Flag-like words that are no flags, with why: `(file, word)`.
const NOT_FLAGS: &[(&str, &str)] = &[
    // CSS custom properties of the HTML report's style sheet (`--fg:`,
    // `var(--fg)`), no command-line flags.
    ("crates/report/src/html.rs", "--fg"),
    ("crates/report/src/html.rs", "--muted"),
    ("crates/report/src/html.rs", "--line"),
    ("crates/report/src/html.rs", "--bad"),
    ("crates/report/src/html.rs", "--s1"),
    ("crates/report/src/html.rs", "--s2"),
    ("crates/report/src/html.rs", "--s3"),
    ("crates/report/src/html.rs", "--s4"),
    ("crates/report/src/html.rs", "--s5"),
];

/// The string literals of code without comments (plain and raw; a
/// character literal is gone already).
fn literals(code: &str) -> Vec<String> {
    let c: Vec<char> = code.chars().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < c.len() {
        let ident_before = i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_');
        let raw_at = match (c[i], c.get(i + 1)) {
            ('r', _) if !ident_before => Some(i + 1),
            ('b', Some('r')) if !ident_before => Some(i + 2),
            _ => None,
        };
        if let Some(mut j) = raw_at {
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) == Some(&'"') {
                let body = j + 1;
                let mut end = body;
                while end < c.len()
                    && !(c[end] == '"' && (0..hashes).all(|h| c.get(end + 1 + h) == Some(&'#')))
                {
                    end += 1;
                }
                found.push(c[body..end.min(c.len())].iter().collect());
                i = end + 1 + hashes;
                continue;
            }
        }
        if c[i] == '"' {
            let start = i + 1;
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            found.push(c[start..i.min(c.len())].iter().collect());
        }
        i += 1;
    }
    found
}

/// The flags a text names.
fn flags_in(text: &str) -> Vec<String> {
    let c: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i + 2 < c.len() {
        let before = i.checked_sub(1).map(|b| c[b]);
        let starts = c[i] == '-'
            && c[i + 1] == '-'
            && c[i + 2].is_ascii_lowercase()
            && !before.is_some_and(|b| b.is_alphanumeric() || b == '_' || b == '-');
        if starts {
            let mut j = i + 2;
            while j < c.len() && (c[j].is_ascii_lowercase() || c[j].is_ascii_digit() || c[j] == '-')
            {
                j += 1;
            }
            out.push(
                c[i..j]
                    .iter()
                    .collect::<String>()
                    .trim_end_matches('-')
                    .to_string(),
            );
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// The string literals of a file's code outside comments and tests.
fn code_literals(text: &str) -> Vec<String> {
    literals(&without_tests(&without_comments_keeping_raw(text)))
}

/// The `.rs` files below `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The files and folders of test modules declared in their own file
/// (`#[cfg(test)] mod tests;`) by one of `files`.
fn test_module_paths(files: &[PathBuf]) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    for f in files {
        let code = without_comments_keeping_raw(&std::fs::read_to_string(f).unwrap_or_default());
        let mut rest = code.as_str();
        while let Some(at) = rest.find("#[cfg(test)]") {
            rest = &rest[at + "#[cfg(test)]".len()..];
            let item = rest.trim_start();
            let item = item.strip_prefix("pub(crate) ").unwrap_or(item);
            let Some(name) = item
                .strip_prefix("mod ")
                .and_then(|m| m.split_once(';'))
                .map(|(n, _)| n.trim())
                .filter(|n| n.chars().all(|ch| ch.is_alphanumeric() || ch == '_'))
            else {
                continue;
            };
            let stem = f.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            let dir = if matches!(stem, "lib" | "main" | "mod") {
                f.parent().map(Path::to_path_buf).unwrap_or_default()
            } else {
                f.with_extension("")
            };
            out.insert(dir.join(format!("{name}.rs")));
            out.insert(dir.join(name));
        }
    }
    out
}

/// `(file, flag, literal)` of every flag a library's code names.
fn flags_named(root: &Path) -> Vec<(String, String, String)> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .map(|entries| {
            entries
                .flatten()
                .map(|e| e.path())
                .filter(|p| !p.ends_with("cli"))
                .map(|p| p.join("src"))
                .collect()
        })
        .unwrap_or_default();
    dirs.push(root.join("python/src"));
    dirs.sort();
    let mut found = Vec::new();
    for dir in dirs {
        let mut files = Vec::new();
        rust_files(&dir, &mut files);
        files.sort();
        let tests = test_module_paths(&files);
        for f in &files {
            if tests.iter().any(|t| f.starts_with(t)) {
                continue;
            }
            let file = relative(root, f);
            let text = std::fs::read_to_string(f).unwrap_or_default();
            for literal in code_literals(&text) {
                for flag in flags_in(&literal) {
                    if !NOT_FLAGS.contains(&(file.as_str(), flag.as_str())) {
                        found.push((file.clone(), flag, literal.clone()));
                    }
                }
            }
        }
    }
    found
}

#[test]
fn no_library_message_names_a_command_line_flag() {
    let root = workspace();
    let found = flags_named(&root);
    let listed: Vec<String> = found
        .iter()
        .map(|(file, flag, literal)| {
            let shown: String = literal.chars().take(120).collect();
            format!("{file}: {flag} in \"{shown}\"")
        })
        .collect();
    assert!(
        listed.is_empty(),
        "{} string literals of the libraries name a CLI flag (name the request setting or the concept; the CLI adds its flags, crates/cli/src/flags.rs):\n{}",
        listed.len(),
        listed.join("\n")
    );
    // The scan sees the libraries at all: the door's own sources are read.
    assert!(root.join("crates/ident/src/error.rs").is_file());
}

/// The scanner: a flag in a string literal counts, in a comment, a doc
/// comment, a test module, a character literal or a CSS property's
/// neighbour word does not.
#[test]
fn the_flag_scanner_reads_code_literals_only() {
    let code = r####"
//! `--in-module-doc`
/// `--in-doc` "--in-doc-string"
fn f() -> String {
    // "--in-comment"
    /* "--in-block" */
    let c = '"';
    let a = "plain --tolerance-mm: must be above 0";
    let b = r#"raw --write-machine "quoted""#;
    format!("{a}{b}{c} --k 3, e--x, a---b, ---, --Upper, -- gap, x_--y")
}
#[cfg(test)]
mod tests {
    const T: &str = "--in-test";
}
"####;
    let flags: Vec<String> = code_literals(code)
        .iter()
        .flat_map(|l| flags_in(l))
        .collect();
    assert_eq!(flags, ["--tolerance-mm", "--write-machine", "--k"]);
    assert_eq!(flags_in("--max-points- and --s1"), ["--max-points", "--s1"]);
}

/// A test module in its own file is skipped; its siblings are not.
#[test]
fn test_modules_in_their_own_files_are_found() {
    let dir = std::env::temp_dir().join(format!("tricept-tidy-flags-{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(src.join("holdout")).unwrap();
    std::fs::write(
        src.join("lib.rs"),
        "mod holdout;\n#[cfg(test)]\nmod testing;\n",
    )
    .unwrap();
    std::fs::write(src.join("holdout.rs"), "#[cfg(test)]\nmod tests;\n").unwrap();
    let files = vec![src.join("lib.rs"), src.join("holdout.rs")];
    let tests = test_module_paths(&files);
    assert!(tests.contains(&src.join("testing.rs")));
    assert!(tests.contains(&src.join("holdout/tests.rs")));
    assert!(!tests.contains(&src.join("holdout.rs")));
    std::fs::remove_dir_all(&dir).ok();
}
