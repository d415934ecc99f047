//! `tricept report`: the page written with the verdict's exit code, and bad
//! inputs refused with exit code 2 and one line naming the file: an
//! edited machine file, a campaign that is not the calibration's, an
//! output that is an input.

use crate::support::{fixture, fresh_workdir, ok, run_in, stderr};

#[test]
fn report_writes_the_page_and_refuses_what_is_not_this_calibration_s() {
    let dir = fresh_workdir("report");
    let grid = fixture("data/table2-grid-seed1.csv");
    ok(
        &dir,
        &["identify", "--data", &grid, "--write-machine", "t2.json"],
    );
    let out = ok(
        &dir,
        &[
            "report",
            "--machine",
            "t2.json",
            "--data",
            &grid,
            "--out",
            "page.html",
        ],
    );
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.starts_with("report written to page.html: TRUSTED"),
        "{text}"
    );
    let page = std::fs::read_to_string(dir.join("page.html")).unwrap();
    assert!(page.starts_with("<!DOCTYPE html>"));
    assert!(page.contains("data-level=\"trusted\""));

    let refused = |args: &[&str], names: &[&str]| {
        let out = run_in(&dir, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        let e = stderr(&out);
        assert_eq!(e.lines().count(), 1, "{e}");
        for n in names {
            assert!(e.contains(n), "{args:?}: `{n}` not named: {e}");
        }
    };
    // The noise made quieter by hand: the seal refuses the file.
    let mut edited: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("t2.json")).unwrap()).unwrap();
    edited["sensors"]["length_noise_um"] = 0.1.into();
    std::fs::write(dir.join("edited.json"), edited.to_string()).unwrap();
    refused(
        &["report", "--machine", "edited.json", "--out", "e.html"],
        &["edited.json", "`sensors.length_noise_um`"],
    );
    refused(
        &[
            "report",
            "--machine",
            "t2.json",
            "--data",
            &fixture("data/diagnose-pitch.csv"),
            "--out",
            "p.html",
        ],
        &["diagnose-pitch.csv", "SHA-256"],
    );
    refused(
        &["report", "--machine", "t2.json", "--out", "t2.json"],
        &["--out", "t2.json"],
    );
}
