//! The rule for the invisible platform joint (`tricept_study::invisible`),
//! stated from the geometry alone, against what the identification sees:
//! the identifiability report's rank and unidentifiable combinations, and
//! the exact model's readings.

use tricept_engine::{IdentifyOptions, identify::identifiability, model::GeometricModel};
use tricept_kinematics::{
    Machine, MachineDescription, description::AxisOrder, description::Placement,
};
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant};
use tricept_study::invisible::invisible_platform_errors;

fn placed(angles_deg: [f64; 3], order: AxisOrder) -> Machine {
    let mut d = MachineDescription::paper();
    let Placement::Circular(c) = &mut d.placement else {
        unreachable!("the paper's machine has a circular placement")
    };
    c.joint_angles_deg = angles_deg;
    d.up_limb.axis_order = order;
    d.build().unwrap()
}

/// Placements with a base joint on base x, on base y, and on neither.
const PLACEMENTS: [[f64; 3]; 4] = [
    [120.0, 240.0, 0.0],
    [0.0, 120.0, 240.0],
    [90.0, 210.0, 330.0],
    [30.0, 150.0, 270.0],
];

#[test]
fn the_rule_names_exactly_the_platform_errors_the_report_cannot_see() {
    let set = ParameterSet::full21();
    let mut predicted = 0;
    for angles in PLACEMENTS {
        for order in [AxisOrder::XFirst, AxisOrder::YFirst] {
            let m = placed(angles, order);
            let mut rule: Vec<String> = invisible_platform_errors(&m)
                .into_iter()
                .map(|e| e.parameter)
                .collect();
            rule.sort();
            predicted += rule.len();
            let poses: Vec<tricept_data::MeasuredPose> = m
                .workspace
                .polar_grid(1, 8, 3)
                .iter()
                .map(|r| tricept_data::MeasuredPose {
                    commands_mm: m.inverse(r).unwrap().legs_mm,
                    ..Default::default()
                })
                .collect();
            let model = GeometricModel::new(m.clone(), set.clone());
            let report = identifiability(
                &model,
                &[0.0; 21],
                &poses,
                &IdentifyOptions::for_machine(&m),
            )
            .unwrap();
            // The two rigid-body gauges of the 21 parameters (a rotation of
            // the base about the fixed axis, O' sliding along the limb) plus
            // one per invisible platform error.
            assert_eq!(report.rank, 21 - 2 - rule.len(), "{angles:?} {order}");
            let mut alone: Vec<String> = report
                .unidentifiable
                .iter()
                .filter(|c| c.terms.iter().skip(1).all(|(_, v)| v.abs() < 1e-6))
                .map(|c| c.terms[0].0.clone())
                .filter(|n| n.contains('A'))
                .collect();
            alone.sort();
            assert_eq!(alone, rule, "{angles:?} {order}");
        }
    }
    // Not vacuous: x-first loses a joint at 0 degrees twice, y-first at 90
    // or 270 degrees twice.
    assert_eq!(predicted, 4);
}

#[test]
fn an_invisible_error_moves_the_exact_readings_only_at_second_order() {
    // Exact, noise-free readings with one error of size e, against the
    // nominal machine's: halving e quarters the change of a second-order
    // effect and halves that of a first-order one (the other in-plane
    // coordinate of the same joint).
    for (angles, order) in [
        ([120.0, 240.0, 0.0], AxisOrder::XFirst),
        ([30.0, 150.0, 270.0], AxisOrder::YFirst),
    ] {
        let m = placed(angles, order);
        let set = ParameterSet::full21();
        let campaign = Campaign::from_targets(&m, m.workspace.polar_grid(1, 8, 3), 0);
        let readings = |p: &[f64]| -> Vec<[f64; 3]> {
            Plant::geometric(m.clone(), set.to_errors(p))
                .true_poses(&campaign)
                .unwrap()
                .iter()
                .map(|t| t.readings.to_array())
                .collect()
        };
        let nominal = readings(&[0.0; 21]);
        // Largest change of any reading, as a displacement of O' (angles
        // times the 750 mm mid-workspace lever), mm; the offsets are the
        // same in both, so differences are the error's effect alone.
        let change = |name: &str, e_mm: f64| -> f64 {
            let mut p = [0.0; 21];
            p[set.index_of(name).unwrap()] = e_mm;
            readings(&p)
                .iter()
                .zip(&nominal)
                .flat_map(|(a, b)| [750.0 * (a[0] - b[0]), 750.0 * (a[1] - b[1]), a[2] - b[2]])
                .fold(0.0, |acc: f64, d| acc.max(d.abs()))
        };
        let lost = invisible_platform_errors(&m);
        assert_eq!(lost.len(), 1, "{angles:?} {order}");
        for e in lost {
            let other = if e.parameter.starts_with("dy") {
                format!("dxA{}", e.leg)
            } else {
                format!("dyA{}", e.leg)
            };
            let (invisible, visible) = (change(&e.parameter, 0.5), change(&other, 0.5));
            let invisible_order = invisible / change(&e.parameter, 0.25);
            let visible_order = visible / change(&other, 0.25);
            assert!(
                (3.8..4.2).contains(&invisible_order) && (1.9..2.1).contains(&visible_order),
                "{order}: halving {} divides its effect by {invisible_order:.3}, {other} by {visible_order:.3}",
                e.parameter
            );
            assert!(
                invisible < 0.01 * visible,
                "{order}: {} moves the readings by {invisible:.2e} mm, {other} by {visible:.2e} mm",
                e.parameter
            );
        }
    }
}
