//! Time and temperature confounded: in a campaign whose logged temperature
//! follows its time (the plant's linear 2 K ramp: |r| = 1, beyond
//! `tricept_diagnose::terms::TEMPERATURE_FOLLOWS_TIME`), a thermal
//! growth and a drift with time read alike. The model's temperature terms
//! and time terms then form one alias set, no time term is named as a
//! cause beside a temperature term, and the report says which campaign
//! separates them.

use crate::common::{CampaignOptions, run_case, simulate, tally};
use tricept_model::effects::{CauseName, Needs};
use tricept_plant::effects::Effect;

#[test]
fn temperature_that_follows_time_makes_one_alias_set() {
    // Legs that grow 11.5 ppm/K with the logged ramp, and a scale that
    // drifts with time: both follow the campaign's clock.
    let runs = run_case(10, |seed| {
        simulate(
            80,
            300 + seed,
            vec![
                Effect::from(tricept_plant::effects::Thermal {
                    drift_k: 2.0,
                    expansion_ppm_per_k: 11.5,
                }),
                Effect::from(tricept_plant::effects::ScaleDrift { um: 3.0 }),
            ],
            CampaignOptions::default(),
        )
    });
    let mut both = 0;
    for (seed, (_, d)) in runs.iter().enumerate() {
        let follows = |n: &CauseName, needs: Needs| n.needs() == needs;
        let named_time: Vec<&CauseName> = d
            .causes
            .iter()
            .map(|c| &c.effect)
            .filter(|n| follows(n, Needs::PoseOrder))
            .collect();
        let named_temperature = d
            .causes
            .iter()
            .any(|c| follows(&c.effect, Needs::Temperature));
        let description = d
            .causes
            .iter()
            .map(|c| c.description.clone())
            .collect::<Vec<_>>();
        assert!(
            !named_temperature || named_time.is_empty(),
            "seed {seed}: a time term named beside a temperature term: {description:?}"
        );
        assert!(
            !description
                .iter()
                .any(|t| t.contains("independent of temperature")),
            "{description:?}"
        );
        let in_model = |needs: Needs| d.model_terms.iter().any(|t| follows(&t.effect, needs));
        if in_model(Needs::Temperature) && in_model(Needs::PoseOrder) {
            both += 1;
            let set = d
                .aliases
                .iter()
                .find(|a| {
                    a.effects.iter().any(|n| follows(n, Needs::Temperature))
                        && a.effects.iter().any(|n| follows(n, Needs::PoseOrder))
                })
                .unwrap_or_else(|| panic!("no time/temperature alias set: {:?}", d.aliases));
            assert!(
                set.why.contains("followed the campaign's time"),
                "{}",
                set.why
            );
            assert!(
                set.separate_by.contains("temperature does not follow time"),
                "{}",
                set.separate_by
            );
        }
    }
    tally(
        "time/temperature alias",
        80,
        "models with both a temperature and a time term, reported as one alias set",
        both,
        runs.len(),
    );
}
