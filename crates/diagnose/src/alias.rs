//! Aliases: candidates that this campaign cannot tell apart.
//!
//! For every term `A` of the final model, with `B0` the rest of the model
//! (offsets, identifiable geometric parameters, the other terms) at the
//! final estimate:
//!
//! ```text
//! s_A    = P_perp(B0) W J_A theta_A          A's fitted signature (noise units)
//! C_perp = P_perp(B0) W J_C                  for every candidate C not in the model
//! lambda(A, C) = min_w |s_A - C_perp w|^2    what no test could use to prefer A over C
//! ```
//!
//! `C` is an alias of `A` when `lambda(A, C) < chi2_1(1 - alpha)` (10.8 at
//! `alpha = 0.001`) and the parameters `w` it needs are plausible; exactly
//! so when the largest canonical correlation of the two projected spans is
//! 1 (to 1e-9). Candidates are the catalogue effects not in the model, an
//! equal lead on all legs, and the dictionary's groups without a period.
//! A catalogue term with a plausible alias is not named: the set is
//! reported instead (the final model keeps `A`, whose predictions equal the
//! alternatives' to within the noise). A generic term stays named, with its
//! alternatives in its description. Structurally, a leg lead whose common
//! part (the mean over the legs) is significant is always reported with
//! `scale-gain`: a scale gain `g` reads exactly like the machine scaled by
//! `1 + g` with a lead `g` on every leg.

use nalgebra::{DMatrix, DVector};
use tricept_data::Dataset;
use tricept_model::effects::{CauseName, CommonPart, EffectName, GenericFamily, Needs, Structural};
use tricept_numerics::stats::chi2_isf;

use crate::fit::{Fit, term_estimates};
use crate::linear::{Linearisation, canonical_correlation, nested};
use crate::report::{Alias, Estimate, RejectStage, Rejected};
use crate::select::Setup;
use crate::terms::{GenericTerm, Term};

/// The outcome of the alias analysis.
pub(crate) struct Aliases {
    /// The alias sets.
    pub(crate) aliases: Vec<Alias>,
    /// Terms of the model that are not named (catalogue terms with a
    /// plausible alias).
    pub(crate) unnamed: Vec<Term>,
    /// For each generic term, the descriptions of its alternatives.
    pub(crate) alternatives: Vec<(Term, Vec<String>)>,
    /// Alternatives that would need implausible parameters.
    pub(crate) rejected: Vec<Rejected>,
}

/// A candidate alternative: its term (or a declared combination), label
/// and weighted columns at zero.
struct Alternative {
    name: CauseName,
    label: String,
    term: Term,
    /// How the columns combine into the alternative's parameters (equal
    /// lead: one column, the sum of the three).
    columns: DMatrix<f64>,
    /// Parameter names of `columns`.
    params: Vec<String>,
    /// Whether it is the common part of a term with one parameter per leg
    /// (its registry spec's [`CommonPart`]): one column, the sum of the
    /// term's.
    common: bool,
}

/// Why two candidates cannot be told apart, and what separates them: a
/// refinement of a generic term, an alias the registry knows (declared by
/// either), two causes that follow the campaign's clock, or their
/// signatures on this campaign.
fn explain(a: CauseName, c: CauseName, c_label: &str) -> (String, String) {
    if c_label.ends_with("(higher order)") {
        return (
            format!(
                "{c_label} explains it as well: it is the part of the leg error the generic form leaves, not an effect of its own"
            ),
            "a campaign that covers more of each leg's stroke, or more readings per pose".into(),
        );
    }
    if let Some(known) = a.known_alias(c) {
        return (known.why.into(), known.separate_by.into());
    }
    if a.needs().follows_time() && c.needs().follows_time() {
        return (
            format!(
                "the logged temperature followed time during the campaign, so a change with temperature and a drift with time ({c_label}) look alike"
            ),
            "a campaign in which temperature does not follow time: log through warm-up and cool-down, or revisit poses at different temperatures".into(),
        );
    }
    (
        "their signatures on this campaign differ by less than the noise".into(),
        "a campaign that moves the machine where they differ".into(),
    )
}

