//! The set of changes a check names: the smallest set of candidates that
//! explains the readings, found by forward selection, and the rule that
//! names a thermal growth before a sensor's gain when both fit alike.
//!
//! # The forward search
//!
//! The set starts empty. At each step every candidate not yet in it is
//! fitted jointly with the set (the reduced Gram matrix of the check's QR:
//! offsets and the calibration's uncertainty projected out), and its
//! *conditional* likelihood-ratio statistic `dT(S + c) - dT(S)` is
//! `chi2(k)` without a further change, `k` the degrees of freedom it adds.
//! A leg tries each leading subset of its nested parameters (length, then
//! lead, then its shapes), the smallest p-value speaking for it, as in the
//! test of each candidate alone.
//!
//! 1. **Enter.** The candidate with the smallest conditional p-value enters
//!    when its statistic exceeds the family-wise critical value of the
//!    check (Bonferroni over every test of every candidate,
//!    [`crate::check::family_level`]). Of the significant candidates of its kind
//!    whose p-value is within a factor 20 of it (they explain the step
//!    alike), the one whose joint fit is the smallest change enters: the
//!    sum of each estimate squared over its unseen limit squared (0.25 mm
//!    for a length). Two legs slipped in opposite directions read, through
//!    the weak common length of the legs, almost as one leg twice as far
//!    and another half as far; the smaller pair is named, the other as its
//!    alias.
//! 2. **Stop** at the first step where no candidate is significant.
//! 3. **Exchange.** A step chooses one change at a time; two changes at
//!    once can read, to the first step, as one bigger candidate (two legs
//!    slipped as one leg's platform joint, whose three coordinates take up
//!    part of the other leg's signal). So the set found is then improved by
//!    trading one geometric change (a leg, a joint) for another: first
//!    while a trade raises the set's score, its statistic less `2 ln 20`
//!    per parameter (a parameter stays only if it makes the readings 20
//!    times likelier, the factor by which the check tells changes apart);
//!    then, for two or more changes, while a trade for a candidate of the
//!    same kind keeps the score within `2 ln 20` of the best and makes the
//!    set's change smaller (the sizes above). Measured on independent
//!    machines (`cargo xtask check-rates --seed 7 --campaigns 100`): two
//!    legs slipped +25/-25 um are both named in 96 and 98 of 100 campaigns
//!    at 10 and 20 poses (61 and 58 without the exchange), one slipped
//!    leg alone in 100 and 97 (97, 97), a moved joint in 89 and 89 (89,
//!    88).
//!
//! The set is then refitted jointly: each change's estimate and standard
//! deviation are those of the joint fit, its platform effect that of its
//! joint estimate, its test the likelihood ratio given the other changes;
//! significant candidates outside the set whose test given the other
//! changes has a p-value within a factor 20 of it are its `aliases`, which
//! the check cannot tell apart from it.

//! # Temperature before the sensors
//!
//! When a thermal growth and a sensor's gain explain a step alike (the
//! sensor named first, the thermal growth among its aliases), the thermal
//! growth is named and the sensor becomes its alias: a scale gain reads
//! exactly as the whole structure grown with the temperature, and of the
//! two only the latter moves the platform. The same rule names a check's
//! most likely change.

use nalgebra::DMatrix;
use serde::Serialize;

use crate::candidates::{Candidate, CandidateKind};
use crate::parts::{
    CandidateResult, ChiSquare, Impact, SHORTLIST_RATIO, SubFit, chi_square, fit_columns,
    unseen_limit,
};

/// The expansion of steel, ppm/K: the growth a structure's temperature
/// change is stated at when its readings cannot show it.
pub(crate) const STEEL_PPM_PER_K: f64 = 11.5;

/// A growth of the structure the readings cannot show is worth a warning
/// from this mean platform effect, um: half the 20 um a check is planned
/// to detect (`tricept plan --instrument check`).
const UNSEEN_GROWTH_UM: f64 = 10.0;

