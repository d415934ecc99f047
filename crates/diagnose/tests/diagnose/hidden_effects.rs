//! Hide an effect in simulated data and require the diagnosis to find it.
//!
//! For every effect of the vocabulary: 20 seeded datasets, each with random
//! geometric errors (uniform in ±0.5 mm on the 15 parameters), a random
//! magnitude drawn from the stated range (which starts at the realistic
//! magnitude of each effect), and a random pose set. Expectations come from
//! the simulator's inputs only: which effect was hidden and with which
//! parameters.
//!
//! Campaign (see `docs/diagnosis.md` for the detectability analysis that
//! chose it): 100 random poses, each visited from both approach directions
//! (200 logged poses), temperature logged; every logged value the mean of
//! 60 readings, except encoder eccentricity (2000) and tube twist (6000),
//! whose realistic magnitudes the default campaign can neither detect nor,
//! by halving the residual, correct. (The same information as 200 poses
//! with half the readings, at half the cost; the realistic campaigns are
//! in `realistic.rs` and `out_of_vocabulary.rs`.)

use crate::common::true_parameters;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_diagnose::{DiagnoseOptions, Diagnosis, diagnose};
use tricept_kinematics::Machine;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_model::ParameterSet;
use tricept_model::effects::{EffectName as E, stiffness_for_platform_deflection};
use tricept_plant::effects::Effect;
use tricept_plant::{Campaign, Plant, campaign::PoseOrder, random_errors};

/// An effect of random magnitude from the stated range.
pub(crate) fn hidden(e: E, rng: &mut Pcg64Mcg, m: &Machine) -> Effect {
    let mut sign = || if rng.random::<bool>() { 1.0 } else { -1.0 };
    let s: [f64; 4] = std::array::from_fn(|_| sign());
    let mut u = |a: f64, b: f64| a + (b - a) * rng.random::<f64>();
    match e {
        // Realistic: 50 ppm, 5 um, 2 K, 50 ppm, 5 arcsec, 30 arcsec or
        // 20 um, 30 arcsec over the stroke, 10 um at the platform.
        E::LegLead => Effect::from(tricept_plant::effects::LegLead {
            ppm: [
                s[0] * u(50.0, 150.0),
                s[1] * u(50.0, 150.0),
                s[2] * u(50.0, 150.0),
            ],
        }),
        E::Backlash => Effect::from(tricept_plant::effects::Backlash {
            um: [u(5.0, 15.0), u(5.0, 15.0), u(5.0, 15.0)],
        }),
        E::Thermal => Effect::from(tricept_plant::effects::Thermal {
            drift_k: s[0] * u(2.0, 5.0),
            expansion_ppm_per_k: 11.5,
        }),
        E::ScaleGain => Effect::from(tricept_plant::effects::ScaleGain {
            ppm: s[0] * u(50.0, 150.0),
        }),
        E::EncoderEccentricity => Effect::from(tricept_plant::effects::EncoderEccentricity {
            phi_arcsec: u(5.0, 15.0),
            phi_phase_deg: u(0.0, 360.0),
            theta_arcsec: u(5.0, 15.0),
            theta_phase_deg: u(0.0, 360.0),
        }),
        E::UjointAxes => {
            if s[2] > 0.0 {
                Effect::from(tricept_plant::effects::UjointAxes {
                    skew_arcsec: s[0] * u(30.0, 90.0),
                    offset_um: 0.0,
                })
            } else {
                Effect::from(tricept_plant::effects::UjointAxes {
                    skew_arcsec: 0.0,
                    offset_um: s[1] * u(20.0, 60.0),
                })
            }
        }
        // Over the workspace's stroke of the UP limb (650 to 940 mm).
        E::TubeTwist => Effect::from(tricept_plant::effects::TubeTwist {
            arcsec_per_100mm: s[0] * u(30.0, 90.0) / 2.9,
        }),
        E::Compliance => Effect::from(tricept_plant::effects::Compliance {
            stiffness_n_per_um_at_1m: stiffness_for_platform_deflection(m, u(10.0, 30.0)),
        }),
        E::Outliers => Effect::from(tricept_plant::effects::Outliers {
            count: 2 + (u(0.0, 3.999) as usize),
            size_sigma: u(300.0, 3000.0),
        }),
    }
}

