//! The verdict on an identification, branch by branch (issue 32): every
//! warning, the adequacy test's p-value and the fit without degrees of
//! freedom.
//!
//! One real fit (the doctest's: Table 2's errors, the grid campaign) is
//! made once; each test then sets the statistics or the estimates the
//! verdict reads to values whose answer follows from the module's
//! documented rules and constants, with p-values from the closed form of
//! the chi-square with 2 degrees of freedom, `P(X > x) = exp(-x/2)`.

use std::sync::OnceLock;

use tricept_engine::{
    Identification, IdentifyOptions, identify, model::GeometricModel, verdict::ADEQUACY_ALPHA,
    verdict::BARELY_SEEN_STD_DEV_MM, verdict::INCONSISTENT_CHI2_PER_DOF,
    verdict::LARGE_ESTIMATE_MM,
};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_plant::{Campaign, Plant};

/// Identifies a machine whose errors are `truth` from the grid campaign.
fn fit(truth: &[f64]) -> Identification {
    let m = Machine::paper();
    let set = ParameterSet::paper15();
    let data = Plant::geometric(m.clone(), set.to_errors(truth))
        .simulate(&Campaign::grid(&m, 1))
        .unwrap();
    identify(
        &GeometricModel::new(m.clone(), set),
        &data,
        &IdentifyOptions::for_machine(&m),
    )
    .unwrap()
}

/// The fit of Table 2's errors: converged, adequate, no warning.
fn good() -> Identification {
    static FIT: OnceLock<Identification> = OnceLock::new();
    FIT.get_or_init(|| fit(&ParameterSet::paper15().table2()))
        .clone()
}

/// `id` with the statistics of a chi-square `chi2` on `dof` degrees of
/// freedom.
fn with_chi2(mut id: Identification, chi2: f64, dof: usize) -> Identification {
    id.stats.chi_square = chi2;
    id.stats.dof = dof;
    id.stats.reduced_chi_square = chi2 / dof as f64;
    id
}

fn has(warnings: &[String], text: &str) -> bool {
    warnings.iter().any(|w| w.contains(text))
}

const FAR: &str = "far from this machine";
const BARELY: &str = "the data barely see";
const NOT_CONVERGED: &str = "did NOT converge";
const NOT_EXPLAINED: &str = "does not explain the data";
const INCONSISTENT: &str = "cannot come from the described machine";

#[test]
fn a_good_fit_has_no_warning() {
    let id = good();
    assert!(id.converged);
    let v = id.verdict();
    assert!(v.converged && v.adequate && !v.inconsistent, "{v:?}");
    assert!(v.warnings.is_empty(), "{:?}", v.warnings);
    assert!(v.chi_square_p_value > ADEQUACY_ALPHA && v.chi_square_p_value < 1.0);
}

#[test]
fn the_p_value_is_the_chi_square_tail() {
    // Two degrees of freedom: p = exp(-x/2).
    for (x, adequate) in [(10.0, true), (13.0, true), (14.5, false), (16.0, false)] {
        let v = with_chi2(good(), x, 2).verdict();
        let p = (-x / 2.0f64).exp();
        assert!(
            (v.chi_square_p_value - p).abs() < 1e-12 * p,
            "{x}: {}",
            v.chi_square_p_value
        );
        assert_eq!(v.adequate, adequate, "chi2 {x}: p {p}");
        assert_eq!(v.adequate, p > ADEQUACY_ALPHA);
        assert_eq!(
            has(&v.warnings, NOT_EXPLAINED),
            !adequate,
            "{:?}",
            v.warnings
        );
        assert!(!v.inconsistent && !has(&v.warnings, INCONSISTENT));
    }
}

#[test]
fn a_fit_without_degrees_of_freedom_has_no_p_value_and_is_not_adequate() {
    for chi2 in [0.0, 0.5, 3.0, 100.0] {
        let mut id = good();
        id.stats.chi_square = chi2;
        id.stats.dof = 0;
        id.stats.reduced_chi_square = f64::NAN;
        let v = id.verdict();
        assert!(v.chi_square_p_value.is_nan(), "{chi2}: {v:?}");
        assert!(!v.adequate, "{chi2}");
        assert!(v.inconsistent, "{chi2}");
        assert!(has(&v.warnings, INCONSISTENT), "{:?}", v.warnings);
    }
}

