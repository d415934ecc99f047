//! What a diagnosis reports: the geometric model's adequacy, the named
//! causes with their parameters and evidence, the bias they had put into
//! the geometric parameters, and the gain of the extended model; as data
//! (serialised to JSON by `serde`) and as text for people.

use serde::Serialize;
use serde::ser::{SerializeMap, Serializer};
use serde_json::Value;
use tricept_kinematics::units::RAD_PER_ARCSEC;
pub use tricept_model::effects::CauseName;

/// The statistical evidence for one candidate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evidence {
    /// Drop of chi-square when the effect is added.
    pub delta_chi_square: f64,
    /// Identifiable parameters the effect adds (the test's degrees of freedom).
    pub dof: usize,
    /// Likelihood-ratio p-value (of the drop divided by the residual
    /// variance factor of the larger model, never below 1).
    pub p_value: f64,
    /// The p-value it had to beat (its half of `alpha` divided by the
    /// multiplicity).
    pub threshold: f64,
    /// BIC improvement (`delta_chi_square - dof ln N`; positive favours the effect).
    pub delta_bic: f64,
    /// Held-out weighted residual RMS without the effect (noise = 1);
    /// `null` when a fold could not be fitted.
    pub holdout_rms_without: Option<f64>,
    /// Held-out weighted residual RMS with the effect.
    pub holdout_rms_with: Option<f64>,
    /// Whether every criterion passed.
    pub selected: bool,
    /// Number of tests of its half of the pool (catalogue candidates, or
    /// the dictionary's groups with every scan period).
    pub multiplicity: usize,
    /// `p_value` times `multiplicity` (at most 1).
    pub p_adjusted: f64,
    /// `delta_chi_square - dof ln N - 2 ln m` (`m` the alternatives of its
    /// family): the penalised gain that ranks admissible candidates.
    pub penalised_gain: f64,
}

/// An estimated parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Name (unit in the name).
    pub name: String,
    /// Value.
    pub value: f64,
    /// Standard deviation (`None` when unidentifiable and held at zero).
    pub std_dev: Option<f64>,
}

/// What kind of cause.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CauseKind {
    /// An effect of the vocabulary.
    Catalogue,
    /// A term of the generic dictionary: an effect outside the vocabulary,
    /// described by its form.
    Generic,
    /// Gross reading errors.
    Outliers,
}

/// A named cause.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cause {
    /// The effect: a name of the vocabulary or a generic family.
    pub effect: CauseName,
    /// Catalogue, generic or outliers.
    pub kind: CauseKind,
    /// What was found, in words a machine builder can act on.
    pub description: String,
    /// Every quantity within its physical range (always true for a named
    /// cause: implausible fits are listed under `rejected`).
    pub plausible: bool,
    /// Its parameters in the final model.
    #[serde(serialize_with = "estimates_by_name")]
    pub parameters: Vec<Estimate>,
    /// Its evidence in the final model (the final model against the final
    /// model without it).
    pub evidence: Evidence,
    /// Lines of the data file flagged (outliers only).
    pub rows: Vec<u64>,
    /// The reading channel of a generic reading term (`phi`, `theta`, `s`).
    pub channel: Option<&'static str>,
    /// The legs of a generic leg term (1-3).
    pub legs: Vec<u8>,
}

/// Candidates that this campaign cannot tell apart.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Alias {
    /// The member in the final model first, then its alternatives.
    pub effects: Vec<CauseName>,
    /// The groups, in words (`reading-drift:s`, `leg-lead (equal on all legs)`).
    pub descriptions: Vec<String>,
    /// Why they cannot be told apart.
    pub why: String,
    /// What measurement would separate them.
    pub separate_by: String,
    /// True when the signatures are identical for any campaign of these
    /// sensors (not just this one).
    pub exact: bool,
    /// The part of the fitted signature the best alternative leaves
    /// unexplained (chi-square units; below the 1-dof critical value at
    /// `alpha` no test could prefer one member).
    pub lambda_unexplained: f64,
    /// The member kept in the final model (its predictions equal the
    /// alternatives' to within the noise).
    pub in_model: CauseName,
    /// The alternatives' parameters that reproduce the fitted signature.
    #[serde(serialize_with = "estimates_by_name")]
    pub parameters: Vec<Estimate>,
}

