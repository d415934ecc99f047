//! The accuracy block: what a machine file will deliver, stated by every
//! verb that writes one (`identify`, fused or not, and `diagnose
//! --write-machine`) in its JSON (`accuracy`), its report's first lines and
//! the file's sealed `calibration.accuracy` (`docs/reliability.md`, "The
//! accuracy block").
//!
//! The promise is the root sum of squares of its parts, each a mean square
//! over the workspace:
//!
//! - **estimate**: the estimate's covariance propagated to the workspace's
//!   evaluation points (held parameters at their tolerance), the rms
//!   `sqrt(trace(M S))` of [`tricept_engine::AccuracyModel`]; for a model
//!   with more than the geometry (a diagnosis' deployed terms) the larger
//!   of that and every fitted parameter's platform variance at the
//!   campaign's poses ([`tricept_engine::CrossValidation::fit_variance_mm2`]);
//! - **unexplained**: the mean square platform error the fitted model
//!   leaves out of sample beyond the stated noise, from the deleted
//!   residuals of the UP limb's readings mapped to the platform through the
//!   limb's Jacobian ([`tricept_engine::cross_validate`]), never below
//!   zero;
//! - **structure** (internal data, `diagnose`): how far the estimate moves
//!   when every leg may also be a polynomial in its command (a lead, a
//!   curved screw), beyond chance; its bound keeps the file's error within
//!   the 95 % quantile of its distribution given the data, `N(D, S_rich)`
//!   (`D` the move, `S_rich` the richer fit's covariance: a flat prior on
//!   the bias), which a shift that chance happens to cancel does not fool;
//! - **head** (fused files): the head parts the external data cannot
//!   calibrate, their invisible combinations at their typical sizes scaled
//!   by the size the data show of this head (`head_scale`: the head
//!   parameters they do see, against their typical sizes);
//! - **structure** (fused files): where a fit of the same sources with a
//!   lead on every leg puts the tool tip, against the geometric fit, beyond
//!   chance (`fused_structure`);
//! - **unchecked** (fused files): the tool tip's shift beyond chance that
//!   sources which cannot be checked on their own, accepted because they
//!   agree with the checked fit of the others, bring.
//!
//! Its 95 % upper bound adds the parts' 95 % upper bounds in quadrature:
//! the estimate's mean square `e^T M e` is a weighted sum of chi-squares,
//! taken as `g chi2_nu` with the same mean and variance (`g = tr(MSMS) /
//! tr(MS)`, `nu = tr(MS)^2 / tr(MSMS)`) and its 95 % quantile by
//! Wilson-Hilferty; the unexplained mean square's bound is its estimate plus
//! 1.645 standard errors.

use serde::Serialize;
use serde_json::{Map, Value};
use std::sync::Arc;

use tricept_data::Dataset;
use tricept_diagnose::{ExtendedModel, Frame, GenericFamily, GenericTerm, Scope, Term};
use tricept_engine::{
    AccuracyModel, CrossValidation, GeometricModel, IdentError, Identification, IdentifyOptions,
};
use tricept_kinematics::Machine;
use tricept_kinematics::description::AccuracyRecord;
use tricept_model::{Effector, ParameterSet};

use crate::error::Error;

/// The one-sided 95 % standard normal quantile.
const Z95: f64 = 1.644_853_626_951_472_2;

/// The point a promise is of: the platform (UP limb alone) or the tool tip
/// (after touch-off, where that applies).
pub(crate) const PLATFORM: &str = "platform";

/// The point of a fused file's promise.
pub(crate) const TOOL_TIP: &str = "tool tip";

/// The accuracy a machine file will deliver: the top-level `accuracy`
/// object of every verb that writes one.
///
/// # Example
/// ```
/// use tricept_ident::advanced::Accuracy;
/// let a = Accuracy::combine("platform", &[(0.003, 0.004), (0.004, 0.006)], Default::default());
/// assert!((a.rms_mm - 0.005).abs() < 1e-12);
/// assert!(a.upper_mm >= a.rms_mm);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Accuracy {
    /// Predicted rms positioning error over the workspace, mm.
    pub rms_mm: f64,
    /// A 95 % upper bound of the rms error delivered, mm.
    pub upper_mm: f64,
    /// The point positioned: `platform` or `tool tip`.
    pub point: String,
    /// The parts it is made of (units in the names).
    pub parts: Map<String, Value>,
}

impl Accuracy {
    /// The promise of independent parts, each `(rms_mm, upper_mm)`, added in
    /// quadrature, with `parts` describing them.
    pub fn combine(point: &str, parts_mm: &[(f64, f64)], parts: Map<String, Value>) -> Accuracy {
        let rss = |f: fn(&(f64, f64)) -> f64| parts_mm.iter().map(|p| f(p).powi(2)).sum::<f64>();
        Accuracy {
            rms_mm: rss(|p| p.0).sqrt(),
            upper_mm: rss(|p| p.1).sqrt(),
            point: point.to_string(),
            parts,
        }
    }

