//! Safe at every edge (docs/reliability.md, "Edges"): outputs that never
//! replace what is not a regular file (or a folder for folder flags), every
//! output flag refused at parse time before any work or append, `-` as
//! stdio or refused everywhere, one history lock per real file, and
//! messages cut and inert.
//!
//! The flags come from the verbs' own `--help` (every flag whose value is
//! a `FILE` or a `DIR`): a new file flag without a case here fails
//! `every_file_flag_is_known_here`.

use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};

use crate::support::{calibrated_machine, fresh_workdir, ok, run_in, stderr};

/// The verbs whose file flags this module covers (`export`'s `--out` and
/// its collision checks belong to the export's own tests).
const VERBS: [&str; 12] = [
    "ik",
    "fk",
    "tool-ik",
    "machine",
    "identifiability",
    "identify",
    "simulate",
    "diagnose",
    "detectability",
    "compensate",
    "check",
    "plan",
];

/// Every flag of `verb` whose value is a file or a directory, as its
/// `--help` shows it (`--write-machine <FILE.json>`): (flag, value name).
fn file_flags(verb: &str) -> Vec<(String, String)> {
    let out = run_in(Path::new("."), &[verb, "--help"]);
    let help = String::from_utf8_lossy(&out.stdout).into_owned();
    help.lines()
        .filter_map(|l| {
            let l = l.trim_start();
            let l = l.strip_prefix("-").and_then(|l| l.strip_prefix('-'))?;
            let (flag, rest) = l.split_once(' ')?;
            let value = rest.strip_prefix('<')?.split('>').next()?;
            (value.contains("FILE") || value.contains("DIR"))
                .then(|| (format!("--{flag}"), value.to_string()))
        })
        .collect()
}

/// What a file flag is: read, written, or a directory written into.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    Input,
    Output,
    Folder,
}

/// The role of each file flag of each verb, and a valid command it goes
/// into (run in a directory prepared by [`prepare`]).
fn role(verb: &str, flag: &str) -> Option<Role> {
    let outputs = [
        ("identify", "--write-machine"),
        ("diagnose", "--write-machine"),
        ("simulate", "--out"),
        ("simulate", "--tracker-out"),
        ("simulate", "--ballbar-out"),
        ("simulate", "--touch-out"),
        ("simulate", "--features-out"),
        ("check", "--history"),
        ("plan", "--out"),
    ];
    let folders = [
        ("diagnose", "--plots"),
        ("check", "--plot"),
        ("compensate", "--map"),
        ("compensate", "--table"),
    ];
    if outputs.contains(&(verb, flag)) {
        Some(Role::Output)
    } else if folders.contains(&(verb, flag)) {
        Some(Role::Folder)
    } else {
        let inputs = [
            "--machine",
            "--data",
            "--input",
            "--tracker",
            "--ballbar",
            "--touch",
            "--features",
            "--plausibility",
            "--tracker-poses",
            "--ballbar-poses",
            "--touch-poses",
            "--targets",
        ];
        inputs.contains(&flag).then_some(Role::Input)
    }
}

