//! Selection of causes from one pool: the effects of the vocabulary and
//! the generic dictionary.
//!
//! **Forward steps.** The available catalogue effects not yet in the
//! model and the dictionary are screened linearly at the current fit (the
//! score test: the linearised drop of chi-square, [`crate::linear`]). The
//! dictionary's best `refit_top` significant groups are refitted exactly,
//! and so is every catalogue effect that could be admissible at
//! [`SCORE_MARGIN`] times its score; the others keep their score test as
//! their evidence (`refitted: false` among the first step's candidates). A
//! refitted candidate `c` is admissible when
//! 1. the likelihood-ratio test passes: its drop of chi-square, divided by
//!    the residual variance of the larger model (never below the noise), is
//!    significant at `alpha / 2` divided by the number of catalogue
//!    candidates (catalogue) or by the dictionary's multiplicity (generic:
//!    every scan period and every pair of a step's edges counts);
//! 2. its penalised gain is positive:
//!    `G = X - k ln(3n) - 2 ln m_c`, the BIC plus an extended-BIC term
//!    for the `m_c` alternatives of its family (1 for a catalogue effect,
//!    every grid point of the scan for a scanned family);
//! 3. its parameters are physically plausible ([`crate::plausibility`]);
//!    otherwise it is recorded as rejected with the reason;
//! 4. the 5-fold cross-validated held-out RMS improves.
//!
//! The admissible candidate with the largest `G` enters (ties prefer the
//! catalogue). Then swaps: a term of the model is replaced by a catalogue
//! effect when that lowers the BIC of the whole model.
//!
//! **Admission on the final model.** Backward elimination: every cause must
//! pass the likelihood-ratio test and the penalised gain against the final
//! model without it, and the final model must predict held-out poses
//! strictly better with it than without it; the least useful failing cause
//! is removed and the test repeated. Finally the final model's held-out RMS
//! must not exceed the geometric model's, else the least useful cause goes.
//! If anything was removed, one more forward step is tried from the pruned
//! model. The evidence reported for each cause is this final-model test,
//! and the reported gain uses the very same cross-validation, so a named
//! cause never makes the held-out fit worse.

use std::sync::Arc;

use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_engine::model::GeometricModel;
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_model::effects::EffectName;

use crate::dictionary::{At, Dictionary, Scored};
use crate::error::DiagnoseError;
use crate::evidence::Reference;
use crate::fit::{Fit, FitResult, Fitter, term_estimates};
use crate::linear::Linearisation;
use crate::options::DiagnoseOptions;
use crate::plausibility::Plausibility;
use crate::report::{Estimate, Evidence, RejectStage, Rejected, Tested};
use crate::terms::{Frame, Term};

mod rules;
use rules::*;

/// Everything the selection works with, fixed for one diagnosis: the fit
/// core and the pool (the dictionary, the available effects of the
/// vocabulary) with its plausibility table.
pub(crate) struct Setup<'a> {
    pub(crate) fitter: Fitter<'a>,
    pub(crate) dictionary: Dictionary,
    pub(crate) plausibility: &'a Plausibility,
    /// Effects of the vocabulary whose data columns are present.
    pub(crate) available: Vec<EffectName>,
    /// The last linear screen with the point it was made at: the
    /// selection's last step and the report's remainder screen the same fit.
    pub(crate) last_screen: std::sync::Mutex<Option<(ScreenPoint, Screen)>>,
}