/// Where a fit was turned down.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RejectStage {
    /// A quantity outside its physical range.
    Plausibility,
    /// Significant, but no better on held-out poses.
    Holdout,
    /// Removed by the admission on the final model.
    FinalEvidence,
    /// An alternative of an alias whose implied parameters are implausible.
    ImplausibleAlias,
}

/// A fit that was not named as a cause, with the reason.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rejected {
    /// The effect or family.
    pub effect: CauseName,
    /// The group (`reading-drift:s`).
    pub description: String,
    /// Its fitted parameters.
    #[serde(serialize_with = "estimates_by_name")]
    pub parameters: Vec<Estimate>,
    /// Why it is not a cause.
    pub reason: String,
    /// Where it was turned down.
    pub stage: RejectStage,
}

/// The best generic term at the final model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TermScore {
    /// Its family.
    pub effect: CauseName,
    /// The group.
    pub description: String,
    /// Linearised drop of chi-square it would give.
    pub delta_chi_square: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// Adjusted p-value (dictionary multiplicity).
    pub p_adjusted: f64,
    /// Why it is not a named cause.
    pub why_not_named: String,
}

/// What the final model leaves unexplained.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Remainder {
    /// Chi-square of the final model.
    pub chi_square: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// Its p-value.
    pub p_value: f64,
    /// Cross-validated held-out RMS of the final model (noise = 1).
    pub holdout_rms: f64,
    /// Strongest residual correlations of the final model.
    pub structure: Vec<Structure>,
    /// The best generic term at the final model.
    pub strongest_term: Option<TermScore>,
    /// One line for people.
    pub text: String,
}

/// The final model's fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FinalFit {
    /// Chi-square (with the temperature logger's noise in the variance of
    /// readings that depend on temperature).
    pub chi_square: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// p-value of the adequacy test.
    pub p_value: f64,
}

/// Which noise the tests used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoiseSource {
    /// The stated sensor noise.
    Stated,
    /// The noise estimated from repeated poses (`--noise-from-data`).
    Data,
}

/// The pure error of repeated poses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PureError {
    /// Groups of poses with the same commands.
    pub groups: usize,
    /// Degrees of freedom per channel (poses in groups minus groups).
    pub dof: usize,
    /// The data's noise of one logged reading.
    pub sigma: ChannelRms,
    /// Data's noise over the stated noise, per channel `[phi, theta, s]`.
    pub ratio: [f64; 3],
    /// Two-sided p-value of each ratio against 1 (chi-square).
    pub p_value: [f64; 3],
    /// Repeats logged in consecutive rows with the same approach: they
    /// miss repositioning and vibration between visits.
    pub within_visit: usize,
}

/// The check of the stated noise against the data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NoiseCheck {
    /// The stated noise of one logged reading.
    pub stated: ChannelRms,
    /// The noise the tests used.
    pub used: NoiseSource,
    /// The pure error, when poses were repeated.
    pub pure_error: Option<PureError>,
    /// Whether the stated noise and the data's agree (`null` without
    /// repeated poses).
    pub agrees: Option<bool>,
    /// One line for people.
    pub note: String,
}

/// The verdict of a diagnosis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// The geometric model explains the data; nothing is named.
    Adequate,
    /// Causes (or an alias set) are named and the final model explains the data.
    Explained,
    /// Causes are named but the final model does not explain the data: a
    /// remainder is reported.
    PartiallyExplained,
    /// The data are not explained and nothing admissible is found.
    Unexplained,
}