fn readings_per_pose(effects: &[E]) -> u32 {
    if effects.contains(&E::TubeTwist) {
        6000
    } else if effects.contains(&E::EncoderEccentricity) {
        2000
    } else {
        60
    }
}

/// Simulates and diagnoses one dataset with `effects` hidden.
fn run(effects: &[E], seed: u64, readings: u32) -> (Diagnosis, Vec<Effect>) {
    let (data, sigma, effects) = campaign(effects, seed, 100, PoseOrder::BothDirections, readings);
    let m = Machine::paper();
    let mut options = DiagnoseOptions::for_machine(&m);
    options.sigma = sigma;
    (diagnose(&m, &data, &options).unwrap(), effects)
}

/// A campaign of `poses` random poses in `order` with `effects` hidden
/// (random magnitudes from their stated ranges, random geometric errors
/// uniform in +-0.5 mm, the temperature logged), every logged value the
/// mean of `readings`: the data, the stated noise of a logged value and
/// the hidden effects.
pub(crate) fn campaign(
    effects: &[E],
    seed: u64,
    poses: usize,
    order: PoseOrder,
    readings: u32,
) -> (Dataset, [f64; 3], Vec<Effect>) {
    campaign_with(effects, &[], seed, poses, order, readings)
}

/// As [`campaign`], with `extra` effects of given magnitudes hidden too
/// (after the random ones: the same seed draws the same magnitudes).
pub(crate) fn campaign_with(
    effects: &[E],
    extra: &[Effect],
    seed: u64,
    poses: usize,
    order: PoseOrder,
    readings: u32,
) -> (Dataset, [f64; 3], Vec<Effect>) {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let mut rng = Pcg64Mcg::seed_from_u64(0xd1a6 ^ seed);
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&random_errors(15, 0.5, seed)));
    plant.effects = effects.iter().map(|e| hidden(*e, &mut rng, &m)).collect();
    plant.effects.extend_from_slice(extra);
    let mut campaign = Campaign::random(&m, poses, 7 * seed + 1);
    campaign.noise.readings_per_pose = readings;
    campaign.order = order;
    let data = plant.simulate(&campaign).unwrap();
    (data, campaign.noise.logged_sigma(), plant.effects)
}

/// Whether `effect` is named first, or (for a scale gain, which no
/// campaign of these sensors can tell from an equal lead of the legs) is
/// the model's member of the first alias set.
fn found_first(d: &Diagnosis, effect: E) -> bool {
    d.causes.first().is_some_and(|c| c.effect == effect)
        || (d.causes.is_empty() || d.causes[0].effect == E::Outliers)
            && d.aliases.first().is_some_and(|a| a.in_model == effect)
}

/// Whether `effect` is named or reported in an alias set.
fn found(d: &Diagnosis, effect: E) -> bool {
    d.causes.iter().any(|c| c.effect == effect)
        || d.aliases
            .iter()
            .any(|a| a.effects.iter().any(|e| *e == effect))
}

/// The estimates of `effect`'s parameters in the final model.
fn fitted(d: &Diagnosis, effect: E) -> Vec<tricept_diagnose::report::Estimate> {
    let prefix = format!("{effect}.");
    d.extended
        .iter()
        .filter(|e| e.name.starts_with(&prefix))
        .cloned()
        .collect()
}

