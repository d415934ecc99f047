//! Robust estimation: a gross reading error must not wreck the
//! identification.
//!
//! After a fit, every pose's readings are standardised by the sensor noise
//! and by a robust scale of the residuals (1.4826 times their median
//! absolute value per channel, never below the noise, so that a systematic
//! misfit is not mistaken for gross errors). A pose with a reading beyond the
//! Bonferroni-corrected normal quantile for the `3 n` readings (family-wise
//! level 0.001 by default) is rejected and the fit repeated on the others,
//! until the set of rejected poses no longer changes. Rejected rows are
//! reported by their line in the data file; at most a stated share of the
//! poses may be rejected (more is a model problem, not gross errors, and
//! nothing is rejected).

use serde::Serialize;
use tricept_data::{Dataset, MeasuredPose};
use tricept_kinematics::UpJoints;

use crate::error::IdentError;
use crate::identify::{Identification, IdentifyOptions, identify};
use crate::model::ReadingModel;
use tricept_numerics::stats::chi2_isf;

/// A rejected pose.
///
/// # Example
/// ```
/// use tricept_ident::{GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let mut data = data;
/// data.poses[3].readings.phi_rad += 1e-3; // a 206 arcsec glitch
/// data.poses[3].line = 42;
/// let (_, rejected) = tricept_ident::identify_robust(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// assert_eq!(rejected[0].line, 42);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rejection {
    /// Index of the pose in the data.
    pub pose: usize,
    /// Its line in the data file.
    pub line: u64,
    /// Its largest standardised residual.
    pub residual_sigma: f64,
}

/// Weighted residuals `(y - g(p) - c) / sigma` of `poses` under `model` at
/// `estimate` with sensor offsets `offsets`; `None` where the pose cannot be
/// solved. An `estimate` of the wrong length is an [`IdentError::Invalid`].
///
/// # Example
/// ```
/// use tricept_ident::{GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let id = tricept_ident::identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// let r = tricept_ident::residuals_at(&model, &id.estimate, &id.offsets, &data.poses, &m.sensors.logged_sigma()).unwrap();
/// // In noise units: of order one.
/// assert!(r.iter().flatten().all(|v| v.iter().all(|x| x.abs() < 5.0)));
/// ```
pub fn residuals_at(
    model: &dyn ReadingModel,
    estimate: &[f64],
    offsets: &[f64; 3],
    poses: &[MeasuredPose],
    sigma: &[f64; 3],
) -> Result<Vec<Option<[f64; 3]>>, IdentError> {
    if estimate.len() != model.names().len() {
        return Err(IdentError::Invalid(format!(
            "{} parameter values for {} parameters",
            estimate.len(),
            model.names().len()
        )));
    }
    let predictor = model.at(estimate);
    let mut jac = vec![0.0; 3 * estimate.len()];
    Ok(poses
        .iter()
        .map(|p| {
            let mut seed: Option<UpJoints> = None;
            predictor.predict(p, &mut seed, &mut jac).ok().map(|g| {
                let y = p.readings.to_array();
                [0, 1, 2].map(|c| (y[c] - g[c] - offsets[c]) / sigma[c])
            })
        })
        .collect())
}

/// `data` without the rejected poses.
fn kept(data: &Dataset, rejected: &[Rejection]) -> Dataset {
    data.subset(|j| !rejected.iter().any(|r| r.pose == j))
}

/// The poses whose readings are gross errors (see the module docs), at
/// family-wise level `alpha`, at most `max_share` of them.
///
/// # Example
/// ```
/// use tricept_ident::{GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let rejected = tricept_ident::screen_gross_errors(&model, &data, &IdentifyOptions::for_machine(&m), 1e-3, 0.1).unwrap();
/// assert!(rejected.is_empty()); // clean data lose nothing
/// ```
pub fn screen_gross_errors(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
    alpha: f64,
    max_share: f64,
) -> Result<Vec<Rejection>, IdentError> {
    let n = data.poses.len();
    let z_crit = chi2_isf(alpha / (3 * n) as f64, 1.0).sqrt();
    let mut rejected: Vec<Rejection> = Vec::new();
    for _ in 0..4 {
        let id = identify(model, &kept(data, &rejected), options)?;
        let res = residuals_at(
            model,
            &id.estimate,
            &id.offsets,
            &data.poses,
            &options.sigma,
        )?;
        let kept = |j: usize| !rejected.iter().any(|r| r.pose == j);
        let scale: [f64; 3] = std::array::from_fn(|c| {
            let mut v: Vec<f64> = res
                .iter()
                .enumerate()
                .filter(|(j, _)| kept(*j))
                .filter_map(|(_, r)| r.map(|r| r[c].abs()))
                .collect();
            v.sort_by(f64::total_cmp);
            (v.get(v.len() / 2).copied().unwrap_or(0.0) * 1.4826).max(1.0)
        });
        let next: Vec<Rejection> = res
            .iter()
            .enumerate()
            .filter_map(|(j, r)| {
                let z = match r {
                    Some(r) => (0..3).map(|c| r[c].abs() / scale[c]).fold(0.0, f64::max),
                    None => f64::INFINITY,
                };
                (z > z_crit).then(|| Rejection {
                    pose: j,
                    line: data.poses[j].line,
                    residual_sigma: z,
                })
            })
            .collect();
        if (next.len() as f64) > max_share * n as f64 {
            return Ok(Vec::new());
        }
        let same = next.len() == rejected.len()
            && next.iter().zip(&rejected).all(|(a, b)| a.pose == b.pose);
        rejected = next;
        if same {
            break;
        }
    }
    Ok(rejected)
}

/// [`identify`] after rejecting gross errors (family-wise level 0.001, at
/// most 10 % of the poses); returns the identification on the kept poses
/// and the rejected ones.
///
/// # Example
/// ```
/// use tricept_ident::{identify_robust, GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let mut data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&Campaign::grid(&m, 3))
///     .unwrap();
/// data.poses[10].readings.s_mm += 0.05; // a 50 um misread of the scale
/// let model = GeometricModel::new(m.clone(), set);
/// let (id, rejected) = identify_robust(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// assert_eq!(rejected.len(), 1);
/// assert_eq!(rejected[0].pose, 10);
/// assert!(id.stats.reduced_chi_square < 1.5);
/// ```
pub fn identify_robust(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
) -> Result<(Identification, Vec<Rejection>), IdentError> {
    let rejected = screen_gross_errors(model, data, options, 1e-3, 0.1)?;
    let id = identify(model, &kept(data, &rejected), options)?;
    Ok((id, rejected))
}
