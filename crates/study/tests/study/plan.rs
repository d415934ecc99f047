//! Planning external measurements: the planned set beats random sets of
//! the same size, the predicted accuracy never gets worse with more
//! measurements, and the prediction agrees with the covariance of the
//! fused identification run on data simulated at the planned poses.

use nalgebra::{Isometry3, Vector3};
use tricept_engine::fusion::{
    FusedModel, FusionOptions, Source, TrackerOptions, TrackerTarget, head_angle_poses,
    identify_fused,
};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant, instruments::Tracker, random_head_errors};
use tricept_study::plan::{
    PlanProblem, candidate_rows, internal_factor, nominal_tracker_data, plan, with_extensions,
};

fn known_target() -> TrackerOptions {
    TrackerOptions {
        sigma_um: 10.0,
        target: TrackerTarget::Known {
            offset_mm: [0.0; 3],
            sigma_um: 5.0,
        },
    }
}

#[test]
fn planned_tracker_points_beat_random_ones_and_predict_the_fit() {
    let m = Machine::paper();
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true).unwrap();
    let f_int = internal_factor(&model, &m.workspace.polar_grid(3, 8, 3)).unwrap();
    let candidates = head_angle_poses(
        &m,
        &m.workspace.polar_grid(2, 8, 3),
        &[0.0, 60.0, 120.0, 180.0, 240.0, 300.0],
        &[-45.0, -25.0, 25.0, 45.0],
    );
    let data = nominal_tracker_data(&model, &with_extensions(&candidates, &[0.0])).unwrap();
    let rows = candidate_rows(&model, &Source::tracker(&data, &known_target()).unwrap()).unwrap();
    let options = FusionOptions::for_machine(&m);
    let problem = PlanProblem::new(&model, &f_int, &rows, &options.eval_poses).unwrap();
    let result = plan(&problem, &[5, 12, 30], 3, 50, 1).unwrap();
    assert!(result.internal_only_um < result.prior_only_um);
    let mut previous = result.internal_only_um;
    for row in &result.rows {
        let random = row.random_median_um.unwrap();
        assert!(
            row.planned_um <= random,
            "k {}: planned {} vs random {random}",
            row.k,
            row.planned_um
        );
        assert!(
            row.planned_um <= previous,
            "k {}: {} after {previous}",
            row.k,
            row.planned_um
        );
        previous = row.planned_um;
    }
    // The prediction at k = 30 against the fit on simulated data at the
    // planned poses: the fit's covariance is that of the linear estimator.
    let planned = &result.rows[2];
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&set.table2()));
    plant.head_errors = random_head_errors(1.0, 3);
    let internal_data = plant.simulate(&Campaign::grid(&m, 1)).unwrap();
    let tracker = Tracker {
        frame: Isometry3::translation(1500.0, 200.0, 100.0),
        target_offset_mm: Vector3::zeros(),
        sigma_um: 10.0,
        setup: 1,
    };
    let poses: Vec<_> = planned
        .selection
        .iter()
        .map(|&c| (candidates[c], 0.0))
        .collect();
    let measured = tracker.measure(&plant, &poses, 2).unwrap();
    let fit = identify_fused(
        &model,
        &[
            Source::internal(&internal_data, m.sensors.logged_sigma()),
            Source::tracker(&measured, &known_target()).unwrap(),
        ],
        &options,
    )
    .unwrap();
    let fitted = fit.report.tool_tip.touch_off_rms_um;
    assert!(
        (planned.planned_um / fitted - 1.0).abs() < 0.1,
        "planned {} um vs fit {fitted} um",
        planned.planned_um
    );
    // The redundancy the plan predicts is the fit's (taken at the estimate
    // instead of the nominal machine).
    let tracker = &fit.sources[1];
    assert!(
        (planned.redundancy - tracker.redundancy).abs() < 0.05 * tracker.redundancy,
        "planned redundancy {} vs fit {}",
        planned.redundancy,
        tracker.redundancy
    );
    // Five planned points reach 25 um but cannot be checked; the
    // recommendation is the smallest checkable k that reaches it.
    let five = &result.rows[0];
    assert!(five.planned_um < 25.0 && !five.checkable, "{five:?}");
    let k = result.recommended(Some(25.0), None).unwrap();
    assert!(k > 5 && result.rows.iter().any(|r| r.k == k && r.checkable));
}
