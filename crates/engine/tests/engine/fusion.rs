//! The fused identification on simulated data: the module, the head and
//! every instrument's nuisance recovered within their standard deviations,
//! and what each source can and cannot see, stated numerically.
//!
//! Every expectation comes from the simulator's inputs (the plant's errors,
//! head errors, instrument frames, pivots, features), never from the fit.
//! Where a parameter is held at its prior because no source sees it, the
//! expected estimate of the others is the truth moved along the reported
//! invisible combination until the held parameter is zero (the basic
//! solution); the combination itself is checked against the model's
//! geometry.

use crate::common::{
    head_truth, internal, known_target, spread_poses, table2_plant, tracker, tracker_points,
};
use nalgebra::{Rotation3, Vector3};
use rayon::prelude::*;
use tricept_data::external::ExternalPose;
use tricept_engine::fusion::{
    BallbarOptions, FusedModel, Fusion, FusionOptions, Source, TouchOptions, TrackerOptions,
    TrackerTarget, identify_fused,
};
use tricept_engine::{IdentError, IdentifyOptions, identify, model::GeometricModel};
use tricept_kinematics::Machine;
use tricept_model::effects::EffectName;
use tricept_model::{ParameterSet, head_errors::HeadParameterSet};
use tricept_numerics::stats::chi2_isf;
use tricept_plant::instruments::commanded;
use tricept_plant::{
    Effect, Plant, instruments::Ballbar, instruments::TouchFeature, instruments::TouchProbe,
    instruments::TouchTarget,
};

/// The truth in the fused model's parameters `[paper15 | effects | head13]`.
fn truth_of(model: &FusedModel, module: &[f64], effects: &[f64], head: &[f64]) -> Vec<f64> {
    let mut t = module.to_vec();
    t.extend_from_slice(effects);
    if model.head().is_some() {
        t.extend_from_slice(head);
    }
    assert_eq!(t.len(), model.len());
    t
}

/// The expected estimate: the truth moved along each reported invisible
/// combination until its held parameter is zero.
fn expected_estimate(fit: &Fusion, truth: &[f64]) -> Vec<f64> {
    let mut e = truth.to_vec();
    let union = &fit.report.union;
    for (held, combo) in union.fixed.iter().zip(&union.unidentifiable) {
        let f = fit.index_of(held).unwrap();
        let scale = combo
            .terms
            .iter()
            .find(|(n, _)| n == held)
            .map(|(_, c)| *c)
            .unwrap();
        let amount = truth[f];
        for (name, c) in &combo.terms {
            let j = fit.index_of(name).unwrap();
            e[j] -= amount * c / scale;
        }
    }
    e
}

/// Asserts every estimated parameter is within 4 standard deviations of
/// its expectation; returns the largest |z|.
fn assert_recovered(fit: &Fusion, truth: &[f64], what: &str) -> f64 {
    assert!(fit.converged, "{what}: not converged");
    let expected = expected_estimate(fit, truth);
    let mut worst: f64 = 0.0;
    for (j, name) in fit.names.iter().enumerate() {
        let Some(sd) = fit.std_dev[j] else { continue };
        let z = (fit.estimate[j] - expected[j]) / sd;
        assert!(
            z.abs() < 4.0,
            "{what}: {name} = {:e}, expected {:e} (sd {sd:e}, z {z:.2})",
            fit.estimate[j],
            expected[j]
        );
        worst = worst.max(z.abs());
    }
    worst
}

/// Asserts a source's chi-square lies in its two-sided 99.9 % interval.
fn assert_chi_square_plausible(fit: &Fusion) {
    for s in &fit.sources {
        let lo = chi2_isf(1.0 - 5e-4, s.redundancy);
        let hi = chi2_isf(5e-4, s.redundancy);
        assert!(
            (lo..=hi).contains(&s.chi_square),
            "{}: chi-square {} outside [{lo}, {hi}] (dof {})",
            s.label,
            s.chi_square,
            s.redundancy
        );
    }
}

