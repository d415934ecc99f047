//! `tricept docs`: every page the help texts name is in the binary, and
//! every page of docs/ is embedded as it is in the repository.

use std::process::Command;

fn tricept(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_tricept"))
        .args(args)
        .output()
        .expect("run tricept");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

const DOCS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs");

#[test]
fn every_page_of_docs_is_embedded_verbatim() {
    let mut pages = 0;
    for entry in std::fs::read_dir(DOCS).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "md") {
            continue;
        }
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let (code, text) = tricept(&["docs", &name]);
        assert_eq!(code, 0, "tricept docs {name}");
        assert_eq!(text, std::fs::read_to_string(&path).unwrap(), "{name}");
        pages += 1;
    }
    let (code, list) = tricept(&["docs"]);
    assert_eq!(code, 0);
    assert_eq!(list.lines().count(), pages + 1, "{list}");
}

#[test]
fn every_page_a_help_text_names_is_there() {
    let (_, top) = tricept(&["--help"]);
    let verbs: Vec<String> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .filter(|v| v != "help")
        .collect();
    assert!(verbs.len() > 5, "{top}");
    let mut named = 0;
    for help in std::iter::once(top.clone()).chain(verbs.iter().map(|v| tricept(&[v, "--help"]).1))
    {
        for (i, _) in help.match_indices("docs/") {
            let page: String = help[i..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || "/-_.".contains(*c))
                .collect();
            let page = page.trim_end_matches('.');
            if !page.ends_with(".md") {
                continue;
            }
            let (code, text) = tricept(&["docs", page]);
            assert_eq!(
                code, 0,
                "a help text names {page}, which `tricept docs` lacks"
            );
            assert!(text.starts_with('#'), "{page}");
            named += 1;
        }
        for (i, _) in help.match_indices("tricept docs ") {
            let page: String = help[i + 13..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || "/-_.".contains(*c))
                .collect();
            let page = page.trim_end_matches('.');
            if page.is_empty() || page == "PAGE" {
                continue;
            }
            assert_eq!(
                tricept(&["docs", page]).0,
                0,
                "a help text names `tricept docs {page}`"
            );
            named += 1;
        }
    }
    assert!(named >= 3, "the help texts name {named} pages");
    let (code, _) = tricept(&["docs", "no-such-page"]);
    assert_eq!(code, 2);
}
