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

use nalgebra::Vector3;
use tricept_data::ExternalPose;
use tricept_kinematics::{HeadBranch, Machine};

use crate::PlantError;

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
