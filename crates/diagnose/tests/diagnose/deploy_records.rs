//! What a deployment writes besides the refitted geometry: the lines it
//! records rather than applies, and the compensation tables of the generic
//! leg terms (their spacing, their extent, their values), against the
//! documented rules (the constants of `deploy.rs`: 24 points per period,
//! 200 spacings over a stroke without one, a step's ramp at most half of
//! `MAX_TABLE_SLOPE_UM_PER_MM`) and the simulator's inputs. The terms
//! under test are set by hand as the model terms of a diagnosis (the
//! deployment reads nothing else of it but its outliers, cleared here).

use std::sync::OnceLock;

use tricept_data::Dataset;
use tricept_diagnose::{
    Deployed, Diagnosis, deploy, diagnose, report::CauseName, report::ModelTerm,
    terms::GenericFamily,
};
use tricept_kinematics::Machine;
use tricept_kinematics::description::{LegTableDescription, MAX_TABLE_SLOPE_UM_PER_MM};
use tricept_model::effects::EffectName;
use tricept_plant::effects::{Effect, LegStep};

use crate::common::{CampaignOptions, simulate};

/// The pitch fixture (`leg-periodic`: 4 um on every leg, period 10 mm,
/// phases 0, 120 and 240 deg, its header) and its diagnosis, the
/// terms and outliers of which the tests replace.
fn pitch() -> &'static (Dataset, Diagnosis) {
    static PITCH: OnceLock<(Dataset, Diagnosis)> = OnceLock::new();
    PITCH.get_or_init(|| {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/data/diagnose-pitch.csv"
        );
        let data = tricept_data::read_path(path.as_ref()).expect("the pitch fixture");
        let options = tricept_diagnose::DiagnoseOptions::for_machine(&Machine::paper());
        let d = diagnose(&Machine::paper(), &data, &options).expect("diagnosis");
        (data, d)
    })
}

/// A model term of family `family` (or effect) on `legs` or `channel`.
fn term(effect: CauseName, legs: &[u8], channel: Option<u8>, deployed: bool) -> ModelTerm {
    ModelTerm {
        effect,
        description: String::new(),
        legs: legs.to_vec(),
        channel,
        period_mm: None,
        edges_mm: None,
        deployed,
        improvement_mm: None,
        improvement_sd_mm: None,
        difference_sd_mm: None,
        holdout_benefit_mm: None,
        holdout_benefit_sd_mm: None,
        expected_rms_with_mm: None,
        expected_rms_without_mm: None,
        kept_back_because: (!deployed).then(|| "a reason".to_string()),
    }
}

/// Deploys `terms` on `data` through the pitch fixture's diagnosis.
fn deploy_terms(data: &Dataset, terms: Vec<ModelTerm>) -> Deployed {
    let mut d = pitch().1.clone();
    d.model_terms = terms;
    d.causes.clear();
    deploy(&Machine::paper(), None, data, &d).expect("deploy")
}

/// The smallest and largest command of leg `leg` (0-2) in `data`.
fn stroke(data: &Dataset, leg: usize) -> (f64, f64) {
    let q = data.poses.iter().map(|p| p.commands_mm[leg]);
    (
        q.clone().fold(f64::INFINITY, f64::min),
        q.fold(f64::NEG_INFINITY, f64::max),
    )
}

/// The table of leg `leg` (1-3).
fn table(d: &Deployed, leg: u8) -> &LegTableDescription {
    d.geometry
        .leg_effects
        .tables
        .iter()
        .find(|t| t.leg == leg)
        .unwrap_or_else(|| panic!("no table of leg {leg}: {:?}", d.applied))
}

