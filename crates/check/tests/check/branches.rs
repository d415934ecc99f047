//! Every verdict of a check and the numbers it reports, branch by branch
//! (issue 32): "changed, unexplained" and "cause unknown", the p-values
//! and degrees of freedom of its tests, the refusal of options no check can
//! use, the campaign's mean temperature, and the report's units and lines.
//!
//! The reference is a perfectly known machine (zero covariance), so that
//! each expectation follows from what the plant was given and from the
//! documented test: the consistency statistic has `3n - 3` degrees of
//! freedom and is compared at `alpha / 2`, each candidate at
//! [`family_level`], the remaining misfit is `T0 - dT_best` on `3n - 3 -
//! dim best` degrees of freedom. P-values are recomputed with
//! `tricept_numerics::stats::chi2_sf`, itself tested against closed forms
//! (crates/numerics/tests/stats_reference.rs).

use nalgebra::DMatrix;
use tricept_check::{
    CheckError, CheckOptions, CheckReport, CheckVerdict, Reference, candidates::Candidate, check,
    check::family_level, check::leg_ranges, parts::ChiSquare,
};
use tricept_data::Dataset;
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_numerics::stats::{chi2_sf, f_sf};
use tricept_plant::{Campaign, Plant};

fn reference(m: &Machine) -> Reference {
    let set = ParameterSet::paper15();
    Reference::new(m.clone(), set, DMatrix::zeros(15, 15), [0.0; 3], None).unwrap()
}

/// A check campaign of `n` random poses on a machine whose errors are
/// `changes` (parameter name, mm), its true noise `noise_factor` times the
/// stated one.
fn campaign(m: &Machine, changes: &[(&str, f64)], n: usize, seed: u64, noise: f64) -> Dataset {
    let set = ParameterSet::paper15();
    let mut e = vec![0.0; set.len()];
    for (name, v) in changes {
        e[set.index_of(name).unwrap()] = *v;
    }
    let mut c = Campaign::random(m, n, seed);
    c.noise_factor = noise;
    Plant::geometric(m.clone(), set.to_errors(&e))
        .simulate(&c)
        .unwrap()
}

fn run(m: &Machine, data: &Dataset) -> CheckReport {
    check(&reference(m), data, &CheckOptions::for_machine(m)).unwrap()
}

/// Asserts that `t` is the chi-square test of its statistic at `tail`.
fn assert_test(t: &ChiSquare, tail: f64, what: &str) {
    assert!(t.dof > 0, "{what}");
    let p = chi2_sf(t.statistic, t.dof as f64);
    assert!(
        (t.p_value - p).abs() <= 1e-12 * p,
        "{what}: p {} vs {p}",
        t.p_value
    );
    assert!(t.p_value < 1.0, "{what}");
    if p > 1e-300 {
        assert!((t.ln_p_value - p.ln()).abs() < 1e-9, "{what}: ln p");
    }
    let at_critical = chi2_sf(t.critical, t.dof as f64);
    assert!(
        (at_critical - tail).abs() < 1e-6 * tail,
        "{what}: critical {} has tail {at_critical}, not {tail}",
        t.critical
    );
}

fn level(m: &Machine, temperatures: bool) -> f64 {
    let candidates = Candidate::all(leg_ranges(m).unwrap(), None, temperatures);
    family_level(0.01, &candidates)
}

#[test]
fn an_unchanged_machine_has_tests_with_their_degrees_of_freedom_and_p_values() {
    let m = Machine::paper();
    let data = campaign(&m, &[], 20, 7, 1.0);
    let r = run(&m, &data);
    assert_eq!(r.verdict, CheckVerdict::Unchanged);
    assert!(!r.changed && r.most_likely.is_none() && r.remaining.is_none());
    // No set of changes, and no misfit after one.
    assert!(r.changes.is_empty() && r.after_changes.is_none());
    assert_eq!(r.poses, 20);
    // 60 readings less the three offsets.
    assert_eq!(r.consistency.dof, 57);
    assert_test(&r.consistency, 0.005, "consistency");
    assert!(r.consistency.statistic <= r.consistency.critical);
    let level = level(&m, false);
    for c in &r.candidates {
        assert_test(&c.test, level, &c.name);
        assert_eq!(
            c.significant,
            c.test.statistic > c.test.critical,
            "{}",
            c.name
        );
        assert!(!c.significant, "{}", c.name);
        assert!(c.test.dof <= c.parameters.len() && c.fitted <= c.parameters.len());
    }
    let text = r.to_text();
    assert!(text.starts_with("verdict: UNCHANGED"), "{text}");
    assert!(
        text.contains("chi2") && text.contains("for 57 dof"),
        "{text}"
    );
}

