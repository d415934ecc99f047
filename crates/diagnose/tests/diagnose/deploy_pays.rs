//! Deploy by what the file will deliver, measured on an independent truth
//! (`tricept-truth`: a true Tricept written from the documented
//! conventions, its leg effects added to the true leg lengths, never the
//! project's simulator): realistic campaigns of 40-200 random poses (the
//! mean of 3 readings, random approach directions logged as `dir1..dir3`,
//! a structure temperature rising 2 K logged as `temp_c`) with backlash, a
//! lead, a quadratic leg, a pitch error, a worn segment, uniform or uneven
//! heating, a scale drift (in the readings), and combinations of two, written as the documented CSV,
//! diagnosed and deployed. The deployed file and `identify`'s
//! geometric-only file command the true machine at held-out targets
//! (random approach directions, the campaign's mean temperature; the
//! controller's backlash and thermal compensation applied as the file's
//! `controller` block says), and the platform's true errors are compared.
//!
//! Required under the default rule: at most one file written at exit 0 in
//! a hundred (one in the CI test's 15) more than 10 % worse in truth than
//! `identify`'s, and each a term deployed by its expected error alone (the
//! rule's known risk: a file better in expectation, worse for some draws of
//! the weak direction's error); a kept-back term says why; a catalogue
//! cause named at exit 0 has its true gain within 4 sd of its predicted
//! gain, and (on the tally) within 3 sd in 95 % of the cases. The CI test
//! runs 17 campaigns; `deploy_pays::tally` (`--ignored`) runs 96 under both
//! rules and compares them.

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_diagnose::{
    DiagnoseOptions, Diagnosis, deploy, diagnose, options::DeployRule, report::CauseKind,
};
use tricept_engine::{IdentifyOptions, identify, model::GeometricModel};
use tricept_kinematics::description::ControllerDescription;
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::{ExtendedMachine, ParameterSet};
use tricept_truth::{LegContext, LegEffect, Row, SensorNoise, TrueMachine, to_csv};

/// Held-out targets per machine.
const HELD_OUT: usize = 200;

/// A deployed file may be at most this much worse in truth than
/// `identify`'s.
const WORSE: f64 = 1.10;

/// The case names, in the order of [`effects`].
const CASES: [&str; 16] = [
    "backlash",
    "leg lead",
    "quadratic leg",
    "pitch 4 um / 10 mm",
    "uneven heating",
    "thermal",
    "worn segment",
    "backlash + lead",
    "uneven heating + lead",
    "pitch + thermal",
    "quadratic + backlash",
    "nothing",
    "uneven warming",
    "uneven warming + backlash",
    "mildly uneven warming",
    "scale drift",
];