/// Its table spans the campaign's stroke of the leg exactly, in equal
/// spacings no wider than `widest_mm`, with no more points than needed.
fn assert_spans(t: &LegTableDescription, (lo, hi): (f64, f64), widest_mm: f64) {
    let n = t.extra_length_um.len();
    assert_eq!(
        t.start_mm, lo,
        "leg {}: starts at the smallest command",
        t.leg
    );
    let end = t.start_mm + t.step_mm * (n - 1) as f64;
    assert!(
        (end - hi).abs() < 1e-9 * hi,
        "leg {}: ends at {end}, not {hi}",
        t.leg
    );
    assert!(
        t.step_mm <= widest_mm * (1.0 + 1e-12),
        "leg {}: spacing {} over {widest_mm}",
        t.leg,
        t.step_mm
    );
    let fewest = ((hi - lo) / widest_mm - 1e-9).ceil() as usize + 1;
    assert!(
        n <= fewest + 1,
        "leg {}: {n} points, {fewest} suffice",
        t.leg
    );
}

/// The number after `key` in `text` (up to the next space).
fn number_after(text: &str, key: &str) -> f64 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("no {key:?} in {text}"))
        + key.len();
    let word = text[at..].split([' ', ')']).next().unwrap_or("");
    word.parse()
        .unwrap_or_else(|_| panic!("{word:?} after {key:?} in {text}"))
}

/// The fitted value of the parameter named `name` (its ending).
fn fitted(d: &Deployed, name: &str) -> f64 {
    let at =
        d.id.names
            .iter()
            .position(|n| n.ends_with(name))
            .unwrap_or_else(|| panic!("no {name} in {:?}", d.id.names));
    d.id.estimate[at]
}

