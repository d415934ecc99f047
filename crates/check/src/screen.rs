//! Bad readings are screened: a gross reading is set aside, named by its
//! line, and the verdict comes from the rest.
//!
//! A gross reading (a misread scale, an encoder glitch) shows only in the
//! residuals of a fit, so the screen works after the check, as `identify`'s
//! does after its fit (`tricept_engine::robust::screen_gross_errors`): at the fit
//! the verdict rests on (the offsets and the calibration's uncertainty,
//! with the most likely change when there is one), every pose gets the
//! statistic of its deleted (leave-one-pose-out) residual,
//! `T_j = e_j^T (I - H_jj)^-1 e_j`, externally studentised by the scatter
//! of the other poses (never below the stated noise). The worst pose above
//! the Bonferroni criterion `chi2_3(1 - SCREEN_ALPHA / n)` is set aside and
//! the check is repeated on the rest, until no pose stands out.
//!
//! A change moves many readings consistently: once its candidate is
//! fitted its readings fit, so the screen does not eat it; and as a change
//! the check has not yet named inflates the other poses' scatter, a single
//! gross reading stands out above it. At most [`MAX_SET_ASIDE_SHARE`] of
//! the poses (at least one) are set aside: when more stand out it is not a
//! matter of gross readings, and the check of every pose is reported, as
//! it was, with a warning.

use nalgebra::Matrix3;
use tricept_data::Dataset;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_numerics::stats::chi2_isf;

use crate::check::{CheckOptions, CheckReport, evaluate};
use crate::design::{Design, change_columns};
use crate::error::CheckError;
use crate::parts::Rejected;
use crate::reference::Reference;

/// Family-wise level of the screen over the poses (as `identify`'s).
pub const SCREEN_ALPHA: f64 = 1e-3;

/// The largest share of a campaign's poses the screen sets aside (at least
/// one pose).
pub const MAX_SET_ASIDE_SHARE: f64 = 0.1;

/// Checks `data` against `reference` (see the module docs).
///
/// # Example
/// ```
/// use tricept_check::{CheckOptions, CheckVerdict, Reference, check};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// // A perfectly known machine; a check of 20 random poses on it.
/// let reference = Reference::new(m.clone(), set.clone(), nalgebra::DMatrix::zeros(15, 15), [0.0; 3], None).unwrap();
/// let data = Plant::geometric(m.clone(), set.to_errors(&[0.0; 15]))
///     .simulate(&Campaign::random(&m, 20, 1))
///     .unwrap();
/// let report = check(&reference, &data, &CheckOptions::for_machine(&m)).unwrap();
/// assert_eq!(report.verdict, CheckVerdict::Unchanged);
/// // Leg 2 slipped by 25 um: found, and named.
/// let mut e = [0.0; 15];
/// e[set.index_of("dq2").unwrap()] = 0.025;
/// let data = Plant::geometric(m.clone(), set.to_errors(&e))
///     .simulate(&Campaign::random(&m, 20, 2))
///     .unwrap();
/// let report = check(&reference, &data, &CheckOptions::for_machine(&m)).unwrap();
/// assert_eq!(report.verdict, CheckVerdict::Changed);
/// let best = &report.candidates[report.most_likely.unwrap()];
/// assert_eq!(best.name, "leg 2");
/// assert!((best.estimate[0] - 0.025).abs() < 5.0 * best.std_dev[0].unwrap());
/// ```
pub fn check(
    reference: &Reference,
    data: &Dataset,
    options: &CheckOptions,
) -> Result<CheckReport, CheckError> {
    screened(reference, data, options)
}

