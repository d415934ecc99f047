//! External instruments that measure the simulated machine from outside: a
//! laser tracker (or CMM) on a target in the spindle, a ballbar from the
//! tool-tip ball to a pivot on the table, and a touch probe on reference
//! spheres and planes. Each measures the exact spindle point of the actual
//! machine ([`Plant::spindle_point`](crate::Plant::spindle_point)), adds
//! its own noise from its own seeded generator (PCG-64 MCG, the seed mixed
//! with a tag per instrument) and writes the external-measurement records
//! of `tricept-data`. One file per instrument (`tracker.rs`, `ballbar.rs`,
//! `touch.rs`), as in `tricept-data`'s `external/` and `tricept-engine`'s
//! `fusion/`.
//!
//! What every instrument repeats is written here once: `measure_each`
//! (the actual machine, the seeded generator of the instrument's tag, one
//! record per item, the records' data set) and `spindle_point` (the
//! actual spindle point at a pose, an error naming the item). Adding an
//! instrument is one file here: its settings and a `measure` that calls
//! `measure_each` with what is new (where the spindle goes, what the
//! instrument reads, its noise).

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use tricept_data::{external::ExternalData, external::ExternalPose};
use tricept_kinematics::{Machine, head::HeadBranch};
use tricept_model::head_errors::Effector;

use crate::{Plant, PlantError};

mod ballbar;
mod touch;
mod tracker;

pub use ballbar::Ballbar;
pub use touch::{TouchFeature, TouchProbe, TouchTarget};
pub use tracker::Tracker;

fn kinematics_error(
    index: usize,
    target: Vector3<f64>,
) -> impl Fn(tricept_kinematics::KinematicsError) -> PlantError {
    move |source| PlantError::Kinematics {
        index,
        target_mm: target.into(),
        source,
    }
}

/// One record per item of `items`, made by `record(actual, index, item,
/// rng)` on the plant's actual machine with the instrument's own generator
/// (the seed mixed with its `tag`), as the data set `source`.
fn measure_each<T, R>(
    plant: &Plant,
    items: &[T],
    seed: u64,
    tag: u64,
    source: &str,
    mut record: impl FnMut(&Machine, usize, &T, &mut Pcg64Mcg) -> Result<R, PlantError>,
) -> Result<ExternalData<R>, PlantError> {
    let actual = plant.actual_machine();
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ tag);
    let records = items
        .iter()
        .enumerate()
        .map(|(j, item)| record(&actual, j, item, &mut rng))
        .collect::<Result<Vec<R>, PlantError>>()?;
    Ok(ExternalData {
        records,
        source: source.into(),
    })
}

/// The actual spindle point (`effector`) at `pose`; an error names item `j`.
fn spindle_point(
    plant: &Plant,
    actual: &Machine,
    j: usize,
    pose: &ExternalPose,
    effector: &Effector,
) -> Result<Vector3<f64>, PlantError> {
    plant
        .spindle_point_on(actual, &pose.commands_mm, pose.head_rad, effector)
        .map_err(kinematics_error(j, Vector3::from(pose.commands_mm)))
}

/// The commands (legs and head angles) the nominal tool IK gives for a tool
/// tip and axis.
pub fn commanded(
    nominal: &Machine,
    tip_mm: &Vector3<f64>,
    axis: &Vector3<f64>,
) -> Result<ExternalPose, tricept_kinematics::KinematicsError> {
    let ik = nominal.tool_inverse(tip_mm, axis, HeadBranch::default())?;
    Ok(ExternalPose {
        commands_mm: ik.legs_mm,
        head_rad: ik.head_rad,
    })
}