/// A valid command of `verb` with `flag` set to `value` (and what the flag
/// needs beside it).
fn command(verb: &str, flag: &str, value: &str) -> Vec<String> {
    let base: &[&str] = match verb {
        "ik" => &["ik", "0", "0", "750"],
        "fk" => &["fk", "796.5", "796.5", "796.5"],
        "tool-ik" => &["tool-ik", "0", "0", "1100", "0", "0", "1"],
        "identify" => &["identify", "--data", "d.csv"],
        "simulate" => &["simulate", "--poses", "random:5,1"],
        "diagnose" => &["diagnose", "--data", "d.csv"],
        "compensate" => &["compensate", "--machine", "cal.json"],
        "check" => &["check", "--machine", "cal.json", "--data", "day.csv"],
        "plan" => &[
            "plan",
            "--instrument",
            "tracker",
            "--tracker-target",
            "tip",
            "--k",
            "5",
            "--passes",
            "1",
            "--random-baseline",
            "0",
        ],
        other => &[other],
    };
    let mut args: Vec<String> = base.iter().map(|s| s.to_string()).collect();
    // What the flag goes with.
    let partner: &[&str] = match (verb, flag) {
        ("identify", "--tracker") => &["--tracker-target", "tip"],
        ("identify", "--touch") => &["--features", "features.json"],
        ("identify", "--features") => &["--touch", "touch.csv"],
        ("identify", "--plausibility") => &["--head", "none"],
        ("simulate", "--tracker-out") => &["--tracker-poses", "points.csv"],
        ("simulate", "--tracker-poses") => &["--tracker-out", "t.csv"],
        ("simulate", "--ballbar-out") => &["--ballbar-poses", "bpoints.csv"],
        ("simulate", "--ballbar-poses") => &["--ballbar-out", "b.csv"],
        ("simulate", "--touch-out") => &["--features-out", "f.json", "--touch-poses", "tposes.csv"],
        ("simulate", "--features-out") => &["--touch-out", "tc.csv", "--touch-poses", "tposes.csv"],
        ("simulate", "--touch-poses") => &["--touch-out", "tc.csv", "--features-out", "f.json"],
        ("check", "--plot") => &["--history", "h.jsonl"],
        ("compensate", "--data") => &[],
        (_, "--input") => {
            args.truncate(1);
            &[]
        }
        _ => &[],
    };
    if verb == "compensate" && flag == "--machine" {
        args.truncate(1);
    }
    if matches!((verb, flag), ("diagnose" | "identify" | "check", "--data")) {
        args.retain(|a| a != "--data" && a != "d.csv" && a != "day.csv");
    }
    args.extend(partner.iter().map(|s| s.to_string()));
    args.push(flag.to_string());
    args.push(value.to_string());
    args
}

/// A directory with what the commands of [`command`] read: a campaign
/// `d.csv`, its calibration `cal.json`, a day `day.csv`, and the files the
/// partner flags name (their content is never read: every case here is
/// refused at parse time).
fn prepare(name: &str) -> PathBuf {
    let dir = fresh_workdir(&format!("edges-{name}"));
    for partner in [
        "points.csv",
        "bpoints.csv",
        "tposes.csv",
        "features.json",
        "touch.csv",
    ] {
        std::fs::write(dir.join(partner), "x\n").unwrap();
    }
    calibrated_machine(&dir);
    std::fs::copy(dir.join("cal.csv"), dir.join("d.csv")).unwrap();
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
    dir
}

/// Every file in `dir` (recursively) with its bytes, or its kind when it
/// is not a regular file: what must be unchanged after a refusal.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let t = std::fs::symlink_metadata(&p).unwrap().file_type();
            let content = if t.is_symlink() {
                format!("link to {}", std::fs::read_link(&p).unwrap().display()).into_bytes()
            } else if t.is_dir() {
                stack.push(p.clone());
                b"dir".to_vec()
            } else if t.is_file() {
                std::fs::read(&p).unwrap()
            } else {
                format!("special {t:?}").into_bytes()
            };
            out.push((p, content));
        }
    }
    out.sort();
    out
}

#[test]
fn every_file_flag_is_known_here() {
    let mut unknown = Vec::new();
    for verb in VERBS {
        for (flag, value) in file_flags(verb) {
            match role(verb, &flag) {
                Some(Role::Folder) if !value.contains("DIR") => {
                    unknown.push(format!("{verb} {flag}"))
                }
                Some(_) => {}
                None => unknown.push(format!("{verb} {flag} <{value}>")),
            }
        }
    }
    assert!(
        unknown.is_empty(),
        "file flags without a role here: {unknown:?}"
    );
}

/// A named pipe at `path`.
fn mkfifo(path: &Path) {
    let made = std::process::Command::new("mkfifo").arg(path).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo {}", path.display());
}