fn nuisance(fit: &Fusion, name: &str) -> (f64, f64) {
    for s in &fit.sources {
        if let Some(k) = s.nuisance_names.iter().position(|n| n == name) {
            return (s.nuisance[k], s.nuisance_std_dev[k]);
        }
    }
    panic!("no nuisance {name}")
}

fn assert_nuisance(fit: &Fusion, name: &str, expected: f64) {
    let (v, sd) = nuisance(fit, name);
    let z = (v - expected) / sd;
    assert!(
        z.abs() < 4.0,
        "{name} = {v:e}, expected {expected:e} (sd {sd:e}, z {z:.2})"
    );
}

#[test]
fn internal_only_fused_identification_is_bit_identical_to_identify() {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let data = tricept_data::read_path(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/data/table2-grid-seed1.csv"
    )))
    .unwrap();
    let reference = identify(
        &GeometricModel::new(m.clone(), set.clone()),
        &data,
        &IdentifyOptions::for_machine(&m),
    )
    .unwrap();
    let model = FusedModel::new(m.clone(), set, &[], false).unwrap();
    let fit = identify_fused(
        &model,
        &[Source::internal(&data, m.sensors.logged_sigma())],
        &FusionOptions::for_machine(&m),
    )
    .unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&fit.estimate), bits(&reference.estimate));
    assert_eq!(bits(&fit.sources[0].nuisance), bits(&reference.offsets));
    assert_eq!(fit.iterations, reference.iterations);
    assert_eq!(
        fit.sources[0].chi_square.to_bits(),
        reference.stats.chi_square.to_bits()
    );
    assert_eq!(fit.report.union, reference.report);
}

#[test]
fn the_head_is_invisible_to_the_internal_data_and_each_of_its_columns_is_zero() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let fit = identify_fused(
        &model,
        &[internal(&plant, 1)],
        &FusionOptions::for_machine(m),
    )
    .unwrap();
    let union = &fit.report.union;
    assert_eq!((union.rank, union.n_params), (14, 28));
    for name in HeadParameterSet::head13(&m.head).names() {
        assert!(union.fixed.contains(name), "{name} not held");
        let k = union.fixed.iter().position(|n| n == name).unwrap();
        // A zero column: the invisible combination is the parameter alone.
        assert_eq!(union.unidentifiable[k].terms, vec![(name.clone(), 1.0)]);
        assert_eq!(union.unidentifiable[k].singular_value, 0.0);
    }
}

#[test]
fn a_tracker_with_a_free_target_recovers_the_module_eight_head_parameters_and_its_frame() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let target = Vector3::new(0.8, -0.5, 25.0);
    let t = tracker(target);
    let poses = spread_poses(m, 30, &[-120.0, 0.0, 120.0], &[-40.0, 5.0, 40.0], 3);
    let data = t
        .measure(
            &plant,
            &poses.iter().map(|p| (*p, 0.0)).collect::<Vec<_>>(),
            5,
        )
        .unwrap();
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let sources = [
        internal(&plant, 2),
        Source::tracker(&data, &TrackerOptions::default()).unwrap(),
    ];
    let fit = identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap();
    let union = &fit.report.union;
    assert_eq!(union.rank, 22, "{}", fit.report.to_text());
    for held in [
        "dyA3",
        "tool_length_mm",
        "tool_shift_e_mm",
        "tool_tilt_e_rad",
    ] {
        assert!(
            union.fixed.contains(&held.to_string()),
            "{held}: {:?}",
            union.fixed
        );
    }
    assert!(
        union.fixed.contains(&"tool_shift_w_mm".to_string())
            || union.fixed.contains(&"h2_zero_rad".to_string())
    );
    let truth = truth_of(
        &model,
        &ParameterSet::paper15().table2(),
        &[],
        &head_truth(),
    );
    assert_recovered(&fit, &truth, "tracker, free target");
    assert_chi_square_plausible(&fit);
    // The frame is found; the target offset carries the tool tip it
    // cannot be told from: the actual head's effective tool point at zero
    // angles (h2's zero folded in) minus the nominal tool tip.
    let actual = plant.actual_machine().head;
    let nominal = &m.head;
    let turn = Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(actual.axis2),
        actual.angle_offsets_rad[1],
    );
    let effective = actual.axis2_point_mm
        + turn * (actual.tool_tip_mm + target - actual.axis2_point_mm)
        - nominal.tool_tip_mm;
    for (c, axis) in ["x", "y", "z"].iter().enumerate() {
        assert_nuisance(&fit, &format!("tracker.target_{axis}_mm"), effective[c]);
        assert_nuisance(
            &fit,
            &format!("tracker.s1.t{axis}_mm"),
            t.frame.translation.vector[c],
        );
        assert_nuisance(
            &fit,
            &format!("tracker.s1.r{axis}_rad"),
            t.frame.rotation.scaled_axis()[c],
        );
    }
    // The report names the tool tip as not calibrated.
    assert!(
        fit.report
            .tool_tip
            .held_moving_tip
            .contains(&"tool_length_mm".to_string())
    );
    assert!(
        fit.warnings
            .iter()
            .any(|w| w.contains("tool tip is not calibrated"))
    );
}

