//! The simulator's own guarantees: readings come from the exact model of
//! the actual machine, the sensors add their offsets and exactly the noise
//! they are said to have, every effect adds what its physics says, the
//! logged context (directions, temperature, time) is that of a real
//! campaign, and a seed always gives the same bits.

use nalgebra::Vector3;
use tricept_kinematics::{Machine, machine::SensorNoise};
use tricept_model::ParameterSet;
use tricept_model::effects::{
    GenericFamily, compliance_extra_mm, gravity_leg_tension_n, scale_gain_error_mm,
};
use tricept_plant::effects::Waveform;
use tricept_plant::{
    Campaign, DEFAULT_SENSOR_OFFSETS, Effect, Plant, campaign::PoseOrder, random_errors,
};

fn plant(seed: u64) -> Plant {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    Plant::geometric(m, set.to_errors(&random_errors(15, 0.5, seed)))
}

fn noise_free(campaign: &mut Campaign) {
    campaign.noise = SensorNoise {
        angle_rad: 0.0,
        length_mm: 0.0,
        readings_per_pose: 1,
    };
}

#[test]
fn noise_free_readings_are_the_exact_joints_of_the_actual_machine_plus_offsets() {
    let p = plant(3);
    let mut c = Campaign::random(&p.nominal, 30, 4);
    noise_free(&mut c);
    let data = p.simulate(&c).unwrap();
    let actual = p.actual_machine();
    for (pose, target) in data.poses.iter().zip(&c.targets_mm) {
        // Commanded by the nominal IK...
        let q = p.nominal.inverse(target).unwrap().legs_mm;
        assert_eq!(pose.commands_mm, q);
        // ...reached by the exact FK of the actual machine.
        let up = actual.forward(&q).unwrap().up.to_array();
        let r = pose.readings.to_array();
        for ch in 0..3 {
            assert!(
                (r[ch] - up[ch] - DEFAULT_SENSOR_OFFSETS[ch]).abs() < 1e-9,
                "channel {ch}: {} vs {}",
                r[ch],
                up[ch] + DEFAULT_SENSOR_OFFSETS[ch]
            );
        }
    }
}

#[test]
fn noise_has_the_stated_size_and_the_same_seed_gives_the_same_bits() {
    let p = plant(5);
    let c = Campaign::random(&p.nominal, 400, 8);
    let mut clean_c = c.clone();
    noise_free(&mut clean_c);
    let clean = p.simulate(&clean_c).unwrap();
    let noisy = p.simulate(&c).unwrap();
    assert_eq!(noisy, p.simulate(&c).unwrap());
    let mut other = c.clone();
    other.seed = 9;
    assert_ne!(
        noisy.poses[0].readings,
        p.simulate(&other).unwrap().poses[0].readings
    );
    // The mean of k readings: sigma / sqrt(k) per logged value.
    let sigma = c.noise.logged_sigma();
    for ch in 0..3 {
        let n = noisy.poses.len() as f64;
        let chi2: f64 = noisy
            .poses
            .iter()
            .zip(&clean.poses)
            .map(|(a, b)| {
                let d = (a.readings.to_array()[ch] - b.readings.to_array()[ch]) / sigma[ch];
                d * d
            })
            .sum();
        // chi-square with n degrees of freedom: n +- 5 sqrt(2 n).
        assert!(
            (chi2 - n).abs() < 5.0 * (2.0 * n).sqrt(),
            "channel {ch}: {chi2} for {n}"
        );
    }
}

#[test]
fn approach_directions_and_the_logged_context_are_those_of_the_campaign() {
    let p = plant(1);
    let mut c = Campaign::random(&p.nominal, 20, 2);
    let data = p.simulate(&c).unwrap();
    // Visited once: each leg's direction is the sign of its last move.
    let mut previous: Option<[f64; 3]> = None;
    for (j, pose) in data.poses.iter().enumerate() {
        let expected: [i8; 3] = match previous {
            None => [1, 1, 1],
            Some(q) => std::array::from_fn(|i| if pose.commands_mm[i] >= q[i] { 1 } else { -1 }),
        };
        assert_eq!(pose.approach, Some(expected), "pose {j}");
        assert_eq!(pose.time_s, Some(j as f64 * c.seconds_per_pose));
        previous = Some(pose.commands_mm);
    }
    // Visited twice: extending, then retracting, at the same commands.
    c.order = PoseOrder::BothDirections;
    let both = p.simulate(&c).unwrap();
    assert_eq!(both.poses.len(), 40);
    for pair in both.poses.chunks(2) {
        assert_eq!(pair[0].commands_mm, pair[1].commands_mm);
        assert_eq!(
            (pair[0].approach, pair[1].approach),
            (Some([1; 3]), Some([-1; 3]))
        );
    }
}