#[test]
fn chi_square_per_dof_beyond_the_limit_is_inconsistent() {
    let dof = 100;
    let limit = INCONSISTENT_CHI2_PER_DOF * dof as f64;
    let v = with_chi2(good(), 0.5 * limit, dof).verdict();
    assert!(!v.inconsistent && !v.adequate);
    assert!(has(&v.warnings, NOT_EXPLAINED) && !has(&v.warnings, INCONSISTENT));
    let v = with_chi2(good(), 2.0 * limit, dof).verdict();
    assert!(v.inconsistent && !v.adequate);
    // One warning says it, not two.
    assert!(has(&v.warnings, INCONSISTENT) && !has(&v.warnings, NOT_EXPLAINED));
}

#[test]
fn a_fit_that_did_not_converge_says_so() {
    let mut id = good();
    id.converged = false;
    id.iterations = 37;
    let v = id.verdict();
    assert!(!v.converged);
    let w: Vec<&String> = v
        .warnings
        .iter()
        .filter(|w| w.contains(NOT_CONVERGED))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", v.warnings);
    assert!(w[0].contains("37 Gauss-Newton iterations"), "{}", w[0]);
}

#[test]
fn a_large_estimate_warns_that_the_description_is_far_from_the_machine() {
    let set = ParameterSet::paper15();
    let j = set.index_of("dq2").unwrap();
    // A leg 12 mm longer than drawn, really simulated.
    let mut truth = set.table2();
    truth[j] = 12.0;
    let id = fit(&truth);
    let v = id.verdict();
    assert!(v.converged && v.adequate && !v.inconsistent, "{v:?}");
    let far: Vec<&String> = v.warnings.iter().filter(|w| w.contains(FAR)).collect();
    assert_eq!(far.len(), 1, "{:?}", v.warnings);
    // It names the estimate, which is the simulated 12 mm within noise.
    let (estimate, sd) = (id.estimate[j], id.std_dev[j].unwrap());
    assert!((estimate - 12.0).abs() < 4.0 * sd, "{estimate} +- {sd}");
    let quoted = format!("dq2 = {estimate:.2} mm");
    assert!(far[0].starts_with(&quoted), "{}", far[0]);
    // Negative estimates count by their size.
    let mut id = good();
    id.estimate[j] = -1.5 * LARGE_ESTIMATE_MM;
    assert!(has(&id.verdict().warnings, FAR));
}

#[test]
fn the_large_estimate_limit_is_exclusive_and_silent_when_inconsistent() {
    let j = 4;
    let mut id = good();
    id.estimate[j] = LARGE_ESTIMATE_MM;
    assert!(!has(&id.verdict().warnings, FAR), "at the limit");
    id.estimate[j] = LARGE_ESTIMATE_MM * (1.0 + 1e-9);
    assert!(has(&id.verdict().warnings, FAR), "above the limit");
    // Data that cannot come from the machine at all: its estimates are
    // quoted in that warning, not judged on their own.
    let dof = id.stats.dof;
    let id = with_chi2(id, 10.0 * INCONSISTENT_CHI2_PER_DOF * dof as f64, dof);
    let v = id.verdict();
    assert!(v.inconsistent);
    assert!(!has(&v.warnings, FAR), "{:?}", v.warnings);
    let name = &id.names[j];
    assert!(
        has(&v.warnings, &format!("estimates up to 10.0 mm ({name})")),
        "{:?}",
        v.warnings
    );
}

#[test]
fn parameters_the_data_barely_see_are_named() {
    let mut id = good();
    let (a, b) = (1, 6);
    assert!(id.std_dev[a].is_some() && id.std_dev[b].is_some());
    id.std_dev[a] = Some(BARELY_SEEN_STD_DEV_MM);
    assert!(!has(&id.verdict().warnings, BARELY), "at the limit");
    id.std_dev[a] = Some(2.5);
    id.std_dev[b] = Some(1.25);
    id.estimate[a] = 0.1234;
    let v = id.verdict();
    let w: Vec<&String> = v.warnings.iter().filter(|w| w.contains(BARELY)).collect();
    assert_eq!(w.len(), 1, "{:?}", v.warnings);
    let first = format!("{} = 0.123 +- 2.500 mm", id.names[a]);
    let second = format!("{} = ", id.names[b]);
    assert!(w[0].contains(&first) && w[0].contains(&second), "{}", w[0]);
    assert!(w[0].contains("+- 1.250 mm"), "{}", w[0]);
    // A fixed parameter (no standard deviation) is not among them.
    assert!(!w[0].contains(&format!("{} =", id.names[0])), "{}", w[0]);
    // The fit itself is still adequate: a warning, not a verdict.
    assert!(v.adequate && v.converged);
}
