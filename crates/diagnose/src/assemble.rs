//! The report assembled from what the pipeline found ([`Outcome`]): the
//! geometric model's adequacy, the aliases, the named causes (outliers
//! first, then each term of the final model with its description), the
//! final adequacy and the verdict, the gain, the remainder when the final
//! model leaves one, and the residual plots.

use tricept_data::Dataset;
use tricept_kinematics::Machine;
use tricept_model::effects::{CHANNELS, CauseName, EffectName, GenericFamily};
use tricept_numerics::stats::chi2_sf;

use crate::alias::{Aliases, analyse};
use crate::describe::describe;
use crate::dictionary::Scored;
use crate::error::DiagnoseError;
use crate::fit::{Fit, clean_poses, estimates, residuals_of, without};
use crate::gain::{improvement, volumetric_difference};
use crate::holdout::deployable;
use crate::noise::{Repeats, noise_check};
use crate::report::{
    Alias, Cause, CauseKind, ChannelRms, Diagnosis, Estimate, Evidence, FinalFit, Gain, Remainder,
    TermScore, Verdict,
};
use crate::residuals::{PlotOf, residual_plot, structure};
use crate::select::{Selection, Setup};
use crate::terms::Term;

/// What one pass of the pipeline found: the poses flagged as outliers and
/// the selection on the others.
pub(crate) struct Outcome {
    pub(crate) flagged: Vec<usize>,
    pub(crate) selection: Selection,
}

/// The diagnosis of `data` (on the machine whose nominal model is
/// `nominal`) from the pipeline's `outcome`.
pub(crate) fn report(
    nominal: &Machine,
    data: &Dataset,
    setup: &Setup<'_>,
    outcome: Outcome,
    repeated: &Repeats,
    limitations: Vec<String>,
) -> Result<Diagnosis, DiagnoseError> {
    let fitter = &setup.fitter;
    let Outcome { flagged, selection } = outcome;
    let outliers = !flagged.is_empty();
    let is_clean = without(data.poses.len(), &flagged);
    let clean = clean_poses(data, &flagged);
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
    let geo_res = residuals_of(&geo, &clean.poses, &fitter.sigma);
    let chi_square = geo.id.stats.chi_square;
    let dof = geo.id.stats.dof;
    let chi_square_p_value = fitter.reference.adequacy_p_value(chi_square, dof);
    let residual_rms_geometric = ChannelRms::from_internal(geo.id.stats.rms);
    let geometric_structure = structure(nominal, &clean, &geo_res);

    let Aliases {
        aliases,
        unnamed,
        alternatives,
        rejected: implausible_alternatives,
    } = analyse(setup, &clean, &current);
    rejected.extend(implausible_alternatives);

    let mut causes = Vec::new();
    if outliers {
        causes.push(outlier_cause(setup, data, &current, &flagged));
    }
    let final_estimates = estimates(&current);
    let named_terms = Named {
        terms: &terms,
        evidences: &evidences,
        unnamed: &unnamed,
        alternatives: &alternatives,
    };
    causes.extend(term_causes(
        setup,
        &clean,
        &current,
        &final_estimates,
        &named_terms,
    ));
    // Strongest first (outliers first only when they are the strongest).
    causes.sort_by(|a, b| b.evidence.delta_bic.total_cmp(&a.evidence.delta_bic));

    // Final adequacy.
    let final_chi2 = fitter.final_chi_square(&current, &clean);
    let final_dof = current.id.stats.dof;
    let final_p = fitter.reference.adequacy_p_value(final_chi2, final_dof);
    let final_screen = setup.screen(&current, &clean);
    let directed = final_screen
        .first()
        .filter(|s| s.p_adjusted < setup.alpha_share());
    let final_adequate = final_p > fitter.options.alpha && directed.is_none();
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
        fitter
            .holdout_rms(&fitter.base_model(), data, &is_clean)
            .unwrap_or(geometric_rms)
            .max(geometric_rms)
    } else {
        geometric_rms
    };
    let (volumetric, volumetric_note) =
        volumetric_difference(nominal, &geo, &current, fitter.options);

    // What is worth deploying, and the deployed model's improvement over
    // the geometric-only fit.
    let (model_terms, deployed_fit) = deployable(nominal, setup, &clean, &current);
    let deployed_fit = match deployed_fit {
        Some(fit) => fit,
        None if model_terms.iter().all(|t| t.deployed) => current.clone(),
        None => geo.clone(),
    };
    let gained = improvement(nominal, &geo, &deployed_fit, fitter.options);

    let noise = noise_check(fitter, repeated, &current, data);
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
            improvement_mm: gained.map(|g| g.mean_mm),
            improvement_sd_mm: gained.map(|g| g.sd_mm),
            difference_sd_mm: gained.map(|g| g.difference_sd_mm),
        },
        model_terms,
        geometric_only,
        extended: final_estimates,
        geometric_bias,
        plots: Vec::new(),
    };
    if !final_adequate {
        let fit = FinalFit {
            chi_square: final_chi2,
            dof: final_dof,
            p_value: final_p,
        };
        let remainder = remainder(
            nominal,
            setup,
            &clean,
            &current,
            &fit,
            current_rms,
            terms.is_empty(),
            &final_screen,
            &d,
        );
        if !named {
            d.unexplained = Some(format!(
                "{}; no candidate effect explains it: the cause is outside the vocabulary and the dictionary",
                remainder.text
            ));
        }
        d.remainder = Some(remainder);
    }
    d.plots = plots(&d.causes, &d.aliases)
        .iter()
        .filter_map(|p| residual_plot(p, nominal, &clean, &geo, &current, &fitter.sigma))
        .collect();
    Ok(d)
}