/// The leg effects of case `case` for machine `seed`.
fn effects(case: usize, seed: u64) -> Vec<LegEffect> {
    let mut rng = Pcg64Mcg::seed_from_u64(0xde91_0a75 ^ (seed * 64 + case as u64));
    let mut u = |a: f64, b: f64| a + (b - a) * rng.random::<f64>();
    let backlash = LegEffect::Backlash {
        um: [u(3.0, 8.0), u(3.0, 8.0), u(3.0, 8.0)],
    };
    let lead = LegEffect::Lead {
        ppm: [u(20.0, 50.0), -u(20.0, 50.0), u(-50.0, 50.0)],
    };
    let quadratic = LegEffect::Quadratic {
        um: [u(20.0, 30.0), -u(10.0, 20.0), u(0.0, 10.0)],
        centre_mm: 845.0,
        half_width_mm: 250.0,
    };
    let pitch = LegEffect::Pitch {
        um: [4.0; 3],
        period_mm: 10.0,
        phase_deg: [u(0.0, 360.0), u(0.0, 360.0), u(0.0, 360.0)],
    };
    let uneven = LegEffect::Heating {
        ppm_per_k: 11.5,
        kelvin: [4.0, 1.0, -2.0],
    };
    let thermal = LegEffect::Heating {
        ppm_per_k: 11.5,
        kelvin: [0.0; 3],
    };
    let warming = LegEffect::Warming {
        ppm_per_k: 11.5,
        kelvin: [4.0, 1.0, -2.0],
        from_c: temperature(0, 2),
        to_c: temperature(1, 2),
    };
    let mild = LegEffect::Warming {
        ppm_per_k: 11.5,
        kelvin: [u(0.3, 1.0), u(-0.3, 0.3), -u(0.3, 1.0)],
        from_c: temperature(0, 2),
        to_c: temperature(1, 2),
    };
    let worn = LegEffect::Step {
        um: [u(2.5, 3.5), 0.0, 0.0],
        from_mm: u(700.0, 740.0),
        to_mm: u(940.0, 980.0),
    };
    match case {
        0 => vec![backlash],
        1 => vec![lead],
        2 => vec![quadratic],
        3 => vec![pitch],
        4 => vec![uneven],
        5 => vec![thermal],
        6 => vec![worn],
        7 => vec![backlash, lead],
        8 => vec![uneven, lead],
        9 => vec![pitch, thermal],
        10 => vec![quadratic, backlash],
        11 => Vec::new(),
        12 => vec![warming],
        13 => vec![warming, backlash],
        14 => vec![mild],
        // The scale drift is in the readings (`campaign`).
        _ => Vec::new(),
    }
}

/// The structure temperature at pose `j` of `n`: 20.5 deg C rising 2 K.
fn temperature(j: usize, n: usize) -> f64 {
    20.5 + 2.0 * j as f64 / (n - 1) as f64
}

/// The campaign: `n` random poses commanded through the nominal IK, in
/// random order (each leg's direction the sign of its last move).
fn campaign(
    truth: &TrueMachine,
    legs: &[LegEffect],
    scale_drift_um: f64,
    n: usize,
    seed: u64,
) -> Dataset {
    let nominal = Machine::paper();
    let mut rng = Pcg64Mcg::seed_from_u64(0xca3a_0001 ^ seed);
    let mut last = [0.0; 3];
    let rows: Vec<Row> = nominal
        .workspace
        .random_poses(n, 0x5eed ^ seed)
        .iter()
        .enumerate()
        .map(|(j, r)| {
            let q = nominal.inverse(r).expect("a workspace target").legs_mm;
            let directions: [i8; 3] = std::array::from_fn(|i| if q[i] >= last[i] { 1 } else { -1 });
            last = q;
            let at = LegContext {
                temp_c: temperature(j, n),
                directions,
                campaign_share: j as f64 / (n - 1).max(1) as f64,
            };
            let joints = truth.forward_lengths(&truth.lengths_with(&q, legs, &at));
            Row {
                commands_mm: q,
                readings: {
                    // A scale drifting `scale_drift_um` over the campaign.
                    let mut y = truth.sensed(&joints, &SensorNoise::DOCUMENTED, &mut rng);
                    y[2] += scale_drift_um * 1e-3 * (j as f64 / (n - 1) as f64 - 0.5);
                    y
                },
                temp_c: Some(at.temp_c),
                directions: Some(directions),
            }
        })
        .collect();
    tricept_data::read_from(to_csv(&rows).as_bytes(), "truth.csv").expect("the documented CSV")
}

/// A file's commands for target `r` at `at`: its IK with its leg effects
/// and tables, then its controller's backlash and thermal compensation.
fn commands(
    file: &ExtendedMachine,
    controller: Option<&ControllerDescription>,
    r: &Vector3<f64>,
    at: &LegContext,
) -> [f64; 3] {
    let mut q = file.inverse(r).expect("target in reach").legs_mm;
    if let Some(c) = controller {
        let grow =
            1.0 + c.thermal_expansion_ppm_per_k * 1e-6 * (at.temp_c - c.reference_temperature_c);
        for i in 0..3 {
            q[i] = q[i] / grow + f64::from(at.directions[i]) * c.backlash_um[i] * 1e-3 / 2.0;
        }
    }
    q
}