#[test]
fn effects_add_what_their_physics_says() {
    let base = plant(7);
    let mut c = Campaign::random(&base.nominal, 12, 3);
    noise_free(&mut c);
    let clean = base.true_poses(&c).unwrap();
    let actual = base.actual_machine();

    // A scale gain changes the scale reading only, by g q4.
    let mut gain = base.clone();
    gain.effects = vec![Effect::from(tricept_plant::effects::ScaleGain {
        ppm: 120.0,
    })];
    for (a, b) in gain.true_poses(&c).unwrap().iter().zip(&clean) {
        let (ra, rb) = (a.readings.to_array(), b.readings.to_array());
        assert_eq!((ra[0], ra[1]), (rb[0], rb[1]));
        assert!((ra[2] - rb[2] - scale_gain_error_mm(120.0, b.up.q4_mm)).abs() < 1e-12);
    }

    // A lead error lengthens leg i by ppm_i q_i: the platform goes where
    // the actual machine's FK of the lengthened legs puts it.
    let ppm = [80.0, -40.0, 60.0];
    let mut lead = base.clone();
    lead.effects = vec![Effect::from(tricept_plant::effects::LegLead { ppm })];
    for t in lead.true_poses(&c).unwrap() {
        let legs: [f64; 3] = std::array::from_fn(|i| t.commands_mm[i] * (1.0 + ppm[i] * 1e-6));
        let fk = actual.forward(&legs).unwrap();
        assert!((fk.position_mm - t.position_mm).norm() < 1e-9);
    }

    // Compliance: each leg stretches by its gravity tension over its
    // stiffness (the tension taken at the nominal joints of the command).
    let stiffness = 40.0;
    let mut soft = base.clone();
    soft.effects = vec![Effect::from(tricept_plant::effects::Compliance {
        stiffness_n_per_um_at_1m: stiffness,
    })];
    let mut sag = 0.0;
    for t in soft.true_poses(&c).unwrap() {
        let nominal_up = base.nominal.forward(&t.commands_mm).unwrap().up;
        let f = gravity_leg_tension_n(&base.nominal, &nominal_up);
        let legs: [f64; 3] = std::array::from_fn(|i| {
            t.commands_mm[i] + compliance_extra_mm(stiffness, f[i], t.commands_mm[i])
        });
        let fk = actual.forward(&legs).unwrap();
        assert!((fk.position_mm - t.position_mm).norm() < 1e-9);
        let rigid = actual.forward(&t.commands_mm).unwrap().position_mm;
        sag += (t.position_mm - rigid).z;
    }
    // A hanging machine: gravity along +z stretches the legs, the platform
    // sags away from the base.
    assert!(sag > 0.0, "{sag}");

    // A temperature drift: the logged temperature rises linearly by the
    // drift (to the logger's noise), the legs grow alpha q dT.
    let mut warm = base.clone();
    warm.effects = vec![Effect::from(tricept_plant::effects::Thermal {
        drift_k: 3.0,
        expansion_ppm_per_k: 11.5,
    })];
    let poses = warm.true_poses(&c).unwrap();
    let n = poses.len();
    for (j, t) in poses.iter().enumerate() {
        let dt = 3.0 * j as f64 / (n - 1) as f64;
        assert!((t.temp_c - c.start_temp_c - dt).abs() < 1e-12);
        let legs: [f64; 3] = std::array::from_fn(|i| t.commands_mm[i] * (1.0 + 11.5e-6 * dt));
        assert!((actual.forward(&legs).unwrap().position_mm - t.position_mm).norm() < 1e-9);
    }
}