/// One change of the set a check names.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Change {
    /// The candidate (`leg 1`, `thermal growth of the structure`, ...).
    pub name: String,
    /// Its kind.
    pub kind: CandidateKind,
    /// The parameters fitted, units in the names (a slipped leg: its
    /// length alone).
    pub parameters: Vec<String>,
    /// Their estimates in the joint fit of the set.
    pub estimate: Vec<f64>,
    /// Their standard deviations in the joint fit (`None`: not seen).
    pub std_dev: Vec<Option<f64>>,
    /// Mean platform error over the evaluation points that the estimated
    /// change causes, um (0 for a sensor).
    pub platform_mean_um: f64,
    /// The largest, um.
    pub platform_max_um: f64,
    /// Its likelihood-ratio test given the other changes of the set.
    pub test: ChiSquare,
    /// Candidates outside the set that, given the other changes, explain
    /// the readings as well (significant, a p-value within a factor 20):
    /// the check cannot tell them apart from it.
    pub aliases: Vec<String>,
}

/// What the forward search works on.
pub(crate) struct Problem<'a> {
    /// The check's candidates, their columns in this order.
    pub candidates: &'a [Candidate],
    /// The reduced Gram matrix of the candidate columns and the residual.
    pub gram: &'a DMatrix<f64>,
    /// The residual's index in `gram`.
    pub residual: usize,
    /// The family-wise level of each test.
    pub level: f64,
    /// The platform effect of a change.
    pub impact: &'a Impact,
    /// The campaign's temperature (thermal growth), °C.
    pub temp_c: Option<f64>,
}

/// The changes found, and the joint fit's statistic and degrees of freedom
/// (the part of the consistency statistic the set explains).
pub(crate) struct ChangeSet {
    pub changes: Vec<Change>,
    pub statistic: f64,
    pub dof: usize,
}

/// A candidate's conditional test at one step: the candidate, the leading
/// parameters fitted, the test.
struct Step {
    cand: usize,
    fitted: usize,
    test: ChiSquare,
    /// The size of the set's changes with it: the sum of each joint
    /// estimate squared over its unseen limit squared.
    size: f64,
}

impl Step {
    fn significant(&self) -> bool {
        self.test.dof > 0 && self.test.statistic > self.test.critical
    }
}

/// The joint fit of `set` (candidate, leading parameters fitted) to the
/// reduced Gram matrix `gram` (candidate `c`'s columns `columns[c]`, the
/// residual's index `residual`), and the size of its changes: the sum of
/// each estimate squared over its unseen limit squared, `limit(c, t)` for
/// candidate `c`'s parameter `t`.
fn fit_set(
    set: &[(usize, usize)],
    columns: &[Vec<usize>],
    limit: &dyn Fn(usize, usize) -> f64,
    gram: &DMatrix<f64>,
    residual: usize,
) -> (SubFit, f64) {
    let mut idx = Vec::new();
    let mut limits = Vec::new();
    for &(c, m) in set {
        idx.extend_from_slice(&columns[c][..m]);
        limits.extend((0..m).map(|t| limit(c, t)));
    }
    let fit = fit_columns(&idx, &limits, gram, residual);
    let size = fit
        .estimate
        .iter()
        .zip(&limits)
        .map(|(x, l)| (x / l).powi(2))
        .sum();
    (fit, size)
}

/// Of the candidate ranked first (`best`) and the others (`rows`: kind,
/// `ln p`, significant, index-aligned), the one to name: `best`, unless it
/// is a sensor and a significant thermal growth has a p-value within a
/// factor 20 of its own (then the most likely of those).
pub(crate) fn named_first(best: usize, rows: &[(CandidateKind, f64, bool)]) -> usize {
    let Some(&(kind, ln_p, _)) = rows.get(best) else {
        return best;
    };
    if kind != CandidateKind::Sensor {
        return best;
    }
    let margin = ln_p + SHORTLIST_RATIO.ln();
    rows.iter()
        .enumerate()
        .filter(|(_, (k, l, s))| *k == CandidateKind::Thermal && *s && *l <= margin)
        .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .map_or(best, |(i, _)| i)
}

