//! One exit code per library error, whichever verb meets it (issue 27):
//! the mapping from an error's kind to the exit code lives in the door
//! (`tricept_ident::advanced::Classify`), so data too small to fit, a pose line the
//! machine cannot take and an invalid option exit alike from `identify`
//! (alone and fused), `identifiability`, `compensate`, `diagnose` and
//! `plan`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `tricept` in `dir`: its exit code and stderr.
fn run(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_tricept"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    (out.status.code().unwrap(), stderr)
}

/// A fresh directory of the test `name`.
fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "tricept-one-exit-code-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The fixture's header and its first `n` poses, the `bad`-th (1-based)
/// with its first leg command replaced by `q1`.
fn campaign(n: usize, bad: Option<(usize, &str)>) -> String {
    let path = format!(
        "{}/../../fixtures/data/table2-grid-seed1.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = String::new();
    let mut poses = 0;
    for line in text.lines() {
        let is_pose = !line.starts_with('#') && !line.starts_with("q1");
        if is_pose {
            poses += 1;
            if poses > n {
                break;
            }
        }
        match bad {
            Some((k, q1)) if is_pose && k == poses => {
                let rest = line.split_once(',').unwrap().1;
                out.push_str(&format!("{q1},{rest}\n"));
            }
            _ => out.push_str(&format!("{line}\n")),
        }
    }
    out
}

/// Every run of `cases` exits with `expected`, and says so in one line
/// containing `needle`.
fn same_code(dir: &Path, what: &str, expected: i32, needle: &str, cases: &[Vec<&str>]) {
    let mut failures = Vec::new();
    for args in cases {
        let (code, stderr) = run(dir, args);
        if code != expected {
            failures.push(format!(
                "{args:?}: exit {code}, expected {expected}\n{stderr}"
            ));
        }
        let errors: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("error: "))
            .collect();
        if errors.len() != 1 || !errors[0].contains(needle) {
            failures.push(format!(
                "{args:?}: not one error line naming `{needle}`:\n{stderr}"
            ));
        }
    }
    assert!(failures.is_empty(), "{what}:\n{}", failures.join("\n"));
}

#[test]
fn too_few_poses_is_an_input_error_from_every_verb() {
    let dir = workdir("few");
    std::fs::write(dir.join("tiny.csv"), campaign(3, None)).unwrap();
    let verbs: Vec<Vec<&str>> = vec![
        vec!["identify", "--data", "tiny.csv"],
        vec!["identify", "--data", "tiny.csv", "--no-robust"],
        vec![
            "identify",
            "--data",
            "tiny.csv",
            "--head",
            "none",
            "--effects",
            "leg-lead",
        ],
        vec!["identifiability", "--data", "tiny.csv"],
        vec!["compensate", "--data", "tiny.csv"],
        vec!["diagnose", "--data", "tiny.csv"],
    ];
    same_code(&dir, "too few poses", 2, "tiny.csv", &verbs);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_pose_the_machine_cannot_take_is_an_input_error_from_every_verb() {
    let dir = workdir("far");
    std::fs::write(dir.join("far.csv"), campaign(75, Some((7, "5000")))).unwrap();
    let verbs: Vec<Vec<&str>> = vec![
        vec!["identify", "--data", "far.csv"],
        vec!["identify", "--data", "far.csv", "--head", "none"],
        vec!["identifiability", "--data", "far.csv"],
        vec!["compensate", "--data", "far.csv"],
        vec!["diagnose", "--data", "far.csv"],
        vec!["plan", "--instrument", "touch", "--data", "far.csv"],
    ];
    same_code(&dir, "unreachable pose", 2, "far.csv: line", &verbs);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_invalid_option_is_an_input_error_from_every_verb() {
    let dir = workdir("option");
    std::fs::write(dir.join("data.csv"), campaign(75, None)).unwrap();
    let params: Vec<Vec<&str>> = vec![
        vec!["identify", "--data", "data.csv", "--params", "paper99"],
        vec!["identifiability", "--params", "paper99"],
        vec!["compensate", "--data", "data.csv", "--params", "paper99"],
        vec!["plan", "--instrument", "touch", "--params", "paper99"],
    ];
    same_code(&dir, "unknown parameter set", 2, "--params", &params);
    let targets: Vec<Vec<&str>> = vec![
        vec![
            "identify",
            "--data",
            "data.csv",
            "--tracker",
            "data.csv",
            "--tracker-target",
            "1,2",
        ],
        vec!["plan", "--instrument", "tracker", "--tracker-target", "1,2"],
    ];
    same_code(
        &dir,
        "bad tracker target",
        2,
        "--tracker-target: expected",
        &targets,
    );
    let grids: Vec<Vec<&str>> = vec![
        vec![
            "identify",
            "--data",
            "data.csv",
            "--head",
            "none",
            "--eval-grid",
            "2,8,0",
        ],
        vec!["plan", "--instrument", "touch", "--eval-grid", "2,8,0"],
    ];
    same_code(
        &dir,
        "bad evaluation grid",
        2,
        "--eval-grid: expected whole numbers",
        &grids,
    );
    std::fs::remove_dir_all(&dir).ok();
}
