//! The parts a check's report is made of, and the fits they come from:
//! a chi-square test ([`ChiSquare`]), what the check says of one candidate
//! ([`CandidateResult`]), a reading set aside ([`Rejected`]); the fit of a
//! subset of a candidate's columns on the check's normal equations and
//! what a change does to the platform. The lowest layer of the crate:
//! `check.rs`, `changes.rs`, `noise.rs` and `screen.rs` all build on it.

use nalgebra::{DMatrix, DVector, Vector3};
use serde::Serialize;
use tricept_kinematics::Machine;
use tricept_model::jacobian::position_error_jacobian;
use tricept_numerics::stats::{chi2_isf, chi2_ln_sf, chi2_sf};

use crate::candidates::{Candidate, CandidateKind};
use crate::error::CheckError;

/// Candidates whose p-value is within this factor of the best's explain
/// the readings about as well (a likelihood ratio of 20, "strong evidence"
/// on the usual scales, separates them).
pub(crate) const SHORTLIST_RATIO: f64 = 20.0;

/// A chi-square test: statistic, degrees of freedom, p-value and the
/// critical value it was compared with.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChiSquare {
    /// The statistic.
    pub statistic: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// `P(chi2_dof > statistic)`.
    pub p_value: f64,
    /// Its natural logarithm, finite where the p-value underflows: how
    /// candidates with very strong evidence are ranked.
    pub ln_p_value: f64,
    /// The critical value of the test.
    pub critical: f64,
}

/// What the check says of one candidate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateResult {
    /// `leg 1`, `base joint B2`, ...
    pub name: String,
    /// Its kind.
    pub kind: CandidateKind,
    /// Parameter names with their units.
    pub parameters: Vec<String>,
    /// How many of the parameters (the leading ones) the reported change
    /// fits: a leg's length alone for a slip, its shapes too for a worn
    /// segment.
    pub fitted: usize,
    /// Estimated change of each parameter (in its unit; 0 for a parameter
    /// not fitted or a component the campaign does not see).
    pub estimate: Vec<f64>,
    /// Standard deviation of each (`None` for a component not seen).
    pub std_dev: Vec<Option<f64>>,
    /// The likelihood-ratio test of the change.
    pub test: ChiSquare,
    /// The test passed at the family-wise level.
    pub significant: bool,
    /// The change of each parameter alone that the check detects with the
    /// stated power at the family-wise level (`None`: not seen).
    pub detectable: Vec<Option<f64>>,
    /// Each parameter fitted alone: its estimate and standard deviation
    /// (what a history follows from check to check).
    pub alone: Vec<Option<(f64, f64)>>,
    /// The change of each parameter alone beyond which the check flags it
    /// (its standard deviation alone times the family-wise critical value:
    /// the band of a history's trend).
    pub flagged_beyond: Vec<Option<f64>>,
    /// Mean and largest platform error over the evaluation points that the
    /// estimated change causes, um (0 for a sensor).
    pub platform_mean_um: f64,
    /// See `platform_mean_um`.
    pub platform_max_um: f64,
}

impl CandidateResult {
    /// True when no component of the candidate is seen.
    pub(crate) fn moves_nothing_seen(&self) -> bool {
        self.detectable.iter().all(Option::is_none)
    }
}

/// The test of a statistic at `tail`.
pub(crate) fn chi_square(statistic: f64, dof: usize, tail: f64) -> ChiSquare {
    let k = dof.max(1) as f64;
    ChiSquare {
        statistic,
        dof,
        p_value: if dof > 0 { chi2_sf(statistic, k) } else { 1.0 },
        ln_p_value: if dof > 0 {
            chi2_ln_sf(statistic, k)
        } else {
            0.0
        },
        critical: if dof > 0 {
            chi2_isf(tail, k)
        } else {
            f64::INFINITY
        },
    }
}

/// The likelihood-ratio fit of the first `n` columns `idx[..n]` of a
/// candidate: statistic, degrees of freedom, estimate and standard
/// deviation of each of them (`None`: a direction the campaign does not
/// see, dropped by the size of its eigenvalue rather than inverted).
pub(crate) struct SubFit {
    pub(crate) statistic: f64,
    pub(crate) dof: usize,
    pub(crate) estimate: Vec<f64>,
    pub(crate) std_dev: Vec<Option<f64>>,
}

