//! Predictions that hold on machines the project did not generate: a true
//! Tricept written from the documented conventions alone (a general
//! two-axis head chain, module errors N(0, 0.25 mm), a tracker at a random
//! pose 1-3 m away; `common/independent.rs`), calibrated with planned
//! tracker points or ballbar readings, deployed as a machine file, and
//! commanded through that file's tool IK. The tool tip's true error after
//! touch-off over 200 held-out tool poses must be at most 1.5 times what
//! the fused identification predicted for them, at head errors of the head
//! table's sizes and at twice them; a known 20 mm target offset stated
//! correctly must deliver within 1.2 times the target at the tip.

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use tricept_data::{
    Dataset, MeasuredPose, Readings, external::BallbarReading, external::ExternalData,
    external::ExternalPose, external::TrackerPoint,
};
use tricept_engine::fusion::{
    BallbarOptions, FusedModel, Fusion, FusionOptions, Source, TrackerOptions, TrackerTarget,
    head_angle_poses, identify_fused,
};
use tricept_kinematics::{Machine, MachineDescription, head::HeadBranch};
use tricept_model::ParameterSet;
use tricept_study::plan::{
    PlanProblem, candidate_rows, internal_factor, nominal_ballbar_data, nominal_tracker_data, plan,
    sphere_candidates, with_extensions,
};
use tricept_truth::{TrueMachine, TrueTracker, normal};

#[derive(Debug, Clone, Copy, PartialEq)]
enum Instrument {
    Tracker,
    Ballbar,
}

const PIVOT: [f64; 3] = [0.0, 0.0, 1250.0];
const MACHINES: u64 = 6;

fn model(m: &Machine) -> FusedModel {
    FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap()
}

fn tip_target() -> TrackerTarget {
    TrackerTarget::Known {
        offset_mm: [0.0; 3],
        sigma_um: 5.0,
    }
}

/// A campaign: each pose with the extension measured there, mm.
type Campaign = Vec<(ExternalPose, f64)>;

/// The planned poses (with extensions) for each of `ks`.
fn planned(m: &Machine, instrument: Instrument, ks: &[usize]) -> Vec<Campaign> {
    let model = model(m);
    let candidates: Vec<(ExternalPose, f64)> = match instrument {
        Instrument::Tracker => with_extensions(
            &head_angle_poses(
                m,
                &m.workspace.polar_grid(2, 8, 3),
                &[0.0, 60.0, 120.0, 180.0, 240.0, 300.0],
                &[-45.0, -25.0, 25.0, 45.0],
            ),
            &[0.0],
        ),
        Instrument::Ballbar => sphere_candidates(m, &Vector3::from(PIVOT), 150.0, 300)
            .into_iter()
            .map(|p| (p, 0.0))
            .collect(),
    };
    let source = match instrument {
        Instrument::Tracker => Source::tracker(
            &nominal_tracker_data(&model, &candidates).unwrap(),
            &TrackerOptions {
                sigma_um: 10.0,
                target: tip_target(),
            },
        )
        .unwrap(),
        Instrument::Ballbar => {
            let poses: Vec<ExternalPose> = candidates.iter().map(|c| c.0).collect();
            Source::ballbar(
                &nominal_ballbar_data(&model, &poses, &Vector3::from(PIVOT)).unwrap(),
                &BallbarOptions::default(),
            )
            .unwrap()
        }
    };
    let f_int = internal_factor(&model, &m.workspace.polar_grid(3, 8, 3)).unwrap();
    let rows = candidate_rows(&model, &source).unwrap();
    let eval = FusionOptions::for_machine(m).eval_poses;
    let problem = PlanProblem::new(&model, &f_int, &rows, &eval).unwrap();
    plan(&problem, ks, 3, 0, 1)
        .unwrap()
        .rows
        .iter()
        .map(|r| r.selection.iter().map(|&c| candidates[c]).collect())
        .collect()
}