#[test]
fn one_slipped_leg_is_changed_and_explained() {
    let m = Machine::paper();
    let r = run(&m, &campaign(&m, &[("dq2", 0.025)], 20, 2, 1.0));
    assert_eq!(r.verdict, CheckVerdict::Changed);
    let best = &r.candidates[r.most_likely.unwrap()];
    assert_eq!(best.name, "leg 2");
    let rest = r.remaining.unwrap();
    assert_eq!(rest.dof, 57 - best.test.dof);
    assert!((rest.statistic - (r.consistency.statistic - best.test.statistic)).abs() < 1e-6);
    assert_test(&rest, 0.005, "remaining");
    assert!(rest.statistic <= rest.critical);
    assert!(!r.to_text().contains("no single change"));
    assert_shortlist(&r);
    // Other candidates take up part of the slip and pass their test, but
    // far less likely than the leg: not on the shortlist.
    assert!(
        r.candidates
            .iter()
            .any(|c| c.significant && !r.shortlist.contains(&c.name)),
        "{:?}",
        r.shortlist
    );
}

/// The shortlist is the documented one: the most likely change first,
/// then every candidate that stands out (significant) with a p-value
/// within a factor 20 of it.
fn assert_shortlist(r: &CheckReport) {
    let best = &r.candidates[r.most_likely.unwrap()];
    assert_eq!(r.shortlist.first(), Some(&best.name));
    let mut expected: Vec<&str> = r
        .candidates
        .iter()
        .filter(|c| c.significant && c.test.ln_p_value <= best.test.ln_p_value + 20f64.ln())
        .map(|c| c.name.as_str())
        .collect();
    let mut listed: Vec<&str> = r.shortlist.iter().map(String::as_str).collect();
    expected.sort_unstable();
    listed.sort_unstable();
    assert_eq!(listed, expected);
}

#[test]
fn two_changes_no_single_one_explains_are_one_set() {
    let m = Machine::paper();
    // Two legs slipped by 50 um in opposite directions: no single
    // candidate holds both, the set of the two does (issue 31).
    let data = campaign(&m, &[("dq1", 0.05), ("dq3", -0.05)], 20, 4, 1.0);
    let r = run(&m, &data);
    assert!(r.changed);
    assert_eq!(r.verdict, CheckVerdict::Changed);
    let best = &r.candidates[r.most_likely.unwrap()];
    assert!(
        best.name == "leg 1" || best.name == "leg 3",
        "{}",
        best.name
    );
    let rest = r.remaining.unwrap();
    assert_eq!(rest.dof, 57 - best.test.dof);
    assert!((rest.statistic - (r.consistency.statistic - best.test.statistic)).abs() < 1e-6);
    assert_test(&rest, 0.005, "remaining");
    assert!(rest.statistic > rest.critical);
    let mut named: Vec<&str> = r.changes.iter().map(|c| c.name.as_str()).collect();
    named.sort_unstable();
    assert_eq!(named, ["leg 1", "leg 3"]);
    let after = r.after_changes.unwrap();
    assert_test(&after, 0.005, "after the changes");
    assert!(after.statistic <= after.critical);
    let text = r.to_text();
    assert!(text.starts_with("verdict: CHANGED"), "{text}");
    assert!(!text.contains("no single change explains"), "{text}");
}

