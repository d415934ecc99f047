//! Seeded fuzzing of the binary, one property test per kind of input a
//! user gives it (docs/reliability.md, "Edges"): measured-data CSV,
//! machine JSON, option values and paths. Each case is a random mutation
//! of a valid input (a seeded generator: the same cases on every run) run
//! through the real binary, and every case must hold the same properties:
//!
//! - no panic, and an exit code of the table (0, 2, 3, 4; never 1 or a
//!   signal);
//! - exit 2 is one line on stderr that names the file (and its line, and
//!   column, where the problem has one) or the flag, at most
//!   [`tricept_data::message::MAX_MESSAGE_CHARS`] characters, no control character;
//! - no file changed by a refusal; by a run that succeeds, none but its
//!   own output.
//!
//! `TRICEPT_FUZZ_CASES` (default 40) sets the cases per kind, and
//! `TRICEPT_FUZZ_SEED` the seed (default 45). The paths stay inside the
//! test's scratch directory (one `..` at most, run one level down), but
//! for `/dev/null` and `/dev/zero`, which no verb writes.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::support::{calibrated_machine, fresh_workdir, ok, run_in, stderr};

/// A small seeded generator (64-bit LCG, high bits).
struct Rng(u64);

impl Rng {
    fn new(stream: u64) -> Rng {
        let seed = std::env::var("TRICEPT_FUZZ_SEED")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(45u64);
        let mut r = Rng(seed ^ stream.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        r.next();
        r
    }
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 33
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// The cases per kind of input.
fn cases() -> usize {
    std::env::var("TRICEPT_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40)
}

/// Every file under `dir` with its bytes (or what it is, when it is not a
/// regular file).
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            let Ok(m) = std::fs::symlink_metadata(&p) else {
                continue;
            };
            let t = m.file_type();
            let content = if t.is_dir() {
                stack.push(p.clone());
                b"dir".to_vec()
            } else if t.is_file() {
                std::fs::read(&p).unwrap_or_default()
            } else {
                format!("{t:?}").into_bytes()
            };
            out.push((p, content));
        }
    }
    out.sort();
    out
}

/// `path` with its directories resolved (links, `..`), as the file
/// system names what a write to it changes.
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    match (path.parent(), path.file_name()) {
        (Some(d), Some(n)) => {
            std::fs::canonicalize(d).map_or_else(|_| path.to_path_buf(), |d| d.join(n))
        }
        _ => path.to_path_buf(),
    }
}

/// What a case's run must hold (the module docs); `outputs` are the files
/// a successful run may write, `names` what its refusal must name.
fn holds(
    case: &str,
    out: &Output,
    before: &[(PathBuf, Vec<u8>)],
    after: &[(PathBuf, Vec<u8>)],
    outputs: &[&Path],
    names: &[&str],
) -> Result<(), String> {
    let err = stderr(out);
    let code = out.status.code();
    let fail = |why: &str| Err(format!("{case}: {why}: {code:?} {err:?}"));
    if err.contains("panicked") {
        return fail("panic");
    }
    match code {
        Some(0 | 3 | 4) => {
            // An output, what is inside an output directory, or a directory
            // created on the way to one.
            let allowed = |p: &Path| {
                outputs
                    .iter()
                    .any(|o| p == *o || p.starts_with(o) || (o.starts_with(p) && p.is_dir()))
            };
            let changed: Vec<&PathBuf> = after
                .iter()
                .filter(|(p, c)| before.iter().find(|(q, _)| q == p).map(|(_, d)| d) != Some(c))
                .map(|(p, _)| p)
                .filter(|p| !allowed(p))
                .collect();
            let removed = before
                .iter()
                .any(|(p, _)| !after.iter().any(|(q, _)| q == p));
            if !changed.is_empty() || removed {
                return fail(&format!("files changed besides the outputs: {changed:?}"));
            }
            Ok(())
        }
        Some(2) => {
            let line = err.trim_end_matches('\n');
            if after != before {
                return fail("a file changed on a refusal");
            }
            let first = line.lines().next().unwrap_or_default();
            // clap's own usage errors (a value it cannot place, a missing
            // one) quote the argument and add the usage; ours are one line
            // naming the file or the flag.
            let clap = line.contains("For more information, try");
            if !clap && !names.iter().any(|n| first.contains(n)) {
                return fail(&format!("the message names none of {names:?}"));
            }
            if !clap && line.lines().count() != 1 {
                return fail("not one line");
            }
            if line.chars().any(|c| c.is_control() && c != '\n')
                || first.chars().count() > tricept_data::message::MAX_MESSAGE_CHARS + 100
            {
                return fail("control characters or an unbounded message");
            }
            Ok(())
        }
        _ => fail("an exit code outside the table"),
    }
}

