//! Robust estimation: a gross reading error of any size must not wreck the
//! identification, in a campaign of any size.
//!
//! The screen ([`screen_gross_errors`]) works in two stages, so that its
//! breakdown does not depend on the number of poses:
//!
//! 1. **Robust start.** Every pose is predicted by the *nominal* machine;
//!    per channel the residuals are centred on their median and scaled by
//!    1.4826 times their median absolute deviation (never below the sensor
//!    noise). Geometric errors move these residuals smoothly over the
//!    workspace, so an ordinary pose stays within a few scale units, while
//!    a misread scale, an encoder jump, swapped columns or a unit slip lies
//!    tens to thousands of units away. The first fit uses only the poses
//!    within [`START_Z`] units (at least half of them: the ones nearest the
//!    median, as a least-trimmed-squares start would).
//! 2. **Deleted residuals, one pose at a time.** At the current fit every
//!    pose gets the statistic `T_j = e_j^T (I -+ H_jj)^-1 e_j / s^2`: for a
//!    pose in the fit its deleted (leave-one-pose-out) residual, with
//!    `H_jj = X_j C X_j^T` the pose's 3 x 3 block of the hat matrix; for a
//!    pose outside, its prediction residual; `s^2` the fit's reduced
//!    chi-square (never below 1, externally studentised), so that a
//!    systematic misfit is not taken for gross errors. Poses outside the fit
//!    whose `T_j` is below the Bonferroni criterion `chi2_3(1 - alpha / n)`
//!    are taken back; otherwise the single worst pose in the fit above it is
//!    set aside; the fit is repeated until nothing changes.
//!
//! At most a stated share of the poses (and never fewer than two) may end
//! up rejected: more is a model problem, not gross errors, and then nothing
//! is rejected (the fit on all poses tells the rest). The cap is applied to
//! the final set, not to an intermediate one, so that one gross reading
//! that smears an early fit cannot hide itself behind the poses it drags
//! along. Rejected rows are reported by their line in the data file. The
//! same screen serves `tricept identify` and `tricept diagnose`.

use nalgebra::Matrix3;
use serde::Serialize;
use tricept_data::{Dataset, MeasuredPose};
use tricept_kinematics::up_limb::UpJoints;
use tricept_numerics::stats::chi2_isf;

use crate::error::IdentError;
use crate::evaluate::map_blocks;
use crate::identify::{FirstEvaluation, Identification, Start, fit, identify};
use crate::model::ReadingModel;
use crate::options::IdentifyOptions;

/// Largest robust z-score (residual at the nominal machine, in units of
/// the larger of the sensor noise and 1.4826 MAD) of a pose in the first
/// fit of the screen.
pub const START_Z: f64 = 10.0;

/// A rejected pose.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let set = ParameterSet::paper15();
let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
    .simulate(&tricept_plant::Campaign::grid(&m, 1))
    .unwrap();
