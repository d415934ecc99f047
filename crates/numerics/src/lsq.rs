//! Rank-revealing weighted least squares with nuisance parameters.
//!
//! A problem is reduced by [`crate::linalg::TriangularAccumulator`] to the
//! triangular factor `R` of its weighted rows `[N | A | b]`: nuisance
//! columns `N` (the three sensor zero offsets), parameter columns `A`, and
//! the right-hand side `b`. Then:
//!
//! 1. **Column scaling.** The parameter block `R_pp` (which is the `R` of the
//!    offset-projected `A`) has its columns scaled to unit norm, so that the
//!    rank decision does not depend on units.
//! 2. **Rank.** The singular values `s_i` of the scaled block decide the
//!    numerical rank: `s_i > tol * s_1` (default `tol = 1e-8`; the stated
//!    tolerance is part of every report).
//! 3. **Which parameters to fix.** Column-pivoted QR of the scaled block
//!    orders the parameters; the last `k - rank` are *fixed at their prior
//!    value* and listed by name. This is the basic solution of the rank-
//!    deficient problem, never a silent minimum-norm number: the estimate of
//!    an unidentifiable combination is the prior, and the report says so.
//! 4. **Solve.** The identifiable columns and the nuisance columns are
//!    re-factored (column-scaled) and solved by back substitution; the
//!    covariance is `(R^T R)^{-1}` in the units of the weighted problem.

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::{Accum, Mat, MatRef, Par};

use crate::linalg::{invert_upper, pivot_order, r_factor, solve_upper, svd_values_and_vectors};

/// A parameter column whose norm is below this fraction of the largest
/// column's is treated as exactly zero (well below any rank tolerance).
pub const ZERO_COLUMN: f64 = 1e-10;

/// Default relative tolerance on singular values for the numerical rank.
pub const DEFAULT_RANK_TOLERANCE: f64 = 1e-8;

/// A weighted least-squares problem reduced to its triangular factor.
///
/// # Example
/// ```
/// use tricept_numerics::linalg::TriangularAccumulator;
/// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
/// // y = 1 + 2 x with one nuisance (the intercept) and one parameter.
/// let mut acc = TriangularAccumulator::new(3);
/// for x in [0.0, 1.0, 2.0, 3.0] {
///     acc.push_row(&[1.0, x, 1.0 + 2.0 * x]);
/// }
/// let p = ReducedProblem { rows: acc.rows(), r: acc.finish(), n_nuisance: 1, k: 1 };
/// let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
/// let s = p.solve(&d);
/// assert!((s.parameters[0] - 2.0).abs() < 1e-12 && (s.nuisance[0] - 1.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone)]
pub struct ReducedProblem {
    /// `(n_nuisance + k + 1)` square upper-triangular factor of `[N | A | b]`.
    pub r: Mat<f64>,
    /// Number of nuisance columns (first).
    pub n_nuisance: usize,
    /// Number of parameter columns.
    pub k: usize,
    /// Number of rows folded in.
    pub rows: usize,
}

/// The rank decision for a problem's parameter block.
///
/// # Example
/// ```
/// use tricept_numerics::linalg::TriangularAccumulator;
/// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
/// // Two identical columns: one of them is held fixed, the combination named.
/// let mut acc = TriangularAccumulator::new(4);
/// for x in [0.0, 1.0, 2.0, 3.0, 5.0] {
///     acc.push_row(&[1.0, x, x, 3.0 * x]);
/// }
/// let p = ReducedProblem { rows: acc.rows(), r: acc.finish(), n_nuisance: 1, k: 2 };
/// let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
/// assert_eq!(d.rank, 1);
/// let null = &d.null_space_basis()[0];
/// assert!((null[0] + null[1]).abs() < 1e-9); // a - b is invisible
/// ```
#[derive(Debug, Clone)]
pub struct RankDecision {
    /// Norm of each parameter column of the weighted, offset-projected matrix.
    pub column_scale: Vec<f64>,
    /// Singular values of the column-scaled parameter block, descending.
    pub singular_values: Vec<f64>,
    /// Right singular vectors (columns) of the scaled block, in scaled units.
    pub right_vectors: Mat<f64>,
    /// Numerical rank.
    pub rank: usize,
    /// Relative tolerance used.
    pub tolerance: f64,
    /// Parameters estimated (ascending indices).
    pub identifiable: Vec<usize>,
    /// Parameters fixed at their prior (ascending indices).
    pub fixed: Vec<usize>,
}