#[test]
fn a_target_known_at_the_tip_calibrates_the_tool_tip_and_two_extensions_its_direction() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let truth = truth_of(
        &model,
        &ParameterSet::paper15().table2(),
        &[],
        &head_truth(),
    );
    let t = tracker(Vector3::zeros());
    let poses = spread_poses(m, 30, &[-120.0, 0.0, 120.0], &[-40.0, 5.0, 40.0], 4);
    let known = TrackerOptions {
        sigma_um: 10.0,
        target: TrackerTarget::Known {
            offset_mm: [0.0; 3],
            sigma_um: 5.0,
        },
    };
    let cases: Vec<(&str, Vec<f64>)> = vec![
        ("tip", vec![0.0; 30]),
        (
            "two extensions",
            (0..30)
                .map(|j| if j % 2 == 0 { 0.0 } else { 100.0 })
                .collect(),
        ),
    ];
    let fits: Vec<Fusion> = cases
        .par_iter()
        .map(|(_, extensions)| {
            let records: Vec<(ExternalPose, f64)> = poses
                .iter()
                .copied()
                .zip(extensions.iter().copied())
                .collect();
            let data = t.measure(&plant, &records, 6).unwrap();
            let sources = [internal(&plant, 3), Source::tracker(&data, &known).unwrap()];
            identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap()
        })
        .collect();
    // The tip: 11 head parameters (the tool's tilt, and one of h2's zero
    // and the tool shift it moves like, are left).
    let tip = &fits[0];
    assert_eq!(tip.report.union.rank, 25, "{}", tip.report.to_text());
    assert!(
        tip.report
            .union
            .fixed
            .contains(&"tool_tilt_e_rad".to_string())
    );
    assert!(tip.std_dev[model.index_of("tool_length_mm").unwrap()].is_some());
    assert_recovered(tip, &truth, "tracker, target at the tip");
    assert_chi_square_plausible(tip);
    // Two known extensions: all 13 (only dyA3 left).
    let two = &fits[1];
    assert_eq!(
        two.report.union.fixed,
        vec!["dyA3".to_string()],
        "{}",
        two.report.to_text()
    );
    assert_recovered(two, &truth, "tracker, two extensions");
    for name in ["h2_zero_rad", "tool_tilt_e_rad"] {
        assert!(
            two.std_dev[model.index_of(name).unwrap()].is_some(),
            "{name}"
        );
    }
}

