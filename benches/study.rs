//! Monte Carlo throughput of the encoder study on the default 75-pose grid
//! at 2 arcsec, both cores. Targets: fast path at least 1,000,000
//! trials per second, exact path at least 5,000.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use tricept_kinematics::Machine;
use tricept_study::exact::run_exact;
use tricept_study::{Scenario, fast::GradeModel};

fn study(c: &mut Criterion) {
    let m = Machine::paper();
    let s = Scenario::paper(m.clone(), m.workspace.polar_grid(3, 8, 3)).unwrap();
    let g = GradeModel::new(&s, 2.0).unwrap();
    let mut group = c.benchmark_group("encoder_study");
    group.sample_size(10);
    let fast_trials = 200_000;
    group.throughput(Throughput::Elements(fast_trials as u64));
    group.bench_function("fast_path_200k_trials", |b| {
        b.iter(|| black_box(g.estimator.run(&s, fast_trials, 1, 0, &|_| {})))
    });
    let exact_trials = 1_000;
    group.throughput(Throughput::Elements(exact_trials as u64));
    group.bench_function("exact_path_1000_trials", |b| {
        b.iter(|| black_box(run_exact(&s, &g, exact_trials, 1, 0, &|_| {}).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, study);
criterion_main!(benches);