/// The true platform error (mm) of each target commanded by a file.
fn true_errors(
    truth: &TrueMachine,
    legs: &[LegEffect],
    file: &ExtendedMachine,
    controller: Option<&ControllerDescription>,
    targets: &[(Vector3<f64>, LegContext)],
) -> Vec<f64> {
    targets
        .iter()
        .map(|(r, at)| {
            let q = commands(file, controller, r, at);
            (truth.reach_with(&q, legs, at) - r).norm()
        })
        .collect()
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// What one campaign gave.
struct Outcome {
    label: String,
    diagnosis: Diagnosis,
    /// Written at exit 0 (the final model explains the data).
    exit0: bool,
    /// Something deployed.
    deployed: bool,
    /// True rms errors at held-out targets, mm: identify's file, the
    /// deployed one.
    geometric_mm: f64,
    deployed_mm: f64,
    /// True gain on the middle plane (mean error of identify's file minus
    /// the deployed one's), mm.
    true_gain_mm: f64,
}

fn run(case: usize, seed: u64, n: usize, rule: DeployRule) -> Outcome {
    let legs = effects(case, seed);
    let truth = TrueMachine::random(0.0, 0x7e57 ^ seed);
    let drift_um = if CASES[case] == "scale drift" {
        2.0 + 4.0 * ((seed * 37 % 11) as f64 / 10.0)
    } else {
        0.0
    };
    let data = campaign(&truth, &legs, drift_um, n, seed);
    let nominal = Machine::paper();
    let mut options = DiagnoseOptions::for_machine(&nominal);
    options.deploy_rule = rule;
    let d = diagnose(&nominal, &data, &options).expect("diagnosis");
    let model = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    let id = identify(&model, &data, &IdentifyOptions::for_machine(&nominal)).expect("identify");
    let geometric = ExtendedMachine::new(model.machine_at(&id.estimate));
    let deployed = deploy(&nominal, None, &data, &d).expect("deploy");
    let json = serde_json::to_string(&deployed.geometry.to_description()).expect("json");
    let file = MachineDescription::from_json(&json)
        .and_then(|m| m.build())
        .map(ExtendedMachine::new)
        .expect("the written file loads");
    let controller = deployed.controller.as_ref();
    // The campaign's mean temperature.
    let temp_c = 0.5 * (temperature(0, n) + temperature(n - 1, n));
    let mut rng = Pcg64Mcg::seed_from_u64(0x4e1d ^ seed);
    let mut context = || LegContext {
        temp_c,
        directions: std::array::from_fn(|_| if rng.random::<bool>() { 1 } else { -1 }),
        campaign_share: tricept_truth::DELIVERY_T,
    };
    let held_out: Vec<(Vector3<f64>, LegContext)> = nominal
        .workspace
        .random_poses(HELD_OUT, 0x4e1d ^ seed)
        .into_iter()
        .map(|r| (r, context()))
        .collect();
    let plane: Vec<(Vector3<f64>, LegContext)> = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), 50.0)
        .into_iter()
        .map(|r| (r, context()))
        .collect();
    let geometric_mm = rms(&true_errors(&truth, &legs, &geometric, None, &held_out));
    // With DEPLOY_PAYS_ALL set, also what the file with every term of the
    // final model would deliver (how the rule was weighed: `ALL` lines).
    if std::env::var_os("DEPLOY_PAYS_ALL").is_some() {
        let mut all = d.clone();
        all.model_terms.iter_mut().for_each(|t| t.deployed = true);
        let every = deploy(&nominal, None, &data, &all).expect("deploy all");
        let f = ExtendedMachine::new(every.geometry.clone());
        println!(
            "ALL {} n={n} seed {seed}: every term deployed {:.1} um",
            CASES[case],
            1e3 * rms(&true_errors(
                &truth,
                &legs,
                &f,
                every.controller.as_ref(),
                &held_out
            ))
        );
    }
    let deployed_mm = rms(&true_errors(&truth, &legs, &file, controller, &held_out));
    let true_gain_mm = mean(&true_errors(&truth, &legs, &geometric, None, &plane))
        - mean(&true_errors(&truth, &legs, &file, controller, &plane));
    Outcome {
        label: format!("{} n={n} seed {seed}", CASES[case]),
        exit0: d.final_adequate,
        deployed: d.model_terms.iter().any(|t| t.deployed),
        diagnosis: d,
        geometric_mm,
        deployed_mm,
        true_gain_mm,
    }
}

