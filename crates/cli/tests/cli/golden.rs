//! The binary's outputs on the repository's fixtures, byte for byte: every
//! verb's text report and `--json`, every file it writes, and a few
//! refusals, recorded once (`TRICEPT_BLESS=1 cargo test -p tricept-cli
//! --test cli golden`) and checked in under `crates/cli/tests/golden/`,
//! one file per case. A refactoring that changes no behaviour leaves them
//! all as they are; a change of an output shows as its diff.
//!
//! The cases run twice, on 2 threads and on 1, each time in order in one work directory holding a copy of
//! `fixtures/` (later cases read what earlier ones wrote: the calibrated
//! machine, the planned points), with relative paths, so that the outputs
//! name the same files on every machine. `SOURCE_DATE_EPOCH` fixes the
//! date written into machine files, histories and priors; the one number
//! that still changes between runs, a solver's wall-clock time (`tricept
//! fleet`'s `seconds`, and its text report's `... s solving, ... s in
//! all`), is replaced by `<seconds>` and `<t>`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::support::{fresh_workdir, tricept};

/// The date every run writes: 2026-01-02T03:04:05Z.
const EPOCH: &str = "1767323045";

/// A case: its name (the file of its recording), the arguments, and the
/// files it writes (relative to the work directory; a directory's files
/// are all recorded).
struct Case {
    name: &'static str,
    args: &'static [&'static str],
    files: &'static [&'static str],
}

const fn case(
    name: &'static str,
    args: &'static [&'static str],
    files: &'static [&'static str],
) -> Case {
    Case { name, args, files }
}

/// Input files the cases read besides the fixtures, written by the test.
const INPUTS: &[(&str, &str)] = &[
    ("points.csv", "x,y,z\n0,0,750\n100,-50,700\n-120.5,80,800\n"),
    ("commands.csv", "q1,q2,q3\n796.5,796.5,796.5\n760,820,801\n"),
    (
        "tool-poses.csv",
        "x,y,z,ax,ay,az\n150,100,1080,0.2,-0.1,1\n0,0,1100,0,0,1\n",
    ),
    ("targets.csv", "x,y,z\n0,0,750\n50,50,760\n"),
];

const DATA: &str = "fixtures/data/table2-grid-seed1.csv";