impl<'a> Setup<'a> {
    /// The fixed setup of a diagnosis of `data` (its poses numbered) on a
    /// machine of nominal model `nominal`: the fit core at the stated
    /// noise, the dictionary, and the effects of the vocabulary whose data
    /// columns are present.
    pub(crate) fn new(
        nominal: &Machine,
        data: &Dataset,
        options: &'a DiagnoseOptions,
    ) -> Setup<'a> {
        let frame = Arc::new(Frame::of(nominal, data));
        let mut geometric = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
        if let Some(reference) = &options.rank_reference {
            geometric = geometric.with_rank_reference(reference.clone());
        }
        let available = EffectName::terms()
            .filter(|e| Term::Catalogue(*e).available(&frame))
            .collect();
        let dictionary = Dictionary::new(&frame, &options.dictionary);
        Setup {
            fitter: Fitter {
                options,
                sigma: options.sigma,
                reference: Reference::stated(),
                frame,
                geometric,
            },
            dictionary,
            plausibility: &options.plausibility,
            available,
            last_screen: Default::default(),
        }
    }
}

/// The linear screen at a fit: the dictionary's groups scored, and the
/// score of each catalogue effect not in the fit's model.
#[derive(Debug, Clone, Default)]
pub(crate) struct Screen {
    /// The dictionary's groups, best first.
    pub(crate) dictionary: Vec<Scored>,
    /// Each catalogue effect with its linearised drop of chi-square and
    /// its rank (empty when the fit cannot be linearised with their
    /// columns).
    pub(crate) catalogue: Vec<(Term, f64, usize)>,
}

/// Everything a dictionary screen depends on besides the fixed setup: the
/// fit (its model's terms, estimate and chi-square), the test reference and
/// the poses.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ScreenPoint {
    terms: Vec<Term>,
    estimate_bits: Vec<u64>,
    chi_square_bits: u64,
    dof: usize,
    reference: crate::evidence::Reference,
    lines: Vec<u64>,
}

impl ScreenPoint {
    fn of(setup: &Setup<'_>, fit: &Fit, data: &Dataset) -> ScreenPoint {
        ScreenPoint {
            terms: fit.model.terms().to_vec(),
            estimate_bits: fit.id.estimate.iter().map(|v| v.to_bits()).collect(),
            chi_square_bits: fit.id.stats.chi_square.to_bits(),
            dof: fit.id.stats.dof,
            reference: setup.fitter.reference,
            lines: data.poses.iter().map(|p| p.line).collect(),
        }
    }
}

