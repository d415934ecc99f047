//! A calibration a user can trust, against the real binary: exit codes that
//! mean something (0 converged and adequate, 3 converged but inadequate, 4
//! not converged, 2 bad input), messages that name the likely cause, a
//! machine file that records its calibration and round-trips, and the
//! deployed extended model doing on the simulated machine what the
//! diagnosis said it would.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::support::{fixture, run, tricept, workdir};

mod compensation;
mod deployment;
mod machine_file;
mod verdicts;

fn json(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The comments, header and rows of a CSV text.
fn parts(csv: &str) -> (Vec<&str>, Vec<String>, Vec<Vec<String>>) {
    let comments: Vec<&str> = csv.lines().filter(|l| l.starts_with('#')).collect();
    let mut rows = csv.lines().filter(|l| !l.starts_with('#'));
    let header = rows
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = rows
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (comments, header, rows)
}

/// Writes `csv` with each row passed through `f` (header names in `h`).
fn rewrite(
    csv: &str,
    path: &Path,
    header: impl Fn(&mut Vec<String>),
    f: impl Fn(usize, &[String], &mut Vec<String>),
) {
    let (comments, mut h, rows) = parts(csv);
    let names = h.clone();
    header(&mut h);
    let mut s = comments.join("\n") + "\n" + &h.join(",") + "\n";
    for (j, r) in rows.iter().enumerate() {
        let mut r = r.clone();
        f(j, &names, &mut r);
        s += &(r.join(",") + "\n");
    }
    std::fs::write(path, s).unwrap();
}

fn col(names: &[String], c: &str) -> usize {
    names.iter().position(|n| n == c).unwrap()
}

/// Identify with `--json` and `--write-machine`; asserts the exit code
/// matches the JSON verdict and returns (code, json, stderr).
fn identify(data: &Path, extra: &[&str], machine_out: &Path) -> (i32, serde_json::Value, String) {
    let mut args = vec![
        "identify".to_string(),
        "--data".into(),
        data.display().to_string(),
        "--json".into(),
        "--write-machine".into(),
        machine_out.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let out = tricept().args(&args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "{stderr}");
    let code = out.status.code().unwrap();
    let v = json(&out);
    let expected = match (
        v["converged"].as_bool(),
        v["adequate"].as_bool(),
        v["worthwhile"].as_bool(),
    ) {
        (Some(false), _, _) => 4,
        (Some(true), Some(false), _) | (Some(true), Some(true), Some(false)) => 3,
        (Some(true), Some(true), Some(true)) => 0,
        _ => panic!("no verdict in {v}"),
    };
    assert_eq!(
        code, expected,
        "exit code against the JSON verdict: {stderr}"
    );
    (code, v, stderr)
}
