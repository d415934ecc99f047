//! The head's error parameters: the analytic Jacobian of a spindle point
//! against central differences of the exact head, the module's point
//! Jacobian against central differences of the exact tool forward
//! kinematics (both U-joint conventions), and the two gauges the 13-set
//! leaves out.

use nalgebra::Vector3;
use tricept_kinematics::{Machine, description::AxisOrder, head::Head};
use tricept_model::{
    GeometricErrors, actual::actual_machine, head_errors::Effector, head_errors::HeadParameterSet,
    head_errors::N_HEAD, head_errors::TYPICAL_HEAD_ERRORS, jacobian::point_error_jacobian,
    params::N_FULL,
};

/// A small deterministic generator (xorshift64*), uniform in [-1, 1).
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        2.0 * (bits as f64 / (1u64 << 53) as f64) - 1.0
    }
}

/// Random head errors ten times the typical size (1-3 mrad, 0.5-1 mm).
fn random_head_errors(u: &mut Uniform) -> Vec<f64> {
    TYPICAL_HEAD_ERRORS
        .iter()
        .map(|s| 10.0 * s * u.next())
        .collect()
}

/// A head that is not the default A/C one: oblique axes and tool.
fn oblique_head() -> Head {
    Head {
        axis1: Vector3::new(0.1, -0.05, 1.0).normalize(),
        axis1_point_mm: Vector3::new(3.0, -2.0, 10.0),
        axis2: Vector3::new(1.0, 0.2, 0.3).normalize(),
        axis2_point_mm: Vector3::new(5.0, 12.0, 140.0),
        tool_tip_mm: Vector3::new(-8.0, 4.0, 330.0),
        tool_direction: Vector3::new(0.05, 0.3, 1.0).normalize(),
        angle_offsets_rad: [0.01, -0.02],
    }
}

#[test]
fn head_jacobian_matches_central_differences_at_random_errors() {
    let mut u = Uniform(0x9e37_79b9_7f4a_7c15);
    for nominal in [Machine::paper().head, oblique_head()] {
        let set = HeadParameterSet::head13(&nominal);
        for _ in 0..50 {
            let p = random_head_errors(&mut u);
            let h = [std::f64::consts::PI * u.next(), 1.2 * u.next()];
            let effector = Effector {
                extension_mm: 100.0 * (u.next() + 1.0),
                offset_mm: Vector3::new(u.next(), u.next(), 30.0 * u.next()),
            };
            let (point, jac) = set.at(&p).point_jacobian(h, &effector);
            // The point agrees with the kinematics crate's own head.
            let head = set.head_at(&p);
            let direct = head.spindle_point(
                h,
                &(head.tool_tip_mm
                    + head.tool_direction * effector.extension_mm
                    + effector.offset_mm),
            );
            assert!((point - direct).norm() < 1e-10);
            for j in 0..N_HEAD {
                let step = if set.names()[j].ends_with("_rad") {
                    1e-6
                } else {
                    1e-4
                };
                let eval = |s: f64| {
                    let mut q = p.clone();
                    q[j] += s;
                    set.at(&q).point_jacobian(h, &effector).0
                };
                let fd = (eval(step) - eval(-step)) / (2.0 * step);
                let err = (fd - jac.column(j)).norm() / jac.column(j).norm().max(1.0);
                assert!(err < 1e-7, "{}: {err:e}", set.names()[j]);
            }
        }
    }
}

#[test]
fn module_point_jacobian_matches_the_exact_tool_forward_kinematics() {
    let mut u = Uniform(7);
    for order in [AxisOrder::XFirst, AxisOrder::YFirst] {
        let m = Machine::paper().with_axis_order(order);
        for _ in 0..10 {
            let r = Vector3::new(300.0 * u.next(), 300.0 * u.next(), 750.0 + 90.0 * u.next());
            let h = [3.0 * u.next(), u.next()];
            let ik = m.inverse(&r).unwrap();
            let geometry = m.legs_at(&ik.up);
            let tip = m.tool_forward(&ik.up, h).tip_mm;
            let analytic = point_error_jacobian(&geometry, &tip).unwrap();
            let step = 1e-3;
            for k in 0..N_FULL {
                let reached = |s: f64| {
                    let mut e = [0.0; N_FULL];
                    e[k] = s;
                    let actual = actual_machine(&m, &GeometricErrors::from_array(&e));
                    let up = actual.forward_from(&ik.legs_mm, &ik.up).unwrap().up;
                    actual.tool_forward(&up, h).tip_mm
                };
                let fd = (reached(step) - reached(-step)) / (2.0 * step);
                let err = (fd - analytic.column(k)).norm();
                assert!(err < 1e-6, "{order} column {k}: {err:e}");
            }
        }
    }
}

#[test]
fn the_two_left_out_coordinates_are_the_angle_zeros() {
    let nominal = Machine::paper().head;
    let set = HeadParameterSet::head13(&nominal);
    let delta = 2e-3;
    let mut p = vec![0.0; N_HEAD];
    p[set.index_of("h1_zero_rad").unwrap()] = delta;
    let with_zero = set.head_at(&p);
    // Everything after joint 1 turned about line 1 by delta.
    let turn =
        nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(nominal.axis1), delta);
    let about = |x: Vector3<f64>| nominal.axis1_point_mm + turn * (x - nominal.axis1_point_mm);
    let turned = Head {
        axis2: turn * nominal.axis2,
        axis2_point_mm: about(nominal.axis2_point_mm),
        tool_tip_mm: about(nominal.tool_tip_mm),
        tool_direction: turn * nominal.tool_direction,
        ..nominal.clone()
    };
    let mut u = Uniform(3);
    for _ in 0..100 {
        let h = [3.0 * u.next(), 1.5 * u.next()];
        let a = with_zero.tool_in_platform(h);
        let b = turned.tool_in_platform(h);
        assert!((a.tip_mm - b.tip_mm).norm() < 1e-12);
        assert!((a.axis - b.axis).norm() < 1e-15);
    }
    // A zero of h2 moves the tip like a tool-tip shift k2 x (t - p2) delta,
    // to second order in delta.
    let mut p = vec![0.0; N_HEAD];
    p[set.index_of("h2_zero_rad").unwrap()] = delta;
    let with_zero = set.head_at(&p);
    let shift = nominal
        .axis2
        .cross(&(nominal.tool_tip_mm - nominal.axis2_point_mm))
        * delta;
    let shifted = Head {
        tool_tip_mm: nominal.tool_tip_mm + shift,
        ..nominal.clone()
    };
    let second_order = 0.5 * delta * delta * (nominal.tool_tip_mm - nominal.axis2_point_mm).norm();
    for _ in 0..100 {
        let h = [3.0 * u.next(), 1.5 * u.next()];
        let d = (with_zero.tool_in_platform(h).tip_mm - shifted.tool_in_platform(h).tip_mm).norm();
        assert!(d <= 1.01 * second_order, "{d:e} vs {second_order:e}");
    }
}
