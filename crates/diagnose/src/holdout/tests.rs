//! The out-of-sample benefit against sums worked by hand, and the
//! deployment rule against the module's documented statement, at and
//! around its thresholds (2 standard deviations each, `report.rs`).
use super::*;

fn b(mean_mm: f64, sd_mm: f64) -> Option<Benefit> {
    Some(Benefit { mean_mm, sd_mm })
}

fn g(mean_mm: f64, sd_mm: f64) -> Option<Improvement> {
    Some(Improvement {
        mean_mm,
        rms_mm: mean_mm,
        sd_mm,
        difference_sd_mm: sd_mm,
    })
}

/// Whether the rule deploys the term: nothing keeps it back.
fn rule(
    policy: DeployRule,
    fitted_without: bool,
    held_out: Option<Benefit>,
    gained: Option<Improvement>,
    expected: Option<(f64, f64)>,
) -> bool {
    kept_back_because(policy, fitted_without, held_out, gained, expected).is_none()
}

#[test]
fn a_held_out_pose_is_predicted_by_a_fit_without_its_fold() {
    // Moving one pose's readings changes no other held-out error of its
    // fold (their fit never saw it), changes its own, and changes poses
    // of the other folds (whose fits did).
    let (data, options) = crate::testing::campaign(40, 11, Vec::new());
    let nominal = Machine::paper();
    let errors = |d: &Dataset| {
        let setup = Setup::new(&nominal, d, &options);
        let model = setup.fitter.base_model();
        platform_errors(&setup, &model, d).expect("every fold fits")
    };
    let before = errors(&data);
    let k = options.folds;
    let moved_pose = 7;
    let mut moved = data.clone();
    moved.poses[moved_pose].readings.phi_rad += 20.0 * options.sigma[0];
    moved.poses[moved_pose].readings.s_mm += 20.0 * options.sigma[2];
    let after = errors(&moved);
    let fold = moved_pose % k;
    for j in (0..data.poses.len()).filter(|j| *j != moved_pose && j % k == fold) {
        assert_eq!(after[j], before[j], "pose {j} of the moved pose's fold");
    }
    assert_ne!(after[moved_pose], before[moved_pose]);
    let others = (0..data.poses.len()).filter(|j| j % k != fold);
    assert!(
        others.clone().all(|j| after[j] != before[j]),
        "{before:?}\n{after:?}"
    );
}

#[test]
fn a_scale_reading_off_by_10_um_puts_the_platform_10_um_off_along_the_limb() {
    // The linear scale measures the UP limb's prismatic joint: a reading
    // 0.01 mm larger is a platform 0.01 mm further along the limb, so
    // each pose's platform error moves by exactly 0.01 mm (the
    // prismatic joint's derivative is a unit vector), whatever the pose.
    let (data, options) = crate::testing::campaign(30, 13, Vec::new());
    let setup = Setup::new(&Machine::paper(), &data, &options);
    let fit = setup
        .fitter
        .fit(setup.fitter.base_model(), &data)
        .expect("the geometric model fits");
    let mut moved = data.clone();
    for p in &mut moved.poses {
        p.readings.s_mm += 0.01;
    }
    let errors = |d: &Dataset| {
        let poses: Vec<(usize, &MeasuredPose)> = d.poses.iter().enumerate().collect();
        pose_errors(&fit, &poses).expect("every pose predicted")
    };
    for ((j, before), (k, after)) in errors(&data).into_iter().zip(errors(&moved)) {
        assert_eq!(j, k);
        let moved_mm = (after - before).norm();
        assert!((moved_mm - 0.01).abs() < 1e-9, "pose {j}: {moved_mm} mm");
    }
}

