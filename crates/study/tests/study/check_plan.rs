//! A planned check detects what its plan says it detects: on the planned
//! poses, a change of a leg of the planned detectable size is found with
//! about the planned power, and a smaller one is missed more often.

use tricept_check::{CheckOptions, Reference, check};
use tricept_engine::{IdentifyOptions, identify, model::GeometricModel};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant, random_errors};
use tricept_study::check_plan::plan_check;

#[test]
fn a_planned_check_detects_its_detectable_change_with_its_power() {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let truth = random_errors(15, 0.25, 3);
    let plant = Plant::geometric(m.clone(), set.to_errors(&truth));
    let data = plant.simulate(&Campaign::random(&m, 80, 3)).unwrap();
    let model = GeometricModel::new(m.clone(), set.clone());
    let id = identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
    let reference = Reference::new(
        model.machine_at(&id.estimate),
        set,
        id.covariance.clone(),
        id.offsets,
        None,
    )
    .unwrap();
    let plan = plan_check(&reference, 20.0, 0.95, 0.01, 20).unwrap();
    assert_eq!(plan.poses, 20);
    let dq2 = plan.parameters.iter().find(|p| p.name == "dq2").unwrap();
    let size = dq2.detectable_mm.unwrap();
    let rate = |size_mm: f64| {
        let mut found = 0;
        for seed in 0..20u64 {
            let mut p = plant.clone();
            p.errors.dq_mm[1] += size_mm;
            let c = Campaign::from_targets(&m, plan.targets_mm.clone(), 700 + seed);
            let r = check(
                &reference,
                &p.simulate(&c).unwrap(),
                &CheckOptions::for_machine(&m),
            )
            .unwrap();
            found += usize::from(r.changed);
        }
        found
    };
    let (at_size, at_half) = (rate(size), rate(0.5 * size));
    eprintln!(
        "TALLY check plan: 20 planned poses detect dq2 = {:.1} um (platform {:.1} um) in {at_size}/20, half of it in {at_half}/20",
        size * 1e3,
        dq2.detectable_platform_um.unwrap()
    );
    // The planned power is 0.95 for the parameter alone; the check tests
    // every candidate, which can only help.
    assert!(at_size >= 17, "{at_size}/20");
    assert!(at_half < at_size, "{at_half} vs {at_size}");
}