/// A character device at `path` (`mknod c 1 3`, what `/dev/null` is),
/// when the test may make one (root); `false` otherwise.
fn mknod(path: &Path) -> bool {
    std::process::Command::new("mknod")
        .arg(path)
        .args(["c", "1", "3"])
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

#[test]
fn no_output_replaces_a_device_a_pipe_or_a_link_to_one_and_nothing_runs_first() {
    let dir = prepare("special");
    std::fs::create_dir_all(dir.join("s")).unwrap();
    let fifo = dir.join("s/pipe");
    mkfifo(&fifo);
    std::os::unix::fs::symlink("/dev/null", dir.join("s/null-link")).unwrap();
    let device = dir.join("s/node");
    let have_device = mknod(&device);
    if !have_device {
        eprintln!("SKIP: mknod needs root; the pipe and the link to /dev/null stand for it");
    }
    let mut specials = vec![
        ("s/pipe", "a named pipe"),
        ("s/null-link", "a character device"),
    ];
    if have_device {
        specials.push(("s/node", "a character device"));
    }
    let mut failures = Vec::new();
    let mut cases = 0;
    for verb in VERBS {
        for (flag, _) in file_flags(verb) {
            let Some(role) = role(verb, &flag).filter(|r| *r != Role::Input) else {
                continue;
            };
            for (special, kind) in &specials {
                // A folder flag: the file it writes first is the special one.
                let (value, expect) = match role {
                    Role::Folder => {
                        let folder = format!("f-{}", flag.trim_start_matches('-'));
                        let _ = std::fs::remove_dir_all(dir.join(&folder));
                        std::fs::create_dir_all(dir.join(&folder)).unwrap();
                        let name = match flag.as_str() {
                            "--plots" => "residual-compliance.svg",
                            "--plot" => "check-dq1.svg",
                            "--map" => "map.csv",
                            _ => "table.csv",
                        };
                        let target = dir.join(&folder).join(name);
                        std::fs::rename(dir.join(special), &target).unwrap();
                        (folder, (target, *special))
                    }
                    _ => (special.to_string(), (dir.join(special), *special)),
                };
                let before = snapshot(&dir);
                let args = command(verb, &flag, &value);
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                let started = std::time::Instant::now();
                let out = run_in(&dir, &args);
                let took = started.elapsed();
                cases += 1;
                let err = stderr(&out);
                let why = format!(
                    "{verb} {flag} {value} ({kind}): {:?} {err}",
                    out.status.code()
                );
                if out.status.code() != Some(2)
                    || !err.contains(kind)
                    || !err.contains(&flag)
                    || err.trim().lines().count() != 1
                {
                    failures.push(why);
                } else if snapshot(&dir) != before {
                    failures.push(format!("{why}: a file changed"));
                } else if took > std::time::Duration::from_secs(2) {
                    failures.push(format!("{why}: took {took:?} (work before the refusal?)"));
                }
                // Put the special file back for the next flag.
                let (target, home) = expect;
                if target != dir.join(home) {
                    std::fs::rename(&target, dir.join(home)).unwrap();
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(cases >= 13 * 2, "{cases} cases");
    // The special files are what they were.
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(
        std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );
    if have_device {
        assert!(
            std::fs::metadata(&device)
                .unwrap()
                .file_type()
                .is_char_device()
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn dash_is_stdio_where_a_flag_says_so_and_refused_everywhere_else() {
    let dir = prepare("dash");
    let mut failures = Vec::new();
    for verb in VERBS {
        for (flag, _) in file_flags(verb) {
            let args = command(verb, &flag, "-");
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let out = run_in(&dir, &args);
            let err = stderr(&out);
            let stdio = match (verb, flag.as_str()) {
                ("simulate", "--out") => {
                    out.status.code() == Some(0)
                        && String::from_utf8_lossy(&out.stdout).contains("q1,q2,q3,phi,theta,s")
                }
                // `--input -` reads stdin (empty here: a header is missing).
                (_, "--input") => out.status.code() == Some(2) && err.contains("stdin"),
                _ => {
                    out.status.code() == Some(2)
                        && (err.contains(&format!("{flag} -:")) || err.contains("the argument"))
                }
            };
            if !stdio || dir.join("-").exists() {
                failures.push(format!("{args:?}: {:?} {err}", out.status.code()));
                let _ = std::fs::remove_file(dir.join("-"));
            }
        }
    }
    // The specs that may name a file: `-` is no file either.
    for args in [
        vec!["simulate", "--truth", "-", "--poses", "random:5,1"],
        vec!["identifiability", "--poses", "-"],
    ] {
        let out = run_in(&dir, &args);
        if out.status.code() != Some(2) || dir.join("-").exists() {
            failures.push(format!(
                "{args:?}: {:?} {}",
                out.status.code(),
                stderr(&out)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn every_refusal_comes_before_the_work_and_the_append() {
    let dir = prepare("late");
    std::fs::write(dir.join("a-file"), "x").unwrap();
    let cases: [(&[&str], &str); 7] = [
        (
            &["diagnose", "--data", "d.csv", "--plots", "a-file"],
            "--plots a-file: is a file, not a directory",
        ),
        (
            &[
                "check",
                "--machine",
                "cal.json",
                "--data",
                "day.csv",
                "--history",
                "h.jsonl",
                "--plot",
                "a-file",
            ],
            "--plot a-file: is a file, not a directory",
        ),
        (
            &["identify", "--data", "d.csv", "--write-machine", "nodir/"],
            "--write-machine nodir/: names a directory",
        ),
        (
            &[
                "identify",
                "--data",
                "d.csv",
                "--write-machine",
                "a-file/m.json",
            ],
            "does not exist",
        ),
        (
            &[
                "identify",
                "--data",
                "d.csv",
                "--plausibility",
                "/nonexistent",
            ],
            "--plausibility /nonexistent: No such file",
        ),
        (
            &["identify", "--data", "d.csv", "--plausibility", "a-file"],
            "--plausibility: the plausible ranges of the head, tool and instruments apply to the fused identification only",
        ),
        (
            &[
                "check",
                "--machine",
                "cal.json",
                "--data",
                "day.csv",
                "--history",
                ".",
            ],
            "--history .: names a directory",
        ),
    ];
    for (args, needle) in cases {
        let before = snapshot(&dir);
        let out = run_in(&dir, args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert_eq!(snapshot(&dir), before, "{args:?}: a file changed");
    }
    assert!(
        !dir.join("h.jsonl").exists(),
        "the history was appended before the refusal"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn fifty_checks_by_name_and_fifty_through_a_link_keep_all_hundred_records() {
    let dir = prepare("history");
    std::os::unix::fs::symlink("H.jsonl", dir.join("L.jsonl")).unwrap();
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let children: Vec<std::process::Child> = (0..100)
        .map(|i| {
            let history = ["H.jsonl", "L.jsonl", "sub/../H.jsonl", "./L.jsonl"][i % 4];
            crate::support::tricept()
                .args([
                    "check",
                    "--machine",
                    "cal.json",
                    "--data",
                    "day.csv",
                    "--history",
                    history,
                ])
                .current_dir(&dir)
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for c in children {
        let out = c.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    }
    let text = std::fs::read_to_string(dir.join("H.jsonl")).unwrap();
    assert_eq!(text.lines().count(), 100);
    assert!(
        std::fs::symlink_metadata(dir.join("L.jsonl"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("lock") || n.contains(".tmp-"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn messages_are_one_line_cut_and_inert() {
    let dir = fresh_workdir("edges-messages");
    // A 50 MB JSON key: echoed in part, with where it is.
    let paper =
        std::fs::read_to_string(crate::support::fixture("machines/tricept-paper.json")).unwrap();
    let key = "k".repeat(50 << 20);
    let big = paper.replacen('{', &format!("{{\"{key}\": 1,"), 1);
    std::fs::write(dir.join("big.json"), big).unwrap();
    let out = run_in(&dir, &["machine", "--machine", "big.json"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(err.len() < 2000, "{} bytes", err.len());
    assert!(err.contains("big.json: line 1, column"), "{err}");
    assert!(err.contains("more bytes)`"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1);
    // A path with a newline and an escape sequence: one line, no escape
    // byte, whether refused or written.
    let name = "a\nb\u{1b}[31mred.csv";
    for args in [
        vec!["identify", "--data", name],
        vec!["simulate", "--poses", "random:40,1", "--out", name],
    ] {
        let out = run_in(&dir, &args);
        let err = stderr(&out);
        assert!(!err.contains('\u{1b}'), "{err:?}");
        assert_eq!(
            err.trim_end().lines().count(),
            1 + usize::from(args[0] == "simulate"),
            "{err:?}"
        );
        assert!(err.contains("a\\nb\\u{1b}[31mred.csv"), "{err:?}");
    }
    // The report on stdout repeats it inertly too.
    let out = run_in(&dir, &["identify", "--data", name]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(!out.stdout.contains(&0x1b));
    std::fs::remove_dir_all(&dir).ok();
}