/// The alias analysis of the final model `fit` on `clean`.
pub(crate) fn analyse(setup: &Setup<'_>, clean: &Dataset, fit: &Fit) -> Aliases {
    let mut out = Aliases {
        aliases: Vec::new(),
        unnamed: Vec::new(),
        alternatives: Vec::new(),
        rejected: Vec::new(),
    };
    let terms = fit.model.terms().to_vec();
    if terms.is_empty() {
        return out;
    }
    let extra: Vec<Term> = setup
        .available
        .iter()
        .map(|e| Term::Catalogue(*e))
        .filter(|t| !terms.contains(t))
        .collect();
    let Some(mut lin) = Linearisation::at_fit(fit, clean, &setup.fitter.sigma, &extra) else {
        return out;
    };
    let critical = chi2_isf(setup.fitter.options.alpha, 1.0);
    let offsets = fit.model.offsets();
    let generic_groups: Vec<GenericTerm> = setup
        .fitter
        .frame
        .generic_groups()
        .into_iter()
        .filter(|g| g.period_mm.is_none() && g.is_scanned())
        .collect();
    for (i, a) in terms.iter().enumerate() {
        let k = a.param_count();
        let params: Vec<usize> = (offsets[i]..offsets[i] + k).collect();
        lin.set_basis(&params);
        // A's signature: its projected columns times its estimate.
        let columns: Vec<usize> = lin
            .x_params
            .iter()
            .copied()
            .filter(|p| params.contains(p))
            .collect();
        if columns.is_empty() {
            continue;
        }
        let theta =
            DVector::from_iterator(columns.len(), columns.iter().map(|&p| fit.id.estimate[p]));
        let xa = lin.projected_columns(&params);
        let signature = &xa * &theta;
        let strength = signature.norm_squared();
        lin.set_target(signature);
        // The alternatives.
        let mut alternatives: Vec<Alternative> = Vec::new();
        for t in &extra {
            if let Some(cols) = lin.extra_columns(t) {
                alternatives.push(Alternative {
                    name: t.name(),
                    label: t.label(),
                    term: *t,
                    params: t.params(),
                    columns: cols,
                    common: false,
                });
            }
        }
        // The common parts the registry declares (an equal lead on all
        // legs).
        for e in EffectName::ALL {
            let Some(part) = e.spec().common_part else {
                continue;
            };
            let term = Term::Catalogue(e);
            if let Some(cols) = lin.extra_columns(&term)
                && cols.ncols() > 0
            {
                let sum = (1..cols.ncols())
                    .fold(cols.column(0).into_owned(), |acc, j| acc + cols.column(j));
                alternatives.push(Alternative {
                    name: term.name(),
                    label: part.label.into(),
                    term,
                    params: vec![part.parameter.into()],
                    columns: DMatrix::from_columns(&[sum]),
                    common: true,
                });
            }
        }
        // Refinements of the generic leg terms in the model (the quartic
        // part of a curved leg error, the second harmonic of a periodic one): a catalogue term that only mops up what the
        // generic form leaves is not a cause of its own.
        if matches!(a, Term::Catalogue(_)) {
            for t in &terms {
                if let Term::Generic(g) = t
                    && let Some(cols) = g.refinement(&setup.fitter.frame, clean)
                {
                    let cols = lin.dense(&cols);
                    let k = cols.ncols();
                    alternatives.push(Alternative {
                        name: t.name(),
                        label: format!("{} (higher order)", g.label()),
                        term: *t,
                        params: (1..=k).map(|j| format!("refinement{j}")).collect(),
                        columns: cols,
                        common: false,
                    });
                }
            }
        }
        for g in &generic_groups {
            let t = Term::Generic(*g);
            if terms.iter().any(|u| u.overlaps(&t)) || t.overlaps(a) {
                continue;
            }
            let cols = lin.generic_columns(g, &setup.fitter.frame, clean);
            if cols.is_empty() {
                continue;
            }
            alternatives.push(Alternative {
                name: t.name(),
                label: g.label(),
                term: t,
                params: g.params(),
                columns: lin.dense(&cols),
                common: false,
            });
        }
        let mut members: Vec<(Alternative, f64, Vec<Estimate>, bool)> = Vec::new();
        for alt in alternatives {
            // A term that contains A (a polynomial leg error contains a
            // lead) generalises it: not another name for it.
            if nested(&xa, &lin.project(&alt.columns)) && alt.columns.ncols() > xa.ncols() {
                continue;
            }
            let s = lin.score_dense(&alt.columns);
            if s.rank == 0 {
                continue;
            }
            let lambda = (strength - s.explained).max(0.0);
            if lambda >= critical {
                continue;
            }
            let values: Vec<f64> = s.coefficients.iter().copied().collect();
            let sds: Vec<f64> = (0..values.len())
                .map(|j| s.covariance[(j, j)].max(0.0).sqrt())
                .collect();
            let estimates: Vec<Estimate> = alt
                .params
                .iter()
                .zip(values.iter().zip(&sds))
                .map(|(n, (v, sd))| Estimate {
                    name: format!("{}.{n}", alt.name),
                    value: *v,
                    std_dev: Some(*sd),
                })
                .collect();
            // A common part's plausibility is that of each leg's parameter.
            let legs = alt.term.param_count();
            let check_values: Vec<f64> = if alt.common {
                vec![values[0]; legs]
            } else {
                values.clone()
            };
            let check_cov = if alt.common {
                DMatrix::from_diagonal_element(legs, legs, s.covariance[(0, 0)])
            } else {
                s.covariance.clone()
            };
            // A refinement belongs to a term already judged plausible.
            let plausible = if alt.label.ends_with("(higher order)") {
                Ok(())
            } else {
                setup.plausibility.judge(
                    alt.term.name(),
                    &alt.term.judgements(),
                    &check_values,
                    &check_cov,
                )
            };
            match plausible {
                Ok(()) => {
                    let projected = lin.project(&alt.columns);
                    let exact = canonical_correlation(&xa, &projected) > 1.0 - 1e-9;
                    members.push((alt, lambda, estimates, exact));
                }
                Err(reason) => out.rejected.push(Rejected {
                    effect: alt.name,
                    description: alt.label.clone(),
                    parameters: estimates,
                    reason: format!(
                        "would explain {} as well (unexplained {:.1}), but {reason}",
                        a.label(),
                        lambda
                    ),
                    stage: RejectStage::ImplausibleAlias,
                }),
            }
        }
        // A common part (an equal lead) is the full term's special case:
        // name it alone.
        let common: Vec<CauseName> = members
            .iter()
            .filter(|m| m.0.common)
            .map(|m| m.0.name)
            .collect();
        members.retain(|m| m.0.common || !common.contains(&m.0.name));
        if members.is_empty() {
            continue;
        }
        members.sort_by(|x, y| x.1.total_cmp(&y.1));
        let (best, lambda, _, exact) = &members[0];
        let (why, mut separate_by) = explain(a.name(), best.name, &best.label);
        if !*exact && *lambda > 0.0 {
            let factor = (critical / lambda).ceil();
            if factor.is_finite() && factor < 1e6 {
                separate_by.push_str(&format!(
                    "; or about {factor:.0} times the readings (poses or readings per pose)"
                ));
            }
        }
        let mut effects = vec![a.name()];
        let mut descriptions = vec![a.label()];
        let mut parameters = Vec::new();
        for (alt, _, est, _) in &members {
            if !effects.contains(&alt.name) || alt.name.is_generic() {
                effects.push(alt.name);
            }
            descriptions.push(alt.label.clone());
            parameters.extend(est.iter().cloned());
        }
        out.aliases.push(Alias {
            effects,
            descriptions: descriptions.clone(),
            why,
            separate_by,
            exact: members.iter().any(|m| m.3),
            lambda_unexplained: *lambda,
            in_model: a.name(),
            parameters,
        });
        match a {
            Term::Catalogue(_) => out.unnamed.push(*a),
            Term::Generic(_) => out.alternatives.push((*a, descriptions[1..].to_vec())),
        }
    }
    // Structural: when the logged temperature follows the campaign's time,
    // the model's temperature terms and time terms are one alias set, kept
    // under the temperature term; no time term is named beside it.
    let frame = &setup.fitter.frame;
    let follows = |t: &Term, needs: Needs| t.needs() == needs;
    let thermal: Vec<Term> = terms
        .iter()
        .copied()
        .filter(|t| follows(t, Needs::Temperature))
        .collect();
    let timed: Vec<Term> = terms
        .iter()
        .copied()
        .filter(|t| follows(t, Needs::PoseOrder))
        .collect();
    if frame.temperature_follows_time()
        && let (Some(first), false) = (thermal.first(), timed.is_empty())
    {
        let r = frame.temperature_time_r.unwrap_or(1.0);
        let members: Vec<Term> = thermal.iter().chain(&timed).copied().collect();
        let mut effects = Vec::new();
        for t in &members {
            if !effects.contains(&t.name()) {
                effects.push(t.name());
            }
        }
        let (_, separate_by) = explain(first.name(), timed[0].name(), &timed[0].label());
        out.aliases
            .retain(|a| !members.iter().any(|t| a.in_model == t.name()));
        // Legs that drift unequally beside a uniform growth: the legs warm
        // unevenly, and the growth is not named alone.
        let uneven = uneven_legs(fit, &thermal, &timed);
        if let Some(t) = uneven.filter(|_| !out.unnamed.contains(first)) {
            out.unnamed.push(t);
        }
        out.aliases.push(Alias {
            effects,
            descriptions: members.iter().map(Term::label).collect(),
            why: format!(
                "the logged temperature followed the campaign's time (r = {r:+.3}): a change with temperature and a drift with time read alike, so none of these is independent of the other{}",
                if uneven.is_some() {
                    "; the legs drift unequally beside the uniform growth: the legs warm unevenly (a per-leg temperature response), which a uniform thermal expansion does not describe"
                } else {
                    ""
                }
            ),
            separate_by,
            exact: false,
            lambda_unexplained: 0.0,
            in_model: first.name(),
            parameters: members
                .iter()
                .flat_map(|t| {
                    let (v, cov) = term_estimates(fit, t);
                    let label = t.name();
                    t.params()
                        .into_iter()
                        .enumerate()
                        .map(move |(j, n)| Estimate {
                            name: format!("{label}.{n}"),
                            value: v[j],
                            std_dev: Some(cov[(j, j)].max(0.0).sqrt()),
                        })
                        .collect::<Vec<_>>()
                })
                .collect(),
        });
        for t in &timed {
            if !out.unnamed.contains(t) {
                out.unnamed.push(*t);
            }
        }
    }
    // Structural, as the registry declares it: a significant common lead
    // is a scale gain.
    for (common, other, structural) in EffectName::structural_aliases() {
        structural_alias(&mut out, fit, &terms, &offsets, common, other, structural);
    }
    out
}