impl Setup<'_> {
    /// The family-wise level of each half of the pool.
    pub(crate) fn alpha_share(&self) -> f64 {
        alpha_share_of(self.fitter.options.alpha, self.dictionary.is_empty())
    }

    /// Number of tests of the half of the pool `term` belongs to.
    pub(crate) fn multiplicity(&self, term: &Term) -> usize {
        match term {
            Term::Catalogue(_) => self.available.len().max(1),
            Term::Generic(_) => self.dictionary.multiplicity().max(1),
        }
    }

    /// Alternatives of `term` within its family (for the penalised gain).
    fn alternatives(&self, term: &Term) -> usize {
        match term {
            Term::Catalogue(_) => 1,
            Term::Generic(g) => {
                if let Some(m) = self.dictionary.scan_alternatives(g.family) {
                    m.max(1)
                } else {
                    self.fitter
                        .frame
                        .generic_groups()
                        .iter()
                        .filter(|h| h.family == g.family)
                        .count()
                        .max(1)
                }
            }
        }
    }

    /// The dictionary screen at `fit` (empty when the fit cannot be
    /// linearised or the dictionary is empty).
    pub(crate) fn screen(&self, fit: &Fit, data: &Dataset) -> Vec<Scored> {
        if self.dictionary.is_empty() {
            return Vec::new();
        }
        self.linear_screen(fit, data).dictionary
    }

    /// The linear screen at `fit`: the dictionary, and the catalogue
    /// effects not in its model (one linearisation for both; the last one
    /// is kept with its point).
    pub(crate) fn linear_screen(&self, fit: &Fit, data: &Dataset) -> Screen {
        let catalogue = catalogue_candidates(&self.available, fit.model.terms());
        if self.dictionary.is_empty() && catalogue.is_empty() {
            return Screen::default();
        }
        let point = ScreenPoint::of(self, fit, data);
        if let Ok(last) = self.last_screen.lock()
            && let Some((at, screen)) = last.as_ref()
            && *at == point
        {
            return screen.clone();
        }
        let sigma = &self.fitter.sigma;
        let linearised = match Linearisation::scoring(fit, data, sigma, &catalogue) {
            Some((lin, scores)) => Some((
                lin,
                scores
                    .into_iter()
                    .map(|(t, s)| (t, s.explained, s.rank))
                    .collect(),
            )),
            // The catalogue's columns cannot be had: the dictionary alone.
            None => Linearisation::scoring(fit, data, sigma, &[]).map(|(lin, _)| (lin, Vec::new())),
        };
        let Some((lin, catalogue)) = linearised else {
            return Screen::default();
        };
        let at = At {
            lin: &lin,
            frame: &self.fitter.frame,
            data,
            reference: &self.fitter.reference,
            chi_square: fit.id.stats.chi_square,
            dof: fit.id.stats.dof,
        };
        let screen = Screen {
            dictionary: if self.dictionary.is_empty() {
                Vec::new()
            } else {
                self.dictionary.screen(&at, fit.model.terms())
            },
            catalogue,
        };
        if let Ok(mut last) = self.last_screen.lock() {
            *last = Some((point, screen.clone()));
        }
        screen
    }

    /// Plausibility of `term` in `fit`.
    pub(crate) fn plausible(&self, fit: &Fit, term: &Term) -> Result<(), String> {
        let (values, cov) = term_estimates(fit, term);
        self.plausibility
            .judge(term.name(), &term.judgements(), &values, &cov)
    }

    /// The evidence for `term` from the nested pair `without` / `with`.
    pub(crate) fn evidence(
        &self,
        term: &Term,
        without: &Fit,
        with: &Fit,
        readings: usize,
    ) -> Evidence {
        let test = Nested::of_fits(
            (without.id.stats.chi_square, without.id.design().rank()),
            (
                with.id.stats.chi_square,
                with.id.stats.dof,
                with.id.design().rank(),
            ),
        );
        self.evidence_of(term, test, readings)
    }

    /// The score test of adding `term` to `current`: the evidence of its
    /// linearised drop of chi-square `explained` for `rank` parameters.
    fn score_evidence(
        &self,
        term: &Term,
        current: &Fit,
        explained: f64,
        rank: usize,
        readings: usize,
    ) -> Evidence {
        let stats = &current.id.stats;
        let test = Nested::of_score((stats.chi_square, stats.dof), explained, rank);
        self.evidence_of(term, test, readings)
    }

    /// The evidence of the nested test `test` of `term` ([`weigh`] with
    /// the term's half of the pool and its family).
    fn evidence_of(&self, term: &Term, test: Nested, readings: usize) -> Evidence {
        let count = Count {
            alpha_share: self.alpha_share(),
            multiplicity: self.multiplicity(term),
            alternatives: self.alternatives(term),
        };
        weigh(&self.fitter.reference, test, readings, count)
    }
}

/// The outcome of the selection on clean data.
pub(crate) struct Selection {
    /// The causes, in the order they entered.
    pub(crate) terms: Vec<Term>,
    /// Each cause's evidence on the final model.
    pub(crate) evidences: Vec<Evidence>,
    /// The final model.
    pub(crate) current: Fit,
    /// Its cross-validated held-out RMS.
    pub(crate) current_rms: f64,
    /// The geometric model's.
    pub(crate) geometric_rms: f64,
    /// The candidates tested at the first step.
    pub(crate) first_candidates: Vec<Tested>,
    /// The geometric fit.
    pub(crate) geo: Fit,
    /// Fits that failed plausibility or the held-out test.
    pub(crate) rejected: Vec<Rejected>,
}

/// A candidate refitted on top of the current model.
struct Trial {
    term: Term,
    fit: Fit,
    evidence: Evidence,
}

