//! What a fit leaves unexplained out of sample, in platform millimetres:
//! the raw material of the accuracy a machine file promises
//! (`docs/reliability.md`, "The accuracy block").
//!
//! The UP limb's readings `(phi, theta, s)` measure the platform's position
//! at the commanded leg lengths, so a reading residual `d` is a platform
//! error `J d`, with `J` the limb's point Jacobian at the pose
//! ([`tricept_kinematics::up_limb::UpLimbPose::point_jacobian`]). The residual of a
//! pose the fit has seen is too small; its **deleted** (leave-one-pose-out)
//! residual, `d_j = W^-1 (I - H_jj)^-1 W (y_j - g_j - c)` with `H_jj` the
//! pose's 3 x 3 block of the weighted hat matrix and `W = diag(1/sigma)`, is
//! what the model fitted without the pose predicts there, exactly for a
//! linear model and to first order here. Under the stated noise alone its
//! covariance is `W^-1 (I - H_jj)^-1 W^-1`, so per pose
//!
//! ```text
//! x_j = |J_j d_j|^2 - trace(J_j W^-1 (I - H_jj)^-1 W^-1 J_j^T)     (mm^2)
//! ```
//!
//! has mean zero when the model explains the data to the noise, and the
//! mean square of the platform error the model leaves unexplained
//! otherwise. [`CrossValidation`] holds their mean and its standard
//! error, and the fit's own platform variance at the poses
//! (`trace(J_j X_j C X_j^T J_j^T)`, every fitted parameter's covariance `C`
//! with the pose's Jacobian `X_j`; the sensor offsets move no platform).

use nalgebra::{DMatrix, Matrix3};
use serde::Serialize;
use tricept_data::MeasuredPose;
use tricept_kinematics::{Machine, up_limb::UpJoints};

use crate::error::IdentError;
use crate::evaluate::map_blocks;
use crate::identify::Identification;
use crate::model::ReadingModel;

/// The platform error a fit leaves unexplained out of sample, over the
/// poses it was fitted on (see the module docs).
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, accuracy::cross_validation::cross_validate, identify};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let model = GeometricModel::new(m.clone(), set);
/// let options = IdentifyOptions::for_machine(&m);
/// let id = identify(&model, &data, &options).unwrap();
/// let cv = cross_validate(&model, &id, &data.poses, &m, &options.sigma).unwrap();
/// // The model explains the data to the noise: nothing is left over but
/// // chance, well below a micrometre squared.
/// assert_eq!(cv.poses, data.poses.len());
/// assert!(cv.excess_mm2.abs() < 1e-6 + 3.0 * cv.excess_se_mm2);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CrossValidation {
    /// Poses whose deleted residual could be formed.
    pub poses: usize,
    /// Mean of `x_j`: the mean square platform error beyond the noise, mm^2
    /// (negative by chance when there is none).
    pub excess_mm2: f64,
    /// Standard error of that mean, mm^2.
    pub excess_se_mm2: f64,
    /// Mean over the poses of the fit's platform variance, mm^2.
    pub fit_variance_mm2: f64,
    /// Mean of the noise's share `trace(J W^-1 (I - H)^-1 W^-1 J^T)`, mm^2.
    pub noise_mm2: f64,
    /// The deleted residuals' chi-square per reading, `mean_j T_j / 3`
    /// with `T_j = e_j^T (I - H_jj)^-1 e_j` (`e_j` weighted): 1 under the
    /// stated noise alone (a Birge ratio out of sample).
    pub chi2_per_reading: f64,
    /// Standard error of that mean.
    pub chi2_se: f64,
}