    /// The promise of an internal calibration: the estimate's covariance
    /// over `model`'s evaluation points (`held` at their tolerance) and the
    /// unexplained out-of-sample platform error `cv`; `terms`: the fit has
    /// parameters beyond the geometry (the first `covariance.nrows()`),
    /// whose platform variance at the campaign's poses counts too.
    pub fn internal(
        model: &AccuracyModel,
        covariance: &nalgebra::DMatrix<f64>,
        held: &[usize],
        cv: &CrossValidation,
        terms: bool,
    ) -> Result<Accuracy, Error> {
        let (m1, m2) = model
            .error_moments(covariance, held)
            .map_err(|e| Error::with_context("accuracy", &e))?;
        // A misfit biases the estimate as extra noise of its size would:
        // the estimate's part grows by the out-of-sample Birge ratio (its
        // bound by the ratio's 95 % bound), never shrinks.
        let birge = cv.chi2_per_reading.max(1.0);
        let birge_upper = (cv.chi2_per_reading + Z95 * cv.chi2_se).max(1.0);
        let (rms, upper) = estimate_part(m1, m2);
        let mut estimate = (rms * birge.sqrt(), upper * birge_upper.sqrt());
        if terms && cv.fit_variance_mm2 > estimate.0.powi(2) {
            // Every fitted parameter at the campaign's poses: the bound
            // keeps the geometric part's ratio to its mean.
            let ratio = if estimate.0 > 0.0 {
                (estimate.1 / estimate.0).powi(2)
            } else {
                1.0
            };
            estimate = (
                cv.fit_variance_mm2.sqrt(),
                (ratio * cv.fit_variance_mm2).sqrt(),
            );
        }
        let unexplained = unexplained_part(cv);
        let mut parts = Map::new();
        parts.insert("estimate_mm".into(), estimate.0.into());
        parts.insert("estimate_upper_mm".into(), estimate.1.into());
        parts.insert("unexplained_mm".into(), unexplained.0.into());
        parts.insert("unexplained_upper_mm".into(), unexplained.1.into());
        parts.insert("cross_validated_poses".into(), cv.poses.into());
        parts.insert(
            "chi2_per_reading_out_of_sample".into(),
            cv.chi2_per_reading.into(),
        );
        let a = Accuracy::combine(PLATFORM, &[estimate, unexplained], parts);
        if a.rms_mm.is_finite() && a.upper_mm.is_finite() {
            Ok(a)
        } else {
            Err(Error::other(
                "accuracy: the estimate's covariance is not finite",
            ))
        }
    }

    /// This promise with the structure part `(rms_mm, upper_mm)` added in
    /// quadrature.
    pub(crate) fn with_structure(mut self, (rms, upper): (f64, f64)) -> Accuracy {
        self.parts.insert("structure_mm".into(), rms.into());
        self.parts.insert("structure_upper_mm".into(), upper.into());
        self.rms_mm = self.rms_mm.hypot(rms);
        self.upper_mm = self.upper_mm.hypot(upper);
        self
    }

    /// The record a machine file carries (`calibration.accuracy`).
    pub fn record(&self) -> AccuracyRecord {
        AccuracyRecord {
            rms_mm: self.rms_mm,
            upper_mm: self.upper_mm,
            point: self.point.clone(),
            parts: self.parts.clone(),
        }
    }

    /// The JSON object (`accuracy`).
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }

    /// The report's line.
    pub fn line(&self) -> String {
        let part = |k: &str| self.parts.get(k).and_then(Value::as_f64).unwrap_or(0.0);
        let mut s = format!(
            "accuracy this file will deliver: {:.4} mm rms at the {} over the workspace, at most {:.4} mm (95 % bound): estimate {:.4} mm, unexplained out of sample {:.4} mm",
            self.rms_mm,
            self.point,
            self.upper_mm,
            part("estimate_mm"),
            part("unexplained_mm"),
        );
        if let Some(h) = self.parts.get("head_mm").and_then(Value::as_f64) {
            s.push_str(&format!(", head parts not calibrated {h:.4} mm"));
        }
        s
    }
}

