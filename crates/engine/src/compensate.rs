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
///
/// # Example
/// ```
/// use tricept_engine::{GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let id = tricept_engine::identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// let actual = tricept_model::actual_machine(&m, &set.to_errors(&set.table2()));
/// let plane = m.workspace.disc_grid(750.0, 100.0);
/// let c = tricept_engine::compensation(&m, &model.machine_at(&id.estimate), &actual, &plane).unwrap();
/// assert!(c.after.stats().mean_mm < 0.2 * c.before.stats().mean_mm);
/// ```
#[derive(Debug, Clone)]
pub struct Compensation {
    /// Nominal commands on the actual machine.
    pub before: ErrorMap,
    /// Identified-model commands on the actual machine.
    pub after: ErrorMap,
}

/// Error maps over `targets_mm` of `actual` commanded by `nominal`
/// (before) and by `identified` (after).
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// let nominal = Machine::paper();
/// let mut actual = nominal.clone();
/// actual.leg_offsets_mm = [0.3, -0.2, 0.1];
/// let targets = nominal.workspace.disc_grid(nominal.workspace.mid_plane_z_mm(), 100.0);
/// // A perfect identification removes the error entirely.
/// let c = tricept_engine::compensation(&nominal, &actual, &actual, &targets).unwrap();
/// assert!(c.before.stats().max_mm > 0.1 && c.after.stats().max_mm < 1e-9);
/// ```
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
///
/// # Example
/// ```
/// use nalgebra::Vector3;
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// // A machine whose leg 1 is 0.1 mm long needs 0.1 mm less command.
/// let mut identified = m.clone();
/// identified.leg_offsets_mm[0] = 0.1;
/// let r = Vector3::new(0.0, 0.0, 750.0);
/// let q = tricept_engine::corrected_commands(&identified, &[r]).unwrap();
/// assert!((m.inverse(&r).unwrap().legs_mm[0] - q[0][0] - 0.1).abs() < 1e-12);
/// ```
pub fn corrected_commands(
    identified: &Machine,
    targets_mm: &[Vector3<f64>],
) -> Result<Vec<[f64; 3]>, ModelError> {
    targets_mm
        .iter()
        .map(|r| Ok(identified.inverse(r)?.legs_mm))
        .collect()
}
