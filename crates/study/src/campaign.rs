//! How many self-calibration poses, and which, make a campaign worth
//! deploying: the advice of a refused campaign
//! ([`tricept_engine::accuracy::PredictedAccuracy`]), and the poses of
//! `--poses optimal:N`.
//!
//! For a pose count `n` on a ladder of sizes, the `n` poses are chosen from
//! the candidate grid of the workspace ([`crate::optimise::candidate_grid`])
//! by the D-optimal exchange of [`crate::optimise`], starting from `n`
//! evenly spread candidates; their predicted covariance is the inverse of
//! the information matrix with the sensor offsets eliminated, the held
//! parameters at their prior. The first size whose predicted platform
//! accuracy is worthwhile is the advice. The same is reported for the
//! campaign users usually run, `n` random poses (`random:N,1`), since a
//! D-optimal set is the best case.

use nalgebra::{DMatrix, Vector3};
use serde::Serialize;
use tricept_engine::{
    IdentifyOptions, accuracy::AccuracyModel, accuracy::PredictedAccuracy, model::GeometricModel,
};
use tricept_kinematics::{Machine, workspace::PoseSet};
use tricept_model::ParameterSet;

use crate::StudyError;
use crate::optimise::{Candidates, Criterion, candidate_grid, exchange};

/// Pose counts tried, smallest first.
pub const CAMPAIGN_SIZES: [usize; 15] = [
    8, 10, 12, 15, 20, 25, 30, 40, 50, 60, 80, 100, 120, 150, 200,
];

/// Exchange passes per size (the criterion gains little after a few).
const PASSES: usize = 3;

/// A campaign that would be worth deploying.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CampaignAdvice {
    /// Number of poses.
    pub poses: usize,
    /// Their platform targets, mm.
    pub targets_mm: Vec<Vector3<f64>>,
    /// The predicted accuracy of a calibration from them.
    pub predicted: PredictedAccuracy,
}

/// The identifiable columns of `set` on `machine` (at the nominal point,
/// from the whole candidate grid) and the held ones.
fn columns(machine: &Machine, set: &ParameterSet) -> Result<(Vec<usize>, Vec<usize>), StudyError> {
    let poses: Vec<tricept_data::MeasuredPose> = candidate_grid(machine)
        .iter()
        .map(|r| {
            Ok(tricept_data::MeasuredPose {
                commands_mm: machine.inverse(r)?.legs_mm,
                ..Default::default()
            })
        })
        .collect::<Result<_, StudyError>>()?;
    let model = GeometricModel::new(machine.clone(), set.clone());
    let d = tricept_engine::identify::design(
        &model,
        &vec![0.0; set.len()],
        &poses,
        &IdentifyOptions::for_machine(machine),
    )?;
    Ok((d.identifiable().to_vec(), d.fixed().to_vec()))
}

/// The covariance (`k x k`, mm^2) of the identifiable `columns` from the
/// information matrix `f` (`None` when it is singular).
fn covariance(f: &DMatrix<f64>, columns: &[usize], k: usize) -> Option<DMatrix<f64>> {
    let inv = f.clone().cholesky()?.inverse();
    let mut c = DMatrix::zeros(k, k);
    for (a, &i) in columns.iter().enumerate() {
        for (b, &j) in columns.iter().enumerate() {
            c[(i, j)] = inv[(a, b)];
        }
    }
    Some(c)
}

/// The `n` D-optimal poses of the candidate grid for `set` (see the module
/// docs), as platform targets (mm).
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let targets = tricept_study::campaign::d_optimal_targets(&m, &ParameterSet::paper15(), 12).unwrap();
/// assert_eq!(targets.len(), 12);
/// assert!(targets.iter().all(|r| m.workspace.contains(r)));
/// ```
pub fn d_optimal_targets(
    machine: &Machine,
    set: &ParameterSet,
    n: usize,
) -> Result<Vec<Vector3<f64>>, StudyError> {
    let (identifiable, _) = columns(machine, set)?;
    let candidates = Candidates::new(
        machine,
        set,
        &identifiable,
        candidate_grid(machine),
        machine.sensors.logged_sigma(),
    )?;
    Ok(select(&candidates, n)
        .into_iter()
        .map(|i| candidates.targets_mm[i])
        .collect())
}