#[test]
fn three_values_of_each_head_angle_see_both_axes_two_do_not() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let known = TrackerOptions {
        sigma_um: 10.0,
        target: TrackerTarget::Known {
            offset_mm: [0.0; 3],
            sigma_um: 5.0,
        },
    };
    let t = tracker(Vector3::zeros());
    let angle_sets: [(&[f64], &[f64]); 3] = [
        (&[0.0, 120.0], &[5.0, 40.0]),
        // Two values of h2 symmetric about zero hide one more combination.
        (&[0.0, 120.0], &[-40.0, 40.0]),
        (&[-120.0, 0.0, 120.0], &[-40.0, 5.0, 40.0]),
    ];
    let ranks: Vec<(usize, Vec<String>)> = angle_sets
        .par_iter()
        .map(|(h1, h2)| {
            let poses = spread_poses(m, 40, h1, h2, 7);
            let data = t
                .measure(
                    &plant,
                    &poses.iter().map(|p| (*p, 0.0)).collect::<Vec<_>>(),
                    8,
                )
                .unwrap();
            let sources = [internal(&plant, 4), Source::tracker(&data, &known).unwrap()];
            let fit = identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap();
            (fit.report.union.rank, fit.report.union.fixed.clone())
        })
        .collect();
    eprintln!(
        "union rank with h1 x h2 = 2 x 2 asymmetric: {}, 2 x 2 symmetric: {}, 3 x 3: {}",
        ranks[0].0, ranks[1].0, ranks[2].0
    );
    assert_eq!(ranks[0].0, 24, "{:?}", ranks[0].1);
    assert_eq!(ranks[1].0, 23, "{:?}", ranks[1].1);
    assert_eq!(ranks[2].0, 25, "{:?}", ranks[2].1);
}

/// Ballbar poses: the ball on the lower half of the sphere of radius
/// `length` about `pivot`, the tool tilted 0.2-0.6 rad in turning
/// directions (so that both head angles take many values).
fn ballbar_poses(m: &Machine, pivot: Vector3<f64>, length: f64, n: usize) -> Vec<ExternalPose> {
    (0..n)
        .map(|j| {
            let f = j as f64 / n as f64;
            let polar = 0.35 + 1.0 * ((j * 7) % n) as f64 / n as f64;
            let azimuth = std::f64::consts::TAU * f * 3.0;
            let u = Vector3::new(
                polar.sin() * azimuth.cos(),
                polar.sin() * azimuth.sin(),
                -polar.cos(),
            );
            let tilt = 0.2 + 0.4 * ((j * 3) % 5) as f64 / 4.0;
            let turn = std::f64::consts::TAU * ((j * 5) % 7) as f64 / 7.0;
            let axis = Vector3::new(tilt.sin() * turn.cos(), tilt.sin() * turn.sin(), tilt.cos());
            commanded(m, &(pivot + u * length), &axis).unwrap()
        })
        .collect()
}

#[test]
fn a_ballbar_recovers_the_module_the_head_and_its_pivot() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let pivot = Vector3::new(40.0, -30.0, 1250.0);
    let bar = Ballbar {
        pivot_mm: pivot,
        length_error_um: 0.7,
        ball_offset_mm: Vector3::zeros(),
        sigma_um: 1.0,
        setup: 1,
    };
    let data = bar
        .measure(&plant, &ballbar_poses(m, pivot, 150.0, 30), 9)
        .unwrap();
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let sources = [
        internal(&plant, 5),
        Source::ballbar(&data, &BallbarOptions::default()).unwrap(),
    ];
    let fit = identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap();
    assert_eq!(fit.report.union.rank, 25, "{}", fit.report.to_text());
    let truth = truth_of(
        &model,
        &ParameterSet::paper15().table2(),
        &[],
        &head_truth(),
    );
    assert_recovered(&fit, &truth, "ballbar");
    assert_chi_square_plausible(&fit);
    for (c, axis) in ["x", "y", "z"].iter().enumerate() {
        assert_nuisance(&fit, &format!("ballbar.s1.pivot_{axis}_mm"), pivot[c]);
    }
    assert_nuisance(&fit, "ballbar.s1.length_error_mm", 0.7e-3);
}