#[test]
fn a_change_no_candidate_holds_is_changed_unexplained() {
    let m = Machine::paper();
    // The scale reads 30 um too long over the upper half of its travel (a
    // damaged scale: no candidate is a step of the scale), and leg 2
    // slipped 50 um, which the candidates hold.
    let mut data = campaign(&m, &[("dq2", 0.05)], 20, 6, 1.0);
    let mut s: Vec<f64> = data.poses.iter().map(|p| p.readings.s_mm).collect();
    s.sort_by(f64::total_cmp);
    let median = s[s.len() / 2];
    for p in &mut data.poses {
        if p.readings.s_mm > median {
            p.readings.s_mm += 0.03;
        }
    }
    let r = run(&m, &data);
    assert!(r.changed);
    assert_eq!(
        r.verdict,
        CheckVerdict::ChangedUnexplained,
        "{}",
        r.to_text()
    );
    assert_eq!(r.verdict.as_str(), "changed-unexplained");
    let rest = r.remaining.unwrap();
    assert!(rest.statistic > rest.critical);
    let text = r.to_text();
    assert!(
        text.starts_with("verdict: CHANGED, and no single change explains it all: most likely"),
        "{text}"
    );
    assert!(text.contains(&format!(
        "after the most likely change: chi2 {:.1} for {} dof",
        rest.statistic, rest.dof
    )));
}

#[test]
fn more_noise_than_stated_is_noisier_than_stated_not_a_change() {
    // The readings' noise 1.25 times the stated one over 100 poses: the
    // consistency statistic is 1.56 chi2(297), beyond its 0.5 % point (about
    // 366) with probability 0.995, and a candidate's 1.56 chi2(k) may pass
    // its Bonferroni level, but none stands out beyond the scatter the
    // readings show (issue 31: the F test of crate::noise): noisier than
    // stated, not a change. (Before issue 31 this was "changed, cause
    // unknown".)
    let m = Machine::paper();
    for seed in 0..5 {
        let r = run(&m, &campaign(&m, &[], 100, 30 + seed, 1.25));
        assert_eq!(r.consistency.dof, 297);
        assert!(
            r.consistency.statistic > r.consistency.critical,
            "seed {seed}"
        );
        assert!(!r.changed, "seed {seed}");
        assert_eq!(r.verdict, CheckVerdict::NoisierThanStated, "seed {seed}");
        assert_eq!(r.verdict.as_str(), "noisier-than-stated");
        assert!(r.most_likely.is_none() && r.remaining.is_none());
        assert!(r.shortlist.is_empty());
        assert!(r.changes.is_empty() && r.after_changes.is_none());
        assert!(r.candidates.iter().all(|c| !c.significant));
        // The noise it sees: 1.25 times the stated (the factor from 297
        // degrees of freedom, sd 3 %; each channel from 99, sd 7 %).
        assert!((r.noise.factor - 1.25).abs() < 0.12, "{:?}", r.noise);
        let n = &r.noise;
        for (seen, stated) in [
            (n.seen.phi_arcsec, n.stated.phi_arcsec),
            (n.seen.theta_arcsec, n.stated.theta_arcsec),
            (n.seen.s_um, n.stated.s_um),
        ] {
            assert!((seen / stated - 1.25).abs() < 0.3, "{n:?}");
        }
        assert!((n.stated.phi_arcsec - 0.8 / 3f64.sqrt()).abs() < 1e-9);
        assert!((n.stated.s_um - 0.5 / 3f64.sqrt()).abs() < 1e-9);
        let text = r.to_text();
        assert!(
            text.starts_with(&format!(
                "verdict: NOISIER THAN STATED: the readings scatter {:.2} times the stated noise",
                n.factor
            )),
            "{text}"
        );
        assert!(text.contains("noise seen: "), "{text}");
        assert_eq!(r.warnings.len(), 1, "{:?}", r.warnings);
        assert!(
            r.warnings[0]
                .contains("state the sensors' noise (`angle_noise_arcsec`, `length_noise_um`"),
            "{:?}",
            r.warnings
        );
    }
}

#[test]
fn a_change_stands_out_beyond_a_larger_noise() {
    // Leg 2 slipped by 40 um and the noise 1.5 times the stated: the slip
    // stands out beyond the scatter it leaves (F test), the verdict names it,
    // and the noise seen is that scatter, not the slip.
    let m = Machine::paper();
    let r = run(&m, &campaign(&m, &[("dq2", 0.04)], 20, 2, 1.5));
    assert!(r.changed);
    let best = &r.candidates[r.most_likely.unwrap()];
    assert_eq!(best.name, "leg 2");
    assert!(best.significant);
    assert!((r.noise.factor - 1.5).abs() < 0.45, "{:?}", r.noise);
    // The same campaign without the slip: noisier than stated.
    let r = run(&m, &campaign(&m, &[], 20, 2, 1.5));
    assert_eq!(r.verdict, CheckVerdict::NoisierThanStated);
}

