//! The diagnosis: is the geometric model adequate; if not, what explains
//! the data, what does not, and what cannot be told apart.
//!
//! 1. **Checks.** Every value finite, at least 20 poses; data without
//!    distinct line numbers are numbered from 1 in pose order.
//! 2. **Noise.** Repeated poses give the pure error ([`crate::noise`]); with
//!    `noise_from_data` the tests use the data's noise and F distributions.
//! 3. **Outliers.** The outlier screen of `tricept_ident::robust`; flagged
//!    poses make the cause `outliers`, and the rest of the analysis uses
//!    the clean poses. The screen is repeated with the selected causes, so
//!    that a misfit they explain is not taken for gross errors.
//! 4. **Selection** from one pool, the vocabulary and the generic
//!    dictionary, with plausibility and admission on the final model
//!    ([`crate::select`]).
//! 5. **Aliases** ([`crate::alias`]).
//! 6. **Final adequacy**: the final model's chi-square (with the
//!    temperature logger's noise propagated into readings that depend on
//!    temperature: errors in variables) and the dictionary screened once
//!    more at the final model; when either fails, the data are *partially
//!    explained* and the remainder is reported.
//! 7. **Report**, with a last check that every number in it is finite.

use std::sync::Arc;

use tricept_data::{Dataset, MeasuredPose};
use tricept_ident::{GeometricModel, IdentError, ReadingModel};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_model::effects::{CauseName, EffectName, GenericFamily};
use tricept_numerics::stats::chi2_sf;

use crate::alias::{Aliases, analyse};
use crate::dictionary::{Dictionary, DictionaryOptions, Scored};
use crate::evidence::Reference;
use crate::finite::first_non_finite;
use crate::model::Candidate;
use crate::noise::{check, pure_error, repeats};
use crate::plausibility::Plausibility;
use crate::report::{
    Cause, CauseKind, ChannelRms, Diagnosis, Estimate, Evidence, FinalFit, Gain, NoiseCheck,
    NoiseSource, Remainder, TermScore, Verdict,
};
use crate::residuals::{PlotOf, residual_plot, structure};
use crate::select::{
    Fit, Selection, Setup, estimates, residuals_of, screen_outliers, select, term_estimates,
};
use crate::terms::{CHANNELS, Frame, Term};

/// Why a diagnosis could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// The geometric identification itself failed.
    #[error(transparent)]
    Ident(#[from] IdentError),
    /// Too few poses for cross-validation.
    #[error("too few poses ({0}) for a diagnosis: at least 20 are needed")]
    TooFewPoses(usize),
    /// The geometric model cannot be fitted to the data: the fit does not
    /// converge or needs geometric errors beyond any machine's.
    #[error(
        "the geometric model cannot be fitted to these data (after {iterations} iterations the largest geometric error is {largest_error_mm:.3e} mm): rows that do not belong together (swapped columns, another machine) or readings in the wrong units"
    )]
    NotConverged {
        /// Largest geometric error of the failed fit, mm.
        largest_error_mm: f64,
        /// Gauss-Newton iterations performed.
        iterations: u32,
    },
    /// The data cannot support a diagnosis.
    #[error("{0}")]
    Degenerate(String),
    /// A report number is not finite (a defect: reported rather than printed).
    #[error("internal error: the report's `{field}` is not a finite number")]
    NonFinite {
        /// Path of the number in the report.
        field: String,
    },
    /// `noise_from_data` without enough repeated poses.
    #[error(
        "the noise can be estimated from the data only with repeated poses: {dof} degrees of freedom of pure error, at least {needed} needed (log some poses again on separate visits)"
    )]
    NoiseFromDataNeedsRepeats {
        /// Degrees of freedom available per channel.
        dof: usize,
        /// Degrees of freedom needed.
        needed: usize,
    },
}

/// Options of [`diagnose`].
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
        }
    }
}