impl Problem<'_> {
    /// Each candidate's column indices in `gram`.
    fn columns(&self) -> Vec<Vec<usize>> {
        let mut at = 0;
        self.candidates
            .iter()
            .map(|c| {
                let idx = (at..at + c.len()).collect();
                at += c.len();
                idx
            })
            .collect()
    }

    /// The numbers of leading parameters candidate `c` is tried with: each
    /// for a nested candidate, all of them otherwise.
    fn sizes(&self, c: usize) -> Vec<usize> {
        let n = self.candidates[c].len();
        if self.candidates[c].is_nested() {
            (1..=n).collect()
        } else {
            vec![n]
        }
    }

    /// The test of change `k` of `set` given the others, and the
    /// candidates outside the set that, given the others, explain the
    /// readings as well (significant, a p-value within a factor 20).
    fn given_others(
        &self,
        k: usize,
        set: &[(usize, usize)],
        columns: &[Vec<usize>],
    ) -> (ChiSquare, Vec<String>) {
        let mut others = set.to_vec();
        others.remove(k);
        let (base, _) = self.fit(&others, columns);
        let (with, _) = self.fit(set, columns);
        let test = chi_square(
            (with.statistic - base.statistic).max(0.0),
            with.dof.saturating_sub(base.dof),
            self.level,
        );
        let margin = test.ln_p_value + SHORTLIST_RATIO.ln();
        let aliases = self
            .outside(set)
            .into_iter()
            .filter_map(|a| self.step(a, &others, &base, columns))
            .filter(|s| s.significant() && s.test.ln_p_value <= margin)
            .map(|s| self.candidates[s.cand].name.clone())
            .collect();
        (test, aliases)
    }

    /// The candidates not in `set`, in order.
    fn outside(&self, set: &[(usize, usize)]) -> Vec<usize> {
        (0..self.candidates.len())
            .filter(|&a| set.iter().all(|&(s, _)| s != a))
            .collect()
    }

    /// The joint fit of `set` (candidate, leading parameters fitted), and
    /// the size of its changes.
    fn fit(&self, set: &[(usize, usize)], columns: &[Vec<usize>]) -> (SubFit, f64) {
        let limit = |c: usize, t: usize| unseen_limit(&self.candidates[c].parameters[t]);
        fit_set(set, columns, &limit, self.gram, self.residual)
    }

    /// The conditional test of candidate `c` given `set` (whose fit is
    /// `base`): for a nested candidate, its leading subset with the smallest
    /// p-value.
    fn step(
        &self,
        c: usize,
        set: &[(usize, usize)],
        base: &SubFit,
        columns: &[Vec<usize>],
    ) -> Option<Step> {
        let mut with = set.to_vec();
        with.push((c, 0));
        self.sizes(c)
            .into_iter()
            .filter_map(|m| {
                if let Some(last) = with.last_mut() {
                    *last = (c, m);
                }
                let (fit, size) = self.fit(&with, columns);
                let dof = fit.dof.checked_sub(base.dof).filter(|&d| d > 0)?;
                let test = chi_square((fit.statistic - base.statistic).max(0.0), dof, self.level);
                Some(Step {
                    cand: c,
                    fitted: m,
                    test,
                    size,
                })
            })
            .min_by(|a, b| {
                a.test
                    .ln_p_value
                    .total_cmp(&b.test.ln_p_value)
                    .then(a.test.dof.cmp(&b.test.dof))
            })
    }
}

/// The score a set's parameter must earn to stay in it: `2 ln 20`, the
/// statistic of a likelihood 20 times larger (the check's factor for
/// changes it cannot tell apart, [`SHORTLIST_RATIO`]).
fn parameter_penalty() -> f64 {
    2.0 * SHORTLIST_RATIO.ln()
}