let mut data = data;
data.poses[3].readings.phi_rad += 1e-3; // a 206 arcsec glitch
data.poses[3].line = 42;
let (_, rejected) = tricept_engine::robust::identify_robust(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
assert_eq!(rejected[0].line, 42);
```
"#
)]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rejection {
    /// Index of the pose in the data.
    pub pose: usize,
    /// Its line in the data file.
    pub line: u64,
    /// Its deleted residual in noise standard deviations (`sqrt(T_j)`,
    /// see the module docs); `None` when the fitted model cannot solve the
    /// pose at all (its commands cannot be reached).
    pub residual_sigma: Option<f64>,
}

/// Weighted residuals `(y - g(p) - c) / sigma` of `poses` under `model` at
/// `estimate` with sensor offsets `offsets`; `None` where the pose cannot be
/// solved. An `estimate` of the wrong length is an [`IdentError::Invalid`].
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let id = tricept_engine::identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// let r = tricept_engine::robust::residuals_at(&model, &id.estimate, &id.offsets, &data.poses, &m.sensors.logged_sigma()).unwrap();
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
/// family-wise level `alpha`, at most `max_share` of them (and never fewer
/// than two may be).
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let set = ParameterSet::paper15();
/// let mut data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let options = IdentifyOptions::for_machine(&m);
/// let rejected = tricept_engine::robust::screen_gross_errors(&model, &data, &options, 1e-3, 0.1).unwrap();
/// assert!(rejected.is_empty()); // clean data lose nothing
/// data.poses[6].readings.s_mm += 10.0; // a 10 mm misread of the scale
/// let rejected = tricept_engine::robust::screen_gross_errors(&model, &data, &options, 1e-3, 0.1).unwrap();
/// assert_eq!(rejected.iter().map(|r| r.pose).collect::<Vec<_>>(), vec![6]);
/// ```
pub fn screen_gross_errors(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
    alpha: f64,
    max_share: f64,
) -> Result<Vec<Rejection>, IdentError> {
    Ok(screen_gross_errors_with_fit(model, data, options, alpha, max_share)?.0)
}

/// [`screen_gross_errors`] with the screen's last fit when it was made on
/// exactly the poses kept: the same [`Identification`] as [`identify`] on
/// them, bit for bit, which a caller need not repeat. `None` when the
/// share cap cleared the rejections (the last fit was of fewer poses).
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, identify, robust::screen_gross_errors_with_fit};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let model = GeometricModel::new(m.clone(), set.clone());
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// let options = IdentifyOptions::for_machine(&m);
/// let (rejected, fit) = screen_gross_errors_with_fit(&model, &data, &options, 1e-3, 0.1).unwrap();
/// assert!(rejected.is_empty());
/// let direct = identify(&model, &data, &options).unwrap();
/// assert_eq!(fit.unwrap().estimate, direct.estimate);
/// ```
pub fn screen_gross_errors_with_fit(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
    alpha: f64,
    max_share: f64,
) -> Result<(Vec<Rejection>, Option<Identification>), IdentError> {
    let n = data.poses.len();
    let cap = ((max_share * n as f64).floor() as usize).max(2);
    let crit = chi2_isf(alpha / n.max(1) as f64, 3.0);
    let (mut inside, mut first) = robust_start(model, data, options)?;
    let mut seen: Vec<Vec<bool>> = Vec::new();
    let mut last: Option<(Vec<bool>, Vec<Option<f64>>, Identification)> = None;
    for _ in 0..(2 * n + 4) {
        if seen.contains(&inside) {
            break;
        }
        seen.push(inside.clone());
        // Every fit starts from the nominal machine, where the rank decision
        // is taken (a start at an earlier estimate would decide the rank at
        // another point and could free a parameter that is invisible to
        // first order).
        let subset;
        let (fitted, first) = if inside.iter().all(|x| *x) {
            // The robust start's evaluation at the nominal machine is this
            // fit's first one.
            (data, first.take())
        } else {
            subset = data.subset(|j| inside[j]);
            (&subset, None)
        };
        let (id, fk) = match fit(model, fitted, options, &Start::default(), first) {
            Ok(fit) => fit,
            // Too few poses left, or a pose the start set cannot solve:
            // fall back to the previous set.
            Err(_) if last.is_some() => break,
            Err(e) => return Err(e),
        };
        // The fit's FK solutions start the FK of its poses again.
        let mut fk = fk.into_iter();
        let seeds: Vec<Option<UpJoints>> = inside
            .iter()
            .map(|&i| if i { fk.next().flatten() } else { None })
            .collect();
        let t = deleted_residuals(model, &id, data, &inside, &seeds, options)?;
        let mut next = inside.clone();
        let mut changed = false;
        for j in 0..n {
            if !inside[j] && t[j].is_some_and(|t| t <= crit) {
                next[j] = true;
                changed = true;
            }
        }
        if !changed {
            let worst = (0..n)
                .filter(|&j| inside[j])
                .filter_map(|j| t[j].map(|t| (j, t)))
                .filter(|(_, t)| *t > crit)
                .max_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((j, _)) = worst {
                next[j] = false;
                changed = true;
            }
        }
        last = Some((inside.clone(), t, id));
        if !changed {
            break;
        }
        inside = next;
    }
    let Some((inside, t, id)) = last else {
        return Ok((Vec::new(), None));
    };
    let rejected: Vec<Rejection> = (0..n)
        .filter(|&j| !inside[j])
        .map(|j| Rejection {
            pose: j,
            line: data.poses[j].line,
            residual_sigma: t[j].map(f64::sqrt),
        })
        .collect();
    if rejected.len() > cap {
        return Ok((Vec::new(), None));
    }
    Ok((rejected, Some(id)))
}