#[test]
fn outliers_corrupt_exactly_the_stated_number_of_readings_by_the_stated_size() {
    let base = plant(2);
    let c = Campaign::random(&base.nominal, 50, 6);
    let clean = base.simulate(&c).unwrap();
    let mut bad = base.clone();
    bad.effects = vec![Effect::from(tricept_plant::effects::Outliers {
        count: 3,
        size_sigma: 400.0,
    })];
    let corrupted = bad.simulate(&c).unwrap();
    let sigma = c.noise.logged_sigma();
    let mut changed = Vec::new();
    for (j, (a, b)) in corrupted.poses.iter().zip(&clean.poses).enumerate() {
        let (ra, rb) = (a.readings.to_array(), b.readings.to_array());
        for ch in 0..3 {
            if ra[ch] != rb[ch] {
                let size = ((ra[ch] - rb[ch]) / sigma[ch]).abs();
                assert!((size - 400.0).abs() < 1e-6, "{size}");
                changed.push(j);
            }
        }
    }
    assert_eq!(changed.len(), 3, "{changed:?}");
    changed.dedup();
    assert_eq!(changed.len(), 3, "one reading per corrupted row");
}

#[test]
fn an_unreachable_target_is_an_error_naming_it() {
    let p = plant(1);
    let c = Campaign::from_targets(
        &p.nominal,
        vec![
            Vector3::new(0.0, 0.0, 750.0),
            Vector3::new(5000.0, 0.0, 750.0),
        ],
        1,
    );
    let e = p.simulate(&c).unwrap_err().to_string();
    // The second target, numbered from 1.
    assert!(e.contains("pose 2") && e.contains("5000"), "{e}");
}

#[test]
fn effects_outside_the_vocabulary_add_what_their_physics_says() {
    let base = plant(9);
    let mut c = Campaign::random(&base.nominal, 15, 4);
    noise_free(&mut c);
    let clean = base.true_poses(&c).unwrap();
    let actual = base.actual_machine();
    let legs_reach = |t: &tricept_plant::TruePose, extra: [f64; 3]| {
        let legs: [f64; 3] = std::array::from_fn(|i| t.commands_mm[i] + extra[i]);
        (actual.forward(&legs).unwrap().position_mm - t.position_mm).norm()
    };

    // Ball-screw pitch error: A sin(2 pi q / P + psi) on each leg, in mm.
    let (um, period, phase) = ([4.0, 3.0, 5.0], 10.0, [0.0, 90.0, 200.0]);
    let mut pitch = base.clone();
    pitch.effects = vec![Effect::from(tricept_plant::effects::LegPeriodic {
        um,
        period_mm: period,
        phase_deg: phase,
        waveform: Waveform::Sine,
    })];
    for t in pitch.true_poses(&c).unwrap() {
        let extra: [f64; 3] = std::array::from_fn(|i| {
            um[i]
                * 1e-3
                * (std::f64::consts::TAU * t.commands_mm[i] / period + phase[i].to_radians()).sin()
        });
        assert!(legs_reach(&t, extra) < 1e-9);
    }
    // A sawtooth rises from -A to A over each period.
    pitch.effects = vec![Effect::from(tricept_plant::effects::LegPeriodic {
        um,
        period_mm: period,
        phase_deg: [0.0; 3],
        waveform: Waveform::Sawtooth,
    })];
    for t in pitch.true_poses(&c).unwrap() {
        let extra: [f64; 3] = std::array::from_fn(|i| {
            let frac = (t.commands_mm[i] / period).rem_euclid(1.0);
            um[i] * 1e-3 * (2.0 * frac - 1.0)
        });
        assert!(legs_reach(&t, extra) < 1e-9);
    }

    // Quadratic and power-law leg errors about a centre.
    let mut quad = base.clone();
    quad.effects = vec![Effect::from(tricept_plant::effects::LegQuadratic {
        um: [10.0, -8.0, 6.0],
        centre_mm: 845.0,
        half_width_mm: 250.0,
    })];
    for t in quad.true_poses(&c).unwrap() {
        let extra: [f64; 3] = std::array::from_fn(|i| {
            [10.0, -8.0, 6.0][i] * 1e-3 * ((t.commands_mm[i] - 845.0) / 250.0).powi(2)
        });
        assert!(legs_reach(&t, extra) < 1e-9);
    }
    quad.effects = vec![Effect::from(tricept_plant::effects::LegPower {
        um: [10.0, -8.0, 6.0],
        exponent: 1.5,
        centre_mm: 845.0,
        half_width_mm: 250.0,
    })];
    for t in quad.true_poses(&c).unwrap() {
        let extra: [f64; 3] = std::array::from_fn(|i| {
            [10.0, -8.0, 6.0][i] * 1e-3 * ((t.commands_mm[i] - 845.0) / 250.0).abs().powf(1.5)
        });
        assert!(legs_reach(&t, extra) < 1e-9);
    }

    // A scale drifting linearly with time, whatever the temperature; an
    // encoder reading (1 + g) times its angle.
    let mut drift = base.clone();
    drift.effects = vec![
        Effect::from(tricept_plant::effects::ScaleDrift { um: 3.0 }),
        Effect::from(tricept_plant::effects::EncoderGain {
            phi_ppm: 200.0,
            theta_ppm: -100.0,
        }),
    ];
    let poses = drift.true_poses(&c).unwrap();
    let n = poses.len();
    for (j, (a, b)) in poses.iter().zip(&clean).enumerate() {
        let (ra, rb) = (a.readings.to_array(), b.readings.to_array());
        assert_eq!(a.position_mm, b.position_mm);
        assert!((ra[0] - rb[0] - 200e-6 * b.up.phi_rad).abs() < 1e-15);
        assert!((ra[1] - rb[1] + 100e-6 * b.up.theta_rad).abs() < 1e-15);
        let expected = 3e-3 * j as f64 / (n - 1) as f64;
        assert!((ra[2] - rb[2] - expected).abs() < 1e-12);
    }
    // Their names are the generic families a perfect diagnosis would give.
    assert!(
        Effect::from(tricept_plant::effects::ScaleDrift { um: 1.0 }).name()
            == GenericFamily::ReadingDrift
    );
}

