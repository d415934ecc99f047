//! The accuracy a machine file promises, kept in truth: campaigns of 40-200
//! poses from the independent generator (`tricept-truth`: a true machine
//! written from the documented conventions, leg effects hidden in its true
//! leg lengths, never through the simulator's effect code), calibrated by
//! the door, written as a machine file, and the true machine commanded
//! with that file on held-out targets over the workspace: the controller
//! computes the leg commands of a target with the FILE's inverse
//! kinematics, the true machine's forward kinematics from those commands
//! says where the platform goes. The delivered rms must be within the
//! file's `upper_mm` in at least 95 % of the files written with exit 0,
//! and never beyond twice it.
//!
//! The CI test runs 24 campaigns; the tally of `docs/reliability.md` runs
//! 200 (`cargo test -p tricept-ident --test accuracy -- --ignored
//! --nocapture`).

use std::path::Path;

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use tricept_ident::serde_json;
use tricept_ident::tricept_kinematics::Machine;
use tricept_ident::{CalibrateRequest, Data, SensorNoise, calibrate, load_machine};
use tricept_truth::{LegEffect, Row, TrueMachine, to_csv};

/// Held-out targets per file.
const TARGETS: usize = 60;

/// A leg effect of kind `kind` (0..5) at a random realistic size.
fn effect(kind: u64, m: &Machine, rng: &mut Pcg64Mcg) -> LegEffect {
    // Log-uniform sizes from barely visible to clearly inadequate.
    let mut size = |lo: f64, hi: f64| lo * (hi / lo).powf(rng.random::<f64>());
    let sign = |x: f64, r: bool| if r { x } else { -x };
    match kind {
        0 => LegEffect::EvenHeating {
            kelvin: size(0.01, 0.5),
            ppm_per_k: 11.5,
        },
        1 => LegEffect::UnevenHeating {
            kelvin: [size(0.01, 0.5), size(0.01, 0.5), size(0.01, 0.5)],
            ppm_per_k: 11.5,
        },
        2 => {
            let ppm = [size(0.2, 25.0), size(0.2, 25.0), size(0.2, 25.0)];
            LegEffect::Lead {
                ppm: [
                    sign(ppm[0], ppm[1] > 2.0),
                    ppm[1],
                    sign(ppm[2], ppm[0] > 2.0),
                ],
            }
        }
        3 => LegEffect::Quadratic {
            leg: (size(1.0, 3.0) as usize) % 3,
            peak_um: size(0.5, 12.0),
            stroke_mm: m.limits.leg_stroke_mm,
        },
        _ => LegEffect::Slip {
            leg: (size(1.0, 3.0) as usize) % 3,
            um: size(0.5, 8.0),
            at: 0.3 + 0.4 * size(1.0, 2.0) - 0.4,
        },
    }
}

/// The effects of campaign `seed`: one kind, or two kinds, in turn.
fn effects(seed: u64, m: &Machine, rng: &mut Pcg64Mcg) -> Vec<LegEffect> {
    const KINDS: u64 = 5;
    let combo = seed % (KINDS + KINDS * (KINDS - 1) / 2 + 1);
    if combo == 0 {
        return Vec::new();
    }
    if combo <= KINDS {
        return vec![effect(combo - 1, m, rng)];
    }
    // The pairs (a, b), a < b, numbered from KINDS + 1.
    let mut n = KINDS;
    for a in 0..KINDS {
        for b in a + 1..KINDS {
            n += 1;
            if n == combo {
                return vec![effect(a, m, rng), effect(b, m, rng)];
            }
        }
    }
    Vec::new()
}

/// One file: its exit code, and when written its promise and delivery.
#[derive(Debug)]
struct Outcome {
    seed: u64,
    poses: usize,
    effects: Vec<LegEffect>,
    exit: u8,
    rms_mm: f64,
    upper_mm: f64,
    delivered_mm: f64,
    parts: serde_json::Value,
}