/// Records `term` as rejected at `stage` with its estimates in `fit`; an
/// earlier entry of the same term at the same stage is replaced (one entry
/// per term and stage).
fn reject(
    rejected: &mut Vec<Rejected>,
    fit: &Fit,
    term: &Term,
    stage: RejectStage,
    reason: String,
) {
    let (values, cov) = term_estimates(fit, term);
    let names = term.params();
    let parameters = values
        .iter()
        .enumerate()
        .map(|(i, v)| Estimate {
            name: format!("{}.{}", term.name(), names[i]),
            value: *v,
            std_dev: Some(cov[(i, i)].max(0.0).sqrt()),
        })
        .collect();
    let description = term.label();
    rejected.retain(|r| !(r.description == description && r.stage == stage));
    rejected.push(Rejected {
        effect: term.name(),
        description,
        parameters,
        reason,
        stage,
    });
}

/// One forward step from `current`: the winning trial and its held-out
/// RMS, or `None`.
fn forward_step(
    setup: &Setup<'_>,
    clean: &Dataset,
    current: &Fit,
    current_rms: &mut Option<f64>,
    rejected: &mut Vec<Rejected>,
    excluded: &[Term],
    tested: Option<&mut Vec<Tested>>,
) -> Option<(Trial, f64)> {
    let terms = current.model.terms().to_vec();
    let mut pool = catalogue_candidates(&setup.available, &terms);
    let alpha_share = setup.alpha_share();
    let screen = setup.linear_screen(current, clean);
    pool.extend(
        screen
            .dictionary
            .iter()
            .filter(|s| significant(s.p_adjusted, alpha_share))
            .take(setup.fitter.options.dictionary.refit_top)
            .map(|s| Term::Generic(s.term)),
    );
    pool.retain(|t| not_excluded(excluded, t));
    let readings = readings_of(clean.poses.len());
    // The score test: a catalogue effect that could not be admissible even
    // at SCORE_MARGIN times its linearised drop is not refitted.
    let mut judged: Vec<(Term, Evidence)> = Vec::new();
    pool.retain(|t| {
        let Some((explained, rank)) = score_of(&screen.catalogue, t) else {
            return true;
        };
        let at = |x: f64| setup.score_evidence(t, current, x, rank, readings);
        match shortlist(at, explained, alpha_share) {
            None => true,
            Some(evidence) => {
                judged.push((*t, evidence));
                false
            }
        }
    });
    let mut trials: Vec<Trial> = pool
        .par_iter()
        .filter_map(|t| {
            let mut with = terms.clone();
            with.push(*t);
            let fit = setup.fitter.fit(setup.fitter.model(&with), clean).ok()?;
            if fit.id.stats.dof == 0 {
                return None;
            }
            let evidence = setup.evidence(t, current, &fit, readings);
            Some(Trial {
                term: *t,
                fit,
                evidence,
            })
        })
        .collect();
    // Strongest first; among equals the catalogue.
    trials.sort_by(|a, b| {
        stronger_first(
            (&a.evidence, a.term.name().is_generic()),
            (&b.evidence, b.term.name().is_generic()),
        )
    });
    let mut winner = None;
    for t in trials.iter_mut() {
        if winner.is_some() || !admissible(&t.evidence, alpha_share) {
            continue;
        }
        if let Err(reason) = setup.plausible(&t.fit, &t.term) {
            reject(rejected, &t.fit, &t.term, RejectStage::Plausibility, reason);
            continue;
        }
        if current_rms.is_none() {
            *current_rms = setup
                .fitter
                .holdout_rms(&current.model, clean, &|_| true)
                .ok();
        }
        let with = setup
            .fitter
            .holdout_rms(&t.fit.model, clean, &|_| true)
            .ok();
        t.evidence.holdout_rms_without = *current_rms;
        t.evidence.holdout_rms_with = with;
        match predicts_better(*current_rms, with) {
            Some(b) => {
                t.evidence.selected = true;
                winner = Some((t.term, b));
            }
            None => reject(
                rejected,
                &t.fit,
                &t.term,
                RejectStage::Holdout,
                format!(
                    "significant, but the held-out rms does not improve ({} -> {})",
                    current_rms.map_or("-".into(), |v| format!("{v:.3}")),
                    with.map_or("-".into(), |v| format!("{v:.3}"))
                ),
            ),
        }
    }
    if let Some(tested) = tested {
        let refitted = trials.iter().map(|t| (t.term, &t.evidence, true));
        let scored = judged.iter().map(|(t, e)| (*t, e, false));
        *tested = refitted
            .chain(scored)
            .map(|(t, evidence, refitted)| Tested {
                effect: t.name(),
                description: t.label(),
                evidence: evidence.clone(),
                refitted,
            })
            .collect();
        // Strongest first; among equals the catalogue.
        tested.sort_by(|a, b| {
            stronger_first(
                (&a.evidence, a.effect.is_generic()),
                (&b.evidence, b.effect.is_generic()),
            )
        });
    }
    let (term, rms) = winner?;
    let index = trials.iter().position(|t| t.term == term)?;
    Some((trials.swap_remove(index), rms))
}

