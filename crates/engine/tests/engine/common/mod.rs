//! Helpers of the fused identification's tests: the documented plant
//! (Table 2 module errors, head errors `random_head_errors(1.0, 11)`), the
//! tracker of the tests, spread tracker poses, the internal campaign.

#![allow(dead_code)]

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use tricept_data::external::ExternalPose;
use tricept_engine::fusion::{Source, TrackerOptions, TrackerTarget};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant, instruments::Tracker, random_head_errors};

/// The documented head errors of these tests: `random_head_errors(1.0, 11)`.
pub fn head_truth() -> Vec<f64> {
    random_head_errors(1.0, 11)
}

/// Table 2's module errors and the documented head errors.
pub fn table2_plant() -> Plant {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(m, set.to_errors(&set.table2()));
    plant.head_errors = head_truth();
    plant
}

/// The tracker of the tests: rotated 0.7 rad about (1, 2, 3), 1.5 m away.
pub fn tracker(target_mm: Vector3<f64>) -> Tracker {
    Tracker {
        frame: Isometry3::from_parts(
            Translation3::new(1500.0, -800.0, 200.0),
            UnitQuaternion::from_axis_angle(
                &nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0)),
                0.7,
            ),
        ),
        target_offset_mm: target_mm,
        sigma_um: 10.0,
        setup: 1,
    }
}

/// The tracker's points of `plant` at `poses` (no extension), target
/// offset `target`, noise seed `seed`.
pub fn tracker_points(
    plant: &Plant,
    target: Vector3<f64>,
    poses: &[ExternalPose],
    seed: u64,
) -> tricept_data::external::TrackerData {
    let records: Vec<(ExternalPose, f64)> = poses.iter().map(|p| (*p, 0.0)).collect();
    tracker(target).measure(plant, &records, seed).unwrap()
}

/// `n` tracker poses: platform points spread over the workspace, head
/// angles cycling through `h1_deg` x `h2_deg`.
pub fn spread_poses(
    m: &Machine,
    n: usize,
    h1_deg: &[f64],
    h2_deg: &[f64],
    seed: u64,
) -> Vec<ExternalPose> {
    let points = m.workspace.random_poses(n, seed);
    points
        .iter()
        .enumerate()
        .map(|(j, r)| {
            let h1 = h1_deg[j % h1_deg.len()];
            let h2 = h2_deg[(j / h1_deg.len()) % h2_deg.len()];
            ExternalPose {
                commands_mm: m.inverse(r).unwrap().legs_mm,
                head_rad: [h1.to_radians(), h2.to_radians()],
            }
        })
        .collect()
}

pub fn internal(plant: &Plant, seed: u64) -> Source {
    let data = plant
        .simulate(&Campaign::grid(&plant.nominal, seed))
        .unwrap();
    Source::internal(&data, plant.nominal.sensors.logged_sigma())
}

/// A tracker target at the tool tip, known to 5 um; 10 um points.
pub fn known_target() -> TrackerOptions {
    TrackerOptions {
        sigma_um: 10.0,
        target: TrackerTarget::Known {
            offset_mm: [0.0; 3],
            sigma_um: 5.0,
        },
    }
}