#[test]
fn the_benefit_is_the_difference_of_the_rms_errors_with_its_sd() {
    let with = [
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(0.0, 0.0, 1.0),
    ];
    let without = [
        Vector3::new(2.0, 0.0, 0.0),
        Vector3::new(0.0, 3.0, 0.0),
        Vector3::new(1.0, 2.0, 3.0),
    ];
    // |e|^2: with 1, 1, 1 (rms 1); without 4, 9, 14 (rms 3).
    // d = 3, 8, 13: mean 8, sample variance (25 + 0 + 25) / 2 = 25,
    // sd(d) / sqrt(3) / (1 + 3) = 5 / sqrt(3) / 4.
    let got = benefit(&with, &without).expect("three poses");
    assert!((got.mean_mm - 2.0).abs() < 1e-12, "{got:?}");
    assert!(
        (got.sd_mm - 5.0 / 3f64.sqrt() / 4.0).abs() < 1e-12,
        "{got:?}"
    );
    // Two poses are enough: |e|^2 with 1, 4 and without 9, 16 (d = 8,
    // 12: variance 8, sd(d) / sqrt(2) = 2), rms sqrt(2.5) and sqrt(12.5).
    let two = benefit(
        &[Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 2.0, 0.0)],
        &[Vector3::new(3.0, 0.0, 0.0), Vector3::new(0.0, 0.0, 4.0)],
    )
    .expect("two poses");
    let (rw, ro) = (2.5f64.sqrt(), 12.5f64.sqrt());
    assert!((two.mean_mm - (ro - rw)).abs() < 1e-12, "{two:?}");
    assert!((two.sd_mm - 2.0 / (ro + rw)).abs() < 1e-12, "{two:?}");
}

#[test]
fn no_benefit_without_two_poses_matching_lengths_or_a_finite_error() {
    let one = [Vector3::new(1.0, 0.0, 0.0)];
    assert!(benefit(&one, &one).is_none());
    let two = [Vector3::new(1.0, 0.0, 0.0); 2];
    let three = [Vector3::new(1.0, 0.0, 0.0); 3];
    assert!(benefit(&two, &three).is_none());
    let zero = [Vector3::zeros(); 3];
    assert!(benefit(&zero, &zero).is_none());
    let infinite = [Vector3::new(f64::INFINITY, 0.0, 0.0); 3];
    assert!(benefit(&three, &infinite).is_none());
    // Equal errors: no benefit, no spread.
    let same = benefit(&three, &three).expect("finite");
    assert_eq!((same.mean_mm, same.sd_mm), (0.0, 0.0));
}

#[test]
fn a_term_the_model_cannot_do_without_is_deployed() {
    assert!(rule(DeployRule::Confident, false, None, None, None));
    assert!(rule(
        DeployRule::Confident,
        false,
        b(-1.0, 0.1),
        g(-1.0, 0.1),
        None
    ));
}

#[test]
fn without_both_numbers_nothing_says_a_term_pays() {
    assert!(!rule(DeployRule::Confident, true, None, g(10.0, 1.0), None));
    assert!(!rule(DeployRule::Confident, true, b(10.0, 1.0), None, None));
    assert!(!rule(DeployRule::Confident, true, None, None, None));
}

#[test]
fn the_out_of_sample_benefit_must_exceed_two_sd() {
    // Improvement 3 sd: the second half holds.
    assert!(rule(
        DeployRule::Confident,
        true,
        b(1.0, 0.4),
        g(3.0, 1.0),
        None
    ));
    // Exactly 2 sd does not exceed 2 sd.
    assert!(!rule(
        DeployRule::Confident,
        true,
        b(1.0, 0.5),
        g(3.0, 1.0),
        None
    ));
    assert!(!rule(
        DeployRule::Confident,
        true,
        b(-1.0, 0.1),
        g(3.0, 1.0),
        None
    ));
}

