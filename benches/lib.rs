//! Shared inputs for the criterion benchmarks in this directory.
//!
//! Run them with `cargo bench -p tricept-benches`; the numbers and the
//! command are recorded in `docs/performance.md`.

use nalgebra::Vector3;
use tricept_kinematics::Machine;

/// Points spread over the workspace of `m` (a fixed, seeded sample).
pub fn workspace_points(m: &Machine, n: usize) -> Vec<Vector3<f64>> {
    m.workspace.random_poses(n, 2009)
}

/// A batch of `machines` machines of the Table 1 machine, `poses` random
/// poses each (the paper's noise): Table 2's errors as the batch error,
/// each machine's own deviation N(0, 0.05 mm) per parameter, seeded.
pub fn fleet_batch(machines: usize, poses: usize, seed: u64) -> Vec<tricept_ident::Dataset> {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let m = Machine::paper();
    let set = tricept_ident::advanced::ParameterSet::paper15();
    let batch = set.table2();
    (0..machines)
        .map(|i| {
            let mut rng =
                rand_pcg::Pcg64Mcg::seed_from_u64(seed ^ (i as u64).wrapping_mul(0x9e37_79b9));
            let errors: Vec<f64> = batch
                .iter()
                .map(|b| {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    b + 0.05 * z
                })
                .collect();
            let plant = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&errors));
            let mut d = plant
                .simulate(&tricept_plant::Campaign::random(&m, poses, seed + i as u64))
                .expect("the bench's campaigns are within reach");
            d.source = format!("m{i}.csv");
            d
        })
        .collect()
}
