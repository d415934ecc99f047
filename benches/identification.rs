//! Identification benchmarks: the full nonlinear identification (exact FK,
//! analytic Jacobian, TSQR + rank decision + Gauss-Newton) of Table 2 from
//! 75 and 1000 poses (target: 1000 poses in under 1 s), and the fused
//! identification of module and head from 1000 internal poses and 100
//! tracker points (target: under 1 s, report included), and what `tricept
//! identify` runs on large logs (the gross-error screen and the fit) on
//! 100 000 and 1 000 000 poses (target: a million in under 5 s with the
//! file read, see `docs/performance.md`).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use tricept_engine::{IdentifyOptions, identify, model::GeometricModel};
use tricept_ident::advanced::ParameterSet;
use tricept_kinematics::Machine;
use tricept_plant::{Campaign, Plant};

fn identification(c: &mut Criterion) {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let plant = Plant::geometric(m.clone(), set.to_errors(&set.table2()));
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let mut group = c.benchmark_group("identify");
    group.sample_size(20);
    for (label, campaign) in [
        ("75_poses_grid", Campaign::grid(&m, 1)),
        ("1000_poses_random", Campaign::random(&m, 1000, 1)),
    ] {
        let data = plant.simulate(&campaign).unwrap();
        group.bench_function(label, |b| {
            b.iter(|| black_box(identify(&model, black_box(&data), &options).unwrap()))
        });
    }
    group.finish();
}

fn large(c: &mut Criterion) {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let plant = Plant::geometric(m.clone(), set.to_errors(&set.table2()));
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let mut group = c.benchmark_group("identify_large");
    group.sample_size(10);
    for n in [100_000, 1_000_000] {
        let data = plant.simulate(&Campaign::random(&m, n, 9)).unwrap();
        group.throughput(criterion::Throughput::Elements(n as u64));
        group.bench_function(format!("{n}_poses_robust"), |b| {
            b.iter(|| {
                black_box(
                    tricept_engine::robust::identify_robust(&model, black_box(&data), &options)
                        .unwrap(),
                )
            })
        });
        // The other part of `tricept identify` on a log: reading and
        // checking the CSV (parsed in parallel batches).
        let mut csv = Vec::new();
        tricept_ident::advanced::files::write_to(&mut csv, &data, &[]).unwrap();
        group.throughput(criterion::Throughput::Bytes(csv.len() as u64));
        group.bench_function(format!("{n}_rows_read"), |b| {
            b.iter(|| black_box(tricept_data::read_from(black_box(&csv[..]), "bench.csv").unwrap()))
        });
    }
    group.finish();
}

fn fused(c: &mut Criterion) {
    use tricept_engine::fusion::{
        FusedModel, FusionOptions, Source, TrackerOptions, TrackerTarget, identify_fused,
    };
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&set.table2()));
    plant.head_errors = tricept_plant::random_head_errors(1.0, 1);
    let internal = plant.simulate(&Campaign::random(&m, 1000, 1)).unwrap();
    let poses: Vec<_> = m
        .workspace
        .random_poses(100, 2)
        .iter()
        .enumerate()
        .map(|(j, r)| {
            let pose = tricept_data::external::ExternalPose {
                commands_mm: m.inverse(r).unwrap().legs_mm,
                head_rad: [(j % 6) as f64 * 1.047, [-0.7, -0.4, 0.4, 0.7][j % 4]],
            };
            (pose, 0.0)
        })
        .collect();
    let tracker = tricept_plant::instruments::Tracker {
        frame: nalgebra::Isometry3::translation(1500.0, -800.0, 200.0),
        target_offset_mm: nalgebra::Vector3::zeros(),
        sigma_um: 10.0,
        setup: 1,
    };
    let points = tracker.measure(&plant, &poses, 3).unwrap();
    let model = FusedModel::new(m.clone(), set, &[], true).unwrap();
    let options = FusionOptions::for_machine(&m);
    let known = TrackerOptions {
        sigma_um: 10.0,
        target: TrackerTarget::Known {
            offset_mm: [0.0; 3],
            sigma_um: 5.0,
        },
    };
    let mut group = c.benchmark_group("identify_fused");
    group.sample_size(10);
    group.bench_function("1000_internal_100_tracker", |b| {
        b.iter(|| {
            let sources = [
                Source::internal(&internal, m.sensors.logged_sigma()),
                Source::tracker(&points, &known).unwrap(),
            ];
            black_box(identify_fused(&model, black_box(&sources), &options).unwrap())
        })
    });
    group.finish();
}

criterion_group!(benches, identification, large, fused);
criterion_main!(benches);
