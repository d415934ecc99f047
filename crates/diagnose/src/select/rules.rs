//! The rules of the selection's module docs ([`super`]), as arithmetic
//! on numbers: the readings behind `ln n`, each candidate's share of
//! `alpha`, the likelihood-ratio evidence of a nested pair of fits, the
//! admission, the shortlist and the BIC (unit-tested in `tests.rs`
//! against values worked by hand from the rules).

use tricept_model::effects::EffectName;

use crate::evidence::Reference;
use crate::report::Evidence;
use crate::terms::Term;

/// A catalogue effect is refitted exactly when it could be admissible (its
/// likelihood-ratio test and penalised gain passed) with a drop of
/// chi-square this many times its linearised drop at the current fit: the
/// two agree to second order in the effect, so a candidate that fails even
/// at twice its score fails when refitted.
pub(crate) const SCORE_MARGIN: f64 = 2.0;

/// The readings of `poses` poses, three coordinates each: the `n` of the
/// BIC's and the penalised gain's `ln n`.
pub(super) fn readings_of(poses: usize) -> usize {
    3 * poses
}

/// The family-wise level of each half of the pool: `alpha` split evenly
/// between the catalogue and the dictionary; all of it the catalogue's when
/// the dictionary is empty.
pub(super) fn alpha_share_of(alpha: f64, dictionary_empty: bool) -> f64 {
    if dictionary_empty { alpha } else { 0.5 * alpha }
}

/// The catalogue effects of `available` that no term of `terms` makes
/// redundant, in the vocabulary's order: the catalogue's candidates.
pub(super) fn catalogue_candidates(available: &[EffectName], terms: &[Term]) -> Vec<Term> {
    available
        .iter()
        .map(|e| Term::Catalogue(*e))
        .filter(|t| !terms.iter().any(|u| u.overlaps(t)))
        .collect()
}

/// Whether `t` may still be tried: neither a cause the admission removed
/// (`excluded`) nor a term one of them makes redundant.
pub(super) fn not_excluded(excluded: &[Term], t: &Term) -> bool {
    !excluded.iter().any(|e| e.overlaps(t) || e == t)
}

/// The linearised drop of chi-square and the rank of `t` in a screen's
/// catalogue scores (`None` when it was not screened).
pub(super) fn score_of(catalogue: &[(Term, f64, usize)], t: &Term) -> Option<(f64, usize)> {
    catalogue
        .iter()
        .find(|(c, _, _)| c == t)
        .map(|&(_, explained, rank)| (explained, rank))
}

/// A nested test: the drop of chi-square `delta` for `k` added parameters,
/// the larger model leaving `with` = (chi-square, degrees of freedom).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Nested {
    pub(super) delta: f64,
    pub(super) k: usize,
    pub(super) with: (f64, usize),
}

impl Nested {
    /// The test of two fitted models, `without` = (chi-square, rank) and
    /// `with` = (chi-square, dof, rank): `k` is the rank the larger one
    /// adds (at least 1).
    pub(super) fn of_fits(without: (f64, usize), with: (f64, usize, usize)) -> Nested {
        Nested {
            delta: without.0 - with.0,
            k: with.2.saturating_sub(without.1).max(1),
            with: (with.0, with.1),
        }
    }

    /// The score test of a linearised drop `explained` for `rank`
    /// parameters (at least 1) on top of a fit leaving `current` =
    /// (chi-square, dof).
    pub(super) fn of_score(current: (f64, usize), explained: f64, rank: usize) -> Nested {
        let k = rank.max(1);
        Nested {
            delta: explained,
            k,
            with: (current.0 - explained, current.1.saturating_sub(k)),
        }
    }
}

/// How a candidate's test is counted: its half of the pool's level, the
/// tests in that half (the multiplicity `m`), and the alternatives `m_c` of
/// its family.
#[derive(Debug, Clone, Copy)]
pub(super) struct Count {
    pub(super) alpha_share: f64,
    pub(super) multiplicity: usize,
    pub(super) alternatives: usize,
}

