//! The door's pages of a diagnosis report's parts ([`crate::diagnosis::Diagnosis`]'s
//! fields), re-exported by [`crate::diagnosis`]: kept here so the workflow
//! module stays short.

/// Causes a campaign cannot tell apart: the one kept in the model first,
/// why they look alike, and what measurement would separate them.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// for alias in &d.aliases {
///     assert_eq!(alias.effects[0], alias.in_model);
///     println!("{:?}: {} (separate by {})", alias.descriptions, alias.why, alias.separate_by);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Alias;
/// What kind of cause a diagnosis names: an effect of its vocabulary, a
/// generic term, or outlying readings (in JSON, kebab-case).
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::CauseKind;
/// assert_eq!(serde_json::to_value(CauseKind::Catalogue)?, "catalogue");
/// assert_eq!(serde_json::to_value(CauseKind::Outliers)?, "outliers");
/// # Ok::<(), serde_json::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::CauseKind;
/// The RMS (or standard deviation) of each reading channel: encoders
/// (arcsec), scale (um).
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::ChannelRms;
/// let rms = ChannelRms::from_internal([1e-6, 2e-6, 0.0005]); // rad, rad, mm
/// assert!((rms.phi_arcsec - 0.206265).abs() < 1e-6); // 1 urad
/// assert!((rms.theta_arcsec - 2.0 * rms.phi_arcsec).abs() < 1e-12);
/// assert!((rms.s_um - 0.5).abs() < 1e-12);
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::ChannelRms;
/// An estimated parameter: its name (unit in it), value and standard
/// deviation (`None`: unidentifiable, held at zero).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// for p in d.causes.iter().flat_map(|c| &c.parameters) {
///     if p.std_dev.is_none() {
///         assert_eq!(p.value, 0.0, "{} is held", p.name);
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Estimate;
/// The statistical evidence for one candidate cause: its chi-square drop
/// and test, its BIC gain, its held-out residuals, whether it was selected.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// for cause in &d.causes {
///     let e = &cause.evidence;
///     assert!((e.p_adjusted - (e.p_value * e.multiplicity as f64).min(1.0)).abs() < 1e-12);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Evidence;
/// The chi-square test of a diagnosis' final model.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// let fit = &d.final_fit;
/// assert!((0.0..=1.0).contains(&fit.p_value));
/// println!("chi2 = {:.1} on {} dof", fit.chi_square, fit.dof);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::FinalFit;
/// A term of the final (extended) model: its effect, where it acts, whether
/// it is deployed into the machine file and what it gains.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// for term in &d.model_terms {
///     if !term.deployed {
///         println!("{} kept back: {:?}", term.description, term.kept_back_because);
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::ModelTerm;
/// The check of the stated sensor noise against the data (repeated poses),
/// and which noise the tests used.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// let noise = &d.noise;
/// if noise.pure_error.is_none() {
///     assert_eq!(noise.agrees, None); // nothing repeated, nothing to compare
/// }
/// println!("{}", noise.note);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::NoiseCheck;
/// Which noise a diagnosis' tests used: the stated one, or the one repeated
/// poses show (`--noise-from-data`).
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::NoiseSource;
/// assert_eq!(serde_json::to_value(NoiseSource::Stated)?, "stated");
/// assert_eq!(serde_json::to_value(NoiseSource::Data)?, "data");
/// # Ok::<(), serde_json::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::NoiseSource;
/// The pure error of repeated poses: the noise the data show per channel,
/// against the stated noise.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// if let Some(pure) = &d.noise.pure_error {
///     let stated = &d.noise.stated;
///     assert!((pure.ratio[2] - pure.sigma.s_um / stated.s_um).abs() < 1e-9); // data over stated
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::PureError;
/// Where a diagnosis turned a fit down: implausible values, no better on
/// held-out poses, removed on the final model, an implausible alias.
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::RejectStage;
/// assert_eq!(serde_json::to_value(RejectStage::FinalEvidence)?, "final-evidence");
/// assert_eq!(serde_json::to_value(RejectStage::ImplausibleAlias)?, "implausible-alias");
/// # Ok::<(), serde_json::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::RejectStage;
/// A fit a diagnosis did not name as a cause: its parameters, why, and at
/// which stage.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// use tricept_ident::diagnosis::RejectStage;
/// for r in d.rejected.iter().filter(|r| r.stage == RejectStage::Plausibility) {
///     println!("{}: implausible: {}", r.description, r.reason);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Rejected;
/// What the final model leaves unexplained: its chi-square test, held-out
/// RMS, the structure left in the residuals, the strongest term not named.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// use tricept_ident::diagnosis::DiagnosisVerdict;
/// if let Some(rest) = &d.remainder {
///     assert_ne!(d.verdict, DiagnosisVerdict::Adequate); // an adequate model leaves none
///     println!("{}", rest.text);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Remainder;
/// A residual plot of a named cause: residuals against its regressor,
/// with the geometric model (`before`) and the final model (`after`).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// for plot in result.plots() {
///     let named = result.diagnosis().causes.iter().any(|c| c.effect == plot.effect);
///     println!("{} ({named}): {} against {}", plot.effect, plot.y_label, plot.x_label);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::ResidualPlot;
/// A correlation of the residuals with a regressor (a channel against a
/// leg command, the temperature, the time), with its p-value.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// for s in &d.structure {
///     assert!(s.correlation.abs() <= 1.0 && (0.0..=1.0).contains(&s.p_value));
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Structure;
/// The strongest term a diagnosis tested but did not name: its chi-square
/// drop, adjusted p-value and why it was not named.
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// if let Some(term) = d.remainder.as_ref().and_then(|r| r.strongest_term.as_ref()) {
///     assert!((0.0..=1.0).contains(&term.p_adjusted));
///     println!("{}: {}", term.description, term.why_not_named);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::TermScore;
/// A candidate a diagnosis tested, with its evidence and whether it was
/// refitted exactly (else judged by the score test).
///
/// # Example
/// ```no_run
/// use tricept_ident::diagnosis::{DiagnoseRequest, diagnose};
/// let result = diagnose(DiagnoseRequest::new("campaign.csv"))?;
/// let d = result.diagnosis();
/// for t in &d.candidates {
///     assert!((0.0..=1.0).contains(&t.evidence.p_adjusted)); // p times tests, at most 1
///     if !t.refitted {
///         println!("{}: score test, drop {:.1}", t.description, t.evidence.delta_chi_square);
///     }
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Tested;
/// A diagnosis' verdict: the geometric model adequate, the data explained
/// by the causes named, partly explained (with a remainder), or
/// unexplained (in JSON, kebab-case).
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::DiagnosisVerdict;
/// assert_eq!(serde_json::to_value(DiagnosisVerdict::PartiallyExplained)?, "partially-explained");
/// assert_eq!(serde_json::to_value(DiagnosisVerdict::Adequate)?, "adequate");
/// # Ok::<(), serde_json::Error>(())
/// ```
#[doc(inline)]
pub use tricept_diagnose::report::Verdict as DiagnosisVerdict;