/// The promise of `id`, fitted with `model` on `data` (logged noise in
/// `options`) on machine `m`: its first `set.len()` parameters are the
/// geometry of `set`, the rest deployed terms; a model with richer legs
/// checks its geometric estimate (module docs).
pub(crate) fn of_fit(
    m: &Machine,
    set: &ParameterSet,
    model: &ExtendedModel,
    id: &Identification,
    data: &Dataset,
    options: &IdentifyOptions,
    tolerance_mm: f64,
) -> Result<Accuracy, Error> {
    let k = set.len();
    let context = |e: IdentError| Error::with_context("accuracy", &e);
    if id.covariance.nrows() < k {
        return Err(Error::other(format!(
            "accuracy: {} parameters fitted for a set of {k}",
            id.covariance.nrows()
        )));
    }
    let points = AccuracyModel::new(m, set, &tricept_engine::accuracy_points(m), tolerance_mm)
        .map_err(context)?;
    let covariance = id.covariance.view((0, 0), (k, k)).into_owned();
    let held: Vec<usize> = id
        .design()
        .fixed()
        .iter()
        .copied()
        .filter(|&i| i < k)
        .collect();
    let cv = tricept_engine::cross_validate(model, id, &data.poses, m, &options.sigma)
        .map_err(context)?;
    let a = Accuracy::internal(&points, &covariance, &held, &cv, id.covariance.nrows() > k)?;
    let fitted = Fitted {
        points: &points,
        model,
        id,
        covariance: &covariance,
        held: &held,
    };
    let estimate_upper_mm = a
        .parts
        .get("estimate_upper_mm")
        .and_then(Value::as_f64)
        .unwrap_or(0.0);
    let birge_upper = (cv.chi2_per_reading + Z95 * cv.chi2_se).max(1.0);
    let structure = structure_part(&fitted, data, options, estimate_upper_mm, birge_upper)?;
    Ok(a.with_structure(structure))
}

/// A fit whose promise is being made: the evaluation points, the model
/// and its identification, the geometry's covariance and held parameters.
struct Fitted<'a> {
    points: &'a AccuracyModel,
    model: &'a ExtendedModel,
    id: &'a Identification,
    covariance: &'a nalgebra::DMatrix<f64>,
    held: &'a [usize],
}

/// The model of `set` on `m` alone, in `data`'s frame: the base of an
/// internal calibration's structure part.
pub(crate) fn geometric_base(
    geometric: &GeometricModel,
    m: &Machine,
    data: &Dataset,
) -> ExtendedModel {
    ExtendedModel::with_terms(geometric.clone(), &[], Arc::new(Frame::of(m, data)))
}

/// The shift of the geometric estimate over the workspace when every leg
/// may also be a polynomial in its command (a lead, a curved screw), as
/// `(rms_mm, upper_mm)` (module docs): its rms is the shift beyond what
/// chance gives it; its bound is what the structure adds to the
/// estimate's bound `estimate_upper_mm` for the file's error to stay
/// within the bound of its distribution given the data, `N(D, birge_upper
/// S_rich)` ([`posterior_upper`]).
fn structure_part(
    f: &Fitted<'_>,
    data: &Dataset,
    options: &IdentifyOptions,
    estimate_upper_mm: f64,
    birge_upper: f64,
) -> Result<(f64, f64), Error> {
    let k = f.covariance.nrows();
    let legs = Term::Generic(GenericTerm::new(
        GenericFamily::LegPolynomial,
        Scope::AllLegs,
    ));
    let rich = f.model.with(&[f.model.terms(), &[legs]].concat());
    // A richer model that cannot be fitted shows nothing.
    let Ok(r) = tricept_engine::identify(&rich, data, options) else {
        return Ok((0.0, 0.0));
    };
    let delta = nalgebra::DVector::from_fn(k, |i, _| r.estimate[i] - f.id.estimate[i]);
    let shifted = &delta * delta.transpose();
    let rich_cov = r.covariance.view((0, 0), (k, k)).into_owned();
    let context = |e: IdentError| Error::with_context("accuracy", &e);
    let moments = |c: &nalgebra::DMatrix<f64>, held: &[usize]| {
        f.points.error_moments(c, held).map_err(context)
    };
    let (shift, _) = moments(&shifted, &[])?;
    let (chance, _) = moments(&(&rich_cov - f.covariance), &[])?;
    let scaled = rich_cov * birge_upper;
    let (m1, m2) = moments(&scaled, f.held)?;
    let (_, m2_shifted) = moments(&(&scaled + &shifted), f.held)?;
    // D^T M S M D from tr(M (S + D D^T) M (S + D D^T)).
    let cross = 0.5 * (m2_shifted - m2 - shift * shift);
    let upper2 = posterior_upper(shift, m1, m2, cross).powi(2);
    Ok((
        (shift - chance.max(0.0)).max(0.0).sqrt(),
        (upper2 - estimate_upper_mm.powi(2)).max(0.0).sqrt(),
    ))
}

