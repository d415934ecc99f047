//! Property tests over the whole workspace: FK inverts IK, the tool-pose IK
//! round-trips, for both U-joint conventions and with class-2 errors.

use nalgebra::Vector3;
use proptest::prelude::*;
use tricept_kinematics::{
    Machine, description::AxisOrder, head::HeadBranch, up_limb::UpLimb, workspace::box_lattice,
};

fn machines() -> Vec<Machine> {
    let paper = Machine::paper();
    let y_first = paper.clone().with_axis_order(AxisOrder::YFirst);
    let mut class2 = paper.clone();
    class2.up_limb = UpLimb {
        axis_order: AxisOrder::XFirst,
        axis_skew_rad: 1.5e-4,
        axis_offset_mm: 0.02,
        twist_rad_per_mm: 5e-7,
        twist_reference_mm: 750.0,
    };
    vec![paper, y_first, class2]
}

/// A point anywhere in the workspace cylinder.
fn workspace_point() -> impl Strategy<Value = Vector3<f64>> {
    (0.0..1.0f64, 0.0..std::f64::consts::TAU, 650.0..=850.0f64).prop_map(|(u, a, z)| {
        let rad = 400.0 * u.sqrt();
        Vector3::new(rad * a.cos(), rad * a.sin(), z)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn fk_inverts_ik_to_1e_9_mm(r in workspace_point()) {
        for m in machines() {
            let ik = m.inverse(&r).unwrap();
            let fk = m.forward(&ik.legs_mm).unwrap();
            prop_assert!((fk.position_mm - r).norm() < 1e-9,
                "{:?}: {} vs {}", m.up_limb, fk.position_mm, r);
            prop_assert!((fk.up.phi_rad - ik.up.phi_rad).abs() < 1e-12);
            prop_assert!((fk.up.theta_rad - ik.up.theta_rad).abs() < 1e-12);
            prop_assert!(fk.condition.is_finite() && fk.condition < 100.0);
        }
    }

    #[test]
    fn tool_pose_ik_round_trips(
        r in workspace_point(),
        tilt in 0.0..0.5f64,
        azimuth in 0.0..std::f64::consts::TAU,
    ) {
        for m in machines() {
            // A tool pose that a platform point in the workspace can reach.
            let up = m.up_limb.inverse(&r).unwrap();
            let axis = Vector3::new(tilt.sin() * azimuth.cos(), tilt.sin() * azimuth.sin(), tilt.cos());
            let tip = r + m.up_limb.pose(&up).rotation * Vector3::new(0.0, 0.0, 150.0) + 200.0 * axis;
            let sol = m.tool_inverse(&tip, &axis, HeadBranch::default()).unwrap();
            let back = m.tool_forward(&sol.up, sol.head_rad);
            prop_assert!((back.tip_mm - tip).norm() < 1e-9, "tip {} vs {}", back.tip_mm, tip);
            prop_assert!((back.axis - axis).norm() < 1e-12);
            prop_assert!(sol.head_rad[1] >= 0.0 || sol.head_singular);
            // The legs it returns drive the platform where the solver says.
            let fk = m.forward(&sol.legs_mm).unwrap();
            prop_assert!((fk.position_mm - sol.platform_mm).norm() < 1e-9);
        }
    }

    #[test]
    fn nearest_branch_is_the_other_solution(r in workspace_point(), tilt in 0.05..0.5f64) {
        let m = Machine::paper();
        let up = m.up_limb.inverse(&r).unwrap();
        let axis = Vector3::new(tilt.sin(), 0.0, tilt.cos());
        let tip = r + m.up_limb.pose(&up).rotation * Vector3::new(0.0, 0.0, 150.0) + 200.0 * axis;
        let a = m.tool_inverse(&tip, &axis, HeadBranch::PositiveSecondAxis).unwrap();
        let flipped = [a.head_rad[0] + std::f64::consts::PI, -a.head_rad[1]];
        let b = m.tool_inverse(&tip, &axis, HeadBranch::Nearest(flipped)).unwrap();
        let back = m.tool_forward(&b.up, b.head_rad);
        prop_assert!((back.tip_mm - tip).norm() < 1e-9);
        prop_assert!(b.head_rad[1] <= 0.0);
    }
}

#[test]
fn fk_beyond_the_workspace_edges_either_solves_exactly_or_says_why() {
    // Sweep well past the workspace: every answer is either exact or an error.
    for m in machines() {
        let mut solved = 0;
        let mut refused = 0;
        for i in -8..=8 {
            for j in -8..=8 {
                for z in [300.0, 600.0, 900.0, 1200.0] {
                    let r = Vector3::new(100.0 * f64::from(i), 100.0 * f64::from(j), z);
                    match m.inverse(&r) {
                        Ok(ik) => {
                            let fk = m.forward(&ik.legs_mm).unwrap();
                            assert!((fk.position_mm - r).norm() < 1e-8, "{r}");
                            solved += 1;
                        }
                        Err(_) => refused += 1,
                    }
                }
            }
        }
        assert!(solved > 150 && refused > 300, "{solved} {refused}");
    }
}

/// The 50 mm lattice out to 1000 mm radius, z from 300 to 1300 mm (also
/// swept by `examples/fk_seeds.rs`).
fn far_lattice() -> Vec<Vector3<f64>> {
    box_lattice(
        Vector3::new(-1000.0, -1000.0, 300.0),
        Vector3::new(1000.0, 1000.0, 1300.0),
        50.0,
    )
}

#[test]
fn fk_recovers_every_configuration_ik_reaches_far_beyond_the_workspace() {
    // A 50 mm lattice out to 1000 mm radius and z from 300 to 1300 mm:
    // wherever IK gives commands, cold-start FK must return that very point
    // (not an error, not the other assembly branch).
    for m in machines() {
        let (mut solved, mut failed) = (0, Vec::new());
        for r in far_lattice() {
            let Ok(ik) = m.inverse(&r) else { continue };
            match m.forward(&ik.legs_mm) {
                Ok(fk) if (fk.position_mm - r).norm() < 1e-8 => solved += 1,
                other => failed.push((r, other.map(|fk| fk.position_mm))),
            }
        }
        assert!(
            failed.is_empty(),
            "{} of {}: {:?}",
            failed.len(),
            solved + failed.len(),
            &failed[..failed.len().min(3)]
        );
        assert!(solved > 4000, "{solved}");
    }
}

#[test]
fn fk_of_arbitrary_leg_commands_is_exact_or_an_error() {
    // Leg commands over the whole stroke, most of them inconsistent.
    let m = Machine::paper();
    let (mut solved, mut refused) = (0, 0);
    let steps: Vec<f64> = (0..=16).map(|k| 450.0 + 50.0 * f64::from(k)).collect();
    for &q1 in &steps {
        for &q2 in &steps {
            for &q3 in &steps {
                match m.forward(&[q1, q2, q3]) {
                    Ok(fk) => {
                        let ik = m.inverse(&fk.position_mm).unwrap();
                        for (a, b) in ik.legs_mm.iter().zip([q1, q2, q3]) {
                            assert!((a - b).abs() < 1e-8, "{q1} {q2} {q3}");
                        }
                        solved += 1;
                    }
                    Err(_) => refused += 1,
                }
            }
        }
    }
    assert!(solved > 100 && refused > 100, "{solved} {refused}");
}