/// A residual correlation with a regressor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Structure {
    /// The regressor.
    pub regressor: String,
    /// The reading channel (`phi`, `theta`, `s`).
    pub channel: &'static str,
    /// Pearson correlation of the weighted residual with the regressor.
    pub correlation: f64,
    /// Two-sided p-value (Fisher z).
    pub p_value: f64,
}

/// What the final model gains over the geometric one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gain {
    /// Held-out weighted residual RMS of the geometric model (noise = 1).
    pub holdout_rms_geometric: f64,
    /// Held-out weighted residual RMS of the final model.
    pub holdout_rms_extended: f64,
    /// Mean platform displacement on the middle plane between the
    /// geometric-only and the final calibration (commands of the former,
    /// positions predicted by both), mm; `null` when no target can be
    /// reached (see `volumetric_note`).
    pub volumetric_mean_mm: Option<f64>,
    /// Largest such displacement, mm.
    pub volumetric_max_mm: Option<f64>,
    /// Mean displacement after removing the best-fit rigid translation
    /// (touch-off): most of the raw figure is often a translation along the
    /// weak leg-length direction that the sensors cannot see, mm.
    pub volumetric_touched_mean_mm: Option<f64>,
    /// Why the displacement is missing or partial.
    pub volumetric_note: Option<String>,
    /// The predicted true improvement of deploying: the mean platform
    /// error on the middle plane of the geometric-only fit minus that of
    /// the deployed final model (the terms worth deploying, [`ModelTerm`]),
    /// both measured against the deployed model, mm; `null` when the plane
    /// cannot be reached.
    pub improvement_mm: Option<f64>,
    /// Its standard deviation against the truth, mm: the root mean square
    /// over the plane of the platform uncertainty of the deployed model
    /// (its covariance, the geometry's weak directions included) and of its
    /// difference from the geometric-only fit (the difference of the two
    /// covariances), in quadrature.
    pub improvement_sd_mm: Option<f64>,
    /// The standard deviation of the difference alone, mm: how far the
    /// deployed model would move the platform from the geometric-only one
    /// by noise (Hausman's covariance; it ignores that the geometric-only
    /// fit is biased, so it is reported, not used by the rule).
    pub difference_sd_mm: Option<f64>,
}

/// A term of the final model, and whether the deployed machine carries it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelTerm {
    /// The effect or family.
    pub effect: CauseName,
    /// The group (`leg-periodic:legs@10.000mm`, `leg-lead`).
    pub description: String,
    /// The legs of a generic leg term (1-3).
    pub legs: Vec<u8>,
    /// The reading channel of a generic reading term (0 `phi`, 1 `theta`,
    /// 2 `s`).
    pub channel: Option<u8>,
    /// The period of a periodic term, mm.
    pub period_mm: Option<f64>,
    /// The edges of a step, leg command `[from, to]`, mm.
    pub edges_mm: Option<[f64; 2]>,
    /// Whether it is deployed: the file with it is predicted better than
    /// the file without it, out of sample (its benefit,
    /// [`ModelTerm::holdout_benefit_mm`], above [`DEPLOY_BENEFIT_SD`]
    /// standard deviations) and where the readings cannot see (its
    /// improvement above [`DEPLOY_IMPROVEMENT_SD`] standard deviations, or,
    /// under the default rule, the smaller expected error by an improvement
    /// of at least one standard deviation: [`crate::options::DeployRule`]), both
    /// against the deployed model without it; no term is exempt. Or the
    /// model without it cannot be fitted.
    pub deployed: bool,
    /// The mean platform error on the middle plane of the deployed model
    /// without this term minus that of the deployed model (the final model
    /// when every term is deployed), mm (`null` when the model without it
    /// cannot be fitted or the plane reached).
    pub improvement_mm: Option<f64>,
    /// Its standard deviation against the truth ([`Gain::improvement_sd_mm`]), mm.
    pub improvement_sd_mm: Option<f64>,
    /// The standard deviation of the move alone ([`Gain::difference_sd_mm`]), mm.
    pub difference_sd_mm: Option<f64>,
    /// The out-of-sample benefit of the term: the root mean square held-out
    /// platform error (5-fold cross-validation, reading residuals mapped to
    /// the platform) of the file without it minus that of the file with
    /// it, mm (`null` when a fold cannot be fitted).
    pub holdout_benefit_mm: Option<f64>,
    /// Its standard deviation over the held-out poses, mm.
    pub holdout_benefit_sd_mm: Option<f64>,
    /// The expected root mean square platform error on the middle plane of
    /// the deployed model with this term, mm: its estimated squared bias and
    /// variance against the richest model the data support (the deployed
    /// model with a polynomial on every leg it does not shape), an unbiased
    /// risk estimate (`null` when a model cannot be fitted or the plane
    /// reached).
    pub expected_rms_with_mm: Option<f64>,
    /// The same for the deployed model without this term, mm.
    pub expected_rms_without_mm: Option<f64>,
    /// Why the deploy rule keeps the term back, in words (`null` when it is
    /// deployed): the readings do not see it pay out of sample, the file
    /// with it is not expected better, its improvement is within its own
    /// uncertainty, or (`--deploy-rule confident`) it is not confidently
    /// better.
    pub kept_back_because: Option<String>,
}

