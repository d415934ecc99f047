//! Each machine of a batch alone: its own calibration, as `tricept
//! identify` would make it (the engine's robust fit, its verdict, whether
//! the campaign is worth deploying), and the batch's rank decision over
//! every machine's poses.
//!
//! A machine enters the batch when its own data fit (converged, adequate)
//! and determine every parameter the batch does: the hierarchical model
//! pools calibrations, not campaigns too short to calibrate (a new machine
//! with a short campaign calibrates from the batch's prior instead).

use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_engine::{
    Identification, IdentifyOptions, accuracy::AccuracyModel, model::ReadingModel,
    robust::Rejection, robust::identify_robust,
};
use tricept_numerics::linalg::TriangularAccumulator;
use tricept_numerics::lsq::{RankDecision, ReducedProblem};

use crate::error::FleetError;

/// Exit code of a fit to be trusted.
pub const EXIT_OK: u8 = 0;
/// Exit code of bad input (a campaign that cannot be identified).
pub const EXIT_INPUT: u8 = 2;
/// Exit code of a converged fit not to be trusted.
pub const EXIT_INADEQUATE: u8 = 3;
/// Exit code of a fit that did not converge.
pub const EXIT_NOT_CONVERGED: u8 = 4;

/// One machine's calibration from its own data.
#[derive(Debug, Clone)]
pub struct OwnFit {
    /// The data set's source (its file).
    pub source: String,
    /// The identification on the kept poses (`None`: it failed, `reason`
    /// says why).
    pub id: Option<Identification>,
    /// Poses rejected as gross errors.
    pub rejected: Vec<Rejection>,
    /// The poses kept.
    pub kept: Dataset,
    /// The exit code `tricept identify` gives this campaign: 0, 2 (it
    /// cannot be identified), 3 (inadequate or not worth deploying), 4.
    pub exit_code: u8,
    /// Why the exit code is not 0.
    pub reason: Option<String>,
}

impl OwnFit {
    /// Calibrates `data` alone with `model`; the exit code judges the fit
    /// as `identify` does (`accuracy`: the machine's worthwhile rule).
    pub fn new(
        model: &dyn ReadingModel,
        data: &Dataset,
        options: &IdentifyOptions,
        accuracy: &AccuracyModel,
    ) -> OwnFit {
        let failed = |why: String, code: u8| OwnFit {
            source: data.source.clone(),
            id: None,
            rejected: Vec::new(),
            kept: data.clone(),
            exit_code: code,
            reason: Some(why),
        };
        let (id, rejected) = match identify_robust(model, data, options) {
            Ok(fit) => fit,
            Err(e) => return failed(format!("its data cannot be identified: {e}"), EXIT_INPUT),
        };
        let verdict = id.verdict();
        let worthwhile = accuracy
            .assess(&id.covariance, id.design().fixed())
            .map(|a| a.worthwhile)
            .unwrap_or(false);
        let (exit_code, reason) = if !verdict.converged {
            (
                EXIT_NOT_CONVERGED,
                Some("its own fit did not converge".to_string()),
            )
        } else if !verdict.adequate {
            (
                EXIT_INADEQUATE,
                Some(format!(
                    "the model does not explain its own data (chi2/dof {:.2}, p = {:.1e})",
                    id.stats.reduced_chi_square, verdict.chi_square_p_value
                )),
            )
        } else if !worthwhile {
            (
                EXIT_INADEQUATE,
                Some("its campaign is too small to calibrate it".to_string()),
            )
        } else {
            (EXIT_OK, None)
        };
        let kept = data.subset(|j| !rejected.iter().any(|r| r.pose == j));
        OwnFit {
            source: data.source.clone(),
            id: Some(id),
            rejected,
            kept,
            exit_code,
            reason,
        }
    }

    /// Whether its data fit (converged and adequate; a short campaign may
    /// still enter the batch when it determines every parameter).
    pub fn fits(&self) -> bool {
        self.id.as_ref().is_some_and(|id| {
            let v = id.verdict();
            v.converged && v.adequate
        })
    }
}

/// The batch's rank decision: which parameters the poses of all machines
/// together can see, each machine with its own sensor offsets, on `model`'s
/// rank reference (or the model) at zero, with the engine's rule
/// ([`ReducedProblem::decide`]: unit-norm columns, singular values, the
/// held ones chosen by column-pivoted QR).
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data: Vec<_> = (0..3)
///     .map(|s| Plant::geometric(m.clone(), set.to_errors(&[0.0; 15])).simulate(&Campaign::random(&m, 20, s)).unwrap())
///     .collect();
/// let model = GeometricModel::new(m.clone(), set.clone());
/// let d = tricept_fleet::own::batch_design(&model, &data.iter().collect::<Vec<_>>(), &IdentifyOptions::for_machine(&m)).unwrap();
/// // x-first U joint: no machine sees dyA3, so neither does the batch.
/// assert_eq!(d.fixed, vec![set.index_of("dyA3").unwrap()]);
/// ```
pub fn batch_design(
    model: &dyn ReadingModel,
    datasets: &[&Dataset],
    options: &IdentifyOptions,
) -> Result<RankDecision, FleetError> {
    let reference = model.rank_reference().unwrap_or(model);
    let k = reference.names().len();
    let blocks: Vec<faer::Mat<f64>> = datasets
        .par_iter()
        .map(|data| parameter_factor(reference, data, options, k))
        .collect::<Result<_, _>>()?;
    let mut acc = TriangularAccumulator::with_rows_hint(k + 1, k * blocks.len());
    let mut row = vec![0.0; k + 1];
    for b in &blocks {
        for i in 0..k {
            row[..k]
                .iter_mut()
                .enumerate()
                .for_each(|(j, v)| *v = b[(i, j)]);
            acc.push_row(&row);
        }
    }
    let problem = ReducedProblem {
        rows: acc.rows(),
        r: acc.finish(),
        n_nuisance: 0,
        k,
    };
    problem
        .decide(options.rank_tolerance)
        .ok_or(FleetError::Numerical("the batch's SVD did not converge"))
}

/// The `k x k` factor of one machine's weighted parameter columns at zero
/// with its three offsets projected out.
fn parameter_factor(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
    k: usize,
) -> Result<faer::Mat<f64>, FleetError> {
    let predictor = model.at(&vec![0.0; k]);
    let mut acc = TriangularAccumulator::with_rows_hint(3 + k, 3 * data.poses.len());
    let mut jac = vec![0.0; 3 * k];
    let mut row = vec![0.0; 3 + k];
    for pose in &data.poses {
        let mut seed = None;
        predictor
            .predict(pose, &mut seed, &mut jac)
            .map_err(|e| FleetError::Identification {
                source_name: data.source.clone(),
                error: tricept_engine::IdentError::Kinematics {
                    pose: 0,
                    line: pose.line,
                    source: e,
                },
            })?;
        for c in 0..3 {
            let w = 1.0 / options.sigma[c];
            row.iter_mut().for_each(|v| *v = 0.0);
            row[c] = w;
            for t in 0..k {
                row[3 + t] = w * jac[c * k + t];
            }
            acc.push_row(&row);
        }
    }
    let r = acc.finish();
    Ok(r.as_ref().submatrix(3, 3, k, k).to_owned())
}
