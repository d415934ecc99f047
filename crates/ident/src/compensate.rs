//! Compensation: command the machine through the identified model's IK and
//! compare where the platform goes before and after.
//!
//! "Before" commands come from the nominal IK, "after" from the IK of the
//! identified machine; both drive the actual machine's exact FK. The
//! residual after compensation is reported raw and with the best-fit rigid
//! translation removed (what touching off on the work piece removes).

use nalgebra::Vector3;
use tricept_kinematics::Machine;
use tricept_model::{ErrorMap, ModelError, volumetric_errors};

/// Before/after error maps of a compensation.
#[derive(Debug, Clone)]
pub struct Compensation {
    /// Nominal commands on the actual machine.
    pub before: ErrorMap,
    /// Identified-model commands on the actual machine.
    pub after: ErrorMap,
}

/// Error maps over `targets_mm` of `actual` commanded by `nominal`
/// (before) and by `identified` (after).
pub fn compensation(
    nominal: &Machine,
    identified: &Machine,
    actual: &Machine,
    targets_mm: &[Vector3<f64>],
) -> Result<Compensation, ModelError> {
    Ok(Compensation {
        before: volumetric_errors(nominal, actual, targets_mm)?,
        after: volumetric_errors(identified, actual, targets_mm)?,
    })
}

/// Corrected leg commands for `targets_mm`: the identified machine's IK.
pub fn corrected_commands(
    identified: &Machine,
    targets_mm: &[Vector3<f64>],
) -> Result<Vec<[f64; 3]>, ModelError> {
    targets_mm
        .iter()
        .map(|r| Ok(identified.inverse(r)?.legs_mm))
        .collect()
}
