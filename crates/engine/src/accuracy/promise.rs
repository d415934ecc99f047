//! The accuracy promise: what a machine file will deliver, stated by every
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
//!   `sqrt(trace(M S))` of [`AccuracyModel`]; for a model
//!   with more than the geometry (a diagnosis' deployed terms) the larger
//!   of that and every fitted parameter's platform variance at the
//!   campaign's poses ([`CrossValidation::fit_variance_mm2`]);
//! - **unexplained**: the mean square platform error the fitted model
//!   leaves out of sample beyond the stated noise, from the deleted
//!   residuals of the UP limb's readings mapped to the platform through the
//!   limb's Jacobian ([`cross_validate`]), never below
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

//!
//! The promise of a fused fit (tool tip) is [`super::fused`]'s.

use serde::Serialize;
use serde_json::{Map, Value};

use tricept_data::Dataset;
use tricept_kinematics::Machine;
use tricept_kinematics::description::AccuracyRecord;
use tricept_model::ParameterSet;

use super::cross_validation::{CrossValidation, cross_validate};
use super::{AccuracyModel, accuracy_points};
use crate::{IdentError, Identification, IdentifyOptions, model::ReadingModel};

/// Why a promise could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PromiseError {
    /// A computation it is made of failed.
    #[error(transparent)]
    Ident(#[from] IdentError),
    /// The fit is not one a promise can be made of (its message says why).
    #[error("{0}")]
    Inconsistent(String),
}

/// The one-sided 95 % standard normal quantile.
pub(crate) const Z95: f64 = 1.644_853_626_951_472_2;

/// The point a promise is of: the platform (UP limb alone) or the tool tip
/// (after touch-off, where that applies).
pub const PLATFORM: &str = "platform";

/// The point of a fused file's promise.
pub const TOOL_TIP: &str = "tool tip";

/// The accuracy a machine file will deliver: the top-level `accuracy`
/// object of every verb that writes one.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::accuracy::Accuracy;
let a = Accuracy::combine("platform", &[(0.003, 0.004), (0.004, 0.006)], Default::default());
assert!((a.rms_mm - 0.005).abs() < 1e-12);
assert!(a.upper_mm >= a.rms_mm);
```
"#
)]
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
    ) -> Result<Accuracy, PromiseError> {
        let (m1, m2) = model.error_moments(covariance, held)?;
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
            Err(PromiseError::Inconsistent(
                "accuracy: the estimate's covariance is not finite".into(),
            ))
        }
    }

    /// This promise with the structure part `(rms_mm, upper_mm)` added in
    /// quadrature.
    pub fn with_structure(mut self, (rms, upper): (f64, f64)) -> Accuracy {
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

/// The fit a promise is made of: `id`, fitted with `model` on `data`
/// (logged noise in `options`) on machine `m`; its first `set.len()`
/// parameters are the geometry of `set`, the rest deployed terms; `rich`
/// is `model` with every leg also a polynomial in its command, which
/// checks the geometric estimate (module docs).
#[derive(Clone, Copy)]
pub struct Fit<'a> {
    /// The machine.
    pub machine: &'a Machine,
    /// The geometric parameter set.
    pub set: &'a ParameterSet,
    /// The fitted model.
    pub model: &'a dyn ReadingModel,
    /// The same model with richer legs.
    pub rich: &'a dyn ReadingModel,
    /// The identification.
    pub id: &'a Identification,
    /// The data fitted.
    pub data: &'a Dataset,
    /// The fit's options (its logged noise).
    pub options: &'a IdentifyOptions,
}

/// The promise of a fit ([`of_fit`]) with its report line
/// ([`Accuracy::line`]), made in one pass: the identify walk states it where
/// it makes it.
pub fn of_fit_stated(fit: &Fit<'_>, tolerance_mm: f64) -> Result<(Accuracy, String), PromiseError> {
    let promise = of_fit(fit, tolerance_mm)?;
    let line = promise.line();
    Ok((promise, line))
}

/// The promise of a fit ([`Fit`]), held parameters at `tolerance_mm`.
pub fn of_fit(fit: &Fit<'_>, tolerance_mm: f64) -> Result<Accuracy, PromiseError> {
    let &Fit {
        machine: m,
        set,
        model,
        rich,
        id,
        data,
        options,
    } = fit;
    let k = set.len();
    if id.covariance.nrows() < k {
        return Err(PromiseError::Inconsistent(format!(
            "accuracy: {} parameters fitted for a set of {k}",
            id.covariance.nrows()
        )));
    }
    let points = AccuracyModel::new(m, set, &accuracy_points(m), tolerance_mm)?;
    let covariance = id.covariance.view((0, 0), (k, k)).into_owned();
    let held: Vec<usize> = id
        .design()
        .fixed()
        .iter()
        .copied()
        .filter(|&i| i < k)
        .collect();
    let cv = cross_validate(model, id, &data.poses, m, &options.sigma)?;
    let a = Accuracy::internal(&points, &covariance, &held, &cv, id.covariance.nrows() > k)?;
    let fitted = Fitted {
        points: &points,
        rich,
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
    rich: &'a dyn ReadingModel,
    id: &'a Identification,
    covariance: &'a nalgebra::DMatrix<f64>,
    held: &'a [usize],
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
) -> Result<(f64, f64), PromiseError> {
    let k = f.covariance.nrows();
    // A richer model that cannot be fitted shows nothing.
    let Ok(r) = crate::identify(f.rich, data, options) else {
        return Ok((0.0, 0.0));
    };
    let delta = nalgebra::DVector::from_fn(k, |i, _| r.estimate[i] - f.id.estimate[i]);
    let shifted = &delta * delta.transpose();
    let rich_cov = r.covariance.view((0, 0), (k, k)).into_owned();
    let moments = |c: &nalgebra::DMatrix<f64>, held: &[usize]| f.points.error_moments(c, held);
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
pub fn posterior_upper(shift: f64, m1: f64, m2: f64, cross: f64) -> f64 {
    estimate_part(shift.max(0.0) + m1, m2 + 2.0 * cross.max(0.0)).1
}

/// The estimate's rms and 95 % bound from the moments `(tr(MS),
/// tr(MSMS))` of its mean square (module docs).
pub fn estimate_part(m1: f64, m2: f64) -> (f64, f64) {
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
pub fn unexplained_part(cv: &CrossValidation) -> (f64, f64) {
    (
        cv.excess_mm2.max(0.0).sqrt(),
        (cv.excess_mm2 + Z95 * cv.excess_se_mm2).max(0.0).sqrt(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

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
