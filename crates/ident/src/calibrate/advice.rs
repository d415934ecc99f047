//! The accuracy a calibration predicts on the platform, against the
//! manufacturing tolerance, and the campaign advice of a campaign too small
//! to calibrate: how many and which poses would be worthwhile.

use tricept_engine::accuracy::{AccuracyModel, PredictedAccuracy, accuracy_points};
use tricept_engine::{IdentError, Identification};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;

use crate::error::Error;

/// The platform accuracy `id` predicts on `m`'s workspace (at
/// [`tricept_engine::accuracy::accuracy_points`]) against the tolerance
/// `tolerance_mm` per parameter.
pub(crate) fn predicted_accuracy(
    m: &Machine,
    set: &ParameterSet,
    id: &Identification,
    tolerance_mm: f64,
) -> Result<PredictedAccuracy, Error> {
    let model =
        AccuracyModel::new(m, set, &accuracy_points(m), tolerance_mm).map_err(|e| match e {
            IdentError::Invalid(why) => Error::invalid(crate::Setting::ToleranceMm, why),
            e => Error::with_context("predicted accuracy", e),
        })?;
    model
        .assess(&id.covariance, id.design().fixed())
        .map_err(|e| Error::with_context("predicted accuracy", e))
}

/// Why a campaign of `poses` poses cannot calibrate (its predicted accuracy
/// `a`), and how many and which poses would.
pub(crate) fn campaign_advice(
    m: &Machine,
    set: &ParameterSet,
    a: &PredictedAccuracy,
    poses: usize,
) -> Result<String, Error> {
    let model = AccuracyModel::new(m, set, &accuracy_points(m), a.tolerance_mm)
        .map_err(|e| Error::with_context("campaign advice", e))?;
    let (optimal, random) = tricept_study::campaign::worthwhile_campaigns(m, set, &model)
        .map_err(|e| Error::with_context("campaign advice", e))?;
    let fix = match (optimal, random) {
        (Some(o), Some(r)) => format!(
            "{} D-optimal poses (poses `optimal:{}`, predicted {:.3} mm) or {} random poses over the workspace (poses `random:{},1`, predicted {:.3} mm) would be worthwhile",
            o.poses, o.poses, o.predicted.after_rms_mm, r.poses, r.poses, r.predicted.after_rms_mm
        ),
        (Some(o), None) => format!(
            "{} D-optimal poses (poses `optimal:{}`, predicted {:.3} mm) would be worthwhile",
            o.poses, o.poses, o.predicted.after_rms_mm
        ),
        _ => "no campaign of up to 200 poses of these sensors would be: better sensors or external measurements are needed (docs/hybrid.md)".to_string(),
    };
    Ok(format!(
        "this campaign cannot calibrate the machine: the predicted platform error after calibration is {:.3} mm rms (up to {:.3} mm), against {:.3} mm for a machine built to {} mm per parameter and not calibrated; a calibration must at least halve it. {poses} poses are too few or too poorly spread: {fix}",
        a.after_rms_mm, a.after_max_mm, a.before_rms_mm, a.tolerance_mm
    ))
}