/// A machine scaled by `1 + g` whose legs read a lead of `g` and whose
/// scale reads a gain of `-g`: the UP limb's sensors see exactly the
/// nominal machine.
fn scaled_plant(g: f64) -> (Plant, Vec<f64>) {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let errors = tricept_model::GeometricErrors {
        db_mm: m.base_joints_mm.map(|b| b * g),
        da_mm: m.platform_joints_mm.map(|a| a * g),
        dq_mm: [0.0; 3],
    };
    let module = set.from_errors(&errors).unwrap();
    let mut plant = Plant::geometric(m, errors);
    plant.effects = vec![
        Effect::from(tricept_plant::effects::LegLead { ppm: [g * 1e6; 3] }),
        Effect::from(tricept_plant::effects::ScaleGain {
            ppm: -g * 1e6 / (1.0 + g),
        }),
    ];
    plant.head_errors = head_truth();
    (plant, module)
}

#[test]
fn the_machine_scale_is_invisible_inside_and_a_ballbar_of_known_length_or_a_tracker_fixes_it() {
    let g = 100e-6;
    let (plant, module) = scaled_plant(g);
    let m = &plant.nominal;
    let model = FusedModel::new(
        m.clone(),
        ParameterSet::paper15(),
        &[EffectName::LegLead, EffectName::ScaleGain],
        true,
    )
    .unwrap();
    let truth = truth_of(
        &model,
        &module,
        &[g * 1e6, g * 1e6, g * 1e6, -g * 1e6 / (1.0 + g)],
        &head_truth(),
    );
    let gain = model.index_of("scale-gain.scale_gain_ppm").unwrap();
    let pivot = Vector3::new(40.0, -30.0, 1250.0);
    let bar = Ballbar {
        pivot_mm: pivot,
        length_error_um: 0.7,
        ball_offset_mm: Vector3::zeros(),
        sigma_um: 1.0,
        setup: 1,
    };
    let ballbar = bar
        .measure(&plant, &ballbar_poses(m, pivot, 150.0, 30), 10)
        .unwrap();
    let poses = spread_poses(m, 30, &[-120.0, 0.0, 120.0], &[-40.0, 5.0, 40.0], 12);
    let tracker_data = tracker_points(&plant, Vector3::zeros(), &poses, 13);
    let free = BallbarOptions {
        length_sigma_um: None,
        ..BallbarOptions::default()
    };
    let known = TrackerOptions {
        sigma_um: 10.0,
        target: TrackerTarget::Known {
            offset_mm: [0.0; 3],
            sigma_um: 5.0,
        },
    };
    let cases = ["internal", "ballbar", "ballbar, length free", "tracker"];
    let fits: Vec<Fusion> = cases
        .par_iter()
        .map(|case| {
            let mut sources = vec![internal(&plant, 6)];
            match *case {
                "ballbar" => {
                    sources.push(Source::ballbar(&ballbar, &BallbarOptions::default()).unwrap())
                }
                "ballbar, length free" => sources.push(Source::ballbar(&ballbar, &free).unwrap()),
                "tracker" => sources.push(Source::tracker(&tracker_data, &known).unwrap()),
                _ => {}
            }
            identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap()
        })
        .collect();
    // Inside: the scale direction is an invisible combination, and the
    // report says the gain is invisible.
    let scale = model.scale_direction().unwrap();
    let inside = &fits[0];
    let named = |fit: &Fusion| {
        fit.report
            .named
            .iter()
            .find(|q| q.name == "scale-gain.scale_gain_ppm")
            .unwrap()
            .union
    };
    assert_eq!(named(inside), None);
    let null = inside
        .report
        .union
        .unidentifiable
        .iter()
        .find(|c| {
            c.terms
                .iter()
                .any(|(n, _)| n == "scale-gain.scale_gain_ppm")
        })
        .unwrap();
    // It is the scale direction's effect part (leads +1, gain -1, per ppm).
    for (name, c) in &null.terms {
        let j = model.index_of(name).unwrap();
        if model.effect_range().contains(&j) {
            assert!((c - scale[j] / 1e6).abs() < 1e-6, "{name}: {c}");
        }
    }
    // A ballbar with a certified length sees it (30 readings: a 100 ppm
    // scale at well over 2 standard deviations, docs/hybrid.md); with the
    // bar's length free it is invisible again; a tracker sees it too.
    for (fit, what) in [(&fits[1], "ballbar"), (&fits[3], "tracker")] {
        let sd = named(fit).unwrap();
        eprintln!(
            "{what}: scale gain {:.1} ± {sd:.1} ppm (truth {:.1})",
            fit.estimate[gain], truth[gain]
        );
        assert!(sd < 50.0, "{what}: scale gain sd {sd} ppm");
        assert_eq!(fit.std_dev[gain], Some(sd));
        assert_recovered(fit, &truth, what);
    }
    assert_eq!(named(&fits[2]), None, "{}", fits[2].report.to_text());
}