/// Which poses enter the first fit (stage 1 of the module docs), and the
/// evaluation of the model at the nominal machine over all poses that
/// gave their residuals (the first evaluation of a fit on all of them). A
/// pose the nominal machine cannot solve is an input error (its commands
/// cannot be reached), not a gross reading.
fn robust_start(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
) -> Result<(Vec<bool>, Option<FirstEvaluation>), IdentError> {
    let k = model.names().len();
    let first = FirstEvaluation::new(model, &vec![0.0; k], &data.poses, &options.sigma)?;
    let median = |mut v: Vec<f64>| -> f64 { tricept_numerics::stats::median(&mut v) };
    // Centre and scale per campaign: each campaign's offsets are its own.
    let mut z = vec![0.0; data.poses.len()];
    let mut campaigns: Vec<u32> = data.poses.iter().map(|p| p.campaign).collect();
    campaigns.sort_unstable();
    campaigns.dedup();
    for campaign in campaigns {
        let members: Vec<usize> = (0..data.poses.len())
            .filter(|&j| data.poses[j].campaign == campaign)
            .collect();
        let residual = |j: usize, c: usize| first.residuals()[j][c];
        let centre: [f64; 3] =
            std::array::from_fn(|c| median(members.iter().map(|&j| residual(j, c)).collect()));
        let scale: [f64; 3] = std::array::from_fn(|c| {
            let mad = median(
                members
                    .iter()
                    .map(|&j| (residual(j, c) - centre[c]).abs())
                    .collect(),
            );
            let s = 1.4826 * mad;
            if s.is_finite() {
                s.max(options.sigma[c])
            } else {
                options.sigma[c]
            }
        });
        for &j in &members {
            z[j] = (0..3)
                .map(|c| (residual(j, c) - centre[c]).abs() / scale[c])
                .fold(0.0, f64::max);
        }
    }
    Ok((start_set(&z), Some(first)))
}

/// The records of the first fit from their robust scores `z`: those within
/// [`START_Z`], or the half with the smallest scores when fewer are.
pub(crate) fn start_set(z: &[f64]) -> Vec<bool> {
    let n = z.len();
    let mut inside: Vec<bool> = z.iter().map(|z| *z <= START_Z).collect();
    let half = n.div_ceil(2);
    if inside.iter().filter(|x| **x).count() < half {
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|a, b| z[*a].total_cmp(&z[*b]));
        inside = vec![false; n];
        for &j in &order[..half] {
            inside[j] = z[j].is_finite();
        }
    }
    inside
}

