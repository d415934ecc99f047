//! Noise is not a change: whether a candidate stands out beyond the
//! scatter the readings show, and the noise a campaign shows.
//!
//! The candidates' chi-square tests assume the stated noise. Sensors
//! noisier than stated inflate every statistic alike: the consistency
//! statistic `T0`, and each candidate's `dT_S` by the same factor, so that
//! with 1.5 times the noise some candidate passes its Bonferroni level in
//! most campaigns although nothing changed. A change, however, moves the
//! readings in its own direction: after it is fitted, the readings scatter
//! as the noise does. So each candidate is tested against the scatter left
//! after it, `s_S^2 = (T0 - dT_S) / (3n - 3 - dim S)`:
//!
//! - when `s_S^2 <= 1` the readings are no noisier than stated and the
//!   chi-square test stands (`dT_S` beyond its quantile);
//! - when `s_S^2 > 1` the candidate must stand out beyond that scatter: the
//!   F test `F_S = (dT_S / dim S) / s_S^2` against `F(dim S, 3n - 3 - dim
//!   S)` at the same family-wise level. Its statistic has this distribution
//!   without a change whatever the noise is, so a uniformly larger noise
//!   raises no more false alarms than the stated one does.
//!
//! When the check's tests fire but no candidate stands out, the verdict is
//! `noisier-than-stated`: the readings are explained by a larger noise and
//! no change is seen beyond it (exit code 0, with a warning to state the
//! noise or to service the sensors).

use serde::Serialize;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_numerics::stats::f_sf;

use crate::design::DesignFit;
use crate::parts::CandidateResult;

/// Re-decides each candidate's `significant` against the scatter the
/// readings leave after it (see the module docs); `t0` on `dof0` degrees
/// of freedom is the consistency statistic, `level` the candidates'
/// family-wise level.
pub(crate) fn beyond_noise(results: &mut [CandidateResult], t0: f64, dof0: usize, level: f64) {
    for c in results.iter_mut().filter(|c| c.significant) {
        let d = c.test.dof;
        let nu = dof0.saturating_sub(d);
        if nu == 0 {
            continue;
        }
        let scatter = (t0 - c.test.statistic).max(0.0) / nu as f64;
        if scatter > 1.0 {
            let f = c.test.statistic / d as f64 / scatter;
            c.significant = f_sf(f, d as f64, nu as f64) < level;
        }
    }
}

/// The noise of one logged reading per channel, in the units a person
/// reads.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChannelNoise {
    /// Encoder `phi`, arcsec.
    pub phi_arcsec: f64,
    /// Encoder `theta`, arcsec.
    pub theta_arcsec: f64,
    /// Linear scale `s`, um.
    pub s_um: f64,
}

impl ChannelNoise {
    /// From `[phi, theta, s]` in rad, rad, mm.
    fn of(sigma: [f64; 3]) -> ChannelNoise {
        ChannelNoise {
            phi_arcsec: sigma[0] / RAD_PER_ARCSEC,
            theta_arcsec: sigma[1] / RAD_PER_ARCSEC,
            s_um: sigma[2] * 1e3,
        }
    }
}

/// The noise a check campaign shows, against the stated one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NoiseSeen {
    /// The readings' scatter in units of the stated noise, `sqrt(misfit /
    /// dof)` after the change the verdict names (none when unchanged or
    /// noisier than stated): about 1 when the noise is as stated.
    pub factor: f64,
    /// Per channel, the scatter of one logged reading (each channel's
    /// squared residuals over its residual degrees of freedom).
    pub seen: ChannelNoise,
    /// The stated noise of one logged reading.
    pub stated: ChannelNoise,
}

impl NoiseSeen {
    /// The noise shown by `fit` (three rows per pose) with the stated
    /// noise `sigma` (rad, rad, mm).
    pub(crate) fn of(fit: &DesignFit, sigma: [f64; 3]) -> NoiseSeen {
        let seen: [f64; 3] = std::array::from_fn(|c| {
            let rows = (c..fit.residual.len()).step_by(3);
            let (ss, dof) = rows.fold((0.0, 0.0), |(ss, dof), i| {
                (
                    ss + fit.residual[i] * fit.residual[i],
                    dof + 1.0 - fit.leverage[i],
                )
            });
            sigma[c] * (ss / dof.max(1.0)).sqrt()
        });
        NoiseSeen {
            factor: (fit.misfit / fit.dof.max(1) as f64).sqrt(),
            seen: ChannelNoise::of(seen),
            stated: ChannelNoise::of(sigma),
        }
    }