/// A set's score and size for the exchange step, from its joint fit and
/// size ([`fit_set`]): the statistic less [`parameter_penalty`] per
/// parameter seen.
fn judged((fit, size): (SubFit, f64)) -> (f64, f64) {
    (fit.statistic - parameter_penalty() * fit.dof as f64, size)
}

/// Whether a candidate is a change of the geometry (a leg, a joint): the
/// kinds the exchange step trades for one another.
fn geometric(kind: CandidateKind) -> bool {
    matches!(
        kind,
        CandidateKind::Leg | CandidateKind::BaseJoint | CandidateKind::PlatformJoint
    )
}

/// A set of changes judged by the exchange step: its score (the
/// statistic less [`parameter_penalty`] per parameter seen) and the size
/// of its changes.
type Judge<'a> = dyn Fn(&[(usize, usize)]) -> (f64, f64) + 'a;

/// The exchange step (see the module docs). `kinds[c]` and `sizes[c]` are
/// candidate `c`'s kind and the numbers of leading parameters it is tried
/// with; `judge` scores a set. First, while trading one geometric change of
/// `set` for a geometric candidate outside it raises the score, make the
/// best such trade. Then, for a set of two or more changes, while trading
/// one for a candidate of its kind keeps the score within `2 ln 20` of the
/// best one and makes the set's change smaller, make the trade that makes
/// it smallest. The score rises, or the size falls, at every trade, so both
/// loops end; the cap is a guard.
fn exchange(
    kinds: &[CandidateKind],
    sizes: &[Vec<usize>],
    judge: &Judge<'_>,
    set: &mut [(usize, usize)],
) {
    let trades = |set: &[(usize, usize)], same_kind: bool| {
        let mut out = Vec::new();
        for (k, &(member, _)) in set.iter().enumerate() {
            let kind = kinds[member];
            if !geometric(kind) {
                continue;
            }
            for (c, &other) in kinds.iter().enumerate() {
                if !geometric(other)
                    || (same_kind && other != kind)
                    || set.iter().any(|&(s, _)| s == c)
                {
                    continue;
                }
                for &m in &sizes[c] {
                    let mut trial = set.to_vec();
                    trial[k] = (c, m);
                    let (score, size) = judge(&trial);
                    out.push((score, size, k, (c, m)));
                }
            }
        }
        out
    };
    let cap = 4 * kinds.len();
    let (mut best_score, mut size) = judge(set);
    for _ in 0..cap {
        let Some(&(score, new_size, k, with)) = trades(set, false)
            .iter()
            .filter(|t| t.0 > best_score)
            .max_by(|a, b| a.0.total_cmp(&b.0))
        else {
            break;
        };
        set[k] = with;
        (best_score, size) = (score, new_size);
    }
    if set.len() < 2 {
        return;
    }
    let floor = best_score - parameter_penalty();
    for _ in 0..cap {
        let Some(&(_, new_size, k, with)) = trades(set, true)
            .iter()
            .filter(|t| t.0 >= floor && t.1 < size)
            .min_by(|a, b| a.1.total_cmp(&b.1))
        else {
            break;
        };
        set[k] = with;
        size = new_size;
    }
}