/// Diagnoses `data` taken on a machine whose nominal model is `nominal`.
///
/// # Example
/// ```no_run
/// use tricept_diagnose::{diagnose, DiagnoseOptions};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let data = tricept_data::read_path("fixtures/data/diagnose-hidden-effect.csv".as_ref()).unwrap();
/// let d = diagnose(&m, &data, &DiagnoseOptions::for_machine(&m)).unwrap();
/// println!("{:?}: {:?}", d.verdict, d.causes.iter().map(|c| c.effect).collect::<Vec<_>>());
/// ```
pub fn diagnose(
    nominal: &Machine,
    data: &Dataset,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let n = data.poses.len();
    if n < 20 {
        return Err(DiagnoseError::TooFewPoses(n));
    }
    check_values(data)?;
    let mut limitations = Vec::new();
    let data = numbered(data, &mut limitations);
    let frame = Arc::new(Frame::of(nominal, &data));
    let repeated = repeats(&data, options.repeat_tolerance_mm);
    let distinct = n - repeated.dof();
    if distinct < 20 {
        return Err(DiagnoseError::Degenerate(format!(
            "only {distinct} distinct leg commands among {n} rows (repeated commands do not count): at least 20 distinct poses are needed to fit and test the model",
        )));
    }
    let mut geometric = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    if let Some(reference) = &options.rank_reference {
        geometric = geometric.with_rank_reference(reference.clone());
    }
    let available: Vec<Candidate> = Candidate::ALL
        .iter()
        .copied()
        .filter(|c| c.available(&data))
        .collect();
    let dictionary = Dictionary::new(&frame, &options.dictionary);
    if !options.dictionary.enabled {
        limitations.push(
            "the generic dictionary was not searched: effects outside the vocabulary can only be reported as unexplained".into(),
        );
    }
    if frame.temperature.is_none() {
        limitations.push(
            "the logged temperature is missing or varies by less than 0.25 K: thermal effects cannot be seen".into(),
        );
    }
    let mut setup = Setup {
        options,
        sigma: options.sigma,
        reference: Reference::stated(),
        frame,
        dictionary,
        plausibility: &options.plausibility,
        geometric,
        available,
    };
    if options.noise_from_data {
        let dof = repeated.dof();
        if dof < MIN_PURE_ERROR_DOF {
            return Err(DiagnoseError::NoiseFromDataNeedsRepeats {
                dof,
                needed: MIN_PURE_ERROR_DOF,
            });
        }
        // Within a repeat group a model without context terms predicts the
        // same readings: the raw readings' spread is the first estimate.
        let raw: Vec<Option<[f64; 3]>> = data
            .poses
            .iter()
            .map(|p| {
                let y = p.readings.to_array();
                Some(std::array::from_fn(|c| y[c] / options.sigma[c]))
            })
            .collect();
        if let Some((ss, dof)) = pure_error(&repeated, &raw) {
            setup.sigma = rescaled(options.sigma, ss, dof);
            setup.reference = Reference {
                pure_error_dof: Some(3.0 * dof as f64),
            };
        }
    }
    let mut outcome = run(&setup, &data)?;
    if options.noise_from_data {
        // The spread about the final model: refit once if it moved.
        let res = residuals_of(&outcome.selection.current, &data.poses, &setup.sigma);
        if let Some((ss, dof)) = pure_error(&repeated, &res) {
            let ratio = ss.map(|s| (s / dof as f64).sqrt());
            if ratio.iter().any(|r| (r - 1.0).abs() > 0.1) {
                setup.sigma = rescaled(setup.sigma, ss, dof);
                outcome = run(&setup, &data)?;
            }
        }
    }
    let d = report(nominal, &data, &setup, outcome, &repeated, limitations)?;
    match first_non_finite(&d) {
        Some(field) => Err(DiagnoseError::NonFinite { field }),
        None => Ok(d),
    }
}

/// `sigma` scaled by the pure error's ratio per channel.
fn rescaled(sigma: [f64; 3], ss: [f64; 3], dof: usize) -> [f64; 3] {
    std::array::from_fn(|c| {
        let ratio = (ss[c] / dof as f64).sqrt();
        if ratio > 0.0 && ratio.is_finite() {
            sigma[c] * ratio
        } else {
            sigma[c]
        }
    })
}

/// Every logged value must be finite.
fn check_values(data: &Dataset) -> Result<(), DiagnoseError> {
    for p in &data.poses {
        let mut values: Vec<f64> = p.commands_mm.to_vec();
        values.extend(p.readings.to_array());
        values.extend(p.temp_c);
        values.extend(p.time_s);
        if values.iter().any(|v| !v.is_finite()) {
            return Err(DiagnoseError::Degenerate(format!(
                "line {}: a value is not a finite number",
                p.line
            )));
        }
    }
    Ok(())
}

