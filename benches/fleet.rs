//! Pooled calibration of a batch (docs/performance.md, "Pooled
//! calibration"): `calibrate_batch` end to end (each machine alone, the
//! spread, the joint fit of every reading) for 10, 100 and 1000 machines of
//! 80 poses, and the joint fit's linear solve by every solver kind on the
//! same block problem (its first step). Target: 1000 machines in well under
//! a minute, time linear in the machines. 10 000 machines and the peak
//! memory: the `fleet_scale` example.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use tricept_benches::fleet_batch;
use tricept_engine::{
    IdentifyOptions, accuracy::AccuracyModel, accuracy::accuracy_points, model::GeometricModel,
};
use tricept_fleet::{BatchOptions, calibrate_batch};
use tricept_ident::advanced::ParameterSet;
use tricept_ident::fleet::SolverKind;
use tricept_kinematics::Machine;

/// Whether the bench solves `machines` machines with `kind`: the dense
/// solve only where it fits (10 machines: 195 unknowns; 100 machines take
/// 20 s a solve, see docs/performance.md), faer's sparse QR up to 100.
fn fits(kind: SolverKind, machines: usize) -> bool {
    match kind {
        SolverKind::Dense => machines <= 10,
        SolverKind::SparseQr => machines <= 100,
        _ => true,
    }
}

fn fleet(c: &mut Criterion) {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let accuracy = AccuracyModel::new(&m, &set, &accuracy_points(&m), 0.25).unwrap();
    let mut g = c.benchmark_group("fleet");
    g.sample_size(10);
    for machines in [10usize, 100, 1000] {
        let data = fleet_batch(machines, 80, 47);
        let batch_options = BatchOptions::default();
        g.bench_function(BenchmarkId::new("calibrate_batch", machines), |b| {
            b.iter(|| {
                black_box(
                    calibrate_batch(&model, &data, &options, &accuracy, &batch_options).unwrap(),
                )
            })
        });
        let batch = calibrate_batch(&model, &data, &options, &accuracy, &batch_options).unwrap();
        let problem = batch.first_step_problem(&model, options.sigma).unwrap();
        for kind in SolverKind::ALL.into_iter().filter(|k| fits(*k, machines)) {
            g.bench_function(
                BenchmarkId::new(format!("solve_{}", kind.name()), machines),
                |b| b.iter(|| black_box(problem.solve(kind).unwrap())),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, fleet);
criterion_main!(benches);