/// The forward search (see the module docs).
pub(crate) fn forward(p: &Problem<'_>) -> ChangeSet {
    let columns = p.columns();
    let mut set: Vec<(usize, usize)> = Vec::new();
    let (mut base, _) = p.fit(&set, &columns);
    while set.len() < p.candidates.len() {
        let steps: Vec<Step> = p
            .outside(&set)
            .into_iter()
            .filter_map(|c| p.step(c, &set, &base, &columns))
            .collect();
        let Some(best) = steps
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.test.ln_p_value.total_cmp(&b.1.test.ln_p_value))
            .map(|(i, _)| i)
        else {
            break;
        };
        if !steps[best].significant() {
            break;
        }
        let rows: Vec<(CandidateKind, f64, bool)> = steps
            .iter()
            .map(|s| {
                (
                    p.candidates[s.cand].kind,
                    s.test.ln_p_value,
                    s.significant(),
                )
            })
            .collect();
        let margin = steps[best].test.ln_p_value + SHORTLIST_RATIO.ln();
        // Of the candidates of the kind named first that explain the step
        // alike, the smallest change.
        let kind = p.candidates[steps[named_first(best, &rows)].cand].kind;
        let Some(chosen) = steps
            .iter()
            .filter(|s| s.significant() && s.test.ln_p_value <= margin)
            .filter(|s| p.candidates[s.cand].kind == kind)
            .min_by(|a, b| a.size.total_cmp(&b.size))
        else {
            break;
        };
        set.push((chosen.cand, chosen.fitted));
        base = p.fit(&set, &columns).0;
    }
    let kinds: Vec<CandidateKind> = p.candidates.iter().map(|c| c.kind).collect();
    let sizes: Vec<Vec<usize>> = (0..p.candidates.len()).map(|c| p.sizes(c)).collect();
    let judge = |s: &[(usize, usize)]| judged(p.fit(s, &columns));
    exchange(&kinds, &sizes, &judge, &mut set);
    let base = p.fit(&set, &columns).0;
    let entered: Vec<(ChiSquare, Vec<String>)> = (0..set.len())
        .map(|k| p.given_others(k, &set, &columns))
        .collect();
    let mut at = 0;
    let changes = set
        .iter()
        .zip(entered)
        .map(|(&(c, m), (test, aliases))| {
            let cand = &p.candidates[c];
            let estimate = base.estimate[at..at + m].to_vec();
            let std_dev = base.std_dev[at..at + m].to_vec();
            at += m;
            let (platform_mean_um, platform_max_um) = if cand.moves_the_platform() {
                p.impact.of(cand, &estimate, p.temp_c)
            } else {
                (0.0, 0.0)
            };
            Change {
                name: cand.name.clone(),
                kind: cand.kind,
                parameters: cand.parameters[..m].to_vec(),
                estimate,
                std_dev,
                platform_mean_um,
                platform_max_um,
                test,
                aliases,
            }
        })
        .collect();
    ChangeSet {
        changes,
        statistic: base.statistic,
        dof: base.dof,
    }
}

