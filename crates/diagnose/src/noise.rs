//! The noise of the data, measured from repeated poses.
//!
//! Poses whose commands agree within `repeat_tolerance_mm` form a repeat
//! group. The pure error of channel `c` is the spread of the final model's
//! weighted residuals within the groups,
//! `SS_c = sum_g sum_j (r_jc - mean_g r_c)^2` with `nu = sum_g (n_g - 1)`
//! degrees of freedom: on the model's residuals rather than the raw
//! readings, so that drift, thermal growth or backlash between two visits
//! are not counted as noise once they are modelled. `SS_c / nu` is the
//! squared ratio of the data's noise to the stated noise; it is tested
//! against 1 (two-sided chi-square) per channel and pooled over the three,
//! at [`NOISE_CHECK_LEVEL`] with a Bonferroni factor of 4.

use tricept_data::Dataset;
use tricept_model::effects::CHANNELS;
use tricept_numerics::stats::chi2_two_sided;

use crate::fit::{Fit, Fitter, residuals_of};
use crate::report::{ChannelRms, NoiseCheck, NoiseSource, PureError};

/// Level of the check of the stated noise against the data (not a naming
/// decision, so not the diagnosis' family-wise `alpha`: a 1.5 times worse
/// noise must be caught with 20 repeated poses).
pub const NOISE_CHECK_LEVEL: f64 = 0.01;

/// Repeat groups of a data set (pose indices).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Repeats {
    /// Groups with at least two poses.
    pub(crate) groups: Vec<Vec<usize>>,
    /// Repeats in consecutive rows with the same approach.
    pub(crate) within_visit: usize,
}

impl Repeats {
    /// Degrees of freedom of the pure error per channel.
    pub(crate) fn dof(&self) -> usize {
        self.groups.iter().map(|g| g.len() - 1).sum()
    }
}

/// The repeat groups of `data`.
pub(crate) fn repeats(data: &Dataset, tolerance_mm: f64) -> Repeats {
    let n = data.poses.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| data.poses[a].commands_mm[0].total_cmp(&data.poses[b].commands_mm[0]));
    let mut group_of = vec![usize::MAX; n];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (k, &a) in order.iter().enumerate() {
        if group_of[a] != usize::MAX {
            continue;
        }
        let qa = data.poses[a].commands_mm;
        let mut members = vec![a];
        for &b in &order[k + 1..] {
            let qb = data.poses[b].commands_mm;
            if qb[0] - qa[0] > tolerance_mm {
                break;
            }
            if group_of[b] == usize::MAX && (0..3).all(|i| (qa[i] - qb[i]).abs() <= tolerance_mm) {
                members.push(b);
            }
        }
        if members.len() > 1 {
            for &m in &members {
                group_of[m] = groups.len();
            }
            members.sort_unstable();
            groups.push(members);
        }
    }
    let within_visit = (1..n)
        .filter(|&j| {
            group_of[j] != usize::MAX
                && group_of[j] == group_of[j - 1]
                && data.poses[j].approach == data.poses[j - 1].approach
        })
        .count();
    Repeats {
        groups,
        within_visit,
    }
}

/// The pure error of weighted residuals (`None` per pose where the model
/// could not be evaluated) within the repeat groups: per channel the sum
/// of squares and the degrees of freedom. `None` without repeats.
pub(crate) fn pure_error(
    repeats: &Repeats,
    residuals: &[Option<[f64; 3]>],
) -> Option<([f64; 3], usize)> {
    let mut ss = [0.0; 3];
    let mut dof = 0;
    for g in &repeats.groups {
        let r: Vec<[f64; 3]> = g
            .iter()
            .filter_map(|&j| residuals.get(j).copied().flatten())
            .collect();
        if r.len() < 2 {
            continue;
        }
        dof += r.len() - 1;
        for c in 0..3 {
            let mean = r.iter().map(|v| v[c]).sum::<f64>() / r.len() as f64;
            ss[c] += r.iter().map(|v| (v[c] - mean).powi(2)).sum::<f64>();
        }
    }
    (dof > 0).then_some((ss, dof))
}

