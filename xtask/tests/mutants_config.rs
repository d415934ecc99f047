//! `.cargo/mutants.toml`'s exclusions still point at the code they were
//! written for.
//!
//! cargo-mutants names a mutant `file:line:column: replace A with B in
//! function`, and an exclusion is a regex over that name: when an edit
//! moves the line, the exclusion silently stops matching (its mutant is
//! then reported missed) or, worse, matches another mutant at the old
//! place. This test reads every exclusion, expands its alternatives, and
//! checks that the source at each `line:column` is the code it replaces:
//! the operator for `replace A with B`, the guard's expression for
//! `replace match guard E with ...`, and that the line lies in the named
//! function.

use std::path::Path;

/// The quoted regexes of `exclude_re`.
fn exclusions(config: &str) -> Vec<String> {
    let start = config
        .find("exclude_re")
        .expect("mutants.toml has exclude_re");
    config[start..]
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with('\''))
        .map(|l| {
            let end = l.rfind('\'').expect("a closing quote");
            l[1..end].to_string()
        })
        .collect()
}

/// The alternatives of a regex with at most one top-level group
/// `(a|b|c)` (escaped `\|` stays inside an alternative).
fn expand(re: &str) -> Vec<String> {
    let chars: Vec<char> = re.chars().collect();
    let mut open = None;
    let mut i = 0;
    while i < chars.len() {
        match chars[i] {
            '\\' => i += 1,
            '(' if open.is_none() => open = Some(i),
            ')' if open.is_some() => {
                let o = open.unwrap_or_default();
                let inner: String = chars[o + 1..i].iter().collect();
                let mut parts = vec![String::new()];
                let mut escaped = false;
                for c in inner.chars() {
                    if c == '|' && !escaped {
                        parts.push(String::new());
                    } else if let Some(p) = parts.last_mut() {
                        p.push(c);
                    }
                    escaped = c == '\\' && !escaped;
                }
                if parts.len() == 1 {
                    // A group without alternatives (`\(` ... is escaped).
                    open = None;
                    i += 1;
                    continue;
                }
                let (head, tail): (String, String) =
                    (chars[..o].iter().collect(), chars[i + 1..].iter().collect());
                return parts
                    .into_iter()
                    .map(|p| format!("{head}{p}{tail}"))
                    .collect();
            }
            _ => {}
        }
        i += 1;
    }
    vec![re.to_string()]
}

/// A regex's literal text: escapes removed.
fn unescape(s: &str) -> String {
    let mut out = String::new();
    let mut it = s.chars();
    while let Some(c) = it.next() {
        if c == '\\' {
            if let Some(n) = it.next() {
                out.push(n);
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// The name of the function a line lies in: the nearest `fn name` at or
/// above it.
fn function_at(lines: &[&str], line: usize) -> Option<String> {
    lines[..line].iter().rev().find_map(|l| {
        let at = l.find("fn ")?;
        let name: String = l[at + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        (!name.is_empty()).then_some(name)
    })
}

#[test]
fn every_exclusion_points_at_the_code_it_replaces() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let config = std::fs::read_to_string(root.join(".cargo/mutants.toml"))
        .expect(".cargo/mutants.toml is readable");
    let mut checked = 0;
    let mut wrong = Vec::new();
    for re in exclusions(&config) {
        for one in expand(&re) {
            // `path:line:column: replace WHAT with ... [in function]`.
            let mut fields = one.splitn(4, ':');
            let (Some(path), Some(line), Some(column), Some(rest)) =
                (fields.next(), fields.next(), fields.next(), fields.next())
            else {
                wrong.push(format!("{re}: not file:line:column: ..."));
                continue;
            };
            let path = unescape(path);
            let (Ok(line), Ok(column)) = (line.parse::<usize>(), column.parse::<usize>()) else {
                wrong.push(format!("{re}: line and column are not numbers"));
                continue;
            };
            let Some(what) = rest.trim_start().strip_prefix("replace ") else {
                wrong.push(format!("{re}: not a replacement"));
                continue;
            };
            let Ok(source) = std::fs::read_to_string(root.join(&path)) else {
                wrong.push(format!("{re}: {path} is not readable"));
                continue;
            };
            let lines: Vec<&str> = source.lines().collect();
            let Some(text) = lines.get(line.wrapping_sub(1)) else {
                wrong.push(format!("{re}: {path} has no line {line}"));
                continue;
            };
            let at: String = text.chars().skip(column - 1).collect();
            let (expected, function) = match what.split_once(" with ") {
                Some((w, tail)) => (
                    w.strip_prefix("match guard ").unwrap_or(w).to_string(),
                    tail.split_once(" in ").map(|(_, f)| f.trim().to_string()),
                ),
                None => match what.split_once(" in ") {
                    Some((w, f)) => (w.to_string(), Some(f.trim().to_string())),
                    None => (what.to_string(), None),
                },
            };
            // `.*`: any operator cargo-mutants replaces there.
            let found = if expected == ".*" {
                at.starts_with(|c: char| "+-*/%<>=!&|".contains(c))
            } else {
                at.starts_with(&unescape(&expected))
            };
            if !found {
                wrong.push(format!(
                    "{re}: {path}:{line}:{column} reads `{}`, not `{}`",
                    at.trim_end(),
                    unescape(&expected)
                ));
            }
            if let Some(f) = function {
                // `Type::method` or `Problem<._>::step`: the method's name.
                let name = unescape(&f);
                let name = name.rsplit("::").next().unwrap_or(&name).to_string();
                if function_at(&lines, line).as_deref() != Some(name.as_str()) {
                    wrong.push(format!(
                        "{re}: {path}:{line} lies in {:?}, not {name}",
                        function_at(&lines, line)
                    ));
                }
            }
            checked += 1;
        }
    }
    assert!(checked > 50, "only {checked} exclusions read");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn alternatives_are_expanded_and_escapes_kept_inside_them() {
    assert_eq!(
        expand(r"a\.rs:(1:2|3:4): replace > with >= "),
        [
            r"a\.rs:1:2: replace > with >= ",
            r"a\.rs:3:4: replace > with >= "
        ]
    );
    assert_eq!(
        expand(r"a:7:(21: replace > with >=|27: replace && with \|\|) in f"),
        [
            r"a:7:21: replace > with >= in f",
            r"a:7:27: replace && with \|\| in f"
        ]
    );
    assert_eq!(
        expand(r"guard link\.is_relative\(\) with true "),
        [r"guard link\.is_relative\(\) with true "]
    );
    assert_eq!(unescape(r"\|\|"), "||");
}