#[test]
fn the_improvement_must_exceed_two_sd_or_be_no_larger_than_the_benefit() {
    // Benefit 1 +- 0.25 (4 sd): its upper bound 1 + 2 * 0.25 = 1.5.
    let seen = b(1.0, 0.25);
    // 1.5 sd, but no larger than 1.5: it cannot lose more than it gains.
    assert!(rule(DeployRule::Confident, true, seen, g(1.5, 1.0), None));
    // 1.6 sd and larger than 1.5.
    assert!(!rule(DeployRule::Confident, true, seen, g(1.6, 1.0), None));
    // Exactly 2 sd does not exceed 2 sd.
    assert!(!rule(DeployRule::Confident, true, seen, g(2.0, 1.0), None));
    assert!(rule(DeployRule::Confident, true, seen, g(2.5, 1.0), None));
    // 3.5 sd of a spread of 0.5 (larger than 1.5): 2 sd is 1.0 there.
    assert!(rule(DeployRule::Confident, true, seen, g(1.75, 0.5), None));
}

#[test]
fn the_least_useful_term_is_the_one_with_fewest_improvement_sds() {
    assert_eq!(improvement_sds(g(3.0, 1.5)), 2.0);
    assert_eq!(improvement_sds(g(-1.0, 4.0)), -0.25);
    assert_eq!(improvement_sds(g(1.0, 0.0)), f64::INFINITY);
    assert_eq!(improvement_sds(g(-1.0, 0.0)), f64::INFINITY);
    assert_eq!(improvement_sds(None), f64::INFINITY);
}

#[test]
fn a_leg_described_in_its_command_keeps_its_own_description() {
    let lead = Term::Catalogue(EffectName::LegLead);
    let generic = |f, scope| Term::Generic(GenericTerm::new(f, scope));
    for leg in 0..3 {
        assert!(shapes_leg(&lead, leg));
        assert!(shapes_leg(
            &generic(GenericFamily::LegPeriodic, Scope::AllLegs),
            leg
        ));
    }
    let curved = generic(GenericFamily::LegPolynomial, Scope::Leg(1));
    assert!(shapes_leg(&curved, 1));
    assert!(!shapes_leg(&curved, 0) && !shapes_leg(&curved, 2));
    // Time, temperature and readings say nothing of the command.
    for t in [
        Term::Catalogue(EffectName::Thermal),
        Term::Catalogue(EffectName::Backlash),
        Term::Catalogue(EffectName::ScaleGain),
        generic(GenericFamily::LegDrift, Scope::AllLegs),
    ] {
        assert!(!shapes_leg(&t, 0), "{t:?}");
    }
}

#[test]
fn the_structure_widens_only_the_files_own_uncertainty() {
    // own 0.03, move 0.04: sd 0.05.
    let g = Improvement {
        mean_mm: 0.12,
        rms_mm: 0.12,
        sd_mm: 0.05,
        difference_sd_mm: 0.04,
    };
    // A structured own sd of 0.09 replaces the own 0.03, the move's
    // 0.04 stays: sqrt(0.09^2 + 0.04^2).
    let w = with_structure(g, Some(0.09));
    assert!((w.sd_mm - 0.09_f64.hypot(0.04)).abs() < 1e-12, "{w:?}");
    assert_eq!((w.mean_mm, w.difference_sd_mm), (0.12, 0.04));
    // The 0.12 move was 2.4 sd, it is no longer 2.
    assert!(w.mean_mm < DEPLOY_IMPROVEMENT_SD * w.sd_mm);
    // Between the own 0.03 and the whole 0.05: it replaces the own
    // part, sqrt(0.05^2 + 0.04^2).
    let w = with_structure(g, Some(0.05));
    assert!((w.sd_mm - 0.05_f64.hypot(0.04)).abs() < 1e-12, "{w:?}");
    // A smaller structured sd, or none, changes nothing.
    for s in [Some(0.02), Some(0.03), None] {
        let same = with_structure(g, s);
        assert_eq!(same.sd_mm, g.sd_mm, "{s:?}");
    }
}

fn with_rms(mean_mm: f64, rms_mm: f64, sd_mm: f64, difference_sd_mm: f64) -> Improvement {
    Improvement {
        mean_mm,
        rms_mm,
        sd_mm,
        difference_sd_mm,
    }
}

