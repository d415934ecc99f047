//! What the CLI writes survives what can go wrong while writing it
//! (docs/reliability.md, "Outputs"):
//!
//! - every file is replaced atomically: a full file system, a read-only
//!   directory or a `kill -9` at any moment leaves the previous file byte
//!   for byte, or a complete new one;
//! - stdout that cannot be written (a full disk, `/dev/full`) is exit 1 with
//!   a message, never a silently short output; only a closed pipe is quiet;
//! - an output that is one of the inputs (by name, symbolic or hard link)
//!   is refused before anything is computed, and the input is untouched.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::support::{fixture, fresh_workdir, run, stderr, tricept};

/// The files of a directory other than `keep`, sorted (temporaries left
/// behind would show here).
fn others(dir: &Path, keep: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !keep.contains(&n.as_str()))
        .collect();
    v.sort();
    v
}

/// A small tmpfs mounted at `dir` (root only; `None` where the test cannot
/// mount one, and the file-system tests are then covered by the injected
/// writer of `tricept_data::write_atomic`'s unit tests alone).
struct Tmpfs(PathBuf);

impl Tmpfs {
    fn mount(dir: &Path, size_kb: usize) -> Option<Tmpfs> {
        std::fs::create_dir_all(dir).unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size_kb}k"), "tmpfs"])
            .arg(dir)
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if ok {
            Some(Tmpfs(dir.to_path_buf()))
        } else {
            eprintln!(
                "SKIP: cannot mount a tmpfs at {} (not root?)",
                dir.display()
            );
            None
        }
    }

    fn remount_read_only(&self) {
        let s = Command::new("mount")
            .args(["-o", "remount,ro"])
            .arg(&self.0)
            .status()
            .unwrap();
        assert!(s.success());
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// Fills the file system of `dir` to the last byte.
fn fill(dir: &Path) {
    use std::io::Write;
    let mut f = std::fs::File::create(dir.join("filler")).unwrap();
    let block = vec![0u8; 4096];
    while f.write_all(&block).is_ok() {}
    while f.write_all(&block[..1]).is_ok() {}
    let _ = f.sync_all();
}

#[test]
fn a_full_file_system_leaves_every_previous_output_intact() {
    let dir = fresh_workdir("outputs-full");
    let data = fixture("data/table2-grid-seed1.csv");
    // Good outputs, written where there is room.
    let good = dir.join("good");
    std::fs::create_dir_all(&good).unwrap();
    let machine = good.join("calibrated.json");
    let out = run(&[
        "identify",
        "--data",
        &data,
        "--write-machine",
        machine.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let out = run(&[
        "compensate",
        "--machine",
        machine.to_str().unwrap(),
        "--table",
        good.to_str().unwrap(),
        "--table-spacing",
        "100",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let Some(fs) = Tmpfs::mount(&dir.join("small"), 256) else {
        return;
    };
    let small = fs.0.clone();
    let m = small.join("calibrated.json");
    let table = small.join("table.csv");
    std::fs::copy(&machine, &m).unwrap();
    std::fs::copy(good.join("table.csv"), &table).unwrap();
    let (old_machine, old_table) = (std::fs::read(&m).unwrap(), std::fs::read(&table).unwrap());
    fill(&small);
    let keep = ["calibrated.json", "table.csv", "filler"];
    for args in [
        vec![
            "identify",
            "--data",
            &data,
            "--write-machine",
            m.to_str().unwrap(),
        ],
        vec![
            "diagnose",
            "--data",
            &data,
            "--write-machine",
            m.to_str().unwrap(),
        ],
        vec![
            "compensate",
            "--machine",
            machine.to_str().unwrap(),
            "--table",
            small.to_str().unwrap(),
            "--table-spacing",
            "50",
        ],
        vec!["simulate", "--out", table.to_str().unwrap()],
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", stderr(&out));
        let e = stderr(&out);
        assert!(
            e.contains("No space left on device") && e.contains("not written"),
            "{args:?}: {e}"
        );
        assert_eq!(std::fs::read(&m).unwrap(), old_machine, "{args:?}");
        assert_eq!(std::fs::read(&table).unwrap(), old_table, "{args:?}");
        assert!(
            others(&small, &keep).is_empty(),
            "{:?}",
            others(&small, &keep)
        );
    }
    drop(fs);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_read_only_directory_leaves_the_previous_machine_file_intact() {
    let dir = fresh_workdir("outputs-readonly");
    let data = fixture("data/table2-grid-seed1.csv");
    let Some(fs) = Tmpfs::mount(&dir.join("ro"), 1024) else {
        return;
    };
    let m = fs.0.join("calibrated.json");
    std::fs::write(&m, "{\"an old\": \"file\"}\n").unwrap();
    fs.remount_read_only();
    let out = run(&[
        "identify",
        "--data",
        &data,
        "--write-machine",
        m.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("calibrated.json: not written: Read-only file system"));
    assert_eq!(
        std::fs::read_to_string(&m).unwrap(),
        "{\"an old\": \"file\"}\n"
    );
    drop(fs);
    std::fs::remove_dir_all(&dir).ok();
}

/// A tiny seeded generator for the kill delays (no dependency needed).
fn lcg(state: &mut u64) -> u64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    *state >> 33
}

#[test]
fn kill_9_at_any_moment_leaves_the_old_machine_file_or_a_complete_new_one() {
    let dir = fresh_workdir("outputs-kill");
    let data = fixture("data/table2-grid-seed1.csv");
    let m = dir.join("calibrated.json");
    // The old file: the nominal machine's description.
    let old = run(&["machine", "--json"]).stdout;
    // How long a write takes here, to spread the kills over it.
    let t0 = std::time::Instant::now();
    let out = run(&[
        "identify",
        "--data",
        &data,
        "--write-machine",
        m.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let span_us = (t0.elapsed().as_micros() as u64).max(1000) * 3 / 2;
    let mut state = 17;
    let (mut kept_old, mut complete_new) = (0, 0);
    for run_index in 0..100 {
        std::fs::write(&m, &old).unwrap();
        let mut child = tricept()
            .args([
                "identify",
                "--data",
                &data,
                "--write-machine",
                m.to_str().unwrap(),
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_micros(lcg(&mut state) % span_us));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        let text = std::fs::read(&m).unwrap();
        if text == old {
            kept_old += 1;
        } else {
            let d = tricept_kinematics::MachineDescription::from_json(
                std::str::from_utf8(&text).unwrap(),
            )
            .unwrap_or_else(|e| panic!("run {run_index}: a damaged machine file: {e}"));
            assert!(d.calibration.is_some(), "run {run_index}");
            complete_new += 1;
        }
    }
    eprintln!("TALLY kill -9: {kept_old} old, {complete_new} new, 0 damaged of 100");
    // Both outcomes happened: the kills did land before and after the rename.
    assert!(
        kept_old > 0 && complete_new > 0,
        "{kept_old} {complete_new}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_stdout_that_cannot_be_written_is_exit_1_with_a_message() {
    let dir = fresh_workdir("outputs-devfull");
    let data = fixture("data/table2-grid-seed1.csv");
    let points = dir.join("points.csv");
    let mut csv = "x,y,z\n".to_string();
    for i in 0..20_000 {
        csv.push_str(&format!(
            "{},{},760\n",
            (i % 200) as f64 - 100.0,
            (i / 200) as f64
        ));
    }
    std::fs::write(&points, csv).unwrap();
    let p = points.to_str().unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec!["ik", "0", "0", "750"],
        vec!["ik", "--input", p],
        vec!["fk", "773", "773", "773", "--json"],
        vec!["tool-ik", "0", "0", "1100", "0", "0", "1"],
        vec!["machine", "--json"],
        vec!["identifiability"],
        vec!["identify", "--data", &data, "--json"],
        vec!["identify", "--data", &data],
        vec!["simulate"],
        vec!["diagnose", "--data", &data],
        vec!["detectability", "--poses", "grid:1,8,3"],
        vec!["compensate", "--data", &data, "--spacing", "50"],
    ];
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    for args in &cases {
        let out = tricept()
            .args(args)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        let e = stderr(&out);
        assert!(!e.contains("panicked"), "{args:?}: {e}");
        assert_eq!(out.status.code(), Some(1), "{args:?}: {e}");
        assert!(
            e.contains("error: stdout: No space left on device") && e.contains("incomplete"),
            "{args:?}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_output_that_is_an_input_is_refused_before_anything_is_computed() {
    let dir = fresh_workdir("outputs-same");
    let data = dir.join("data.csv");
    std::fs::copy(fixture("data/table2-grid-seed1.csv"), &data).unwrap();
    let original = std::fs::read(&data).unwrap();
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&data, &link).unwrap();
    let hard = dir.join("hard.csv");
    std::fs::hard_link(&data, &hard).unwrap();
    let poses = dir.join("poses.csv");
    std::fs::write(&poses, "q1,q2,q3,h1,h2\n800,800,800,0,0\n").unwrap();
    let (d, l, h, p) = (
        data.to_str().unwrap(),
        link.to_str().unwrap(),
        hard.to_str().unwrap(),
        poses.to_str().unwrap(),
    );
    let machine = dir.join("m.json");
    std::fs::write(&machine, run(&["machine", "--json"]).stdout).unwrap();
    let mj = machine.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["identify", "--data", d, "--write-machine", d],
            "--data",
        ),
        (
            vec!["identify", "--data", d, "--write-machine", l],
            "--data",
        ),
        (
            vec!["identify", "--data", d, "--write-machine", h],
            "--data",
        ),
        (
            vec![
                "identify",
                "--data",
                d,
                "--machine",
                mj,
                "--write-machine",
                mj,
            ],
            "--machine",
        ),
        (
            vec!["diagnose", "--data", d, "--write-machine", l],
            "--data",
        ),
        (
            vec!["plan", "--instrument", "tracker", "--data", d, "--out", h],
            "--data",
        ),
        (
            vec!["simulate", "--tracker-poses", p, "--tracker-out", p],
            "--tracker-poses",
        ),
        (vec!["simulate", "--out", d, "--machine", d], "--machine"),
        (
            vec!["identify", "--data", d, "--tracker", p, "--tracker", p],
            "--tracker",
        ),
    ];
    for (args, flag) in &cases {
        let out = run(args);
        let e = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(flag), "{args:?}: {e}");
        assert!(
            e.contains("choose another name") || e.contains("each file counts once"),
            "{args:?}: {e}"
        );
        assert_eq!(std::fs::read(&data).unwrap(), original, "{args:?}");
        assert_eq!(
            std::fs::read_to_string(&poses).unwrap(),
            "q1,q2,q3,h1,h2\n800,800,800,0,0\n"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