/// The evidence of a nested test with `readings` readings (the module
/// docs' rules 1 and 2): the p-value of `delta / s2` (`s2` the larger
/// model's residual variance, never below the noise) for `k` parameters,
/// adjusted by the multiplicity (at most 1), against the level
/// `alpha_share / m`; the BIC gain `delta - k ln n` and the penalised gain
/// `G = delta - k ln n - 2 ln m_c`.
pub(super) fn weigh(
    reference: &Reference,
    test: Nested,
    readings: usize,
    count: Count,
) -> Evidence {
    let Nested { delta, k, with } = test;
    let s2 = reference.scale(with.0, with.1);
    let p = reference.p_value(delta / s2, k);
    let m = count.multiplicity;
    let ln_n = (readings as f64).ln();
    Evidence {
        delta_chi_square: delta,
        dof: k,
        p_value: p,
        threshold: count.alpha_share / m as f64,
        delta_bic: delta - k as f64 * ln_n,
        holdout_rms_without: None,
        holdout_rms_with: None,
        selected: false,
        multiplicity: m,
        p_adjusted: (p * m as f64).min(1.0),
        penalised_gain: delta - k as f64 * ln_n - 2.0 * (count.alternatives as f64).ln(),
    }
}

/// Whether an adjusted p-value is significant at its half's level.
pub(super) fn significant(p_adjusted: f64, alpha_share: f64) -> bool {
    p_adjusted < alpha_share
}

/// Rules 1 and 2: the likelihood-ratio test passes and the penalised gain
/// is positive.
pub(super) fn admissible(evidence: &Evidence, alpha_share: f64) -> bool {
    significant(evidence.p_adjusted, alpha_share) && evidence.penalised_gain > 0.0
}

/// The score test's shortlist: `None` when a catalogue effect is to be
/// refitted (admissible with [`SCORE_MARGIN`] times its linearised drop
/// `explained`), else its evidence at `explained` (`score` gives the
/// evidence of a drop).
pub(super) fn shortlist(
    score: impl Fn(f64) -> Evidence,
    explained: f64,
    alpha_share: f64,
) -> Option<Evidence> {
    if admissible(&score(SCORE_MARGIN * explained), alpha_share) {
        None
    } else {
        Some(score(explained))
    }
}

/// The order of candidates: the largest penalised gain first; among equal
/// gains the catalogue's (`generic` false) before the dictionary's.
pub(super) fn stronger_first(a: (&Evidence, bool), b: (&Evidence, bool)) -> std::cmp::Ordering {
    b.0.penalised_gain
        .total_cmp(&a.0.penalised_gain)
        .then(a.1.cmp(&b.1))
}

/// Rule 4 of a forward step: the held-out RMS with the candidate, when it
/// is below the current model's (both known).
pub(super) fn predicts_better(without: Option<f64>, with: Option<f64>) -> Option<f64> {
    match (without, with) {
        (Some(a), Some(b)) if b < a => Some(b),
        _ => None,
    }
}

/// Whether a cause holds up in the final model: admissible against the
/// model without it, which predicts held-out poses strictly worse
/// (`rms_without`, `None` when that model cannot be cross-validated: the
/// cause is needed) than the final model's `rms`.
pub(super) fn holds_up(
    evidence: &Evidence,
    alpha_share: f64,
    rms: f64,
    rms_without: Option<f64>,
) -> bool {
    admissible(evidence, alpha_share) && rms_without.is_none_or(|w| rms < w)
}

/// The cause the backward elimination removes: the least useful
/// ([`usefulness`]; the first among equals) of those failing their
/// final-model test, or of all when the final model's held-out `rms`
/// exceeds the geometric model's.
pub(super) fn least_useful_failing(
    tests: &[(Evidence, Option<f64>, bool)],
    rms: f64,
    geometric_rms: f64,
) -> Option<usize> {
    tests
        .iter()
        .enumerate()
        .filter(|(_, t)| !t.2 || rms > geometric_rms)
        .min_by(|a, b| usefulness(a.1, rms).total_cmp(&usefulness(b.1, rms)))
        .map(|(i, _)| i)
}

/// How much a cause helps held-out prediction (larger is more useful): the
/// held-out RMS without it less the final model's `rms`; infinite when the
/// model without it cannot be cross-validated.
pub(super) fn usefulness(test: &(Evidence, Option<f64>, bool), rms: f64) -> f64 {
    test.1.map_or(f64::INFINITY, |w| w - rms)
}

/// Whether the selection makes one more pass (forward steps, swaps,
/// admission) after an admission: only when it `removed` a cause, and only
/// once (`pruned_once`: a pass after a removal was already made).
pub(super) fn another_pass(removed: bool, pruned_once: bool) -> bool {
    removed && !pruned_once
}

/// The BIC of a model: `chi-square + rank ln n` for `readings` readings.
pub(super) fn bic_of(chi_square: f64, rank: usize, readings: usize) -> f64 {
    chi_square + rank as f64 * (readings as f64).ln()
}

/// A swap is made when it lowers the model's BIC by more than rounding
/// (1e-6).
pub(super) fn lowers_bic(candidate: f64, current: f64) -> bool {
    candidate < current - 1e-6
}