/// The solution of a reduced problem under a rank decision.
///
/// # Example
/// ```
/// use tricept_numerics::linalg::TriangularAccumulator;
/// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
/// let mut acc = TriangularAccumulator::new(3);
/// for x in [0.0, 1.0, 2.0, 3.0] {
///     acc.push_row(&[1.0, x, 1.0 + 2.0 * x + if x == 1.0 { 0.1 } else { 0.0 }]);
/// }
/// let p = ReducedProblem { rows: acc.rows(), r: acc.finish(), n_nuisance: 1, k: 1 };
/// let s = p.solve(&p.decide(DEFAULT_RANK_TOLERANCE).unwrap());
/// // Unit-weight rows: the slope's variance is 1 / sum (x - mean)^2 = 1 / 5.
/// assert!((s.covariance[(1, 1)] - 0.2).abs() < 1e-12);
/// assert!(s.residual_norm2 > 0.0);
/// ```
#[derive(Debug, Clone)]
pub struct Solution {
    /// Parameter values (zero for fixed parameters).
    pub parameters: Vec<f64>,
    /// Nuisance values.
    pub nuisance: Vec<f64>,
    /// Covariance of `[nuisance, parameters]` (zero rows and columns for
    /// fixed parameters), in the units of the unweighted unknowns when the
    /// rows were weighted by `1/sigma`.
    pub covariance: Mat<f64>,
    /// Squared norm of the weighted residual.
    pub residual_norm2: f64,
}

impl ReducedProblem {
    /// The union of reduced problems over the same `k` parameters: their
    /// factors stacked with every nuisance block first (in the order of
    /// `parts`), then the parameters and the right-hand side, and factored
    /// again. Each part keeps its own nuisance columns; the rows add up.
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::ReducedProblem;
    /// // Two sources of y = 2 x, each with an offset of its own.
    /// let part = |offset: f64| {
    ///     let mut acc = TriangularAccumulator::new(3);
    ///     for x in [0.0, 1.0, 2.0] {
    ///         acc.push_row(&[1.0, x, offset + 2.0 * x]);
    ///     }
    ///     ReducedProblem { r: acc.finish(), n_nuisance: 1, k: 1, rows: 3 }
    /// };
    /// let (a, b) = (part(1.0), part(-3.0));
    /// let union = ReducedProblem::merge(&[&a, &b]);
    /// assert_eq!((union.n_nuisance, union.k, union.rows), (2, 1, 6));
    /// assert_eq!((union.r.nrows(), union.r.ncols()), (4, 4));
    /// ```
    pub fn merge(parts: &[&ReducedProblem]) -> ReducedProblem {
        let k = parts.first().map_or(0, |p| p.k);
        let n_nuisance: usize = parts.iter().map(|p| p.n_nuisance).sum();
        let width = n_nuisance + k + 1;
        let height: usize = parts.iter().map(|p| p.r.nrows()).sum();
        let mut stacked = Mat::<f64>::zeros(height, width);
        let (mut row, mut offset) = (0, 0);
        for part in parts {
            let nn = part.n_nuisance;
            for i in 0..part.r.nrows() {
                for j in 0..part.r.ncols() {
                    let col = if j < nn {
                        offset + j
                    } else {
                        n_nuisance + (j - nn)
                    };
                    stacked[(row + i, col)] = part.r[(i, j)];
                }
            }
            row += part.r.nrows();
            offset += nn;
        }
        ReducedProblem {
            r: r_factor(stacked.as_ref()),
            n_nuisance,
            k,
            rows: parts.iter().map(|p| p.rows).sum(),
        }
    }