/// The [`CrossValidation`] of `id` (fitted with `model` on `poses`, logged
/// noise `sigma`), its limb Jacobians taken on `machine`'s UP limb.
pub fn cross_validate(
    model: &dyn ReadingModel,
    id: &Identification,
    poses: &[MeasuredPose],
    machine: &Machine,
    sigma: &[f64; 3],
) -> Result<CrossValidation, IdentError> {
    let k = model.names().len();
    if id.estimate.len() != k || id.full_covariance.nrows() != 3 * id.campaign_offsets.len() + k {
        return Err(IdentError::Invalid(format!(
            "an identification of {} parameters for a model of {k}",
            id.estimate.len()
        )));
    }
    if sigma.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(IdentError::Invalid(format!(
            "the logged noise must be positive, got {sigma:?}"
        )));
    }
    // Per campaign: its offsets and the covariance of [its offsets |
    // identifiable parameters], the columns its poses' rows touch.
    let identifiable = id.design().identifiable();
    let q = 3 + identifiable.len();
    let blocks: Vec<([f64; 3], DMatrix<f64>)> = id
        .campaign_blocks()
        .into_iter()
        .map(|(o, c)| (o, DMatrix::from_row_slice(q, q, &c)))
        .collect();
    let predictor = model.at(&id.estimate);
    let w = Matrix3::from_diagonal(&nalgebra::Vector3::from_fn(|i, _| 1.0 / sigma[i]));
    let w_inv = Matrix3::from_diagonal(&nalgebra::Vector3::from_fn(|i, _| sigma[i]));
    // (x_j, fit variance, noise share, T_j / 3) of every pose that can be
    // solved.
    let terms: Vec<Option<(f64, f64, f64, f64)>> = map_blocks(poses, |_, block| {
        let mut jac = vec![0.0; 3 * k];
        Ok(block
            .iter()
            .map(|p| {
                let mut seed: Option<UpJoints> = None;
                let g = predictor.predict(p, &mut seed, &mut jac).ok()?;
                let (offsets, cov) = &blocks[id.campaign_of(p)?];
                let y = p.readings.to_array();
                let e = nalgebra::Vector3::from_fn(|r, _| y[r] - g[r] - offsets[r]);
                // X_j: the pose's unweighted rows [its offsets | identifiable].
                let x = DMatrix::from_fn(3, q, |r, t| {
                    if t < 3 {
                        f64::from(u8::from(t == r))
                    } else {
                        jac[r * k + identifiable[t - 3]]
                    }
                });
                let xw =
                    DMatrix::from_diagonal(&nalgebra::DVector::from_fn(3, |r, _| 1.0 / sigma[r]))
                        * &x;
                let h = &xw * cov * xw.transpose();
                let h = Matrix3::from_fn(|a, b| h[(a, b)]);
                let inv = (Matrix3::identity() - h).try_inverse()?;
                let limb = machine.up_limb.pose(&UpJoints::from_array(g));
                let jl = limb.point_jacobian(&limb.position_mm);
                let deleted = w_inv * inv * w * e;
                let noise = (jl * w_inv * inv * w_inv * jl.transpose()).trace();
                // The fit's platform variance: the parameter columns only.
                let jx = DMatrix::from_fn(3, q, |r, t| {
                    (0..3).map(|s| jl[(r, s)] * x[(s, t)]).sum::<f64>()
                });
                let jx_p = jx.columns(3, q - 3);
                let cov_p = cov.view((3, 3), (q - 3, q - 3));
                let fit = (jx_p * cov_p * jx_p.transpose()).trace();
                let x_j = (jl * deleted).norm_squared() - noise;
                let ew = w * e;
                let t_j = (ew.transpose() * inv * ew)[0] / 3.0;
                (x_j.is_finite() && fit.is_finite() && t_j.is_finite()).then_some((
                    x_j,
                    fit.max(0.0),
                    noise,
                    t_j,
                ))
            })
            .collect())
    })?;
    let kept: Vec<(f64, f64, f64, f64)> = terms.into_iter().flatten().collect();
    let n = kept.len();
    if n < 2 {
        return Err(IdentError::Invalid(
            "fewer than two poses to cross-validate".into(),
        ));
    }
    let nf = n as f64;
    let (mean, se) = mean_se(kept.iter().map(|t| t.0), nf);
    let (chi2, chi2_se) = mean_se(kept.iter().map(|t| t.3), nf);
    Ok(CrossValidation {
        poses: n,
        excess_mm2: mean,
        excess_se_mm2: se,
        chi2_per_reading: chi2,
        chi2_se,
        fit_variance_mm2: kept.iter().map(|t| t.1).sum::<f64>() / nf,
        noise_mm2: kept.iter().map(|t| t.2).sum::<f64>() / nf,
    })
}

/// The mean of `n` values and its standard error.
fn mean_se(values: impl Iterator<Item = f64> + Clone, n: f64) -> (f64, f64) {
    let mean = values.clone().sum::<f64>() / n;
    let var = values.map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}
