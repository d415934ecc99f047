//! Batch kinematics end to end: CSV text in, CSV text out, through
//! `tricept_ident::kinematics::run` (what `tricept ik --input` and `tricept fk
//! --input` run: parse, solve in parallel blocks, format). Target: at least
//! 200 000 points/s.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use tricept_benches::workspace_points;
use tricept_ident::kinematics::ExtendedMachine;
use tricept_ident::kinematics::{Verb, run};
use tricept_kinematics::Machine;

/// Points per iteration.
const POINTS: usize = 100_000;

fn batch(c: &mut Criterion) {
    let m = Machine::paper();
    let points = workspace_points(&m, POINTS);
    let mut ik_csv = String::from("x,y,z\n");
    let mut fk_csv = String::from("q1,q2,q3\n");
    for r in &points {
        ik_csv += &format!("{},{},{}\n", r.x, r.y, r.z);
        let q = m.inverse(r).unwrap().legs_mm;
        fk_csv += &format!("{},{},{}\n", q[0], q[1], q[2]);
    }
    let plain = ExtendedMachine::new(m.clone());
    let mut with_effects = m.clone();
    with_effects.leg_effects.lead_ppm = [60.0, -40.0, 20.0];
    with_effects.leg_effects.compliance_um_per_kn_at_1m = 30.0;
    let with_effects = ExtendedMachine::new(with_effects);

    let mut g = c.benchmark_group("batch");
    g.throughput(Throughput::Elements(POINTS as u64));
    g.sample_size(10);
    for (name, verb, input, machine) in [
        ("ik_csv", Verb::Ik, &ik_csv, &plain),
        ("fk_csv", Verb::Fk, &fk_csv, &plain),
        ("ik_csv_leg_effects", Verb::Ik, &ik_csv, &with_effects),
        ("fk_csv_leg_effects", Verb::Fk, &fk_csv, &with_effects),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut out = Vec::with_capacity(POINTS * 160);
                let n = run(
                    verb,
                    machine,
                    input.as_bytes(),
                    "bench.csv",
                    &mut out,
                    || false,
                )
                .unwrap();
                black_box((n, out))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, batch);
criterion_main!(benches);