#[test]
fn records_sensor_and_time_terms_and_the_terms_not_worth_deploying() {
    let data = &pitch().0;
    let generic = |f| CauseName::Generic(f);
    let mut not_worth = term(generic(GenericFamily::LegPolynomial), &[3], None, false);
    not_worth.description = "leg-polynomial:leg3".into();
    not_worth.holdout_benefit_mm = Some(0.0123);
    not_worth.holdout_benefit_sd_mm = Some(0.0045);
    let mut unmeasured = term(generic(GenericFamily::LegPolynomial), &[1], None, false);
    unmeasured.description = "leg-polynomial:leg1".into();
    unmeasured.improvement_mm = Some(0.5);
    let d = deploy_terms(
        data,
        vec![
            term(generic(GenericFamily::ScalePolynomial), &[], Some(2), true),
            term(generic(GenericFamily::EncoderGain), &[], Some(0), true),
            term(generic(GenericFamily::LegDrift), &[1, 2, 3], None, true),
            term(CauseName::Catalogue(EffectName::ScaleGain), &[], None, true),
            not_worth,
            unmeasured,
        ],
    );
    let line = |start: &str| -> String {
        d.recorded
            .iter()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no recorded line {start}: {:#?}", d.recorded))
            .clone()
    };
    // Reading terms: sensor corrections of their channel (phi, theta, s).
    assert!(line("scale-polynomial:s: ").contains("a sensor correction of the s reading"));
    assert!(line("encoder-gain:phi: ").contains("a sensor correction of the phi reading"));
    // The legs' drift: a time term, at the campaign's middle time.
    let times: Vec<f64> = data
        .poses
        .iter()
        .map(|p| p.time_s.expect("time logged"))
        .collect();
    let middle = 0.5
        * (times.iter().copied().fold(f64::INFINITY, f64::min)
            + times.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    assert!(middle > 100.0, "{middle}");
    let drift = line("leg-drift:legs: ");
    assert!(drift.contains("a time term"), "{drift}");
    assert!(drift.ends_with(&format!("(time_s {middle:.0})")), "{drift}");
    // A sensor-side effect of the vocabulary is recorded, not applied.
    let gain = format!("{}: ", EffectName::ScaleGain);
    line(&gain);
    assert!(
        !d.applied.iter().any(|l| l.starts_with(&gain)),
        "{:#?}",
        d.applied
    );
    // Terms seen but not worth deploying, with their numbers.
    let seen = line("leg-polynomial:leg3: seen, not worth deploying");
    assert!(
        seen.contains("out-of-sample benefit 0.0123 +- 0.0045 mm, improvement not computed mm"),
        "{seen}"
    );
    let seen = line("leg-polynomial:leg1: seen, not worth deploying");
    assert!(
        seen.contains("out-of-sample benefit not computed mm, improvement not computed mm"),
        "{seen}"
    );
    // And why each was kept back.
    assert!(seen.contains("; kept back because a reason;"), "{seen}");
    // Neither applies a table; nothing else is applied but the scale gain's absence.
    assert!(d.geometry.leg_effects.tables.is_empty(), "{:?}", d.applied);
}

#[test]
fn a_pitch_table_carries_the_simulated_sine_on_24_points_a_period() {
    let data = &pitch().0;
    let mut pitch_term = term(
        CauseName::Generic(GenericFamily::LegPeriodic),
        &[1, 2, 3],
        None,
        true,
    );
    pitch_term.period_mm = Some(10.0);
    let d = deploy_terms(data, vec![pitch_term]);
    for (leg, phase_deg) in [(1u8, 0.0f64), (2, 120.0), (3, 240.0)] {
        let t = table(&d, leg);
        assert_spans(t, stroke(data, usize::from(leg - 1)), 10.0 / 24.0);
        // The simulated error, 4 um sin(2 pi q / 10 mm + phase), to within
        // 1 um (the fit's noise) at every point.
        for (k, v) in t.extra_length_um.iter().enumerate() {
            let q = t.start_mm + t.step_mm * k as f64;
            let truth = 4.0 * (std::f64::consts::TAU * q / 10.0 + phase_deg.to_radians()).sin();
            assert!(
                (v - truth).abs() < 1.0,
                "leg {leg} at {q} mm: {v} um, simulated {truth} um"
            );
        }
        // Linear interpolation of A sin(2 pi q / P) over a spacing h misses
        // it at the midpoint by A |sin| (1 - cos(pi h / P)); the midpoints,
        // 1/24 of a period apart, come within 1/48 of a period of a crest.
        let amplitude_um =
            fitted(&d, &format!("leg{leg}_sin_um")).hypot(fitted(&d, &format!("leg{leg}_cos_um")));
        assert!((amplitude_um - 4.0).abs() < 1.0, "{amplitude_um}");
        let most = amplitude_um * (1.0 - (std::f64::consts::PI * t.step_mm / 10.0).cos());
        let worst = number_after(&t.source, "largest interpolation error ");
        assert!(
            worst <= most + 5e-4 && worst >= (std::f64::consts::PI / 48.0).cos() * most - 5e-4,
            "leg {leg}: {worst} um, at most {most} um: {}",
            t.source
        );
    }
    // The pitch is known only over the stroke measured; a step (below) is
    // not periodic.
    for leg in 1..=3 {
        assert!(
            table(&d, leg)
                .source
                .contains("(a periodic error is known only where the campaign measured it)"),
            "{}",
            table(&d, leg).source
        );
    }
    // A table is applied, not recorded.
    assert!(d.recorded.is_empty(), "{:#?}", d.recorded);
    assert_eq!(
        d.applied
            .iter()
            .filter(|l| l.contains("compensation table"))
            .count(),
        3,
        "{:#?}",
        d.applied
    );
}

#[test]
fn a_step_table_ramps_within_its_slope_share_and_a_polynomial_takes_200_spacings() {
    let s = simulate(
        80,
        3,
        vec![Effect::from(LegStep {
            um: [20.0, 0.0, 0.0],
            from_mm: 760.0,
            to_mm: 900.0,
        })],
        CampaignOptions::default(),
    );
    let mut step = term(CauseName::Generic(GenericFamily::LegStep), &[1], None, true);
    // The edges a fifth of a spacing past the simulated ones (which the
    // fit hardly notices): the table ramps mostly beyond each edge.
    let edges_mm = [760.05, 900.07];
    step.edges_mm = Some(edges_mm);
    let polynomial = term(
        CauseName::Generic(GenericFamily::LegPolynomial),
        &[2],
        None,
        true,
    );
    let d = deploy_terms(&s.data, vec![step, polynomial]);
    let (lo, hi) = stroke(&s.data, 0);
    assert!(lo < 760.0 && hi > 900.0, "{lo} to {hi}");
    // The step (simulated 20 um, fitted to within 2 um) ramps over one
    // spacing, its slope at most half of what a table may have: a spacing
    // of |step| / (200 / 2) mm, finer than 200 spacings over the stroke.
    let t = table(&d, 1);
    let step_um = fitted(&d, "leg1_um").abs();
    assert!((step_um - 20.0).abs() < 2.0, "{step_um}");
    let ramp_mm = step_um / (0.5 * MAX_TABLE_SLOPE_UM_PER_MM);
    assert!(ramp_mm < (hi - lo) / 200.0, "{ramp_mm}");
    assert_spans(t, (lo, hi), ramp_mm);
    let mean = |inside: bool| {
        let v: Vec<f64> = t
            .extra_length_um
            .iter()
            .enumerate()
            .filter(|(k, _)| {
                let q = t.start_mm + t.step_mm * *k as f64;
                if inside {
                    (770.0..=890.0).contains(&q)
                } else {
                    !(750.0..=910.0).contains(&q)
                }
            })
            .map(|(_, v)| *v)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    assert!(
        (mean(true) - mean(false) - 20.0).abs() < 2.0,
        "{} {}",
        mean(true),
        mean(false)
    );
    assert!(
        t.source.contains("at a step's edge (760.050, 900.070 mm)"),
        "{}",
        t.source
    );
    assert!(!t.source.contains("periodic"), "{}", t.source);
    // Away from the edges the step is constant: interpolation is exact.
    assert_eq!(
        number_after(&t.source, "largest interpolation error "),
        0.0,
        "{}",
        t.source
    );
    // Beside an edge at a fraction f of its spacing the table has ramped f
    // of the step (1 - f on the far side): the larger share of the step.
    let fraction = |e: f64| ((e - t.start_mm) / t.step_mm).fract();
    assert!(
        edges_mm.iter().all(|e| fraction(*e) < 0.5),
        "{:?}",
        edges_mm.map(fraction)
    );
    let at_edges = step_um
        * edges_mm
            .map(|e| 1.0 - fraction(e))
            .into_iter()
            .fold(0.0, f64::max);
    let reported = number_after(&t.source, "that holds it, up to ");
    assert!(
        (reported - at_edges).abs() < 1e-3 + 1e-4 * at_edges,
        "{reported} um, expected {at_edges} um: {}",
        t.source
    );
    // An edge at the stroke's end is not inside it: no ramp there.
    for (edges, inside) in [([lo, 900.0], "900.000"), ([760.0, hi], "760.000")] {
        let mut step = term(CauseName::Generic(GenericFamily::LegStep), &[1], None, true);
        step.edges_mm = Some(edges);
        let d = deploy_terms(&s.data, vec![step]);
        let source = &table(&d, 1).source;
        assert!(
            source.contains(&format!("at a step's edge ({inside} mm)")),
            "{source}"
        );
    }
    // A polynomial alone: 200 spacings over the stroke.
    let (lo2, hi2) = stroke(&s.data, 1);
    assert_spans(table(&d, 2), (lo2, hi2), (hi2 - lo2) / 200.0);
    assert!(table(&d, 2).extra_length_um.len() >= 201);
}

#[test]
fn an_effect_with_a_parameter_per_leg_deploys_each_to_its_leg() {
    // A lead error of 80, -60 and 30 ppm (simulated), fitted to within
    // 10 ppm, each in its own leg's slot of the machine file.
    let truth = [80.0, -60.0, 30.0];
    let s = simulate(
        80,
        5,
        vec![Effect::from(tricept_plant::effects::LegLead { ppm: truth })],
        CampaignOptions::default(),
    );
    let d = deploy_terms(
        &s.data,
        vec![term(
            CauseName::Catalogue(EffectName::LegLead),
            &[],
            None,
            true,
        )],
    );
    let lead = d.geometry.leg_effects.lead_ppm;
    for leg in 0..3 {
        assert!((lead[leg] - truth[leg]).abs() < 10.0, "{lead:?}");
    }
    let applied = format!("{}: ", EffectName::LegLead);
    assert!(
        d.applied.iter().any(|l| l.starts_with(&applied)),
        "{:#?}",
        d.applied
    );
    assert!(d.recorded.is_empty(), "{:#?}", d.recorded);
}

#[test]
fn a_polynomial_table_reports_its_largest_interpolation_error_anywhere_on_the_stroke() {
    // A cubic leg error, 60 um ((q - 600 mm) / 100 mm)^3 on leg 3 (its
    // stroke lies above 600 mm, so the power is a polynomial there):
    // its curvature, and the table's interpolation error with it, grows
    // along the stroke and is largest in the last spacing.
    let s = simulate(
        80,
        11,
        vec![Effect::from(tricept_plant::effects::LegPower {
            um: [0.0, 0.0, 60.0],
            exponent: 3.0,
            centre_mm: 600.0,
            half_width_mm: 100.0,
        })],
        CampaignOptions::default(),
    );
    let (lo, hi) = stroke(&s.data, 2);
    assert!(lo > 600.0, "{lo}");
    let d = deploy_terms(
        &s.data,
        vec![term(
            CauseName::Generic(GenericFamily::LegPolynomial),
            &[3],
            None,
            true,
        )],
    );
    let t = table(&d, 3);
    assert_spans(t, (lo, hi), (hi - lo) / 200.0);
    // The fitted polynomial by its documented basis: p1 x + p2 P2(x) +
    // p3 P3(x) um, x the command mapped from the stroke onto [-1, 1].
    let p = ["leg3_p1_um", "leg3_p2_um", "leg3_p3_um"].map(|n| fitted(&d, n));
    let f_um = |q: f64| {
        let x = (2.0 * q - lo - hi) / (hi - lo);
        p[0] * x + p[1] * 0.5 * (3.0 * x * x - 1.0) + p[2] * 0.5 * (5.0 * x.powi(3) - 3.0 * x)
    };
    let n = t.extra_length_um.len();
    let at = |k: usize| t.start_mm + t.step_mm * k as f64;
    for (k, v) in t.extra_length_um.iter().enumerate() {
        // The table's values differ from the polynomial by one constant
        // (a leg offset belongs to the geometry).
        let shift = t.extra_length_um[0] - f_um(at(0));
        assert!(
            (v - shift - f_um(at(k))).abs() < 1e-6,
            "{v} at {} mm",
            at(k)
        );
    }
    // The error of linear interpolation at each spacing's midpoint.
    let errors: Vec<f64> = (0..n - 1)
        .map(|k| (0.5 * (f_um(at(k)) + f_um(at(k + 1))) - f_um(0.5 * (at(k) + at(k + 1)))).abs())
        .collect();
    let largest = errors.iter().copied().fold(0.0, f64::max);
    let first_half = errors[..n / 2].iter().copied().fold(0.0, f64::max);
    // The simulated curvature makes the last spacings' error stand out.
    assert!(largest > 1.4 * first_half + 2e-3, "{largest} {first_half}");
    let reported = number_after(&t.source, "largest interpolation error ");
    assert!(
        (reported - largest).abs() < 6e-4,
        "{reported} um, expected {largest} um: {}",
        t.source
    );
}