/// 200 held-out tool poses: random platform points, `h1` anywhere, `h2`
/// 15-35 deg (commanded by the nominal IK: where the tool is asked to be).
fn held_out(m: &Machine) -> Vec<ExternalPose> {
    let mut rng = Pcg64Mcg::seed_from_u64(4242);
    m.workspace
        .random_poses(200, 4243)
        .iter()
        .map(|r| ExternalPose {
            commands_mm: m.inverse(r).unwrap().legs_mm,
            head_rad: [
                std::f64::consts::TAU * rng.random::<f64>(),
                (15.0 + 20.0 * rng.random::<f64>()).to_radians(),
            ],
        })
        .collect()
}

/// What one calibration predicted and delivered.
#[derive(Debug, Clone, Copy)]
struct Outcome {
    predicted_um: f64,
    delivered_um: f64,
    predicted_axis_arcsec: f64,
    delivered_axis_arcsec: f64,
    /// The held parameters' share of the prediction, um.
    held_um: f64,
    trustworthy: bool,
}

/// Calibrates `truth` with the internal grid and `instrument` at `poses`
/// (the target `offset` from the tip, stated as `stated`), deploys the
/// machine file and commands the held-out tool poses through its tool IK.
fn calibrate(
    truth: &TrueMachine,
    instrument: Instrument,
    poses: &[(ExternalPose, f64)],
    offset: Vector3<f64>,
    stated: TrackerTarget,
    eval: &[ExternalPose],
    seed: u64,
) -> Outcome {
    let m = Machine::paper();
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let grid: Vec<MeasuredPose> = m
        .workspace
        .polar_grid(3, 8, 3)
        .iter()
        .enumerate()
        .map(|(j, r)| {
            let q = m.inverse(r).unwrap().legs_mm;
            MeasuredPose {
                commands_mm: q,
                readings: Readings::from_array(truth.readings(&q, &mut rng)),
                line: j as u64 + 2,
                ..Default::default()
            }
        })
        .collect();
    let data = Dataset {
        poses: grid,
        source: "internal.csv".into(),
    };
    let external = match instrument {
        Instrument::Tracker => {
            let station = TrueTracker::random(seed);
            let records = poses
                .iter()
                .enumerate()
                .map(|(j, (pose, extension))| {
                    let x =
                        truth.spindle_point(&pose.commands_mm, pose.head_rad, *extension, &offset);
                    TrackerPoint {
                        pose: *pose,
                        position_mm: station.measure(&x, &mut rng),
                        extension_mm: *extension,
                        setup: 1,
                        line: j as u64 + 2,
                        ..Default::default()
                    }
                })
                .collect();
            Source::tracker(
                &ExternalData {
                    records,
                    source: "tracker.csv".into(),
                },
                &TrackerOptions {
                    sigma_um: 10.0,
                    target: stated,
                },
            )
            .unwrap()
        }
        Instrument::Ballbar => {
            let pivot = Vector3::from(PIVOT)
                + Vector3::from_fn(|_, _| 0.5 * normal(&mut rng).clamp(-3.0, 3.0));
            let records = poses
                .iter()
                .enumerate()
                .map(|(j, (pose, _))| {
                    let x = truth.spindle_point(
                        &pose.commands_mm,
                        pose.head_rad,
                        0.0,
                        &Vector3::zeros(),
                    );
                    let z = normal(&mut rng);
                    BallbarReading {
                        pose: *pose,
                        length_mm: (x - pivot).norm() + 1e-3 * z,
                        setup: 1,
                        line: j as u64 + 2,
                        ..Default::default()
                    }
                })
                .collect();
            Source::ballbar(
                &ExternalData {
                    records,
                    source: "ballbar.csv".into(),
                },
                &BallbarOptions::default(),
            )
            .unwrap()
        }
    };
    let mut options = FusionOptions::for_machine(&m);
    options.eval_poses = eval.to_vec();
    let model = model(&m);
    let fit: Fusion = identify_fused(
        &model,
        &[Source::internal(&data, m.sensors.logged_sigma()), external],
        &options,
    )
    .unwrap();
    // The deployed machine file, as `--write-machine` writes its geometry.
    let text = model.machine_at(&fit.estimate).to_description().to_json();
    let deployed = MachineDescription::from_json(&text)
        .unwrap()
        .build()
        .unwrap();
    let mut errors = Vec::with_capacity(eval.len());
    let mut axis2 = 0.0;
    for pose in eval {
        let up = m.forward(&pose.commands_mm).unwrap().up;
        let target = m.tool_forward(&up, pose.head_rad);
        let ik = deployed
            .tool_inverse(
                &target.tip_mm,
                &target.axis,
                HeadBranch::Nearest(pose.head_rad),
            )
            .unwrap();
        errors.push(
            truth.spindle_point(&ik.legs_mm, ik.head_rad, 0.0, &Vector3::zeros()) - target.tip_mm,
        );
        axis2 += truth
            .tool_axis(&ik.legs_mm, ik.head_rad)
            .angle(&target.axis)
            .powi(2);
    }
    let n = errors.len() as f64;
    let mean = errors.iter().sum::<Vector3<f64>>() / n;
    let delivered = (errors
        .iter()
        .map(|e| (e - mean).norm_squared())
        .sum::<f64>()
        / n)
        .sqrt();
    Outcome {
        predicted_um: fit.report.tool_tip.touch_off_rms_um,
        delivered_um: 1e3 * delivered,
        predicted_axis_arcsec: fit.report.tool_axis.rms_arcsec,
        delivered_axis_arcsec: (axis2 / n).sqrt() / tricept_kinematics::units::RAD_PER_ARCSEC,
        held_um: fit.report.tool_tip.held_touch_off_rms_um,
        trustworthy: fit.is_trustworthy(),
    }
}

