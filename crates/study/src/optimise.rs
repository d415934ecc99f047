//! Pose-set optimisation: choose `n` poses from a candidate grid of the
//! workspace to maximise an observability index of the identification.
//!
//! The information matrix of a pose set `S` with the three sensor offsets
//! eliminated is
//!
//! ```text
//! F(S) = sum_{j in S} sum_c a_jc a_jc^T - (1/n) sum_c s_c s_c^T,   s_c = sum_{j in S} a_jc
//! ```
//!
//! where `a_jc` is the noise-weighted Jacobian row of reading `c` at pose
//! `j` (identifiable parameters only). Two criteria:
//!
//! - [`Criterion::DOptimal`]: `log det F`, equivalent to maximising O1
//!   (Borm-Menq) for a fixed number of poses;
//! - [`Criterion::NoiseAmplification`]: O4 (Nahvi-Hollerbach),
//!   `s_min^2 / s_max` of the column-scaled matrix, i.e. `l_min / sqrt(l_max)`
//!   of `D^-1 F D^-1` with `D = sqrt(diag F)`.
//!
//! The search is a sequential exchange (Fedorov / DETMAX family): for every
//! selected pose in turn, the best swap with an unselected candidate is
//! made if it improves the criterion; passes repeat until none does. Swaps
//! update `F` in `O(q^2)`; candidates of a swap are scored in parallel, the
//! choice is deterministic.
//!
//! The exchange (and the greedy construction that can seed it) is written
//! once, for any criterion that implements [`ExchangeCriterion`]: the
//! observability indices here, and the predicted tool-tip uncertainty of
//! planned external measurements ([`crate::plan`]).

use nalgebra::{DMatrix, Vector3};
use rayon::prelude::*;
use tricept_kinematics::Machine;
use tricept_model::{ParameterSet, jacobian::error_jacobian};

use crate::StudyError;

/// The index to maximise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Criterion {
    /// `log det F` (O1, D-optimality).
    DOptimal,
    /// O4, the noise amplification index.
    NoiseAmplification,
}

/// Candidate poses with their weighted Jacobian rows.
#[derive(Debug, Clone)]
pub struct Candidates {
    /// Target points, mm.
    pub targets_mm: Vec<Vector3<f64>>,
    /// `rows[j][c]`: weighted row of reading `c` at candidate `j` (length q).
    rows: Vec<[Vec<f64>; 3]>,
    q: usize,
}