/// [`evaluate`] with gross readings set aside (see the module docs).
pub(crate) fn screened(
    reference: &Reference,
    data: &Dataset,
    options: &CheckOptions,
) -> Result<CheckReport, CheckError> {
    let n = data.poses.len();
    let cap = ((MAX_SET_ASIDE_SHARE * n as f64).floor() as usize).max(1);
    let (first, design) = evaluate(reference, data, options)?;
    let mut kept: Vec<usize> = (0..n).collect();
    let mut rejected: Vec<Rejected> = Vec::new();
    let mut current = (first.clone(), design);
    while let Some((j, mut r)) = worst(
        &current.1,
        &change_columns(&current.0.candidates, current.0.most_likely),
        options.sigma,
    ) {
        if rejected.len() == cap {
            let mut report = first;
            report.warnings.push(format!(
                "more than {cap} of the {n} poses stand out from the rest: not a matter of gross readings, so none is set aside"
            ));
            return Ok(report);
        }
        let pose = kept.remove(j);
        r.pose = pose + 1;
        r.line = data.poses[pose].line;
        rejected.push(r);
        let rest = data.subset(|i| kept.contains(&i));
        match evaluate(reference, &rest, options) {
            Ok(next) => current = next,
            // The rest is no check (too few distinct poses): none is set
            // aside.
            Err(_) => return Ok(first),
        }
    }
    let mut report = current.0;
    for r in &rejected {
        report.warnings.push(format!(
            "a gross reading set aside: pose {} (line {}), {} off by {:+.1} {} ({:.1} noise standard deviations from what the other poses predict); the verdict comes from the other poses",
            r.pose, r.line, r.column, r.residual, r.unit, r.residual_sigma
        ));
    }
    report.rejected = rejected;
    Ok(report)
}

