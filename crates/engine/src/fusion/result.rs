//! The result of a fused identification: each source's fit (its
//! redundancy, whether its rows can check the fit, its chi-square test),
//! the verdict in the fields `identify` has (`converged`, `adequate`,
//! `chi_square_p_value`, `consistent_with_machine`) and the fused fit's own
//! (`checkable`, `plausible`), the records the screen rejected, the
//! implausible estimates, the likely causes, the warnings, and the JSON.

use nalgebra::DMatrix;
use serde::Serialize;
use serde_json::{Map, Value, json};
use tricept_numerics::stats::chi2_sf;

use crate::fusion::model::FusedModel;
use crate::fusion::options::FusionOptions;
use crate::fusion::plausibility::{FusionPlausibility, Implausible};
use crate::fusion::report::FusionReport;
use crate::fusion::source::{Source, SourceKind};
use crate::verdict::{ADEQUACY_ALPHA, INCONSISTENT_CHI2_PER_DOF};

/// The fit of one source.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceFit {
    /// Label (prefix of its nuisance names).
    pub label: String,
    /// Kind of instrument.
    pub kind: SourceKind,
    /// File the records came from.
    pub file: String,
    /// Records in the fit (those the screen rejected are not counted).
    pub records: usize,
    /// Data rows in the fit.
    pub rows: usize,
    /// Nuisance parameter names (with the label).
    pub nuisance_names: Vec<String>,
    /// Their estimates (rotations as rotation vectors, rad).
    pub nuisance: Vec<f64>,
    /// Their standard deviations.
    pub nuisance_std_dev: Vec<f64>,
    /// Sum of squared standardised residuals of the data rows.
    pub chi_square: f64,
    /// The source's degrees of freedom: `sum (1 - h_ii)` over its data
    /// rows, `h` the union's hat matrix: its rows less what they alone
    /// determine (its nuisance, the parameters no other source sees, its
    /// share of the rest). The expectation of `chi_square` when the model
    /// and the stated noise are right.
    pub redundancy: f64,
    /// The redundancy its rows need to check the fit: 6 per tracker
    /// station, 4 per ballbar setup or touched feature, 6 for the UP limb.
    pub min_redundancy: f64,
    /// Whether `redundancy >= min_redundancy`: a source that is not checkable
    /// fits its rows whatever they hold (a gross error, another machine's
    /// file), and its chi-square says nothing.
    pub checkable: bool,
    /// When not checkable: how many more records (like these) make it so.
    pub more_records: Option<usize>,
    /// `chi_square / redundancy` (NaN below one degree of freedom): about 1
    /// when the model and the stated noise explain this source.
    pub reduced_chi_square: f64,
    /// `P(chi2_redundancy > chi_square)` (NaN below one degree of freedom).
    pub p_value: f64,
    /// RMS residual, um (external sources; `None` for the internal one,
    /// whose rows mix rad and mm).
    pub rms_um: Option<f64>,
    /// Largest standardised residual and the line of its record.
    pub max_standardised: (f64, u64),
    /// Fitted geometry beyond the nuisance values (touch-offs: the unit
    /// normal of each plane, `plane_normals`); `null` when there is none.
    pub extra: Value,
}