#[test]
fn an_unknown_tracker_frame_leaves_the_raw_tip_uncertain_a_touch_off_makes_it_irrelevant() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let poses = spread_poses(m, 20, &[-120.0, 0.0, 120.0], &[-40.0, 5.0, 40.0], 21);
    let data = tracker_points(&plant, Vector3::zeros(), &poses, 22);
    let fits: Vec<Fusion> = [false, true]
        .par_iter()
        .map(|with_internal| {
            let mut sources = vec![Source::tracker(&data, &known_target()).unwrap()];
            if *with_internal {
                sources.push(internal(&plant, 7));
            }
            identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap()
        })
        .collect();
    let ratio = |f: &Fusion| f.report.tool_tip.raw_rms_um / f.report.tool_tip.touch_off_rms_um;
    for (f, what) in fits.iter().zip(["tracker alone", "fusion"]) {
        let t = &f.report.tool_tip;
        eprintln!(
            "{what}, 20 points: predicted tool tip raw {:.1} um, after touch-off {:.1} um",
            t.raw_rms_um, t.touch_off_rms_um
        );
    }
    // With the target at the tip, nothing that moves the tip is held.
    assert!(
        fits.iter()
            .all(|f| f.report.tool_tip.held_moving_tip.is_empty())
    );
    let (alone, fused) = (ratio(&fits[0]), ratio(&fits[1]));
    assert!(
        alone > 5.0,
        "tracker alone: raw / touch-off {alone:.2}\n{}",
        fits[0].report.to_text()
    );
    assert!(
        fused < 4.0,
        "fusion: raw / touch-off {fused:.2}\n{}",
        fits[1].report.to_text()
    );
}

#[test]
fn with_the_head_free_the_weak_leg_length_combination_becomes_nearly_harmless_not_visible() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let poses = spread_poses(m, 40, &[-120.0, 0.0, 120.0], &[-40.0, 5.0, 40.0], 23);
    let data = tracker_points(&plant, Vector3::zeros(), &poses, 24);
    let sources = [
        internal(&plant, 8),
        Source::tracker(&data, &known_target()).unwrap(),
    ];
    let fit = identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap();
    let coefficient = |c: &tricept_engine::report::Combination, name: &str| {
        c.terms
            .iter()
            .find(|(n, _)| n == name)
            .map_or(0.0, |(_, v)| *v)
    };
    let union_weak: Vec<_> = fit
        .report
        .weak
        .iter()
        .filter(|w| w.scope == "union")
        .collect();
    let internal_weak: Vec<_> = fit
        .report
        .weak
        .iter()
        .filter(|w| w.scope == "internal")
        .collect();
    assert_eq!(
        (union_weak.len(), internal_weak.len()),
        (1, 1),
        "{}",
        fit.report.to_text()
    );
    let (u, i) = (union_weak[0], internal_weak[0]);
    // The union's weak combination: the three leg lengths together with the
    // head sliding along z' (ax2_shift_a is along -z', tool_length along z').
    let dq: Vec<f64> = ["dq1", "dq2", "dq3"]
        .iter()
        .map(|n| coefficient(&u.combination, n))
        .collect();
    assert!(
        dq.iter()
            .all(|c| c.abs() > 0.5 && c.signum() == dq[0].signum()),
        "{dq:?}"
    );
    let (shift, length) = (
        coefficient(&u.combination, "ax2_shift_a_mm"),
        coefficient(&u.combination, "tool_length_mm"),
    );
    assert!(
        length.abs() > 0.5 && (shift + length).abs() < 0.1 * length.abs(),
        "{shift} {length}"
    );
    assert!(length.signum() != dq[0].signum());
    // Still weak (not made visible), but it hardly moves the tip after a
    // touch-off: under 5 um per standard deviation, and under a tenth of
    // what the internal data's own weak combination does.
    eprintln!(
        "weak combination per sd: union raw {:.1} / touch-off {:.1} um; internal raw {:.1} / touch-off {:.1} um",
        u.raw_um, u.touch_off_um, i.raw_um, i.touch_off_um
    );
    assert!(
        u.touch_off_um < 5.0 && u.harmless,
        "{}",
        fit.report.to_text()
    );
    assert!(
        u.touch_off_um < 0.1 * i.touch_off_um,
        "{} vs {}",
        u.touch_off_um,
        i.touch_off_um
    );
}