/// The campaigns to run: `cases`, or with `DEPLOY_PAYS_CASES=3,9` only
/// those cases (by index in [`CASES`]).
fn selected(cases: Vec<(usize, u64, usize)>) -> Vec<(usize, u64, usize)> {
    let only: Option<Vec<usize>> = std::env::var("DEPLOY_PAYS_CASES")
        .ok()
        .map(|v| v.split(',').filter_map(|c| c.trim().parse().ok()).collect());
    cases
        .into_iter()
        .filter(|(c, _, _)| only.as_ref().is_none_or(|o| o.contains(c)))
        .collect()
}

/// The deploy rule the campaigns are diagnosed with: the default, or
/// `DEPLOY_PAYS_RULE` (`confident`, `expected-error`).
fn rule_of_run() -> DeployRule {
    std::env::var("DEPLOY_PAYS_RULE")
        .map(|s| s.parse().expect("DEPLOY_PAYS_RULE: a deploy rule"))
        .unwrap_or_default()
}

/// Runs the campaigns under `rule` and returns the failures
/// ([`judge`]).
fn evaluate(cases: Vec<(usize, u64, usize)>, within3_share: bool) -> Vec<String> {
    let rule = rule_of_run();
    let outcomes: Vec<Outcome> = selected(cases)
        .into_par_iter()
        .map(|(case, seed, n)| run(case, seed, n, rule))
        .collect();
    judge(&outcomes, rule, within3_share)
}

