//! Pooled calibration in truth (`docs/fleet.md`): batches of true machines
//! written in this test from the documented conventions
//! (`docs/conventions.md`: each parameter is the error of one coordinate of
//! a joint, `dxB2 = dxB1` by the paper's frame convention, the leg error is
//! actual length minus command), their readings from `tricept-truth`'s
//! exact model; the door pools them; every expectation is drawn from the
//! generator's inputs.
//!
//! - A batch: the batch error `b` (N(0, 0.2 mm) per coordinate), each
//!   machine's own deviation N(0, tau_k^2) (tau from 0.02 to 0.08 mm),
//!   sensors homed anywhere, and one machine assembled wrong (one joint off
//!   by 12 tau): the batch mean is within its stated sd of `b`, the spread
//!   within its stated sd of `tau^2`, the faulty machine and only it named
//!   an outlier, with the faulty parameter among its deviates.
//! - Clean batches: no machine named.
//! - New machines from the batch's prior, short campaigns: each file's
//!   promise kept on held-out targets (the true machine commanded with the
//!   file's inverse kinematics).
//! - Campaigns of one machine re-homed between them: pooled, more precise
//!   than any alone; a campaign taken after a leg slipped is named.
//!
//! The tallies (`#[ignore]`, `cargo test -p tricept-ident --test accuracy
//! fleet:: -- --ignored --nocapture`; `FLEET_SEED=103` runs one batch of
//! it) run more batches and measure how many poses a new machine needs
//! with the prior for the accuracy an 80-pose campaign gives alone.

use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde_json::Value;
use tricept_ident::advanced::ParameterSet;
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::fleet::{FleetRequest, fleet};
use tricept_ident::kinematics::GeometricMachine as Machine;
use tricept_ident::{DataInput, EXIT_INADEQUATE, EXIT_OK};
use tricept_truth::{Row, SensorNoise, TrueMachine, normal, to_csv};

use super::{TARGETS, delivered, scratch};

/// The paper's 15 parameters, in the door's order.
fn names() -> Vec<String> {
    ParameterSet::paper15().names().to_vec()
}

/// `truth` with the errors `e` (by name) added to its joints and legs
/// (`docs/conventions.md`).
fn with_errors(truth: &TrueMachine, e: &[(String, f64)]) -> TrueMachine {
    let mut t = truth.clone();
    for (name, v) in e {
        let v = *v;
        match name.as_str() {
            // The paper's convention dxB2 = dxB1: B1B2 stays parallel to y.
            "dxB1" => {
                t.base[0].x += v;
                t.base[1].x += v;
            }
            "dyB1" => t.base[0].y += v,
            "dyB2" => t.base[1].y += v,
            "dxB3" => t.base[2].x += v,
            "dyB3" => t.base[2].y += v,
            "dzB3" => t.base[2].z += v,
            "dxA1" => t.platform[0].x += v,
            "dyA1" => t.platform[0].y += v,
            "dxA2" => t.platform[1].x += v,
            "dyA2" => t.platform[1].y += v,
            "dxA3" => t.platform[2].x += v,
            "dyA3" => t.platform[2].y += v,
            "dq1" => t.leg_offsets_mm[0] += v,
            "dq2" => t.leg_offsets_mm[1] += v,
            "dq3" => t.leg_offsets_mm[2] += v,
            other => panic!("no coordinate for {other}"),
        }
    }
    t
}

/// A population of machines: the batch error and the spread per parameter.
struct Population {
    batch: Vec<f64>,
    tau: Vec<f64>,
}