#[test]
fn the_noise_seen_at_the_stated_noise_is_about_one() {
    let m = Machine::paper();
    let r = run(&m, &campaign(&m, &[], 100, 12, 1.0));
    assert_eq!(r.verdict, CheckVerdict::Unchanged);
    assert!((r.noise.factor - 1.0).abs() < 0.1, "{:?}", r.noise);
    assert!(r.rejected.is_empty() && r.warnings.is_empty());
    // Without noise the readings scatter not at all.
    let r = run(&m, &campaign(&m, &[], 20, 12, 0.0));
    assert!(
        r.noise.factor < 1e-3 && r.noise.seen.s_um < 1e-3,
        "{:?}",
        r.noise
    );
}

#[test]
fn gross_readings_beyond_the_cap_are_not_set_aside() {
    // 20 poses: at most 2 set aside. Three gross readings are not a matter
    // of gross readings: none is set aside, and the check of every pose is
    // reported with a warning.
    let m = Machine::paper();
    let clean = campaign(&m, &[], 20, 8, 1.0);
    let mut data = clean.clone();
    for (j, p) in data.poses.iter_mut().enumerate() {
        p.line = j as u64 + 2;
    }
    data.poses[3].readings.s_mm += 0.025;
    data.poses[9].readings.s_mm += 0.025;
    let r = run(&m, &data);
    assert_eq!(
        r.rejected.iter().map(|x| x.line).collect::<Vec<_>>(),
        vec![5, 11],
        "{:?}",
        r.rejected
    );
    assert_eq!(r.poses, 18);
    assert!(!r.changed);
    data.poses[15].readings.theta_rad += 0.0002;
    let r = run(&m, &data);
    assert!(r.rejected.is_empty(), "{:?}", r.rejected);
    assert_eq!(r.poses, 20);
    assert!(
        r.warnings
            .iter()
            .any(|w| w == "more than 2 of the 20 poses stand out from the rest: not a matter of gross readings, so none is set aside"),
        "{:?}",
        r.warnings
    );
}

#[test]
fn a_reading_nine_noise_deviations_off_is_set_aside() {
    // 2.5 um on the scale at a stated 0.29 um: its deleted residual, against
    // the scatter of the other poses (about 1), is far beyond the screen's
    // criterion (24.7 for 20 poses); against a scatter that counted it too
    // (about 4) it would not be.
    let m = Machine::paper();
    let mut data = campaign(&m, &[], 20, 9, 1.0);
    data.poses[6].readings.s_mm += 0.0025;
    data.poses[6].line = 77;
    let r = run(&m, &data);
    assert_eq!(r.rejected.len(), 1, "{:?}", r.rejected);
    assert_eq!((r.rejected[0].pose, r.rejected[0].line), (7, 77));
    assert!(
        (r.rejected[0].residual - 3.0).abs() < 0.5,
        "{:?}",
        r.rejected
    );
    assert_eq!(r.verdict, CheckVerdict::Unchanged);
}

#[test]
fn a_gross_reading_whose_pose_the_rest_needs_is_kept() {
    // Eight rows at four distinct poses: without the one pose that holds
    // the gross reading, three distinct poses are blind, so nothing is set
    // aside and the verdict is that of every pose.
    let m = Machine::paper();
    let t = m.workspace.random_poses(4, 11);
    let targets = [0, 1, 2, 3, 0, 1, 2, 0].map(|i| t[i]).to_vec();
    let data = Plant::geometric(m.clone(), ParameterSet::paper15().to_errors(&[0.0; 15]))
        .simulate(&Campaign::from_targets(&m, targets, 3))
        .unwrap();
    let mut bad = data.clone();
    bad.poses[3].readings.s_mm += 0.025;
    let r = run(&m, &bad);
    assert!(r.rejected.is_empty(), "{:?}", r.rejected);
    assert_eq!(r.poses, 8);
    assert!(r.consistency.statistic > r.consistency.critical);
    // The same reading at a pose that is repeated is set aside.
    let mut bad = data;
    bad.poses[0].readings.s_mm += 0.025;
    let r = run(&m, &bad);
    assert_eq!(r.rejected.len(), 1, "{:?}", r.rejected);
    assert_eq!(r.rejected[0].pose, 1);
    assert_eq!(r.rejected[0].column, "s");
}