/// The data with distinct line numbers (numbered from 1 in pose order
/// when they are not).
fn numbered(data: &Dataset, limitations: &mut Vec<String>) -> Dataset {
    let mut lines: Vec<u64> = data.poses.iter().map(|p| p.line).collect();
    lines.sort_unstable();
    lines.dedup();
    if lines.len() == data.poses.len() {
        return data.clone();
    }
    limitations.push(
        "the poses carry no distinct line numbers: rows are numbered from 1 in pose order".into(),
    );
    let mut d = data.clone();
    for (j, p) in d.poses.iter_mut().enumerate() {
        p.line = j as u64 + 1;
    }
    d
}

/// What one pass of the pipeline found.
struct Outcome {
    flagged: Vec<usize>,
    selection: Selection,
}

fn run(setup: &Setup<'_>, data: &Dataset) -> Result<Outcome, DiagnoseError> {
    let base = setup.base_model();
    let mut flagged = screen_outliers(setup, &base, data)?;
    let mut rounds = 0;
    loop {
        rounds += 1;
        let clean = data.subset(|j| !flagged.contains(&j));
        let selection = select(setup, &clean)?;
        let again = screen_outliers(setup, &selection.current.model, data)?;
        if again == flagged || rounds == 3 {
            return Ok(Outcome { flagged, selection });
        }
        flagged = again;
    }
}

/// Standard screw leads, mm.
const SCREW_LEADS_MM: [f64; 12] = [
    4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 32.0, 40.0, 50.0,
];