    /// The warning of a `noisier-than-stated` verdict: the noise seen and
    /// what to do.
    pub(crate) fn warning(&self) -> String {
        let (s, t) = (&self.seen, &self.stated);
        format!(
            "the readings scatter {:.2} times the stated noise (per logged reading: phi {:.2} arcsec, theta {:.2} arcsec, s {:.2} um, against the stated {:.2}, {:.2}, {:.2}) and no change stands out beyond that noise: state the sensors' noise (`angle_noise_arcsec`, `length_noise_um`, the noise of one reading) or service the sensors",
            self.factor, s.phi_arcsec, s.theta_arcsec, s.s_um, t.phi_arcsec, t.theta_arcsec, t.s_um
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidates::CandidateKind;
    use crate::parts::ChiSquare;
    use tricept_numerics::stats::chi2_isf;

    /// A candidate of `dof` parameters whose statistic is `statistic`,
    /// significant by its chi-square test at `level`.
    fn candidate(statistic: f64, dof: usize, level: f64) -> CandidateResult {
        let critical = chi2_isf(level, dof as f64);
        CandidateResult {
            name: "leg 1".into(),
            kind: CandidateKind::Leg,
            parameters: vec!["dq1_mm".into(); dof],
            fitted: dof,
            estimate: vec![0.0; dof],
            std_dev: vec![Some(1e-3); dof],
            test: ChiSquare {
                statistic,
                dof,
                p_value: 0.0,
                ln_p_value: 0.0,
                critical,
            },
            significant: statistic > critical,
            detectable: vec![None; dof],
            alone: vec![None; dof],
            flagged_beyond: vec![None; dof],
            platform_mean_um: 0.0,
            platform_max_um: 0.0,
        }
    }

    #[test]
    fn a_candidate_is_tested_against_the_scatter_it_leaves() {
        let level = 0.005 / 21.0;
        // chi2_1 critical at this level: 13.5; F(1, 56): 15.3.
        // 57 dof: T0 = 57 + 20 leaves a scatter of exactly 1 after a
        // statistic of 20: the chi-square test stands.
        let mut r = vec![candidate(20.0, 1, level)];
        beyond_noise(&mut r, 77.0, 57, level);
        assert!(r[0].significant);
        // A scatter of exactly 1 with a statistic between the chi-square
        // (13.5) and F (15.3) quantiles: the chi-square test decides.
        let mut r = vec![candidate(14.0, 1, level)];
        beyond_noise(&mut r, 14.0 + 56.0, 57, level);
        assert!(r[0].significant);
        // The same statistic with twice the scatter left: F = 20 / 2 = 10,
        // below 15.3.
        let mut r = vec![candidate(20.0, 1, level)];
        beyond_noise(&mut r, 20.0 + 2.0 * 56.0, 57, level);
        assert!(!r[0].significant);
        // F = 40 / 2 = 20 beyond 15.3: it stands out.
        let mut r = vec![candidate(40.0, 1, level)];
        beyond_noise(&mut r, 40.0 + 2.0 * 56.0, 57, level);
        assert!(r[0].significant);
        // Just above and below the F quantile (found by bisection on f_sf).
        let (mut lo, mut hi) = (1.0, 100.0);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if f_sf(mid, 1.0, 56.0) < level {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        assert!((lo - 15.3).abs() < 0.3, "{lo}");
        for (f, expected) in [(0.99 * lo, false), (1.01 * lo, true)] {
            let mut r = vec![candidate(2.0 * f, 1, level)];
            beyond_noise(&mut r, 2.0 * f + 2.0 * 56.0, 57, level);
            assert_eq!(r[0].significant, expected, "F = {f}");
        }
        // A candidate not significant stays so, whatever the scatter.
        let mut r = vec![candidate(5.0, 1, level)];
        beyond_noise(&mut r, 5.0 + 0.5 * 56.0, 57, level);
        assert!(!r[0].significant);
        // No degrees of freedom left: the chi-square decision stands.
        let mut r = vec![candidate(20.0, 3, level)];
        beyond_noise(&mut r, 1e6, 3, level);
        assert!(r[0].significant);
    }

    #[test]
    fn the_noise_seen_is_each_channel_over_its_degrees_of_freedom() {
        // Two poses: channel phi residuals 1, 1 at leverage 0.5 each
        // (variance 2 / 1 = 2), theta 3, 0 at no leverage (9 / 2), s none.
        let fit = DesignFit {
            residual: vec![1.0, 3.0, 0.0, 1.0, 0.0, 0.0],
            leverage: vec![0.5, 0.0, 0.0, 0.5, 0.0, 0.0],
            hat: Vec::new(),
            misfit: 16.0,
            dof: 4,
        };
        let a = RAD_PER_ARCSEC;
        let n = NoiseSeen::of(&fit, [a, 2.0 * a, 1e-3]);
        assert!((n.factor - 2.0).abs() < 1e-12);
        assert!((n.seen.phi_arcsec - 2f64.sqrt()).abs() < 1e-9);
        assert!((n.seen.theta_arcsec - 2.0 * 4.5f64.sqrt()).abs() < 1e-9);
        assert!(n.seen.s_um.abs() < 1e-12);
        assert!((n.stated.theta_arcsec - 2.0).abs() < 1e-9);
        assert!((n.stated.s_um - 1.0).abs() < 1e-12);
        let w = n.warning();
        assert!(w.starts_with("the readings scatter 2.00 times the stated noise (per logged reading: phi 1.41 arcsec, theta 4.24 arcsec, s 0.00 um, against the stated 1.00, 2.00, 1.00)"), "{w}");
    }
}