#[test]
fn options_no_check_can_use_are_refused() {
    let m = Machine::paper();
    let data = campaign(&m, &[], 8, 1, 1.0);
    let reference = reference(&m);
    let good = CheckOptions::for_machine(&m);
    assert!(check(&reference, &data, &good).is_ok());
    let mut cases: Vec<(CheckOptions, &str)> = Vec::new();
    for alpha in [0.0, -0.01, 0.5, 0.7, f64::NAN] {
        cases.push((
            CheckOptions {
                alpha,
                ..good.clone()
            },
            "false-alarm probability",
        ));
    }
    for power in [0.0, -0.5, 1.0, 1.5, f64::NAN] {
        cases.push((
            CheckOptions {
                power,
                ..good.clone()
            },
            "power",
        ));
    }
    for c in 0..3 {
        for bad in [0.0, -1e-6, f64::NAN, f64::INFINITY] {
            let mut sigma = good.sigma;
            sigma[c] = bad;
            cases.push((
                CheckOptions {
                    sigma,
                    ..good.clone()
                },
                "noise",
            ));
        }
    }
    cases.push((
        CheckOptions {
            points_mm: Vec::new(),
            ..good.clone()
        },
        "evaluation points",
    ));
    for (options, what) in &cases {
        match check(&reference, &data, options) {
            Err(CheckError::Invalid(message)) => assert!(message.contains(what), "{message}"),
            other => panic!("{options:?}: {other:?}"),
        }
    }
    // Just inside the ranges.
    for (alpha, power) in [(0.49, 0.01), (1e-6, 0.999)] {
        let options = CheckOptions {
            alpha,
            power,
            ..good.clone()
        };
        let r = check(&reference, &data, &options).unwrap();
        assert_eq!(r.alpha, alpha);
    }
}

#[test]
fn three_distinct_poses_are_blind() {
    let m = Machine::paper();
    let mut data = campaign(&m, &[], 8, 1, 1.0);
    for j in 3..8 {
        data.poses[j].commands_mm = data.poses[j % 3].commands_mm;
    }
    let e = check(&reference(&m), &data, &CheckOptions::for_machine(&m)).unwrap_err();
    assert!(matches!(e, CheckError::Blind(_)), "{e:?}");
    data.poses[7].commands_mm = campaign(&m, &[], 8, 1, 1.0).poses[7].commands_mm;
    assert!(check(&reference(&m), &data, &CheckOptions::for_machine(&m)).is_ok());
}

#[test]
fn the_campaign_temperature_is_its_mean() {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let reference =
        Reference::new(m.clone(), set, DMatrix::zeros(15, 15), [0.0; 3], Some(20.0)).unwrap();
    let mut data = campaign(&m, &[], 10, 3, 1.0);
    let temps = [21.0, 22.0, 23.5, 20.5, 24.0, 22.0, 21.5, 23.0, 22.5, 25.0];
    for (p, t) in data.poses.iter_mut().zip(temps) {
        p.temp_c = Some(t);
    }
    // 225.0 / 10.
    let options = CheckOptions::for_machine(&m);
    let r = check(&reference, &data, &options).unwrap();
    assert_eq!(r.temperature_c, Some(22.5));
    assert!(r.candidates.iter().any(|c| c.name == "thermal growth"));
    assert!(
        r.to_text()
            .contains("structure temperature at the check: 22.50 °C")
    );
    for p in data.poses.iter_mut() {
        p.temp_c = p.temp_c.map(|t| t + 2.5);
    }
    let r = check(&reference, &data, &options).unwrap();
    assert_eq!(r.temperature_c, Some(25.0));
    // One pose without a temperature: no campaign temperature, no thermal
    // candidate.
    data.poses[4].temp_c = None;
    let r3 = check(&reference, &data, &options).unwrap();
    assert_eq!(r3.temperature_c, None);
    assert!(r3.candidates.iter().all(|c| c.name != "thermal growth"));
    assert!(!r3.to_text().contains("structure temperature"));
}

