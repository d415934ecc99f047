//! One exit-code table for every verb (docs/reliability.md): 0 success; 3
//! a fit that converged but must not be trusted (the model does not explain
//! the data, the campaign is too small, the machine changed); 4 a fit that
//! did not converge; 2 bad input; 1 anything else. The same data give the
//! same code with and without `--write-machine`.

use crate::support;

use std::path::{Path, PathBuf};

fn code(dir: &Path, args: &[&str]) -> i32 {
    support::run_in(dir, args).status.code().unwrap()
}

fn fixture(name: &str) -> String {
    support::fixture(&format!("data/{name}"))
}

fn workdir() -> PathBuf {
    support::fresh_workdir("exit-codes")
}

#[test]
fn every_verb_follows_the_one_exit_code_table() {
    let dir = workdir();
    let d = dir.as_path();
    let (good, hidden) = (
        fixture("table2-grid-seed1.csv"),
        fixture("diagnose-hidden-effect.csv"),
    );
    // phi and theta exchanged: a fit that does not converge.
    let text = std::fs::read_to_string(&good).unwrap();
    let swapped: String = text
        .lines()
        .map(|l| {
            if l.starts_with("q1,") {
                l.replace("phi,theta", "theta,phi")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("swapped.csv"), swapped + "\n").unwrap();
    std::fs::write(dir.join("points.csv"), "x,y,z\n0,0,750\n").unwrap();
    assert_eq!(
        code(
            d,
            &["identify", "--data", &good, "--write-machine", "cal.json"]
        ),
        0
    );
    assert_eq!(
        code(
            d,
            &[
                "simulate",
                "--poses",
                "random:20,4",
                "--seed",
                "3",
                "--out",
                "today.csv"
            ]
        ),
        0
    );
    // (verb and arguments, expected code)
    let table: Vec<(Vec<&str>, i32)> = vec![
        (vec!["ik", "0", "0", "750"], 0),
        (vec!["ik", "0", "0", "5000"], 2),
        (vec!["fk", "796.5", "796.5", "796.5"], 0),
        (vec!["fk", "1", "1", "1"], 2),
        (vec!["tool-ik", "0", "0", "1100", "0", "0", "1"], 0),
        (vec!["tool-ik", "0", "0", "1100", "0", "0", "0"], 2),
        (vec!["machine"], 0),
        (vec!["effects"], 0),
        (vec!["effects", "nope"], 2),
        (vec!["machine", "--machine", "missing.json"], 2),
        (vec!["identifiability"], 0),
        (vec!["identifiability", "--poses", "grid:0,1,1"], 2),
        (vec!["identify", "--data", &good], 0),
        (vec!["identify", "--data", &hidden], 3),
        (vec!["identify", "--data", "swapped.csv"], 4),
        (vec!["identify", "--data", "missing.csv"], 2),
        (vec!["simulate", "--poses", "grid:1,4,1"], 0),
        (vec!["simulate", "--poses", "random:0"], 2),
        (vec!["diagnose", "--data", &hidden], 0),
        (vec!["diagnose", "--data", "missing.csv"], 2),
        (vec!["detectability", "--poses", "grid:1,8,3"], 0),
        (vec!["detectability", "--data", "missing.csv"], 2),
        (vec!["compensate", "--data", &good, "--spacing", "50"], 0),
        (vec!["compensate", "--data", &hidden, "--spacing", "50"], 3),
        (
            vec!["compensate", "--data", "swapped.csv", "--spacing", "50"],
            4,
        ),
        (vec!["compensate", "--data", &good, "--spacing", "0.1"], 2),
        (
            vec![
                "plan",
                "--instrument",
                "tracker",
                "--tracker-target",
                "tip",
                "--k",
                "5",
            ],
            0,
        ),
        (
            vec![
                "plan",
                "--instrument",
                "tracker",
                "--tracker-target",
                "tip",
                "--k",
                "0",
            ],
            2,
        ),
        (
            vec!["check", "--machine", "cal.json", "--data", "today.csv"],
            0,
        ),
        (vec!["check", "--data", "today.csv"], 2),
        (vec!["nonsense"], 2),
    ];
    let mut failures = Vec::new();
    for (args, expected) in &table {
        let got = code(d, args);
        if got != *expected {
            failures.push(format!("{args:?}: exit {got}, the table says {expected}"));
        }
        // The same data give the same code with --write-machine (the file
        // is written only at 0, or with --force).
        if matches!(args[0], "identify" | "diagnose") && *expected != 2 {
            let _ = std::fs::remove_file(dir.join("written.json"));
            let mut with = args.clone();
            with.extend(["--write-machine", "written.json"]);
            let got = code(d, &with);
            if got != *expected {
                failures.push(format!("{with:?}: exit {got}, the table says {expected}"));
            }
            if (got == 0) != dir.join("written.json").exists() {
                failures.push(format!(
                    "{with:?}: a file written at exit {got}, or none at 0"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}

/// One library error, one exit code and one message, from every verb that
/// reads measured data: a command outside the leg stroke is the input's
/// fault (exit 2), named by file, line and column whichever verb meets it.
#[test]
fn the_same_bad_data_give_the_same_code_and_message_from_every_verb() {
    // Its own directory: the other test removes its work directory.
    let dir = std::env::temp_dir().join(format!("tricept-same-error-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let d = dir.as_path();
    let good = fixture("table2-grid-seed1.csv");
    assert_eq!(
        code(
            d,
            &["diagnose", "--data", &good, "--write-machine", "cal.json"]
        ),
        0
    );
    // The first data row (line 7) commands leg 2 beyond its stroke.
    let text = std::fs::read_to_string(&good).unwrap();
    let bad: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 6 {
                let mut f: Vec<&str> = l.split(',').collect();
                f[1] = "5000";
                f.join(",")
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(dir.join("bad.csv"), bad.join("\n") + "\n").unwrap();
    let verbs: [&[&str]; 6] = [
        &["identify", "--data", "bad.csv"],
        &["diagnose", "--data", "bad.csv"],
        &["check", "--machine", "cal.json", "--data", "bad.csv"],
        &["compensate", "--data", "bad.csv"],
        &["detectability", "--data", "bad.csv"],
        &["identifiability", "--data", "bad.csv"],
    ];
    let mut failures = Vec::new();
    for args in verbs {
        let out = support::tricept()
            .args(args)
            .current_dir(d)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        let line = stderr.lines().last().unwrap_or_default();
        if out.status.code() != Some(2)
            || !line.starts_with("error: bad.csv: line 7, column `q2`: command 5000 mm")
        {
            failures.push(format!("{args:?}: exit {:?}: {stderr}", out.status.code()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}