/// One-line description of a named term.
fn describe(
    term: &Term,
    fit: &Fit,
    setup: &Setup<'_>,
    period_sd: Option<f64>,
    alternatives: &[String],
) -> String {
    let (v, cov) = term_estimates(fit, term);
    let sd = |i: usize| cov[(i, i)].max(0.0).sqrt();
    let pm = |i: usize| format!("{:.1} +- {:.1}", v[i], sd(i));
    let legs_list = |legs: &[usize]| {
        let names: Vec<String> = legs.iter().map(|i| (i + 1).to_string()).collect();
        format!(
            "leg{} {}",
            if legs.len() > 1 { "s" } else { "" },
            names.join(", ")
        )
    };
    let or_alternatives = if alternatives.is_empty() {
        String::new()
    } else {
        format!(
            " (or, indistinguishably on this campaign: {})",
            alternatives.join(", ")
        )
    };
    let text = match term {
        Term::Catalogue(c) => {
            let params: Vec<String> = c
                .params()
                .iter()
                .enumerate()
                .map(|(i, n)| format!("{n} {}", pm(i)))
                .collect();
            let what = match c.0 {
                EffectName::LegLead => "ball-screw lead errors",
                EffectName::Backlash => "lost motion of the legs",
                EffectName::Thermal => "thermal growth of the legs with the logged temperature",
                EffectName::ScaleGain => "gain error of the linear scale",
                EffectName::EncoderEccentricity => "once-per-revolution errors of the encoders",
                EffectName::UjointAxes => "U-joint axes skewed or offset",
                EffectName::TubeTwist => "the platform twists about the UP limb as it extends",
                EffectName::Compliance => "the legs stretch under the platform's weight",
                EffectName::Outliers => "gross reading errors",
            };
            format!("{what}: {}", params.join(", "))
        }
        Term::Generic(g) => {
            let legs = g.legs();
            match g.family {
                GenericFamily::LegPeriodic => {
                    let period = g.period_mm.unwrap_or(f64::NAN);
                    let amps: Vec<String> = (0..legs.len())
                        .map(|k| format!("{:.1}", v[2 * k].hypot(v[2 * k + 1])))
                        .collect();
                    let sd_text = period_sd.map_or(String::new(), |s| format!(" +- {s:.3}"));
                    let lead = SCREW_LEADS_MM.iter().find(|&&l| {
                        (period - l).abs() <= 3.0 * period_sd.unwrap_or(0.0) + 0.005 * l
                    });
                    // A harmonic of another periodic term of the model: the
                    // error is periodic but not sinusoidal.
                    let fundamental = fit.model.terms().iter().find_map(|t| match t {
                        Term::Generic(o) if o.period_mm.is_some_and(|p| p > 1.5 * period) => {
                            let p = o.period_mm.unwrap_or(f64::NAN);
                            let k = (p / period).round();
                            ((p / period - k).abs() < 0.01 * k).then_some((p, k))
                        }
                        _ => None,
                    });
                    format!(
                        "{}: length error periodic in the leg length, period {period:.3}{sd_text} mm, amplitude {} um: {}",
                        legs_list(&legs),
                        amps.join(" / "),
                        match (fundamental, lead) {
                            (Some((p, k)), _) => format!(
                                "harmonic {k:.0} of the {p:.3} mm period: that periodic error is not a sine"
                            ),
                            (None, Some(l)) => format!("ball-screw pitch error ({l} mm lead)?"),
                            (None, None) => "a periodic error of the drive (screw pitch, gear or encoder of the drive)?".into(),
                        }
                    )
                }
                GenericFamily::LegPolynomial => {
                    let parts: Vec<String> = legs
                        .iter()
                        .enumerate()
                        .map(|(k, i)| {
                            let [lo, hi] = setup.frame.leg_range_mm[*i];
                            let (c1, a, b) = (v[3 * k], v[3 * k + 1], v[3 * k + 2]);
                            let curve = |x: f64| {
                                a * tricept_model::effects::legendre_p2(x)
                                    + b * tricept_model::effects::legendre_p3(x)
                            };
                            let (mn, mx) = (0..=100)
                                .map(|s| curve(-1.0 + 0.02 * s as f64))
                                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
                                    (l.min(y), h.max(y))
                                });
                            let lead_ppm = c1 / (0.5 * (hi - lo)).max(1e-9) * 1e3;
                            format!(
                                "leg {}: curvature {:.1} um peak-to-valley over {lo:.0}-{hi:.0} mm, linear part {lead_ppm:.0} ppm",
                                i + 1,
                                mx - mn
                            )
                        })
                        .collect();
                    format!(
                        "length error curved along the stroke ({}): ball-screw travel variation (and mean travel deviation) or a bent guide?",
                        parts.join("; ")
                    )
                }
                GenericFamily::LegDrift => {
                    let d: Vec<String> = (0..legs.len()).map(pm).collect();
                    format!(
                        "{}: lengths drift by {} um over the campaign: creep or drive warm-up?",
                        legs_list(&legs),
                        d.join(" / ")
                    )
                }
                GenericFamily::ReadingDrift => {
                    let c = g.channel().unwrap_or(2);
                    let unit = if c == 2 { "um" } else { "arcsec" };
                    let temperature = if alternatives
                        .iter()
                        .any(|a| a.starts_with("reading-temperature") || a == "thermal")
                    {
                        "with time or with temperature (they followed each other during the campaign)"
                    } else if setup.frame.temperature.is_some() {
                        "independent of temperature"
                    } else {
                        "with time (no varying temperature was logged to tell)"
                    };
                    format!(
                        "{} reading drifts {} {unit} over the campaign, {temperature}",
                        CHANNELS[c],
                        pm(0)
                    )
                }
                GenericFamily::ReadingTemperature => {
                    let c = g.channel().unwrap_or(2);
                    let unit = if c == 2 { "um/K" } else { "arcsec/K" };
                    format!(
                        "{} reading changes by {} {unit} with the logged temperature: thermal drift of the sensor or its mount?",
                        CHANNELS[c],
                        pm(0)
                    )
                }
                GenericFamily::EncoderGain => {
                    let c = g.channel().unwrap_or(0);
                    format!(
                        "the {} encoder reads (1 + g) times the angle, g = {} ppm: encoder gain (scaling or interpolation) error?",
                        CHANNELS[c],
                        pm(0)
                    )
                }
                GenericFamily::ScalePolynomial => format!(
                    "scale reading error curved along the UP-limb stroke (P2 {} um, P3 {} um): scale bending or mounting?",
                    pm(0),
                    pm(1)
                ),
                GenericFamily::ReadingHysteresis => {
                    let c = g.channel().unwrap_or(2);
                    let unit = if c == 2 { "um" } else { "arcsec" };
                    format!(
                        "{} reading lags in the direction the sensor moved: reversal error {} {unit}",
                        CHANNELS[c],
                        pm(0)
                    )
                }
            }
        }
    };
    format!("{text}{or_alternatives}")
}