    /// The parameter block `R_pp` (`k x k`).
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::ReducedProblem;
    /// let mut acc = TriangularAccumulator::new(4);
    /// (0..5).for_each(|i| acc.push_row(&[1.0, i as f64, (i * i) as f64, 0.0]));
    /// let p = ReducedProblem { rows: acc.rows(), r: acc.finish(), n_nuisance: 1, k: 2 };
    /// assert_eq!(p.parameter_block().nrows(), 2);
    /// ```
    pub fn parameter_block(&self) -> MatRef<'_, f64> {
        self.r
            .as_ref()
            .submatrix(self.n_nuisance, self.n_nuisance, self.k, self.k)
    }

    /// Squared norm of the weighted residual after fitting only the nuisance
    /// columns (the cost of the current parameter values).
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::ReducedProblem;
    /// // Right-hand side 1, 2, 3 with an intercept as nuisance: the residual
    /// // about the mean is 1 + 0 + 1.
    /// let mut acc = TriangularAccumulator::new(3);
    /// for (x, y) in [(0.0, 1.0), (1.0, 2.0), (2.0, 3.0)] {
    ///     acc.push_row(&[1.0, x, y]);
    /// }
    /// let p = ReducedProblem { rows: 3, r: acc.finish(), n_nuisance: 1, k: 1 };
    /// assert!((p.cost_without_parameters() - 2.0).abs() < 1e-12);
    /// ```
    pub fn cost_without_parameters(&self) -> f64 {
        let rhs = self.n_nuisance + self.k;
        (self.n_nuisance..=rhs)
            .map(|i| self.r[(i, rhs)] * self.r[(i, rhs)])
            .sum()
    }

    /// The nuisance values that fit best with the parameters held at their
    /// current values (zero step): `R_nn c = r_n`.
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::ReducedProblem;
    /// // y = 1 + 2 x: with the slope held at zero, the intercept is the mean, 4.
    /// let mut acc = TriangularAccumulator::new(3);
    /// for x in [0.0, 1.0, 2.0, 3.0] {
    ///     acc.push_row(&[1.0, x, 1.0 + 2.0 * x]);
    /// }
    /// let p = ReducedProblem { rows: 4, r: acc.finish(), n_nuisance: 1, k: 1 };
    /// assert!((p.nuisance_without_parameters()[0] - 4.0).abs() < 1e-12);
    /// ```
    pub fn nuisance_without_parameters(&self) -> Vec<f64> {
        let nn = self.n_nuisance;
        let rhs = nn + self.k;
        let r_nn = self.r.as_ref().submatrix(0, 0, nn, nn);
        let b: Vec<f64> = (0..nn).map(|i| self.r[(i, rhs)]).collect();
        solve_upper(r_nn, &b)
    }

    /// Scales, ranks and orders the parameter columns (steps 1-3).
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
    /// // Two parameters that always appear as their sum: rank 1, one fixed.
    /// let mut acc = TriangularAccumulator::new(3);
    /// (0..6).for_each(|i| acc.push_row(&[i as f64, 2.0 * i as f64, 1.0]));
    /// let p = ReducedProblem { rows: 6, r: acc.finish(), n_nuisance: 0, k: 2 };
    /// let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
    /// assert_eq!((d.rank, d.fixed.len()), (1, 1));
    /// ```
    pub fn decide(&self, tolerance: f64) -> Option<RankDecision> {
        self.decide_weighted(tolerance, None)
    }

    /// [`ReducedProblem::decide`] with the choice of the parameters to hold
    /// (step 3) made on the columns multiplied by `prior_sizes` (each
    /// parameter's typical size, in its unit) instead of on the unit-norm
    /// columns: of a set of columns that cannot be told apart, the one
    /// whose typical size moves the data least is held, so that the held
    /// combination is the one the prior says matters least. The rank
    /// (steps 1-2) is decided on the unit-norm columns as before.
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
    /// // b's column is twice a's: one of them is held. Typical sizes 1 and
    /// // 0.1 make a's effect (1) larger than b's (2 x 0.1): b is held.
    /// let mut acc = TriangularAccumulator::new(3);
    /// (1..6).for_each(|i| acc.push_row(&[i as f64, 2.0 * i as f64, 1.0]));
    /// let p = ReducedProblem { rows: 5, r: acc.finish(), n_nuisance: 0, k: 2 };
    /// let d = p.decide_weighted(DEFAULT_RANK_TOLERANCE, Some(&[1.0, 0.1])).unwrap();
    /// assert_eq!(d.fixed, vec![1]);
    /// let d = p.decide_weighted(DEFAULT_RANK_TOLERANCE, Some(&[0.1, 1.0])).unwrap();
    /// assert_eq!(d.fixed, vec![0]);
    /// ```
    pub fn decide_weighted(
        &self,
        tolerance: f64,
        prior_sizes: Option<&[f64]>,
    ) -> Option<RankDecision> {
        let k = self.k;
        let block = self.parameter_block();
        let norms: Vec<f64> = (0..k)
            .map(|j| {
                (0..k)
                    .map(|i| block[(i, j)] * block[(i, j)])
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        let largest = norms.iter().copied().fold(0.0, f64::max);
        // A column below ZERO_COLUMN of the largest is rounding noise (a
        // parameter the readings do not depend on, like dyA3 on the x-first
        // machine, whose analytic column is exactly zero): it is zeroed, so
        // that it lands in the null space instead of being blown up to a
        // random unit direction whose size depends on the weights' magnitude.
        let zero: Vec<bool> = norms
            .iter()
            .map(|&n| n.is_nan() || n <= ZERO_COLUMN * largest)
            .collect();
        let column_scale: Vec<f64> = norms
            .iter()
            .zip(&zero)
            .map(|(&n, &z)| if z { 1.0 } else { n })
            .collect();
        let scaled = Mat::from_fn(k, k, |i, j| {
            if zero[j] {
                0.0
            } else {
                block[(i, j)] / column_scale[j]
            }
        });
        let (singular_values, right_vectors) = svd_values_and_vectors(scaled.as_ref())?;
        let top = singular_values.first().copied().unwrap_or(0.0);
        let rank = singular_values
            .iter()
            .filter(|s| **s > tolerance * top && **s > 0.0)
            .count();
        let order = match prior_sizes {
            Some(sizes) if sizes.len() == k => {
                let weighted = Mat::from_fn(k, k, |i, j| {
                    scaled[(i, j)] * column_scale[j] * sizes[j].abs()
                });
                pivot_order(weighted.as_ref())
            }
            _ => pivot_order(scaled.as_ref()),
        };
        let mut identifiable: Vec<usize> = order[..rank].to_vec();
        let mut fixed: Vec<usize> = order[rank..].to_vec();
        identifiable.sort_unstable();
        fixed.sort_unstable();
        Some(RankDecision {
            column_scale,
            singular_values,
            right_vectors,
            rank,
            tolerance,
            identifiable,
            fixed,
        })
    }

    /// Solves for the nuisance and identifiable parameters (step 4).
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
    /// // y = a + b with a, b inseparable: the fixed one is held at 0 (its
    /// // prior) and the other takes the whole sum, never a minimum-norm split.
    /// let mut acc = TriangularAccumulator::new(3);
    /// (1..6).for_each(|i| acc.push_row(&[i as f64, i as f64, 3.0 * i as f64]));
    /// let p = ReducedProblem { rows: 5, r: acc.finish(), n_nuisance: 0, k: 2 };
    /// let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
    /// let s = p.solve(&d);
    /// assert_eq!(s.parameters[d.fixed[0]], 0.0);
    /// assert!((s.parameters[d.identifiable[0]] - 3.0).abs() < 1e-12);
    /// ```
    pub fn solve(&self, decision: &RankDecision) -> Solution {
        let nn = self.n_nuisance;
        let (columns, scale, rs) = self.selected(decision);
        let q = columns.len();
        let tri = rs.as_ref().submatrix(0, 0, q, q);
        let c: Vec<f64> = (0..q).map(|i| rs[(i, q)]).collect();
        let y = solve_upper(tri, &c);
        let residual_norm2 = rs[(q, q)] * rs[(q, q)];
        let rinv = invert_upper(tri);
        let cov_scaled = &rinv * rinv.transpose();

        let total = nn + self.k;
        let mut parameters = vec![0.0; self.k];
        let mut nuisance = vec![0.0; nn];
        let mut covariance = Mat::<f64>::zeros(total, total);
        let position = |j: usize| -> usize { columns[j] };
        for a in 0..q {
            let value = y[a] / scale[a];
            let col = position(a);
            if col < nn {
                nuisance[col] = value;
            } else {
                parameters[col - nn] = value;
            }
            for b in 0..q {
                covariance[(col, position(b))] = cov_scaled[(a, b)] / (scale[a] * scale[b]);
            }
        }
        Solution {
            parameters,
            nuisance,
            covariance,
            residual_norm2,
        }
    }
}

impl ReducedProblem {
    /// The estimated columns under `decision` (nuisance, then the
    /// identifiable parameters, in the problem's column order), their
    /// scales (unit norm) and the triangular factor of the scaled columns
    /// with the right-hand side last.
    fn selected(&self, decision: &RankDecision) -> (Vec<usize>, Vec<f64>, Mat<f64>) {
        let nn = self.n_nuisance;
        let rhs = nn + self.k;
        let columns: Vec<usize> = (0..nn)
            .chain(decision.identifiable.iter().map(|j| nn + j))
            .collect();
        let q = columns.len();
        let scale: Vec<f64> = columns
            .iter()
            .map(|&c| {
                let n = (0..=c)
                    .map(|i| self.r[(i, c)] * self.r[(i, c)])
                    .sum::<f64>()
                    .sqrt();
                if n > 0.0 { n } else { 1.0 }
            })
            .collect();
        let selected = Mat::from_fn(rhs + 1, q + 1, |i, j| {
            if j < q {
                self.r[(i, columns[j])] / scale[j]
            } else {
                self.r[(i, rhs)]
            }
        });
        let rs = r_factor(selected.as_ref());
        (columns, scale, rs)
    }

    /// The factor that gives any row's leverage under `decision`: the
    /// diagonal of the hat matrix `H = X (X^T X)^-1 X^T` over the estimated
    /// columns, computed as `|R^-T x|^2` on the column-scaled factor (a sum
    /// of squares: no cancellation, whatever the conditioning).
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
    /// // A straight line through 4 points: the leverages sum to the 2 unknowns.
    /// let rows: Vec<[f64; 3]> = [0.0, 1.0, 2.0, 5.0].iter().map(|&x| [1.0, x, 0.0]).collect();
    /// let mut acc = TriangularAccumulator::new(3);
    /// rows.iter().for_each(|r| acc.push_row(r));
    /// let p = ReducedProblem { rows: 4, r: acc.finish(), n_nuisance: 1, k: 1 };
    /// let hat = p.hat_factor(&p.decide(DEFAULT_RANK_TOLERANCE).unwrap());
    /// let h: f64 = rows.iter().map(|r| hat.whiten(r).iter().map(|w| w * w).sum::<f64>()).sum();
    /// assert!((h - 2.0).abs() < 1e-12);
    /// ```
    pub fn hat_factor(&self, decision: &RankDecision) -> HatFactor {
        let (columns, scale, rs) = self.selected(decision);
        let q = columns.len();
        HatFactor {
            r_inv: invert_upper(rs.as_ref().submatrix(0, 0, q, q)),
            columns,
            scale,
        }
    }
}

/// What [`ReducedProblem::hat_factor`] returns: the inverse of the
/// triangular factor of the estimated, column-scaled columns.
#[derive(Debug, Clone)]
pub struct HatFactor {
    columns: Vec<usize>,
    scale: Vec<f64>,
    r_inv: Mat<f64>,
}

impl HatFactor {
    /// `w = R^-T x` for a row `x` of the problem (its `n_nuisance + k`
    /// columns, a right-hand side beyond them ignored): the row's leverage
    /// is `|w|^2`, the hat matrix' entry of two rows `w_a . w_b`.
    pub fn whiten(&self, row: &[f64]) -> Vec<f64> {
        let q = self.columns.len();
        let x: Vec<f64> = self
            .columns
            .iter()
            .zip(&self.scale)
            .map(|(&c, s)| row.get(c).copied().unwrap_or(0.0) / s)
            .collect();
        (0..q)
            .map(|a| (0..=a).map(|b| x[b] * self.r_inv[(b, a)]).sum())
            .collect()
    }

    /// [`HatFactor::whiten`] of many rows at once (one matrix product):
    /// `w_i` for each row `x_i` of `rows` (`n x (n_nuisance + k)`, row-major
    /// slices), as the rows of an `n x q` matrix.
    pub fn whiten_rows(&self, rows: &[&[f64]]) -> Mat<f64> {
        let q = self.columns.len();
        let x = Mat::from_fn(rows.len(), q, |i, j| {
            rows[i].get(self.columns[j]).copied().unwrap_or(0.0) / self.scale[j]
        });
        let mut w = Mat::<f64>::zeros(rows.len(), q);
        matmul(
            w.as_mut(),
            Accum::Replace,
            x.as_ref(),
            self.r_inv.as_ref(),
            1.0,
            Par::Seq,
        );
        w
    }

    /// The step of the estimated unknowns a row predicts: `x . delta` for
    /// the solution's `delta` (`[nuisance | parameters]`, held ones zero).
    pub fn predict(row: &[f64], solution: &Solution) -> f64 {
        solution
            .nuisance
            .iter()
            .chain(&solution.parameters)
            .zip(row)
            .map(|(d, x)| d * x)
            .sum()
    }
}

impl RankDecision {
    /// A direction of the scaled parameter space, in parameter units: the
    /// scaled singular vector `i` divided by the column scales.
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
    /// // Readings depend on a + 2 b only: the null direction is (2, -1) / ...
    /// let mut acc = TriangularAccumulator::new(3);
    /// (1..6).for_each(|i| acc.push_row(&[i as f64, 2.0 * i as f64, 0.0]));
    /// let p = ReducedProblem { rows: 5, r: acc.finish(), n_nuisance: 0, k: 2 };
    /// let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
    /// let v = d.direction(1);
    /// assert!((v[0] / v[1] + 2.0).abs() < 1e-9);
    /// ```
    pub fn direction(&self, i: usize) -> Vec<f64> {
        (0..self.column_scale.len())
            .map(|j| self.right_vectors[(j, i)] / self.column_scale[j])
            .collect()
    }

    /// Basis of the unidentifiable subspace in parameter units, one vector
    /// per fixed parameter: vector `f` moves fixed parameter `f` by 1, the
    /// other fixed parameters by 0, and the identifiable ones so that the
    /// readings do not change (to first order).
    ///
    /// # Example
    /// ```
    /// use tricept_numerics::linalg::TriangularAccumulator;
    /// use tricept_numerics::lsq::{ReducedProblem, DEFAULT_RANK_TOLERANCE};
    /// let mut acc = TriangularAccumulator::new(3);
    /// (1..6).for_each(|i| acc.push_row(&[i as f64, 2.0 * i as f64, 0.0]));
    /// let p = ReducedProblem { rows: 5, r: acc.finish(), n_nuisance: 0, k: 2 };
    /// let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
    /// let basis = d.null_space_basis();
    /// let f = d.fixed[0];
    /// // Moves the fixed parameter by exactly 1 and keeps a + 2 b unchanged.
    /// assert!((basis[0][f] - 1.0).abs() < 1e-12);
    /// assert!((basis[0][0] + 2.0 * basis[0][1]).abs() < 1e-9);
    /// ```
    pub fn null_space_basis(&self) -> Vec<Vec<f64>> {
        let k = self.column_scale.len();
        let d = k - self.rank;
        if d == 0 {
            return Vec::new();
        }
        // Null vectors in parameter units.
        let null: Vec<Vec<f64>> = (self.rank..k).map(|i| self.direction(i)).collect();
        // Solve N_F c = e_f for each fixed parameter f (N_F: rows of the fixed
        // parameters), by Gaussian elimination with partial pivoting.
        let nf = Mat::from_fn(d, d, |a, b| null[b][self.fixed[a]]);
        let mut out = Vec::with_capacity(d);
        for f in 0..d {
            let mut e = vec![0.0; d];
            e[f] = 1.0;
            let Some(c) = solve_square(nf.as_ref(), &e) else {
                // Degenerate fixed block: fall back to the raw null vectors.
                return null;
            };
            let v: Vec<f64> = (0..k)
                .map(|j| (0..d).map(|b| c[b] * null[b][j]).sum())
                .collect();
            out.push(v);
        }
        out
    }
}

/// Solves the small square system `a x = b` by faer's LU with partial
/// pivoting; `None` when `a` is singular (a zero pivot) or the solution is
/// not finite.
fn solve_square(a: MatRef<'_, f64>, b: &[f64]) -> Option<Vec<f64>> {
    let n = b.len();
    let lu = a.partial_piv_lu();
    let u = lu.U();
    if (0..n).any(|i| u[(i, i)] == 0.0) {
        return None;
    }
    let x = lu.solve(Mat::from_fn(n, 1, |i, _| b[i]));
    let x: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::TriangularAccumulator;

    /// y = 2 + 3 x1 - x2 + noise-free, with x3 = x1 + x2 (unidentifiable).
    fn problem() -> ReducedProblem {
        let mut acc = TriangularAccumulator::new(5);
        for i in 0..40 {
            let x1 = (i as f64 * 0.3).sin();
            let x2 = (i as f64 * 0.7).cos();
            let x3 = x1 + x2;
            let y = 2.0 + 3.0 * x1 - x2;
            acc.push_row(&[1.0, x1, x2, x3, y]);
        }
        ReducedProblem {
            rows: acc.rows(),
            r: acc.finish(),
            n_nuisance: 1,
            k: 3,
        }
    }

    #[test]
    fn rank_deficiency_is_found_and_fixed_by_pivoting() {
        let p = problem();
        let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
        assert_eq!(d.rank, 2);
        assert_eq!(d.fixed.len(), 1);
        let basis = p.decide(DEFAULT_RANK_TOLERANCE).unwrap().null_space_basis();
        assert_eq!(basis.len(), 1);
        // The null direction is x1 + x2 - x3 = 0, i.e. (1, 1, -1) up to scale.
        let v = &basis[0];
        assert!(
            (v[0] - v[1]).abs() < 1e-9 && (v[0] + v[2]).abs() < 1e-9,
            "{v:?}"
        );
        // The fit still reproduces the data exactly.
        let s = p.solve(&d);
        assert!(s.residual_norm2 < 1e-20);
        assert!((s.nuisance[0] - 2.0).abs() < 1e-12);
        assert_eq!(s.parameters[d.fixed[0]], 0.0);
    }

    #[test]
    fn leverages_sum_to_the_unknowns_whichever_parameter_is_held() {
        let p = problem();
        let rows: Vec<[f64; 4]> = (0..40)
            .map(|i| {
                let x1 = (i as f64 * 0.3).sin();
                let x2 = (i as f64 * 0.7).cos();
                [1.0, x1, x2, x1 + x2]
            })
            .collect();
        let leverages = |d: &RankDecision| -> Vec<f64> {
            let hat = p.hat_factor(d);
            rows.iter()
                .map(|r| hat.whiten(r).iter().map(|w| w * w).sum())
                .collect()
        };
        let a = leverages(&p.decide(DEFAULT_RANK_TOLERANCE).unwrap());
        // One nuisance and two identifiable parameters: trace 3.
        assert!((a.iter().sum::<f64>() - 3.0).abs() < 1e-10);
        // The hat matrix projects on the column space: holding another of
        // the three collinear parameters changes no leverage.
        for sizes in [[1.0, 1.0, 1e-3], [1e-3, 1.0, 1.0], [1.0, 1e-3, 1.0]] {
            let d = p
                .decide_weighted(DEFAULT_RANK_TOLERANCE, Some(&sizes))
                .unwrap();
            let b = leverages(&d);
            assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-10));
        }
        let held = |sizes: [f64; 3]| {
            p.decide_weighted(DEFAULT_RANK_TOLERANCE, Some(&sizes))
                .unwrap()
                .fixed
        };
        assert_eq!(held([1.0, 1.0, 1e-3]), vec![2]);
        assert_eq!(held([1e-3, 1.0, 1.0]), vec![0]);
    }

    #[test]
    fn square_solve_handles_pivoting() {
        let a = Mat::from_fn(3, 3, |i, j| {
            [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]][i][j]
        });
        let b = [5.0, 3.0, 6.0];
        let x = solve_square(a.as_ref(), &b).unwrap();
        for i in 0..3 {
            let ax: f64 = (0..3).map(|j| a[(i, j)] * x[j]).sum();
            assert!((ax - b[i]).abs() < 1e-12, "{x:?}");
        }
        // The first pivot must swap rows (a[0][0] = 0); a singular matrix is refused.
        let singular = Mat::from_fn(2, 2, |i, _| i as f64);
        assert!(solve_square(singular.as_ref(), &[1.0, 1.0]).is_none());
    }
}
#[cfg(test)]
mod scale_tests {
    use super::*;
    use crate::linalg::TriangularAccumulator;

    #[test]
    fn solution_is_invariant_to_a_uniform_weight() {
        let build = |w: f64| {
            let mut acc = TriangularAccumulator::new(5);
            for i in 0..40 {
                let x1 = (i as f64 * 0.3).sin();
                let x2 = (i as f64 * 0.7).cos();
                let x3 = x1 * x2 + 0.01 * (i as f64).sqrt();
                let y = 2.0 + 3.0 * x1 - x2 + 0.5 * x3 + 1e-3 * ((i * 7919) % 13) as f64;
                acc.push_row(&[w, w * x1, w * x2, w * x3, w * y]);
            }
            let p = ReducedProblem {
                rows: acc.rows(),
                r: acc.finish(),
                n_nuisance: 1,
                k: 3,
            };
            let d = p.decide(DEFAULT_RANK_TOLERANCE).unwrap();
            p.solve(&d).parameters
        };
        let base = build(1.0);
        for w in [1e-8, 1e6, 1e12] {
            let other = build(w);
            for j in 0..3 {
                assert!(
                    (other[j] - base[j]).abs() < 1e-9 * base[j].abs().max(1.0),
                    "w {w}: {other:?} vs {base:?}"
                );
            }
        }
    }
}