/// The failures of `outcomes` diagnosed under `rule`: a file written at
/// exit 0 more than 10 % worse in truth than identify's (under the
/// default rule), a named cause beyond 4 sd of its predicted gain (with
/// `within3_share`, also fewer than 95 % within 3 sd: a share, asserted on
/// the tally's 48, not on the CI test's 9).
fn judge(outcomes: &[Outcome], rule: DeployRule, within3_share: bool) -> Vec<String> {
    let mut failures = Vec::new();
    let (mut written, mut deployed, mut worse) = (0, 0, 0);
    let (mut named, mut within3, mut beyond4) = (0, 0, 0);
    for o in outcomes {
        let d = &o.diagnosis;
        let g = &d.gain;
        let catalogue: Vec<String> = d
            .causes
            .iter()
            .filter(|c| c.kind == CauseKind::Catalogue)
            .map(|c| format!("{:?}", c.effect))
            .collect();
        println!(
            "{}: {:?}, exit {}, held-out rms {:.2} (noise = 1); identify {:.1} um, deployed {:.1} um (x{:.2}); gain true {:.1} um, predicted {:.1?} +- {:.1?} um; causes {:?}; terms {:?}",
            o.label,
            d.verdict,
            if o.exit0 { 0 } else { 3 },
            g.holdout_rms_extended,
            1e3 * o.geometric_mm,
            1e3 * o.deployed_mm,
            o.deployed_mm / o.geometric_mm,
            1e3 * o.true_gain_mm,
            g.improvement_mm.map(|v| 1e3 * v),
            g.improvement_sd_mm.map(|v| 1e3 * v),
            d.causes
                .iter()
                .map(|c| c.description.clone())
                .collect::<Vec<_>>(),
            terms(d)
        );
        if !o.exit0 {
            continue;
        }
        written += 1;
        if o.deployed {
            deployed += 1;
            if o.deployed_mm > WORSE * o.geometric_mm {
                worse += 1;
            }
            if o.deployed_mm > WORSE * o.geometric_mm {
                let risk = deployed_by_expected_error_alone(d);
                println!(
                    "WORSE {}: deployed {:.1} um, identify's file {:.1} um; deployed by the expected error alone: {risk:?}",
                    o.label,
                    1e3 * o.deployed_mm,
                    1e3 * o.geometric_mm
                );
                // Under the default rule a worse file is only the expected
                // error's known risk (a term whose file is better in
                // expectation, deployed below 2 sd), and rare.
                if rule == DeployRule::default() && risk.is_empty() {
                    failures.push(format!(
                        "{}: deployed {:.1} um, identify's file {:.1} um",
                        o.label,
                        1e3 * o.deployed_mm,
                        1e3 * o.geometric_mm
                    ));
                }
            }
        }
        // A term kept back says why, in the JSON and the report.
        let text = d.to_text("campaign");
        for t in d.model_terms.iter().filter(|t| !t.deployed) {
            match &t.kept_back_because {
                Some(why) if text.contains(&format!("kept back because {why}")) => {}
                _ => failures.push(format!(
                    "{}: {} kept back without its reason in the report",
                    o.label, t.description
                )),
            }
        }
        if let (false, Some(p), Some(sd)) =
            (catalogue.is_empty(), g.improvement_mm, g.improvement_sd_mm)
        {
            named += 1;
            let z = (o.true_gain_mm - p) / sd;
            within3 += usize::from(z.abs() <= 3.0);
            if z.abs() > 4.0 {
                beyond4 += 1;
                failures.push(format!(
                    "{}: {catalogue:?} named at exit 0, true gain {:.1} um, predicted {:.1} +- {:.1} um (z = {z:.1})",
                    o.label,
                    1e3 * o.true_gain_mm,
                    1e3 * p,
                    1e3 * sd
                ));
            }
        }
    }
    println!(
        "TALLY deploy pays ({}): {} campaigns, {written} written at exit 0, {deployed} with a term deployed, {worse} more than 10 % worse in truth than identify's file, sum of delivered rms {:.2} mm",
        rule.name(),
        outcomes.len(),
        outcomes
            .iter()
            .filter(|o| o.exit0)
            .map(|o| o.deployed_mm)
            .sum::<f64>()
    );
    println!(
        "TALLY named causes hold: {named} with a catalogue cause named at exit 0, true gain within 3 sd of the predicted {within3}, beyond 4 sd {beyond4}"
    );
    if rule == DeployRule::default() && worse > worse_allowed(written) {
        failures.push(format!(
            "{worse} of {written} files more than 10 % worse than identify's (at most {} allowed)",
            worse_allowed(written)
        ));
    }
    if within3_share && (within3 as f64) < 0.95 * named as f64 {
        failures.push(format!(
            "{within3} of {named} named causes within 3 sd of their predicted gain (95 % required)"
        ));
    }
    failures
}

/// How many of `written` files may be more than 10 % worse in truth than
/// identify's under the default rule: one in every hundred files or part
/// of a hundred (the CI test's 15 have one: a lead deployed by its expected
/// error at 1.4 sd, docs/reliability.md).
fn worse_allowed(written: usize) -> usize {
    written.div_ceil(100)
}