/// Campaign `seed`: simulated by the independent generator, calibrated
/// and written in `dir`, and (exit 0) commanded on held-out targets.
fn campaign(seed: u64, dir: &Path) -> Outcome {
    let nominal = Machine::paper();
    let truth = TrueMachine::random(0.0, seed);
    let mut rng = Pcg64Mcg::seed_from_u64(seed.wrapping_mul(0x9e37_79b9) ^ 0xacc);
    let poses = 40 + (rng.random::<f64>() * 161.0) as usize;
    let effects = effects(seed, &nominal, &mut rng);
    let commands: Vec<[f64; 3]> = nominal
        .workspace
        .random_poses(poses, seed ^ 0x5eed)
        .iter()
        .filter_map(|r| nominal.inverse(r).ok().map(|s| s.legs_mm))
        .collect();
    let n = commands.len();
    let rows: Vec<Row> = commands
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let t = i as f64 / (n - 1).max(1) as f64;
            let joints = truth.forward_lengths(&truth.lengths_with(q, &effects, t));
            Row {
                commands_mm: *q,
                readings: truth.sensed(&joints, &tricept_truth::SensorNoise::DOCUMENTED, &mut rng),
                temp_c: None,
                directions: None,
            }
        })
        .collect();
    let data = dir.join(format!("campaign-{seed}.csv"));
    std::fs::write(&data, to_csv(&rows)).unwrap();
    let mut c = calibrate(&CalibrateRequest::new(Data::File(data))).unwrap();
    let exit = c.exit_code();
    let json = c.to_json();
    let a = &json["accuracy"];
    let (rms_mm, upper_mm) = (
        a["rms_mm"].as_f64().unwrap(),
        a["upper_mm"].as_f64().unwrap(),
    );
    assert_eq!(a["point"], "platform");
    let mut outcome = Outcome {
        seed,
        poses: n,
        effects: effects.clone(),
        exit,
        rms_mm,
        upper_mm,
        delivered_mm: f64::NAN,
        parts: a["parts"].clone(),
    };
    if exit != 0 {
        return outcome;
    }
    let file = dir.join(format!("machine-{seed}.json"));
    c.write_machine(&file, false).unwrap();
    let loaded = load_machine(Some(&file), &SensorNoise::default()).unwrap();
    let record = loaded.description().calibration.as_ref().unwrap();
    let promise = record.accuracy.as_ref().unwrap();
    assert_eq!(
        (promise.rms_mm, promise.upper_mm),
        (rms_mm, upper_mm),
        "the file promises what the JSON says"
    );
    let targets = nominal.workspace.random_poses(TARGETS, seed ^ 0x7a26_e75);
    let mut sum = 0.0;
    let mut count = 0usize;
    for target in &targets {
        let Ok(ik) = loaded.machine().inverse(target) else {
            continue;
        };
        let joints = truth.forward_lengths(&truth.delivered_lengths(&ik.legs_mm, &effects));
        sum += (TrueMachine::platform_point(&joints) - target).norm_squared();
        count += 1;
    }
    assert!(count > TARGETS / 2, "seed {seed}: {count} targets reached");
    outcome.delivered_mm = (sum / count as f64).sqrt();
    outcome
}

/// The tally of `seeds`: (written, within the promise, beyond twice it).
fn tally(seeds: impl Iterator<Item = u64>, dir: &Path) -> (Vec<Outcome>, usize, usize, usize) {
    let outcomes: Vec<Outcome> = seeds.map(|s| campaign(s, dir)).collect();
    let written: Vec<&Outcome> = outcomes.iter().filter(|o| o.exit == 0).collect();
    let within = written
        .iter()
        .filter(|o| o.delivered_mm <= o.upper_mm)
        .count();
    let beyond = written
        .iter()
        .filter(|o| o.delivered_mm > 2.0 * o.upper_mm)
        .count();
    for o in &outcomes {
        eprintln!(
            "seed {:>3} poses {:>3} exit {} rms {:.4} upper {:.4} delivered {:.4} ratio {:.2} {:?} {}",
            o.seed,
            o.poses,
            o.exit,
            o.rms_mm,
            o.upper_mm,
            o.delivered_mm,
            o.delivered_mm / o.upper_mm,
            o.effects,
            o.parts
        );
    }
    let n = written.len();
    (outcomes, n, within, beyond)
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-accuracy-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn files_written_at_exit_0_deliver_their_promise_in_truth() {
    let dir = scratch("ci");
    let (outcomes, written, within, beyond) = tally(1..=24, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!("written {written}, within {within}, beyond 2x {beyond}");
    // Enough files are written to judge, and some are refused: the
    // effects range from invisible to plainly not geometric.
    assert!(
        written >= 10,
        "{written} files written of {}",
        outcomes.len()
    );
    assert!(written < outcomes.len(), "no campaign was refused");
    assert!(
        within as f64 >= 0.95 * written as f64 - 1e-9 || written - within <= 1,
        "{within} of {written} within the promise"
    );
    assert_eq!(beyond, 0, "a file delivered beyond twice its promise");
}

#[test]
#[ignore = "the tally of docs/reliability.md: 200 campaigns, minutes"]
fn tally_of_200_campaigns() {
    let dir = scratch("tally");
    let (outcomes, written, within, beyond) = tally(1000..1200, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "campaigns {}, files written (exit 0) {written}, within the promise {within}, beyond 2x {beyond}",
        outcomes.len()
    );
    assert!(within as f64 >= 0.95 * written as f64);
    assert_eq!(beyond, 0);
}

#[test]
fn an_edited_promise_is_refused() {
    let dir = scratch("seal");
    let outcome = campaign(0, &dir);
    assert_eq!(outcome.exit, 0, "{outcome:?}");
    let file = dir.join("machine-0.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let better = v["calibration"]["accuracy"]["upper_mm"].as_f64().unwrap() / 2.0;
    v["calibration"]["accuracy"]["upper_mm"] = better.into();
    std::fs::write(&file, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let e = load_machine(Some(&file), &SensorNoise::default()).unwrap_err();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(e.exit_code(), tricept_ident::EXIT_INPUT, "{e}");
    assert!(e.message().contains("calibration.accuracy"), "{e}");
}