/// How many standard deviations ([`ModelTerm::improvement_sd_mm`]) a
/// term's in-sample improvement had to exceed for the term to be deployed
/// before the out-of-sample rule ([`DEPLOY_BENEFIT_SD`]); kept for callers
/// that compare with it, no longer the rule.
pub const SIGNIFICANT_IMPROVEMENT_SD: f64 = 2.0;

/// How many standard deviations ([`ModelTerm::holdout_benefit_sd_mm`]) a
/// term's out-of-sample benefit ([`ModelTerm::holdout_benefit_mm`]) must
/// exceed for the term to be deployed: the file with it predicted better,
/// out of sample, than the file without it, beyond its uncertainty.
pub const DEPLOY_BENEFIT_SD: f64 = 2.0;

/// How many standard deviations ([`ModelTerm::improvement_sd_mm`]) a
/// term's predicted improvement ([`ModelTerm::improvement_mm`], what the
/// term moves where the readings cannot see) must exceed for the term to
/// be deployed, besides its out-of-sample benefit: deploying it pays
/// against the uncertainty it adds (unless its improvement is no larger
/// than its out-of-sample benefit: it cannot lose more than it gains).
pub const DEPLOY_IMPROVEMENT_SD: f64 = 2.0;

/// A residual plot: weighted residuals of a channel (or implied leg-length
/// residuals) against the regressor that exposes a cause.
#[derive(Debug, Clone, PartialEq)]
pub struct ResidualPlot {
    /// The cause it illustrates.
    pub effect: CauseName,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Points with the geometric model.
    pub before: Vec<(f64, f64)>,
    /// Points with the final model.
    pub after: Vec<(f64, f64)>,
}

