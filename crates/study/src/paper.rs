//! The paper's own solve, for comparison: readings differenced against the
//! first pose (eq. 10), the nominal Jacobian, no weighting (radians and
//! millimetres mixed as they come), and `deps = (H^T H)^{-1} H^T l` with an
//! explicit inverse (eq. 12).
//!
//! The solve is built from two parts so that its variants can be studied
//! one change at a time: the [`NominalLinearisation`] of the readings (one
//! per scenario) and a [`DifferencedSolve`] on it, which names the
//! parameters estimated, the reference pose and the [`RowWeights`].
//! [`paper_solve`] is the paper's choice (every parameter, pose 0, unit
//! weights). Weighting each differenced row by `1 / sigma^2` isolates the
//! cost of not weighting; weighting by the inverse covariance of the
//! differenced rows gives the solve that estimates the offsets instead,
//! which isolates the cost of treating differenced rows as independent.
//!
//! A differenced solve is linear in the readings, so it runs as a
//! [`LinearEstimator`] through the same fast Monte Carlo as ours: `p_hat =
//! Op (y_clean - g_0) + Op diag(sigma) z`, with `Op = (H^T W H)^{-1} H^T W
//! D` and `D` the differencing. For `mu` this is exact, not an
//! approximation; the compensated plane error is first order: `dr = G
//! (truth - p_hat)`.

use faer::Mat;
use nalgebra::DMatrix;
use tricept_model::jacobian::error_jacobian;

use crate::StudyError;
use crate::fast::{LinearEstimator, plane_jacobian};
use crate::scenario::Scenario;

/// The paper's estimator, or why it cannot be formed.
#[derive(Debug, Clone)]
pub enum PaperSolve {
    /// `H^T H` could be inverted (its 2-norm condition number is given).
    Formed {
        /// The estimator.
        estimator: Box<LinearEstimator>,
        /// Condition number of `H^T H`.
        condition: f64,
    },
    /// `H^T H` is singular to working precision.
    Singular {
        /// Condition number of `H^T H`.
        condition: f64,
    },
}

/// The readings linearised at the nominal machine: what the paper's solve
/// sees of a scenario.
#[derive(Debug, Clone)]
pub struct NominalLinearisation {
    /// Nominal readings `g_0` at the commanded poses, `[phi, theta, s]` per
    /// pose (rad, rad, mm), without sensor offsets.
    pub predictions: Vec<f64>,
    /// `J` (3 n x k): readings per unit of each parameter of the scenario's
    /// set, at the nominal machine.
    pub jacobian: DMatrix<f64>,
}

impl NominalLinearisation {
    /// Predictions and Jacobian at the scenario's target points.
    ///
    /// # Example
    /// ```
    /// use tricept_kinematics::Machine;
    /// use tricept_study::{Scenario, paper::NominalLinearisation};
    /// let m = Machine::paper();
    /// let s = Scenario::paper(m.clone(), m.workspace.polar_grid(1, 8, 2)).unwrap();
    /// let lin = NominalLinearisation::new(&s).unwrap();
    /// assert_eq!(lin.jacobian.shape(), (3 * 18, 15));
    /// // The x-first machine's readings do not depend on dyA3 (to first order).
    /// let dya3 = s.set.index_of("dyA3").unwrap();
    /// assert!(lin.jacobian.column(dya3).amax() < 1e-12);
    /// ```
    pub fn new(s: &Scenario) -> Result<NominalLinearisation, StudyError> {
        let k = s.set.len();
        let m = s.rows();
        let mut predictions = vec![0.0; m];
        let mut jacobian = DMatrix::<f64>::zeros(m, k);
        let mut block = vec![0.0; 3 * k];
        for (j, r) in s.targets_mm.iter().enumerate() {
            let ik = s.nominal.inverse(r)?;
            let j21 = error_jacobian(&s.nominal, &ik.up)?;
            s.set.project(3, |row, f| j21[(row, f)], &mut block);
            let up = ik.up.to_array();
            for c in 0..3 {
                predictions[3 * j + c] = up[c];
                for t in 0..k {
                    jacobian[(3 * j + c, t)] = block[c * k + t];
                }
            }
        }
        Ok(NominalLinearisation {
            predictions,
            jacobian,
        })
    }

    /// Number of readings (rows).
    pub fn rows(&self) -> usize {
        self.predictions.len()
    }
}

/// A differenced least-squares solve on a [`NominalLinearisation`]: the
/// readings of every pose minus those of `reference` (which removes the
/// sensors' zero offsets), rows weighted by [`RowWeights`], the parameters
/// `columns` estimated by `(H^T W H)^{-1} H^T W l`, every other parameter
/// held at zero.
#[derive(Debug, Clone)]
pub struct DifferencedSolve {
    /// Indices (into the scenario's set) of the parameters estimated.
    pub columns: Vec<usize>,
    /// The reference pose.
    pub reference: usize,
    /// `Op` (columns x 3 n): the estimate of `columns` is `Op (y - g_0)`.
    pub operator: DMatrix<f64>,
    /// Condition number of `H^T W H`.
    pub condition: f64,
}