/// The pose whose deleted residual stands out the most beyond the screen's
/// criterion at the fit of `design` on the nuisance and the `change`
/// columns (the fit the report rests on), by its index in the design
/// (`pose` and `line` of the entry are left to the caller); `sigma` is the
/// stated noise (rad, rad, mm).
fn worst(design: &Design, change: &[usize], sigma: [f64; 3]) -> Option<(usize, Rejected)> {
    let fit = design.fit(change);
    let n = design.poses();
    let crit = chi2_isf(SCREEN_ALPHA / n.max(1) as f64, 3.0);
    let nu = fit.dof;
    (0..n)
        .filter_map(|j| {
            let e = fit.pose_residual(j);
            let deleted = (Matrix3::identity() - fit.hat[j]).try_inverse()? * e;
            let t = e.dot(&deleted);
            let scatter = if nu > 3 {
                ((fit.misfit - t) / (nu - 3) as f64).max(1.0)
            } else {
                1.0
            };
            let z = t / scatter;
            (z > crit).then_some((j, z, deleted))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(j, z, deleted)| {
            let c = (0..3)
                .max_by(|&a, &b| deleted[a].abs().total_cmp(&deleted[b].abs()))
                .unwrap_or(0);
            let value = deleted[c] * sigma[c];
            let (column, residual, unit) = match c {
                0 => ("phi", value / RAD_PER_ARCSEC, "arcsec"),
                1 => ("theta", value / RAD_PER_ARCSEC, "arcsec"),
                _ => ("s", value * 1e3, "um"),
            };
            (
                j,
                Rejected {
                    pose: 0,
                    line: 0,
                    residual_sigma: z.sqrt(),
                    column,
                    residual,
                    unit,
                },
            )
        })
}

#[cfg(test)]
mod tests {
    //! The screen's rule on a design of offsets alone, worked by hand.
    use super::*;

    /// Five poses, each channel's offset column one-hot and its whitened
    /// residual last; the fifth pose's scale reading is `s`, the others
    /// scatter about 0 with a sum of squares of 10 + 10 + 26 = 46.
    fn five_poses(s: f64) -> Design {
        let values = [
            [2.0, -1.0, 3.0],
            [-2.0, 1.0, -3.0],
            [1.0, 2.0, -2.0],
            [-1.0, -2.0, 2.0],
            [0.0, 0.0, s],
        ];
        let mut design = Design::new(4, Vec::new());
        for pose in values {
            for (channel, value) in pose.into_iter().enumerate() {
                let mut row = [0.0; 4];
                row[channel] = 1.0;
                row[3] = value;
                design.push(&row);
            }
        }
        design
    }

    /// `chi2_3(1 - 1e-3 / 5)`, the criterion for five poses: the tail of 3
    /// degrees of freedom is `erfc(sqrt(x/2)) + sqrt(2x/pi) e^(-x/2)`,
    /// 2e-4 at 19.6561 (bisection of the closed form).
    const CRITERION_5: f64 = 19.6561;

    #[test]
    fn a_pose_stands_out_beyond_the_scatter_of_the_other_poses_only() {
        assert!((chi2_isf(SCREEN_ALPHA / 5.0, 3.0) - CRITERION_5).abs() < 1e-3);
        // With the offsets alone the fifth pose's deleted residual is its
        // reading less the mean of the others (0): `s` on the scale; its
        // statistic `T = |e|^2 n / (n - 1)` with `e = s - s/5`: `0.8 s^2`.
        // The other poses leave their own sum of squares, 46, on
        // `3n - 3 - 3 = 9` degrees of freedom: a scatter of 46/9 = 5.11
        // times the stated variance. At s = 10, T = 80: 15.65 scatters,
        // below the criterion (with 15 degrees of freedom instead of 9 it
        // would be 26.1, above it).
        assert!(worst(&five_poses(10.0), &[], [1e-6, 1e-6, 1e-3]).is_none());
        // At s = 14, T = 156.8: 30.68 scatters, beyond it. The reading is
        // 14 stated deviations (1 um each) from what the others predict.
        let (pose, r) = worst(&five_poses(14.0), &[], [1e-6, 1e-6, 1e-3]).unwrap();
        assert_eq!(pose, 4);
        assert_eq!((r.column, r.unit), ("s", "um"));
        assert!((r.residual - 14.0).abs() < 1e-9, "{r:?}");
        let z: f64 = 156.8 / (46.0 / 9.0);
        assert!((r.residual_sigma - z.sqrt()).abs() < 1e-9, "{r:?}");
    }
}

#[cfg(test)]
mod design_tests {
    use crate::check::{CheckOptions, evaluate};
    use crate::design::change_columns;
    use crate::reference::Reference;
    use nalgebra::DMatrix;
    use tricept_kinematics::Machine;
    use tricept_model::ParameterSet;
    use tricept_plant::{Campaign, Plant};

    #[test]
    fn the_design_fits_are_the_checks_own_statistics() {
        // A calibrated machine known to 1 um, leg 2 slipped by 50 um.
        let m = Machine::paper();
        let set = ParameterSet::paper15();
        let covariance = DMatrix::identity(15, 15) * 1e-6;
        let reference = Reference::new(m.clone(), set.clone(), covariance, [0.0; 3], None).unwrap();
        let mut e = [0.0; 15];
        e[set.index_of("dq2").unwrap()] = 0.05;
        let data = Plant::geometric(m.clone(), set.to_errors(&e))
            .simulate(&Campaign::random(&m, 20, 5))
            .unwrap();
        let (report, design) = evaluate(&reference, &data, &CheckOptions::for_machine(&m)).unwrap();
        assert_eq!(design.poses(), 20);
        assert_eq!(design.n_prior(), 15);
        // No candidate: the consistency statistic on 3n - 3.
        let null = design.fit(&[]);
        let t0 = report.consistency.statistic;
        assert!(
            (null.misfit - t0).abs() < 1e-6 * t0,
            "{} vs {t0}",
            null.misfit
        );
        assert_eq!(null.dof, 57);
        assert_eq!(null.hat.len(), 20);
        // The offsets alone take 3 of the hat's trace, the prior some more.
        let trace: f64 = null.leverage.iter().sum();
        assert!(trace > 3.0 && trace < 18.0, "{trace}");
        // The most likely change: the misfit it leaves.
        let best = report.most_likely.unwrap();
        assert_eq!(report.candidates[best].name, "leg 2");
        let cols = change_columns(&report.candidates, report.most_likely);
        assert_eq!(
            cols,
            (0..report.candidates[best].fitted)
                .map(|t| 4 + t)
                .collect::<Vec<_>>()
        );
        let rest = design.fit(&cols);
        let expected = report.remaining.unwrap().statistic;
        assert!(
            (rest.misfit - expected).abs() < 1e-6 * t0,
            "{} vs {expected}",
            rest.misfit
        );
        assert_eq!(rest.dof, 57 - cols.len());
        assert!(change_columns(&report.candidates, None).is_empty());
    }
}
