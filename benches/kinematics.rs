//! Kinematics benchmarks: module IK, FK (cold and warm start), 5-DOF
//! tool-pose IK and the eq. 9 Jacobian. Targets: IK < 100 ns,
//! FK < 1 us, tool-pose IK < 5 us, Jacobian < 1 us.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use tricept_benches::workspace_points;
use tricept_ident::kinematics::HeadBranch;
use tricept_kinematics::{Machine, fk::FkSeed};
use tricept_model::jacobian::error_jacobian;

/// Cycles through the inputs without an integer division in the timed loop.
#[inline]
fn next(k: usize, len: usize) -> usize {
    if k + 1 == len { 0 } else { k + 1 }
}

fn kinematics(c: &mut Criterion) {
    let m = Machine::paper();
    let points = workspace_points(&m, 256);
    let iks: Vec<_> = points.iter().map(|r| m.inverse(r).unwrap()).collect();
    let tools: Vec<(Vector3<f64>, Vector3<f64>)> = points
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let tilt = 0.4 * (k as f64 / 256.0);
            let axis = Vector3::new(tilt.sin(), 0.3 * tilt.sin(), tilt.cos()).normalize();
            (r + Vector3::new(0.0, 0.0, 150.0) + 200.0 * axis, axis)
        })
        .collect();

    let mut k = 0usize;
    c.bench_function("ik", |b| {
        b.iter(|| {
            k = next(k, points.len());
            black_box(m.inverse(black_box(&points[k])).unwrap())
        })
    });
    c.bench_function("fk_cold_start", |b| {
        b.iter(|| {
            k = next(k, iks.len());
            black_box(m.forward(black_box(&iks[k].legs_mm)).unwrap())
        })
    });
    c.bench_function("fk_cold_start_extrapolated_seed", |b| {
        b.iter(|| {
            k = next(k, iks.len());
            black_box(
                m.forward_seeded(black_box(&iks[k].legs_mm), FkSeed::Extrapolated)
                    .unwrap(),
            )
        })
    });
    c.bench_function("fk_warm_start", |b| {
        b.iter(|| {
            k = next(k, iks.len());
            let seed = iks[next(k, iks.len())].up;
            let seed = tricept_ident::kinematics::UpJoints {
                phi_rad: 0.5 * (seed.phi_rad + iks[k].up.phi_rad),
                theta_rad: 0.5 * (seed.theta_rad + iks[k].up.theta_rad),
                q4_mm: 0.5 * (seed.q4_mm + iks[k].up.q4_mm),
            };
            black_box(m.forward_from(black_box(&iks[k].legs_mm), &seed).unwrap())
        })
    });
    c.bench_function("tool_pose_ik", |b| {
        b.iter(|| {
            k = next(k, tools.len());
            let (tip, axis) = &tools[k];
            black_box(
                m.tool_inverse(black_box(tip), axis, HeadBranch::default())
                    .unwrap(),
            )
        })
    });
    c.bench_function("jacobian_eq9", |b| {
        b.iter(|| {
            k = next(k, iks.len());
            black_box(error_jacobian(&m, black_box(&iks[k].up)).unwrap())
        })
    });
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
