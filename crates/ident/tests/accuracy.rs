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
//! The pooled calibrations (campaigns, batches, new machines from a
//! batch's prior) are kept in truth in `accuracy/fleet.rs`.
//!
//! The CI tests run 24 campaigns through `identify` and 12 through
//! `diagnose --write-machine`; the tallies of `docs/reliability.md` run 200
//! each (`cargo test -p tricept-ident --test accuracy -- --ignored
//! --nocapture`; `TRICEPT_TALLY_SEED_OFFSET=2000` runs them on another 200
//! seeds each; `TRICEPT_TALLY_DEPLOY_RULE=expected-error` diagnoses with
//! that deploy rule).

#[path = "accuracy/fleet.rs"]
mod fleet;

use std::path::Path;

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use tricept_ident::advanced::nalgebra::Vector3;
use tricept_ident::advanced::{SensorNoise, load_machine};
use tricept_ident::calibrate::{CalibrateRequest, calibrate};
use tricept_ident::compensate::{Calibrated, CompensateRequest, compensate};
use tricept_ident::diagnosis::{DeployRule, DiagnoseRequest, diagnose};
use tricept_ident::kinematics::GeometricMachine as Machine;
use tricept_ident::{DataInput, MachineInput};
use tricept_truth::{LegContext, LegEffect, Row, TrueMachine, to_csv};

/// Held-out targets per file.
const TARGETS: usize = 60;