/// 20 datasets with `effect` hidden: named first and held-out RMS halved
/// in at least 19; parameters recovered within 5 standard deviations.
fn check_effect(effect: E) {
    let readings = readings_per_pose(&[effect]);
    let (mut first, mut halved) = (0, 0);
    let mut failures = Vec::new();
    // Data sets in parallel, collected in order.
    let runs: Vec<(Diagnosis, Vec<Effect>)> = (0..20)
        .into_par_iter()
        .map(|seed| run(&[effect], 100 + seed, readings))
        .collect();
    for (seed, (d, hidden)) in runs.into_iter().enumerate() {
        let named_first = found_first(&d, effect);
        let ratio = d.gain.holdout_rms_extended / d.gain.holdout_rms_geometric;
        first += usize::from(named_first);
        halved += usize::from(ratio <= 0.5);
        if !named_first || ratio > 0.5 {
            failures.push(format!(
                "seed {seed}: causes {:?}, RMS {:.2} -> {:.2}",
                d.causes.iter().map(|c| c.effect).collect::<Vec<_>>(),
                d.gain.holdout_rms_geometric,
                d.gain.holdout_rms_extended
            ));
        }
        if let (true, Some(truth)) = (named_first, true_parameters(&hidden[0])) {
            if effect == E::Outliers {
                continue;
            }
            for (est, t) in fitted(&d, effect).iter().zip(&truth) {
                let sd = est.std_dev.unwrap_or(f64::INFINITY);
                // The thermal regressor is the logged temperature, whose
                // 0.02 K logger noise (errors in variables, not in the
                // reported sd) attenuates the estimate by a few 0.1 %.
                let slack = if effect == E::Thermal {
                    0.01 * t.abs()
                } else {
                    0.0
                };
                assert!(
                    (est.value - t).abs() <= 5.0 * sd + slack + 1e-9,
                    "{effect} seed {seed}: {} = {} vs true {t} (sd {sd})",
                    est.name,
                    est.value
                );
            }
        }
        if effect == E::Outliers {
            let Some(&tricept_plant::effects::Outliers { count, .. }) = hidden[0].input() else {
                unreachable!()
            };
            let rows = d
                .causes
                .iter()
                .find(|c| c.effect == E::Outliers)
                .map_or(0, |c| c.rows.len());
            assert_eq!(
                rows, count,
                "seed {seed}: {rows} rows flagged for {count} outliers"
            );
        }
    }
    // The tally quoted in docs/diagnosis.md (`-- --nocapture` shows it).
    eprintln!("TALLY {effect}: named first {first}/20, held-out RMS halved {halved}/20");
    assert!(
        first >= 19 && halved >= 19,
        "{effect}: first {first}/20, halved {halved}/20\n{}",
        failures.join("\n")
    );
}

macro_rules! effect_tests {
    ($($name:ident: $effect:expr),* $(,)?) => {$(
        #[test]
        fn $name() {
            check_effect($effect);
        }
    )*};
}

effect_tests! {
    leg_lead_is_found: E::LegLead,
    backlash_is_found: E::Backlash,
    thermal_is_found: E::Thermal,
    scale_gain_is_found: E::ScaleGain,
    encoder_eccentricity_is_found: E::EncoderEccentricity,
    ujoint_axes_are_found: E::UjointAxes,
    tube_twist_is_found: E::TubeTwist,
    compliance_is_found: E::Compliance,
    outliers_are_found: E::Outliers,
}

#[test]
fn data_without_hidden_effects_are_reported_adequate() {
    let mut adequate = 0;
    let mut named = Vec::new();
    let runs: Vec<(Diagnosis, Vec<Effect>)> = (0..40)
        .into_par_iter()
        .map(|seed| run(&[], 500 + seed, 3))
        .collect();
    for (seed, (d, _)) in runs.into_iter().enumerate() {
        if d.adequate {
            adequate += 1;
        } else {
            named.push((seed, d.causes.iter().map(|c| c.effect).collect::<Vec<_>>()));
        }
    }
    eprintln!("TALLY no hidden effect: adequate {adequate}/40");
    assert!(
        adequate >= 38,
        "{adequate}/40 adequate; false causes: {named:?}"
    );
}

/// Both effects of each pair found in at least 16 of 20 datasets.
fn check_pairs(pairs: &[(E, E)]) {
    for &(a, b) in pairs {
        let readings = readings_per_pose(&[a, b]);
        let both = (0..20)
            .into_par_iter()
            .filter(|seed| {
                let (d, _) = run(&[a, b], 900 + seed, readings);
                found(&d, a) && found(&d, b)
            })
            .count();
        eprintln!("TALLY {a} + {b}: both found {both}/20");
        assert!(both >= 16, "{a} + {b}: both found in {both}/20");
    }
}

