//! Every verb with its stdout closed before it writes (`tricept ... | head`
//! where `head` has already gone): no panic, and the exit code the verb
//! would have had anyway (files it writes are still written).

use crate::support::{fixture, workdir};

use std::process::{Command, Stdio};

#[test]
fn every_verb_survives_a_closed_stdout() {
    let dir = workdir("closed");
    let good = fixture("data/table2-grid-seed1.csv");
    let hidden = fixture("data/diagnose-hidden-effect.csv");
    let points = dir.join("points.csv");
    std::fs::write(&points, "x,y,z\n0,0,750\n10,0,760\n").unwrap();
    let written = dir.join("written.json");
    let (p, w) = (points.to_str().unwrap(), written.to_str().unwrap());
    // A batch of three machines: the fixture's campaign under three names.
    let batch: Vec<String> = (1..=3)
        .map(|i| {
            let copy = dir.join(format!("machine-{i}.csv"));
            std::fs::copy(&good, &copy).unwrap();
            copy.display().to_string()
        })
        .collect();
    let cases: Vec<(Vec<&str>, i32)> = vec![
        (vec!["ik", "0", "0", "750"], 0),
        (vec!["ik", "0", "0", "750", "--json"], 0),
        (vec!["ik", "--input", p], 0),
        (vec!["fk", "773", "773", "773"], 0),
        (vec!["tool-ik", "0", "0", "1100", "0", "0", "1"], 0),
        (vec!["machine"], 0),
        (vec!["machine", "--json"], 0),
        (vec!["identifiability"], 0),
        (vec!["identifiability", "--json"], 0),
        (vec!["identify", "--data", &good, "--write-machine", w], 0),
        (vec!["identify", "--data", &good, "--json"], 0),
        (vec!["identify", "--data", &hidden], 3),
        (vec!["simulate"], 0),
        (vec!["diagnose", "--data", &good], 0),
        (vec!["diagnose", "--data", &hidden, "--json"], 0),
        (vec!["detectability", "--poses", "grid:1,8,3"], 0),
        (vec!["compensate", "--data", &good, "--spacing", "50"], 0),
        (
            vec![
                "compensate",
                "--data",
                &good,
                "--targets",
                p,
                "--spacing",
                "50",
            ],
            0,
        ),
        (
            vec![
                "fleet", "--data", &batch[0], "--data", &batch[1], "--data", &batch[2],
            ],
            0,
        ),
        (
            vec![
                "identify", "--data", &batch[0], "--data", &batch[1], "--json",
            ],
            0,
        ),
        (vec!["--help"], 0),
        (vec!["identify", "--help"], 0),
        (vec!["docs", "diagnosis"], 0),
    ];
    let mut failures = Vec::new();
    for (args, code) in &cases {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tricept"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Close the read end before the child has written anything.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        if stderr.contains("panicked") || out.status.code() != Some(*code) {
            failures.push(format!("{args:?}: exit {:?}\n{stderr}", out.status.code()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The machine file was written although nothing could be printed.
    assert!(written.exists());
    std::fs::remove_dir_all(&dir).ok();
}