/// `n` evenly spread candidates improved by the D-optimal exchange.
fn select(candidates: &Candidates, n: usize) -> Vec<usize> {
    let len = candidates.len();
    let n = n.min(len);
    let start: Vec<usize> = (0..n).map(|i| i * len / n.max(1)).collect();
    exchange(candidates, &start, Criterion::DOptimal, PASSES).indices
}

/// The smallest campaigns on [`CAMPAIGN_SIZES`] that `accuracy` calls
/// worthwhile: D-optimal poses, and random poses (`random:N,1`). `None`
/// where no size up to 200 is.
pub fn worthwhile_campaigns(
    machine: &Machine,
    set: &ParameterSet,
    accuracy: &AccuracyModel,
) -> Result<(Option<CampaignAdvice>, Option<CampaignAdvice>), StudyError> {
    let (identifiable, held) = columns(machine, set)?;
    let sigma = machine.sensors.logged_sigma();
    let assess = |targets: Vec<Vector3<f64>>| -> Result<Option<CampaignAdvice>, StudyError> {
        let c = Candidates::new(machine, set, &identifiable, targets, sigma)?;
        let all: Vec<usize> = (0..c.len()).collect();
        let Some(cov) = covariance(&c.information(&all), &identifiable, set.len()) else {
            return Ok(None);
        };
        let predicted = accuracy.assess(&cov, &held)?;
        Ok(predicted.worthwhile.then(|| CampaignAdvice {
            poses: c.len(),
            targets_mm: c.targets_mm.clone(),
            predicted,
        }))
    };
    let grid = Candidates::new(machine, set, &identifiable, candidate_grid(machine), sigma)?;
    let mut optimal = None;
    for &n in &CAMPAIGN_SIZES {
        let targets = select(&grid, n)
            .into_iter()
            .map(|i| grid.targets_mm[i])
            .collect();
        if let Some(a) = assess(targets)? {
            optimal = Some(a);
            break;
        }
    }
    let mut random = None;
    for &n in &CAMPAIGN_SIZES {
        let spec = PoseSet::Random { n, seed: 1 };
        let Some(targets) = spec.generate(&machine.workspace) else {
            continue;
        };
        if let Some(a) = assess(targets)? {
            random = Some(a);
            break;
        }
    }
    Ok((optimal, random))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_few_optimal_poses_suffice_where_eight_grid_poses_do_not() {
        let m = Machine::paper();
        let set = ParameterSet::paper15();
        let points = tricept_engine::accuracy::accuracy_points(&m);
        let accuracy = AccuracyModel::new(&m, &set, &points, 0.25).unwrap();
        let (optimal, random) = worthwhile_campaigns(&m, &set, &accuracy).unwrap();
        let (optimal, random) = (optimal.unwrap(), random.unwrap());
        assert!(optimal.predicted.worthwhile && random.predicted.worthwhile);
        assert!(
            optimal.poses <= random.poses,
            "{} {}",
            optimal.poses,
            random.poses
        );
        // The advice is the smallest size that passes: the size below it
        // on the ladder does not.
        let below = CAMPAIGN_SIZES
            .iter()
            .rev()
            .find(|&&n| n < random.poses)
            .copied();
        if let Some(n) = below {
            let (identifiable, held) = columns(&m, &set).unwrap();
            let targets = PoseSet::Random { n, seed: 1 }
                .generate(&m.workspace)
                .unwrap();
            let c = Candidates::new(&m, &set, &identifiable, targets, m.sensors.logged_sigma())
                .unwrap();
            let all: Vec<usize> = (0..n).collect();
            let worthwhile = covariance(&c.information(&all), &identifiable, 15)
                .map(|cov| accuracy.assess(&cov, &held).unwrap().worthwhile);
            assert_ne!(worthwhile, Some(true), "{n} random poses");
        }
    }
}