#[test]
fn the_report_shows_lengths_in_um_and_the_shortlist() {
    let m = Machine::paper();
    let mut r = run(&m, &campaign(&m, &[("dq2", 0.025)], 20, 2, 1.0));
    let b = r.most_likely.unwrap();
    {
        let c = &mut r.candidates[b];
        assert_eq!(c.parameters[0], "dq2_mm");
        c.estimate = vec![0.0253, 12.0, -40.0, 0.0];
        c.std_dev = vec![Some(0.0012), Some(5.0), Some(3.0), None];
        c.detectable = vec![Some(0.0049), Some(61.0), None, None];
        c.platform_mean_um = 17.26;
        c.platform_max_um = 31.5;
    }
    r.offsets_change = [0.0, 0.0, -0.00125];
    r.shortlist = vec!["leg 2".into(), "base joint B2".into()];
    let text = r.to_text();
    let first = text.lines().next().unwrap();
    assert_eq!(
        first,
        "verdict: CHANGED: most likely leg 2 (dq2 = +25.3 +- 1.2 um, lead2 = +12.0 +- 5.0 ppm, p2_leg2 = -40.0 +- 3.0 um), which moves the platform by 17.3 um on average and up to 31.5 um over the workspace"
    );
    let second = text.lines().nth(1).unwrap();
    assert!(
        second.starts_with("  the check cannot tell apart: leg 2, base joint B2 (each explains"),
        "{second}"
    );
    assert!(text.contains("s -1.25 um"), "{text}");
    let row = text.lines().find(|l| l.starts_with("leg 2 ")).unwrap();
    assert!(row.contains("dq2 4.9 um, lead2 61.0 ppm"), "{row}");
    // One candidate alone: no shortlist line.
    r.shortlist.truncate(1);
    assert!(!r.to_text().contains("cannot tell apart"));
}

#[test]
fn a_candidate_the_campaign_cannot_see_is_named() {
    // Every pose at the calibration's temperature: a thermal growth has no
    // effect on any reading (its columns are proportional to T - T_cal).
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let reference =
        Reference::new(m.clone(), set, DMatrix::zeros(15, 15), [0.0; 3], Some(20.0)).unwrap();
    let mut data = campaign(&m, &[], 20, 5, 1.0);
    for p in data.poses.iter_mut() {
        p.temp_c = Some(20.0);
    }
    let r = check(&reference, &data, &CheckOptions::for_machine(&m)).unwrap();
    let thermal = r
        .candidates
        .iter()
        .find(|c| c.name == "thermal growth")
        .unwrap();
    assert!(thermal.detectable.iter().all(Option::is_none));
    assert_eq!(
        r.warnings,
        vec!["this campaign cannot see a change of thermal growth".to_string()]
    );
    // A campaign that sees every candidate warns of none, and is not blind:
    // 20 spread poses see a leg's length change of a few um, not 1 mm.
    let r = run(&m, &campaign(&m, &[], 20, 5, 1.0));
    assert!(r.warnings.is_empty());
    assert!(!r.is_blind());
    assert!(r.smallest_detectable_mm().unwrap() < 0.1);
}

#[test]
fn a_pose_out_of_reach_is_named_by_its_number() {
    let m = Machine::paper();
    let mut data = campaign(&m, &[], 10, 6, 1.0);
    data.poses[2].commands_mm = [1e5, 1.0, 1.0];
    match check(&reference(&m), &data, &CheckOptions::for_machine(&m)) {
        Err(CheckError::Kinematics { pose, .. }) => assert_eq!(pose, 3),
        other => panic!("{other:?}"),
    }
}

