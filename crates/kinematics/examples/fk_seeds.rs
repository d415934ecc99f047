//! The two cold-start seeds of forward kinematics compared: Newton
//! iterations over the workspace, and configurations solved on a lattice
//! far beyond it (the figures quoted in `docs/performance.md`).
//!
//! ```sh
//! cargo run --release -p tricept-kinematics --example fk_seeds
//! ```

use nalgebra::Vector3;
use tricept_kinematics::{Machine, description::AxisOrder, fk::FkSeed, workspace::box_lattice};

fn main() {
    for machine in [
        Machine::paper(),
        Machine::paper().with_axis_order(AxisOrder::YFirst),
    ] {
        println!("{} ({})", machine.name, machine.up_limb.axis_order);
        // The criterion bench's 256 workspace points.
        let inside: Vec<[f64; 3]> = machine
            .workspace
            .random_poses(256, 2009)
            .iter()
            .filter_map(|r| machine.inverse(r).ok().map(|ik| ik.legs_mm))
            .collect();
        // A 50 mm lattice out to 1000 mm radius, z from 300 to 1300 mm: the
        // configurations IK reaches there.
        let beyond: Vec<(Vector3<f64>, [f64; 3])> = box_lattice(
            Vector3::new(-1000.0, -1000.0, 300.0),
            Vector3::new(1000.0, 1000.0, 1300.0),
            50.0,
        )
        .into_iter()
        .filter_map(|r| machine.inverse(&r).ok().map(|ik| (r, ik.legs_mm)))
        .collect();
        for seed in [FkSeed::Level, FkSeed::Extrapolated] {
            let iterations: u32 = inside
                .iter()
                .map(|legs| {
                    machine
                        .forward_seeded(legs, seed)
                        .map_or(0, |fk| fk.iterations)
                })
                .sum();
            let solved = beyond
                .iter()
                .filter(|(r, legs)| {
                    machine
                        .forward_seeded(legs, seed)
                        .is_ok_and(|fk| (fk.position_mm - r).norm() < 1e-8)
                })
                .count();
            println!(
                "  {seed:?}: {:.2} Newton iterations on average in the workspace; {solved} of {} configurations solved beyond it",
                f64::from(iterations) / inside.len() as f64,
                beyond.len()
            );
        }
    }
}