/// RMS over machines.
fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = values.collect();
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

#[test]
fn the_predicted_tool_tip_holds_on_machines_the_project_did_not_generate() {
    let m = Machine::paper();
    let eval = held_out(&m);
    let ks = [12, 30];
    let plans: Vec<(Instrument, Vec<Campaign>)> = [Instrument::Tracker, Instrument::Ballbar]
        .par_iter()
        .map(|&i| (i, planned(&m, i, &ks)))
        .collect();
    let mut cases = Vec::new();
    for (instrument, selections) in &plans {
        for (k, poses) in ks.iter().zip(selections) {
            for scale in [1.0, 2.0] {
                cases.push((*instrument, *k, scale, poses.clone()));
            }
        }
    }
    let results: Vec<Vec<Outcome>> = cases
        .par_iter()
        .map(|(instrument, _, scale, poses)| {
            (0..MACHINES)
                .map(|i| {
                    let truth = TrueMachine::random(*scale, 100 + i);
                    calibrate(
                        &truth,
                        *instrument,
                        poses,
                        Vector3::zeros(),
                        tip_target(),
                        &eval,
                        500 + i,
                    )
                })
                .collect()
        })
        .collect();
    let mut failures = Vec::new();
    for ((instrument, k, scale, _), outcomes) in cases.iter().zip(&results) {
        let predicted = rms(outcomes.iter().map(|o| o.predicted_um));
        let delivered = rms(outcomes.iter().map(|o| o.delivered_um));
        let axis_p = rms(outcomes.iter().map(|o| o.predicted_axis_arcsec));
        let axis_d = rms(outcomes.iter().map(|o| o.delivered_axis_arcsec));
        let trusted = outcomes.iter().filter(|o| o.trustworthy).count();
        eprintln!(
            "TALLY {instrument:?} k = {k}, head errors x{scale}: tip after touch-off predicted {predicted:.1} um, delivered {delivered:.1} um (ratio {:.2}); axis predicted {axis_p:.0}, delivered {axis_d:.0} arcsec; trusted {trusted}/{MACHINES}",
            delivered / predicted
        );
        if delivered > 1.5 * predicted {
            failures.push(format!(
                "{instrument:?} k = {k} x{scale}: {delivered:.1} um > 1.5 x {predicted:.1} um"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn a_known_target_offset_stated_correctly_does_not_bias_the_tip() {
    // The target 20 mm beyond the tip (spindle frame), stated as such,
    // against the target at the tip, on the same machines and poses. With a
    // single known offset the data see `h2`'s zero and the tool's shift along
    // w only together, over a lever 20 mm longer than the tip's: the tip
    // keeps an error of about 20/220 of that shift, which the prediction
    // states (the held parameters' share, `held_touch_off_rms_um`). Beyond it
    // the offset adds nothing: within 1.2 times the target at the tip.
    let m = Machine::paper();
    let eval = held_out(&m);
    let ks = [12, 30];
    let selections = planned(&m, Instrument::Tracker, &ks);
    let offset = Vector3::new(0.0, 0.0, 20.0);
    let stated = TrackerTarget::Known {
        offset_mm: [0.0, 0.0, 20.0],
        sigma_um: 5.0,
    };
    let runs: Vec<(usize, f64, f64, f64, f64)> = ks
        .par_iter()
        .zip(&selections)
        .map(|(k, poses)| {
            let (at_tip, beyond): (Vec<Outcome>, Vec<Outcome>) = (0..MACHINES)
                .map(|i| {
                    let truth = TrueMachine::random(1.0, 100 + i);
                    (
                        calibrate(
                            &truth,
                            Instrument::Tracker,
                            poses,
                            Vector3::zeros(),
                            tip_target(),
                            &eval,
                            500 + i,
                        ),
                        calibrate(
                            &truth,
                            Instrument::Tracker,
                            poses,
                            offset,
                            stated,
                            &eval,
                            500 + i,
                        ),
                    )
                })
                .unzip();
            (
                *k,
                rms(at_tip.iter().map(|o| o.delivered_um)),
                rms(beyond.iter().map(|o| o.delivered_um)),
                rms(beyond.iter().map(|o| o.predicted_um)),
                rms(beyond.iter().map(|o| o.held_um)),
            )
        })
        .collect();
    for (k, at_tip, beyond, predicted, held) in runs {
        let allowed = ((1.2 * at_tip).powi(2) + held * held).sqrt();
        eprintln!(
            "TALLY tracker k = {k}: target at the tip {at_tip:.1} um, 20 mm beyond (stated) {beyond:.1} um (ratio {:.2}; predicted {predicted:.1}, of which the invisible w/h2 combination {held:.1}; allowed {allowed:.1})",
            beyond / at_tip
        );
        assert!(
            beyond <= allowed,
            "k = {k}: {beyond} vs {at_tip} (held {held})"
        );
        assert!(
            beyond <= 1.5 * predicted,
            "k = {k}: {beyond} vs predicted {predicted}"
        );
    }
}

#[test]
fn the_independent_machine_without_errors_is_the_documented_one() {
    // The generator's conventions against the project's exact model at zero
    // errors (the one place the two meet).
    let m = Machine::paper();
    let truth = TrueMachine::documented();
    for pose in held_out(&m).iter().take(20) {
        let up = m.forward(&pose.commands_mm).unwrap().up;
        let joints = truth.forward(&pose.commands_mm);
        assert!(
            (joints[0] - up.phi_rad).abs() < 1e-10,
            "{joints:?} vs {up:?}"
        );
        assert!(
            (joints[1] - up.theta_rad).abs() < 1e-10,
            "{joints:?} vs {up:?}"
        );
        assert!((joints[2] - up.q4_mm).abs() < 1e-8, "{joints:?} vs {up:?}");
        let tool = m.tool_forward(&up, pose.head_rad);
        let tip = truth.spindle_point(&pose.commands_mm, pose.head_rad, 0.0, &Vector3::zeros());
        assert!(
            (tip - tool.tip_mm).norm() < 1e-8,
            "{tip} vs {}",
            tool.tip_mm
        );
        assert!(
            truth
                .tool_axis(&pose.commands_mm, pose.head_rad)
                .angle(&tool.axis)
                < 1e-10
        );
    }
}