impl SourceFit {
    /// The fit of `source` from its records in the fit (`active`), its
    /// standardised residuals `z`, redundancy and nuisance.
    pub(crate) fn new(
        source: &Source,
        active: &[bool],
        z: &[(usize, f64, f64)],
        redundancy: f64,
        (nuisance, nuisance_std_dev, extra): (Vec<f64>, Vec<f64>, Value),
    ) -> SourceFit {
        let rows = source.rows();
        let records = active.iter().filter(|a| **a).count();
        let chi_square: f64 = z.iter().map(|(_, v, _)| v * v).sum();
        let n_rows = records * rows.rows_per_record();
        let min_redundancy = rows.min_redundancy();
        let checkable = redundancy >= min_redundancy - 1e-9;
        let judged = redundancy >= 1.0;
        let more_records = (!checkable).then(|| {
            // Rows like these add `rows_per_record` each and carry the same
            // unknowns: `m n - carried >= min`.
            let m = rows.rows_per_record().max(1) as f64;
            let carried = n_rows as f64 - redundancy;
            (((min_redundancy + carried) / m).ceil() as usize)
                .saturating_sub(records)
                .max(1)
        });
        let (max_z, max_record) = z.iter().fold((0.0f64, 0usize), |acc, (r, v, _)| {
            if v.abs() > acc.0 { (v.abs(), *r) } else { acc }
        });
        let rms_um = rows.residual_unit_um().map(|unit| {
            let sum: f64 = z.iter().map(|(_, _, raw)| raw * raw).sum();
            unit * (sum / z.len().max(1) as f64).sqrt()
        });
        SourceFit {
            label: source.label().to_string(),
            kind: source.kind(),
            file: source.file().to_string(),
            records,
            rows: n_rows,
            nuisance_names: source.nuisance_names(),
            nuisance,
            nuisance_std_dev,
            chi_square,
            redundancy,
            min_redundancy,
            checkable,
            more_records,
            reduced_chi_square: if judged {
                chi_square / redundancy
            } else {
                f64::NAN
            },
            p_value: if judged {
                chi2_sf(chi_square, redundancy)
            } else {
                f64::NAN
            },
            rms_um,
            max_standardised: (max_z, rows.line(max_record)),
            extra,
        }
    }

    /// Whether its chi-square passes the adequacy test of `identify`
    /// ([`ADEQUACY_ALPHA`]); never for a source below one degree of freedom.
    pub fn explained(&self) -> bool {
        self.p_value > ADEQUACY_ALPHA
    }
}

/// One record's check at the end of a fit: its weighted residual `e` after
/// the last step and its block `H` of the union's hat matrix give
/// `e^T (I - H)^-1 e` (in the fit: the deleted residual) or
/// `e^T (I + H)^-1 e` (outside: the prediction residual).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RecordCheck {
    /// The record's line in its file.
    pub line: u64,
    /// Whether it is in the fit.
    pub active: bool,
    /// Its data rows.
    pub rows: usize,
    /// `tr H` of its block (its share of the fitted unknowns).
    pub leverage: f64,
    /// The quadratic form above (in noise units, before any rescaling).
    pub quadratic: f64,
}

/// The verdict on a fused fit: the fields `identify` has and the fused
/// fit's own.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FusionVerdict {
    /// The iteration met its tolerance.
    pub converged: bool,
    /// Every source passes its chi-square test at [`ADEQUACY_ALPHA`] (a
    /// source that cannot be checked does not).
    pub adequate: bool,
    /// `P(chi2 > chi_square)` of all sources together.
    pub chi_square_p_value: f64,
    /// No source is beyond [`INCONSISTENT_CHI2_PER_DOF`].
    pub consistent_with_machine: bool,
    /// Every source has the redundancy to check the fit.
    pub checkable: bool,
    /// Every estimate is within its plausible range.
    pub plausible: bool,
}

/// The result of [`crate::fusion::identify_fused`].
#[derive(Debug, Clone)]
pub struct Fusion {
    /// Global parameter names `[module | effects | head]`.
    pub names: Vec<String>,
    /// Estimates (held parameters at their prior, zero).
    pub estimate: Vec<f64>,
    /// Standard deviations (`None` for held parameters).
    pub std_dev: Vec<Option<f64>>,
    /// Covariance of the global parameters (zero rows and columns for held
    /// ones).
    pub covariance: DMatrix<f64>,
    /// Each source's fit.
    pub sources: Vec<SourceFit>,
    /// What the sources, alone and together, can see.
    pub report: FusionReport,
    /// Gauss-Newton iterations.
    pub iterations: u32,
    /// Whether the iteration met its tolerance.
    pub converged: bool,
    /// The verdict.
    pub verdict: FusionVerdict,
    /// Records the gross-error screen rejected (the fit is without them).
    pub rejected: Vec<RejectedRecord>,
    /// Sources whose screen found more gross errors than its cap allows
    /// (nothing rejected there: a model problem, not gross errors).
    pub screen_overflow: Vec<String>,
    /// Estimates outside their plausible range.
    pub implausible: Vec<Implausible>,
    /// Mistakes whose undoing makes the data fit (tested by refitting).
    pub likely_causes: Vec<FusionCause>,
    /// Problems a user must read: no convergence, a rejected record, a
    /// source that cannot be checked or that the model does not explain,
    /// an implausible estimate and its likely causes, a tool tip or axis
    /// that is not calibrated.
    pub warnings: Vec<String>,
    /// Every record's check, per source (for the screen).
    pub(crate) checks: Vec<Vec<RecordCheck>>,
    /// Warnings of the fit itself (report, evaluation).
    fit_warnings: Vec<String>,
    /// Whether a cause search was asked for and found nothing.
    causes_searched: bool,
}