/// The diagnosis of a data set.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnosis {
    /// The geometric model alone explains the data: it passes its
    /// chi-square test, no cause is named and no generic term of the
    /// dictionary is significant.
    pub adequate: bool,
    /// Adequate, explained, partially explained or unexplained.
    pub verdict: Verdict,
    /// The final model (geometric plus the named causes and aliases)
    /// explains the data.
    pub final_adequate: bool,
    /// Chi-square of the geometric fit (clean poses).
    pub chi_square: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// p-value of the geometric model's adequacy test (`P(chi2_dof >
    /// chi_square)` with the stated noise; the lack-of-fit F test with the
    /// data's noise).
    pub chi_square_p_value: f64,
    /// The final model's fit.
    #[serde(rename = "final")]
    pub final_fit: FinalFit,
    /// RMS residual of the geometric fit.
    pub residual_rms_geometric: ChannelRms,
    /// Strongest residual correlations of the geometric fit.
    pub structure: Vec<Structure>,
    /// Named causes, strongest first.
    pub causes: Vec<Cause>,
    /// Candidates this campaign cannot tell apart.
    pub aliases: Vec<Alias>,
    /// Fits that are not causes, with the reason.
    pub rejected: Vec<Rejected>,
    /// What the final model leaves unexplained, when it is not adequate.
    pub remainder: Option<Remainder>,
    /// The noise check.
    pub noise: NoiseCheck,
    /// Every candidate tested at the first selection step.
    pub candidates: Vec<Tested>,
    /// Number of tests of the generic dictionary (every scan period counts).
    pub dictionary_tests: usize,
    /// When the data are not explained and no cause is found: what is seen.
    pub unexplained: Option<String>,
    /// Stated limitations of this diagnosis (data it could not use, ...).
    pub limitations: Vec<String>,
    /// Gain of the final model.
    pub gain: Gain,
    /// The terms of the final model, each deployed or "seen, not worth
    /// deploying", with its improvement.
    pub model_terms: Vec<ModelTerm>,
    /// Geometric parameters of the geometric-only fit.
    #[serde(serialize_with = "estimates_by_name")]
    pub geometric_only: Vec<Estimate>,
    /// Every parameter of the final model.
    #[serde(serialize_with = "estimates_by_name")]
    pub extended: Vec<Estimate>,
    /// How much adding the causes moved each geometric parameter
    /// (final minus geometric-only), mm.
    #[serde(rename = "geometric_bias_mm", serialize_with = "values_by_name")]
    pub geometric_bias: Vec<(String, f64)>,
    /// Residual plots of the named causes.
    #[serde(skip)]
    pub plots: Vec<ResidualPlot>,
}

/// RMS (or standard deviation) of each reading channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChannelRms {
    /// Encoder `phi`, arcsec.
    pub phi_arcsec: f64,
    /// Encoder `theta`, arcsec.
    pub theta_arcsec: f64,
    /// Linear scale `s`, um.
    pub s_um: f64,
}

impl ChannelRms {
    /// From `[phi rad, theta rad, s mm]`.
    pub fn from_internal(v: [f64; 3]) -> ChannelRms {
        ChannelRms {
            phi_arcsec: v[0] / RAD_PER_ARCSEC,
            theta_arcsec: v[1] / RAD_PER_ARCSEC,
            s_um: v[2] * 1e3,
        }
    }
}

/// A candidate with the evidence it had when tested.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tested {
    /// The effect or family.
    pub effect: CauseName,
    /// The group.
    pub description: String,
    /// Its evidence.
    pub evidence: Evidence,
    /// Whether it was refitted exactly, its evidence the likelihood-ratio
    /// test of the two fits; `false`: judged by the score test at the
    /// current fit, its `delta_chi_square` the linearised drop of
    /// chi-square (a catalogue effect that could not be admissible even at
    /// twice its score is not refitted).
    pub refitted: bool,
}

/// Serialises estimates as `{name: {"value": v, "std_dev": s}}`.
fn estimates_by_name<S: Serializer>(v: &[Estimate], s: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Entry {
        value: f64,
        std_dev: Option<f64>,
    }
    let mut map = s.serialize_map(Some(v.len()))?;
    for e in v {
        map.serialize_entry(
            &e.name,
            &Entry {
                value: e.value,
                std_dev: e.std_dev,
            },
        )?;
    }
    map.end()
}

/// Serialises `(name, value)` pairs as `{name: value}`.
fn values_by_name<S: Serializer>(v: &[(String, f64)], s: S) -> Result<S::Ok, S::Error> {
    let mut map = s.serialize_map(Some(v.len()))?;
    for (name, value) in v {
        map.serialize_entry(name, value)?;
    }
    map.end()
}