impl Population {
    fn new(seed: u64) -> Population {
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0xba7c);
        let batch = (0..15).map(|_| 0.2 * normal(&mut rng)).collect();
        let tau = (0..15).map(|_| 0.02 + 0.06 * rng.random::<f64>()).collect();
        Population { batch, tau }
    }

    /// Machine `i`: the batch error, its own deviation, its sensors homed
    /// anywhere; `fault`: one parameter off by that much more.
    fn machine(&self, seed: u64, i: u64, fault: Option<(usize, f64)>) -> TrueMachine {
        let mut rng = Pcg64Mcg::seed_from_u64(seed.wrapping_mul(1_000_003) ^ i);
        let e: Vec<(String, f64)> = names()
            .into_iter()
            .enumerate()
            .map(|(k, n)| {
                let extra = fault.filter(|f| f.0 == k).map_or(0.0, |f| f.1);
                (n, self.batch[k] + self.tau[k] * normal(&mut rng) + extra)
            })
            .collect();
        let mut t = with_errors(&TrueMachine::documented(), &e);
        t.sensor_offsets = [
            0.02 * normal(&mut rng),
            0.02 * normal(&mut rng),
            -600.0 + 20.0 * normal(&mut rng),
        ];
        t
    }
}

/// A campaign of `n` random poses of `truth` (seed `seed`), written at
/// `path` with a logged temperature `temp_c`; its sensors `noise` times
/// noisier than the documented noise the data format states.
fn campaign_with(
    truth: &TrueMachine,
    n: usize,
    seed: u64,
    temp_c: Option<f64>,
    path: &Path,
    noise: f64,
) {
    let nominal = Machine::paper();
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0xca4b);
    let rows: Vec<Row> = nominal
        .workspace
        .random_poses(n, seed ^ 0x5eed)
        .iter()
        .filter_map(|r| nominal.inverse(r).ok().map(|s| s.legs_mm))
        .map(|q| Row {
            commands_mm: q,
            readings: truth.sensed(
                &truth.forward(&q),
                &SensorNoise::DOCUMENTED.times(noise),
                &mut rng,
            ),
            temp_c: temp_c.map(|t| t + 0.02 * normal(&mut rng)),
            directions: None,
        })
        .collect();
    std::fs::write(path, to_csv(&rows)).unwrap();
}

/// [`campaign_with`] at the documented noise.
fn campaign(truth: &TrueMachine, n: usize, seed: u64, temp_c: Option<f64>, path: &Path) {
    campaign_with(truth, n, seed, temp_c, path, 1.0);
}

/// `{name: value}` of a JSON object as numbers (`null` -> None).
fn values(v: &Value, names: &[String]) -> Vec<Option<f64>> {
    names.iter().map(|n| v[n].as_f64()).collect()
}

/// A batch of `machines` machines with `poses` poses each, machine 0
/// faulty when `fault` is given; returns the door's JSON and the files.
fn batch(
    pop: &Population,
    seed: u64,
    machines: u64,
    poses: usize,
    fault: Option<(usize, f64)>,
    dir: &Path,
) -> (tricept_ident::fleet::FleetResult, Vec<PathBuf>) {
    batch_with(pop, seed, machines, poses, fault, None, dir)
}

/// [`batch`] with machine `noisy`'s sensors three times noisier than
/// stated (its own data then do not fit).
fn batch_with(
    pop: &Population,
    seed: u64,
    machines: u64,
    poses: usize,
    fault: Option<(usize, f64)>,
    noisy: Option<u64>,
    dir: &Path,
) -> (tricept_ident::fleet::FleetResult, Vec<PathBuf>) {
    let files: Vec<PathBuf> = (0..machines)
        .map(|i| {
            let path = dir.join(format!("b{seed}-m{i}.csv"));
            let t = pop.machine(seed, i, if i == 0 { fault } else { None });
            let noise = if noisy == Some(i) { 3.0 } else { 1.0 };
            campaign_with(&t, poses, seed * 100 + i, None, &path, noise);
            path
        })
        .collect();
    let r = fleet(FleetRequest::new(
        files.iter().cloned().map(DataInput::File).collect(),
    ))
    .unwrap();
    (r, files)
}

