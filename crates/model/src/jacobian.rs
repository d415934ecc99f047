//! The analytic first-order error model of eq. 9: `delta = J deps` with
//! `J = J1^{-1} J2`.
//!
//! `delta = [dphi, dtheta, dq4]` is the change of the UP limb's passive joint
//! values (what its encoders and scale see) caused by the geometric errors
//! `deps` (21 values, see [`crate::GeometricErrors`]) at fixed leg commands.
//! Perturbing the closure `|A_i - B_i| = q_i + dq_i` with
//! `A_i = r + R (a_0i + da_0i)` gives, per leg,
//!
//! ```text
//! w_i^T dA_i/dx delta = w_i^T db_i - w_i^T R da_0i + dq_i        (eq. 7)
//! ```
//!
//! so `J1` has rows `w_i^T dA_i/dx` (on an ideal U joint
//! `[(b_i x w_i)^T J_theta, w_i^T w_4]`, eq. 9; [`LegGeometry::j1`]) and
//! `J2 = blockdiag(d_i)`, `d_i = [w_i^T, -w_i^T R, 1]`. The paper prints
//! `J = J1 J2`; the consistent reading, checked against finite differences of
//! the exact model in this crate's tests, is `J = J1^{-1} J2`. Both U-joint
//! conventions are covered because `J1` is built from the limb's own
//! rotation axes (`J_theta = [e_x, Rx(phi) e_y]` for x-first,
//! `[Ry(theta) e_x, e_y]` for y-first).

use nalgebra::{Matrix3, SMatrix};
use tricept_kinematics::{
    KinematicsError, Machine, error::SINGULARITY_CONDITION_LIMIT, machine::LegGeometry,
    up_limb::UpJoints,
};

use crate::params::N_FULL;

/// `J` of eq. 9: 3 x 21, rows `(phi, theta, q4)` in rad/mm, rad/mm, mm/mm.
pub type ErrorJacobian = SMatrix<f64, 3, N_FULL>;

/// `J2 = blockdiag(d_i)`, `d_i = [w_i^T, -w_i^T R, 1]`.
pub fn j2(geometry: &LegGeometry) -> ErrorJacobian {
    let mut j2 = ErrorJacobian::zeros();
    let rotation = geometry.limb.rotation;
    for i in 0..3 {
        let w = geometry.directions[i];
        let wr = -(rotation.transpose() * w);
        let c = 7 * i;
        for k in 0..3 {
            j2[(i, c + k)] = w[k];
            j2[(i, c + 3 + k)] = wr[k];
        }
        j2[(i, c + 6)] = 1.0;
    }
    j2
}

/// `J = J1^{-1} J2` from a leg geometry already computed (the hot path).
pub fn error_jacobian_at(geometry: &LegGeometry) -> Result<ErrorJacobian, KinematicsError> {
    let j1_inv = invert_j1(&geometry.j1())?;
    Ok(j1_inv * j2(geometry))
}

/// `J = J1^{-1} J2` of `machine` with its UP limb at `up`.
///
/// # Example
/// ```
/// use nalgebra::Vector3;
/// use tricept_kinematics::Machine;
/// use tricept_model::{jacobian::error_jacobian, ParameterSet};
/// let m = Machine::paper();
/// let up = m.inverse(&Vector3::new(100.0, 50.0, 700.0)).unwrap().up;
/// let j = error_jacobian(&m, &up).unwrap();
/// // First-order change of (phi, theta, q4) for the Table 2 errors:
/// let set = ParameterSet::paper15();
/// let deps = nalgebra::SVector::<f64, 21>::from(set.to_errors(&set.table2()).to_array());
/// let delta = j * deps;
/// assert!(delta[2].abs() < 2.0); // mm
/// ```
pub fn error_jacobian(machine: &Machine, up: &UpJoints) -> Result<ErrorJacobian, KinematicsError> {
    error_jacobian_at(&machine.legs_at(up))
}

/// First-order error of the platform point: `dr = (dr/dx) J deps`, 3 x 21 (mm/mm).
pub fn position_error_jacobian(geometry: &LegGeometry) -> Result<ErrorJacobian, KinematicsError> {
    point_error_jacobian(geometry, &geometry.limb.position_mm)
}

/// First-order error of any point fixed to the platform (a tool tip, a
/// tracker target), at world position `point_mm`: `dp = (dp/dx) J deps`,
/// 3 x 21 (mm/mm), where `dp/dx` is the point's derivative with respect to
/// the UP joints. At the platform point O' this is
/// [`position_error_jacobian`].
///
/// # Example
/// ```
/// use nalgebra::Vector3;
/// use tricept_kinematics::Machine;
/// use tricept_model::{jacobian::point_error_jacobian, jacobian::position_error_jacobian};
/// let m = Machine::paper();
/// let up = m.inverse(&Vector3::new(100.0, 50.0, 700.0)).unwrap().up;
/// let g = m.legs_at(&up);
/// let at_o = point_error_jacobian(&g, &g.limb.position_mm).unwrap();
/// assert_eq!(at_o, position_error_jacobian(&g).unwrap());
/// // A point 350 mm down the tool also turns with the platform: it moves more.
/// let tip = g.limb.position_mm + g.limb.rotation * Vector3::new(0.0, 0.0, 350.0);
/// let at_tip = point_error_jacobian(&g, &tip).unwrap();
/// assert!(at_tip.norm() > at_o.norm());
/// ```
pub fn point_error_jacobian(
    geometry: &LegGeometry,
    point_mm: &nalgebra::Vector3<f64>,
) -> Result<ErrorJacobian, KinematicsError> {
    let dp_dx = geometry.limb.point_jacobian(point_mm);
    Ok(dp_dx * error_jacobian_at(geometry)?)
}

fn invert_j1(j1: &Matrix3<f64>) -> Result<Matrix3<f64>, KinematicsError> {
    j1.try_inverse().ok_or(KinematicsError::Singular {
        condition: f64::INFINITY,
        limit: SINGULARITY_CONDITION_LIMIT,
    })
}