impl Diagnosis {
    /// The file lines of the poses the outlier screen set aside (empty when
    /// `outliers` is not a named cause): the poses the final model was not
    /// fitted to.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```no_run
use tricept_diagnose::{diagnose, DiagnoseOptions};
let m = tricept_kinematics::Machine::paper();
let data = tricept_data::read_path("fixtures/data/diagnose-hidden-effect.csv".as_ref()).unwrap();
let d = diagnose(&m, &data, &DiagnoseOptions::for_machine(&m)).unwrap();
let clean = data.subset(|j| !d.outlier_lines().contains(&data.poses[j].line));
```
"#
    )]
    pub fn outlier_lines(&self) -> Vec<u64> {
        use tricept_model::effects::{CauseName, EffectName};
        self.causes
            .iter()
            .filter(|c| c.effect == CauseName::Catalogue(EffectName::Outliers))
            .flat_map(|c| c.rows.iter().copied())
            .collect()
    }

    /// The effects of the vocabulary in the final model: the named causes
    /// (outliers aside) and the model's member of each alias set (a scale
    /// gain, for instance, is never named alone but is modelled). What a
    /// calibration that deploys the diagnosis' model needs.
    pub fn model_effects(&self) -> Vec<tricept_model::effects::EffectName> {
        use tricept_model::effects::EffectName;
        let mut out: Vec<EffectName> = Vec::new();
        let names = self
            .causes
            .iter()
            .map(|c| c.effect)
            .chain(self.aliases.iter().map(|a| a.in_model));
        for e in names.filter_map(|n| n.catalogue()) {
            if e.is_term() && !out.contains(&e) {
                out.push(e);
            }
        }
        out
    }

    /// JSON with the contract keys `adequate`, `causes` (each with
    /// `effect`, its parameter estimates and evidence) and `gain`
    /// (`holdout_rms_geometric`, `holdout_rms_extended`), and more: the
    /// serialisation of this type.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }
}

impl Diagnosis {
    /// The report as text for people; `source` names the data (a file).
    pub fn to_text(&self, source: &str) -> String {
        use std::fmt::Write as _;
        let mut out = String::new();
        // Writing to a String cannot fail.
        macro_rules! w {
            ($($arg:tt)*) => {{
                let _ = writeln!(out, $($arg)*);
            }};
        }
        let verdict = match self.verdict {
            Verdict::Adequate => "the geometric model explains the data (adequate)",
            Verdict::Explained => {
                "the geometric model does NOT explain the data; the named causes do"
            }
            Verdict::PartiallyExplained => {
                "the geometric model does NOT explain the data; the named causes explain it only PARTIALLY (see remainder)"
            }
            Verdict::Unexplained => {
                "the geometric model does NOT explain the data, and no cause is found"
            }
        };
        w!("{source}: {verdict}");
        w!(
            "geometric fit: chi2 {:.1} for {} dof (p = {:.2e}); residual rms phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um",
            self.chi_square,
            self.dof,
            self.chi_square_p_value,
            self.residual_rms_geometric.phi_arcsec,
            self.residual_rms_geometric.theta_arcsec,
            self.residual_rms_geometric.s_um
        );
        w!("noise: {}", self.noise.note);
        if let Some(s) = self.structure.first() {
            w!(
                "strongest residual structure: {} vs {} (r = {:+.2}, p = {:.1e})",
                s.channel,
                s.regressor,
                s.correlation,
                s.p_value
            );
        }
        for (i, c) in self.causes.iter().enumerate() {
            let ev = &c.evidence;
            w!("cause {}: {}: {}", i + 1, c.effect, c.description);
            w!(
                "    evidence: chi2 drop {:.1} for {} dof, adjusted p = {:.1e} ({} tests); penalised gain {:.1}{}",
                ev.delta_chi_square,
                ev.dof,
                ev.p_adjusted,
                ev.multiplicity,
                ev.penalised_gain,
                match (ev.holdout_rms_without, ev.holdout_rms_with) {
                    (Some(a), Some(b)) => format!("; held-out rms {a:.2} -> {b:.2}"),
                    _ => String::new(),
                }
            );
            for p in &c.parameters {
                match p.std_dev {
                    Some(sd) => w!("    {:<40} {:>12.4} +- {:.4}", p.name, p.value, sd),
                    None => w!("    {:<40} {:>12.4}", p.name, p.value),
                }
            }
            if !c.rows.is_empty() {
                w!("    lines: {:?}", c.rows);
            }
        }
        for a in &self.aliases {
            w!(
                "alias: {} cannot be told apart on this campaign{}: {}",
                a.descriptions.join(" ~ "),
                if a.exact { " (exactly)" } else { "" },
                a.why
            );
            w!("    separate by: {}", a.separate_by);
        }
        for r in &self.rejected {
            w!("rejected: {}: {}", r.description, r.reason);
        }
        if let Some(r) = &self.remainder {
            w!("remainder: {}", r.text);
        }
        if let (Some(u), None) = (&self.unexplained, &self.remainder) {
            w!("unexplained: {u}");
        }
        for l in &self.limitations {
            w!("limitation: {l}");
        }
        let mut bias = self.geometric_bias.clone();
        bias.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        if !self.causes.is_empty() || !self.aliases.is_empty() {
            let text: Vec<String> = bias
                .iter()
                .take(4)
                .map(|(n, v)| format!("{n} {:+.4}", v))
                .collect();
            w!(
                "bias the causes put into the geometric parameters (mm): {}",
                text.join(", ")
            );
        }
        let g = &self.gain;
        let moved = match (
            g.volumetric_mean_mm,
            g.volumetric_touched_mean_mm,
            g.volumetric_max_mm,
        ) {
            (Some(mean), Some(touched), Some(max)) => format!(
                "platform moved on the middle plane by {mean:.4} mm mean ({touched:.4} after touch-off), {max:.4} mm max"
            ),
            _ => "platform displacement not computed".into(),
        };
        w!(
            "gain: held-out rms {:.3} -> {:.3} (noise = 1); {moved}{}",
            g.holdout_rms_geometric,
            g.holdout_rms_extended,
            g.volumetric_note
                .as_ref()
                .map_or(String::new(), |n| format!(" ({n})"))
        );
        if let (Some(i), Some(sd)) = (g.improvement_mm, g.improvement_sd_mm) {
            w!(
                "predicted improvement of the deployed model over the geometric-only one: {:.4} +- {:.4} mm mean platform error on the middle plane",
                i,
                sd
            );
        }
        for t in &self.model_terms {
            let mut numbers = match (t.improvement_mm, t.improvement_sd_mm, t.difference_sd_mm) {
                (Some(i), Some(sd), Some(moved)) => {
                    format!(": improvement {i:.4} +- {sd:.4} mm (the move's own sd {moved:.4} mm)")
                }
                _ => String::new(),
            };
            if let (Some(b), Some(sd)) = (t.holdout_benefit_mm, t.holdout_benefit_sd_mm) {
                numbers.push_str(&format!(
                    "{}out-of-sample benefit {b:.4} +- {sd:.4} mm",
                    if numbers.is_empty() { ": " } else { "; " }
                ));
            }
            if let (Some(with), Some(without)) = (t.expected_rms_with_mm, t.expected_rms_without_mm)
            {
                numbers.push_str(&format!(
                    "{}expected rms error {with:.4} mm with it, {without:.4} mm without",
                    if numbers.is_empty() { ": " } else { "; " }
                ));
            }
            if t.deployed {
                w!("deployed: {}{numbers}", t.description);
            } else {
                w!(
                    "seen, not worth deploying: {}{numbers}; kept back because {}",
                    t.description,
                    t.kept_back_because.as_deref().unwrap_or("the deploy rule")
                );
            }
        }
        out
    }
}