/// The inverse of the symmetric, unit-diagonal-scaled matrix `s` on the
/// directions it determines (eigenvalues above 1e-10 times the largest;
/// the others are left out, not inverted), and how many those are.
pub(crate) fn seen_inverse(s: DMatrix<f64>) -> (DMatrix<f64>, usize) {
    let q = s.nrows();
    let eig = s.symmetric_eigen();
    let emax = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
    let mut inv = DMatrix::zeros(q, q);
    let mut rank = 0;
    for e in 0..q {
        let l = eig.eigenvalues[e];
        if l > 1e-10 * emax {
            let u = eig.eigenvectors.column(e);
            inv += u * u.transpose() / l;
            rank += 1;
        }
    }
    (inv, rank)
}

pub(crate) fn fit_columns(idx: &[usize], limits: &[f64], gram: &DMatrix<f64>, r: usize) -> SubFit {
    let n = idx.len();
    // Scaled to unit diagonal, so that the rank tolerance is relative.
    let scale: Vec<f64> = idx.iter().map(|&i| gram[(i, i)].max(0.0).sqrt()).collect();
    let top = scale.iter().copied().fold(0.0, f64::max);
    // A parameter whose change the campaign sees, alone, no better than
    // to its unseen limit (the manufacturing tolerance for a length) is
    // not seen: fitting it would only pass its noise on to the others.
    let kept: Vec<usize> = (0..n)
        .filter(|&a| scale[a] > 0.0 && scale[a] > 1e-9 * top && 1.0 / scale[a] < limits[a])
        .collect();
    let mut fit = SubFit {
        statistic: 0.0,
        dof: 0,
        estimate: vec![0.0; n],
        std_dev: vec![None; n],
    };
    if kept.is_empty() {
        return fit;
    }
    let q = kept.len();
    let s = DMatrix::from_fn(q, q, |a, b| {
        gram[(idx[kept[a]], idx[kept[b]])] / (scale[kept[a]] * scale[kept[b]])
    });
    let (inv, rank) = seen_inverse(s);
    fit.dof = rank;
    let gs = DVector::from_fn(q, |a, _| gram[(idx[kept[a]], r)] / scale[kept[a]]);
    let x = &inv * &gs;
    fit.statistic = gs.dot(&x);
    for (a, &i) in kept.iter().enumerate() {
        fit.estimate[i] = x[a] / scale[i];
        let v = inv[(a, a)];
        fit.std_dev[i] = (v > 0.0).then(|| v.sqrt() / scale[i]);
    }
    fit
}

/// The standard deviation (in the parameter's unit) beyond which a
/// candidate's parameter counts as not seen: the class-1 tolerance of
/// 0.25 mm for a length, 1000 ppm for a gain or lead, 250 um for a leg's
/// shape, 100 ppm/K for an expansion.
pub(crate) fn unseen_limit(parameter: &str) -> f64 {
    if parameter.ends_with("_mm") {
        0.25
    } else if parameter.ends_with("_um") {
        250.0
    } else if parameter.ends_with("_ppm_per_k") {
        100.0
    } else {
        1000.0
    }
}

/// The platform point's Jacobian at each evaluation target of the
/// calibrated machine, with the commands that reach it.
pub(crate) struct Impact {
    at: Vec<(
        tricept_model::jacobian::ErrorJacobian,
        Vector3<f64>,
        [f64; 3],
    )>,
}

impl Impact {
    pub(crate) fn new(machine: &Machine, points: &[Vector3<f64>]) -> Result<Impact, CheckError> {
        let at = points
            .iter()
            .enumerate()
            .map(|(j, r)| {
                let e = |source| CheckError::Kinematics {
                    pose: j + 1,
                    line: 0,
                    source,
                };
                let ik = machine.inverse(r).map_err(e)?;
                let p21 = position_error_jacobian(&machine.legs_at(&ik.up)).map_err(e)?;
                Ok((p21, *r, ik.legs_mm))
            })
            .collect::<Result<_, CheckError>>()?;
        Ok(Impact { at })
    }

    /// Mean and largest platform error (um) of a change `value`.
    pub(crate) fn of(&self, cand: &Candidate, value: &[f64], temp_c: Option<f64>) -> (f64, f64) {
        let e: Vec<f64> = self
            .at
            .iter()
            .map(|(p21, r, q)| cand.platform_error(p21, r, q, temp_c, value).norm() * 1e3)
            .collect();
        let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
        (mean, e.iter().copied().fold(0.0, f64::max))
    }
}