/// The deployed terms of `d` whose predicted improvement is below
/// [`tricept_diagnose::report::DEPLOY_IMPROVEMENT_SD`] standard deviations: what
/// the expected-error rule deploys and the confident one keeps back.
fn deployed_by_expected_error_alone(d: &Diagnosis) -> Vec<String> {
    d.model_terms
        .iter()
        .filter(|t| {
            let two = tricept_diagnose::report::DEPLOY_IMPROVEMENT_SD;
            t.deployed
                && matches!(
                    (t.improvement_mm, t.improvement_sd_mm, t.holdout_benefit_mm, t.holdout_benefit_sd_mm),
                    (Some(i), Some(sd), Some(b), Some(b_sd)) if i <= two * sd && i > b + two * b_sd
                )
        })
        .map(|t| t.description.clone())
        .collect()
}

/// Each model term of `d` in a few numbers: how the deploy rule judged it.
fn terms(d: &Diagnosis) -> Vec<String> {
    d.model_terms
        .iter()
        .map(|t| format!(
            "{}{}: benefit {:.1?} +- {:.1?} um, improvement {:.1?} +- {:.1?} um (move {:.1?}), expected rms {:.1?} with, {:.1?} without",
            t.description,
            if t.deployed { "" } else { " (not deployed)" },
            t.holdout_benefit_mm.map(|v| 1e3 * v),
            t.holdout_benefit_sd_mm.map(|v| 1e3 * v),
            t.improvement_mm.map(|v| 1e3 * v),
            t.improvement_sd_mm.map(|v| 1e3 * v),
            t.difference_sd_mm.map(|v| 1e3 * v),
            t.expected_rms_with_mm.map(|v| 1e3 * v),
            t.expected_rms_without_mm.map(|v| 1e3 * v),
        ))
        .collect()
}

/// The same campaigns under two rules (`a` the one judged, `b` the
/// comparison): the files written at exit 0 under both whose deployed
/// terms differ, each in truth, and the sums of delivered rms. Prints a
/// `COMPARE` line per changed file and a `TALLY compare` line.
fn compare(a: DeployRule, outcomes_a: &[Outcome], b: DeployRule, outcomes_b: &[Outcome]) {
    let deployed_terms = |o: &Outcome| -> Vec<String> {
        o.diagnosis
            .model_terms
            .iter()
            .filter(|t| t.deployed)
            .map(|t| t.description.clone())
            .collect()
    };
    let (mut changed, mut better, mut worse, mut sum_a, mut sum_b) = (0, 0, 0, 0.0, 0.0);
    for (x, y) in outcomes_a.iter().zip(outcomes_b) {
        if !(x.exit0 && y.exit0) {
            continue;
        }
        sum_a += x.deployed_mm;
        sum_b += y.deployed_mm;
        if deployed_terms(x) == deployed_terms(y) {
            continue;
        }
        changed += 1;
        better += usize::from(x.deployed_mm < y.deployed_mm);
        worse += usize::from(x.deployed_mm > WORSE * x.geometric_mm);
        println!(
            "COMPARE {}: identify {:.1} um, {} {:.1} um, {} {:.1} um; {} terms {:?}",
            x.label,
            1e3 * x.geometric_mm,
            b.name(),
            1e3 * y.deployed_mm,
            a.name(),
            1e3 * x.deployed_mm,
            a.name(),
            terms(&x.diagnosis)
        );
    }
    println!(
        "TALLY compare {} against {}: {changed} files changed of those written at exit 0 under both, {better} better, {worse} more than 10 % worse than identify's; sum of delivered rms {:.2} mm -> {:.2} mm",
        a.name(),
        b.name(),
        sum_b,
        sum_a
    );
}

