//! A Gaussian prior on a model's parameters: what a batch of machines says
//! about a new one before its own readings are seen (`docs/fleet.md`).
//!
//! A prior `N(m, P)` on some of the parameters enters a fit as rows of
//! pseudo-observations `L^-1 (p - m) = 0` (`L L^T = P`) appended to every
//! evaluation's reduced problem: the fit is then the maximum a posteriori
//! estimate on the exact model, its covariance the posterior's, the rank
//! decision taken on readings and prior together (a combination the prior
//! covers is estimated even when the readings alone cannot see it; one
//! neither sees is held as before), and the chi-square and its degrees of
//! freedom count the prior's rows too (the fit's adequacy test then also
//! asks whether the machine belongs to the prior's batch;
//! [`PriorFit`] keeps that part apart).

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::error::IdentError;

/// A Gaussian prior on some of a model's `k` parameters.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use nalgebra::DMatrix;
use tricept_engine::prior::Prior;
// Parameters 0 and 2 of three: N([0.1, 0.3], diag(0.01, 0.04)); parameter 1 free.
let p = Prior::new(vec![0.1, 0.0, 0.3], &[0, 2], &DMatrix::from_row_slice(2, 2, &[0.01, 0.0, 0.0, 0.04])).unwrap();
assert_eq!(p.dimension(), 2);
// (0.2 - 0.1)^2 / 0.01 + (0.1 - 0.3)^2 / 0.04 = 1 + 1.
assert!((p.chi_square(&[0.2, 5.0, 0.1]) - 2.0).abs() < 1e-12);
```
"#
)]
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    mean: Vec<f64>,
    /// `r x k`: `rows (p - mean)` is standard normal under the prior.
    rows: DMatrix<f64>,
}

/// The prior's share of a fit: its chi-square at the estimate and its
/// degrees of freedom (the parameters it covers).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PriorFit {
    /// `(p - m)^T P^-1 (p - m)` at the estimate.
    pub chi_square: f64,
    /// The number of parameters the prior covers.
    pub dof: usize,
}

impl Prior {
    /// The prior with `mean` (all `k` parameters; those not covered are
    /// ignored) and `covariance` of the parameters `covers` (in that
    /// order); the covariance must be symmetric positive definite.
    pub fn new(
        mean: Vec<f64>,
        covers: &[usize],
        covariance: &DMatrix<f64>,
    ) -> Result<Prior, IdentError> {
        let k = mean.len();
        let c = covers.len();
        if covariance.shape() != (c, c) || covers.iter().any(|&j| j >= k) {
            return Err(IdentError::Invalid(format!(
                "a prior covariance of {:?} over parameters {covers:?} of {k}",
                covariance.shape()
            )));
        }
        let mut sorted = covers.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() != c {
            return Err(IdentError::Invalid(format!(
                "a prior names a parameter twice: {covers:?}"
            )));
        }
        if mean.iter().chain(covariance.iter()).any(|v| !v.is_finite()) {
            return Err(IdentError::Invalid(
                "a prior with a non-finite value".into(),
            ));
        }
        let symmetric = (covariance - covariance.transpose()).amax()
            <= 1e-12 * covariance.amax().max(f64::MIN_POSITIVE);
        let cholesky = covariance
            .clone()
            .cholesky()
            .filter(|_| symmetric)
            .ok_or_else(|| {
                IdentError::Invalid(
                    "the prior covariance is not symmetric positive definite".into(),
                )
            })?;
        let inverse_root = cholesky
            .l()
            .solve_lower_triangular(&DMatrix::identity(c, c))
            .ok_or(IdentError::Numerical(
                "the prior covariance's factor is singular",
            ))?;
        let mut rows = DMatrix::zeros(c, k);
        for (a, &j) in covers.iter().enumerate() {
            for r in 0..c {
                rows[(r, j)] = inverse_root[(r, a)];
            }
        }
        Ok(Prior { mean, rows })
    }

    /// The number of parameters it covers (its rows).
    pub fn dimension(&self) -> usize {
        self.rows.nrows()
    }

    /// The number of parameters of the model it belongs to.
    pub fn parameters(&self) -> usize {
        self.mean.len()
    }

    /// The prior mean (every parameter; those not covered as given).
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// `(p - m)^T P^-1 (p - m)` over the covered parameters.
    pub fn chi_square(&self, p: &[f64]) -> f64 {
        let d = DVector::from_fn(self.mean.len(), |i, _| {
            p.get(i).copied().unwrap_or(f64::NAN) - self.mean[i]
        });
        (&self.rows * d).norm_squared()
    }

    /// The same prior on a model with `extra` more parameters after these
    /// (a diagnosis' terms): they are not covered.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use nalgebra::DMatrix;
let p = tricept_engine::prior::Prior::new(vec![1.0], &[0], &DMatrix::from_element(1, 1, 4.0)).unwrap();
let wider = p.padded(2);
assert_eq!((wider.parameters(), wider.dimension()), (3, 1));
assert!((wider.chi_square(&[3.0, 7.0, 8.0]) - 1.0).abs() < 1e-12);
```
"#
    )]
    pub fn padded(&self, extra: usize) -> Prior {
        let k = self.mean.len();
        let mut mean = self.mean.clone();
        mean.resize(k + extra, 0.0);
        let rows = DMatrix::from_fn(self.rows.nrows(), k + extra, |r, j| {
            if j < k { self.rows[(r, j)] } else { 0.0 }
        });
        Prior { mean, rows }
    }

    /// The prior's rows for a reduced problem `[nuisance | parameters |
    /// rhs]` of `n_nuisance` nuisance columns at parameters `p`: the step
    /// `d` from `p` should satisfy `rows d = rows (m - p)`.
    pub(crate) fn problem_rows(&self, n_nuisance: usize, p: &[f64]) -> Vec<Vec<f64>> {
        let k = self.mean.len();
        (0..self.rows.nrows())
            .map(|r| {
                let mut row = vec![0.0; n_nuisance + k + 1];
                for j in 0..k {
                    row[n_nuisance + j] = self.rows[(r, j)];
                }
                row[n_nuisance + k] = (0..k)
                    .map(|j| self.rows[(r, j)] * (self.mean[j] - p[j]))
                    .sum();
                row
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_covariance_that_is_not_positive_definite_or_of_the_wrong_size_is_refused() {
        let bad = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(Prior::new(vec![0.0; 2], &[0, 1], &bad).is_err());
        let asym = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]);
        assert!(Prior::new(vec![0.0; 2], &[0, 1], &asym).is_err());
        assert!(Prior::new(vec![0.0; 2], &[0, 2], &DMatrix::identity(2, 2)).is_err());
        assert!(Prior::new(vec![0.0; 2], &[1, 1], &DMatrix::identity(2, 2)).is_err());
    }

    #[test]
    fn the_rows_whiten_a_correlated_prior() {
        // P = [[4, 2], [2, 3]]: rows^T rows = P^-1.
        let p = DMatrix::from_row_slice(2, 2, &[4.0, 2.0, 2.0, 3.0]);
        let prior = Prior::new(vec![0.0; 3], &[2, 0], &p).unwrap();
        let info = prior.rows.transpose() * &prior.rows;
        let inv = p.try_inverse().unwrap();
        for (a, ja) in [(0, 2), (1, 0)] {
            for (b, jb) in [(0, 2), (1, 0)] {
                assert!((info[(ja, jb)] - inv[(a, b)]).abs() < 1e-12);
            }
        }
        assert_eq!(info.column(1).amax(), 0.0);
    }
}
