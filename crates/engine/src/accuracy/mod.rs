//! What a calibration promises, and whether that is worth deploying: the
//! platform error predicted after calibration against the error a machine
//! built to its tolerance has without one.
//!
//! A machine commanded by a model whose parameters are off by `e` (in the
//! parameter set's coordinates, mm) misses a target `r` by
//! `dr = P(r) e` to first order, where `P(r)` is the platform point's error
//! Jacobian projected on the set ([`tricept_model::jacobian::position_error_jacobian`]).
//! For `e` with covariance `S`, `E|dr|^2 = trace(P S P^T)`, so the **rms
//! platform error** over evaluation points `r_j` is
//!
//! ```text
//! rms(S) = sqrt( mean_j trace(P(r_j) S P(r_j)^T) )     (mm)
//! ```
//!
//! - **Before calibration** `S = t^2 I`: every parameter of the set is off
//!   by its manufacturing tolerance `t` (default
//!   [`DEFAULT_TOLERANCE_MM`] = 0.25 mm, class 1).
//! - **After calibration** `S` is the estimate's covariance, with every held
//!   parameter at its prior `t^2` (a held parameter is as uncertain as it was
//!   built; the weak directions of the campaign are already in the
//!   covariance, at their size).
//!
//! A campaign is **worthwhile** when the predicted rms after calibration is
//! at most [`WORTHWHILE_RATIO`] (one half) of the rms before: a calibration
//! that does not clearly beat the machine's tolerance is a coin flip at
//! best, and at 8 poses it is far worse (`dq` +- 4 mm along the weak
//! direction of all three legs).
//!
//! The accuracy a machine file promises is made here too, from the same
//! evaluation points: [`promise`] (internal data: the estimate, what the
//! fit leaves unexplained out of sample ([`cross_validation`]), the
//! structure) and [`fused`] (the tool tip of a fused fit).

pub mod cross_validation;
pub mod fused;
pub mod promise;

pub use promise::{Accuracy, Fit, PromiseError, of_fit, of_fit_stated};

use nalgebra::{DMatrix, Vector3};
use serde::Serialize;
use tricept_kinematics::Machine;
use tricept_model::{ParameterSet, jacobian::position_error_jacobian};

use crate::IdentError;

/// The default manufacturing tolerance of every geometric parameter, mm
/// (class-1 accuracy of joint positions and leg lengths).
pub const DEFAULT_TOLERANCE_MM: f64 = 0.25;

/// A calibration is worth deploying when its predicted rms platform error
/// is at most this fraction of the uncalibrated machine's.
pub const WORTHWHILE_RATIO: f64 = 0.5;

/// The evaluation points of a predicted platform accuracy, mm: the
/// workspace's polar grid of 2 rings of 8 points on 3 levels (51 points).
/// The one grid of every accuracy the project predicts (identify, check,
/// the campaign study).
///
/// # Example
/// ```
/// let m = tricept_kinematics::Machine::paper();
/// assert_eq!(tricept_engine::accuracy::accuracy_points(&m).len(), 51);
/// ```
pub fn accuracy_points(m: &Machine) -> Vec<Vector3<f64>> {
    m.workspace.polar_grid(2, 8, 3)
}

/// The predicted platform accuracy of a calibration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PredictedAccuracy {
    /// Predicted rms platform error after calibration, mm.
    pub after_rms_mm: f64,
    /// Largest predicted rms error at one evaluation point after
    /// calibration, mm.
    pub after_max_mm: f64,
    /// Expected rms platform error without calibration, mm.
    pub before_rms_mm: f64,
    /// The manufacturing tolerance per parameter assumed before
    /// calibration (and for held parameters after), mm.
    pub tolerance_mm: f64,
    /// Number of evaluation points.
    pub points: usize,
    /// `after_rms_mm <= WORTHWHILE_RATIO * before_rms_mm`.
    pub worthwhile: bool,
}