#[test]
fn a_batch_is_estimated_in_truth_and_its_faulty_machine_named() {
    let dir = scratch("fleet-batch");
    let pop = Population::new(47);
    let names = names();
    let faulty = names.iter().position(|n| n == "dxA2").unwrap();
    let fault = 12.0 * pop.tau[faulty];
    // Machine 1's sensors are three times noisier than stated: its own
    // data do not fit, and it is kept out (not an outlier).
    let (r, files) = batch_with(&pop, 47, 21, 80, Some((faulty, fault)), Some(1), &dir);
    let json = r.to_json();
    assert_eq!(
        json["outliers"],
        serde_json::json!([files[0].display().to_string()]),
        "{}",
        r.report()
    );
    assert_eq!(
        r.exit_code(),
        EXIT_INADEQUATE,
        "a machine kept out is exit 3"
    );
    let machines = json["machines"].as_array().unwrap();
    assert!(
        machines[0]["deviates"]
            .as_array()
            .unwrap()
            .contains(&"dxA2".into()),
        "{}",
        machines[0]
    );
    let noisy = &machines[1];
    assert_eq!(
        (
            noisy["in_batch"].clone(),
            noisy["outlier"].clone(),
            noisy["exit_code"].clone()
        ),
        (false.into(), false.into(), 3.into()),
        "{noisy}"
    );
    assert!(
        noisy["kept_out"]
            .as_str()
            .unwrap()
            .contains("does not explain its own data"),
        "{noisy}"
    );
    for m in &machines[2..] {
        assert_eq!(m["in_batch"], true, "{m}");
        assert!(m["deviates"].as_array().unwrap().is_empty(), "{m}");
    }
    // The batch mean within 3 of its stated sd of the batch error, the
    // spread within 3 of its stated sd of tau^2 (a parameter no machine
    // sees, dyA3, is held, with no mean and no spread).
    let mean = values(&json["batch_mean_mm"], &names);
    let sd = values(&json["batch_mean_sd_mm"], &names);
    let spread = values(&json["batch_spread_mm"], &names);
    let b = r.batch();
    let (mut worst_mean, mut worst_spread) = (0.0f64, 0.0f64);
    for (k, n) in names.iter().enumerate() {
        if n == "dyA3" {
            assert!(mean[k].is_none() && spread[k].is_none(), "{n}");
            continue;
        }
        let z = (mean[k].unwrap() - pop.batch[k]) / sd[k].unwrap();
        worst_mean = worst_mean.max(z.abs());
        let a = b.identifiable.iter().position(|&j| j == k).unwrap();
        let zt = (spread[k].unwrap().powi(2) - pop.tau[k].powi(2)) / b.spread.variance_sd[a];
        worst_spread = worst_spread.max(zt.abs());
        eprintln!(
            "{n}: mean {:+.2} sd, spread {:.4} for {:.4} ({zt:+.2} sd)",
            z,
            spread[k].unwrap(),
            pop.tau[k]
        );
    }
    assert!(worst_mean < 3.0, "batch mean {worst_mean:.2} sd off");
    assert!(worst_spread < 3.0, "spread {worst_spread:.2} sd off");
    let solver = &json["solver"];
    assert_eq!(solver["kind"], "schur");
    assert_eq!(solver["readings"], 19 * 80 * 3);
    assert_eq!(solver["unknowns"], 19 * (3 + 14) + 14);
}

#[test]
fn clean_batches_name_no_machine() {
    let dir = scratch("fleet-clean");
    for seed in [1u64, 2, 3] {
        let pop = Population::new(seed);
        let (r, _) = batch(&pop, seed, 12, 60, None, &dir);
        let json = r.to_json();
        assert_eq!(
            json["outliers"],
            serde_json::json!([]),
            "seed {seed}: {}",
            r.report()
        );
        for m in json["machines"].as_array().unwrap() {
            assert!(
                m["deviates"].as_array().unwrap().is_empty(),
                "seed {seed}: {m}"
            );
        }
    }
}