/// A pose set aside as a gross reading (the keys of `identify`'s
/// `rejected`, with the reading that is off).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rejected {
    /// 1-based number of the pose in the data.
    pub pose: usize,
    /// Its line in the data file.
    pub line: u64,
    /// Its deleted residual in noise standard deviations (`sqrt(T_j)`,
    /// studentised).
    pub residual_sigma: f64,
    /// The data column whose reading is off the most: `phi`, `theta` or
    /// `s`.
    pub column: &'static str,
    /// That reading less what the other poses predict for it, in `unit`.
    pub residual: f64,
    /// `arcsec` or `um`.
    pub unit: &'static str,
}

#[cfg(test)]
mod tests {
    //! The parts' arithmetic against values worked by hand: a test of no
    //! degrees of freedom, and the fit of a diagonal Gram matrix (each
    //! column its own least squares: estimate `g_ir / g_ii`, statistic
    //! `g_ir^2 / g_ii`, standard deviation `1 / sqrt(g_ii)`).
    use super::*;

    #[test]
    fn a_test_of_no_degrees_of_freedom_never_rejects() {
        // Nothing is left to test: whatever the statistic, p = 1 and the
        // critical value is infinite.
        for statistic in [0.0, 2.5, 40.0] {
            let t = chi_square(statistic, 0, 0.005);
            assert_eq!(t.p_value, 1.0, "{statistic}");
            assert_eq!(t.ln_p_value, 0.0, "{statistic}");
            assert_eq!(t.critical, f64::INFINITY, "{statistic}");
        }
        // One degree of freedom: p = erfc(sqrt(x / 2)); at x = 4,
        // erfc(sqrt 2) = 0.0455003 (tables).
        let t = chi_square(4.0, 1, 0.005);
        assert!((t.p_value - 0.045_500_26).abs() < 1e-7, "{}", t.p_value);
    }

    #[test]
    fn a_matrix_that_determines_no_direction_inverts_to_nothing() {
        let (inv, rank) = seen_inverse(DMatrix::zeros(2, 2));
        assert_eq!(rank, 0);
        assert_eq!(inv, DMatrix::zeros(2, 2));
        // diag(4, 1): both seen, inverse diag(1/4, 1).
        let (inv, rank) = seen_inverse(DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 1.0])));
        assert_eq!(rank, 2);
        assert!((inv[(0, 0)] - 0.25).abs() < 1e-15 && (inv[(1, 1)] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_parameter_seen_no_better_than_its_limit_is_left_out() {
        // Two parameters with uncorrelated columns: the first seen to
        // 1 / sqrt(100) = 0.1 mm (under its 0.25 mm limit), the second to
        // 1 / sqrt(4) = 0.5 mm (beyond it). Residual column r = 2.
        let gram = DMatrix::from_row_slice(
            3,
            3,
            &[
                100.0, 0.0, 30.0, //
                0.0, 4.0, 6.0, //
                30.0, 6.0, 50.0,
            ],
        );
        let fit = fit_columns(&[0, 1], &[0.25, 0.25], &gram, 2);
        assert_eq!(fit.dof, 1);
        assert!((fit.statistic - 9.0).abs() < 1e-12, "{}", fit.statistic);
        assert!((fit.estimate[0] - 0.3).abs() < 1e-12, "{:?}", fit.estimate);
        assert_eq!(fit.estimate[1], 0.0);
        assert!((fit.std_dev[0].unwrap_or(f64::NAN) - 0.1).abs() < 1e-12);
        assert_eq!(fit.std_dev[1], None);
        // With a limit of 1 mm the second is seen too: 9 + 6^2 / 4.
        let fit = fit_columns(&[0, 1], &[0.25, 1.0], &gram, 2);
        assert_eq!(fit.dof, 2);
        assert!((fit.statistic - 18.0).abs() < 1e-12, "{}", fit.statistic);
        assert!((fit.estimate[1] - 1.5).abs() < 1e-12, "{:?}", fit.estimate);
        // A column seen more than 1e9 times worse than the best is left out
        // whatever its limit (the rank tolerance is relative): scales 1e10
        // and 0.1 (seen to 10 ppm, under a 1000 ppm limit).
        let gram = DMatrix::from_row_slice(
            3,
            3,
            &[
                1e20, 0.0, 1e10, //
                0.0, 0.01, 0.02, //
                1e10, 0.02, 50.0,
            ],
        );
        let fit = fit_columns(&[0, 1], &[1000.0, 1000.0], &gram, 2);
        assert_eq!(fit.dof, 1);
        assert_eq!(fit.std_dev[1], None);
        assert!((fit.statistic - 1.0).abs() < 1e-12, "{}", fit.statistic);
    }
}