#[test]
fn revisits_repeat_commands_and_worse_noise_is_worse() {
    let base = plant(3);
    let mut c = Campaign::random(&base.nominal, 30, 8);
    c.revisits = 10;
    let data = base.simulate(&c).unwrap();
    assert_eq!(data.poses.len(), 40);
    for k in 0..10 {
        assert_eq!(data.poses[30 + k].commands_mm, data.poses[k].commands_mm);
    }
    // The true noise scales with the factor; the same seed draws the same
    // normal deviates.
    let mut noisy = c.clone();
    noisy.noise_factor = 2.0;
    let worse = base.simulate(&noisy).unwrap();
    let truth = base.true_poses(&c).unwrap();
    for ((a, b), t) in worse.poses.iter().zip(&data.poses).zip(&truth) {
        let (ra, rb, rt) = (
            a.readings.to_array(),
            b.readings.to_array(),
            t.readings.to_array(),
        );
        for ch in 0..3 {
            assert!(((ra[ch] - rt[ch]) - 2.0 * (rb[ch] - rt[ch])).abs() < 1e-12);
        }
    }
}

/// A plant with module and head errors.
fn plant_with_head(seed: u64) -> Plant {
    let mut p = plant(seed);
    p.head_errors = tricept_plant::random_head_errors(1.0, seed);
    p
}

/// Tracker poses spread over the workspace and the head's angles.
fn external_poses(m: &Machine, n: usize) -> Vec<tricept_data::external::ExternalPose> {
    m.workspace
        .random_poses(n, 9)
        .iter()
        .enumerate()
        .map(|(j, r)| tricept_data::external::ExternalPose {
            commands_mm: m.inverse(r).unwrap().legs_mm,
            head_rad: [0.9 * j as f64, 0.6 * ((j % 5) as f64 - 2.0) / 2.0],
        })
        .collect()
}

