//! The "actual machine": the nominal description plus geometric errors,
//! with exact IK and FK inherited from [`tricept_kinematics::Machine`].
//!
//! Simulated sensor readings are computed on this exact model, never from
//! the linearisation being tested.

use tricept_kinematics::Machine;

use crate::params::GeometricErrors;

/// The nominal machine with `errors` applied: joint centres moved by
/// `db_i`, `da_0i`, leg offsets increased by `dq_i`.
///
/// # Example
/// ```
/// use nalgebra::Vector3;
/// use tricept_kinematics::Machine;
/// use tricept_model::{actual::actual_machine, ParameterSet};
/// let nominal = Machine::paper();
/// let set = ParameterSet::paper15();
/// let actual = actual_machine(&nominal, &set.to_errors(&set.table2()));
/// let r = Vector3::new(0.0, 0.0, 750.0);
/// let q = nominal.inverse(&r).unwrap().legs_mm;
/// let reached = actual.forward(&q).unwrap().position_mm;
/// assert!((reached - r).norm() > 0.1); // the errors move the platform
/// ```
pub fn actual_machine(nominal: &Machine, errors: &GeometricErrors) -> Machine {
    let mut m = nominal.clone();
    for i in 0..3 {
        m.base_joints_mm[i] += errors.db_mm[i];
        m.platform_joints_mm[i] += errors.da_mm[i];
        m.leg_offsets_mm[i] += errors.dq_mm[i];
    }
    m
}

/// The errors that turn `nominal` into `actual` (the inverse of
/// [`actual_machine`] for machines that differ only in joints and offsets).
pub fn errors_between(nominal: &Machine, actual: &Machine) -> GeometricErrors {
    GeometricErrors {
        db_mm: std::array::from_fn(|i| actual.base_joints_mm[i] - nominal.base_joints_mm[i]),
        da_mm: std::array::from_fn(|i| {
            actual.platform_joints_mm[i] - nominal.platform_joints_mm[i]
        }),
        dq_mm: std::array::from_fn(|i| actual.leg_offsets_mm[i] - nominal.leg_offsets_mm[i]),
    }
}