/// The estimates of a fit outside the ranges of `options.plausibility`:
/// every estimated global parameter, and the nuisance values each source
/// judges ([`crate::fusion::source::SourceRows::judged_nuisance`]).
pub(crate) fn judge(
    model: &FusedModel,
    estimate: &[f64],
    std_dev: &[Option<f64>],
    sources: &[Source],
    fits: &[SourceFit],
    options: &FusionOptions,
) -> Vec<Implausible> {
    let table = &options.plausibility.ranges;
    let mut out = Vec::new();
    let mut check = |name: &str, key: String, value: f64, sd: f64| {
        if let Some(range) = table.get(&key)
            && !range.admits(value, sd)
        {
            out.push(Implausible {
                name: name.to_string(),
                key,
                value,
                std_dev: sd,
                range: range.clone(),
            });
        }
    };
    for (j, name) in model.names().iter().enumerate() {
        if let Some(sd) = std_dev[j] {
            check(name, FusionPlausibility::key_of(model, j), estimate[j], sd);
        }
    }
    for (source, fit) in sources.iter().zip(fits) {
        for (key, index, value) in source.rows().judged_nuisance(&fit.nuisance) {
            let sd = fit.nuisance_std_dev.get(index).copied().unwrap_or(0.0);
            let name = fit.nuisance_names.get(index).cloned().unwrap_or_default();
            check(&name, key.to_string(), value, sd);
        }
    }
    out
}