/// The scratch directory of a kind: a calibration `cal.json` (from
/// `cal.csv`), a day's campaign `day.csv`, an old `out.json`.
fn scratch(kind: &str) -> PathBuf {
    let dir = fresh_workdir(&format!("fuzz-{kind}"));
    calibrated_machine(&dir);
    ok(
        &dir,
        &[
            "simulate",
            "--truth",
            "random:0.25,5",
            "--poses",
            "random:20,9",
            "--seed",
            "4",
            "--out",
            "day.csv",
        ],
    );
    std::fs::write(dir.join("out.json"), "old\n").unwrap();
    dir
}

/// Tokens a mutation inserts: separators, line ends, odd numbers, bytes a
/// terminal acts on, a byte-order mark, quotes.
const TOKENS: [&str; 22] = [
    ",",
    "\n",
    "\r\n",
    "\r",
    ";",
    "\t",
    "nan",
    "inf",
    "-",
    "1e308",
    "1e-320",
    "1e400",
    "\u{663}",
    "\u{feff}",
    "\"",
    "#",
    "0x10",
    "+",
    "1,5",
    "\u{1b}[2J",
    "\0",
    "   ",
];

/// `text` mutated 1-4 times at random places.
fn mutated(rng: &mut Rng, text: &[u8]) -> Vec<u8> {
    let mut b = text.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(b.len() + 1);
        match rng.below(6) {
            0 if at < b.len() => b[at] = rng.next() as u8,
            1 => {
                let t = rng.pick(&TOKENS).as_bytes().to_vec();
                b.splice(at..at, t);
            }
            2 => {
                let end = (at + 1 + rng.below(20)).min(b.len());
                b.drain(at.min(end)..end);
            }
            3 => {
                // A line repeated.
                let text = String::from_utf8_lossy(&b).into_owned();
                let lines: Vec<&str> = text.split('\n').collect();
                let i = rng.below(lines.len());
                let mut v: Vec<&str> = lines.clone();
                v.insert(i, lines[i]);
                b = v.join("\n").into_bytes();
            }
            4 => b.truncate(at),
            _ => {
                // A field replaced by an odd value.
                let text = String::from_utf8_lossy(&b).into_owned();
                let mut fields: Vec<String> = text.split(',').map(str::to_string).collect();
                let i = rng.below(fields.len());
                fields[i] = rng.pick(&TOKENS).to_string();
                b = fields.join(",").into_bytes();
            }
        }
    }
    b
}