/// Every case, in the order they run.
const CASES: &[Case] = &[
    // Kinematics.
    case("ik", &["ik", "0", "0", "750"], &[]),
    case("ik-json", &["ik", "0", "0", "750", "--json"], &[]),
    case(
        "ik-y-first",
        &[
            "ik",
            "100",
            "-50",
            "700",
            "--machine",
            "fixtures/machines/tricept-paper-y-first.json",
            "--json",
        ],
        &[],
    ),
    case("fk", &["fk", "796.5", "796.5", "796.5"], &[]),
    case("fk-json", &["fk", "760", "820", "801", "--json"], &[]),
    case(
        "tool-ik",
        &["tool-ik", "150", "100", "1080", "0.2", "-0.1", "1"],
        &[],
    ),
    case(
        "tool-ik-json",
        &["tool-ik", "0", "0", "1100", "0", "0", "1", "--json"],
        &[],
    ),
    case("ik-batch", &["ik", "--input", "points.csv"], &[]),
    case("fk-batch", &["fk", "--input", "commands.csv"], &[]),
    case(
        "tool-ik-batch",
        &["tool-ik", "--input", "tool-poses.csv"],
        &[],
    ),
    case("machine", &["machine"], &[]),
    case("machine-json", &["machine", "--json"], &[]),
    // Identifiability.
    case("identifiability", &["identifiability"], &[]),
    case(
        "identifiability-json",
        &[
            "identifiability",
            "--poses",
            "random:30,1",
            "--params",
            "full21",
            "--json",
        ],
        &[],
    ),
    // Calibration from the fixture.
    case("identify", &["identify", "--data", DATA], &[]),
    case(
        "identify-json",
        &["identify", "--data", DATA, "--json"],
        &[],
    ),
    case(
        "identify-write",
        &["identify", "--data", DATA, "--write-machine", "cal.json"],
        &["cal.json"],
    ),
    case(
        "identify-inadequate",
        &[
            "identify",
            "--data",
            "fixtures/data/diagnose-hidden-effect.csv",
            "--json",
        ],
        &[],
    ),
    case(
        "identify-refused",
        &[
            "identify",
            "--data",
            "fixtures/data/diagnose-hidden-effect.csv",
            "--write-machine",
            "refused.json",
        ],
        &[],
    ),
    case(
        "identify-forced",
        &[
            "identify",
            "--data",
            "fixtures/data/diagnose-hidden-effect.csv",
            "--write-machine",
            "forced.json",
            "--force",
        ],
        &["forced.json"],
    ),
    case(
        "ik-calibrated",
        &["ik", "0", "0", "750", "--machine", "cal.json", "--json"],
        &[],
    ),
    case(
        "machine-calibrated",
        &["machine", "--machine", "cal.json"],
        &[],
    ),
    // Simulation.
    case(
        "simulate",
        &[
            "simulate",
            "--truth",
            "random:0.25,5",
            "--poses",
            "random:60,3",
            "--seed",
            "3",
            "--out",
            "sim.csv",
        ],
        &["sim.csv"],
    ),
    case(
        "simulate-json",
        &[
            "simulate",
            "--truth",
            "random:0.25,5",
            "--poses",
            "random:40,4",
            "--seed",
            "4",
            "--out",
            "sim2.csv",
            "--json",
        ],
        &["sim2.csv"],
    ),
    case(
        "identify-pooled",
        &[
            "identify", "--data", "sim.csv", "--data", "sim2.csv", "--json",
        ],
        &[],
    ),
    case(
        "identify-pooled-text",
        &[
            "identify",
            "--data",
            "sim.csv",
            "--data",
            "sim2.csv",
            "--write-machine",
            "pooled.json",
        ],
        &["pooled.json"],
    ),
    // Diagnosis.
    case(
        "diagnose",
        &[
            "diagnose",
            "--data",
            "fixtures/data/diagnose-hidden-effect.csv",
        ],
        &[],
    ),
    case(
        "diagnose-json",
        &[
            "diagnose",
            "--data",
            "fixtures/data/diagnose-hidden-effect.csv",
            "--json",
        ],
        &[],
    ),
    case(
        "diagnose-pitch-deploy",
        &[
            "diagnose",
            "--data",
            "fixtures/data/diagnose-pitch.csv",
            "--write-machine",
            "deployed.json",
            "--json",
        ],
        &["deployed.json"],
    ),
    case(
        "diagnose-hidden-deploy",
        &[
            "diagnose",
            "--data",
            "fixtures/data/diagnose-hidden-effect.csv",
            "--write-machine",
            "deployed-hidden.json",
        ],
        &["deployed-hidden.json"],
    ),
    case(
        "diagnose-noisy",
        &[
            "diagnose",
            "--data",
            "fixtures/data/diagnose-noisy.csv",
            "--noise-from-data",
            "--json",
        ],
        &[],
    ),
    case(
        "diagnose-plots",
        &[
            "diagnose",
            "--data",
            "fixtures/data/diagnose-hidden-effect.csv",
            "--plots",
            "plots",
        ],
        &["plots"],
    ),
    case(
        "ik-deployed",
        &[
            "ik",
            "0",
            "0",
            "750",
            "--machine",
            "deployed.json",
            "--json",
        ],
        &[],
    ),
    case(
        "ik-deployed-hidden",
        &["ik", "0", "0", "750", "--machine", "deployed-hidden.json"],
        &[],
    ),
    case(
        "fk-deployed",
        &[
            "fk",
            "--input",
            "commands.csv",
            "--machine",
            "deployed.json",
        ],
        &[],
    ),
    case(
        "machine-deployed",
        &["machine", "--machine", "deployed.json"],
        &[],
    ),
    case(
        "detectability",
        &["detectability", "--poses", "random:40,1"],
        &[],
    ),
    case(
        "detectability-json",
        &["detectability", "--poses", "random:40,1", "--json"],
        &[],
    ),
    // Compensation.
    case(
        "compensate-truth",
        &[
            "compensate",
            "--data",
            DATA,
            "--truth",
            "table2",
            "--map",
            "map",
            "--spacing",
            "50",
        ],
        &["map"],
    ),
    case(
        "compensate-json",
        &[
            "compensate",
            "--data",
            DATA,
            "--truth",
            "table2",
            "--spacing",
            "50",
            "--json",
        ],
        &[],
    ),
    case(
        "compensate-targets",
        &["compensate", "--data", DATA, "--targets", "targets.csv"],
        &[],
    ),
    case(
        "compensate-table",
        &[
            "compensate",
            "--machine",
            "cal.json",
            "--table",
            "table",
            "--spacing",
            "50",
            "--json",
        ],
        &["table"],
    ),
    case(
        "compensate-leg-tables",
        &[
            "compensate",
            "--machine",
            "deployed.json",
            "--table",
            "legs",
            "--spacing",
            "50",
        ],
        &["legs"],
    ),
    // Checks.
    case(
        "check-unchanged",
        &[
            "check",
            "--machine",
            "fixtures/report/table2.json",
            "--data",
            "fixtures/report/checks/day1.csv",
            "--history",
            "history.jsonl",
        ],
        &["history.jsonl"],
    ),
    case(
        "check-changed-json",
        &[
            "check",
            "--machine",
            "fixtures/report/table2.json",
            "--data",
            "fixtures/report/checks/day5.csv",
            "--history",
            "history.jsonl",
            "--json",
        ],
        &["history.jsonl"],
    ),
    case(
        "check-plots",
        &[
            "check",
            "--machine",
            "fixtures/report/table2.json",
            "--data",
            "fixtures/report/checks/day2.csv",
            "--history",
            "history.jsonl",
            "--plot",
            "trends",
        ],
        &["history.jsonl", "trends"],
    ),
    // Planning and the fused calibration.
    case(
        "plan-tracker",
        &[
            "plan",
            "--instrument",
            "tracker",
            "--tracker-target",
            "tip",
            "--k",
            "5,12",
            "--random-baseline",
            "3",
            "--passes",
            "1",
            "--out",
            "tracker-poses.csv",
        ],
        &["tracker-poses.csv"],
    ),
    case(
        "plan-tracker-json",
        &[
            "plan",
            "--instrument",
            "tracker",
            "--tracker-target",
            "tip",
            "--k",
            "12",
            "--random-baseline",
            "0",
            "--passes",
            "1",
            "--json",
        ],
        &[],
    ),
    case(
        "plan-ballbar",
        &[
            "plan",
            "--instrument",
            "ballbar",
            "--ballbar-pivot-mm",
            "0,0,1250",
            "--k",
            "30",
            "--random-baseline",
            "0",
            "--passes",
            "1",
            "--out",
            "ballbar-poses.csv",
        ],
        &["ballbar-poses.csv"],
    ),
    case(
        "plan-touch",
        &[
            "plan",
            "--instrument",
            "touch",
            "--k",
            "30",
            "--random-baseline",
            "0",
            "--passes",
            "1",
            "--out",
            "touches.csv",
        ],
        &["touches.csv"],
    ),
    case(
        "plan-check",
        &[
            "plan",
            "--instrument",
            "check",
            "--machine",
            "fixtures/report/table2.json",
            "--out",
            "check-poses.csv",
        ],
        &["check-poses.csv"],
    ),
    case(
        "plan-check-json",
        &[
            "plan",
            "--instrument",
            "check",
            "--machine",
            "cal.json",
            "--detect-um",
            "30",
            "--json",
        ],
        &[],
    ),
    case(
        "simulate-tracker",
        &[
            "simulate",
            "--head-errors",
            "random:1,5",
            "--out",
            "internal.csv",
            "--tracker-out",
            "tracker.csv",
            "--tracker-poses",
            "tracker-poses.csv",
        ],
        &["internal.csv", "tracker.csv"],
    ),
    case(
        "identify-tracker",
        &[
            "identify",
            "--data",
            "internal.csv",
            "--tracker",
            "tracker.csv",
            "--tracker-target",
            "tip",
            "--write-machine",
            "fused.json",
        ],
        &["fused.json"],
    ),
    case(
        "identify-tracker-json",
        &[
            "identify",
            "--data",
            "internal.csv",
            "--tracker",
            "tracker.csv",
            "--tracker-target",
            "tip",
            "--json",
        ],
        &[],
    ),
    case(
        "simulate-ballbar",
        &[
            "simulate",
            "--head-errors",
            "random:1,5",
            "--out",
            "internal-b.csv",
            "--ballbar-out",
            "ballbar.csv",
            "--ballbar-poses",
            "ballbar-poses.csv",
        ],
        &["internal-b.csv", "ballbar.csv"],
    ),
    case(
        "identify-ballbar-json",
        &[
            "identify",
            "--data",
            "internal-b.csv",
            "--ballbar",
            "ballbar.csv",
            "--json",
        ],
        &[],
    ),
    case(
        "simulate-touch",
        &[
            "simulate",
            "--head-errors",
            "random:1,5",
            "--out",
            "internal-t.csv",
            "--touch-out",
            "touch.csv",
            "--features-out",
            "features.json",
            "--touch-poses",
            "touches.csv",
        ],
        &["internal-t.csv", "touch.csv", "features.json"],
    ),
    case(
        "identify-touch",
        &[
            "identify",
            "--data",
            "internal-t.csv",
            "--touch",
            "touch.csv",
            "--features",
            "features.json",
        ],
        &[],
    ),
    // The effects.
    case("effects", &["effects"], &[]),
    case("effects-json", &["effects", "--json"], &[]),
    case("effects-one", &["effects", "compliance"], &[]),
    // A batch of machines and its prior.
    case(
        "simulate-m1",
        &[
            "simulate",
            "--truth",
            "random:0.1,1",
            "--poses",
            "random:40,1",
            "--seed",
            "1",
            "--out",
            "m1.csv",
        ],
        &[],
    ),
    case(
        "simulate-m2",
        &[
            "simulate",
            "--truth",
            "random:0.1,2",
            "--poses",
            "random:40,2",
            "--seed",
            "2",
            "--out",
            "m2.csv",
        ],
        &[],
    ),
    case(
        "simulate-m3",
        &[
            "simulate",
            "--truth",
            "random:0.1,3",
            "--poses",
            "random:40,3",
            "--seed",
            "3",
            "--out",
            "m3.csv",
        ],
        &[],
    ),
    case(
        "simulate-m4",
        &[
            "simulate",
            "--truth",
            "random:0.1,4",
            "--poses",
            "random:40,4",
            "--seed",
            "4",
            "--out",
            "m4.csv",
        ],
        &[],
    ),
    case(
        "fleet",
        &[
            "fleet", "--data", "m1.csv", "--data", "m2.csv", "--data", "m3.csv", "--data", "m4.csv",
        ],
        &[],
    ),
    case(
        "fleet-json",
        &[
            "fleet",
            "--data",
            "m1.csv",
            "--data",
            "m2.csv",
            "--data",
            "m3.csv",
            "--data",
            "m4.csv",
            "--json",
            "--write-prior",
            "prior.json",
        ],
        &["prior.json"],
    ),
    case(
        "simulate-new",
        &[
            "simulate",
            "--truth",
            "random:0.1,9",
            "--poses",
            "random:12,9",
            "--seed",
            "9",
            "--out",
            "new.csv",
        ],
        &[],
    ),
    case(
        "identify-prior",
        &[
            "identify",
            "--data",
            "new.csv",
            "--prior",
            "prior.json",
            "--json",
            "--write-machine",
            "new.json",
        ],
        &["new.json"],
    ),
    // Exports.
    case(
        "export",
        &["export", "--machine", "cal.json", "--out", "cnc"],
        &["cnc"],
    ),
    case(
        "export-heidenhain-json",
        &[
            "export",
            "--machine",
            "deployed.json",
            "--control",
            "heidenhain-itnc530",
            "--out",
            "cnc-h",
            "--json",
        ],
        &["cnc-h"],
    ),
    case(
        "export-fanuc",
        &[
            "export",
            "--machine",
            "cal.json",
            "--control",
            "fanuc-0i",
            "--axis-names",
            "U,V,W",
            "--detection-unit-um",
            "0.1",
            "--out",
            "cnc-f",
            "--json",
        ],
        &["cnc-f"],
    ),
    // The page.
    case(
        "report",
        &[
            "report",
            "--machine",
            "fixtures/report/table2.json",
            "--data",
            DATA,
            "--history",
            "fixtures/report/checks.jsonl",
            "--export",
            "fixtures/report/export",
            "--out",
            "page.html",
        ],
        &["page.html"],
    ),
    case(
        "report-alone",
        &["report", "--machine", "cal.json", "--out", "cal.html"],
        &["cal.html"],
    ),
    // Refusals: one line naming the file, the flag or the value.
    case(
        "error-missing-data",
        &["identify", "--data", "no-such.csv"],
        &[],
    ),
    case(
        "error-missing-machine",
        &["ik", "0", "0", "750", "--machine", "no-such.json"],
        &[],
    ),
    case("error-out-of-reach", &["ik", "0", "0", "5000"], &[]),
    case(
        "error-tolerance",
        &["identify", "--data", DATA, "--tolerance-mm", "0"],
        &[],
    ),
    case(
        "error-no-record",
        &[
            "check",
            "--machine",
            "fixtures/machines/tricept-paper.json",
            "--data",
            DATA,
        ],
        &[],
    ),
    case(
        "error-edited",
        &["ik", "0", "0", "750", "--machine", "edited.json"],
        &[],
    ),
    case(
        "error-tracker-target",
        &[
            "identify",
            "--data",
            "internal.csv",
            "--tracker",
            "tracker.csv",
        ],
        &[],
    ),
    case(
        "error-noise",
        &["identify", "--data", DATA, "--readings-per-pose", "0"],
        &[],
    ),
    case(
        "error-export-uncalibrated",
        &[
            "export",
            "--machine",
            "fixtures/machines/tricept-paper.json",
            "--out",
            "cnc-x",
        ],
        &[],
    ),
    case(
        "error-plan-check-uncalibrated",
        &["plan", "--instrument", "check"],
        &[],
    ),
    case("error-bad-csv", &["identify", "--data", "points.csv"], &[]),
];