/// The report of a pure error against the stated noise `sigma`
/// (`[rad, rad, mm]`), and whether they agree.
pub(crate) fn check(
    repeats: &Repeats,
    ss: [f64; 3],
    dof: usize,
    sigma: [f64; 3],
) -> (PureError, bool) {
    let nu = dof as f64;
    let ratio = ss.map(|s| (s / nu).sqrt());
    let p_value = ss.map(|s| chi2_two_sided(s, nu));
    let pooled = chi2_two_sided(ss.iter().sum(), 3.0 * nu);
    let smallest = p_value.iter().copied().fold(pooled, f64::min);
    let agrees = 4.0 * smallest > NOISE_CHECK_LEVEL;
    (
        PureError {
            groups: repeats.groups.len(),
            dof,
            sigma: ChannelRms::from_internal(std::array::from_fn(|c| ratio[c] * sigma[c])),
            ratio,
            p_value,
            within_visit: repeats.within_visit,
        },
        agrees,
    )
}

/// The noise check against the repeated poses.
pub(crate) fn noise_check(
    fitter: &Fitter<'_>,
    repeated: &Repeats,
    fit: &Fit,
    data: &Dataset,
) -> NoiseCheck {
    let stated = ChannelRms::from_internal(fitter.options.sigma);
    let used = if fitter.reference.pure_error_dof.is_some() {
        NoiseSource::Data
    } else {
        NoiseSource::Stated
    };
    // Without repeats there is no pure error: no residuals needed.
    let res = if repeated.groups.is_empty() {
        Vec::new()
    } else {
        residuals_of(fit, &data.poses, &fitter.options.sigma)
    };
    let Some((ss, dof)) = pure_error(repeated, &res) else {
        return NoiseCheck {
            stated,
            used,
            pure_error: None,
            agrees: None,
            note: "no repeated poses: the stated noise cannot be checked (revisit some poses on separate visits to check it)".into(),
        };
    };
    let (pe, agrees) = check(repeated, ss, dof, fitter.options.sigma);
    let worst = (0..3)
        .max_by(|&a, &b| (pe.ratio[a].ln().abs()).total_cmp(&pe.ratio[b].ln().abs()))
        .unwrap_or(0);
    let mut note = if agrees {
        format!(
            "the stated noise agrees with {} repeated poses ({} dof; data/stated {:.2} / {:.2} / {:.2})",
            pe.groups, pe.dof, pe.ratio[0], pe.ratio[1], pe.ratio[2]
        )
    } else {
        format!(
            "the data's noise is {:.2}x the stated noise on {} (p = {:.1e}; {} repeated poses, {} dof): chi-square tests against the stated noise are unreliable{}",
            pe.ratio[worst],
            CHANNELS[worst],
            pe.p_value[worst],
            pe.groups,
            pe.dof,
            if used == NoiseSource::Data {
                ""
            } else {
                "; rerun with the noise estimated from the data (noise_from_data)"
            }
        )
    };
    if used == NoiseSource::Data {
        let s = ChannelRms::from_internal(fitter.sigma);
        note.push_str(&format!(
            "; the tests used the data's noise: phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um (F tests)",
            s.phi_arcsec, s.theta_arcsec, s.s_um
        ));
    }
    if pe.within_visit > 0 {
        note.push_str(&format!(
            "; {} repeats were logged in consecutive rows (within a visit): they miss repositioning and vibration",
            pe.within_visit
        ));
    }
    NoiseCheck {
        stated,
        used,
        pure_error: Some(pe),
        agrees: Some(agrees),
        note,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tricept_data::MeasuredPose;

    #[test]
    fn groups_and_pure_error() {
        let pose = |q: f64| MeasuredPose {
            commands_mm: [q, 800.0, 900.0],
            ..Default::default()
        };
        let poses = vec![
            pose(700.0),
            pose(750.0),
            pose(700.0005),
            pose(760.0),
            pose(750.0),
        ];
        let data = Dataset {
            poses,
            source: String::new(),
        };
        let r = repeats(&data, 1e-3);
        assert_eq!(r.groups, vec![vec![0, 2], vec![1, 4]]);
        assert_eq!(r.dof(), 2);
        let res = vec![
            Some([1.0, 0.0, 0.0]),
            Some([2.0, 0.0, 0.0]),
            Some([-1.0, 0.0, 0.0]),
            Some([9.0, 9.0, 9.0]),
            Some([2.0, 0.0, 0.0]),
        ];
        let (ss, dof) = pure_error(&r, &res).unwrap();
        assert_eq!(dof, 2);
        assert_eq!(ss, [2.0, 0.0, 0.0]);
    }
}