#[test]
fn the_expected_error_is_the_references_variance_less_the_moves_plus_its_squared_bias() {
    // Reference sd 0.10, the move's sd 0.06, rms of the move 0.08:
    // variance 0.01 - 0.0036 = 0.0064, squared bias 0.0064 - 0.0036 =
    // 0.0028: 0.0092 mm^2.
    let e = expected_error(with_rms(0.07, 0.08, 0.2, 0.06), 0.10);
    assert!((e - 0.0092).abs() < 1e-15, "{e}");
    // A move smaller than its sd shows no bias (never negative): the
    // file is the reference less the move's variance.
    let e = expected_error(with_rms(0.03, 0.04, 0.2, 0.06), 0.10);
    assert!((e - 0.0064).abs() < 1e-15, "{e}");
    // A move's variance beyond the reference's (rounding) leaves no
    // negative variance: the squared bias alone, 0.05^2 - 0.04^2.
    let e = expected_error(with_rms(0.05, 0.05, 0.2, 0.04), 0.03);
    assert!((e - 0.0009).abs() < 1e-15, "{e}");
    // The deployed model as its own reference (no move): its variance.
    let e = expected_error(with_rms(0.0, 0.0, 0.1, 0.0), 0.1);
    assert!((e - 0.01).abs() < 1e-15, "{e}");
}

#[test]
fn the_expected_error_rule_adds_files_expected_better_by_a_move_of_one_sd() {
    let seen = b(1.0, 0.25);
    let better = Some((0.01, 0.02));
    let worse = Some((0.02, 0.01));
    // 1.6 sd, larger than the benefit (and its 2 sd, 1.5): the confident rule keeps it
    // back, the expected-error rule deploys it when the file with it is
    // expected better.
    assert!(!rule(
        DeployRule::Confident,
        true,
        seen,
        g(1.6, 1.0),
        better
    ));
    assert!(rule(
        DeployRule::ExpectedError,
        true,
        seen,
        g(1.6, 1.0),
        better
    ));
    assert!(!rule(
        DeployRule::ExpectedError,
        true,
        seen,
        g(1.6, 1.0),
        worse
    ));
    assert!(!rule(
        DeployRule::ExpectedError,
        true,
        seen,
        g(1.6, 1.0),
        Some((0.01, 0.01))
    ));
    assert!(!rule(
        DeployRule::ExpectedError,
        true,
        seen,
        g(1.6, 1.0),
        None
    ));
    // Exactly one sd is enough, less is not.
    assert!(rule(
        DeployRule::ExpectedError,
        true,
        seen,
        g(1.6, 1.6),
        better
    ));
    assert!(!rule(
        DeployRule::ExpectedError,
        true,
        seen,
        g(1.59, 1.6),
        better
    ));
    // The out-of-sample benefit is still required.
    assert!(!rule(
        DeployRule::ExpectedError,
        true,
        b(1.0, 0.5),
        g(3.0, 1.0),
        better
    ));
    // What the confident rule deploys, it deploys.
    assert!(rule(
        DeployRule::ExpectedError,
        true,
        seen,
        g(2.5, 1.0),
        worse
    ));
    assert!(rule(DeployRule::ExpectedError, false, None, None, None));
}