/// The `outliers` cause: the flagged poses of `data`, their largest
/// residual under the final model `current` and the evidence of setting
/// them aside.
fn outlier_cause(setup: &Setup<'_>, data: &Dataset, current: &Fit, flagged: &[usize]) -> Cause {
    let fitter = &setup.fitter;
    let n = data.poses.len();
    let all = fitter.fit(current.model.clone(), data).ok();
    let z_max = residuals_of(current, &data.poses, &fitter.sigma)
        .iter()
        .flatten()
        .flat_map(|r| r.iter().map(|v| v.abs()))
        .fold(0.0, f64::max);
    let p_value = ((3 * n) as f64 * chi2_sf(z_max * z_max, 1.0)).min(1.0);
    let delta = all.map_or(0.0, |a| a.id.stats.chi_square - current.id.stats.chi_square);
    let rows: Vec<u64> = flagged.iter().map(|&j| data.poses[j].line).collect();
    let penalty = (3 * flagged.len()) as f64 * ((3 * n) as f64).ln();
    Cause {
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
            threshold: fitter.options.alpha,
            delta_bic: delta - penalty,
            holdout_rms_without: None,
            holdout_rms_with: None,
            selected: true,
            multiplicity: 3 * n,
            p_adjusted: p_value,
            penalised_gain: delta - penalty,
        },
        rows,
        channel: None,
        legs: Vec::new(),
    }
}

/// The terms of the final model and what the alias analysis said of them.
struct Named<'a> {
    terms: &'a [Term],
    evidences: &'a [Evidence],
    /// Terms not named (a plausible alias is reported instead).
    unnamed: &'a [Term],
    /// The alternatives of each generic term, in words.
    alternatives: &'a [(Term, Vec<String>)],
}

/// A cause for every named term of the final model `current`, with its
/// estimates (a periodic term's period first, with its uncertainty from the
/// screen that found it, recomputed at the final model without the term).
fn term_causes(
    setup: &Setup<'_>,
    clean: &Dataset,
    current: &Fit,
    final_estimates: &[Estimate],
    named: &Named<'_>,
) -> Vec<Cause> {
    let offsets = current.model.offsets();
    let mut causes = Vec::new();
    for ((term, ev), at) in named.terms.iter().zip(named.evidences).zip(&offsets) {
        if named.unnamed.contains(term) {
            continue;
        }
        let k = term.param_count();
        let mut parameters = final_estimates[*at..*at + k].to_vec();
        let (mut period_sd, mut edges_sd) = (None, [None, None]);
        if let Term::Generic(g) = term
            && (g.period_mm.is_some() || g.edges_mm.is_some())
        {
            let rescanned = scan_uncertainty(setup, clean, current, term);
            let prefix = g.family.as_str();
            if let Some(p) = g.period_mm {
                period_sd = rescanned.as_ref().and_then(|s| s.period_sd_mm);
                parameters.insert(
                    0,
                    Estimate {
                        name: format!("{prefix}.period_mm"),
                        value: p,
                        std_dev: period_sd,
                    },
                );
            }
            if let (Some(edges), Some(leg)) = (g.edges_mm, g.legs().first()) {
                edges_sd = rescanned
                    .as_ref()
                    .and_then(|s| s.edges_sd_mm)
                    .unwrap_or([None, None]);
                for (k, side) in ["from", "to"].iter().enumerate().rev() {
                    parameters.insert(
                        0,
                        Estimate {
                            name: format!("{prefix}.leg{}_{side}_mm", leg + 1),
                            value: edges[k],
                            std_dev: edges_sd[k],
                        },
                    );
                }
            }
        }
        let alts = named
            .alternatives
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
            description: describe(
                term,
                current,
                &setup.fitter.frame,
                period_sd,
                edges_sd,
                &alts,
            ),
            plausible: setup.plausible(current, term).is_ok(),
            parameters,
            evidence: ev.clone(),
            rows: Vec::new(),
            channel,
            legs,
        });
    }
    causes
}