/// What a differenced solve is, or why it cannot be formed.
#[derive(Debug, Clone)]
pub enum Differenced {
    /// `H^T W H` could be inverted.
    Formed(Box<DifferencedSolve>),
    /// `H^T W H` is singular to working precision (condition number given).
    Singular {
        /// Condition number of `H^T W H`.
        condition: f64,
    },
}

/// The weight matrix `W` of a differenced solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RowWeights {
    /// Every differenced row of sensor `c` (`phi`, `theta`, `s`) weighted
    /// by `w[c]`, the rows treated as independent. The paper: all 1.
    /// Differenced rows are not independent (each carries the reference
    /// pose's noise), so this loses information even with `w[c] = 1 /
    /// sigma_c^2`.
    PerSensor([f64; 3]),
    /// The inverse of the covariance the differencing gives readings of
    /// standard deviation `sigma` (`[phi, theta, s]`, rad, rad, mm): per
    /// sensor `sigma_c^2 (I + 1 1^T)` over its `n - 1` differenced rows,
    /// whose inverse is `(I - 1 1^T / n) / sigma_c^2`. This is the
    /// generalised least-squares solve, identical to estimating the three
    /// offsets with rows weighted by `1 / sigma^2`, whatever the reference
    /// pose.
    DifferencedCovariance([f64; 3]),
}

impl DifferencedSolve {
    /// Forms the solve of `columns` with the readings differenced against
    /// pose `reference`, the rows weighted by `weights`.
    ///
    /// # Example
    /// ```
    /// use tricept_kinematics::{description::AxisOrder, Machine};
    /// use tricept_study::Scenario;
    /// use tricept_study::paper::{Differenced, DifferencedSolve, NominalLinearisation, RowWeights};
    /// let m = Machine::paper().with_axis_order(AxisOrder::YFirst);
    /// let s = Scenario::paper(m.clone(), m.workspace.polar_grid(2, 8, 3)).unwrap();
    /// let lin = NominalLinearisation::new(&s).unwrap();
    /// let all: Vec<usize> = (0..15).collect();
    /// let paper = RowWeights::PerSensor([1.0; 3]);
    /// let Differenced::Formed(solve) = DifferencedSolve::form(&lin, &all, 0, paper).unwrap() else {
    ///     panic!("the y-first machine's 15 parameters are identifiable");
    /// };
    /// // Noise-free readings linear in the truth are solved exactly, offsets or not.
    /// let truth = s.set.table2();
    /// let y: Vec<f64> = (0..lin.rows())
    ///     .map(|r| lin.predictions[r] + (0..15).map(|t| lin.jacobian[(r, t)] * truth[t]).sum::<f64>() + [0.1, -0.2, 600.0][r % 3])
    ///     .collect();
    /// let p = solve.estimate(&lin, 15, &y).unwrap();
    /// assert!(p.iter().zip(&truth).all(|(a, b)| (a - b).abs() < 1e-6));
    ///
    /// // With the covariance of the differenced rows, the solve is the one
    /// // that estimates the offsets: the same operator for every reference.
    /// let gls = |reference| match DifferencedSolve::form(
    ///     &lin, &all, reference, RowWeights::DifferencedCovariance([4e-6, 4e-6, 3e-4]),
    /// ).unwrap() {
    ///     Differenced::Formed(d) => d.operator,
    ///     Differenced::Singular { .. } => panic!("identifiable"),
    /// };
    /// let (a, b) = (gls(0), gls(17));
    /// assert!((&a - &b).amax() <= 1e-8 * a.amax());
    /// ```
    pub fn form(
        lin: &NominalLinearisation,
        columns: &[usize],
        reference: usize,
        weights: RowWeights,
    ) -> Result<Differenced, StudyError> {
        let m = lin.rows();
        let n = m / 3;
        if reference >= n || n < 2 {
            return Err(StudyError::Invalid(format!(
                "reference pose {reference} of {n} poses"
            )));
        }
        if let Some(&bad) = columns.iter().find(|&&c| c >= lin.jacobian.ncols()) {
            return Err(StudyError::Invalid(format!(
                "parameter {bad} of {}",
                lin.jacobian.ncols()
            )));
        }
        let q = columns.len();
        // D: row (i, c) -> reading (j, c) - reading (reference, c), the
        // i-th pose j other than the reference.
        let others: Vec<usize> = (0..n).filter(|&j| j != reference).collect();
        let mut d = DMatrix::<f64>::zeros(m - 3, m);
        for (i, &j) in others.iter().enumerate() {
            for c in 0..3 {
                d[(3 * i + c, 3 * j + c)] = 1.0;
                d[(3 * i + c, 3 * reference + c)] = -1.0;
            }
        }
        let jac = DMatrix::from_fn(m, q, |r, t| lin.jacobian[(r, columns[t])]);
        let h = &d * jac;
        let wh = match weights {
            RowWeights::PerSensor(w) => DMatrix::from_fn(h.nrows(), q, |r, t| w[r % 3] * h[(r, t)]),
            RowWeights::DifferencedCovariance(sigma) => {
                // (I - 1 1^T / n) / sigma_c^2 on each sensor's rows.
                let mut sums = DMatrix::<f64>::zeros(3, q);
                for r in 0..h.nrows() {
                    for t in 0..q {
                        sums[(r % 3, t)] += h[(r, t)];
                    }
                }
                DMatrix::from_fn(h.nrows(), q, |r, t| {
                    let c = r % 3;
                    (h[(r, t)] - sums[(c, t)] / n as f64) / (sigma[c] * sigma[c])
                })
            }
        };
        let hth = h.transpose() * &wh;
        let sv = hth.singular_values();
        let (max, min) = (sv.max(), sv.min());
        let condition = if min > 0.0 { max / min } else { f64::INFINITY };
        let Some(inv) = hth.try_inverse() else {
            return Ok(Differenced::Singular { condition });
        };
        if !inv.iter().all(|v| v.is_finite()) || condition > 1.0 / f64::EPSILON {
            return Ok(Differenced::Singular { condition });
        }
        Ok(Differenced::Formed(Box::new(DifferencedSolve {
            columns: columns.to_vec(),
            reference,
            operator: inv * wh.transpose() * &d,
            condition,
        })))
    }