/// A leg effect of kind `kind` (0..5) at a random realistic size.
fn effect(kind: u64, m: &Machine, rng: &mut Pcg64Mcg) -> LegEffect {
    // Log-uniform sizes from barely visible to clearly inadequate.
    let mut size = |lo: f64, hi: f64| lo * (hi / lo).powf(rng.random::<f64>());
    let sign = |x: f64, r: bool| if r { x } else { -x };
    match kind {
        0 => LegEffect::Drift {
            kelvin: [size(0.01, 0.5); 3],
            ppm_per_k: 11.5,
        },
        1 => LegEffect::Drift {
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
        3 => {
            let mut um = [0.0; 3];
            um[(size(1.0, 3.0) as usize) % 3] = size(0.5, 12.0);
            let [start, end] = m.limits.leg_stroke_mm;
            LegEffect::Quadratic {
                um,
                centre_mm: 0.5 * (start + end),
                half_width_mm: 0.5 * (end - start),
            }
        }
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
    /// (`diagnose`) what identify's geometric file delivers, written with
    /// `--force` when it must be.
    geometric_mm: f64,
    /// (`diagnose`, compared) under the other deploy rule: its exit code,
    /// what its file delivers, and whether it deploys other terms.
    other: Option<(u8, f64, bool)>,
}

/// The verb that writes the file.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Verb {
    Identify,
    /// `diagnose --write-machine` under a deploy rule.
    Diagnose(DeployRule),
    /// `diagnose --write-machine` under a deploy rule and, compared, under
    /// the other rule ([`other_rule`]).
    DiagnoseCompared(DeployRule),
}

/// Campaign `seed`: simulated by the independent generator, calibrated
/// and written in `dir`, and (exit 0) commanded on held-out targets.
fn campaign(seed: u64, dir: &Path, verb: Verb) -> Outcome {
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
            let joints =
                truth.forward_lengths(&truth.lengths_with(q, &effects, &LegContext::at_share(t)));
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
    let targets = nominal.workspace.random_poses(TARGETS, seed ^ 0x07a2_6e75);
    let c = calibrate(CalibrateRequest::new(DataInput::File(data.clone()))).unwrap();
    let identify_file = dir.join(format!("identify-{seed}.json"));
    let mut outcome = Outcome {
        seed,
        poses: n,
        effects: effects.clone(),
        exit: c.exit_code(),
        rms_mm: f64::NAN,
        upper_mm: f64::NAN,
        delivered_mm: f64::NAN,
        parts: serde_json::Value::Null,
        geometric_mm: f64::NAN,
        other: None,
    };
    let file = match verb {
        Verb::Identify => {
            let json = c.to_json();
            let a = &json["accuracy"];
            assert_eq!(a["point"], "platform");
            assert!(first_lines_state_it(&c.report()), "{}", c.report());
            outcome.rms_mm = a["rms_mm"].as_f64().unwrap();
            outcome.upper_mm = a["upper_mm"].as_f64().unwrap();
            outcome.parts = a["parts"].clone();
            if outcome.exit != 0 {
                return outcome;
            }
            c.write_machine(&identify_file, tricept_ident::WriteOptions::default())
                .unwrap();
            identify_file
        }
        Verb::Diagnose(rule) | Verb::DiagnoseCompared(rule) => {
            c.write_machine(
                &identify_file,
                tricept_ident::WriteOptions::default().force(true),
            )
            .unwrap();
            let (sum, count) = delivered(&identify_file, &truth, &effects, &targets, dir);
            outcome.geometric_mm = (sum / count as f64).sqrt();
            let diagnosed = |rule: DeployRule| {
                let loaded = load_machine(None, &SensorNoise::default()).unwrap();
                let mut request =
                    DiagnoseRequest::new(DataInput::File(data.clone())).machine(loaded);
                request.deploy_rule = rule;
                let r = diagnose(request).unwrap();
                if std::env::var_os("TRICEPT_TALLY_TERMS").is_some() {
                    eprintln!(
                        "seed {seed} {} terms: {}",
                        rule.name(),
                        terms_line(&r.to_json().to_string())
                    );
                }
                r
            };
            let r = diagnosed(rule);
            outcome.exit = r.exit_code();
            if verb == Verb::DiagnoseCompared(rule) {
                let o = diagnosed(other_rule(rule));
                let changed = deployed_terms(&o.to_json().to_string())
                    != deployed_terms(&r.to_json().to_string());
                let mut delivered_mm = f64::NAN;
                if o.exit_code() == 0 {
                    let file = dir.join(format!("diagnose-other-{seed}.json"));
                    o.write_machine(&file, tricept_ident::WriteOptions::default())
                        .unwrap();
                    let (sum, count) = delivered(&file, &truth, &effects, &targets, dir);
                    delivered_mm = (sum / count as f64).sqrt();
                }
                outcome.other = Some((o.exit_code(), delivered_mm, changed));
            }
            if outcome.exit != 0 {
                return outcome;
            }
            let file = dir.join(format!("diagnose-{seed}.json"));
            r.write_machine(&file, tricept_ident::WriteOptions::default())
                .unwrap();
            let a = r.accuracy().unwrap();
            let json = r.to_json();
            assert_eq!(json["accuracy"]["upper_mm"].as_f64(), Some(a.upper_mm));
            assert!(first_lines_state_it(&r.report()), "{}", r.report());
            outcome.rms_mm = a.rms_mm;
            outcome.upper_mm = a.upper_mm;
            outcome.parts = serde_json::Value::Object(a.parts.clone());
            file
        }
    };
    let loaded = load_machine(Some(&file), &SensorNoise::default()).unwrap();
    let record = loaded.description().calibration.as_ref().unwrap();
    let promise = record.accuracy.as_ref().unwrap();
    assert_eq!(
        (promise.rms_mm, promise.upper_mm),
        (outcome.rms_mm, outcome.upper_mm),
        "the file promises what the JSON says"
    );
    let (sum, count) = delivered(&file, &truth, &effects, &targets, dir);
    assert!(count > TARGETS / 2, "seed {seed}: {count} targets reached");
    outcome.delivered_mm = (sum / count as f64).sqrt();
    outcome
}

/// The descriptions of the terms a diagnosis' JSON deploys.
fn deployed_terms(json: &str) -> Vec<String> {
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    v["model_terms"]
        .as_array()
        .map(|terms| {
            terms
                .iter()
                .filter(|t| t["deployed"] == true)
                .filter_map(|t| t["description"].as_str().map(str::to_string))
                .collect()
        })
        .unwrap_or_default()
}

/// Each model term of a diagnosis' JSON in a few numbers (um): how the
/// deploy rule judged it.
fn terms_line(json: &str) -> String {
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    let um = |t: &serde_json::Value, k: &str| {
        t[k].as_f64()
            .map_or("-".to_string(), |x| format!("{:.1}", 1e3 * x))
    };
    let f = &v["final"];
    let fit = format!(
        "final chi2/dof {:.2} (p {:.3}), held-out rms {:.2} (noise = 1); ",
        f["chi_square"].as_f64().unwrap_or(f64::NAN) / f["dof"].as_f64().unwrap_or(f64::NAN),
        f["p_value"].as_f64().unwrap_or(f64::NAN),
        v["gain"]["holdout_rms_extended"]
            .as_f64()
            .unwrap_or(f64::NAN)
    );
    fit + &v["model_terms"]
        .as_array()
        .map(|terms| {
            terms
                .iter()
                .map(|t| {
                    format!(
                        "{}{}: benefit {} +- {}, improvement {} +- {} (move {}), expected {} with, {} without",
                        t["description"].as_str().unwrap_or("?"),
                        if t["deployed"] == true { "" } else { " (kept back)" },
                        um(t, "holdout_benefit_mm"),
                        um(t, "holdout_benefit_sd_mm"),
                        um(t, "improvement_mm"),
                        um(t, "improvement_sd_mm"),
                        um(t, "difference_sd_mm"),
                        um(t, "expected_rms_with_mm"),
                        um(t, "expected_rms_without_mm"),
                    )
                })
                .collect::<Vec<_>>()
                .join("; ")
        })
        .unwrap_or_default()
}

/// Whether a report states the promise in its first lines.
fn first_lines_state_it(report: &str) -> bool {
    report
        .lines()
        .take(3)
        .any(|l| l.starts_with("accuracy this file will deliver:"))
}

/// Where the true machine with `effects` puts the platform when the
/// controller commands `targets` with the machine file `file` (the door's
/// compensate): `(sum of squared errors mm^2, targets reached)`.
fn delivered(
    file: &Path,
    truth: &TrueMachine,
    effects: &[LegEffect],
    targets: &[Vector3<f64>],
    dir: &Path,
) -> (f64, usize) {
    let csv: String = std::iter::once("x,y,z\n".to_string())
        .chain(
            targets
                .iter()
                .map(|t| format!("{:?},{:?},{:?}\n", t.x, t.y, t.z)),
        )
        .collect();
    let path = dir.join(format!(
        "targets-{}.csv",
        file.file_stem().unwrap().to_string_lossy()
    ));
    std::fs::write(&path, csv).unwrap();
    let mut request = CompensateRequest::new(Calibrated::MachineFile(MachineInput::from(file)));
    request.targets = Some(path);
    request.spacing_mm = 200.0;
    // identify's geometric file of a diagnosed campaign may be forced.
    request.force = true;
    let compensation = compensate(request).unwrap();
    let mut sum = 0.0;
    let mut count = 0usize;
    for (target, q) in compensation.corrected_targets().unwrap() {
        let joints = truth.forward_lengths(&truth.delivered_lengths(q, effects));
        sum += (truth.position(&joints) - target).norm_squared();
        count += 1;
    }
    (sum, count)
}

/// The tally of `seeds`: (written, within the promise, beyond twice it).
fn tally(
    seeds: impl Iterator<Item = u64>,
    dir: &Path,
    verb: Verb,
) -> (Vec<Outcome>, usize, usize, usize) {
    let outcomes: Vec<Outcome> = seeds.map(|s| campaign(s, dir, verb)).collect();
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
            "seed {:>3} poses {:>3} exit {} rms {:.4} upper {:.4} delivered {:.4} ratio {:.2} geometric {:.4} {:?} {}",
            o.seed,
            o.poses,
            o.exit,
            o.rms_mm,
            o.upper_mm,
            o.delivered_mm,
            o.delivered_mm / o.upper_mm,
            o.geometric_mm,
            o.effects,
            o.parts
        );
    }
    let n = written.len();
    (outcomes, n, within, beyond)
}