/// 17 campaigns: each case once (40, 80 or 200 poses), backlash twice,
/// under the default rule: at most the one file worse than identify's by
/// more than 10 % (a lead deployed by its expected error at 1.4 sd: the
/// rule's known risk), every kept-back term with its reason, no named
/// cause beyond 4 sd.
#[test]
fn deployed_files_pay_in_truth() {
    let cases: Vec<(usize, u64, usize)> = (0..CASES.len())
        .map(|c| (c, c as u64, [40, 80, 200][c % 3]))
        .chain([(0, 11, 80)])
        .collect();
    let failures = evaluate(cases, false);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// 96 campaigns: each case at 40, 80 and 200 poses on two machines,
/// diagnosed under the rule of the run and (compared) under the other rule.
#[test]
#[ignore = "the tally of docs/reliability.md: 192 diagnoses"]
fn tally() {
    let cases: Vec<(usize, u64, usize)> = (0..CASES.len())
        .flat_map(|c| {
            [40, 80, 200]
                .into_iter()
                .flat_map(move |n| (0..2u64).map(move |s| (c, 100 + 7 * s + n as u64, n)))
        })
        .collect();
    let rule = rule_of_run();
    let other = other_rule(rule);
    let both: Vec<(Outcome, Outcome)> = selected(cases)
        .into_par_iter()
        .map(|(case, seed, n)| (run(case, seed, n, rule), run(case, seed, n, other)))
        .collect();
    let (judged, compared): (Vec<Outcome>, Vec<Outcome>) = both.into_iter().unzip();
    compare(rule, &judged, other, &compared);
    // The other rule's tally, for the comparison (its failures are not
    // this rule's).
    let _ = judge(&compared, other, true);
    let failures = judge(&judged, rule, true);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The rule a tally compares `rule` with.
fn other_rule(rule: DeployRule) -> DeployRule {
    if rule == DeployRule::Confident {
        DeployRule::ExpectedError
    } else {
        DeployRule::Confident
    }
}

/// The pitch errors the confident rule keeps back on the tally (their
/// predicted improvement 1.0-1.7 sd, the out-of-sample benefit beyond 8
/// sd): the default rule (expected error) deploys them, and in truth each
/// file is better than the confident rule's and than identify's; the
/// confident rule's report says why it keeps each back.
#[test]
fn the_default_rule_deploys_the_pitch_terms_the_confident_rule_keeps_back() {
    assert_eq!(DeployRule::default(), DeployRule::ExpectedError);
    let pitch = |o: &Outcome| {
        o.diagnosis
            .model_terms
            .iter()
            .find(|t| t.description.starts_with("leg-periodic"))
            .cloned()
            .expect("the pitch term")
    };
    let cases = [(3, 140, 40), (9, 180, 80), (9, 300, 200)];
    let outcomes: Vec<(Outcome, Outcome)> = cases
        .into_par_iter()
        .map(|(case, seed, n)| {
            (
                run(case, seed, n, DeployRule::Confident),
                run(case, seed, n, DeployRule::default()),
            )
        })
        .collect();
    for (confident, expected) in &outcomes {
        println!(
            "{}: identify {:.1} um, confident {:.1} um, expected-error {:.1} um",
            confident.label,
            1e3 * confident.geometric_mm,
            1e3 * confident.deployed_mm,
            1e3 * expected.deployed_mm
        );
        assert!(confident.exit0 && expected.exit0, "{}", confident.label);
        let kept = pitch(confident);
        assert!(!kept.deployed, "{}", confident.label);
        let why = kept.kept_back_because.expect("a reason");
        assert!(
            why.starts_with("the confident rule (deploy_rule `confident`): "),
            "{why}"
        );
        assert!(
            confident
                .diagnosis
                .to_text("campaign")
                .contains(&format!("kept back because {why}")),
            "{}",
            confident.label
        );
        let term = pitch(expected);
        assert!(term.deployed, "{}", expected.label);
        assert_eq!(term.kept_back_because, None);
        assert!(
            expected.deployed_mm < confident.deployed_mm
                && expected.deployed_mm < confident.geometric_mm,
            "{}",
            expected.label
        );
        let (Some(with), Some(without)) = (term.expected_rms_with_mm, term.expected_rms_without_mm)
        else {
            panic!("{}: no expected errors", expected.label);
        };
        assert!(with < without, "{}: {with} {without}", expected.label);
    }
}
