//! The promise of a fused fit, at the tool tip after touch-off: the
//! estimate, what the external sources leave unexplained, the head parts
//! the data cannot calibrate scaled by the size the data show of this head
//! ([`head_scale`]), the structure ([`fused_structure`]) and the sources
//! accepted unchecked ([`super::promise`]'s module docs hold the parts'
//! definitions).

use serde_json::Map;

use tricept_model::head_errors::Effector;

use super::promise::{Accuracy, TOOL_TIP, Z95, posterior_upper};
use crate::fusion::{FusedModel, Fusion, SourceKind};

/// The promise of a fused fit at the tool tip after touch-off: the tip's
/// predicted covariance over the evaluation poses (`tip`) without the held
/// parameters as the estimate part; the held parameters' share (their
/// invisible combinations at their typical sizes) scaled by the size the
/// data show of this head ([`head_scale`]) as the head part; the external
/// sources' residuals beyond their stated noise out of sample; and, when
/// sources that cannot be checked on their own were accepted because they
/// agree with the checked fit, the tip's shift they bring beyond chance
/// (`unchecked`, `(rms_mm, upper_mm)`); `structure`: [`fused_structure`]
/// (module docs).
pub fn of_fusion(
    model: &FusedModel,
    fit: &Fusion,
    structure: (f64, f64),
    unchecked: Option<(f64, f64)>,
) -> Accuracy {
    let held_mm = fit.report.tool_tip.held_touch_off_rms_um * 1e-3;
    let estimate_mm = fused_estimate_mm(fit);
    // One dominant weak direction: the chi-square of one degree of freedom.
    let one_dof = ONE_DOF_95;
    let (mut unexplained, mut unexplained_upper) = (0.0_f64, 0.0_f64);
    for s in fit
        .sources
        .iter()
        .filter(|s| s.kind != SourceKind::Internal)
    {
        let (Some(rms_um), chi2) = (s.rms_um, s.reduced_chi_square) else {
            continue;
        };
        if !(chi2.is_finite() && chi2 > 0.0 && s.redundancy > 0.0) {
            continue;
        }
        let nu = (s.rows as f64 * s.redundancy).max(1.0);
        let noise_mm2 = (rms_um * 1e-3).powi(2) / chi2;
        // Three coordinates of an isotropic error; deleted residuals are the
        // fitted ones over the redundancy.
        let excess = |c: f64| 3.0 * noise_mm2 * (c - 1.0).max(0.0) / s.redundancy;
        unexplained = unexplained.max(excess(chi2));
        unexplained_upper = unexplained_upper.max(excess(chi2 + Z95 * (2.0 / nu).sqrt()));
    }
    let size = head_scale(model, fit);
    let head = (held_mm * size.scale, one_dof * held_mm * size.upper);
    let mut parts = Map::new();
    parts.insert("estimate_mm".into(), estimate_mm.into());
    parts.insert("estimate_upper_mm".into(), (one_dof * estimate_mm).into());
    parts.insert("unexplained_mm".into(), unexplained.sqrt().into());
    parts.insert(
        "unexplained_upper_mm".into(),
        unexplained_upper.sqrt().into(),
    );
    parts.insert("head_mm".into(), head.0.into());
    parts.insert("head_upper_mm".into(), head.1.into());
    parts.insert("head_at_typical_size_mm".into(), held_mm.into());
    parts.insert("head_size_seen".into(), size.scale.into());
    parts.insert("head_size_seen_upper".into(), size.upper.into());
    parts.insert("head_parameters_seen".into(), size.seen.into());
    parts.insert("structure_mm".into(), structure.0.into());
    parts.insert("structure_upper_mm".into(), structure.1.into());
    let mut list = vec![
        (estimate_mm, one_dof * estimate_mm),
        (unexplained.sqrt(), unexplained_upper.sqrt()),
        head,
        structure,
    ];
    if let Some((rms, upper)) = unchecked {
        parts.insert("unchecked_mm".into(), rms.into());
        parts.insert("unchecked_upper_mm".into(), upper.into());
        list.push((rms, upper));
    }
    Accuracy::combine(TOOL_TIP, &list, parts)
}