/// Chi-square of the final model with the temperature logger's noise in
/// the variance of readings that depend on temperature (errors in
/// variables).
fn final_chi_square(setup: &Setup<'_>, fit: &Fit, clean: &Dataset) -> f64 {
    let temperature_terms = fit.model.terms().iter().any(|t| {
        matches!(t, Term::Catalogue(Candidate(EffectName::Thermal)))
            || matches!(t, Term::Generic(g) if g.family == GenericFamily::ReadingTemperature)
    });
    let sigma = setup.sigma;
    if !temperature_terms || setup.options.temperature_sigma_k <= 0.0 {
        return fit.id.stats.chi_square;
    }
    let predictor = fit.model.at(&fit.id.estimate);
    let k = fit.model.names().len();
    let mut jac = vec![0.0; 3 * k];
    let st = setup.options.temperature_sigma_k;
    let mut chi2 = 0.0;
    for (pose, r) in clean.poses.iter().zip(&fit.id.residuals) {
        let mut at = |dt: f64| -> Option<[f64; 3]> {
            let mut p: MeasuredPose = *pose;
            p.temp_c = p.temp_c.map(|t| t + dt);
            let mut seed = None;
            predictor.predict(&p, &mut seed, &mut jac).ok()
        };
        let slope = match (at(0.5), at(-0.5)) {
            (Some(a), Some(b)) => std::array::from_fn(|c| a[c] - b[c]),
            _ => [0.0; 3],
        };
        for c in 0..3 {
            let var = sigma[c] * sigma[c] + (slope[c] * st).powi(2);
            chi2 += r[c] * r[c] / var;
        }
    }
    chi2
}

fn why_not_named(s: &Scored, d: &Diagnosis, alpha_share: f64) -> String {
    let label = s.term.label();
    if let Some(r) = d.rejected.iter().find(|r| r.description == label) {
        return r.reason.clone();
    }
    if s.p_adjusted >= alpha_share {
        format!(
            "not significant after the dictionary's {} tests (adjusted p = {:.1e})",
            d.dictionary_tests, s.p_adjusted
        )
    } else {
        "significant, but it did not improve the held-out fit or the penalised gain when refitted"
            .into()
    }
}