impl Fusion {
    /// The result of one fit (see `estimate.rs`), its verdict and warnings.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn assemble(
        model: &FusedModel,
        estimate: Vec<f64>,
        std_dev: Vec<Option<f64>>,
        covariance: DMatrix<f64>,
        sources: Vec<SourceFit>,
        report: FusionReport,
        (iterations, converged): (u32, bool),
        implausible: Vec<Implausible>,
        checks: Vec<Vec<RecordCheck>>,
        fit_warnings: Vec<String>,
        options: &FusionOptions,
    ) -> Fusion {
        let chi2: f64 = sources.iter().map(|s| s.chi_square).sum();
        let dof: f64 = sources.iter().map(|s| s.redundancy).sum();
        let verdict = FusionVerdict {
            converged,
            adequate: sources.iter().all(SourceFit::explained),
            chi_square_p_value: if dof >= 1.0 {
                chi2_sf(chi2, dof)
            } else {
                f64::NAN
            },
            consistent_with_machine: sources.iter().all(|s| {
                s.reduced_chi_square.is_nan() || s.reduced_chi_square <= INCONSISTENT_CHI2_PER_DOF
            }),
            checkable: sources.iter().all(|s| s.checkable),
            plausible: implausible.is_empty(),
        };
        let mut fit_warnings = fit_warnings;
        fit_warnings.extend(report.warnings(options.tool_axis_arcsec));
        let mut fit = Fusion {
            names: model.names().to_vec(),
            estimate,
            std_dev,
            covariance,
            sources,
            report,
            iterations,
            converged,
            verdict,
            rejected: Vec::new(),
            screen_overflow: Vec::new(),
            implausible,
            likely_causes: Vec::new(),
            warnings: Vec::new(),
            checks,
            fit_warnings,
            causes_searched: false,
        };
        fit.compose_warnings();
        fit
    }

    /// Whether the fit is implausible or an external source is not
    /// explained: what the likely-cause search is for.
    pub(crate) fn needs_causes(&self) -> bool {
        !self.implausible.is_empty()
            || self
                .sources
                .iter()
                .any(|s| s.kind != SourceKind::Internal && s.checkable && !s.explained())
    }

    /// Records the screen's result.
    pub(crate) fn set_screen(&mut self, rejected: Vec<RejectedRecord>, overflow: Vec<String>) {
        self.rejected = rejected;
        self.screen_overflow = overflow;
        self.compose_warnings();
    }

    /// Records the likely causes found.
    pub(crate) fn add_causes(&mut self, causes: Vec<FusionCause>) {
        self.likely_causes = causes;
        self.causes_searched = true;
        self.compose_warnings();
    }

    fn compose_warnings(&mut self) {
        let mut w = Vec::new();
        if !self.converged {
            w.push(format!(
                "Gauss-Newton did not converge in {} iterations: the estimate is not trustworthy",
                self.iterations
            ));
        }
        for r in &self.rejected {
            w.push(r.to_text());
        }
        for label in &self.screen_overflow {
            w.push(format!(
                "{label}: more records look like gross errors than the screen may reject (10 %, at least 2): nothing rejected there; a model or setup problem, not a few bad rows (a tracker moved without a new `setup` number, a file of another machine)"
            ));
        }
        for s in &self.sources {
            if !s.checkable {
                w.push(format!(
                    "{} ({}) cannot be checked: its {} {} leave {:.1} redundant rows of the {:.0} needed (they carry {:.1} unknowns no other source determines), so any gross error or wrong file would fit them; at least {} more {} make it checkable",
                    s.label,
                    s.file,
                    s.records,
                    plural(s.kind, s.records),
                    s.redundancy.max(0.0),
                    s.min_redundancy,
                    s.rows as f64 - s.redundancy,
                    s.more_records.unwrap_or(1),
                    plural(s.kind, s.more_records.unwrap_or(1)),
                ));
            } else if !s.explained() {
                let advice = if s.kind == SourceKind::Internal {
                    "run `tricept diagnose` on the internal data and add the effects it names (effects), or check the sensor noise".to_string()
                } else {
                    format!(
                        "its largest residual is {:.1} sigma at line {}: check that row; if the misfit is spread over the rows, check the instrument's stated noise and that each station or setup has its own `setup` number",
                        s.max_standardised.0, s.max_standardised.1
                    )
                };
                w.push(format!(
                    "the model does not explain {} ({}): reduced chi-square {:.2} for {:.1} degrees of freedom (p = {:.1e}); {advice}",
                    s.label, s.file, s.reduced_chi_square, s.redundancy, s.p_value
                ));
            }
        }
        for i in self.implausible.iter().take(3) {
            w.push(format!(
                "{}: the estimate absorbs a mistake, not a machine error",
                i.to_text()
            ));
        }
        if self.implausible.len() > 3 {
            let rest: Vec<&str> = self.implausible[3..]
                .iter()
                .map(|i| i.name.as_str())
                .collect();
            w.push(format!(
                "{} more estimates are far outside their plausible ranges: {}",
                rest.len(),
                rest.join(", ")
            ));
        }
        for c in &self.likely_causes {
            w.push(format!("likely cause (tested): {}", c.description));
        }
        if self.causes_searched && self.likely_causes.is_empty() {
            w.push(
                "no usual mistake explains the misfit (tried: the tracker target free, its offset's sign, each external source alone)".into(),
            );
        }
        w.extend(self.fit_warnings.iter().cloned());
        self.warnings = w;
    }

    /// Whether the fit may be deployed as it stands: converged, adequate,
    /// every source checkable, every estimate plausible.
    pub fn is_trustworthy(&self) -> bool {
        let v = &self.verdict;
        v.converged && v.adequate && v.checkable && v.plausible
    }

    /// Index of a global parameter by name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// JSON: every global parameter at the top level (as `identify`), with
    /// `std_dev`, `groups`, `sources` (each with its `redundancy`,
    /// `checkable`, chi-square test), the identifiability report of the
    /// union and of each source (`visibility`, with `tool_tip` and
    /// `tool_axis`), the verdict fields of `identify` (`converged`,
    /// `adequate`, `chi_square_p_value`, `consistent_with_machine`) and the
    /// fused fit's (`checkable`, `plausible`), `rejected`, `implausible`,
    /// `likely_causes`, `warnings`.
    pub fn to_json(&self, model: &FusedModel) -> Value {
        let mut m = Map::new();
        for (n, v) in self.names.iter().zip(&self.estimate) {
            m.insert(n.clone(), (*v).into());
        }
        m.insert(
            "std_dev".into(),
            Value::Object(
                self.names
                    .iter()
                    .zip(&self.std_dev)
                    .map(|(n, s)| (n.clone(), s.map_or(Value::Null, Value::from)))
                    .collect(),
            ),
        );
        let group = |r: std::ops::Range<usize>| -> Value {
            self.names[r].iter().cloned().map(Value::from).collect()
        };
        m.insert(
            "groups".into(),
            json!({"module": group(model.module_range()), "effects": group(model.effect_range()), "head": group(model.head_range())}),
        );
        let named = |names: &[String], values: &[f64]| -> Value {
            Value::Object(
                names
                    .iter()
                    .zip(values)
                    .map(|(n, x)| (n.clone(), Value::from(*x)))
                    .collect(),
            )
        };
        m.insert(
            "sources".into(),
            Value::Array(
                self.sources
                    .iter()
                    .map(|s| {
                        let mut v = serde_json::to_value(s).unwrap_or(Value::Null);
                        if let Value::Object(o) = &mut v {
                            o.insert("nuisance".into(), named(&s.nuisance_names, &s.nuisance));
                            o.insert(
                                "nuisance_std_dev".into(),
                                named(&s.nuisance_names, &s.nuisance_std_dev),
                            );
                            o.remove("nuisance_names");
                            o.insert(
                                "max_standardised".into(),
                                json!({"value": s.max_standardised.0, "line": s.max_standardised.1}),
                            );
                        }
                        v
                    })
                    .collect(),
            ),
        );
        if let Value::Object(r) = self.report.union.to_json() {
            for (key, v) in r {
                m.insert(key, v);
            }
        }
        m.insert("visibility".into(), self.report.to_json());
        m.insert("iterations".into(), self.iterations.into());
        if let Value::Object(v) = serde_json::to_value(self.verdict).unwrap_or(Value::Null) {
            for (key, x) in v {
                m.insert(key, x);
            }
        }
        let list = |v: Value| if v.is_array() { v } else { json!([]) };
        m.insert(
            "rejected".into(),
            list(serde_json::to_value(&self.rejected).unwrap_or(Value::Null)),
        );
        m.insert(
            "implausible".into(),
            list(serde_json::to_value(&self.implausible).unwrap_or(Value::Null)),
        );
        m.insert(
            "likely_causes".into(),
            list(serde_json::to_value(&self.likely_causes).unwrap_or(Value::Null)),
        );
        m.insert(
            "warnings".into(),
            Value::Array(self.warnings.iter().cloned().map(Value::from).collect()),
        );
        Value::Object(m)
    }
}