/// The structure part of a fused fit: where the geometric fit (`fit`)
/// and the same sources fitted with a lead on every leg (`rich`, its model
/// `rich_model`) put the tool tip at the same commands, over the
/// evaluation poses after touch-off (the mean difference removed), as
/// `(rms_mm, upper_mm)`. Its rms is the mean square difference `D` less
/// what chance gives it (`tr(M V)`, `M = mean_e G_e^T G_e` with `G_e` the
/// rich model's tip Jacobian less its mean over the poses, `V` the rich
/// covariance less the geometric one in its coordinates: Hausman). Its
/// bound is, as for internal files ([`posterior_upper`]), what it adds to
/// the estimate's bound for the file's error to stay within the 95 %
/// quantile of its distribution given the data, `N(d, S_rich)` (`d` the
/// tip differences, a flat prior on the bias), which a shift that chance
/// happens to cancel does not fool. `(0, 0)` when a tip cannot be had.
pub fn fused_structure(
    model: &FusedModel,
    fit: &Fusion,
    rich_model: &FusedModel,
    rich: &Fusion,
    eval: &[tricept_data::external::ExternalPose],
) -> (f64, f64) {
    let (k, kr) = (model.len(), rich_model.len());
    // The geometric parameters' places among the rich model's.
    let index: Vec<usize> = rich_model
        .module_range()
        .chain(rich_model.head_range())
        .collect();
    if index.len() != k || fit.estimate.len() != k || rich.estimate.len() != kr {
        return (0.0, 0.0);
    }
    let tip = Effector::default();
    let diffs: Option<Vec<nalgebra::Vector3<f64>>> = eval
        .iter()
        .map(|pose| {
            let r = rich_model.spindle_point(&rich.estimate, pose, &tip).ok()?;
            let g = model.spindle_point(&fit.estimate, pose, &tip).ok()?;
            Some(r.0 - g.0)
        })
        .collect();
    let Some(diffs) = diffs else {
        return (0.0, 0.0);
    };
    let Ok(g) = rich_model.spindle_jacobians(&rich.estimate, eval, &[tip]) else {
        return (0.0, 0.0);
    };
    let g: Vec<&nalgebra::DMatrix<f64>> = g.iter().filter_map(|v| v.first()).collect();
    let n = diffs.len().max(1) as f64;
    let centre = diffs.iter().sum::<nalgebra::Vector3<f64>>() / n;
    let shift = diffs
        .iter()
        .map(|d| (d - centre).norm_squared())
        .sum::<f64>()
        / n;
    let mean = g
        .iter()
        .fold(nalgebra::DMatrix::zeros(3, kr), |a, b| a + *b)
        / n;
    let mut m = nalgebra::DMatrix::zeros(kr, kr);
    for ge in &g {
        let c = *ge - &mean;
        m += c.transpose() * c;
    }
    m /= n;
    let mut v = rich.covariance.clone();
    for (a, &ia) in index.iter().enumerate() {
        for (b, &ib) in index.iter().enumerate() {
            v[(ia, ib)] -= fit.covariance[(a, b)];
        }
    }
    let chance = (&m * &v).trace();
    let bias2 = shift - chance.max(0.0);
    // The moments of the tip error's mean square under N(d, S_rich):
    // `cross = (G^T d)^T S (G^T d) / n^2` with `G^T d = sum_e G_e^T d_e`.
    let s_rich = &rich.covariance;
    let ms = &m * s_rich;
    let gd = g
        .iter()
        .zip(&diffs)
        .fold(nalgebra::DVector::zeros(kr), |a, (ge, d)| {
            a + (*ge - &mean).transpose() * (d - centre)
        });
    let cross = (gd.transpose() * s_rich * &gd)[(0, 0)] / (n * n);
    let upper2 = posterior_upper(shift, ms.trace(), (&ms * &ms).trace(), cross).powi(2);
    let estimate_upper = ONE_DOF_95 * fused_estimate_mm(fit);
    let upper = (upper2 - estimate_upper.powi(2)).max(0.0).sqrt();
    if !(bias2.is_finite() && upper.is_finite()) {
        return (0.0, 0.0);
    }
    (bias2.max(0.0).sqrt(), upper)
}