    /// The estimate (all `k` parameters of the set, zero where not
    /// estimated) from the readings `y` (`[phi, theta, s]` per pose, in the
    /// order of the linearisation's poses, offsets included). An error if
    /// `y` does not have one reading per row of `lin` and of the solve, or
    /// `k` does not cover the estimated parameters.
    pub fn estimate(
        &self,
        lin: &NominalLinearisation,
        k: usize,
        y: &[f64],
    ) -> Result<Vec<f64>, StudyError> {
        let m = lin.rows();
        if y.len() != m || self.operator.ncols() != m {
            return Err(StudyError::Invalid(format!(
                "{} readings for a solve of {} rows on a linearisation of {m}",
                y.len(),
                self.operator.ncols()
            )));
        }
        if let Some(&bad) = self.columns.iter().find(|&&c| c >= k) {
            return Err(StudyError::Invalid(format!("parameter {bad} of {k}")));
        }
        let mut p = vec![0.0; k];
        for (u, &col) in self.columns.iter().enumerate() {
            p[col] = (0..m)
                .map(|r| self.operator[(u, r)] * (y[r] - lin.predictions[r]))
                .sum();
        }
        Ok(p)
    }

    /// The solve as a [`LinearEstimator`] for readings with the logged noise
    /// `sigma` (`[phi, theta, s]`; a zero switches that sensor's noise off):
    /// `p*` is the estimate from the scenario's exact noise-free readings.
    pub fn estimator(
        &self,
        s: &Scenario,
        lin: &NominalLinearisation,
        sigma: [f64; 3],
    ) -> Result<LinearEstimator, StudyError> {
        let k = s.set.len();
        let y: Vec<f64> = s.clean.iter().flat_map(|p| p.readings.to_array()).collect();
        let p_star = self.estimate(lin, k, &y)?;
        let operator = Mat::from_fn(self.columns.len(), lin.rows(), |i, r| {
            self.operator[(i, r)] * sigma[r % 3]
        });
        let all: Vec<usize> = (0..k).collect();
        let g_all = plane_jacobian(s, &all)?;
        // dr0 = G (truth - p*); the runner subtracts G (p_hat - p*).
        let plane_clean: Vec<f64> = (0..g_all.nrows())
            .map(|row| {
                (0..k)
                    .map(|t| g_all[(row, t)] * (s.truth[t] - p_star[t]))
                    .sum()
            })
            .collect();
        let g = Mat::from_fn(g_all.nrows(), self.columns.len(), |row, u| {
            g_all[(row, self.columns[u])]
        });
        Ok(LinearEstimator::new(
            p_star,
            self.columns.clone(),
            operator,
            g,
            plane_clean,
        ))
    }
}

/// Builds the paper's estimator for an encoder of `grade_arcsec`.
pub fn paper_solve(s: &Scenario, grade_arcsec: f64) -> Result<PaperSolve, StudyError> {
    paper_solve_with_sigma(s, s.logged_sigma(grade_arcsec))
}

/// The paper's estimator for readings with the logged noise `sigma`
/// (`[phi, theta, s]`; a zero switches that sensor's noise off, which
/// splits the solve's error into its sources).
pub fn paper_solve_with_sigma(s: &Scenario, sigma: [f64; 3]) -> Result<PaperSolve, StudyError> {
    let lin = NominalLinearisation::new(s)?;
    let all: Vec<usize> = (0..s.set.len()).collect();
    Ok(
        match DifferencedSolve::form(&lin, &all, 0, RowWeights::PerSensor([1.0; 3]))? {
            Differenced::Formed(solve) => PaperSolve::Formed {
                estimator: Box::new(solve.estimator(s, &lin, sigma)?),
                condition: solve.condition,
            },
            Differenced::Singular { condition } => PaperSolve::Singular { condition },
        },
    )
}
