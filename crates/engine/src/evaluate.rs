//! One evaluation of a reading model over a data set: predictions,
//! Jacobians and the reduced weighted problem, in blocks of
//! [`EVALUATION_BLOCK`] poses (in parallel beyond one block, the blocks'
//! factors merged in block order: the same bits at any thread count).
//! The nuisance columns are the sensor offsets, three per campaign
//! ([`Campaigns`]); a model's prior adds its rows last ([`crate::prior::Prior`]).

use rayon::prelude::*;
use tricept_data::MeasuredPose;
use tricept_kinematics::up_limb::UpJoints;
use tricept_numerics::linalg::TriangularAccumulator;
use tricept_numerics::lsq::ReducedProblem;

use crate::campaigns::Campaigns;
use crate::error::IdentError;
use crate::model::{PosePredictor, ReadingModel};

/// One evaluation of the model at fixed parameters over all poses.
pub(crate) struct Evaluation {
    /// The reduced weighted problem `[offsets | parameters | y - g(p)]`,
    /// with the prior's rows when the model has one.
    pub problem: ReducedProblem,
    /// `y - g(p)` per pose (rad, rad, mm).
    pub residuals: Vec<[f64; 3]>,
}

/// Poses per block of an evaluation: each block is predicted and reduced
/// to its triangular factor on its own, the blocks in parallel, and the
/// factors are merged in block order, so the result does not depend on
/// the number of threads. Up to one block the evaluation is sequential.
pub(crate) const EVALUATION_BLOCK: usize = 4096;

/// Evaluates `model` at `p` on `poses`: predictions, Jacobians and the
/// reduced weighted problem. `seeds` carries FK starting points between
/// calls; `seeds` and `pose_weights` have one entry per pose (checked by
/// the callers).
pub(crate) fn evaluate(
    model: &dyn ReadingModel,
    p: &[f64],
    poses: &[MeasuredPose],
    sigma: &[f64; 3],
    pose_weights: Option<&[f64]>,
    seeds: &mut [Option<UpJoints>],
) -> Result<Evaluation, IdentError> {
    let k = model.names().len();
    let campaigns = Campaigns::of(poses);
    let nn = campaigns.nuisance();
    let predictor = model.at(p);
    let block = |first: usize, poses: &[MeasuredPose], seeds: &mut [Option<UpJoints>]| {
        let layout = Layout {
            k,
            campaigns: &campaigns,
        };
        evaluate_block(
            &*predictor,
            &layout,
            first,
            poses,
            sigma,
            pose_weights,
            seeds,
        )
    };
    let blocks: Vec<Result<Block, IdentError>> = if poses.len() <= EVALUATION_BLOCK {
        vec![block(0, poses, seeds)]
    } else {
        poses
            .par_chunks(EVALUATION_BLOCK)
            .zip(seeds.par_chunks_mut(EVALUATION_BLOCK))
            .enumerate()
            .map(|(b, (poses, seeds))| block(b * EVALUATION_BLOCK, poses, seeds))
            .collect()
    };
    let mut residuals = Vec::with_capacity(poses.len());
    let mut factors = Vec::with_capacity(blocks.len());
    let mut rows = 0;
    for b in blocks {
        let b = b?;
        rows += b.rows;
        residuals.extend(b.residuals);
        factors.push(b.r);
    }
    let prior = model.prior().map(|prior| prior.problem_rows(nn, p));
    let r = match (factors.pop(), &prior) {
        (Some(r), None) if factors.is_empty() => r,
        (last, _) => {
            let n = nn + k + 1;
            let mut acc = TriangularAccumulator::with_rows_hint(n, n * (factors.len() + 2));
            let mut row = vec![0.0; n];
            for f in factors.iter().chain(&last) {
                for i in 0..f.nrows() {
                    row.iter_mut().enumerate().for_each(|(j, v)| *v = f[(i, j)]);
                    acc.push_row(&row);
                }
            }
            for extra in prior.iter().flatten() {
                acc.push_row(extra);
            }
            acc.finish()
        }
    };
    Ok(Evaluation {
        problem: ReducedProblem {
            rows: rows + prior.map_or(0, |p| p.len()),
            r,
            n_nuisance: nn,
            k,
        },
        residuals,
    })
}

/// `f(first, block)` over the poses a block of [`EVALUATION_BLOCK`] at a
/// time (in parallel beyond one block), the results in pose order; the
/// first error in pose order is the one returned.
pub(crate) fn map_blocks<T: Send>(
    poses: &[MeasuredPose],
    f: impl Fn(usize, &[MeasuredPose]) -> Result<Vec<T>, IdentError> + Sync,
) -> Result<Vec<T>, IdentError> {
    if poses.len() <= EVALUATION_BLOCK {
        return f(0, poses);
    }
    let blocks: Vec<Result<Vec<T>, IdentError>> = poses
        .par_chunks(EVALUATION_BLOCK)
        .enumerate()
        .map(|(b, block)| f(b * EVALUATION_BLOCK, block))
        .collect();
    let mut out = Vec::with_capacity(poses.len());
    for b in blocks {
        out.extend(b?);
    }
    Ok(out)
}

/// One block of an evaluation: its triangular factor, rows and residuals.
struct Block {
    r: faer::Mat<f64>,
    rows: usize,
    residuals: Vec<[f64; 3]>,
}

/// The columns of an evaluation's rows: `k` parameters after three
/// offsets per campaign.
struct Layout<'a> {
    k: usize,
    campaigns: &'a Campaigns,
}

/// The poses `first..first + poses.len()` of an evaluation.
fn evaluate_block(
    predictor: &dyn PosePredictor,
    layout: &Layout<'_>,
    first: usize,
    poses: &[MeasuredPose],
    sigma: &[f64; 3],
    pose_weights: Option<&[f64]>,
    seeds: &mut [Option<UpJoints>],
) -> Result<Block, IdentError> {
    let k = layout.k;
    let nn = layout.campaigns.nuisance();
    let mut acc = TriangularAccumulator::with_rows_hint(nn + k + 1, 3 * poses.len());
    let mut jac = vec![0.0; 3 * k];
    let mut row = vec![0.0; nn + k + 1];
    let mut residuals = Vec::with_capacity(poses.len());
    for ((i, pose), seed) in poses.iter().enumerate().zip(seeds.iter_mut()) {
        let j = first + i;
        // Every pose's campaign is among the campaigns of the poses.
        let offsets = 3 * layout.campaigns.index(pose).unwrap_or(0);
        let g =
            predictor
                .predict(pose, seed, &mut jac)
                .map_err(|source| IdentError::Kinematics {
                    pose: j,
                    line: pose.line,
                    source,
                })?;
        let y = pose.readings.to_array();
        let w_pose = pose_weights.and_then(|w| w.get(j)).copied().unwrap_or(1.0);
        let mut res = [0.0; 3];
        for c in 0..3 {
            res[c] = y[c] - g[c];
            let w = w_pose / sigma[c];
            row.iter_mut().for_each(|v| *v = 0.0);
            row[offsets + c] = w;
            for t in 0..k {
                row[nn + t] = w * jac[c * k + t];
            }
            row[nn + k] = w * res[c];
            acc.push_row(&row);
        }
        residuals.push(res);
    }
    Ok(Block {
        rows: acc.rows(),
        r: acc.finish(),
        residuals,
    })
}