/// The noun of a source's records, singular or plural.
fn plural(kind: SourceKind, n: usize) -> &'static str {
    match (kind, n == 1) {
        (SourceKind::Internal, true) => "pose",
        (SourceKind::Internal, false) => "poses",
        (SourceKind::Tracker, true) => "point",
        (SourceKind::Tracker, false) => "points",
        (SourceKind::Ballbar, true) => "reading",
        (SourceKind::Ballbar, false) => "readings",
        (SourceKind::Touch, true) => "touch",
        (SourceKind::Touch, false) => "touches",
    }
}

/// A mistake whose undoing makes the data fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FusionCause {
    /// The source it concerns (label).
    pub source: String,
    /// Which mistake: `target-sign`, `target-mode` or `another-machine`.
    pub mistake: &'static str,
    /// What it is and what the refit gave, in words.
    pub description: String,
    /// The source's reduced chi-square with the mistake undone.
    pub chi2_per_dof: f64,
}

/// A record the screen rejected.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RejectedRecord {
    /// The source's label.
    pub label: String,
    /// Its file.
    pub file: String,
    /// The record's line in the file.
    pub line: u64,
    /// Index of the record in the source (0-based).
    pub record: usize,
    /// Its prediction residual from the fit without it, in noise standard
    /// deviations (`sqrt(T_j)`, see the module docs).
    pub residual_sigma: f64,
}

impl RejectedRecord {
    /// One sentence.
    pub fn to_text(&self) -> String {
        format!(
            "rejected {} line {} ({}): {:.1} noise standard deviations from the fit of the other records (a gross error); the fit is without it",
            self.file, self.line, self.label, self.residual_sigma
        )
    }
}