/// The 95 % bound of the rms of an error `e ~ N(d, S)` over the
/// workspace, mm: `e^T M e` has mean `shift + m1` and variance `2 (m2 + 2
/// cross)` (`shift = d^T M d`, `m1 = tr(M S)`, `m2 = tr(M S M S)`, `cross
/// = d^T M S M d`), taken as `g chi2_nu` with those moments ([`estimate_part`]).
pub(crate) fn posterior_upper(shift: f64, m1: f64, m2: f64, cross: f64) -> f64 {
    estimate_part(shift.max(0.0) + m1, m2 + 2.0 * cross.max(0.0)).1
}

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
pub(crate) fn of_fusion(
    model: &tricept_engine::fusion::FusedModel,
    fit: &tricept_engine::fusion::Fusion,
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
        .filter(|s| s.kind != tricept_engine::fusion::SourceKind::Internal)
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
pub(crate) fn fused_structure(
    model: &tricept_engine::fusion::FusedModel,
    fit: &tricept_engine::fusion::Fusion,
    rich_model: &tricept_engine::fusion::FusedModel,
    rich: &tricept_engine::fusion::Fusion,
    eval: &[tricept_data::ExternalPose],
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
fn fused_estimate_mm(fit: &tricept_engine::fusion::Fusion) -> f64 {
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
pub(crate) struct HeadScale {
    /// The moment estimate `c`.
    pub scale: f64,
    /// Its 95 % upper bound.
    pub upper: f64,
    /// Head parameters seen.
    pub seen: usize,
}

/// The size of the head's errors the data show ([`HeadScale`]).
pub(crate) fn head_scale(
    model: &tricept_engine::fusion::FusedModel,
    fit: &tricept_engine::fusion::Fusion,
) -> HeadScale {
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
    pub(crate) fn of(seen: &[(f64, f64, f64)]) -> HeadScale {
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

/// The estimate's rms and 95 % bound from the moments `(tr(MS),
/// tr(MSMS))` of its mean square (module docs).
pub(crate) fn estimate_part(m1: f64, m2: f64) -> (f64, f64) {
    if !(m1 > 0.0 && m2 > 0.0) {
        let m = m1.max(0.0).sqrt();
        return (m, m);
    }
    let g = m2 / m1;
    let nu = m1 * m1 / m2;
    let a = 2.0 / (9.0 * nu);
    let q = g * nu * (1.0 - a + Z95 * a.sqrt()).max(0.0).powi(3);
    (m1.sqrt(), q.max(m1).sqrt())
}

/// The unexplained part's rms and 95 % bound (module docs).
pub(crate) fn unexplained_part(cv: &CrossValidation) -> (f64, f64) {
    (
        cv.excess_mm2.max(0.0).sqrt(),
        (cv.excess_mm2 + Z95 * cv.excess_se_mm2).max(0.0).sqrt(),
    )
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

    #[test]
    fn the_estimate_bound_is_the_chi_square_quantile() {
        // One parameter: e^T M e = m1 chi2_1, whose 95 % quantile is 3.84
        // (Wilson-Hilferty gives 3.7 at one degree of freedom).
        let (rms, upper) = estimate_part(4.0, 16.0);
        assert!((rms - 2.0).abs() < 1e-12);
        let q = upper * upper / 4.0;
        assert!((3.5..4.0).contains(&q), "{q}");
        // Many equal parameters: the mean square concentrates at its mean.
        let (rms, upper) = estimate_part(1.0, 1e-4);
        assert!(
            (rms - 1.0).abs() < 1e-12 && upper > 1.0 && upper < 1.02,
            "{upper}"
        );
    }

    #[test]
    fn the_posterior_bound_follows_the_shift_and_its_spread() {
        // No shift: the bound of the spread alone.
        assert_eq!(
            posterior_upper(0.0, 4.0, 16.0, 0.0),
            estimate_part(4.0, 16.0).1
        );
        // One dimension, e ~ N(10, 1): e^2's 95 % quantile is (10 +
        // 1.645)^2 = 135.6 (the other tail is negligible).
        let upper = posterior_upper(100.0, 1.0, 1.0, 100.0);
        assert!((upper - 11.645).abs() < 0.05, "{upper}");
        // The shift's spread counts: without it the bound is too tight.
        let tight = posterior_upper(100.0, 1.0, 1.0, 0.0);
        assert!(tight < 11.3, "{tight}");
        // A larger shift, a larger bound; a negative one is no shift.
        assert!(posterior_upper(4.0, 1.0, 1.0, 4.0) > posterior_upper(1.0, 1.0, 1.0, 1.0));
        assert_eq!(
            posterior_upper(-1.0, 1.0, 1.0, 0.0),
            posterior_upper(0.0, 1.0, 1.0, 0.0)
        );
    }
}