#[test]
fn pairs_of_effects_are_both_found() {
    check_pairs(&[
        (E::LegLead, E::Backlash),
        (E::Thermal, E::ScaleGain),
        (E::UjointAxes, E::Compliance),
        (E::EncoderEccentricity, E::TubeTwist),
    ]);
}

#[test]
fn more_pairs_of_effects_are_both_found() {
    check_pairs(&[
        (E::Outliers, E::LegLead),
        (E::Compliance, E::Thermal),
        (E::Backlash, E::TubeTwist),
        (E::ScaleGain, E::EncoderEccentricity),
    ]);
}

#[test]
fn the_report_names_the_evidence_and_the_bias() {
    let (d, hidden) = run(&[E::ScaleGain], 7, 60);
    let json = d.to_json();
    assert_eq!(json["adequate"], false);
    assert_eq!(json["final_adequate"], true);
    // A scale gain is never named alone: it is reported with the equal
    // lead of the legs that reads exactly like it.
    assert_eq!(json["causes"].as_array().map(Vec::len), Some(0));
    assert_eq!(json["aliases"][0]["effects"][0], "scale-gain");
    assert_eq!(json["aliases"][0]["effects"][1], "leg-lead");
    assert_eq!(json["aliases"][0]["exact"], true);
    assert!(
        json["aliases"][0]["separate_by"]
            .as_str()
            .unwrap()
            .contains("external length")
    );
    assert!(
        json["gain"]["holdout_rms_geometric"].as_f64().unwrap()
            > 2.0 * json["gain"]["holdout_rms_extended"].as_f64().unwrap()
    );
    let Some(tricept_plant::effects::ScaleGain { ppm }) = hidden[0].input() else {
        unreachable!()
    };
    let est = json["extended"]["scale-gain.scale_gain_ppm"]["value"]
        .as_f64()
        .unwrap();
    assert!((est - ppm).abs() < 0.05 * ppm.abs(), "{est} vs {ppm}");
    // An unmodelled scale gain drags the geometric parameters: the report
    // says by how much (the largest shift is at least a micrometre).
    let largest = d
        .geometric_bias
        .iter()
        .map(|(_, v)| v.abs())
        .fold(0.0, f64::max);
    assert!(largest > 1e-3, "{largest}");
    // The model's member of the alias set is plotted.
    assert!(!d.plots.is_empty() && !d.plots[0].before.is_empty());
    let _ = RAD_PER_ARCSEC;
}

/// Not a check (ignored; a finding recorded in docs/testing.md): the
/// causes named beyond the hidden ones in short campaigns (60 poses in one
/// direction, every logged value the mean of 60 readings) with a thermal
/// drift, tallied over four pose sets. Run with `cargo test -p
/// tricept-diagnose --test diagnose -- --ignored --nocapture
/// short_campaigns`.
#[test]
#[ignore]
fn short_campaigns_with_a_thermal_drift_tally_their_extra_causes() {
    let cases: [&[E]; 4] = [
        &[E::Thermal],
        &[E::Thermal, E::LegLead],
        &[E::Thermal, E::Backlash],
        &[E::Thermal, E::LegLead, E::Backlash],
    ];
    for hidden in cases {
        let extra: Vec<String> = (0..4)
            .into_par_iter()
            .map(|k| {
                let seed = 900 + k;
                let (data, sigma, _) = campaign(hidden, seed, 60, PoseOrder::AsGiven, 60);
                let m = Machine::paper();
                let mut options = DiagnoseOptions::for_machine(&m);
                options.sigma = sigma;
                let d = diagnose(&m, &data, &options).unwrap();
                let beyond: Vec<String> = d
                    .causes
                    .iter()
                    .filter(|c| !c.effect.catalogue().is_some_and(|e| hidden.contains(&e)))
                    .map(|c| c.effect.to_string())
                    .collect();
                format!("seed {seed}: {beyond:?}")
            })
            .collect();
        eprintln!("TALLY {hidden:?}: {}", extra.join("; "));
    }
}