#[test]
fn a_tracker_measures_the_exact_target_in_its_frame_with_the_stated_noise() {
    let p = plant_with_head(4);
    let poses: Vec<_> = external_poses(&p.nominal, 400)
        .into_iter()
        .enumerate()
        .map(|(j, pose)| (pose, if j % 2 == 0 { 0.0 } else { 80.0 }))
        .collect();
    let mut tracker = tricept_plant::instruments::Tracker {
        frame: nalgebra::Isometry3::new(
            Vector3::new(900.0, -300.0, 50.0),
            Vector3::new(0.3, -0.2, 0.1),
        ),
        target_offset_mm: Vector3::new(0.5, -0.3, 20.0),
        sigma_um: 0.0,
        setup: 2,
    };
    let clean = tracker.measure(&p, &poses, 7).unwrap();
    let actual = p.actual_machine();
    for (r, (pose, extension)) in clean.records.iter().zip(&poses) {
        // The exact point: FK of the actual machine, the actual head at the
        // commands plus its zeros, the target along the actual tool axis.
        let fk = actual.forward(&pose.commands_mm).unwrap();
        let h = &actual.head;
        let local = h.spindle_point(
            pose.head_rad,
            &(h.tool_tip_mm + h.tool_direction * *extension + tracker.target_offset_mm),
        );
        let x = fk.position_mm + fk.rotation * local;
        let y = tracker.frame * nalgebra::Point3::from(x);
        for c in 0..3 {
            assert!((r.position_mm[c] - y[c]).abs() < 1e-9);
        }
        assert_eq!((r.setup, r.extension_mm), (2, *extension));
    }
    tracker.sigma_um = 10.0;
    let noisy = tracker.measure(&p, &poses, 7).unwrap();
    assert_eq!(noisy, tracker.measure(&p, &poses, 7).unwrap());
    let d: Vec<f64> = noisy
        .records
        .iter()
        .zip(&clean.records)
        .flat_map(|(a, b)| (0..3).map(move |c| 1e3 * (a.position_mm[c] - b.position_mm[c])))
        .collect();
    let sd = (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt();
    assert!((sd / 10.0 - 1.0).abs() < 0.08, "{sd} um");
}

#[test]
fn a_ballbar_reads_the_exact_distance_plus_its_length_error() {
    let p = plant_with_head(5);
    let pivot = Vector3::new(30.0, -20.0, 1250.0);
    let bar = tricept_plant::instruments::Ballbar {
        pivot_mm: pivot,
        length_error_um: 2.5,
        ball_offset_mm: Vector3::new(0.0, 0.0, 5.0),
        sigma_um: 0.0,
        setup: 1,
    };
    let poses = external_poses(&p.nominal, 20);
    let data = bar.measure(&p, &poses, 3).unwrap();
    for (r, pose) in data.records.iter().zip(&poses) {
        let effector = tricept_model::head_errors::Effector {
            extension_mm: 0.0,
            offset_mm: bar.ball_offset_mm,
        };
        let x = p
            .spindle_point(&pose.commands_mm, pose.head_rad, &effector)
            .unwrap();
        assert!((r.length_mm - (x - pivot).norm() - 2.5e-3).abs() < 1e-9);
    }
}

#[test]
fn a_touch_latches_the_commands_where_the_actual_stylus_meets_the_true_feature() {
    let p = plant_with_head(6);
    let (centre, radius, r) = (Vector3::new(100.0, 50.0, 1150.0), 12.7, 1.0);
    let probe = tricept_plant::instruments::TouchProbe {
        stylus_radius_mm: r,
        stylus_radius_error_um: 4.0,
        stylus_radius_sigma_um: 5.0,
        sigma_um: 0.0,
        features: vec![tricept_plant::instruments::TouchFeature::Sphere {
            id: 1,
            centre_mm: centre,
            radius_mm: radius,
        }],
    };
    let targets: Vec<_> = (0..8)
        .map(|j| {
            let a = j as f64 * 0.8;
            let u = Vector3::new(0.5 * a.cos(), 0.5 * a.sin(), -0.8).normalize();
            tricept_plant::instruments::TouchTarget {
                feature: 1,
                tip_mm: centre + u * (radius + r),
                axis: Vector3::new(0.2 * a.sin(), 0.2 * a.cos(), 1.0),
                approach: -u,
            }
        })
        .collect();
    let data = probe.measure(&p, &targets, 1).unwrap();
    for t in &data.records {
        let x = p
            .spindle_point(&t.pose.commands_mm, t.pose.head_rad, &Default::default())
            .unwrap();
        let clearance = (x - centre).norm() - radius - (r + 4e-3);
        assert!(clearance.abs() < 1e-9, "{clearance:e} mm");
    }
}