/// The uniform thermal growth among `thermal` when a per-leg drift among
/// `timed` (`leg-drift`) differs between legs beyond 3 standard deviations
/// (any pair): legs warming unevenly.
fn uneven_legs(fit: &Fit, thermal: &[Term], timed: &[Term]) -> Option<Term> {
    let uniform = thermal
        .iter()
        .copied()
        .find(|t| *t == Term::Catalogue(EffectName::Thermal))?;
    let unequal = timed.iter().any(|t| {
        let Term::Generic(g) = t else { return false };
        if g.family != GenericFamily::LegDrift {
            return false;
        }
        let (v, cov) = term_estimates(fit, t);
        (0..v.len()).any(|i| {
            (i + 1..v.len()).any(|j| {
                let var = cov[(i, i)] + cov[(j, j)] - 2.0 * cov[(i, j)];
                var > 0.0 && (v[i] - v[j]).abs() > 3.0 * var.sqrt()
            })
        })
    });
    unequal.then_some(uniform)
}

/// A structural alias of the registry ([`EffectName::structural_aliases`]):
/// when the model carries `common` (a leg lead) and not `other` (a scale
/// gain), and `common`'s common part is significant (beyond 3 standard
/// deviations), the two are reported as one exact alias set.
fn structural_alias(
    out: &mut Aliases,
    fit: &Fit,
    terms: &[Term],
    offsets: &[usize],
    common: EffectName,
    other: EffectName,
    structural: &Structural,
) {
    let (common_name, other_name) = (CauseName::Catalogue(common), CauseName::Catalogue(other));
    let common_term = Term::Catalogue(common);
    let Some(i) = terms.iter().position(|t| *t == common_term) else {
        return;
    };
    let already = out
        .aliases
        .iter()
        .any(|al| al.effects.contains(&other_name) && al.effects.contains(&common_name));
    let (v, cov) = term_estimates(fit, &common_term);
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = cov.iter().sum::<f64>() / (n * n);
    let sd = var.max(0.0).sqrt();
    let other_in_model = terms.contains(&Term::Catalogue(other));
    let significant = mean.abs() > 3.0 * sd;
    if already || other_in_model || !significant || offsets.get(i).is_none() {
        return;
    }
    let (why, separate_by) = explain(common_name, other_name, other.as_str());
    let part = common
        .spec()
        .common_part
        .map_or(common.as_str(), |p: CommonPart| p.as_alias);
    out.aliases.push(Alias {
        effects: vec![common_name, other_name],
        descriptions: vec![part.into(), other.as_str().into()],
        why: format!("{why}: {}", (structural.says)(mean, sd)),
        separate_by,
        exact: true,
        lambda_unexplained: 0.0,
        in_model: common_name,
        parameters: other
            .spec()
            .parameters
            .iter()
            .take(1)
            .map(|p| Estimate {
                name: format!("{other}.{}", p.name),
                value: mean,
                std_dev: Some(sd),
            })
            .collect(),
    });
}
