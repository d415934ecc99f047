//! Bit-identical simulation across refactors: for every effect the
//! simulator knows (its typical example), and for all of them at once, a
//! simulated campaign (readings, logged temperature, approach directions)
//! and the actual spindle point at a few commands are compared bit for bit
//! with `tests/fixtures/pinned_campaigns.json`.
//!
//! The fixture was written by the plant of commit 0107a78, before the
//! plant's `Effect` enum was replaced by the registry's simulation hooks
//! (the values are the frozen old code's output, not the code under test's):
//! the effects are read back from their JSON in the fixture, so the
//! `--truth-effect` format is pinned too. To write it again (only when a
//! change of the simulated data is intended), run with
//! `TRICEPT_BLESS_PINNED=1`.

use nalgebra::Vector3;
use serde_json::{Value, json};
use tricept_kinematics::Machine;
use tricept_model::{ParameterSet, head_errors::Effector};
use tricept_plant::effects::typical_effects;
use tricept_plant::{Campaign, Effect, Plant, random_errors, random_head_errors};

const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/pinned_campaigns.json"
);

fn bits(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

/// The simulated values of one case, as bit patterns.
fn simulate(effects: Vec<Effect>) -> Value {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&random_errors(15, 0.5, 21)));
    plant.head_errors = random_head_errors(1.0, 5);
    plant.effects = effects;
    let mut campaign = Campaign::random(&m, 18, 17);
    campaign.revisits = 3;
    let data = plant.simulate(&campaign).unwrap();
    let readings: Vec<String> = data
        .poses
        .iter()
        .flat_map(|p| p.readings.to_array())
        .map(bits)
        .collect();
    let temps: Vec<String> = data.poses.iter().map(|p| bits(p.temp_c.unwrap())).collect();
    let approach: Vec<[i8; 3]> = data.poses.iter().map(|p| p.approach.unwrap()).collect();
    let mut spindle = Vec::new();
    for r in [
        Vector3::new(0.0, 0.0, 750.0),
        Vector3::new(120.0, -80.0, 700.0),
    ] {
        let ik = m.inverse(&r).unwrap();
        let p = plant
            .spindle_point(&ik.legs_mm, [0.1, -0.2], &Effector::default())
            .unwrap();
        spindle.extend(p.iter().copied().map(bits));
        spindle.extend(plant.reach(&ik.legs_mm).unwrap().iter().copied().map(bits));
    }
    json!({"readings": readings, "temp_c": temps, "approach": approach, "spindle": spindle})
}

fn cases() -> Vec<(Value, Vec<Effect>)> {
    let all = typical_effects();
    let mut v: Vec<(Value, Vec<Effect>)> = all
        .iter()
        .map(|e| (serde_json::to_value(e).unwrap(), vec![e.clone()]))
        .collect();
    v.push((serde_json::to_value(&all).unwrap(), all));
    v
}

#[test]
fn every_effect_simulates_the_pinned_bits() {
    if std::env::var_os("TRICEPT_BLESS_PINNED").is_some() {
        let out: Vec<Value> = cases()
            .into_iter()
            .map(|(effects, list)| json!({"effects": effects, "simulated": simulate(list)}))
            .collect();
        std::fs::write(FIXTURE, serde_json::to_string_pretty(&out).unwrap()).unwrap();
        return;
    }
    let text = std::fs::read_to_string(FIXTURE).unwrap();
    let pinned: Vec<Value> = serde_json::from_str(&text).unwrap();
    assert_eq!(pinned.len(), typical_effects().len() + 1);
    for case in &pinned {
        let json = &case["effects"];
        let effects: Vec<Effect> = match json {
            Value::Array(a) => a
                .iter()
                .map(|e| serde_json::from_value(e.clone()).unwrap())
                .collect(),
            e => vec![serde_json::from_value(e.clone()).unwrap()],
        };
        // The JSON format round-trips exactly.
        let back: Vec<Value> = effects
            .iter()
            .map(|e| serde_json::to_value(e).unwrap())
            .collect();
        match json {
            Value::Array(a) => assert_eq!(&back, a),
            e => assert_eq!(&back[0], e),
        }
        assert_eq!(simulate(effects), case["simulated"], "case {json}");
    }
}