/// The statistic `T_j` of every pose at fit `id` made on the poses marked
/// `inside` (stage 2 of the module docs); `None` where the fitted model
/// cannot solve the pose. One pass over the poses, with the fit's own
/// covariance `C` of `[offsets | identifiable parameters]`: nothing per
/// pose is kept but its statistic.
fn deleted_residuals(
    model: &dyn ReadingModel,
    id: &Identification,
    data: &Dataset,
    inside: &[bool],
    seeds: &[Option<UpJoints>],
    options: &IdentifyOptions,
) -> Result<Vec<Option<f64>>, IdentError> {
    let k = model.names().len();
    let q = 3 + id.design().rank();
    let identifiable = id.design().identifiable();
    let blocks = id.campaign_blocks();
    let predictor = model.at(&id.estimate);
    // (e^T (I -+ H)^-1 e, |e|^2, inside) of every pose that can be solved.
    let forms: Vec<Option<(f64, f64, bool)>> = map_blocks(&data.poses, |first, poses| {
        let mut jac = vec![0.0; 3 * k];
        let mut x = vec![0.0; 3 * q];
        let mut xc = vec![0.0; 3 * q];
        let range = first..first + poses.len();
        Ok(poses
            .iter()
            .zip(&inside[range.clone()])
            .zip(&seeds[range])
            .map(|((p, &inside), &seed)| {
                let mut seed = seed;
                let g = predictor.predict(p, &mut seed, &mut jac).ok()?;
                let (offsets, cov) = &blocks[id.campaign_of(p)?];
                let y = p.readings.to_array();
                let e = nalgebra::Vector3::from_fn(|c, _| {
                    (y[c] - g[c] - offsets[c]) / options.sigma[c]
                });
                // X_j: the pose's weighted rows [its offsets | identifiable].
                x.iter_mut().for_each(|v| *v = 0.0);
                for c in 0..3 {
                    let w = 1.0 / options.sigma[c];
                    x[c * q + c] = w;
                    for (t, &col) in identifiable.iter().enumerate() {
                        x[c * q + 3 + t] = w * jac[c * k + col];
                    }
                }
                // H_jj = X_j C X_j^T.
                for a in 0..3 {
                    for t in 0..q {
                        xc[a * q + t] = (0..q).map(|s| x[a * q + s] * cov[s * q + t]).sum();
                    }
                }
                let h = Matrix3::from_fn(|a, b| (0..q).map(|t| xc[a * q + t] * x[b * q + t]).sum());
                let d = if inside {
                    (Matrix3::identity() - h)
                        .try_inverse()
                        .map_or(0.0, |inv| (e.transpose() * inv * e)[0])
                } else {
                    (Matrix3::identity() + h)
                        .try_inverse()
                        .map_or(f64::INFINITY, |inv| (e.transpose() * inv * e)[0])
                };
                Some((d, e.norm_squared(), inside))
            })
            .collect())
    })?;
    // The fit's own chi-square and degrees of freedom (a prior's rows
    // count as readings the fit explains).
    let (mut chi2, mut m) = id
        .prior_fit
        .map_or((0.0, 0usize), |f| (f.chi_square, f.dof));
    for (_, e2, _) in forms.iter().flatten().filter(|f| f.2) {
        chi2 += e2;
        m += 3;
    }
    let nu = m.saturating_sub(q + 3 * (id.campaign_offsets.len() - 1));
    Ok(forms
        .into_iter()
        .map(|f| {
            let (d, _, inside) = f?;
            // Deleted residuals externally studentised; prediction
            // residuals against the fit's scale.
            let scale = match (inside, nu) {
                (true, nu) if nu > 3 => (chi2 - d) / (nu - 3) as f64,
                (false, nu) if nu > 0 => chi2 / nu as f64,
                _ => 1.0,
            };
            Some(d / scale.max(1.0))
        })
        .collect())
}

/// [`identify`] after rejecting gross errors ([`screen_gross_errors`] at
/// family-wise level 0.001, at most 10 % of the poses); returns the
/// identification on the kept poses and the rejected ones.
///
/// # Example
/// ```
/// use tricept_engine::{robust::identify_robust, model::GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let mut data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&Campaign::grid(&m, 3))
///     .unwrap();
/// data.poses[10].readings.s_mm += 0.05; // a 50 um misread of the scale
/// data.poses[30].readings.phi_rad += 0.1; // a 0.1 rad encoder jump
/// let model = GeometricModel::new(m.clone(), set);
/// let (id, rejected) = identify_robust(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// assert_eq!(rejected.iter().map(|r| r.pose).collect::<Vec<_>>(), vec![10, 30]);
/// assert!(id.stats.reduced_chi_square < 1.5);
/// ```
pub fn identify_robust(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
) -> Result<(Identification, Vec<Rejection>), IdentError> {
    let (rejected, fit) = screen_gross_errors_with_fit(model, data, options, 1e-3, 0.1)?;
    let id = match fit {
        Some(id) => id,
        None => identify(model, &kept(data, &rejected), options)?,
    };
    Ok((id, rejected))
}