#[test]
fn noise_free_changes_come_back_exactly() {
    // Without noise a slipped leg's length, fitted alone, is the slip (to
    // the linearisation, well under 1 %), and it moves the platform.
    let m = Machine::paper();
    let r = run(&m, &campaign(&m, &[("dq2", 0.025)], 20, 2, 0.0));
    let leg = r.candidates.iter().find(|c| c.name == "leg 2").unwrap();
    let (alone, sd) = leg.alone[0].unwrap();
    assert!((alone - 0.025).abs() < 2.5e-4, "{alone}");
    assert!(sd > 0.0 && sd < 0.25);
    // A leg's length change moves the platform by about as much (the legs
    // carry it), more in some places than others.
    let (mean, max) = (leg.platform_mean_um, leg.platform_max_um);
    assert!(mean > 0.25 * 25.0 && mean < 4.0 * 25.0, "{mean}");
    assert!(max > mean && max < 8.0 * 25.0, "{max}");
    // A sensor's gain moves no platform.
    let scale = r
        .candidates
        .iter()
        .find(|c| c.name == "scale gain")
        .unwrap();
    assert_eq!((scale.platform_mean_um, scale.platform_max_um), (0.0, 0.0));
}

#[test]
fn the_leg_ranges_hold_the_workspace_centre() {
    let m = Machine::paper();
    let ranges = leg_ranges(&m).unwrap();
    let centre = m
        .inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0))
        .unwrap()
        .legs_mm;
    for i in 0..3 {
        let (lo, hi) = ranges[i];
        assert!(
            lo > 100.0 && lo < centre[i] && centre[i] < hi,
            "leg {i}: {lo}..{hi}"
        );
    }
}

#[test]
fn sensors_a_thousand_times_noisier_are_blind() {
    let m = Machine::paper();
    let data = campaign(&m, &[], 20, 5, 1.0);
    let mut options = CheckOptions::for_machine(&m);
    assert!(!check(&reference(&m), &data, &options).unwrap().is_blind());
    options.sigma = options.sigma.map(|s| 1000.0 * s);
    let r = check(&reference(&m), &data, &options).unwrap();
    assert!(r.is_blind());
    assert!(r.smallest_detectable_mm().is_none_or(|d| d > 1.0));
}

#[test]
fn an_uncertain_calibration_is_checked_with_four_poses() {
    // More determined directions (15) than readings (12): the check still
    // runs, its consistency test on 12 - 3 degrees of freedom.
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let covariance = DMatrix::identity(15, 15) * 1e-4;
    let reference = Reference::new(m.clone(), set, covariance, [0.0; 3], None).unwrap();
    let data = campaign(&m, &[], 4, 9, 1.0);
    let r = check(&reference, &data, &CheckOptions::for_machine(&m)).unwrap();
    assert_eq!(r.consistency.dof, 9);
    assert_test(&r.consistency, 0.005, "consistency");
}

#[test]
fn a_campaign_that_sees_changes_only_beyond_a_millimetre_is_blind() {
    // Sensors 200 and 300 times noisier, a level of 1e-6 and a power of
    // 0.99: the legs and joints are seen, their smallest detectable change
    // on either side of 1 mm (the documented limit of a blind campaign).
    let m = Machine::paper();
    let data = campaign(&m, &[], 20, 5, 1.0);
    for (factor, blind) in [(200.0, false), (300.0, true)] {
        let mut options = CheckOptions::for_machine(&m);
        options.alpha = 1e-6;
        options.power = 0.99;
        options.sigma = options.sigma.map(|s| factor * s);
        let r = check(&reference(&m), &data, &options).unwrap();
        let d = r.smallest_detectable_mm().expect("a change is detectable");
        assert_eq!(d > 1.0, blind, "x{factor}: {d} mm");
        assert_eq!(r.is_blind(), blind, "x{factor}: {d} mm");
        // A parameter alone counts as seen only with a standard deviation
        // below its class-1 tolerance (0.25 mm, 250 um, 100 ppm/K, else
        // 1000 ppm); so noisy, some are not.
        let limit = |p: &str| match p {
            p if p.ends_with("_mm") => 0.25,
            p if p.ends_with("_um") => 250.0,
            p if p.ends_with("_ppm_per_k") => 100.0,
            _ => 1000.0,
        };
        let mut unseen = 0;
        for c in &r.candidates {
            for (p, alone) in c.parameters.iter().zip(&c.alone) {
                match alone {
                    Some((_, sd)) => assert!(*sd < limit(p), "{} {p}: {sd}", c.name),
                    None => unseen += 1,
                }
            }
        }
        assert!(unseen > 0, "x{factor}");
    }
}