/// A new machine of the population: its campaign of `poses` poses
/// calibrated with `prior` (or alone), written, and commanded on held-out
/// targets: `(exit code, promised rms, upper bound, delivered rms)`.
fn new_machine(
    pop: &Population,
    seed: u64,
    poses: usize,
    prior: Option<&Path>,
    dir: &Path,
) -> (u8, f64, f64, f64) {
    let truth = pop.machine(seed, 1_000_000, None);
    let data = dir.join(format!("new-{seed}-{poses}.csv"));
    campaign(&truth, poses, seed ^ 0xfee1, None, &data);
    let mut request = CalibrateRequest::new(DataInput::File(data));
    request.prior = prior.map(Path::to_path_buf);
    let c = calibrate(request).unwrap();
    let a = c.to_json()["accuracy"].clone();
    let (rms, upper) = (
        a["rms_mm"].as_f64().unwrap(),
        a["upper_mm"].as_f64().unwrap(),
    );
    if c.exit_code() != EXIT_OK {
        return (c.exit_code(), rms, upper, f64::NAN);
    }
    let file = dir.join(format!("new-{seed}-{poses}-{}.json", prior.is_some()));
    c.write_machine(&file, tricept_ident::WriteOptions::default())
        .unwrap();
    let targets = Machine::paper()
        .workspace
        .random_poses(TARGETS, seed ^ 0x07a2);
    let (sum, count) = delivered(&file, &truth, &[], &targets, dir);
    assert!(count > TARGETS / 2);
    (EXIT_OK, rms, upper, (sum / count as f64).sqrt())
}

#[test]
fn new_machines_calibrated_from_the_batch_keep_their_promise_in_truth() {
    let dir = scratch("fleet-new");
    let pop = Population::new(48);
    let (r, _) = batch(&pop, 48, 16, 80, None, &dir);
    let prior = dir.join("prior.json");
    assert_eq!(
        r.write_prior(&prior, tricept_ident::WriteOptions::default())
            .unwrap()
            .forced(),
        None
    );
    for seed in 0..6u64 {
        let (exit, rms, upper, got) = new_machine(&pop, 480 + seed, 10, Some(&prior), &dir);
        assert_eq!(exit, EXIT_OK, "seed {seed}");
        assert!(
            got <= upper,
            "seed {seed}: delivered {got:.4} mm beyond the promise {upper:.4} (rms {rms:.4})"
        );
        // Alone, ten poses cannot calibrate this well.
        let (_, alone_rms, _, _) = new_machine(&pop, 480 + seed, 10, None, &dir);
        assert!(rms < alone_rms, "seed {seed}: {rms} >= {alone_rms}");
    }
    // An edited prior is refused, naming the field.
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&prior).unwrap()).unwrap();
    v["mean_mm"]["dq1"] = (v["mean_mm"]["dq1"].as_f64().unwrap() + 0.01).into();
    let edited = dir.join("edited.json");
    std::fs::write(&edited, v.to_string()).unwrap();
    let mut request = CalibrateRequest::new(DataInput::File(dir.join("new-480-10.csv")));
    request.prior = Some(edited);
    let e = calibrate(request).unwrap_err();
    assert_eq!(e.exit_code(), tricept_ident::EXIT_INPUT);
    assert!(e.message().contains("mean_mm"), "{e}");
}