/// The warning for a structure whose temperature differs from the
/// calibration's when the readings show no thermal growth (no thermal
/// change named, the structure's growth not significant): a linear scale
/// that grows with the structure reads the longer limb as the same length,
/// and the sensors then see nothing, while the platform is off by the
/// growth. Stated at the expansion of steel, when its platform effect is
/// at least 10 um.
pub(crate) fn unseen_growth(
    candidates: &[Candidate],
    results: &[CandidateResult],
    changes: &[Change],
    impact: &Impact,
    temp_c: Option<f64>,
) -> Option<String> {
    if changes.iter().any(|c| c.kind == CandidateKind::Thermal) {
        return None;
    }
    let (i, dt) = candidates
        .iter()
        .enumerate()
        .find_map(|(i, c)| c.structure_delta_k().map(|dt| (i, dt)))?;
    if results.get(i)?.significant {
        return None;
    }
    let (mean_um, max_um) = impact.of(&candidates[i], &[STEEL_PPM_PER_K], temp_c);
    (mean_um >= UNSEEN_GROWTH_UM).then(|| {
        format!(
            "the structure is {dt:+.1} K from its calibration's temperature and the readings show no thermal growth: if the linear scale grows with the structure, the sensors cannot see it, and at {STEEL_PPM_PER_K} ppm/K (steel) it moves the platform by {mean_um:.1} um on average and up to {max_um:.1} um; check at the calibration's temperature or recalibrate at this one"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three legs and one platform joint on 30 synthetic readings
    /// (whitened: unit noise). Leg 3's column is `-(a + b) + eps d`, so the
    /// legs' common length is seen only through `eps`; the joint's columns
    /// are leg 1's and two directions of its own (the first of them 3 times
    /// leg 1's when `along_leg`). The residual is `r`.
    /// Returns the kinds, the sizes tried and the judge of the exchange
    /// step, scoring sets as `forward` does.
    fn synthetic(
        eps: f64,
        along_leg: bool,
        r: impl Fn(&[f64; 6]) -> f64,
    ) -> (Vec<CandidateKind>, Vec<Vec<usize>>, DMatrix<f64>) {
        // Columns: a, b, c (legs), a, u, v (the joint), r.
        let z = DMatrix::from_fn(30, 7, |i, j| {
            let x = i as f64;
            let base = [
                10.0 * (0.7 * x + 0.3).sin(),
                10.0 * (1.3 * x).cos(),
                0.0,
                0.0,
                10.0 * (2.1 * x + 1.0).sin(),
                10.0 * (0.4 * x + 2.0).cos(),
            ];
            let d = 10.0 * (0.9 * x + 0.5).cos();
            let mut col = base;
            col[2] = -(base[0] + base[1]) + eps * d;
            col[3] = base[0];
            if along_leg {
                col[4] = 3.0 * base[0];
            }
            if j < 6 { col[j] } else { r(&col) }
        });
        let kinds = vec![L, L, L, CandidateKind::PlatformJoint];
        let sizes = vec![vec![1], vec![1], vec![1], vec![3]];
        (kinds, sizes, z.transpose() * z)
    }

    fn judge(gram: &DMatrix<f64>) -> impl Fn(&[(usize, usize)]) -> (f64, f64) + '_ {
        let columns = vec![vec![0], vec![1], vec![2], vec![3, 4, 5]];
        move |set| judged(fit_set(set, &columns, &|_, _| 0.25, gram, 6))
    }

    fn exchanged(
        kinds: &[CandidateKind],
        sizes: &[Vec<usize>],
        gram: &DMatrix<f64>,
        start: &[(usize, usize)],
    ) -> Vec<usize> {
        // The check's other candidates: sensors, never traded.
        let mut kinds = kinds.to_vec();
        let mut sizes = sizes.to_vec();
        kinds.resize(12, S);
        sizes.resize(12, vec![1]);
        let mut set = start.to_vec();
        exchange(&kinds, &sizes, &judge(gram), &mut set);
        let mut named: Vec<usize> = set.iter().map(|&(c, _)| c).collect();
        named.sort_unstable();
        named
    }

    #[test]
    fn a_parameter_must_make_the_readings_20_times_likelier() {
        // 2 ln 20 = ln 400.
        assert!((parameter_penalty() - 5.991_464_547_107_98).abs() < 1e-12);
    }

    #[test]
    fn a_joint_that_only_stands_for_its_leg_is_traded_for_the_leg() {
        // Legs 1 and 2 slipped; the search named the joint and leg 2. The
        // joint's two own directions explain nothing: 2 x 2 ln 20 of score
        // lost, the leg is named.
        let (kinds, sizes, gram) = synthetic(1.0, false, |c| 0.3 * c[0] - 0.2 * c[1]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(3, 3), (1, 1)]), [0, 1]);
        // One leg named as its joint, alone: traded too.
        let (kinds, sizes, gram) = synthetic(1.0, false, |c| 0.3 * c[0]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(3, 3)]), [0]);
    }

    #[test]
    fn a_joint_that_moved_stays_a_joint() {
        // The joint moved across its leg as well: its own directions
        // explain up to (0.2 x |u|)^2, about 60 of statistic (|u|^2 about
        // 1500), beyond the 12 of penalty its two more parameters cost.
        let (kinds, sizes, gram) = synthetic(1.0, false, |c| 0.3 * c[0] + 0.2 * c[4]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(3, 3)]), [3]);
        // Named as the leg by the search: traded for the joint.
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1)]), [3]);
        // Too little across the leg, (0.03 x |u|)^2 at most 1.4 < 12: the
        // leg is named.
        let (kinds, sizes, gram) = synthetic(1.0, false, |c| 0.3 * c[0] + 0.03 * c[4]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(3, 3)]), [0]);
    }

    #[test]
    fn of_two_leg_pairs_that_read_alike_the_smaller_change_is_named() {
        // Leg 1 +1 mm-equivalent, leg 3 -1: through the common length,
        // barely seen (eps 0.02), it reads as legs 1 and 2 at +2 and +1.
        // Both pairs fit within 2 ln 20; the smaller pair is named.
        let (kinds, sizes, gram) = synthetic(0.02, false, |c| 0.1 * c[0] - 0.1 * c[2]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1), (1, 1)]), [0, 2]);
        // Seen well (eps 1), the other pair fits much worse: the search's
        // right pair stays, and a wrong one is traded for the better fit.
        let (kinds, sizes, gram) = synthetic(1.0, false, |c| 0.1 * c[0] - 0.1 * c[2]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1), (2, 1)]), [0, 2]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1), (1, 1)]), [0, 2]);
        // The readings a little closer to the bigger pair (0.006 of
        // statistic): the smaller pair is still named.
        let (kinds, sizes, gram) = synthetic(0.02, false, |c| 0.2 * c[0] + 0.1 * c[1]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1), (1, 1)]), [0, 2]);
        // One leg alone is never traded for a smaller one that fits alike:
        // the size rule needs two changes. Leg 1 at 0.1 fits best; leg 3
        // at about -0.06 leaves about 4.8 of statistic, within 2 ln 20.
        let (kinds, sizes, gram) = synthetic(0.0, false, |c| 0.1 * c[0] + 0.02 * c[1]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1)]), [0]);
        // Nor a leg of a pair for a joint of smaller size (the joint's own
        // direction 3 times the leg's) that fits alike: sizes compare
        // within a kind only.
        let (kinds, sizes, gram) = synthetic(1.0, true, |c| 0.3 * c[0] + 0.2 * c[1] + 0.01 * c[5]);
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1), (1, 1)]), [0, 1]);
    }

    #[test]
    fn sensors_and_thermal_growth_are_not_traded() {
        // A sensor named beside a leg stays, though a joint would fit the
        // sensor's column better.
        let (mut kinds, sizes, gram) = synthetic(1.0, false, |c| 0.3 * c[0] + 0.2 * c[4]);
        kinds[3] = S;
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1)]), [0]);
        kinds[3] = T;
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(0, 1)]), [0]);
        // A sensor in the set is not traded for the leg that reads as it
        // does with fewer parameters.
        let (mut kinds, sizes, gram) = synthetic(1.0, false, |c| 0.3 * c[0]);
        kinds[3] = S;
        assert_eq!(exchanged(&kinds, &sizes, &gram, &[(3, 3)]), [3]);
    }

    const S: CandidateKind = CandidateKind::Sensor;
    const T: CandidateKind = CandidateKind::Thermal;
    const L: CandidateKind = CandidateKind::Leg;

    #[test]
    fn a_thermal_growth_is_named_before_a_sensor_that_fits_alike() {
        // The scale gain first, a thermal growth a factor 10 behind: named.
        let rows = [
            (L, -5.0, true),
            (S, -40.0, true),
            (T, -40.0 + 10f64.ln(), true),
        ];
        assert_eq!(named_first(1, &rows), 2);
        // A factor 30 behind: the sensor stays.
        let rows = [(S, -40.0, true), (T, -40.0 + 30f64.ln(), true)];
        assert_eq!(named_first(0, &rows), 0);
        // Not significant: the sensor stays.
        let rows = [(S, -40.0, true), (T, -40.0, false)];
        assert_eq!(named_first(0, &rows), 0);
        // A leg first: never displaced by a thermal growth.
        let rows = [(L, -40.0, true), (T, -40.0, true)];
        assert_eq!(named_first(0, &rows), 0);
        // Of two thermal growths, the more likely.
        let rows = [(S, -40.0, true), (T, -39.0, true), (T, -39.5, true)];
        assert_eq!(named_first(0, &rows), 2);
    }
}
