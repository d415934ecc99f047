//! The deployed diagnosis measured in truth: an effect outside the
//! vocabulary (a ball-screw pitch error, a quadratic leg, a bowed screw, a
//! worn segment) is hidden in the plant of a realistic campaign (random
//! poses, the mean of 3 readings, class-1 errors N(0, 0.25 mm), unknown
//! sensor offsets), diagnosed and deployed; the deployed machine file
//! (written and read back) commands the plant's *true* machine at
//! held-out targets, and so does `identify`'s geometric-only fit. Every
//! expectation comes from the simulator's inputs and the plant's true
//! machine, never from the code under test.

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_diagnose::{Diagnosis, deploy, diagnose};
use tricept_engine::{IdentifyOptions, identify, model::GeometricModel};
use tricept_kinematics::{Machine, MachineDescription};
use tricept_model::effects::{CauseName, EffectName};
use tricept_model::{ExtendedMachine, ParameterSet};
use tricept_plant::effects::{Effect, Waveform};
use tricept_plant::{Campaign, Plant};

/// Held-out targets per machine.
const HELD_OUT: usize = 300;

/// A standard normal draw (Box-Muller), so that the class-1 errors are
/// N(0, s) as in the evaluation the issue reports, not the plant's own
/// uniform draw.
fn normal(rng: &mut Pcg64Mcg) -> f64 {
    let u: f64 = rng.random::<f64>().max(1e-300);
    let v: f64 = rng.random::<f64>();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// The plant of machine `seed`: class-1 errors N(0, 0.25 mm), random
/// sensor offsets (up to 0.01 rad and 1 mm), a logged temperature drifting
/// 2 K (with no growth) and `effect` hidden.
fn plant(seed: u64, effect: Effect) -> Plant {
    let m = Machine::paper();
    let mut rng = Pcg64Mcg::seed_from_u64(0x5eed_0020 ^ seed.wrapping_mul(0x9e37_79b9));
    let errors: Vec<f64> = (0..15).map(|_| 0.25 * normal(&mut rng)).collect();
    let mut p = Plant::geometric(m, ParameterSet::paper15().to_errors(&errors));
    p.sensor_offsets = [
        0.01 * (2.0 * rng.random::<f64>() - 1.0),
        0.01 * (2.0 * rng.random::<f64>() - 1.0),
        2.0 * rng.random::<f64>() - 1.0,
    ];
    p.effects = vec![
        Effect::from(tricept_plant::effects::Thermal {
            drift_k: 2.0,
            expansion_ppm_per_k: 0.0,
        }),
        effect,
    ];
    p
}

/// The campaign of machine `seed`: `n` random poses, the mean of 3
/// readings (the paper's sensors), lines numbered from 2.
fn campaign(p: &Plant, n: usize, seed: u64) -> Dataset {
    let c = Campaign::random(&p.nominal, n, 31 * seed + 5);
    assert_eq!(c.noise.readings_per_pose, 3);
    let mut data = p.simulate(&c).expect("simulated campaign");
    for (j, pose) in data.poses.iter_mut().enumerate() {
        pose.line = j as u64 + 2;
    }
    data
}

/// Mean true error (mm) of commanding the plant's true machine with
/// `commanding`'s IK at held-out targets.
fn true_error_mm(p: &Plant, commanding: &ExtendedMachine, targets: &[Vector3<f64>]) -> f64 {
    let errors: Vec<f64> = targets
        .iter()
        .map(|r| {
            let q = commanding.inverse(r).expect("target in reach").legs_mm;
            (p.reach(&q).expect("the true machine reaches it") - r).norm()
        })
        .collect();
    errors.iter().sum::<f64>() / errors.len() as f64
}

/// The outcome of one machine.
struct Outcome {
    label: String,
    effect: Effect,
    diagnosis: Diagnosis,
    written: bool,
    geometric_mm: f64,
    deployed_mm: f64,
    /// The written file's compensation tables (leg, the table).
    tables: Vec<tricept_kinematics::description::LegTableDescription>,
}

/// Diagnoses, deploys (through the machine file's JSON) and measures in
/// truth.
fn run(label: &str, seed: u64, n: usize, effect: Effect) -> Outcome {
    let p = plant(seed, effect.clone());
    let data = campaign(&p, n, seed);
    let nominal = Machine::paper();
    let d = diagnose(
        &nominal,
        &data,
        &tricept_diagnose::DiagnoseOptions::for_machine(&nominal),
    )
    .expect("diagnosis");
    // What `identify` writes: the geometric-only fit.
    let model = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    let id = identify(&model, &data, &IdentifyOptions::for_machine(&nominal)).expect("identify");
    let geometric = ExtendedMachine::new(model.machine_at(&id.estimate));
    let targets = nominal.workspace.random_poses(HELD_OUT, 0x4e1d ^ seed);
    let geometric_mm = true_error_mm(&p, &geometric, &targets);
    // What `diagnose --write-machine` writes (exit 0 when the data are
    // explained, else with --force): the deployed model, through its JSON
    // file.
    let written = d.final_adequate;
    let deployed = deploy(&nominal, None, &data, &d).expect("deploy");
    let json = serde_json::to_string(&deployed.geometry.to_description()).expect("json");
    let machine = MachineDescription::from_json(&json)
        .and_then(|m| m.build())
        .expect("the written file loads");
    let tables = machine.leg_effects.tables.clone();
    let deployed_mm = true_error_mm(&p, &ExtendedMachine::new(machine), &targets);
    Outcome {
        label: format!("{label} seed {seed}"),
        effect,
        diagnosis: d,
        written,
        geometric_mm,
        deployed_mm,
        tables,
    }
}

/// The step a written table carries between the simulated segment's
/// edges: its mean extra length inside minus outside, more than `margin_mm`
/// from either edge, um (`None` without a table of leg `leg` or without
/// its points on both sides).
fn table_step_um(
    tables: &[tricept_kinematics::description::LegTableDescription],
    leg: u8,
    from_mm: f64,
    to_mm: f64,
    margin_mm: f64,
) -> Option<f64> {
    let t = tables.iter().find(|t| t.leg == leg)?;
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for (k, v) in t.extra_length_um.iter().enumerate() {
        let q = t.start_mm + t.step_mm * k as f64;
        if q > from_mm + margin_mm && q < to_mm - margin_mm {
            inside.push(*v);
        } else if q < from_mm - margin_mm || q > to_mm + margin_mm {
            outside.push(*v);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    (!inside.is_empty() && !outside.is_empty()).then(|| mean(&inside) - mean(&outside))
}

fn leg_effects(seed: u64) -> Vec<(&'static str, Effect)> {
    let mut rng = Pcg64Mcg::seed_from_u64(0xe44ec7 ^ seed);
    let mut u = |a: f64, b: f64| a + (b - a) * rng.random::<f64>();
    vec![
        (
            "pitch 4 um / 10 mm",
            Effect::from(tricept_plant::effects::LegPeriodic {
                um: [4.0, 4.0, 4.0],
                period_mm: 10.0,
                phase_deg: [u(0.0, 360.0), u(0.0, 360.0), u(0.0, 360.0)],
                waveform: Waveform::Sine,
            }),
        ),
        (
            "quadratic leg",
            Effect::from(tricept_plant::effects::LegQuadratic {
                um: [u(20.0, 30.0), -u(10.0, 20.0), u(0.0, 10.0)],
                centre_mm: 845.0,
                half_width_mm: 250.0,
            }),
        ),
        (
            // A screw bent into one arc over its length: a half sine
            // of 12-20 um over 400 mm, its crest anywhere.
            "bowed screw",
            Effect::from(tricept_plant::effects::LegPeriodic {
                um: [u(12.0, 20.0), u(12.0, 20.0), u(12.0, 20.0)],
                period_mm: 800.0,
                phase_deg: [u(0.0, 360.0), u(0.0, 360.0), u(0.0, 360.0)],
                waveform: Waveform::Sine,
            }),
        ),
        (
            "worn segment",
            Effect::from(tricept_plant::effects::LegStep {
                um: [u(2.5, 3.5), 0.0, 0.0],
                from_mm: u(700.0, 740.0),
                to_mm: u(940.0, 980.0),
            }),
        ),
    ]
}

/// Three machines of each leg error (80, 80 and 120 poses): every data
/// set is explained by a term of the dictionary and written (exit 0); a
/// leg term deployed beyond 2 sd of its improvement makes the machine at
/// least 2x more accurate in truth than identify's file, one deployed by
/// its expected error alone (1-2 sd, the default rule) no more than 10 %
/// worse, and the deployed machines are 3x more accurate on average; a term
/// seen but not worth deploying leaves identify's file; the true
/// improvement is within 3 sd of the predicted one. A worn segment (a step: `leg-step`, its edges
/// scanned) is deployed as a table that carries the simulated step away
/// from its edges to within 1 um.
#[test]
fn generic_leg_errors_are_deployed_and_pay_in_truth() {
    let cases: Vec<(u64, usize, &'static str, Effect)> = (0..3u64)
        .flat_map(|seed| {
            leg_effects(seed)
                .into_iter()
                .map(move |(label, e)| (seed, [80, 80, 120][seed as usize], label, e))
        })
        .collect();
    let outcomes: Vec<Outcome> = cases
        .into_par_iter()
        .map(|(seed, n, label, e)| run(label, seed, n, e))
        .collect();
    let mut ratios = Vec::new();
    let mut failures = Vec::new();
    let mut not_worth = 0;
    for o in &outcomes {
        let g = &o.diagnosis.gain;
        let (Some(predicted), Some(sd)) = (g.improvement_mm, g.improvement_sd_mm) else {
            panic!("{}: no predicted improvement", o.label);
        };
        let truth = o.geometric_mm - o.deployed_mm;
        let ratio = o.geometric_mm / o.deployed_mm;
        println!(
            "{}: geometric-only {:.1} um, deployed {:.1} um (x{ratio:.1}); improvement true {:.1} um, predicted {:.1} +- {:.1} um; terms {:?}",
            o.label,
            1e3 * o.geometric_mm,
            1e3 * o.deployed_mm,
            1e3 * truth,
            1e3 * predicted,
            1e3 * sd,
            o.diagnosis
                .model_terms
                .iter()
                .map(|t| format!(
                    "{}{} {:?} +- {:?} (move {:?})",
                    t.description,
                    if t.deployed { "" } else { " (not deployed)" },
                    t.improvement_mm,
                    t.improvement_sd_mm,
                    t.difference_sd_mm
                ))
                .collect::<Vec<_>>()
        );
        if let Some(&tricept_plant::effects::LegStep { um, from_mm, to_mm }) = o.effect.input() {
            // The written table carries the simulated step, away from its
            // edges (beyond 15 mm: the edges are known to a few mm at
            // these sizes), to within 1 um.
            let carried = table_step_um(&o.tables, 1, from_mm, to_mm, 15.0);
            println!(
                "    simulated: {:.2} um on leg 1 from {from_mm:.1} to {to_mm:.1} mm; table: {carried:.2?} um; named: {:?}",
                um[0],
                o.diagnosis
                    .causes
                    .iter()
                    .map(|c| c.description.clone())
                    .collect::<Vec<_>>()
            );
            if !carried.is_some_and(|c| (c - um[0]).abs() <= 1.0) {
                failures.push(format!(
                    "{}: the table of leg 1 carries {carried:?} um, simulated {:.2} um",
                    o.label, um[0]
                ));
            }
            if let Some(t) = o.tables.iter().find(|t| t.leg == 1) {
                println!("    table: {}", t.source);
            }
        }
        let deployed_generic = o
            .diagnosis
            .model_terms
            .iter()
            .any(|t| t.deployed && t.effect.is_generic());
        let nothing_deployed = o.diagnosis.model_terms.iter().all(|t| !t.deployed);
        if !o.written {
            failures.push(format!("{}: not explained, exit 3", o.label));
        }
        // Deployed by its expected error alone: an improvement of 1-2 sd,
        // better in expectation; in truth one draw of the weak direction.
        let by_expected_error = o.diagnosis.model_terms.iter().any(|t| {
            t.deployed
                && t.effect.is_generic()
                && matches!((t.improvement_mm, t.improvement_sd_mm), (Some(i), Some(sd))
                    if i <= tricept_diagnose::report::DEPLOY_IMPROVEMENT_SD * sd)
        });
        let floor = if by_expected_error { 1.0 / 1.1 } else { 2.0 };
        if deployed_generic && ratio < floor {
            failures.push(format!("{}: deployed, x{ratio:.2}", o.label));
        }
        if nothing_deployed && (ratio - 1.0).abs() > 1e-6 {
            failures.push(format!(
                "{}: nothing deployed, yet not identify's file",
                o.label
            ));
        }
        if !deployed_generic && !nothing_deployed {
            failures.push(format!(
                "{}: the leg error deployed as no generic term",
                o.label
            ));
        }
        if (truth - predicted).abs() > 3.0 * sd {
            failures.push(format!(
                "{}: true improvement {truth:.4} mm, predicted {predicted:.4} +- {sd:.4} mm",
                o.label
            ));
        }
        if deployed_generic {
            ratios.push(ratio);
        } else {
            not_worth += 1;
        }
    }
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    println!(
        "TALLY deployed vs geometric-only: mean x{mean:.2} (lowest x{:.2}) over the {} machines with a deployed leg term; {not_worth} of {} with the term seen, not worth deploying",
        ratios.iter().copied().fold(f64::INFINITY, f64::min),
        ratios.len(),
        outcomes.len()
    );
    assert!(ratios.len() >= 8, "{} deployed", ratios.len());
    assert!(failures.is_empty(), "{failures:#?}");
    assert!(mean >= 3.0, "mean x{mean:.2}");
}

#[test]
fn a_marginal_effect_is_never_deployed_when_it_makes_the_truth_worse() {
    let cases: Vec<(u64, &'static str, Effect, EffectName)> = (0..10u64)
        .flat_map(|seed| {
            [
                (
                    seed,
                    "twist 30 arcsec / 100 mm",
                    Effect::from(tricept_plant::effects::TubeTwist {
                        arcsec_per_100mm: 30.0,
                    }),
                    EffectName::TubeTwist,
                ),
                (
                    seed,
                    "eccentricity 5 arcsec",
                    Effect::from(tricept_plant::effects::EncoderEccentricity {
                        phi_arcsec: 5.0,
                        phi_phase_deg: 36.0 * seed as f64,
                        theta_arcsec: 5.0,
                        theta_phase_deg: 90.0 + 36.0 * seed as f64,
                    }),
                    EffectName::EncoderEccentricity,
                ),
            ]
        })
        .collect();
    let outcomes: Vec<(Outcome, EffectName)> = cases
        .into_par_iter()
        .map(|(seed, label, e, name)| (run(label, 100 + seed, 200, e), name))
        .collect();
    let (mut deployed, mut worse, mut named, mut none_deployed) = (0, 0, 0, 0);
    let mut failures = Vec::new();
    for (o, name) in &outcomes {
        // With nothing deployed the deployed model is the geometric-only
        // fit (what `identify` writes), so the diagnosis predicts no
        // improvement over it, exactly.
        let d = &o.diagnosis;
        if !d.model_terms.is_empty() && d.model_terms.iter().all(|t| !t.deployed) {
            none_deployed += 1;
            if d.gain.improvement_mm.is_some_and(|i| i.abs() > 1e-12) {
                failures.push(format!(
                    "{}: nothing deployed, yet an improvement of {:?} mm predicted",
                    o.label, d.gain.improvement_mm
                ));
            }
        }
        let term = o
            .diagnosis
            .model_terms
            .iter()
            .find(|t| t.effect == CauseName::Catalogue(*name));
        named += usize::from(term.is_some());
        let is_deployed = term.is_some_and(|t| t.deployed);
        deployed += usize::from(is_deployed);
        let hurts = o.deployed_mm > o.geometric_mm;
        println!(
            "{}: {} ; geometric-only {:.1} um, deployed {:.1} um",
            o.label,
            term.map_or("not in the model".to_string(), |t| format!(
                "{} {:?} +- {:?} (move {:?}) mm",
                if t.deployed {
                    "deployed"
                } else {
                    "not deployed"
                },
                t.improvement_mm,
                t.improvement_sd_mm,
                t.difference_sd_mm
            )),
            1e3 * o.geometric_mm,
            1e3 * o.deployed_mm
        );
        if is_deployed && hurts {
            worse += 1;
        }
    }
    println!(
        "TALLY marginal effects at 200 poses: {} data sets, {named} in the model, {deployed} deployed, {worse} deployed and worse in truth, {none_deployed} with terms and none deployed",
        outcomes.len()
    );
    assert_eq!(worse, 0);
    assert!(failures.is_empty(), "{failures:#?}");
    assert!(none_deployed >= 1, "no data set deploys none of its terms");
}
