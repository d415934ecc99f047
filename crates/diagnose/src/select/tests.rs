//! Unit tests of the selection's rules (the module docs of
//! [`crate::select`]): each expected value is worked by hand from the
//! documented rule (chi-square tails of 2 degrees of freedom by their closed
//! form `exp(-x/2)`), never taken from the code under test.

use std::cmp::Ordering;

use tricept_model::effects::{EffectName, GenericFamily};

use super::*;
use crate::terms::{GenericTerm, Scope};

/// Evidence with the given adjusted p-value and penalised gain (the rest
/// neutral).
fn ev(p_adjusted: f64, penalised_gain: f64) -> Evidence {
    Evidence {
        delta_chi_square: 0.0,
        dof: 1,
        p_value: p_adjusted,
        threshold: 0.0,
        delta_bic: 0.0,
        holdout_rms_without: None,
        holdout_rms_with: None,
        selected: false,
        multiplicity: 1,
        p_adjusted,
        penalised_gain,
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

fn generic(family: GenericFamily, scope: Scope) -> Term {
    Term::Generic(GenericTerm::new(family, scope))
}

fn periodic(leg: u8, period_mm: f64) -> Term {
    Term::Generic(GenericTerm {
        period_mm: Some(period_mm),
        ..GenericTerm::new(GenericFamily::LegPeriodic, Scope::Leg(leg))
    })
}

#[test]
fn three_readings_a_pose() {
    assert_eq!(readings_of(40), 120);
    assert_eq!(readings_of(1), 3);
    assert_eq!(readings_of(0), 0);
}

#[test]
fn alpha_is_split_between_the_halves_of_the_pool() {
    // alpha / 2 each for the catalogue and the dictionary; all of alpha
    // for the catalogue when there is no dictionary.
    assert!(close(alpha_share_of(0.01, false), 0.005));
    assert!(close(alpha_share_of(0.01, true), 0.01));
    assert!(close(alpha_share_of(0.05, false), 0.025));
}

#[test]
fn catalogue_candidates_leave_out_the_effects_in_the_model() {
    let [a, b, c] = [EffectName::ALL[0], EffectName::ALL[1], EffectName::ALL[2]];
    let available = [a, b, c];
    let drift = generic(GenericFamily::ReadingDrift, Scope::Channel(2));
    assert_eq!(
        catalogue_candidates(&available, &[Term::Catalogue(b), drift]),
        vec![Term::Catalogue(a), Term::Catalogue(c)]
    );
    assert_eq!(
        catalogue_candidates(&available, &[]),
        vec![Term::Catalogue(a), Term::Catalogue(b), Term::Catalogue(c)]
    );
    assert!(
        catalogue_candidates(
            &available,
            &[Term::Catalogue(a), Term::Catalogue(b), Term::Catalogue(c)]
        )
        .is_empty()
    );
}

#[test]
fn a_removed_cause_and_what_it_makes_redundant_are_not_tried_again() {
    let [a, b] = [EffectName::ALL[0], EffectName::ALL[1]];
    // The cause itself.
    assert!(!not_excluded(&[Term::Catalogue(a)], &Term::Catalogue(a)));
    // Another effect is still tried.
    assert!(not_excluded(&[Term::Catalogue(a)], &Term::Catalogue(b)));
    assert!(not_excluded(&[], &Term::Catalogue(b)));
    // A periodic term overlaps nothing (periods differ), but the very term
    // removed is not tried again; another period is.
    assert!(!not_excluded(&[periodic(0, 5.0)], &periodic(0, 5.0)));
    assert!(not_excluded(&[periodic(0, 5.0)], &periodic(0, 7.0)));
    // A polynomial on every leg makes one leg's redundant.
    let all = generic(GenericFamily::LegPolynomial, Scope::AllLegs);
    let one = generic(GenericFamily::LegPolynomial, Scope::Leg(1));
    assert!(!not_excluded(&[all], &one));
    assert!(not_excluded(
        &[all],
        &generic(GenericFamily::ReadingDrift, Scope::Channel(0))
    ));
}

#[test]
fn a_catalogue_effect_has_the_score_of_its_own_line() {
    let [a, b, c] = [EffectName::ALL[0], EffectName::ALL[1], EffectName::ALL[2]];
    let screen = [(Term::Catalogue(a), 3.0, 1), (Term::Catalogue(b), 7.5, 2)];
    assert_eq!(score_of(&screen, &Term::Catalogue(b)), Some((7.5, 2)));
    assert_eq!(score_of(&screen, &Term::Catalogue(a)), Some((3.0, 1)));
    assert_eq!(score_of(&screen, &Term::Catalogue(c)), None);
}

#[test]
fn a_nested_test_drops_chi_square_for_the_added_rank() {
    // Without: chi2 120 at rank 10; with: chi2 80, 40 dof, rank 12.
    assert_eq!(
        Nested::of_fits((120.0, 10), (80.0, 40, 12)),
        Nested {
            delta: 40.0,
            k: 2,
            with: (80.0, 40)
        }
    );
    // No rank added: still one parameter tested.
    assert_eq!(Nested::of_fits((50.0, 10), (50.0, 41, 10)).k, 1);
}

#[test]
fn a_score_test_subtracts_its_drop_from_the_current_fit() {
    // The current fit leaves chi2 100 on 50 dof; 30 explained by 2.
    assert_eq!(
        Nested::of_score((100.0, 50), 30.0, 2),
        Nested {
            delta: 30.0,
            k: 2,
            with: (70.0, 48)
        }
    );
    // Rank 0 counts as one parameter.
    assert_eq!(
        Nested::of_score((100.0, 50), 4.0, 0),
        Nested {
            delta: 4.0,
            k: 1,
            with: (96.0, 49)
        }
    );
}

#[test]
fn evidence_follows_the_documented_rules() {
    // A drop of 10 for 2 parameters, the larger model leaving chi2 60 on 30
    // dof: s2 = max(1, 60 / 30) = 2, the statistic 5, its chi2(2) tail
    // exp(-5/2). Four tests in the half (level 0.025 / 4), three
    // alternatives in the family, 30 readings.
    let count = Count {
        alpha_share: 0.025,
        multiplicity: 4,
        alternatives: 3,
    };
    let test = Nested {
        delta: 10.0,
        k: 2,
        with: (60.0, 30),
    };
    let e = weigh(&Reference::stated(), test, 30, count);
    let p = (-2.5f64).exp();
    assert!(close(e.p_value, p), "{}", e.p_value);
    assert!(close(e.p_adjusted, 4.0 * p), "{}", e.p_adjusted);
    assert!(close(e.threshold, 0.00625), "{}", e.threshold);
    assert_eq!(e.multiplicity, 4);
    assert_eq!(e.dof, 2);
    assert_eq!(e.delta_chi_square, 10.0);
    // BIC gain 10 - 2 ln 30; penalised gain less 2 ln 3.
    let bic = 10.0 - 2.0 * 30f64.ln();
    assert!(close(e.delta_bic, bic), "{}", e.delta_bic);
    assert!(
        close(e.penalised_gain, bic - 2.0 * 3f64.ln()),
        "{}",
        e.penalised_gain
    );
    assert!(
        (e.penalised_gain - 1.000_380_659_3).abs() < 1e-9,
        "{}",
        e.penalised_gain
    );
    assert!(!e.selected);
    assert_eq!((e.holdout_rms_without, e.holdout_rms_with), (None, None));

    // A residual variance below the noise scales nothing: chi2 20 on 30.
    let e = weigh(
        &Reference::stated(),
        Nested {
            with: (20.0, 30),
            ..test
        },
        30,
        count,
    );
    assert!(close(e.p_value, (-5.0f64).exp()), "{}", e.p_value);
    // A catalogue effect (one alternative) pays no family penalty.
    let e = weigh(
        &Reference::stated(),
        test,
        30,
        Count {
            alternatives: 1,
            ..count
        },
    );
    assert!(close(e.penalised_gain, bic), "{}", e.penalised_gain);
    // The adjusted p-value is at most 1: a drop of 1 has p = exp(-1/4).
    let e = weigh(
        &Reference::stated(),
        Nested { delta: 1.0, ..test },
        30,
        count,
    );
    assert!(close(e.p_value, (-0.25f64).exp()), "{}", e.p_value);
    assert_eq!(e.p_adjusted, 1.0);
}

#[test]
fn admissible_needs_a_significant_test_and_a_positive_gain() {
    let share = 0.01;
    assert!(admissible(&ev(0.009, 0.5), share));
    // The level is strict: p exactly at it is not significant.
    assert!(!admissible(&ev(0.01, 0.5), share));
    assert!(!admissible(&ev(0.011, 0.5), share));
    // So is the gain: zero is not positive.
    assert!(!admissible(&ev(0.009, 0.0), share));
    assert!(!admissible(&ev(0.009, -0.5), share));
    assert!(!admissible(&ev(0.5, -0.5), share));
    assert!(significant(0.0049, 0.005));
    assert!(!significant(0.005, 0.005));
    assert!(!significant(0.0051, 0.005));
}

#[test]
fn a_catalogue_effect_is_refitted_when_twice_its_score_could_be_admissible() {
    // A score test of 2 parameters in 4 tests: p_adjusted = 4 exp(-x/2),
    // gain x - 8; the level 0.025.
    let score = |x: f64| Evidence {
        delta_chi_square: x,
        ..ev((4.0 * (-x / 2.0).exp()).min(1.0), x - 8.0)
    };
    // 6 explained: at 12, p_adjusted 4 e^-6 = 0.0099 and gain 4: refitted.
    assert_eq!(shortlist(score, 6.0, 0.025), None);
    // 4.5 explained: at 9, 4 e^-4.5 = 0.044 fails: judged on its score
    // at 4.5 itself.
    let judged = shortlist(score, 4.5, 0.025).expect("judged on its score");
    assert_eq!(judged.delta_chi_square, 4.5);
    assert!(close(judged.p_adjusted, 4.0 * (-2.25f64).exp()));
    // 5 explained: at 10, 4 e^-5 = 0.027 > 0.025: not refitted.
    assert!(shortlist(score, 5.0, 0.025).is_some());
}

#[test]
fn the_largest_gain_enters_and_ties_prefer_the_catalogue() {
    let (one, two, three) = (ev(0.0, 1.0), ev(0.0, 2.0), ev(0.0, 3.0));
    assert_eq!(stronger_first((&two, false), (&one, false)), Ordering::Less);
    assert_eq!(
        stronger_first((&one, false), (&two, true)),
        Ordering::Greater
    );
    assert_eq!(
        stronger_first((&two, true), (&two, false)),
        Ordering::Greater
    );
    assert_eq!(stronger_first((&two, false), (&two, true)), Ordering::Less);
    assert_eq!(stronger_first((&two, true), (&two, true)), Ordering::Equal);
    let mut ranked = [(&one, true), (&three, true), (&three, false), (&two, false)];
    ranked.sort_by(|a, b| stronger_first(*a, *b));
    let order: Vec<(f64, bool)> = ranked.iter().map(|(e, g)| (e.penalised_gain, *g)).collect();
    assert_eq!(
        order,
        vec![(3.0, false), (3.0, true), (2.0, false), (1.0, true)]
    );
}

#[test]
fn a_candidate_enters_only_when_held_out_rms_improves() {
    assert_eq!(predicts_better(Some(2.0), Some(1.5)), Some(1.5));
    assert_eq!(predicts_better(Some(1.5), Some(1.5)), None);
    assert_eq!(predicts_better(Some(1.5), Some(2.0)), None);
    assert_eq!(predicts_better(None, Some(1.0)), None);
    assert_eq!(predicts_better(Some(1.0), None), None);
}

#[test]
fn a_cause_holds_up_when_the_model_without_it_predicts_strictly_worse() {
    let good = ev(0.001, 5.0);
    assert!(holds_up(&good, 0.01, 1.0, Some(1.2)));
    // Strictly: no better without it is not enough.
    assert!(!holds_up(&good, 0.01, 1.0, Some(1.0)));
    assert!(!holds_up(&good, 0.01, 1.0, Some(0.9)));
    // The model without it cannot be cross-validated: it is needed.
    assert!(holds_up(&good, 0.01, 1.0, None));
    // Not admissible: fails whatever its held-out RMS.
    assert!(!holds_up(&ev(0.001, -1.0), 0.01, 1.0, None));
    assert!(!holds_up(&ev(0.02, 5.0), 0.01, 1.0, Some(2.0)));
}

#[test]
fn usefulness_is_the_held_out_rms_a_cause_saves() {
    let t = |w: Option<f64>, pass: bool| (ev(0.0, 1.0), w, pass);
    assert!(close(usefulness(&t(Some(1.5), true), 1.2), 0.3));
    assert!(close(usefulness(&t(Some(1.1), false), 1.2), -0.1));
    assert_eq!(usefulness(&t(None, true), 1.2), f64::INFINITY);
}

#[test]
fn backward_elimination_removes_the_least_useful_failing_cause() {
    let t = |w: Option<f64>, pass: bool| (ev(0.0, 1.0), w, pass);
    // Held-out rms 1.0 with every cause; without each: 1.5, 1.4, 1.3, 1.05.
    let tests = [
        t(Some(1.5), true),
        t(Some(1.4), false),
        t(Some(1.3), false),
        t(Some(1.05), true),
    ];
    // Of the two failing causes the one saving least (0.3) goes.
    assert_eq!(least_useful_failing(&tests, 1.0, 2.0), Some(2));
    // As good as the geometric model is still good enough.
    assert_eq!(least_useful_failing(&tests, 1.0, 1.0), Some(2));
    // Worse than the geometric model: the least useful of all goes.
    assert_eq!(least_useful_failing(&tests, 1.0, 0.9), Some(3));
    // Every cause holds up: none goes.
    let passing = [t(Some(1.5), true), t(Some(1.05), true)];
    assert_eq!(least_useful_failing(&passing, 1.0, 2.0), None);
    assert_eq!(least_useful_failing(&passing, 1.0, 1.0), None);
    // A cause without which the model cannot be cross-validated is the
    // most useful: a failing one with a known rms goes first.
    let unknown = [t(None, false), t(Some(3.0), false)];
    assert_eq!(least_useful_failing(&unknown, 1.0, 2.0), Some(1));
    // Among equals the first.
    let equal = [t(Some(1.2), false), t(Some(1.2), false)];
    assert_eq!(least_useful_failing(&equal, 1.0, 2.0), Some(0));
}

#[test]
fn a_swap_must_lower_the_bic_by_more_than_rounding() {
    // chi2 + rank ln n: 100 + 4 ln 30.
    assert!(close(bic_of(100.0, 4, 30), 100.0 + 4.0 * 30f64.ln()));
    assert!((bic_of(100.0, 4, 30) - 113.604_789_526_6).abs() < 1e-9);
    assert!(close(bic_of(7.0, 0, 30), 7.0));
    assert!(lowers_bic(99.0, 100.0));
    assert!(lowers_bic(100.0 - 2e-6, 100.0));
    assert!(!lowers_bic(100.0 - 0.5e-6, 100.0));
    assert!(!lowers_bic(100.0 - 1e-6, 100.0));
    assert!(!lowers_bic(100.0, 100.0));
    assert!(!lowers_bic(101.0, 100.0));
}

#[test]
fn one_more_pass_follows_a_removal_and_only_the_first() {
    // The module docs: "If anything was removed, one more forward step is
    // tried from the pruned model." No removal: no pass; a removal in the
    // first admission: one pass; a removal in that pass's admission: none.
    assert!(!another_pass(false, false));
    assert!(another_pass(true, false));
    assert!(!another_pass(true, true));
    assert!(!another_pass(false, true));
}

#[test]
fn a_term_is_listed_once_per_stage_that_rejects_it() {
    // The same term rejected again at the same stage replaces its entry
    // (the later reason stands); at another stage it is listed beside it.
    let (data, options) = crate::testing::campaign(30, 5, Vec::new());
    let setup = Setup::new(&Machine::paper(), &data, &options);
    let lead = Term::Catalogue(EffectName::LegLead);
    let fit = setup
        .fitter
        .fit(setup.fitter.model(&[lead]), &data)
        .expect("the lead's model fits");
    let mut rejected = Vec::new();
    reject(
        &mut rejected,
        &fit,
        &lead,
        RejectStage::Holdout,
        "first".into(),
    );
    reject(
        &mut rejected,
        &fit,
        &lead,
        RejectStage::Holdout,
        "again".into(),
    );
    let listed = |r: &[Rejected]| {
        r.iter()
            .map(|r| (r.description.clone(), r.stage, r.reason.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        listed(&rejected),
        [(lead.label(), RejectStage::Holdout, "again".to_string())]
    );
    reject(
        &mut rejected,
        &fit,
        &lead,
        RejectStage::FinalEvidence,
        "final".into(),
    );
    assert_eq!(
        listed(&rejected),
        [
            (lead.label(), RejectStage::Holdout, "again".to_string()),
            (
                lead.label(),
                RejectStage::FinalEvidence,
                "final".to_string()
            )
        ]
    );
    // Each entry carries the term's three parameters, named after it.
    let names: Vec<&str> = rejected[1]
        .parameters
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "leg-lead.lead1_ppm",
            "leg-lead.lead2_ppm",
            "leg-lead.lead3_ppm"
        ]
    );
}