/// The deploy rule of the diagnosed campaigns: `TRICEPT_TALLY_DEPLOY_RULE`
/// (`confident` or `expected-error`), or the default.
fn deploy_rule() -> DeployRule {
    std::env::var("TRICEPT_TALLY_DEPLOY_RULE")
        .map(|s| s.parse().expect("TRICEPT_TALLY_DEPLOY_RULE: a deploy rule"))
        .unwrap_or_default()
}

/// The rule a tally compares `rule` with.
fn other_rule(rule: DeployRule) -> DeployRule {
    if rule == DeployRule::Confident {
        DeployRule::ExpectedError
    } else {
        DeployRule::Confident
    }
}

/// The 200 seeds of a tally from `first`, moved by
/// `TRICEPT_TALLY_SEED_OFFSET` (another seed set: `2000` runs the identify
/// tally on seeds 3000-3199); `TRICEPT_TALLY_SEEDS=2127,2174` runs only
/// those of them.
fn seeds(first: u64) -> Vec<u64> {
    let offset: u64 = std::env::var("TRICEPT_TALLY_SEED_OFFSET")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let only: Option<Vec<u64>> = std::env::var("TRICEPT_TALLY_SEEDS")
        .ok()
        .map(|v| v.split(',').filter_map(|s| s.trim().parse().ok()).collect());
    (first + offset..first + offset + 200)
        .filter(|s| only.as_ref().is_none_or(|o| o.contains(s)))
        .collect()
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tricept-accuracy-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn files_written_at_exit_0_deliver_their_promise_in_truth() {
    let dir = scratch("ci");
    let (outcomes, written, within, beyond) = tally(1..=24, &dir, Verb::Identify);
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
#[ignore = "the identify tally of docs/reliability.md: 200 campaigns"]
fn tally_of_200_campaigns() {
    let dir = scratch("tally");
    let (outcomes, written, within, beyond) = tally(seeds(1000).into_iter(), &dir, Verb::Identify);
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "campaigns {}, files written (exit 0) {written}, within the promise {within}, beyond 2x {beyond}, median delivered/upper {:.2}",
        outcomes.len(),
        median_ratio(&outcomes)
    );
    assert!(within as f64 >= 0.95 * written as f64);
    assert_eq!(beyond, 0);
}

/// The median of delivered / `upper_mm` over the files written: how
/// tight the promise is.
fn median_ratio(outcomes: &[Outcome]) -> f64 {
    let mut r: Vec<f64> = outcomes
        .iter()
        .filter(|o| o.exit == 0)
        .map(|o| o.delivered_mm / o.upper_mm)
        .collect();
    r.sort_by(f64::total_cmp);
    r.get(r.len() / 2).copied().unwrap_or(f64::NAN)
}

#[test]
fn an_edited_promise_is_refused() {
    let dir = scratch("seal");
    let outcome = campaign(0, &dir, Verb::Identify);
    assert_eq!(outcome.exit, 0, "{outcome:?}");
    let file = dir.join("identify-0.json");
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

#[test]
fn diagnosed_files_state_and_keep_their_promise() {
    let dir = scratch("diagnose-ci");
    let (outcomes, written, within, beyond) =
        tally(2000..2012, &dir, Verb::Diagnose(DeployRule::default()));
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        written >= 6,
        "{written} files written of {}",
        outcomes.len()
    );
    assert!(
        written - within <= 1,
        "{within} of {written} within the promise"
    );
    assert_eq!(beyond, 0, "a file delivered beyond twice its promise");
}

/// The four campaigns of the diagnose tally whose nearly right terms (a
/// drift where the legs grow with their length, a curved leg beside an
/// unexplained slip, a scale gain for a lead with a curved screw) moved the
/// platform along the direction the readings cannot see, and were deployed
/// worse than identify's file until the move had to stand out of the legs'
/// structure (docs/diagnosis.md, `holdout::structured_sd`): under the
/// confident rule, whose threshold that structure sets, none is now. (The
/// default rule deploys the curved leg, 2127, by its expected error at 1.9
/// sd: one of its explained worse files, docs/reliability.md.)
#[test]
fn moves_the_readings_cannot_see_are_not_deployed_worse() {
    let dir = scratch("weak-direction");
    let (outcomes, _, _, _) = tally(
        [2065, 2066, 2127, 2141].into_iter(),
        &dir,
        Verb::Diagnose(DeployRule::Confident),
    );
    let _ = std::fs::remove_dir_all(&dir);
    let worse: Vec<(u64, f64, f64)> = outcomes
        .iter()
        .filter(|o| o.exit == 0 && o.delivered_mm > 1.1 * o.geometric_mm)
        .map(|o| (o.seed, o.delivered_mm, o.geometric_mm))
        .collect();
    assert!(
        worse.is_empty(),
        "deployed worse than identify's file (seed, delivered mm, identify's mm): {worse:?}"
    );
}

#[test]
#[ignore = "the diagnose tally of docs/reliability.md: 200 campaigns"]
fn tally_of_diagnosed_campaigns() {
    let dir = scratch("diagnose");
    let (outcomes, written, within, beyond) = tally(
        seeds(2000).into_iter(),
        &dir,
        Verb::DiagnoseCompared(deploy_rule()),
    );
    let _ = std::fs::remove_dir_all(&dir);
    let worse: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.exit == 0 && o.delivered_mm > 1.1 * o.geometric_mm)
        .collect();
    let rule = deploy_rule();
    let sum = |f: &dyn Fn(&Outcome) -> Option<f64>| outcomes.iter().filter_map(f).sum::<f64>();
    println!(
        "diagnose ({}): campaigns {}, files written (exit 0) {written}, within the promise {within}, beyond 2x {beyond}, deployed worse than identify's file by more than 10 % {}, median delivered/upper {:.2}, sum of delivered rms {:.2} mm",
        rule.name(),
        outcomes.len(),
        worse.len(),
        median_ratio(&outcomes),
        sum(&|o| (o.exit == 0).then_some(o.delivered_mm)),
    );
    for o in &worse {
        println!(
            "worse: seed {} delivered {:.1} um, identify's {:.1} um, {:?}",
            o.seed,
            1e3 * o.delivered_mm,
            1e3 * o.geometric_mm,
            o.effects
        );
    }
    // Against the other rule, on the files both write at exit 0.
    let both: Vec<(&Outcome, f64, bool)> = outcomes
        .iter()
        .filter_map(|o| match o.other {
            Some((0, other_mm, changed)) if o.exit == 0 => Some((o, other_mm, changed)),
            _ => None,
        })
        .collect();
    let changed: Vec<&(&Outcome, f64, bool)> = both.iter().filter(|b| b.2).collect();
    for (o, other_mm, _) in &changed {
        println!(
            "changed: seed {} identify {:.1} um, {} {:.1} um, {} {:.1} um",
            o.seed,
            1e3 * o.geometric_mm,
            other_rule(rule).name(),
            1e3 * other_mm,
            rule.name(),
            1e3 * o.delivered_mm
        );
    }
    println!(
        "diagnose ({}) against {}: written at exit 0 under both {}, changed {}, better {}, sum of delivered rms {:.2} mm -> {:.2} mm",
        rule.name(),
        other_rule(rule).name(),
        both.len(),
        changed.len(),
        changed
            .iter()
            .filter(|(o, other, _)| o.delivered_mm < *other)
            .count(),
        both.iter().map(|b| b.1).sum::<f64>(),
        both.iter().map(|b| b.0.delivered_mm).sum::<f64>(),
    );
    assert!(within as f64 >= 0.95 * written as f64);
    assert_eq!(beyond, 0);
    // One in every hundred files or part of a hundred (docs/reliability.md
    // explains each).
    assert!(
        worse.len() <= written.div_ceil(100),
        "{} of {written} deployed files more than 10 % worse than identify's",
        worse.len()
    );
}
