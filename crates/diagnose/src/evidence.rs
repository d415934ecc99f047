//! The reference distribution of every test of the diagnosis.
//!
//! With the stated sensor noise, a drop of chi-square `X` for `k` added
//! parameters is chi-square with `k` degrees of freedom under the null. When
//! the noise is estimated from repeated poses (`--noise-from-data`) with `nu`
//! degrees of freedom of pure error, the same statistic divided by `k` is
//! `F(k, nu)`. In both cases a statistic is first divided by the residual
//! variance the larger model leaves, never below the stated (or estimated)
//! noise (`s2 = max(1, chi2 / dof)`): a misfit the model does not explain
//! makes every test more cautious, never less.

use tricept_numerics::stats::{chi2_sf, f_sf};

/// How statistics are referred to a distribution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Reference {
    /// Degrees of freedom of the pure error when the noise is estimated
    /// from the data; `None` with the stated noise.
    pub(crate) pure_error_dof: Option<f64>,
}

impl Reference {
    /// The stated noise.
    pub(crate) fn stated() -> Reference {
        Reference {
            pure_error_dof: None,
        }
    }

    /// The residual variance factor `max(1, chi2 / dof)` of a model.
    pub(crate) fn scale(&self, chi_square: f64, dof: usize) -> f64 {
        if dof == 0 {
            return 1.0;
        }
        (chi_square / dof as f64).max(1.0)
    }

    /// p-value of a (scaled) drop of chi-square `x` for `k` parameters.
    pub(crate) fn p_value(&self, x: f64, k: usize) -> f64 {
        let k = k.max(1) as f64;
        match self.pure_error_dof {
            None => chi2_sf(x.max(0.0), k),
            Some(nu) => f_sf(x.max(0.0) / k, k, nu),
        }
    }

    /// p-value of a model's chi-square `chi_square` for `dof` degrees of
    /// freedom (the adequacy test): chi-square against the stated noise;
    /// with pure error `SS = nu` (the noise is scaled to it), the classical
    /// lack-of-fit test `F = ((chi2 - nu) / (dof - nu)) / 1 ~ F(dof - nu, nu)`.
    pub(crate) fn adequacy_p_value(&self, chi_square: f64, dof: usize) -> f64 {
        match self.pure_error_dof {
            None => chi2_sf(chi_square, dof as f64),
            Some(nu) => {
                let lack = dof as f64 - nu;
                if lack < 1.0 {
                    chi2_sf(chi_square, dof as f64)
                } else {
                    f_sf((chi_square - nu).max(0.0) / lack, lack, nu)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stated_and_estimated_noise() {
        let stated = Reference::stated();
        assert!((stated.p_value(3.841_458_820_694_124, 1) - 0.05).abs() < 1e-9);
        assert_eq!(stated.scale(50.0, 100), 1.0);
        assert_eq!(stated.scale(300.0, 100), 3.0);
        // With 20 dof of pure error the same drop is less significant.
        let data = Reference {
            pure_error_dof: Some(20.0),
        };
        assert!(data.p_value(10.0, 1) > stated.p_value(10.0, 1));
        // Lack of fit: a chi-square at its expectation passes.
        assert!(data.adequacy_p_value(200.0, 200) > 0.1);
        assert!(data.adequacy_p_value(1000.0, 200) < 1e-3);
    }
}