/// The 95 % quantile of the root of a chi-square of one degree of
/// freedom: the bound of an error along one dominant weak direction.
const ONE_DOF_95: f64 = 1.959_963_984_540_054;

/// A fused fit's tool-tip rms after touch-off from its estimate's
/// covariance alone (the held parameters' share removed), mm.
fn fused_estimate_mm(fit: &Fusion) -> f64 {
    let tip = &fit.report.tool_tip;
    let held_mm = tip.held_touch_off_rms_um * 1e-3;
    let total_mm = tip.touch_off_rms_um * 1e-3;
    (total_mm * total_mm - held_mm * held_mm).max(0.0).sqrt()
}

/// The size of a head's errors the data show, in units of the parameters'
/// typical sizes: the head parameters the data see (`n` of them, estimate
/// `e_j`, standard deviation `s_j`, typical size `t_j`) give `S = sum
/// (e_j / t_j)^2`, whose mean is `n c^2 + sum (s_j / t_j)^2` for a head of
/// `c` typical sizes; the scale is the moment estimate `c^2 = (S - sum (s_j
/// / t_j)^2) / n` (never below zero), its 95 % upper bound `S / chi2_n(5
/// %)`. A fit that sees no head parameter keeps the typical size (1, 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadScale {
    /// The moment estimate `c`.
    pub scale: f64,
    /// Its 95 % upper bound.
    pub upper: f64,
    /// Head parameters seen.
    pub seen: usize,
}

/// The size of the head's errors the data show ([`HeadScale`]).
pub fn head_scale(model: &FusedModel, fit: &Fusion) -> HeadScale {
    let typical = model.typical_sizes();
    let seen: Vec<(f64, f64, f64)> = model
        .head_range()
        .filter_map(|j| {
            let sd = (*fit.std_dev.get(j)?)?;
            Some((*fit.estimate.get(j)?, sd, *typical.get(j)?))
        })
        .collect();
    HeadScale::of(&seen)
}

impl HeadScale {
    /// The scale of the head parameters seen, each `(estimate, standard
    /// deviation, typical size)` (one without a positive typical size or
    /// with a value that is not finite is left out).
    pub fn of(seen: &[(f64, f64, f64)]) -> HeadScale {
        let (mut sum, mut noise, mut n) = (0.0, 0.0, 0usize);
        for &(e, sd, t) in seen {
            if t > 0.0 && e.is_finite() && sd.is_finite() {
                sum += (e / t).powi(2);
                noise += (sd / t).powi(2);
                n += 1;
            }
        }
        if n == 0 {
            return HeadScale {
                scale: 1.0,
                upper: 1.0,
                seen: 0,
            };
        }
        let low = tricept_numerics::stats::chi2_isf(0.95, n as f64);
        HeadScale {
            scale: ((sum - noise).max(0.0) / n as f64).sqrt(),
            upper: if low > 0.0 { (sum / low).sqrt() } else { 1.0 },
            seen: n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_head_scale_is_what_the_seen_parameters_show() {
        // Eleven parameters seen at twice their typical sizes, exactly: a
        // head of two typical sizes; the bound S / chi2_11(5 %) = 44 / 4.57.
        let seen = vec![(0.6, 0.0, 0.3); 11];
        let h = HeadScale::of(&seen);
        assert!((h.scale - 2.0).abs() < 1e-12, "{h:?}");
        assert!(
            (h.upper - (44.0_f64 / 4.574_813).sqrt()).abs() < 1e-3,
            "{h:?}"
        );
        assert_eq!(h.seen, 11);
        // Estimates no larger than their noise show no head beyond it.
        let h = HeadScale::of(&[(0.01, 0.02, 0.3), (-0.01, 0.02, 0.1)]);
        assert_eq!(h.scale, 0.0);
        assert!(h.upper > 0.0);
        // Nothing seen: the typical size.
        let h = HeadScale::of(&[(1.0, f64::NAN, 0.3)]);
        assert_eq!((h.scale, h.upper, h.seen), (1.0, 1.0, 0));
    }
}
