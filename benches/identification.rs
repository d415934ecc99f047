//! Identification benchmarks: the full nonlinear identification (exact FK,
//! analytic Jacobian, TSQR + rank decision + Gauss-Newton) of Table 2 from
//! 75 and 1000 poses. Target: 1000 poses in under 1 s.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use tricept_ident::{GeometricModel, IdentifyOptions, identify};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
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

criterion_group!(benches, identification);
criterion_main!(benches);