/// Touch targets on a sphere: contacts on the cap facing the probe (up,
/// -z), the tool tilted in turning directions.
fn sphere_touches(
    id: u32,
    centre: Vector3<f64>,
    contact_radius: f64,
    n: usize,
) -> Vec<TouchTarget> {
    (0..n)
        .map(|j| {
            let polar = 0.3 + 0.9 * ((j * 5) % n) as f64 / n as f64;
            let azimuth = std::f64::consts::TAU * j as f64 * 0.382;
            let u = Vector3::new(
                polar.sin() * azimuth.cos(),
                polar.sin() * azimuth.sin(),
                -polar.cos(),
            );
            let tilt = 0.15 + 0.35 * ((j * 3) % 4) as f64 / 3.0;
            let turn = std::f64::consts::TAU * ((j * 2) % 5) as f64 / 5.0;
            TouchTarget {
                feature: id,
                tip_mm: centre + u * contact_radius,
                axis: Vector3::new(tilt.sin() * turn.cos(), tilt.sin() * turn.sin(), tilt.cos()),
                approach: -u,
            }
        })
        .collect()
}

#[test]
fn touch_offs_on_spheres_and_a_plane_locate_them_and_the_stylus() {
    let plant = table2_plant();
    let m = &plant.nominal;
    let (r0, r_error_um) = (1.0, 3.0);
    let spheres = [
        (1, Vector3::new(150.0, 100.0, 1150.0)),
        (2, Vector3::new(-180.0, -60.0, 1130.0)),
    ];
    let (normal, offset) = (Vector3::new(0.02, -0.01, -1.0).normalize(), -1190.0);
    let probe = TouchProbe {
        stylus_radius_mm: r0,
        stylus_radius_error_um: r_error_um,
        stylus_radius_sigma_um: 5.0,
        sigma_um: 1.5,
        features: vec![
            TouchFeature::Sphere {
                id: 1,
                centre_mm: spheres[0].1,
                radius_mm: 12.7,
            },
            TouchFeature::Sphere {
                id: 2,
                centre_mm: spheres[1].1,
                radius_mm: 12.7,
            },
            TouchFeature::Plane {
                id: 3,
                normal,
                offset_mm: offset,
            },
        ],
    };
    let mut targets = Vec::new();
    for (id, c) in spheres {
        targets.extend(sphere_touches(id, c, 12.7 + r0, 14));
    }
    for j in 0..12 {
        let (a, b) = (
            std::f64::consts::TAU * j as f64 / 12.0,
            100.0 + 150.0 * (j % 3) as f64,
        );
        let on_plane = Vector3::new(b * a.cos(), b * a.sin(), 0.0);
        let z = (offset - normal.x * on_plane.x - normal.y * on_plane.y) / normal.z;
        let tilt = 0.2 + 0.1 * (j % 3) as f64;
        targets.push(TouchTarget {
            feature: 3,
            tip_mm: Vector3::new(on_plane.x, on_plane.y, z) + normal * r0,
            axis: Vector3::new(tilt * (a + 1.0).cos(), tilt * (a + 1.0).sin(), 1.0),
            approach: -normal,
        });
    }
    let data = probe.measure(&plant, &targets, 25).unwrap();
    let features = probe.features_file(0.0);
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let planes_only = tricept_data::external::ExternalData {
        records: data
            .records
            .iter()
            .filter(|t| t.feature == 3)
            .copied()
            .collect(),
        source: "planes".into(),
    };
    let fits: Vec<Fusion> = [&data, &planes_only]
        .par_iter()
        .map(|d| {
            let sources = [
                internal(&plant, 9),
                Source::touch(d, &features, &TouchOptions::default()).unwrap(),
            ];
            identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap()
        })
        .collect();
    let fit = &fits[0];
    let truth = truth_of(
        &model,
        &ParameterSet::paper15().table2(),
        &[],
        &head_truth(),
    );
    assert_recovered(fit, &truth, "touch-offs");
    assert_chi_square_plausible(fit);
    for (id, c) in spheres {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            assert_nuisance(fit, &format!("touch.f{id}.centre_{axis}_mm"), c[k]);
        }
    }
    let r_true = r0 + 1e-3 * r_error_um;
    assert_nuisance(fit, "touch.stylus_radius_mm", r_true);
    // The plane's offset absorbs the stylus radius; its normal is found.
    assert_nuisance(fit, "touch.f3.offset_mm", offset + r_true);
    let fitted: Vec<f64> =
        serde_json::from_value(fit.sources[1].extra["plane_normals"]["f3"].clone()).unwrap();
    let angle = Vector3::from_column_slice(&fitted).angle(&normal);
    let (_, tilt_sd) = nuisance(fit, "touch.f3.tilt_a_rad");
    assert!(
        angle < 4.0 * 2f64.sqrt() * tilt_sd,
        "normal off by {angle:e} rad (sd {tilt_sd:e})"
    );
    // Touches of a plane alone carry no information on the stylus: it
    // stays at its prior.
    let (r, sd) = nuisance(&fits[1], "touch.stylus_radius_mm");
    assert!(
        (r - r0).abs() < 1e-9 && (sd - 5e-3).abs() < 1e-9,
        "{r} ± {sd}"
    );
}