/// The platform error Jacobians of a parameter set at evaluation points:
/// everything [`PredictedAccuracy`] needs besides a covariance.
///
/// # Example
/// ```
/// use tricept_engine::{accuracy::AccuracyModel, model::GeometricModel, IdentifyOptions, identify};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&Campaign::grid(&m, 1))
///     .unwrap();
/// let id = identify(&GeometricModel::new(m.clone(), set.clone()), &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// let points = m.workspace.polar_grid(2, 8, 3);
/// let model = AccuracyModel::new(&m, &set, &points, 0.25).unwrap();
/// let a = model.assess(&id.covariance, id.design().fixed()).unwrap();
/// // 75 poses calibrate the platform to a few hundredths of a millimetre,
/// // from the best part of a millimetre.
/// assert!(a.worthwhile && a.after_rms_mm < 0.1 && a.before_rms_mm > 0.5);
/// ```
#[derive(Debug, Clone)]
pub struct AccuracyModel {
    /// `P(r_j)`, 3 x k each (mm/mm).
    jacobians: Vec<DMatrix<f64>>,
    tolerance_mm: f64,
    before_rms_mm: f64,
}

impl AccuracyModel {
    /// The Jacobians of `set` on `machine` at `points_mm`, with the
    /// tolerance `tolerance_mm` per parameter.
    pub fn new(
        machine: &Machine,
        set: &ParameterSet,
        points_mm: &[Vector3<f64>],
        tolerance_mm: f64,
    ) -> Result<AccuracyModel, IdentError> {
        if !(tolerance_mm.is_finite() && tolerance_mm > 0.0) {
            return Err(IdentError::Invalid(format!(
                "the manufacturing tolerance must be a positive number of mm, got {tolerance_mm}"
            )));
        }
        if points_mm.is_empty() {
            return Err(IdentError::Invalid("no evaluation points".into()));
        }
        let k = set.len();
        let mut block = vec![0.0; 3 * k];
        let mut jacobians = Vec::with_capacity(points_mm.len());
        for (j, r) in points_mm.iter().enumerate() {
            let kinematics = |e: tricept_kinematics::KinematicsError| {
                IdentError::Invalid(format!(
                    "evaluation point {} ({:.1}, {:.1}, {:.1}) mm: {e}",
                    j + 1,
                    r.x,
                    r.y,
                    r.z
                ))
            };
            let up = machine.inverse(r).map_err(kinematics)?.up;
            let p21 = position_error_jacobian(&machine.legs_at(&up)).map_err(kinematics)?;
            set.project(3, |row, f| p21[(row, f)], &mut block);
            jacobians.push(DMatrix::from_row_slice(3, k, &block));
        }
        let t2 = tolerance_mm * tolerance_mm;
        let mean_trace =
            jacobians.iter().map(|p| t2 * p.norm_squared()).sum::<f64>() / jacobians.len() as f64;
        Ok(AccuracyModel {
            jacobians,
            tolerance_mm,
            before_rms_mm: mean_trace.sqrt(),
        })
    }

    /// Number of parameters.
    pub fn n_params(&self) -> usize {
        self.jacobians.first().map_or(0, |p| p.ncols())
    }

    /// The expected rms platform error without calibration, mm.
    pub fn before_rms_mm(&self) -> f64 {
        self.before_rms_mm
    }

    /// `covariance` with every `held` parameter at its prior `t^2`.
    fn with_held(
        &self,
        covariance: &DMatrix<f64>,
        held: &[usize],
    ) -> Result<DMatrix<f64>, IdentError> {
        let k = self.n_params();
        if covariance.shape() != (k, k) || held.iter().any(|&i| i >= k) {
            return Err(IdentError::Invalid(format!(
                "a {}x{} covariance (held {held:?}) for {k} parameters",
                covariance.nrows(),
                covariance.ncols()
            )));
        }
        let mut s = covariance.clone();
        let t2 = self.tolerance_mm * self.tolerance_mm;
        for &i in held {
            s[(i, i)] += t2;
        }
        Ok(s)
    }

