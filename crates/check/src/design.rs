//! The check's whitened design, kept row by row, for what needs the
//! readings one by one: the noise a campaign shows per channel
//! (`noise.rs`) and the deleted residual of each pose (`screen.rs`).
//!
//! A row of a pose's channel is `[offsets (3) | prior directions |
//! candidates | residual]`, whitened by the stated noise, in pose order
//! (three rows per pose); the prior adds one pseudo-observation
//! `eta_t / sqrt(lambda_t)` per direction the calibration determined. A fit
//! on the nuisance columns (offsets and prior) and some candidate columns
//! is the check's own augmented least-squares problem restricted to them:
//! with no candidate column its misfit is the consistency statistic `T0`.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::parts::{CandidateResult, seen_inverse};

/// The whitened rows of a check (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct Design {
    /// Row-major data rows, `width` values each.
    rows: Vec<f64>,
    width: usize,
    /// `1 / sqrt(lambda_t)` of each prior direction.
    prior_weights: Vec<f64>,
}

/// A least-squares fit on a [`Design`]'s nuisance columns and some
/// candidate columns.
#[derive(Debug, Clone)]
pub(crate) struct DesignFit {
    /// Residual of each data row (whitened).
    pub residual: Vec<f64>,
    /// Diagonal of the hat matrix of each data row.
    pub leverage: Vec<f64>,
    /// The 3 x 3 hat block of each pose.
    pub hat: Vec<Matrix3<f64>>,
    /// The misfit: the residuals' and the prior rows' squares.
    pub misfit: f64,
    /// Its degrees of freedom: data rows less the offsets and the fitted
    /// candidate columns (the prior's own rows count for their directions).
    pub dof: usize,
}

impl Design {
    /// An empty design of rows `width` wide with `prior_weights.len()`
    /// prior directions.
    pub(crate) fn new(width: usize, prior_weights: Vec<f64>) -> Design {
        Design {
            rows: Vec::new(),
            width,
            prior_weights,
        }
    }

    /// Appends one data row (`width` values).
    pub(crate) fn push(&mut self, row: &[f64]) {
        self.rows.extend_from_slice(&row[..self.width]);
    }

    /// Number of poses (three data rows each).
    pub(crate) fn poses(&self) -> usize {
        self.rows.len() / self.width / 3
    }

    /// The number of prior directions.
    pub(crate) fn n_prior(&self) -> usize {
        self.prior_weights.len()
    }

    /// The least-squares fit of the residual column on the nuisance
    /// columns and `candidate` columns (indices counted from the first
    /// candidate column). Directions of the normal matrix below `1e-10` of
    /// its largest eigenvalue (columns scaled to unit norm) are not fitted.
    pub(crate) fn fit(&self, candidate: &[usize]) -> DesignFit {
        let na = 3 + self.n_prior();
        let cols: Vec<usize> = (0..na).chain(candidate.iter().map(|&i| na + i)).collect();
        let q = cols.len();
        let m = self.rows.len() / self.width;
        let r_col = self.width - 1;
        let at = |row: usize, col: usize| self.rows[row * self.width + col];
        let x = DMatrix::from_fn(m, q, |i, j| at(i, cols[j]));
        let b = DVector::from_fn(m, |i, _| at(i, r_col));
        // Normal equations with the prior rows (they touch the prior
        // columns only, with a zero right-hand side).
        let mut normal = x.transpose() * &x;
        for (t, w) in self.prior_weights.iter().enumerate() {
            normal[(3 + t, 3 + t)] += w * w;
        }
        let rhs = x.transpose() * &b;
        let scale = DVector::from_fn(q, |j, _| {
            let d = normal[(j, j)];
            if d > 0.0 { 1.0 / d.sqrt() } else { 0.0 }
        });
        let scaled = DMatrix::from_fn(q, q, |i, j| normal[(i, j)] * scale[i] * scale[j]);
        let (inv, _) = seen_inverse(scaled);
        let cov = DMatrix::from_fn(q, q, |i, j| inv[(i, j)] * scale[i] * scale[j]);
        let beta = &cov * rhs;
        let residual: Vec<f64> = (b - &x * &beta).iter().copied().collect();
        let xc = &x * &cov;
        let leverage: Vec<f64> = (0..m).map(|i| xc.row(i).dot(&x.row(i))).collect();
        let hat = (0..m / 3)
            .map(|j| Matrix3::from_fn(|a, c| xc.row(3 * j + a).dot(&x.row(3 * j + c))))
            .collect();
        let prior_misfit: f64 = self
            .prior_weights
            .iter()
            .enumerate()
            .map(|(t, w)| (w * beta[3 + t]).powi(2))
            .sum();
        DesignFit {
            misfit: residual.iter().map(|e| e * e).sum::<f64>() + prior_misfit,
            dof: m.saturating_sub(3 + candidate.len()),
            residual,
            leverage,
            hat,
        }
    }
}

impl DesignFit {
    /// Pose `j`'s residual (whitened, three channels).
    pub(crate) fn pose_residual(&self, j: usize) -> Vector3<f64> {
        Vector3::from_fn(|c, _| self.residual[3 * j + c])
    }
}

/// The candidate columns (counted from the first candidate column) of the
/// change `best` of `results` names: its fitted parameters the campaign
/// sees; none without a change.
pub(crate) fn change_columns(results: &[CandidateResult], best: Option<usize>) -> Vec<usize> {
    let Some(b) = best else {
        return Vec::new();
    };
    let start: usize = results[..b].iter().map(|c| c.parameters.len()).sum();
    let c = &results[b];
    (0..c.fitted.min(c.std_dev.len()))
        .filter(|&t| c.std_dev[t].is_some())
        .map(|t| start + t)
        .collect()
}

#[cfg(test)]
mod tests {
    //! The design's fit against sums worked by hand.
    use super::*;

    #[test]
    fn a_column_no_reading_sees_is_not_fitted() {
        // Two poses, each channel's offset column one-hot, one candidate
        // column of zeros, residual column last. The fit is the channel
        // means (2, 2, 2): residuals -1, 0, 1, 1, 0, -1, misfit 4, each
        // row's leverage 1/2 (two rows per offset); the zero column adds
        // nothing and no NaN.
        let mut design = Design::new(5, Vec::new());
        for (channel, value) in [(0, 1.0), (1, 2.0), (2, 3.0), (0, 3.0), (1, 2.0), (2, 1.0)] {
            let mut row = [0.0; 5];
            row[channel] = 1.0;
            row[4] = value;
            design.push(&row);
        }
        let fit = design.fit(&[0]);
        let expected = [-1.0, 0.0, 1.0, 1.0, 0.0, -1.0];
        for (got, want) in fit.residual.iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{:?}", fit.residual);
        }
        assert!((fit.misfit - 4.0).abs() < 1e-12, "{}", fit.misfit);
        assert!(
            fit.leverage.iter().all(|h| (h - 0.5).abs() < 1e-12),
            "{:?}",
            fit.leverage
        );
        assert_eq!(fit.dof, 2);
    }
}