fn report(
    nominal: &Machine,
    data: &Dataset,
    setup: &Setup<'_>,
    outcome: Outcome,
    repeated: &crate::noise::Repeats,
    limitations: Vec<String>,
) -> Result<Diagnosis, DiagnoseError> {
    let options = setup.options;
    let Outcome { flagged, selection } = outcome;
    let n = data.poses.len();
    let outliers = !flagged.is_empty();
    let is_clean = |j: usize| !flagged.contains(&j);
    let clean = data.subset(is_clean);
    let Selection {
        terms,
        evidences,
        current,
        current_rms,
        geometric_rms,
        first_candidates,
        geo,
        mut rejected,
    } = selection;

    // Adequacy of the geometric model on the clean poses.
    let geo_res = residuals_of(&geo, &clean.poses, &setup.sigma);
    let chi_square = geo.id.stats.chi_square;
    let dof = geo.id.stats.dof;
    let chi_square_p_value = setup.reference.adequacy_p_value(chi_square, dof);
    let residual_rms_geometric = ChannelRms::from_internal(geo.id.stats.rms);
    let geometric_structure = structure(nominal, &clean, &geo_res);

    // Aliases.
    let Aliases {
        aliases,
        unnamed,
        alternatives,
        rejected: implausible_alternatives,
    } = analyse(setup, &clean, &current);
    rejected.extend(implausible_alternatives);

    // Causes.
    let mut causes = Vec::new();
    if outliers {
        let all = setup.fit(current.model.clone(), data).ok();
        let z_max = residuals_of(&current, &data.poses, &setup.sigma)
            .iter()
            .flatten()
            .flat_map(|r| r.iter().map(|v| v.abs()))
            .fold(0.0, f64::max);
        let p_value = ((3 * n) as f64 * chi2_sf(z_max * z_max, 1.0)).min(1.0);
        let delta = all.map_or(0.0, |a| a.id.stats.chi_square - current.id.stats.chi_square);
        let rows: Vec<u64> = flagged.iter().map(|&j| data.poses[j].line).collect();
        causes.push(Cause {
            effect: CauseName::Catalogue(EffectName::Outliers),
            kind: CauseKind::Outliers,
            description: format!(
                "{} gross reading error{} (largest {z_max:.0} sigma), set aside",
                rows.len(),
                if rows.len() == 1 { "" } else { "s" }
            ),
            plausible: true,
            parameters: vec![
                Estimate {
                    name: "flagged_poses".into(),
                    value: flagged.len() as f64,
                    std_dev: None,
                },
                Estimate {
                    name: "largest_residual_sigma".into(),
                    value: z_max,
                    std_dev: None,
                },
            ],
            evidence: Evidence {
                delta_chi_square: delta,
                dof: 3 * flagged.len(),
                p_value,
                threshold: options.alpha,
                delta_bic: delta - (3 * flagged.len()) as f64 * ((3 * n) as f64).ln(),
                holdout_rms_without: None,
                holdout_rms_with: None,
                selected: true,
                multiplicity: 3 * n,
                p_adjusted: p_value,
                penalised_gain: delta - (3 * flagged.len()) as f64 * ((3 * n) as f64).ln(),
            },
            rows,
            channel: None,
            legs: Vec::new(),
        });
    }
    let final_estimates = estimates(&current);
    let offsets = current.model.offsets();
    // The period's uncertainty of a periodic term, from the screen that
    // found it (recomputed at the final model without the term).
    for ((term, ev), at) in terms.iter().zip(&evidences).zip(&offsets) {
        if unnamed.contains(term) {
            continue;
        }
        let k = term.params().len();
        let mut parameters = final_estimates[*at..*at + k].to_vec();
        let mut period_sd = None;
        if let Term::Generic(g) = term
            && let Some(p) = g.period_mm
        {
            period_sd = period_uncertainty(setup, &clean, &current, term);
            let prefix = final_estimates[*at]
                .name
                .split('.')
                .next()
                .unwrap_or("leg-periodic")
                .to_string();
            parameters.insert(
                0,
                Estimate {
                    name: format!("{prefix}.period_mm"),
                    value: p,
                    std_dev: period_sd,
                },
            );
        }
        let alts = alternatives
            .iter()
            .find(|(t, _)| t == term)
            .map(|(_, a)| a.clone())
            .unwrap_or_default();
        let (channel, legs) = match term {
            Term::Generic(g) => (
                g.channel().map(|c| CHANNELS[c]),
                g.legs().iter().map(|i| *i as u8 + 1).collect(),
            ),
            Term::Catalogue(_) => (None, Vec::new()),
        };
        causes.push(Cause {
            effect: term.name(),
            kind: if term.name().is_generic() {
                CauseKind::Generic
            } else {
                CauseKind::Catalogue
            },
            description: describe(term, &current, setup, period_sd, &alts),
            plausible: setup.plausible(&current, term).is_ok(),
            parameters,
            evidence: ev.clone(),
            rows: Vec::new(),
            channel,
            legs,
        });
    }
    // Strongest first (outliers first only when they are the strongest).
    causes.sort_by(|a, b| b.evidence.delta_bic.total_cmp(&a.evidence.delta_bic));

    // Final adequacy.
    let final_chi2 = final_chi_square(setup, &current, &clean);
    let final_dof = current.id.stats.dof;
    let final_p = setup.reference.adequacy_p_value(final_chi2, final_dof);
    let final_screen = setup.screen(&current, &clean);
    let directed = final_screen
        .first()
        .filter(|s| s.p_adjusted < setup.alpha_share());
    let final_adequate = final_p > options.alpha && directed.is_none();
    let named = !causes.is_empty() || !aliases.is_empty();
    let adequate = !named && final_adequate;
    let verdict = match (adequate, named, final_adequate) {
        (true, _, _) => Verdict::Adequate,
        (false, true, true) => Verdict::Explained,
        (false, true, false) => Verdict::PartiallyExplained,
        (false, false, _) => Verdict::Unexplained,
    };

    let geometric_only = estimates(&geo);
    let g = current.model.n_geometric();
    let geometric_bias = final_estimates[..g]
        .iter()
        .zip(&geometric_only)
        .map(|(f, o)| (f.name.clone(), f.value - o.value))
        .collect();

    // Gain: held-out RMS on the clean poses for both models; with
    // outliers, the geometric model is trained on all poses.
    let holdout_rms_geometric = if outliers {
        setup
            .holdout_rms(&setup.base_model(), data, &is_clean)
            .unwrap_or(geometric_rms)
            .max(geometric_rms)
    } else {
        geometric_rms
    };
    let (volumetric, volumetric_note) = volumetric_difference(nominal, &geo, &current, options);

    let noise = noise_check(setup, repeated, &current, data);
    let mut d = Diagnosis {
        adequate,
        verdict,
        final_adequate,
        chi_square,
        dof,
        chi_square_p_value,
        final_fit: FinalFit {
            chi_square: final_chi2,
            dof: final_dof,
            p_value: final_p,
        },
        residual_rms_geometric,
        structure: geometric_structure,
        causes,
        aliases,
        rejected,
        remainder: None,
        noise,
        candidates: first_candidates,
        dictionary_tests: setup.dictionary.multiplicity(),
        unexplained: None,
        limitations,
        gain: Gain {
            holdout_rms_geometric,
            holdout_rms_extended: current_rms,
            volumetric_mean_mm: volumetric.map(|v| v.0),
            volumetric_max_mm: volumetric.map(|v| v.1),
            volumetric_touched_mean_mm: volumetric.map(|v| v.2),
            volumetric_note,
        },
        geometric_only,
        extended: final_estimates,
        geometric_bias,
        plots: Vec::new(),
    };
    if !final_adequate {
        let final_res = residuals_of(&current, &clean.poses, &setup.sigma);
        let remaining = structure(nominal, &clean, &final_res);
        let strongest_term = final_screen.first().map(|s| TermScore {
            effect: CauseName::Generic(s.term.family),
            description: s.term.label(),
            delta_chi_square: s.explained,
            dof: s.rank,
            p_adjusted: s.p_adjusted,
            why_not_named: why_not_named(s, &d, setup.alpha_share()),
        });
        let mut text = format!(
            "{} leaves chi-square {final_chi2:.1} for {final_dof} dof (p = {final_p:.1e}), held-out rms {current_rms:.2}",
            if terms.is_empty() {
                "the geometric model".to_string()
            } else {
                "the final model".to_string()
            }
        );
        if let Some(s) = remaining.first() {
            text.push_str(&format!(
                "; strongest residual structure: {} vs {} (r = {:+.2}, p = {:.1e})",
                s.channel, s.regressor, s.correlation, s.p_value
            ));
        }
        if let Some(t) = &strongest_term {
            text.push_str(&format!(
                "; best unnamed generic term: {} (chi2 drop {:.1} for {} dof, adjusted p = {:.1e}): {}",
                t.description, t.delta_chi_square, t.dof, t.p_adjusted, t.why_not_named
            ));
        }
        if !named {
            d.unexplained = Some(format!(
                "{text}; no candidate effect explains it: the cause is outside the vocabulary and the dictionary"
            ));
        }
        d.remainder = Some(Remainder {
            chi_square: final_chi2,
            dof: final_dof,
            p_value: final_p,
            holdout_rms: current_rms,
            structure: remaining,
            strongest_term,
            text,
        });
    }
    // Plots of the causes and of the model's member of each alias set.
    let mut plotted: Vec<PlotOf> = d.causes.iter().map(PlotOf::cause).collect();
    for a in &d.aliases {
        if a.in_model.catalogue().is_some() && !plotted.iter().any(|p| p.effect == a.in_model) {
            plotted.push(PlotOf {
                effect: a.in_model,
                leg: 0,
                channel: 2,
                period_mm: None,
            });
        }
    }
    d.plots = plotted
        .iter()
        .filter_map(|p| residual_plot(p, nominal, &clean, &geo, &current, &setup.sigma))
        .collect();
    Ok(d)
}

