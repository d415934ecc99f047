//! What every CLI test needs: the `tricept` binary, a work directory per
//! test (or per module), the repository's fixtures, and runs that fail the
//! test on a panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `tricept` binary this package builds.
pub fn tricept() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tricept"))
}

/// `tricept-{name}-{pid}` in the temporary directory, created if needed
/// (what is already in it stays: tests that share it write their own files).
pub fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// [`workdir`] emptied first.
pub fn fresh_workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The path of `fixtures/{name}` in the repository.
pub fn fixture(name: &str) -> String {
    format!("{}/../../fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Runs `tricept args`; a panic fails the test.
pub fn run(args: &[&str]) -> Output {
    no_panic(args, tricept().args(args).output().unwrap())
}

/// Runs `tricept args` in `dir`; a panic fails the test.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    no_panic(
        args,
        tricept().args(args).current_dir(dir).output().unwrap(),
    )
}

fn no_panic(args: &[&str], out: Output) -> Output {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    out
}

/// Runs `tricept args` in `dir`, asserting success; its stdout.
pub fn ok(dir: &Path, args: &[&str]) -> Vec<u8> {
    let out = run_in(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// The stderr of a run, as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The true errors a simulated file's comment records (`# true errors`).
pub fn truth_of(csv: &str) -> serde_json::Map<String, serde_json::Value> {
    let line = csv
        .lines()
        .find(|l| l.starts_with("# true errors"))
        .unwrap();
    serde_json::from_str(&line[line.find('{').unwrap()..]).unwrap()
}

/// Writes `dir/out`: the true errors of the calibration campaign in `dir`
/// (`cal.csv`, [`calibrated_machine`]) with each `(parameter, mm)` of
/// `moves` added, for `simulate --truth out`: the machine after a change.
pub fn moved_truth(dir: &Path, moves: &[(&str, f64)], out: &str) {
    let csv = std::fs::read_to_string(dir.join("cal.csv")).unwrap();
    let mut truth = truth_of(&csv);
    for (name, by) in moves {
        let v = truth[*name].as_f64().unwrap();
        truth.insert((*name).into(), (v + by).into());
    }
    std::fs::write(dir.join(out), serde_json::to_string(&truth).unwrap()).unwrap();
}

/// The calibration the check tests start from, in `dir`: `cal.csv`, 80
/// random poses of a machine with random errors of up to 0.25 mm (seed 5),
/// and `cal.json`, the machine `identify` writes from it (exit 0 asserted).
pub fn calibrated_machine(dir: &Path) {
    ok(
        dir,
        &[
            "simulate",
            "--truth",
            "random:0.25,5",
            "--poses",
            "random:80,3",
            "--out",
            "cal.csv",
        ],
    );
    ok(
        dir,
        &[
            "identify",
            "--data",
            "cal.csv",
            "--write-machine",
            "cal.json",
        ],
    );
}
