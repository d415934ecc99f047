//! The settings of a diagnosis ([`DiagnoseOptions`]) and of its generic
//! dictionary ([`DictionaryOptions`]).

use tricept_kinematics::Machine;

use crate::plausibility::Plausibility;

/// Options of [`crate::diagnose`].
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseOptions {
    /// Standard deviation of one logged reading `[phi, theta, s]` (rad, rad, mm).
    pub sigma: [f64; 3],
    /// Family-wise significance level of the tests.
    pub alpha: f64,
    /// Folds of the cross-validation.
    pub folds: usize,
    /// Largest number of causes named.
    pub max_causes: usize,
    /// Lattice of the middle-plane comparison, mm.
    pub plane_spacing_mm: f64,
    /// Largest share of poses that may be called outliers.
    pub max_outlier_share: f64,
    /// The generic dictionary.
    pub dictionary: DictionaryOptions,
    /// Physical ranges of the effects.
    pub plausibility: Plausibility,
    /// Estimate the noise from repeated poses and use it in every test.
    pub noise_from_data: bool,
    /// Poses whose commands agree within this are repeats, mm.
    pub repeat_tolerance_mm: f64,
    /// Standard deviation of the logged temperature, K.
    pub temperature_sigma_k: f64,
    /// A fit needing a geometric error larger than this has failed, mm.
    pub max_error_mm: f64,
    /// The machine whose rank decision the fits use (the nominal machine
    /// of a calibrated one: docs/identifiability.md); `None`: the machine
    /// diagnosed.
    pub rank_reference: Option<Machine>,
    /// How a term of the final model is judged worth deploying
    /// ([`DeployRule`]; default [`DeployRule::ExpectedError`]).
    pub deploy_rule: DeployRule,
}

/// How a term of the final model is judged worth deploying. Both deploy a
/// term only when its out-of-sample benefit exceeds
/// [`crate::report::DEPLOY_BENEFIT_SD`] standard deviations; they differ where the
/// readings cannot see (the weak leg-length direction,
/// `docs/diagnosis.md`, "Deploy by what the file will deliver").
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_diagnose::{options::DeployRule, DiagnoseOptions};
use tricept_kinematics::Machine;
let mut options = DiagnoseOptions::for_machine(&Machine::paper());
assert_eq!(options.deploy_rule, DeployRule::ExpectedError);
options.deploy_rule = "confident".parse().unwrap();
assert_eq!(options.deploy_rule, DeployRule::Confident);
```
"#
)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DeployRule {
    /// The term's predicted improvement exceeds
    /// [`crate::report::DEPLOY_IMPROVEMENT_SD`] standard deviations of what the file
    /// does not know, or the term moves the platform where the readings
    /// cannot see by no more than they see it gain: the rule before the
    /// expected error (`--deploy-rule confident`). It keeps back terms whose
    /// files are expected better (pitch errors among them), for a larger sum
    /// of delivered errors over the tallies of `docs/reliability.md`.
    Confident,
    /// The default: what [`DeployRule::Confident`] deploys, and also a term
    /// whose file has the smaller expected error
    /// ([`crate::report::ModelTerm::expected_rms_with_mm`]) by a predicted
    /// improvement of at least one standard deviation: the file the report
    /// expects to be best. Measured in truth (`docs/reliability.md`, "Deployed
    /// terms that pay in truth"): the sum of delivered errors lower on every
    /// tally; 3 of 439 files more than 10 % worse than the geometric-only
    /// one (each explained there), none under the confident rule.
    #[default]
    ExpectedError,
}

impl DeployRule {
    /// The rule's name on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            DeployRule::Confident => "confident",
            DeployRule::ExpectedError => "expected-error",
        }
    }
}

impl std::str::FromStr for DeployRule {
    type Err = String;
    fn from_str(s: &str) -> Result<DeployRule, String> {
        [DeployRule::Confident, DeployRule::ExpectedError]
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| format!("unknown deploy rule {s:?} (confident, expected-error)"))
    }
}

/// Smallest degrees of freedom of pure error per channel for
/// `noise_from_data`.
pub const MIN_PURE_ERROR_DOF: usize = 10;

impl DiagnoseOptions {
    /// Defaults with the logged noise of `machine`'s sensors.
    pub fn for_machine(machine: &Machine) -> DiagnoseOptions {
        DiagnoseOptions {
            sigma: machine.sensors.logged_sigma(),
            alpha: 1e-3,
            folds: 5,
            max_causes: 4,
            plane_spacing_mm: 50.0,
            max_outlier_share: 0.1,
            dictionary: DictionaryOptions::default(),
            plausibility: Plausibility::default(),
            noise_from_data: false,
            repeat_tolerance_mm: 1e-3,
            temperature_sigma_k: 0.02,
            max_error_mm: 20.0,
            rank_reference: None,
            deploy_rule: DeployRule::default(),
        }
    }
}

/// Settings of the generic dictionary.
#[derive(Debug, Clone, PartialEq)]
pub struct DictionaryOptions {
    /// Search the dictionary at all (off: the vocabulary only).
    pub enabled: bool,
    /// Shortest and longest period of the ball-screw scan, mm.
    pub period_range_mm: (f64, f64),
    /// Grid points per independent frequency of the scan.
    pub oversampling: f64,
    /// Cells of the step scan's grid over each leg's stroke (its
    /// `K (K + 1) / 2 - 1` pairs of edges each count in the multiplicity;
    /// 0: no step scan).
    pub step_cells: usize,
    /// Best-ranked groups refitted exactly at each selection step.
    pub refit_top: usize,
}

impl Default for DictionaryOptions {
    fn default() -> DictionaryOptions {
        DictionaryOptions {
            enabled: true,
            period_range_mm: (4.0, 50.0),
            oversampling: 4.0,
            step_cells: 16,
            refit_top: 3,
        }
    }
}
