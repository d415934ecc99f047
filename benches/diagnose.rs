//! Diagnosis benchmarks on realistic campaigns (random poses, one approach
//! direction, the mean of 3 readings, class-1 errors of 0.25 mm, a logged
//! 2 K temperature drift): the whole `diagnose` (outlier screen, selection
//! from the vocabulary and the generic dictionary with its period scan,
//! cross-validation, admission on the final model, aliases, final
//! adequacy). Target: 200 poses in under 2 s. `diagnose_large`: a
//! continuous log of 100 000 poses, and `identify`'s fit of the same poses
//! in the same run (target: the diagnosis in at most 10 times its time).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use tricept_diagnose::{DiagnoseOptions, diagnose};
use tricept_engine::{IdentifyOptions, model::GeometricModel, robust::identify_robust};
use tricept_ident::advanced::ParameterSet;
use tricept_ident::effects::Effect;
use tricept_kinematics::Machine;
use tricept_plant::effects::Waveform;
use tricept_plant::{Campaign, Plant, random_errors};

fn data(n: usize, seed: u64, effects: Vec<Effect>) -> tricept_ident::Dataset {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&random_errors(15, 0.25, seed)));
    plant.effects = vec![Effect::from(tricept_plant::effects::Thermal {
        drift_k: 2.0,
        expansion_ppm_per_k: 0.0,
    })];
    plant.effects.extend(effects);
    let mut d = plant.simulate(&Campaign::random(&m, n, seed)).unwrap();
    for (j, p) in d.poses.iter_mut().enumerate() {
        p.line = j as u64 + 2;
    }
    d
}

fn diagnosis(c: &mut Criterion) {
    let m = Machine::paper();
    let options = DiagnoseOptions::for_machine(&m);
    let mut glitch = data(40, 3, Vec::new());
    glitch.poses[17].readings.s_mm += 0.05;
    let cases = [
        ("200_poses_clean", data(200, 1, Vec::new())),
        (
            "200_poses_pitch_error",
            data(
                200,
                2,
                vec![Effect::from(tricept_plant::effects::LegPeriodic {
                    um: [4.0; 3],
                    period_mm: 10.0,
                    phase_deg: [0.0, 120.0, 240.0],
                    waveform: Waveform::Sine,
                })],
            ),
        ),
        (
            "200_poses_leg_lead_and_scale_drift",
            data(
                200,
                4,
                vec![
                    Effect::from(tricept_plant::effects::LegLead {
                        ppm: [80.0, -60.0, 50.0],
                    }),
                    Effect::from(tricept_plant::effects::ScaleDrift { um: 4.0 }),
                ],
            ),
        ),
        ("40_poses_one_glitch", glitch),
    ];
    let mut group = c.benchmark_group("diagnose");
    group.sample_size(10);
    for (label, d) in &cases {
        group.bench_function(*label, |b| {
            b.iter(|| black_box(diagnose(&m, black_box(d), &options).unwrap()))
        });
    }
    group.finish();
}

fn large(c: &mut Criterion) {
    let m = Machine::paper();
    let options = DiagnoseOptions::for_machine(&m);
    let d = data(100_000, 5, Vec::new());
    let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
    let identify_options = IdentifyOptions::for_machine(&m);
    let mut group = c.benchmark_group("diagnose_large");
    group.sample_size(10);
    group.bench_function("100000_poses_clean", |b| {
        b.iter(|| black_box(diagnose(&m, black_box(&d), &options).unwrap()))
    });
    // `identify`'s fit (its gross-error screen included) of the same poses.
    group.bench_function("100000_poses_identify", |b| {
        b.iter(|| black_box(identify_robust(&model, black_box(&d), &identify_options).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, diagnosis, large);
criterion_main!(benches);