    /// The first two moments of the mean square platform error `e^T M e`
    /// over the evaluation points (`M = mean_j P_j^T P_j`) for an error
    /// `e ~ N(0, S)`, `S` as in [`AccuracyModel::assess`]:
    /// `(trace(M S), trace(M S M S))`, mm^2 and mm^4. The square of the
    /// first is the predicted rms; the second is what a quantile of the
    /// rms needs (`e^T M e` is a weighted sum of chi-squares of one degree
    /// of freedom, with mean `trace(M S)` and variance `2 trace(M S M S)`).
    pub fn error_moments(
        &self,
        covariance: &DMatrix<f64>,
        held: &[usize],
    ) -> Result<(f64, f64), IdentError> {
        let s = self.with_held(covariance, held)?;
        let k = self.n_params();
        let mut m = DMatrix::zeros(k, k);
        for p in &self.jacobians {
            m += p.transpose() * p;
        }
        m /= self.jacobians.len() as f64;
        let ms = m * s;
        Ok((ms.trace(), (&ms * &ms).trace()))
    }

    /// The predicted accuracy of an estimate with `covariance` (`k x k`,
    /// mm^2; rows and columns of held parameters may be zero) whose
    /// parameters `held` (indices) were held at their prior.
    pub fn assess(
        &self,
        covariance: &DMatrix<f64>,
        held: &[usize],
    ) -> Result<PredictedAccuracy, IdentError> {
        let s = self.with_held(covariance, held)?;
        let traces: Vec<f64> = self
            .jacobians
            .iter()
            .map(|p| (p * &s * p.transpose()).trace().max(0.0))
            .collect();
        let mean = traces.iter().sum::<f64>() / traces.len() as f64;
        let after_rms_mm = mean.sqrt();
        let after_max_mm = traces.iter().copied().fold(0.0, f64::max).sqrt();
        // A non-finite covariance (a singular design) is never worthwhile.
        let worthwhile =
            after_rms_mm.is_finite() && after_rms_mm <= WORTHWHILE_RATIO * self.before_rms_mm;
        Ok(PredictedAccuracy {
            after_rms_mm,
            after_max_mm,
            before_rms_mm: self.before_rms_mm,
            tolerance_mm: self.tolerance_mm,
            points: self.jacobians.len(),
            worthwhile,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prediction_is_the_monte_carlo_rms_of_the_linearised_error() {
        // Draw parameter errors with a known covariance and compare the
        // rms of P e with the closed form.
        use rand::{RngExt, SeedableRng};
        let m = Machine::paper();
        let set = ParameterSet::paper15();
        let points = m.workspace.polar_grid(1, 6, 2);
        let model = AccuracyModel::new(&m, &set, &points, 0.25).unwrap();
        let k = set.len();
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let l = DMatrix::from_fn(k, k, |i, j| {
            if j <= i {
                rng.random_range(-0.05..0.05)
            } else {
                0.0
            }
        });
        let cov = &l * l.transpose();
        let a = model.assess(&cov, &[]).unwrap();
        let trials = 4000;
        let mut sum = 0.0;
        for _ in 0..trials {
            let z = DMatrix::from_fn(k, 1, |_, _| {
                // Box-Muller: two uniforms to one normal.
                let (u1, u2): (f64, f64) = (rng.random(), rng.random());
                (-2.0 * (1.0 - u1).ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
            });
            let e = &l * z;
            for p in &model.jacobians {
                sum += (p * &e).norm_squared();
            }
        }
        let mc = (sum / (trials * points.len()) as f64).sqrt();
        assert!(
            (mc / a.after_rms_mm - 1.0).abs() < 0.05,
            "{mc} vs {}",
            a.after_rms_mm
        );
        // Holding every parameter at its prior is the machine uncalibrated.
        let all: Vec<usize> = (0..k).collect();
        let none = model.assess(&DMatrix::zeros(k, k), &all).unwrap();
        assert!((none.after_rms_mm / none.before_rms_mm - 1.0).abs() < 1e-12);
        assert!(!none.worthwhile);
    }
}