/// The period's standard deviation of a periodic term of `fit`: the scan's
/// curvature at the final model without the term.
fn period_uncertainty(setup: &Setup<'_>, clean: &Dataset, fit: &Fit, term: &Term) -> Option<f64> {
    let others: Vec<Term> = fit
        .model
        .terms()
        .iter()
        .copied()
        .filter(|t| t != term)
        .collect();
    let without = setup.fit(setup.model(&others), clean).ok()?;
    let Term::Generic(g) = term else { return None };
    let target = g.period_mm?;
    setup
        .screen(&without, clean)
        .into_iter()
        .filter(|s| s.term.family == GenericFamily::LegPeriodic)
        .filter_map(|s| {
            let p = s.term.period_mm?;
            ((p - target).abs() < 0.02 * target).then_some(s.period_sd_mm)
        })
        .next()
        .flatten()
}

/// The noise check against the repeated poses.
fn noise_check(
    setup: &Setup<'_>,
    repeated: &crate::noise::Repeats,
    fit: &Fit,
    data: &Dataset,
) -> NoiseCheck {
    let stated = ChannelRms::from_internal(setup.options.sigma);
    let used = if setup.reference.pure_error_dof.is_some() {
        NoiseSource::Data
    } else {
        NoiseSource::Stated
    };
    let res = residuals_of(fit, &data.poses, &setup.options.sigma);
    let Some((ss, dof)) = pure_error(repeated, &res) else {
        return NoiseCheck {
            stated,
            used,
            pure_error: None,
            agrees: None,
            note: "no repeated poses: the stated noise cannot be checked (revisit some poses on separate visits to check it)".into(),
        };
    };
    let (pe, agrees) = check(repeated, ss, dof, setup.options.sigma);
    let worst = (0..3)
        .max_by(|&a, &b| (pe.ratio[a].ln().abs()).total_cmp(&pe.ratio[b].ln().abs()))
        .unwrap_or(0);
    let mut note = if agrees {
        format!(
            "the stated noise agrees with {} repeated poses ({} dof; data/stated {:.2} / {:.2} / {:.2})",
            pe.groups, pe.dof, pe.ratio[0], pe.ratio[1], pe.ratio[2]
        )
    } else {
        format!(
            "the data's noise is {:.2}x the stated noise on {} (p = {:.1e}; {} repeated poses, {} dof): chi-square tests against the stated noise are unreliable{}",
            pe.ratio[worst],
            CHANNELS[worst],
            pe.p_value[worst],
            pe.groups,
            pe.dof,
            if used == NoiseSource::Data {
                ""
            } else {
                "; rerun with --noise-from-data"
            }
        )
    };
    if used == NoiseSource::Data {
        let s = ChannelRms::from_internal(setup.sigma);
        note.push_str(&format!(
            "; the tests used the data's noise: phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um (F tests)",
            s.phi_arcsec, s.theta_arcsec, s.s_um
        ));
    }
    if pe.within_visit > 0 {
        note.push_str(&format!(
            "; {} repeats were logged in consecutive rows (within a visit): they miss repositioning and vibration",
            pe.within_visit
        ));
    }
    NoiseCheck {
        stated,
        used,
        pure_error: Some(pe),
        agrees: Some(agrees),
        note,
    }
}

