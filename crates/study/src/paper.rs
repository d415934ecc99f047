//! The paper's own solve, for comparison: readings differenced against the
//! first pose (eq. 10), the nominal Jacobian, no weighting (radians and
//! millimetres mixed as they come), and `deps = (H^T H)^{-1} H^T l` with an
//! explicit inverse (eq. 12).
//!
//! It is linear in the readings, so it runs as a [`LinearEstimator`]
//! through the same fast Monte Carlo as ours: `p_hat = Op (y_clean - g_0) +
//! Op diag(sigma) z`, with `Op = (H^T H)^{-1} H^T D` and `D` the
//! differencing. The compensated plane error is first order throughout:
//! `dr = G (truth - p_hat)`.

use faer::Mat;
use nalgebra::DMatrix;
use tricept_model::error_jacobian;

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

/// Builds the paper's estimator for an encoder of `grade_arcsec`.
pub fn paper_solve(s: &Scenario, grade_arcsec: f64) -> Result<PaperSolve, StudyError> {
    let k = s.set.len();
    let n = s.clean.len();
    let m = 3 * n;
    // Nominal predictions and Jacobians at the commanded poses.
    let mut g0 = vec![0.0; m];
    let mut jac = DMatrix::<f64>::zeros(m, k);
    let mut block = vec![0.0; 3 * k];
    for (j, r) in s.targets_mm.iter().enumerate() {
        let ik = s.nominal.inverse(r)?;
        let j21 = error_jacobian(&s.nominal, &ik.up)?;
        s.set.project(3, |row, f| j21[(row, f)], &mut block);
        let up = ik.up.to_array();
        for c in 0..3 {
            g0[3 * j + c] = up[c];
            for t in 0..k {
                jac[(3 * j + c, t)] = block[c * k + t];
            }
        }
    }
    // H = D J, D: row (j, c) -> reading (j, c) - reading (0, c), j >= 1.
    let mut d = DMatrix::<f64>::zeros(m - 3, m);
    for j in 1..n {
        for c in 0..3 {
            d[(3 * (j - 1) + c, 3 * j + c)] = 1.0;
            d[(3 * (j - 1) + c, c)] = -1.0;
        }
    }
    let h = &d * &jac;
    let hth = h.transpose() * &h;
    let sv = hth.singular_values();
    let max = sv.max();
    let min = sv.min();
    let condition = if min > 0.0 { max / min } else { f64::INFINITY };
    let Some(inv) = hth.clone().try_inverse() else {
        return Ok(PaperSolve::Singular { condition });
    };
    if !inv.iter().all(|v| v.is_finite()) || condition > 1.0 / f64::EPSILON {
        return Ok(PaperSolve::Singular { condition });
    }
    let op = inv * h.transpose() * &d; // k x m
    let l: Vec<f64> = s
        .clean
        .iter()
        .flat_map(|p| p.readings.to_array())
        .zip(&g0)
        .map(|(y, g)| y - g)
        .collect();
    let p_star: Vec<f64> = (0..k)
        .map(|i| (0..m).map(|r| op[(i, r)] * l[r]).sum())
        .collect();
    let sigma = s.logged_sigma(grade_arcsec);
    let operator = Mat::from_fn(k, m, |i, r| op[(i, r)] * sigma[r % 3]);
    let columns: Vec<usize> = (0..k).collect();
    let g = plane_jacobian(s, &columns)?;
    // dr0 = G (truth - p*); the runner subtracts G (p_hat - p*).
    let plane_clean: Vec<f64> = (0..g.nrows())
        .map(|row| (0..k).map(|t| g[(row, t)] * (s.truth[t] - p_star[t])).sum())
        .collect();
    Ok(PaperSolve::Formed {
        estimator: Box::new(LinearEstimator::new(
            p_star,
            columns,
            operator,
            g,
            plane_clean,
        )),
        condition,
    })
}