/// Swaps: a term of the model (catalogue or generic) replaced by a
/// catalogue effect when that lowers the BIC of the whole model (a
/// polynomial leg error that entered for a scale gain while an
/// eccentricity was still unmodelled is a lead once the eccentricity is in).
fn swaps(setup: &Setup<'_>, clean: &Dataset, mut current: Fit) -> Fit {
    let readings = readings_of(clean.poses.len());
    let bic = |f: &Fit| bic_of(f.id.stats.chi_square, f.id.design().rank(), readings);
    loop {
        let terms = current.model.terms().to_vec();
        let options: Vec<(usize, Term)> = terms
            .iter()
            .enumerate()
            .flat_map(|(slot, _)| {
                setup
                    .available
                    .iter()
                    .map(|e| Term::Catalogue(*e))
                    .filter(|c| !terms.contains(c))
                    .map(move |c| (slot, c))
            })
            .collect();
        let best = options
            .par_iter()
            .filter_map(|&(slot, c)| {
                let mut with = terms.clone();
                with[slot] = c;
                let f = setup.fitter.fit(setup.fitter.model(&with), clean).ok()?;
                setup.plausible(&f, &c).ok()?;
                Some((bic(&f), f))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let now = bic(&current);
        match best.filter(|(value, _)| lowers_bic(*value, now)) {
            Some((_, f)) => current = f,
            None => return current,
        }
    }
}

/// The final-model test of every cause: (evidence, held-out RMS without
/// it, whether it passes).
fn final_tests(
    setup: &Setup<'_>,
    clean: &Dataset,
    current: &Fit,
    current_rms: f64,
) -> Vec<(Evidence, Option<f64>, bool)> {
    let terms = current.model.terms().to_vec();
    let readings = readings_of(clean.poses.len());
    (0..terms.len())
        .into_par_iter()
        .map(|slot| {
            let others: Vec<Term> = terms
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != slot)
                .map(|(_, t)| *t)
                .collect();
            let model = setup.fitter.model(&others);
            let Ok(without) = setup.fitter.fit(model.clone(), clean) else {
                // The model without the cause cannot be fitted: the cause
                // is needed.
                let mut ev = setup.evidence(&terms[slot], current, current, readings);
                ev.selected = true;
                return (ev, None, true);
            };
            let mut ev = setup.evidence(&terms[slot], &without, current, readings);
            let rms_without = setup.fitter.holdout_rms(&model, clean, &|_| true).ok();
            ev.holdout_rms_without = rms_without;
            ev.holdout_rms_with = Some(current_rms);
            let pass = holds_up(&ev, setup.alpha_share(), current_rms, rms_without);
            ev.selected = pass;
            (ev, rms_without, pass)
        })
        .collect()
}

/// Forward selection, swaps and admission on the final model (see the
/// module docs).
/// `geo` is the geometric model's fit to `clean` when the caller has made
/// it already.
pub(crate) fn select(
    setup: &Setup<'_>,
    clean: &Dataset,
    geo: Option<FitResult>,
) -> Result<Selection, DiagnoseError> {
    let geo = match geo {
        Some(fit) => fit?,
        None => setup.fitter.fit(setup.fitter.base_model(), clean)?,
    };
    if geo.id.stats.dof == 0 {
        return Err(DiagnoseError::Degenerate(
            "as many unknowns as readings: no degree of freedom is left to test the model".into(),
        ));
    }
    let geometric_rms = setup
        .fitter
        .holdout_rms(&geo.model, clean, &|_| true)
        .map_err(DiagnoseError::FoldNotFitted)?;
    let mut rejected = Vec::new();
    let mut first_candidates = Vec::new();
    let mut current = geo.clone();
    let mut current_rms = Some(geometric_rms);
    let mut pruned_once = false;
    let mut first_step = true;
    let mut excluded: Vec<Term> = Vec::new();
    loop {
        // Forward steps.
        while current.model.terms().len() < setup.fitter.options.max_causes {
            let tested = first_step.then_some(&mut first_candidates);
            first_step = false;
            match forward_step(
                setup,
                clean,
                &current,
                &mut current_rms,
                &mut rejected,
                &excluded,
                tested,
            ) {
                Some((trial, rms)) => {
                    current = trial.fit;
                    current_rms = Some(rms);
                }
                None => break,
            }
        }
        if !current.model.terms().is_empty() {
            let swapped = swaps(setup, clean, current.clone());
            if swapped.model.terms() != current.model.terms() {
                current = swapped;
                current_rms = None;
            }
        }
        // Admission on the final model.
        let mut removed = false;
        loop {
            if current.model.terms().is_empty() {
                break;
            }
            let rms = match current_rms {
                Some(r) => r,
                None => setup
                    .fitter
                    .holdout_rms(&current.model, clean, &|_| true)
                    .map_err(DiagnoseError::FoldNotFitted)?,
            };
            current_rms = Some(rms);
            let tests = final_tests(setup, clean, &current, rms);
            let Some(slot) = least_useful_failing(&tests, rms, geometric_rms) else {
                break;
            };
            let terms = current.model.terms().to_vec();
            let term = terms[slot];
            let (ev, _, _) = &tests[slot];
            reject(
                &mut rejected,
                &current,
                &term,
                RejectStage::FinalEvidence,
                format!(
                    "does not hold up in the final model (chi2 drop {:.1} for {} dof, adjusted p = {:.1e}, penalised gain {:.1}, held-out rms {} without it -> {:.3} with it)",
                    ev.delta_chi_square,
                    ev.dof,
                    ev.p_adjusted,
                    ev.penalised_gain,
                    ev.holdout_rms_without
                        .map_or("-".into(), |v| format!("{v:.3}")),
                    rms
                ),
            );
            excluded.push(term);
            let others: Vec<Term> = terms.into_iter().filter(|t| *t != term).collect();
            current = setup.fitter.fit(setup.fitter.model(&others), clean)?;
            current_rms = others.is_empty().then_some(geometric_rms);
            removed = true;
        }
        if another_pass(removed, pruned_once) {
            pruned_once = true;
        } else {
            break;
        }
    }
    let current_rms = current_rms.unwrap_or(geometric_rms);
    let evidences = if current.model.terms().is_empty() {
        Vec::new()
    } else {
        final_tests(setup, clean, &current, current_rms)
            .into_iter()
            .map(|t| t.0)
            .collect()
    };
    Ok(Selection {
        terms: current.model.terms().to_vec(),
        evidences,
        current_rms,
        current,
        geometric_rms,
        first_candidates,
        geo,
        rejected,
    })
}

#[cfg(test)]
mod tests;