#[test]
fn a_tracker_target_that_never_turns_cannot_be_told_from_the_frame() {
    let plant = table2_plant();
    let m = &plant.nominal;
    // Five tool tips, one tool orientation: the target's offset along the
    // tool is a translation of the tracker.
    let poses: Vec<(ExternalPose, f64)> = [
        (0.0, 0.0),
        (150.0, 0.0),
        (0.0, 150.0),
        (-150.0, -100.0),
        (100.0, -150.0),
    ]
    .iter()
    .map(|(x, y)| {
        (
            commanded(m, &Vector3::new(*x, *y, 1100.0), &Vector3::z()).unwrap(),
            0.0,
        )
    })
    .collect();
    let data = tracker(Vector3::new(0.0, 0.0, 25.0))
        .measure(&plant, &poses, 26)
        .unwrap();
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let sources = [
        internal(&plant, 10),
        Source::tracker(&data, &TrackerOptions::default()).unwrap(),
    ];
    let e = identify_fused(&model, &sources, &FusionOptions::for_machine(m)).unwrap_err();
    assert!(
        matches!(e, IdentError::NuisanceUnidentifiable { .. }),
        "{e}"
    );
    let text = e.to_string();
    assert!(
        text.contains("tracker.target_z_mm") && text.contains("vary the spindle's orientation"),
        "{text}"
    );
}
