//! `tricept docs`: every page the help texts name is in the binary, and
//! every page of docs/ is embedded as it is in the repository.

use crate::support;

fn tricept(args: &[&str]) -> (i32, String) {
    let out = support::tricept().args(args).output().expect("run tricept");
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

/// `tricept effects` lists every simulated effect with keys that
/// `simulate --truth-effect` takes as they are (and no others), and
/// docs/diagnosis.md's table holds every one of them.
#[test]
fn every_simulated_effect_is_listed_simulated_and_documented() {
    let (code, listing) = tricept(&["effects", "--json"]);
    assert_eq!(code, 0);
    let page = std::fs::read_to_string(format!("{DOCS}/diagnosis.md")).unwrap();
    let table = page
        .split("## The simulator's effects")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .expect("docs/diagnosis.md has a section on the simulator's effects");
    let dir = std::env::temp_dir().join(format!("tricept-effects-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("data.csv");
    let out = out.to_str().unwrap();
    let mut effects = 0;
    for line in listing.lines() {
        let entry: serde_json::Value = serde_json::from_str(line).unwrap();
        let name = entry["effect"].as_str().unwrap();
        let example = entry["example"].to_string();
        assert!(
            table.contains(&format!("`{example}`")),
            "{name}: its example is not in docs/diagnosis.md"
        );
        for key in entry["keys"].as_array().unwrap() {
            let key = key["key"].as_str().unwrap();
            assert!(
                table.contains(&format!("`{key}`")),
                "{name}.{key} undocumented"
            );
        }
        let simulate = |effect: &str| {
            tricept(&[
                "simulate",
                "--poses",
                "random:12,1",
                "--truth-effect",
                effect,
                "--out",
                out,
            ])
            .0
        };
        assert_eq!(simulate(&example), 0, "simulate --truth-effect '{example}'");
        // A key the listing does not give is refused.
        let mut extra = entry["example"].clone();
        extra["not_a_key"] = serde_json::json!(1.0);
        assert_eq!(simulate(&extra.to_string()), 2, "{name} with an extra key");
        effects += 1;
    }
    assert_eq!(effects, 15, "{listing}");
    let (code, _) = tricept(&["effects", "no-such-effect"]);
    assert_eq!(code, 2);
    std::fs::remove_dir_all(&dir).ok();
}