#[test]
fn measured_data_csv_mutated_at_random() {
    let dir = scratch("csv");
    let valid = std::fs::read(dir.join("cal.csv")).unwrap();
    let mut rng = Rng::new(1);
    let mut failures = Vec::new();
    let mut codes = [0usize; 5];
    for case in 0..cases() {
        std::fs::write(dir.join("m.csv"), mutated(&mut rng, &valid)).unwrap();
        let check = case % 2 == 1;
        let args: &[&str] = if check {
            &[
                "check",
                "--machine",
                "cal.json",
                "--data",
                "m.csv",
                "--history",
                "h.jsonl",
            ]
        } else {
            &["identify", "--data", "m.csv", "--write-machine", "out.json"]
        };
        let before = snapshot(&dir);
        let out = run_in(&dir, args);
        let after = snapshot(&dir);
        let outputs = [dir.join("out.json"), dir.join("h.jsonl")];
        let outputs: Vec<&Path> = outputs.iter().map(PathBuf::as_path).collect();
        let result = holds(
            &format!("csv case {case} ({})", args[0]),
            &out,
            &before,
            &after,
            &outputs,
            &["m.csv"],
        )
        .and_then(|()| {
            // Where there is a line, the message says it as FILE: line N.
            let err = stderr(&out);
            let at_line = err
                .match_indices(" line ")
                .any(|(i, _)| err[i + 6..].starts_with(|c: char| c.is_ascii_digit()));
            if out.status.code() == Some(2) && at_line && !err.contains("m.csv: line ") {
                Err(format!(
                    "csv case {case}: a line not given as m.csv: line N: {err}"
                ))
            } else {
                Ok(())
            }
        });
        if let Err(e) = result {
            failures.push(e);
        }
        codes[usize::from(out.status.code().unwrap_or(1) as u8).min(4)] += 1;
        // The old output back for the next case.
        std::fs::write(dir.join("out.json"), "old\n").unwrap();
    }
    println!(
        "TALLY fuzz csv: {} cases, exit codes 0..4: {codes:?}",
        cases()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn machine_json_mutated_at_random() {
    let dir = scratch("json");
    let valid = std::fs::read_to_string(dir.join("cal.json")).unwrap();
    let original = tricept_ident::kinematics::MachineDescription::from_json(&valid).unwrap();
    let root: serde_json::Value = serde_json::from_str(&valid).unwrap();
    let mut rng = Rng::new(2);
    let mut failures = Vec::new();
    let mut codes = [0usize; 5];
    let odd: [serde_json::Value; 9] = [
        serde_json::json!(-1.0),
        serde_json::json!(1e300),
        serde_json::json!(0),
        serde_json::json!("x"),
        serde_json::json!(null),
        serde_json::json!([]),
        serde_json::json!({}),
        serde_json::json!(true),
        serde_json::json!("k".repeat(1 << 20)),
    ];
    for case in 0..cases() {
        let text = if case % 2 == 0 {
            String::from_utf8_lossy(&mutated(&mut rng, valid.as_bytes())).into_owned()
        } else {
            // A random value anywhere in the document replaced.
            let mut v = root.clone();
            let mut pointer = String::new();
            let mut here = &root;
            loop {
                let next = match here {
                    serde_json::Value::Object(m) if !m.is_empty() && rng.below(4) != 0 => {
                        let k = m.keys().nth(rng.below(m.len())).cloned().unwrap();
                        pointer.push_str(&format!("/{}", k.replace('~', "~0").replace('/', "~1")));
                        &m[&k]
                    }
                    serde_json::Value::Array(a) if !a.is_empty() && rng.below(4) != 0 => {
                        let i = rng.below(a.len());
                        pointer.push_str(&format!("/{i}"));
                        &a[i]
                    }
                    _ => break,
                };
                here = next;
            }
            let here = v.pointer_mut(&pointer).unwrap();
            *here = rng.pick(&odd).clone();
            if case % 4 == 3 {
                // Nesting beyond any machine file.
                format!("{}{}", "[".repeat(100_000), v)
            } else {
                v.to_string()
            }
        };
        std::fs::write(dir.join("m.json"), &text).unwrap();
        let args = [
            "check",
            "--machine",
            "m.json",
            "--data",
            "day.csv",
            "--history",
            "h.jsonl",
        ];
        let before = snapshot(&dir);
        let out = run_in(&dir, &args);
        let after = snapshot(&dir);
        let history = dir.join("h.jsonl");
        let mut result = holds(
            &format!("json case {case}"),
            &out,
            &before,
            &after,
            &[&history],
            &["m.json"],
        );
        // Loaded: only a mutation that leaves the description as it was.
        if result.is_ok() && out.status.code() != Some(2) {
            let same = tricept_ident::kinematics::MachineDescription::from_json(&text)
                .is_ok_and(|d| d == original);
            if !same {
                result = Err(format!(
                    "json case {case}: an edited file was used: {}",
                    stderr(&out)
                ));
            }
        }
        if let Err(e) = result {
            failures.push(e);
        }
        codes[usize::from(out.status.code().unwrap_or(1) as u8).min(4)] += 1;
    }
    println!(
        "TALLY fuzz machine json: {} cases, exit codes 0..4: {codes:?}",
        cases()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn option_values_at_random() {
    let dir = scratch("options");
    let mut rng = Rng::new(3);
    let values = [
        "-1",
        "0",
        "1e400",
        "nan",
        "inf",
        "-inf",
        "1e-400",
        "abc",
        "",
        "1,2",
        "18446744073709551616",
        "-0",
        "0x1f",
        "1_000",
        " 3",
        "\u{ff13}",
        "1e308",
        "2",
        "0.5",
        "random:x",
        "grid:0,0,0",
        "random:2000000,1",
        "\u{1b}[2J",
        "-1e-300",
    ];
    let flags: [(&[&str], &str); 17] = [
        (&["identify", "--data", "cal.csv"], "--tolerance-mm"),
        (&["identify", "--data", "cal.csv"], "--readings-per-pose"),
        (&["identify", "--data", "cal.csv"], "--angle-noise-arcsec"),
        (&["identify", "--data", "cal.csv"], "--length-noise-um"),
        (
            &["check", "--machine", "cal.json", "--data", "day.csv"],
            "--alpha",
        ),
        (&["simulate", "--poses", "random:5,1"], "--seed"),
        (&["simulate", "--poses", "random:5,1"], "--revisit"),
        (&["simulate", "--poses", "random:5,1"], "--noise-factor"),
        (&["simulate"], "--poses"),
        (&["simulate", "--poses", "random:5,1"], "--truth"),
        (&["compensate", "--machine", "cal.json"], "--plane-z"),
        (&["compensate", "--machine", "cal.json"], "--spacing"),
        (
            &["compensate", "--machine", "cal.json", "--table", "t"],
            "--table-spacing",
        ),
        (&["identifiability"], "--poses"),
        (
            &["detectability", "--poses", "random:20,1"],
            "--temperature-drift",
        ),
        (&["diagnose", "--data", "cal.csv"], "--temperature-noise"),
        (&["ik", "0", "0"], "--machine"),
    ];
    let mut failures = Vec::new();
    let mut codes = [0usize; 5];
    for case in 0..cases() {
        let (base, flag) = *rng.pick(&flags);
        let value = *rng.pick(&values);
        let mut args: Vec<&str> = base.to_vec();
        if base[0] == "ik" {
            // A position given as an odd value.
            args = vec!["ik", "0", "0", value];
        } else {
            args.extend([flag, value]);
        }
        let before = snapshot(&dir);
        let out = run_in(&dir, &args);
        let after = snapshot(&dir);
        let t = dir.join("t");
        let name = flag.trim_start_matches('-');
        let names = [flag, name, "ik:"];
        if let Err(e) = holds(
            &format!("options case {case} {args:?}"),
            &out,
            &before,
            &after,
            &[&t],
            &names,
        ) {
            failures.push(e);
        }
        codes[usize::from(out.status.code().unwrap_or(1) as u8).min(4)] += 1;
    }
    println!(
        "TALLY fuzz options: {} cases, exit codes 0..4: {codes:?}",
        cases()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn paths_at_random() {
    let root = scratch("paths");
    // Run one level down, so that a `..` stays inside the scratch.
    let dir = root.join("in");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let pristine: Vec<(&str, Vec<u8>)> = ["cal.csv", "cal.json", "day.csv", "out.json"]
        .into_iter()
        .map(|f| (f, std::fs::read(root.join(f)).unwrap()))
        .collect();
    for (f, bytes) in &pristine {
        std::fs::write(dir.join(f), bytes).unwrap();
    }
    let made = std::process::Command::new("mkfifo")
        .arg(dir.join("pipe"))
        .status();
    assert!(made.is_ok_and(|s| s.success()));
    std::os::unix::fs::symlink("/dev/null", dir.join("null-link")).unwrap();
    std::os::unix::fs::symlink("loop", dir.join("loop")).unwrap();
    let mut rng = Rng::new(4);
    let parts = [
        "a",
        ".",
        "",
        "-",
        "sub",
        "cal.csv",
        "cal.json",
        "\n",
        "\u{1b}[2J",
        "pipe",
        "null-link",
        "loop",
        "ø",
        " ",
        "out.json",
        "x.json",
    ];
    let long = "y".repeat(300);
    let whole = [
        "/dev/null",
        "/dev/zero",
        "/dev/null/x",
        "-",
        "",
        "sub/",
        "..",
        ".",
    ];
    let flags: [(&[&str], &str); 8] = [
        (&["identify", "--data", "cal.csv"], "--write-machine"),
        (&["identify"], "--data"),
        (
            &["check", "--machine", "cal.json", "--data", "day.csv"],
            "--history",
        ),
        (&["check", "--data", "day.csv"], "--machine"),
        (&["diagnose", "--data", "cal.csv"], "--plots"),
        (&["simulate", "--poses", "random:5,1"], "--out"),
        (&["compensate", "--machine", "cal.json"], "--table"),
        (&["ik", "0", "0", "750"], "--machine"),
    ];
    let mut failures = Vec::new();
    let mut codes = [0usize; 5];
    for case in 0..cases() {
        let path = if rng.below(4) == 0 {
            rng.pick(&whole).to_string()
        } else {
            let n = 1 + rng.below(3);
            let mut p: Vec<String> = (0..n).map(|_| rng.pick(&parts).to_string()).collect();
            if rng.below(6) == 0 {
                p.insert(0, "..".into());
            }
            if rng.below(8) == 0 {
                p.push(long.clone());
            }
            let mut p = p.join("/");
            if rng.below(6) == 0 {
                p.push('/');
            }
            // An empty first name would make it absolute: keep it here.
            if p.starts_with('/') {
                p.insert(0, '.');
            }
            p
        };
        // Nothing outside the scratch is ever named but what no verb
        // writes (a device, a path through one).
        assert!(
            !path.starts_with('/') || path.starts_with("/dev/"),
            "{path:?}"
        );
        let (base, flag) = *rng.pick(&flags);
        // A named pipe is read as a stream (`--data <(zcat d.csv.gz)`):
        // with no writer it would wait, so inputs are given none.
        let input = matches!(flag, "--data" | "--machine");
        let path = if input {
            path.replace("pipe", "cal.csv")
        } else {
            path
        };
        let mut args: Vec<&str> = base.to_vec();
        args.extend([flag, path.as_str()]);
        let before = snapshot(&root);
        let out = run_in(&dir, &args);
        let after = snapshot(&root);
        // A run that succeeds may write what it names (resolved in `dir`).
        let target = resolved(&dir.join(&path));
        let history = dir.join("h.jsonl");
        let outputs = [target.as_path(), history.as_path()];
        let shown = tricept_data::message::shown_path(Path::new(&path));
        let shown: String = shown.chars().take(40).collect();
        let names = [flag, shown.as_str()];
        let case = format!("paths case {case} {args:?}");
        let mut result = holds(&case, &out, &before, &after, &outputs, &names);
        let err = stderr(&out);
        if result.is_ok()
            && out.status.code() == Some(2)
            && (err.contains('\u{1b}')
                || (err.trim_end().lines().count() != 1 && !err.contains("For more information")))
        {
            result = Err(format!("{case}: {err:?}"));
        }
        if let Err(e) = result {
            failures.push(e);
        }
        codes[usize::from(out.status.code().unwrap_or(1) as u8).min(4)] += 1;
        // The inputs as they were, for the next case (a run may have
        // written over one, as it may).
        for (f, bytes) in &pristine {
            for d in [&root, &dir] {
                if std::fs::symlink_metadata(d.join(f)).is_ok_and(|m| m.is_dir()) {
                    std::fs::remove_dir_all(d.join(f)).unwrap();
                }
                std::fs::write(d.join(f), bytes).unwrap();
            }
        }
    }
    println!(
        "TALLY fuzz paths: {} cases, exit codes 0..4: {codes:?}",
        cases()
    );
    assert!(std::fs::metadata("/dev/null").is_ok_and(|m| {
        use std::os::unix::fs::FileTypeExt;
        m.file_type().is_char_device()
    }));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&root).ok();
}