/// The golden directory.
fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// Copies `from` into `to`, recursively.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            copy_dir(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

/// The files of `path` (itself, or a directory's, sorted), relative to
/// `dir`.
fn files_of(dir: &Path, path: &str) -> Vec<String> {
    let p = dir.join(path);
    if !p.is_dir() {
        return vec![path.to_string()];
    }
    let mut names: Vec<String> = std::fs::read_dir(&p)
        .unwrap()
        .flatten()
        .map(|e| format!("{path}/{}", e.file_name().to_string_lossy()))
        .collect();
    names.sort();
    names
}

/// Wall-clock times with their numbers replaced: `"seconds": NUMBER`
/// (and `"fit_seconds"`) in JSON, `NUMBER s solving` and `NUMBER s in
/// all` in the fleet's text report.
fn without_times(text: &str) -> String {
    let mut text = without_json_seconds(text);
    for unit in [" s solving", " s in all"] {
        text = without_number_before(&text, unit);
    }
    text
}

/// `text` with the number just before each `marker` replaced by `<t>`.
fn without_number_before(text: &str, marker: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(marker) {
        let number = rest[..at]
            .rfind(|c: char| !(c.is_ascii_digit() || c == '.'))
            .map_or(0, |i| i + 1);
        out.push_str(&rest[..number]);
        out.push_str("<t>");
        out.push_str(marker);
        rest = &rest[at + marker.len()..];
    }
    out.push_str(rest);
    out
}