/// The scan of a scanned term of `fit` (a periodic term, a step) at the
/// final model without the term, for the uncertainty of its nonlinear
/// parameters: the period's from the scan's curvature, the edges' from
/// their profile likelihood.
fn scan_uncertainty(setup: &Setup<'_>, clean: &Dataset, fit: &Fit, term: &Term) -> Option<Scored> {
    let others: Vec<Term> = fit
        .model
        .terms()
        .iter()
        .copied()
        .filter(|t| t != term)
        .collect();
    let fitter = &setup.fitter;
    let without = fitter.fit(fitter.model(&others), clean).ok()?;
    let Term::Generic(g) = term else { return None };
    let mut screened = setup.screen(&without, clean).into_iter();
    match (g.period_mm, g.edges_mm) {
        (Some(target), _) => screened
            .filter(|s| s.term.family == GenericFamily::LegPeriodic)
            .find(|s| {
                s.term
                    .period_mm
                    .is_some_and(|p| (p - target).abs() < 0.02 * target)
            }),
        (None, Some(_)) => {
            screened.find(|s| s.term.family == GenericFamily::LegStep && s.term.scope == g.scope)
        }
        (None, None) => None,
    }
}

/// What the final model leaves: its fit, the strongest residual structure
/// and the best generic term the dictionary did not name, with why.
#[allow(clippy::too_many_arguments)]
fn remainder(
    nominal: &Machine,
    setup: &Setup<'_>,
    clean: &Dataset,
    current: &Fit,
    fit: &FinalFit,
    current_rms: f64,
    geometric_only: bool,
    final_screen: &[Scored],
    d: &Diagnosis,
) -> Remainder {
    let final_res = residuals_of(current, &clean.poses, &setup.fitter.sigma);
    let remaining = structure(nominal, clean, &final_res);
    let strongest_term = final_screen.first().map(|s| TermScore {
        effect: CauseName::Generic(s.term.family),
        description: s.term.label(),
        delta_chi_square: s.explained,
        dof: s.rank,
        p_adjusted: s.p_adjusted,
        why_not_named: why_not_named(s, d, setup.alpha_share()),
    });
    let mut text = format!(
        "{} leaves chi-square {:.1} for {} dof (p = {:.1e}), held-out rms {current_rms:.2}",
        if geometric_only {
            "the geometric model"
        } else {
            "the final model"
        },
        fit.chi_square,
        fit.dof,
        fit.p_value
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
    Remainder {
        chi_square: fit.chi_square,
        dof: fit.dof,
        p_value: fit.p_value,
        holdout_rms: current_rms,
        structure: remaining,
        strongest_term,
        text,
    }
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

/// The residual plots: of the causes, and of the model's member of each
/// alias set.
fn plots(causes: &[Cause], aliases: &[Alias]) -> Vec<PlotOf> {
    let mut plotted: Vec<PlotOf> = causes.iter().map(PlotOf::cause).collect();
    for a in aliases {
        if a.in_model.catalogue().is_some() && !plotted.iter().any(|p| p.effect == a.in_model) {
            plotted.push(PlotOf {
                effect: a.in_model,
                leg: 0,
                channel: 2,
                period_mm: None,
            });
        }
    }
    plotted
}