#[test]
fn a_term_kept_back_says_why() {
    let seen = b(1.0, 0.25);
    let why = |policy, held_out, gained, expected| {
        kept_back_because(policy, true, held_out, gained, expected).expect("kept back")
    };
    // Not seen out of sample: said so, with its numbers, under either rule,
    // even when the file with it is expected better.
    for policy in [DeployRule::Confident, DeployRule::ExpectedError] {
        let w = why(policy, b(0.2, 0.1), g(3.0, 1.0), Some((0.01, 0.04)));
        assert!(
            w.starts_with(
                "the readings do not see it pay out of sample (its benefit not above 2 sd)"
            ),
            "{w}"
        );
    }
    // Expected better by 1.6 sd: only the confident rule keeps it back, and
    // names itself.
    let w = why(DeployRule::Confident, seen, g(1.6, 1.0), Some((0.01, 0.04)));
    assert!(
        w.starts_with("the confident rule (deploy_rule `confident`): its improvement is 1.6 sd, not above 2 sd"),
        "{w}"
    );
    // Not expected better: the two expected errors.
    let w = why(
        DeployRule::ExpectedError,
        seen,
        g(1.6, 1.0),
        Some((0.04, 0.01)),
    );
    assert_eq!(w, "the file with it is not expected better");
    // Expected better, but by less than one sd.
    let w = why(
        DeployRule::ExpectedError,
        seen,
        g(1.6, 2.0),
        Some((0.01, 0.04)),
    );
    assert!(
        w.starts_with("its improvement is within its own uncertainty (0.8 sd, below 1)"),
        "{w}"
    );
    // Nothing to judge by.
    let w = why(DeployRule::ExpectedError, seen, g(1.6, 1.0), None);
    assert!(w.starts_with("its expected errors could not be had"), "{w}");
    assert!(
        why(DeployRule::ExpectedError, None, g(1.0, 1.0), None)
            .starts_with("no out-of-sample benefit")
    );
    assert!(why(DeployRule::ExpectedError, seen, None, None).starts_with("its improvement where"));
}

#[test]
fn the_richer_model_adds_a_polynomial_on_every_leg_nothing_shapes() {
    let generic = |f, scope| Term::Generic(GenericTerm::new(f, scope));
    let polynomial = |scope| generic(GenericFamily::LegPolynomial, scope);
    let thermal = Term::Catalogue(EffectName::Thermal);
    // No leg shaped: one polynomial over all legs, after the terms.
    assert_eq!(
        richer_terms(&[thermal]),
        Some(vec![thermal, polynomial(Scope::AllLegs)])
    );
    assert_eq!(richer_terms(&[]), Some(vec![polynomial(Scope::AllLegs)]));
    // Leg 2 (index 1) shaped by its own polynomial: legs 1 and 3 get one each.
    let curved = polynomial(Scope::Leg(1));
    assert_eq!(
        richer_terms(&[curved, thermal]),
        Some(vec![
            curved,
            thermal,
            polynomial(Scope::Leg(0)),
            polynomial(Scope::Leg(2))
        ])
    );
    // Every leg shaped (a lead, a periodic error on all legs): none.
    assert_eq!(richer_terms(&[Term::Catalogue(EffectName::LegLead)]), None);
    assert_eq!(
        richer_terms(&[thermal, generic(GenericFamily::LegPeriodic, Scope::AllLegs)]),
        None
    );
}

#[test]
fn the_structured_sd_is_the_own_part_of_the_improvements_sd() {
    // sd 0.05 of which the move 0.04: own 0.03.
    let own = structured_sd(with_rms(0.1, 0.1, 0.05, 0.04)).expect("finite");
    assert!((own - 0.03).abs() < 1e-12, "{own}");
    // A move's sd beyond the total (rounding): no own part, not NaN.
    assert_eq!(structured_sd(with_rms(0.1, 0.1, 0.04, 0.05)), Some(0.0));
    assert_eq!(structured_sd(with_rms(0.1, 0.1, f64::NAN, 0.05)), None);
    assert_eq!(structured_sd(with_rms(0.1, 0.1, f64::INFINITY, 0.05)), None);
}

#[test]
fn the_reference_is_priced_from_one_improvement() {
    // The reference's own sd 0.10 beside a move of sd 0.06 (total
    // sqrt(0.0136)), the move's rms 0.08: the reference's sd 0.10 and
    // the file's expected error 0.0092 mm^2 (worked above).
    let (sd, error) =
        against_reference(with_rms(0.07, 0.08, 0.0136_f64.sqrt(), 0.06)).expect("finite");
    assert!((sd - 0.10).abs() < 1e-12, "{sd}");
    assert!((error - 0.0092).abs() < 1e-12, "{error}");
    assert_eq!(
        against_reference(with_rms(0.07, 0.08, f64::NAN, 0.06)),
        None
    );
}