/// `"seconds": NUMBER` (and `"fit_seconds"`) with the number replaced.
fn without_json_seconds(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("seconds\":") {
        let end = at + "seconds\":".len();
        out.push_str(&rest[..end]);
        let after = &rest[end..];
        let spaces = after.len() - after.trim_start().len();
        let number = after[spaces..]
            .find(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c)))
            .unwrap_or(after.len() - spaces);
        out.push_str(&after[..spaces]);
        out.push_str("\"<seconds>\"");
        rest = &after[spaces + number..];
    }
    out.push_str(rest);
    out
}

/// Runs a case in `dir` on `threads` threads: its recording.
fn record(dir: &Path, c: &Case, threads: &str) -> String {
    let out = tricept()
        .args(c.args)
        .current_dir(dir)
        .env("SOURCE_DATE_EPOCH", EPOCH)
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap();
    let mut s = String::new();
    let _ = writeln!(s, "$ tricept {}", c.args.join(" "));
    let _ = writeln!(s, "exit: {:?}", out.status.code());
    let _ = writeln!(s, "--- stdout");
    s.push_str(&String::from_utf8_lossy(&out.stdout));
    let _ = writeln!(s, "--- stderr");
    s.push_str(&String::from_utf8_lossy(&out.stderr));
    for f in c.files {
        for name in files_of(dir, f) {
            let text = std::fs::read(dir.join(&name))
                .map(|b| String::from_utf8_lossy(&b).into_owned())
                .unwrap_or_else(|e| format!("<not written: {}>\n", e.kind()));
            let _ = writeln!(s, "--- file {name}");
            s.push_str(&text);
        }
    }
    without_times(&s)
}

