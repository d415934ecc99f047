//! The analytic Jacobian of eq. 9 against central finite differences of the
//! exact model, and the first-order prediction against the exact error for
//! Table 2, over the whole workspace and for both U-joint conventions.

use nalgebra::{SVector, Vector3};
use proptest::prelude::*;
use tricept_kinematics::{Machine, description::AxisOrder, up_limb::UpJoints, up_limb::UpLimb};
use tricept_model::{
    GeometricErrors, ParameterSet, actual::actual_machine, jacobian::error_jacobian,
    jacobian::position_error_jacobian, params::N_FULL,
};

fn machines() -> Vec<Machine> {
    let paper = Machine::paper();
    let y_first = paper.clone().with_axis_order(AxisOrder::YFirst);
    let mut class2 = paper.clone();
    class2.up_limb = UpLimb {
        axis_order: AxisOrder::YFirst,
        axis_skew_rad: 1e-4,
        axis_offset_mm: 0.03,
        twist_rad_per_mm: 3e-7,
        twist_reference_mm: 700.0,
    };
    vec![paper, y_first, class2]
}

fn workspace_point() -> impl Strategy<Value = Vector3<f64>> {
    (0.0..1.0f64, 0.0..std::f64::consts::TAU, 650.0..=850.0f64).prop_map(|(u, a, z)| {
        let rad = 400.0 * u.sqrt();
        Vector3::new(rad * a.cos(), rad * a.sin(), z)
    })
}

/// UP joints reached by `actual` when commanded with `legs`, seeded at `seed`.
fn reached(actual: &Machine, legs: &[f64; 3], seed: &UpJoints) -> [f64; 3] {
    actual.forward_from(legs, seed).unwrap().up.to_array()
}

/// Scales the angle rows by q4 so that all three rows are in mm.
fn to_mm(v: [f64; 3], q4: f64) -> [f64; 3] {
    [v[0] * q4, v[1] * q4, v[2]]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(60))]

    #[test]
    fn analytic_jacobian_matches_central_differences(r in workspace_point()) {
        for m in machines() {
            let ik = m.inverse(&r).unwrap();
            let analytic = error_jacobian(&m, &ik.up).unwrap();
            let h = 1e-3;
            let mut columns = Vec::new();
            for k in 0..N_FULL {
                let mut plus = [0.0; N_FULL];
                plus[k] = h;
                let minus = plus.map(|x| -x);
                let xp = reached(&actual_machine(&m, &GeometricErrors::from_array(&plus)), &ik.legs_mm, &ik.up);
                let xm = reached(&actual_machine(&m, &GeometricErrors::from_array(&minus)), &ik.legs_mm, &ik.up);
                let fd: [f64; 3] = std::array::from_fn(|i| (xp[i] - xm[i]) / (2.0 * h));
                let an: [f64; 3] = std::array::from_fn(|i| analytic[(i, k)]);
                columns.push((to_mm(fd, ik.up.q4_mm), to_mm(an, ik.up.q4_mm)));
            }
            let norm = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
            let largest = columns.iter().map(|(fd, _)| norm(fd)).fold(0.0, f64::max);
            for (k, (fd, an)) in columns.iter().enumerate() {
                let diff = [fd[0] - an[0], fd[1] - an[1], fd[2] - an[2]];
                // Relative to the column, floored at 1e-3 of the largest
                // column (some columns vanish identically, e.g. dyA3 x-first).
                let rel = norm(&diff) / norm(fd).max(1e-3 * largest);
                prop_assert!(rel < 1e-6, "{:?} column {k}: relative error {rel:e}", m.up_limb.axis_order);
            }
        }
    }
}

#[test]
fn first_order_prediction_matches_exact_error_for_table2() {
    let set = ParameterSet::paper15();
    let errors = set.to_errors(&set.table2());
    let deps = SVector::<f64, N_FULL>::from(errors.to_array());
    for m in machines() {
        let actual = actual_machine(&m, &errors);
        let mut worst_joint: f64 = 0.0;
        let mut worst_position: f64 = 0.0;
        for r in m.workspace.polar_grid(4, 12, 5) {
            let ik = m.inverse(&r).unwrap();
            let fk = actual.forward_from(&ik.legs_mm, &ik.up).unwrap();
            // Joint-space error, angles scaled to mm at the limb length.
            let exact = to_mm(
                [
                    fk.up.phi_rad - ik.up.phi_rad,
                    fk.up.theta_rad - ik.up.theta_rad,
                    fk.up.q4_mm - ik.up.q4_mm,
                ],
                ik.up.q4_mm,
            );
            let lin = error_jacobian(&m, &ik.up).unwrap() * deps;
            let lin = to_mm([lin[0], lin[1], lin[2]], ik.up.q4_mm);
            let d = Vector3::from(exact) - Vector3::from(lin);
            worst_joint = worst_joint.max(d.norm() / Vector3::from(exact).norm());
            // Platform position error.
            let dr_exact = fk.position_mm - r;
            let dr_lin = position_error_jacobian(&m.legs_at(&ik.up)).unwrap() * deps;
            worst_position = worst_position.max((dr_exact - dr_lin).norm() / dr_exact.norm());
        }
        assert!(
            worst_joint < 1e-3,
            "{:?}: joint-space relative error {worst_joint:e}",
            m.up_limb
        );
        assert!(
            worst_position < 1e-3,
            "{:?}: position relative error {worst_position:e}",
            m.up_limb
        );
    }
}