#[test]
fn campaigns_of_one_machine_pool_and_a_changed_one_is_named() {
    let dir = scratch("fleet-campaigns");
    let pop = Population::new(49);
    let truth = pop.machine(49, 7, None);
    // Three campaigns, the sensors homed again before each, 20.0, 20.6
    // and 21.1 °C logged; a fourth after leg 2 slipped by 40 um.
    let files: Vec<PathBuf> = (0..4)
        .map(|c| {
            let mut t = truth.clone();
            t.sensor_offsets = [0.01 * c as f64, -0.02 * c as f64, -600.0 - 3.0 * c as f64];
            if c == 3 {
                t.leg_offsets_mm[1] += 0.040;
            }
            let path = dir.join(format!("campaign-{c}.csv"));
            campaign(&t, 60, 4900 + c, Some(20.0 + 0.55 * c as f64), &path);
            path
        })
        .collect();
    let calibrate_all = |files: &[PathBuf]| {
        let mut request = CalibrateRequest::new(DataInput::File(files[0].clone()));
        request.campaigns = files[1..].iter().cloned().map(DataInput::File).collect();
        calibrate(request).unwrap()
    };
    let pooled = calibrate_all(&files[..3]);
    assert_eq!(pooled.exit_code(), EXIT_OK, "{}", pooled.report());
    let json = pooled.to_json();
    let campaigns = json["campaigns"].as_array().unwrap();
    assert_eq!(campaigns.len(), 3);
    for (c, row) in campaigns.iter().enumerate() {
        // Each campaign's offsets are its own homing, within 4 sd.
        let homed = [0.01 * c as f64, -0.02 * c as f64, -600.0 - 3.0 * c as f64];
        for (ch, key) in ["phi_rad", "theta_rad", "s_mm"].iter().enumerate() {
            let o = &row["offsets"];
            let z = (o[key].as_f64().unwrap() - homed[ch]) / o["std_dev"][key].as_f64().unwrap();
            assert!(z.abs() < 4.0, "campaign {c} {key}: {z:.1} sd: {row}");
        }
        assert!(row["chi_square"].as_f64().unwrap() > 0.0);
        let t = row["temperature_c"].as_f64().unwrap();
        assert!((t - (20.0 + 0.55 * c as f64)).abs() < 0.01, "{row}");
    }
    let names = names();
    let sd = values(&json["std_dev_mm"], &names);
    for f in &files[..3] {
        let alone = calibrate(CalibrateRequest::new(DataInput::File(f.clone()))).unwrap();
        let alone_sd = values(&alone.to_json()["std_dev_mm"], &names);
        for k in 0..15 {
            if let (Some(p), Some(a)) = (sd[k], alone_sd[k]) {
                assert!(p < a, "{}: pooled {p} >= alone {a}", names[k]);
            }
        }
    }
    let with_slip = calibrate_all(&files);
    let json = with_slip.to_json();
    assert_eq!(
        with_slip.exit_code(),
        EXIT_INADEQUATE,
        "{}",
        with_slip.report()
    );
    assert_eq!(
        json["disagreeing_campaigns"],
        serde_json::json!([files[3].display().to_string()])
    );
    // Not averaged in: the estimate is the other three's.
    let est = values(&json["estimates_mm"], &names);
    let without = values(&pooled.to_json()["estimates_mm"], &names);
    assert_eq!(est, without);
}

