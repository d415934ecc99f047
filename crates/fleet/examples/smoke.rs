use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use tricept_engine::{AccuracyModel, GeometricModel, IdentifyOptions, accuracy_points};
use tricept_fleet::{BatchOptions, SolverKind, calibrate_batch};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(12);
    let kind: SolverKind = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(SolverKind::Schur);
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(5);
    let batch_err: Vec<f64> = set.table2();
    let tau = 0.05;
    let t0 = std::time::Instant::now();
    let data: Vec<_> = (0..n)
        .map(|i| {
            let e: Vec<f64> = batch_err
                .iter()
                .map(|b| {
                    b + tau * {
                        let z: f64 = StandardNormal.sample(&mut rng);
                        z
                    }
                })
                .collect();
            let mut d = Plant::geometric(m.clone(), set.to_errors(&e))
                .simulate(&Campaign::random(&m, 80, i as u64))
                .unwrap();
            d.source = format!("m{i}.csv");
            d
        })
        .collect();
    eprintln!("simulated in {:?}", t0.elapsed());
    let model = GeometricModel::new(m.clone(), set.clone());
    let options = IdentifyOptions::for_machine(&m);
    let acc = AccuracyModel::new(&m, &set, &accuracy_points(&m), 0.25).unwrap();
    let t0 = std::time::Instant::now();
    let b = calibrate_batch(
        &model,
        &data,
        &options,
        &acc,
        &BatchOptions {
            kind,
            ..Default::default()
        },
    )
    .unwrap();
    eprintln!(
        "batch in {:?}; joint {:.3}s solve {:.3}s iters {} conv {}",
        t0.elapsed(),
        b.joint.fit_seconds,
        b.joint.stats.seconds,
        b.joint.iterations,
        b.joint.converged
    );
    let (mean, sd) = b.mean();
    let spread = b.spread_mm();
    for j in 0..15 {
        println!(
            "{:>5} mean {:9.5} true {:8.4} sd {:?} spread {:?}",
            set.names()[j],
            mean[j],
            batch_err[j],
            sd[j],
            spread[j]
        );
    }
    println!(
        "exit {} outliers {:?} members {} stats {:?} reml it {} conv {}",
        b.exit_code(),
        b.outliers(),
        b.members(),
        b.joint.stats,
        b.spread.iterations,
        b.spread.converged
    );
    for w in &b.warnings {
        println!("W {w}");
    }
}