/// Every case run in order in a fresh work directory on `threads`
/// threads: each case's name and recording.
fn run_all(threads: &str) -> Vec<(&'static str, String)> {
    let dir = fresh_workdir(&format!("golden-{threads}"));
    copy_dir(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures"),
        &dir.join("fixtures"),
    );
    for (name, text) in INPUTS {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let mut recordings = Vec::with_capacity(CASES.len());
    for c in CASES {
        if c.name == "error-edited" {
            // A calibrated file edited after it was written.
            let text = std::fs::read_to_string(dir.join("cal.json")).unwrap();
            let edited = text.replacen("\"max_tilt_deg\": 40.0", "\"max_tilt_deg\": 41.0", 1);
            assert!(edited != text, "the edit did not apply");
            std::fs::write(dir.join("edited.json"), edited).unwrap();
        }
        recordings.push((c.name, record(&dir, c, threads)));
    }
    std::fs::remove_dir_all(&dir).ok();
    recordings
}

/// Where `got` first differs from the recording at `path`, if it does.
fn difference(name: &str, path: &Path, got: &str, threads: &str) -> Option<String> {
    let want = std::fs::read_to_string(path).unwrap_or_default();
    if got == want {
        return None;
    }
    let line = got
        .lines()
        .zip(want.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| got.lines().count().min(want.lines().count()));
    Some(format!(
        "{name} (on {threads} threads): differs from {} at line {}:\n  got:  {}\n  want: {}",
        path.display(),
        line + 1,
        got.lines().nth(line).unwrap_or("<end>"),
        want.lines().nth(line).unwrap_or("<end>")
    ))
}

/// Every case's outputs are the recorded ones, on 2 threads and on 1
/// (the same bits at any thread count). `TRICEPT_BLESS=1` records them
/// anew from the run on 2 threads; the diff of `crates/cli/tests/golden/`
/// then shows what changed.
#[test]
fn every_verb_s_outputs_on_the_fixtures_are_the_recorded_ones() {
    let mut names = std::collections::BTreeSet::new();
    for c in CASES {
        assert!(names.insert(c.name), "{}: two cases of one name", c.name);
    }
    let bless = std::env::var_os("TRICEPT_BLESS").is_some();
    let golden = golden_dir();
    let mut changed = Vec::new();
    for threads in ["2", "1"] {
        let recordings = run_all(threads);
        if bless && threads == "2" {
            let _ = std::fs::remove_dir_all(&golden);
            std::fs::create_dir_all(&golden).unwrap();
            for (name, got) in &recordings {
                std::fs::write(golden.join(format!("{name}.txt")), got).unwrap();
            }
            continue;
        }
        for (name, got) in &recordings {
            let path = golden.join(format!("{name}.txt"));
            changed.extend(difference(name, &path, got, threads));
        }
    }
    // A recording without its case is a case removed.
    for e in std::fs::read_dir(&golden).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !names.contains(name.trim_end_matches(".txt")) {
            changed.push(format!("{name}: recorded, but no case runs it"));
        }
    }
    assert!(
        changed.is_empty(),
        "{} of {} cases changed (TRICEPT_BLESS=1 records them anew):\n{}",
        changed.len(),
        CASES.len(),
        changed.join("\n")
    );
}