/// Mean, max and touched-off mean displacement of the platform on the
/// middle plane between the geometric-only calibration and the final one
/// (targets commanded through the geometric fit's IK, positions predicted
/// by the final model with the leg effects at the campaign's mean context),
/// and a note when targets could not be reached.
fn volumetric_difference(
    nominal: &Machine,
    geo: &Fit,
    fin: &Fit,
    options: &DiagnoseOptions,
) -> (Option<(f64, f64, f64)>, Option<String>) {
    let targets = nominal
        .workspace
        .disc_grid(nominal.workspace.mid_plane_z_mm(), options.plane_spacing_mm);
    let m_geo = geo.model.machine_at(&geo.id.estimate);
    let m_fin = fin.model.machine_at(&fin.id.estimate);
    let predictor = fin.model.at(&fin.id.estimate);
    let k = fin.model.names().len();
    let mut jac = vec![0.0; 3 * k];
    let mut map = tricept_model::ErrorMap {
        targets_mm: Vec::new(),
        errors_mm: Vec::new(),
    };
    for r in &targets {
        let Ok(ik) = m_geo.inverse(r) else { continue };
        let pose = MeasuredPose {
            commands_mm: ik.legs_mm,
            approach: None,
            ..Default::default()
        };
        let mut seed = Some(ik.up);
        // The final model's reading prediction solves its UP joints (the
        // reading effects are sensor-side and do not move the platform).
        if predictor.predict(&pose, &mut seed, &mut jac).is_err() {
            continue;
        }
        let Some(up) = seed else { continue };
        map.targets_mm.push(*r);
        map.errors_mm.push(m_fin.up_limb.pose(&up).position_mm - r);
    }
    let reached = map.targets_mm.len();
    if reached == 0 {
        return (
            None,
            Some(format!(
                "the calibrations cannot reach the middle plane (0 of {} targets)",
                targets.len()
            )),
        );
    }
    let raw = map.stats();
    let touched = map.without_mean_translation().stats();
    let note = (reached < targets.len()).then(|| {
        format!(
            "{reached} of {} middle-plane targets reached",
            targets.len()
        )
    });
    (Some((raw.mean_mm, raw.max_mm, touched.mean_mm)), note)
}
