//! `tricept fleet`, `identify --data` given several times and `identify
//! --prior` end to end: the contract keys, the exit codes, the prior file
//! written, sealed and read back, and the inputs refused with one line.

use std::path::PathBuf;

use crate::support::{fresh_workdir, run_in};

/// `tricept simulate` of machine `truth` (a `--truth` spec) with `poses`
/// random poses (seed `seed`) into `dir/name`.
fn simulate(dir: &std::path::Path, name: &str, truth: &str, poses: &str, seed: &str) -> PathBuf {
    let out = run_in(
        dir,
        &[
            "simulate", "--truth", truth, "--poses", poses, "--seed", seed, "--out", name,
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir.join(name)
}

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)))
}

#[test]
fn a_batch_its_prior_and_pooled_campaigns_through_the_binary() {
    let dir = fresh_workdir("fleet");
    let files: Vec<String> = (1..=4)
        .map(|i| {
            let f = simulate(
                &dir,
                &format!("m{i}.csv"),
                &format!("random:0.1,{i}"),
                &format!("random:40,{i}"),
                &i.to_string(),
            );
            f.display().to_string()
        })
        .collect();
    let mut args = vec!["fleet", "--json", "--write-prior", "prior.json", "--data"];
    args.extend(files.iter().map(String::as_str));
    let out = run_in(&dir, &args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j = json(&out);
    for key in [
        "batch_mean_mm",
        "batch_mean_sd_mm",
        "batch_spread_mm",
        "machines",
        "outliers",
        "solver",
    ] {
        assert!(!j[key].is_null(), "{key} missing: {j}");
    }
    for key in ["kind", "unknowns", "nonzeros", "readings", "seconds"] {
        assert!(!j["solver"][key].is_null(), "solver.{key}");
    }
    let m = &j["machines"][0];
    for key in [
        "data_file",
        "estimates_mm",
        "std_dev_mm",
        "exit_code",
        "deviates",
    ] {
        assert!(!m[key].is_null(), "machines[].{key}");
    }
    assert_eq!(j["batch_mean_mm"]["dyA3"], serde_json::Value::Null);
    assert!(dir.join("prior.json").exists());
    // A new machine from the prior, and two campaigns of it pooled.
    let new = simulate(&dir, "new.csv", "random:0.1,9", "random:12,9", "9");
    let again = simulate(&dir, "again.csv", "random:0.1,9", "random:40,10", "10");
    let (new, again) = (new.display().to_string(), again.display().to_string());
    let out = run_in(
        &dir,
        &[
            "identify",
            "--data",
            &new,
            "--prior",
            "prior.json",
            "--json",
            "--write-machine",
            "new.json",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j = json(&out);
    assert_eq!(j["prior"]["file"], "prior.json");
    assert_eq!(j["prior"]["dof"], 14);
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("new.json")).unwrap()).unwrap();
    assert_eq!(
        written["calibration"]["external_sources"][0]["kind"],
        "prior"
    );
    let out = run_in(
        &dir,
        &["identify", "--data", &new, "--data", &again, "--json"],
    );
    let j = json(&out);
    assert_eq!(out.status.code(), Some(0), "{j}");
    let campaigns = j["campaigns"].as_array().unwrap();
    assert_eq!(campaigns.len(), 2);
    assert_eq!(campaigns[1]["data_file"], again.as_str());
    assert!(campaigns[0]["offsets"]["s_mm"].is_number());
    assert!(campaigns[0]["agreement"]["p_value"].as_f64().unwrap() > 1e-3);
}

#[test]
fn what_a_batch_cannot_use_is_refused_with_one_line() {
    let dir = fresh_workdir("fleet-bad");
    let a = simulate(&dir, "a.csv", "random:0.1,1", "random:30,1", "1")
        .display()
        .to_string();
    let b = simulate(&dir, "b.csv", "random:0.1,2", "random:30,2", "2")
        .display()
        .to_string();
    let c = simulate(&dir, "c.csv", "random:0.1,3", "random:30,3", "3")
        .display()
        .to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["fleet", "--data", &a, "--data", &b],
            "at least 3 machines",
        ),
        (
            vec!["fleet", "--data", &a, "--data", &a, "--data", &b],
            "--data",
        ),
        (
            vec![
                "fleet",
                "--data",
                &a,
                "--data",
                &b,
                "--data",
                &c,
                "--write-prior",
                &a,
            ],
            "--write-prior",
        ),
        (
            vec![
                "fleet", "--data", &a, "--data", &b, "--data", &c, "--solver", "lu",
            ],
            "unknown solver",
        ),
        (
            vec!["identify", "--data", &a, "--prior", &b],
            "not a prior file",
        ),
        (vec!["identify", "--data", &a, "--data", &a], "--data"),
    ];
    for (args, says) in cases {
        let out = run_in(&dir, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    }
    // An edited prior is refused, naming the field.
    let out = run_in(
        &dir,
        &[
            "fleet",
            "--data",
            &a,
            "--data",
            &b,
            "--data",
            &c,
            "--write-prior",
            "p.json",
        ],
    );
    assert!(
        dir.join("p.json").exists(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.join("p.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["covariance_mm2"]["matrix"][0][0] =
        (v["covariance_mm2"]["matrix"][0][0].as_f64().unwrap() * 4.0).into();
    std::fs::write(dir.join("edited.json"), v.to_string()).unwrap();
    let out = run_in(&dir, &["identify", "--data", &a, "--prior", "edited.json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("covariance_mm2"), "{err}");
    // The prior of another machine.
    let out = run_in(
        &dir,
        &[
            "identify",
            "--data",
            &a,
            "--prior",
            "p.json",
            "--machine",
            &crate::support::fixture("machines/tricept-paper-y-first.json"),
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("the batch's machine"), "{err}");
}