#[test]
#[ignore = "the fleet tally of docs/fleet.md"]
fn tally_of_batches_and_new_machines() {
    let dir = scratch("fleet-tally");
    let (mut named_right, mut named_wrong, mut batches) = (0, 0, 0);
    let (mut mean_within, mut spread_within, mut params) = (0, 0, 0);
    let only: Option<u64> = std::env::var("FLEET_SEED")
        .ok()
        .and_then(|s| s.parse().ok());
    for seed in (100..130u64).filter(|s| only.is_none_or(|o| o == *s)) {
        let pop = Population::new(seed);
        let faulty = (seed % 15) as usize;
        let fault = if names()[faulty] == "dyA3" {
            None
        } else {
            Some((faulty, 12.0 * pop.tau[faulty]))
        };
        let (r, files) = batch(&pop, seed, 20, 80, fault, &dir);
        let json = r.to_json();
        let outliers: Vec<String> = json["outliers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        batches += 1;
        if fault.is_some() && outliers == vec![files[0].display().to_string()] {
            named_right += 1;
        }
        named_wrong += outliers
            .iter()
            .filter(|o| **o != files[0].display().to_string())
            .count();
        if fault.is_some() != (outliers == vec![files[0].display().to_string()])
            || outliers.len() > 1
        {
            let m0 = &json["machines"][0];
            eprintln!(
                "seed {seed}: fault {:?} ({}), named {} machine(s): {:?}; machine 0 distance {} deviates {}",
                fault.map(|f| (names()[f.0].clone(), f.1)),
                fault.map_or(String::new(), |f| format!("{:.3} mm spread", pop.tau[f.0])),
                outliers.len(),
                outliers
                    .iter()
                    .map(|o| o.rsplit('/').next().unwrap_or(o))
                    .collect::<Vec<_>>(),
                m0["distance"],
                m0["deviates"]
            );
            if let Some((k, _)) = fault {
                let n = &names()[k];
                eprintln!(
                    "  {n}: machine 0 {} (sd {}), batch mean {} spread {}, truth batch {:.4} machine 0 {:.4}",
                    m0["estimates_mm"][n],
                    m0["std_dev_mm"][n],
                    json["batch_mean_mm"][n],
                    json["batch_spread_mm"][n],
                    pop.batch[k],
                    pop.batch[k]
                );
            }
        }
        let b = r.batch();
        let (mean, sd) = b.mean();
        for (a, &k) in b.identifiable.iter().enumerate() {
            params += 1;
            mean_within += usize::from(((mean[k] - pop.batch[k]) / sd[k].unwrap()).abs() < 2.0);
            spread_within += usize::from(
                ((b.spread.variance[a] - pop.tau[k].powi(2)) / b.spread.variance_sd[a]).abs() < 2.0,
            );
        }
    }
    eprintln!(
        "TALLY fleet: batches {batches}, faulty machine named alone {named_right} of {}, clean machines named {named_wrong}, batch mean within 2 sd {mean_within} of {params}, spread within 2 sd {spread_within} of {params}",
        (100..130u64)
            .filter(|s| names()[(s % 15) as usize] != "dyA3")
            .count()
    );
    // How many poses with the prior give what 80 alone give.
    let pop = Population::new(200);
    let (r, _) = batch(&pop, 200, 20, 80, None, &dir);
    let prior = dir.join("tally-prior.json");
    r.write_prior(&prior, tricept_ident::WriteOptions::default())
        .unwrap();
    let trials = 20u64;
    let alone: Vec<f64> = (0..trials)
        .map(|s| new_machine(&pop, 2000 + s, 80, None, &dir).3)
        .collect();
    let alone_mean = (alone.iter().map(|x| x * x).sum::<f64>() / trials as f64).sqrt();
    eprintln!("TALLY 80 poses alone: delivered rms {alone_mean:.4} mm over {trials} machines");
    for poses in [6usize, 8, 10, 12, 15, 20, 30, 40, 80] {
        let runs: Vec<(u8, f64, f64, f64)> = (0..trials)
            .map(|s| new_machine(&pop, 2000 + s, poses, Some(&prior), &dir))
            .collect();
        let written: Vec<&(u8, f64, f64, f64)> = runs.iter().filter(|r| r.0 == EXIT_OK).collect();
        let within = written.iter().filter(|r| r.3 <= r.2).count();
        let delivered =
            (written.iter().map(|r| r.3 * r.3).sum::<f64>() / written.len().max(1) as f64).sqrt();
        let promised =
            (written.iter().map(|r| r.1 * r.1).sum::<f64>() / written.len().max(1) as f64).sqrt();
        eprintln!(
            "TALLY {poses} poses with the prior: written {} of {trials}, within the promise {within}, delivered rms {delivered:.4} mm, promised rms {promised:.4} mm",
            written.len()
        );
    }
}