impl Candidates {
    /// Rows of `set` restricted to `columns`, weighted by `sigma`
    /// (`[phi, theta, s]` of a logged reading), at the nominal machine.
    pub fn new(
        machine: &Machine,
        set: &ParameterSet,
        columns: &[usize],
        targets_mm: Vec<Vector3<f64>>,
        sigma: [f64; 3],
    ) -> Result<Candidates, StudyError> {
        let k = set.len();
        let mut block = vec![0.0; 3 * k];
        let mut rows = Vec::with_capacity(targets_mm.len());
        for r in &targets_mm {
            let up = machine.inverse(r)?.up;
            let j21 = error_jacobian(machine, &up)?;
            set.project(3, |row, f| j21[(row, f)], &mut block);
            rows.push([0, 1, 2].map(|c| {
                columns
                    .iter()
                    .map(|&t| block[c * k + t] / sigma[c])
                    .collect::<Vec<f64>>()
            }));
        }
        Ok(Candidates {
            targets_mm,
            rows,
            q: columns.len(),
        })
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The information matrix `F(S)` of a selection (indices, repeats
    /// allowed), the three sensor offsets eliminated (see the module docs).
    pub fn information(&self, selection: &[usize]) -> DMatrix<f64> {
        Sums::of(self, selection).information()
    }

    /// Index of the candidate nearest to `p`.
    pub fn nearest(&self, p: &Vector3<f64>) -> usize {
        (0..self.len())
            .min_by(|&a, &b| {
                (self.targets_mm[a] - p)
                    .norm()
                    .total_cmp(&(self.targets_mm[b] - p).norm())
            })
            .unwrap_or(0)
    }
}

/// Running sums of a selection.
#[derive(Debug, Clone)]
struct Sums {
    g: DMatrix<f64>,
    s: [Vec<f64>; 3],
    n: usize,
}

impl Sums {
    fn of(c: &Candidates, selection: &[usize]) -> Sums {
        let mut sums = Sums {
            g: DMatrix::zeros(c.q, c.q),
            s: [vec![0.0; c.q], vec![0.0; c.q], vec![0.0; c.q]],
            n: 0,
        };
        for &j in selection {
            sums.add(c, j, 1.0);
        }
        sums
    }

    fn add(&mut self, c: &Candidates, j: usize, sign: f64) {
        if sign > 0.0 {
            self.n += 1;
        } else {
            self.n = self.n.saturating_sub(1);
        }
        for ch in 0..3 {
            let a = &c.rows[j][ch];
            for u in 0..c.q {
                self.s[ch][u] += sign * a[u];
                for v in 0..c.q {
                    self.g[(u, v)] += sign * a[u] * a[v];
                }
            }
        }
    }

    fn information(&self) -> DMatrix<f64> {
        let mut f = self.g.clone();
        let n = self.n.max(1) as f64;
        let q = f.nrows();
        for ch in 0..3 {
            for u in 0..q {
                for v in 0..q {
                    f[(u, v)] -= self.s[ch][u] * self.s[ch][v] / n;
                }
            }
        }
        f
    }
}

/// The criterion's value for an information matrix (`-inf` if singular).
pub fn score(criterion: Criterion, f: &DMatrix<f64>) -> f64 {
    match criterion {
        Criterion::DOptimal => match f.clone().cholesky() {
            Some(ch) => 2.0 * ch.l().diagonal().iter().map(|d| d.ln()).sum::<f64>(),
            None => f64::NEG_INFINITY,
        },
        Criterion::NoiseAmplification => {
            let q = f.nrows();
            let d: Vec<f64> = (0..q).map(|i| f[(i, i)].max(0.0).sqrt()).collect();
            if d.contains(&0.0) {
                return f64::NEG_INFINITY;
            }
            let b = DMatrix::from_fn(q, q, |i, j| f[(i, j)] / (d[i] * d[j]));
            let ev = b.symmetric_eigenvalues();
            let (lo, hi) = (ev.min(), ev.max());
            if lo <= 0.0 {
                f64::NEG_INFINITY
            } else {
                lo / hi.sqrt()
            }
        }
    }
}

/// A selected pose set.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Selection {
    /// Indices into the candidates.
    pub indices: Vec<usize>,
    /// Criterion value of the start.
    pub start_value: f64,
    /// Criterion value reached.
    pub value: f64,
    /// Swaps made.
    pub swaps: usize,
    /// Passes over the selection.
    pub passes: usize,
}

/// A design criterion that the sequential exchange can improve: larger is
/// better. The state of a selection is whatever makes adding and removing
/// one candidate cheap (running sums, an information matrix).
pub trait ExchangeCriterion: Sync {
    /// What is kept about a selection.
    type State: Clone + Send + Sync;
    /// Number of candidates.
    fn candidates(&self) -> usize;
    /// The state of a selection.
    fn state(&self, selection: &[usize]) -> Self::State;
    /// The criterion's value (larger is better; `-inf` for a degenerate one).
    fn value(&self, state: &Self::State) -> f64;
    /// The state with candidate `c` removed (it is in the selection).
    fn without(&self, state: &Self::State, c: usize) -> Self::State;
    /// The state with candidate `c` added.
    fn with(&self, state: &Self::State, c: usize) -> Self::State;
    /// The value of `state` plus each of `candidates` (default: [`with`]
    /// then [`value`], candidates in parallel).
    ///
    /// [`with`]: ExchangeCriterion::with
    /// [`value`]: ExchangeCriterion::value
    fn values_with(&self, state: &Self::State, candidates: &[usize]) -> Vec<f64> {
        candidates
            .par_iter()
            .map(|&c| self.value(&self.with(state, c)))
            .collect()
    }
}

/// The best of `values` (paired with `candidates`): largest value, lowest
/// index on ties; `(-inf, usize::MAX)` when there is none.
fn best_of(candidates: &[usize], values: &[f64]) -> (f64, usize) {
    candidates
        .iter()
        .zip(values)
        .fold((f64::NEG_INFINITY, usize::MAX), |a, (&c, &v)| {
            if v > a.0 || (v == a.0 && c < a.1) {
                (v, c)
            } else {
                a
            }
        })
}

/// Sequential exchange from `start` (indices of candidates), at most
/// `max_passes` passes: for each selected candidate in turn, the best swap
/// with an unselected one is made if it improves the criterion by more than
/// a relative 1e-9; passes repeat until none does.
pub fn exchange_with<C: ExchangeCriterion>(
    criterion: &C,
    start: &[usize],
    max_passes: usize,
) -> Selection {
    let mut selected: Vec<usize> = start.to_vec();
    let mut state = criterion.state(&selected);
    let start_value = criterion.value(&state);
    let mut value = start_value;
    let mut swaps = 0;
    let mut passes = 0;
    while passes < max_passes {
        passes += 1;
        let mut improved = false;
        for pos in 0..selected.len() {
            let out = selected[pos];
            let reduced = criterion.without(&state, out);
            let free: Vec<usize> = (0..criterion.candidates())
                .filter(|c| !selected.contains(c))
                .collect();
            let best = best_of(&free, &criterion.values_with(&reduced, &free));
            if best.0 > value * (1.0 + 1e-9 * value.signum()) + 1e-12 && best.1 != usize::MAX {
                state = criterion.with(&reduced, best.1);
                selected[pos] = best.1;
                value = best.0;
                swaps += 1;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    Selection {
        indices: selected,
        start_value,
        value,
        swaps,
        passes,
    }
}

/// Greedy construction: from `start`, add the best candidate one at a time
/// until `k` are selected. The selections along the way are nested: the
/// first `j` of the result are the greedy selection of size `j`.
pub fn greedy<C: ExchangeCriterion>(criterion: &C, start: &[usize], k: usize) -> Vec<usize> {
    let mut selected = start.to_vec();
    let mut state = criterion.state(&selected);
    while selected.len() < k {
        let free: Vec<usize> = (0..criterion.candidates())
            .filter(|c| !selected.contains(c))
            .collect();
        let best = best_of(&free, &criterion.values_with(&state, &free));
        if best.1 == usize::MAX {
            break;
        }
        state = criterion.with(&state, best.1);
        selected.push(best.1);
    }
    selected
}

/// The observability indices of [`Candidates`] as an exchange criterion.
struct Observability<'a> {
    candidates: &'a Candidates,
    criterion: Criterion,
}

impl ExchangeCriterion for Observability<'_> {
    type State = Sums;

    fn candidates(&self) -> usize {
        self.candidates.len()
    }

    fn state(&self, selection: &[usize]) -> Sums {
        Sums::of(self.candidates, selection)
    }

    fn value(&self, state: &Sums) -> f64 {
        score(self.criterion, &state.information())
    }

    fn without(&self, state: &Sums, c: usize) -> Sums {
        let mut s = state.clone();
        s.add(self.candidates, c, -1.0);
        s
    }

    fn with(&self, state: &Sums, c: usize) -> Sums {
        let mut s = state.clone();
        s.add(self.candidates, c, 1.0);
        s
    }
}

/// Sequential exchange from `start` (indices into `c`), at most `max_passes`.
pub fn exchange(
    c: &Candidates,
    start: &[usize],
    criterion: Criterion,
    max_passes: usize,
) -> Selection {
    exchange_with(
        &Observability {
            candidates: c,
            criterion,
        },
        start,
        max_passes,
    )
}

/// The default candidate grid: 5 levels x (axis + 5 rings x 16) = 405 points.
pub fn candidate_grid(machine: &Machine) -> Vec<Vector3<f64>> {
    machine.workspace.polar_grid(5, 16, 5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exchange_never_lowers_the_criterion_and_beats_a_poor_start() {
        let m =
            Machine::paper().with_axis_order(tricept_kinematics::description::AxisOrder::YFirst);
        let set = ParameterSet::paper15();
        let columns: Vec<usize> = (0..15).collect();
        let c = Candidates::new(
            &m,
            &set,
            &columns,
            candidate_grid(&m),
            m.sensors.logged_sigma(),
        )
        .unwrap();
        // A poor start: 20 poses crowded around the axis on one level.
        let start: Vec<usize> = (0..20).collect();
        for criterion in [Criterion::DOptimal, Criterion::NoiseAmplification] {
            let s = exchange(&c, &start, criterion, 5);
            assert!(s.value >= s.start_value, "{criterion:?}");
            assert!(
                s.value > s.start_value + 1e-9,
                "{criterion:?} found no improvement"
            );
            assert_eq!(s.indices.len(), 20);
            let mut unique = s.indices.clone();
            unique.sort_unstable();
            unique.dedup();
            assert_eq!(unique.len(), 20);
        }
    }
}