#[test]
fn a_workspace_out_of_reach_names_its_first_pose() {
    // The workspace's polar grid 5 m above the machine: its first pose
    // (numbered from 1, no data line) is out of reach.
    let mut m = Machine::paper();
    m.workspace.z_min_mm = 5000.0;
    m.workspace.z_max_mm = 6000.0;
    match leg_ranges(&m) {
        Err(tricept_check::CheckError::Kinematics { pose, line, .. }) => {
            assert_eq!((pose, line), (1, 0));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_detectable_change_is_detected_with_the_stated_power() {
    // Each parameter alone: flagged beyond c sd (c the two-sided critical
    // value of the family-wise level) and detectable at delta sd, where the
    // test detects a change of delta sd with the stated power:
    // Phi(delta - c) + Phi(-delta - c) = power (Phi from the chi-square
    // tail of one degree of freedom: P(|Z| > x) = chi2_sf(x^2, 1)).
    use tricept_numerics::stats::chi2_sf;
    let phi = |x: f64| {
        let tail = 0.5 * chi2_sf(x * x, 1.0);
        if x < 0.0 { tail } else { 1.0 - tail }
    };
    let m = Machine::paper();
    let data = campaign(&m, &[], 20, 5, 1.0);
    let options = CheckOptions::for_machine(&m);
    let r = check(&reference(&m), &data, &options).unwrap();
    let mut seen = 0;
    for c in &r.candidates {
        for i in 0..c.parameters.len() {
            let (Some((_, sd)), Some(d), Some(f)) =
                (c.alone[i], c.detectable[i], c.flagged_beyond[i])
            else {
                continue;
            };
            let (critical, delta) = (f / sd, d / sd);
            let power = phi(delta - critical) + phi(-delta - critical);
            assert!(
                (power - options.power).abs() < 1e-6,
                "{} {}: {power}",
                c.name,
                c.parameters[i]
            );
            seen += 1;
        }
    }
    assert!(seen >= 10, "{seen}");
}

#[test]
fn the_most_likely_change_is_one_that_stands_out_beyond_the_noise() {
    // Leg 2 slipped by 40 um, the sensors 4 times noisier than stated, 20
    // poses. The slipped leg's best chi-square test (all four of its
    // nested parameters, which take up noise too) has the smallest p-value
    // of all, but does not stand out beyond the scatter it leaves (the F
    // test of crate::noise); a platform joint does. The most likely change
    // is chosen among the candidates that stand out (issue 32: a
    // non-significant candidate chosen would give "cause unknown").
    let m = Machine::paper();
    let r = run(&m, &campaign(&m, &[("dq2", 0.04)], 20, 102, 4.0));
    assert!(r.changed);
    let level = level(&m, false);
    let (t0, dof0) = (r.consistency.statistic, r.consistency.dof);
    // Each chi-square-significant candidate re-decided by the F test
    // against the scatter it leaves, when that scatter exceeds 1.
    for c in &r.candidates {
        let chi2_significant = c.test.statistic > c.test.critical;
        let nu = dof0 - c.test.dof;
        let scatter = (t0 - c.test.statistic) / nu as f64;
        let f = c.test.statistic / c.test.dof as f64 / scatter;
        let beyond = scatter <= 1.0 || f_sf(f, c.test.dof as f64, nu as f64) < level;
        assert_eq!(c.significant, chi2_significant && beyond, "{}", c.name);
    }
    let smallest = |significant: bool| {
        r.candidates
            .iter()
            .filter(|c| c.significant == significant)
            .map(|c| c.test.ln_p_value)
            .fold(f64::INFINITY, f64::min)
    };
    let leg2 = r.candidates.iter().find(|c| c.name == "leg 2").unwrap();
    assert!(!leg2.significant && leg2.test.ln_p_value == smallest(false));
    assert!(
        smallest(false) < smallest(true),
        "{} {}",
        smallest(false),
        smallest(true)
    );
    let best = &r.candidates[r.most_likely.expect("a most likely change")];
    assert!(best.significant, "{}", best.name);
    assert_eq!(best.test.ln_p_value, smallest(true));
    assert!(!r.to_text().contains("cause unknown"), "{}", r.to_text());
    // The leg, within a factor 20 of it, is not on the shortlist: it does
    // not stand out.
    assert!(leg2.test.ln_p_value <= best.test.ln_p_value + 20f64.ln());
    assert_shortlist(&r);
}
