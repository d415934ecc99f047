//! Planning a few external measurements: which `k` tracker points or
//! ballbar readings (legs and head angles) to take so that the tool tip is
//! best known over the workspace, given the internal campaign.
//!
//! **Criterion.** The mean squared predicted tool-tip error after touch-off
//! over evaluation tool poses `e`:
//!
//! ```text
//! phi(S) = (1/E) sum_e tr(G~_e Sigma(S) G~_e^T),   G~_e = G_e - mean_e G_e
//! ```
//!
//! where `G_e` is the tool tip's Jacobian with respect to the global
//! parameters at the nominal machine and `Sigma(S)` the posterior
//! covariance of the parameters with the internal campaign's information,
//! the external measurements `S`, and a prior. `sqrt(phi)` is printed as
//! "RMS predicted tool-tip standard deviation after touch-off". The design
//! is Bayesian (A-optimal with weight `W = (1/E) sum G~_e^T G~_e`): for a
//! few points the head is not determined by data alone, so a prior (the
//! parameters' typical sizes, [`FusedModel::typical_sizes`]; 10 mrad and
//! 10 mm for an instrument's frame, pivot or target) is part of the
//! criterion. The estimator itself stays prior-free.
//!
//! **Arithmetic.** Everything is whitened by the prior (`z = p / sigma`), so
//! `Lambda(S) = I + D F_int D + sum_{c in S} a_c^T a_c`. The gain of adding
//! candidate `c` is `tr(S_c^-1 U_c^T W U_c)` with `U_c = Sigma a_c^T` and
//! `S_c = I + a_c U_c`; `Sigma` is recomputed from `Lambda` by Cholesky for
//! every state, never by accumulated rank updates (which lose positive
//! definiteness within a few picks). The search is the greedy path (nested,
//! so one run serves every `k`) followed by the sequential exchange of
//! [`crate::optimise`] at each requested `k`.
//!
//! It is linear-Gaussian and variance-only: an unmodelled effect's bias is
//! not in it (docs/hybrid.md measures how much that matters).

use nalgebra::{DMatrix, Vector3};
use rand::SeedableRng;
use rand::seq::index::sample;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use tricept_data::MeasuredPose;
use tricept_data::{
    BallbarData, BallbarReading, ExternalData, ExternalPose, TrackerData, TrackerPoint,
};
use tricept_ident::fusion::{DesignRows, FusedModel, Source, design_rows, information};
use tricept_kinematics::{HeadBranch, Machine};
use tricept_model::Effector;

use crate::StudyError;
use crate::optimise::{ExchangeCriterion, exchange_with, greedy};
use tricept_numerics::stats::quantile;

/// Prior standard deviation of an instrument's nuisance parameter: what a
/// closed-form start leaves (10 mrad for an angle, 10 mm for a length).
fn nuisance_prior(name: &str) -> f64 {
    if name.ends_with("_rad") { 0.01 } else { 10.0 }
}

/// The planning problem in whitened coordinates (see the module docs).
#[derive(Debug, Clone)]
pub struct PlanProblem {
    /// `I + D F D` (parameters first, then the instrument's nuisance).
    lambda0: DMatrix<f64>,
    /// Whitened rows of each candidate (`r x n`).
    rows: Vec<DMatrix<f64>>,
    /// The criterion's weight after touch-off (`n x n`, mm^2).
    touch_off: DMatrix<f64>,
    /// The same without touch-off (raw tool tip).
    raw: DMatrix<f64>,
}

impl PlanProblem {
    /// The problem for `model` with the internal campaign's information
    /// `internal` (`k x k`, [`tricept_ident::fusion::information`]; zeros
    /// for none), candidate measurements `candidates` (one instrument's
    /// [`DesignRows`]) and the tool poses `eval` the criterion averages over.
    pub fn new(
        model: &FusedModel,
        internal: &DMatrix<f64>,
        candidates: &DesignRows,
        eval: &[ExternalPose],
    ) -> Result<PlanProblem, StudyError> {
        let k = model.len();
        let nn = candidates.nuisance_names.len();
        if internal.shape() != (k, k) {
            return Err(StudyError::Invalid(format!(
                "internal information is {:?}, expected {k} x {k}",
                internal.shape()
            )));
        }
        let n = k + nn;
        let sigma: Vec<f64> = model
            .typical_sizes()
            .into_iter()
            .chain(candidates.nuisance_names.iter().map(|s| nuisance_prior(s)))
            .collect();
        // Reorder [nuisance | parameters] to [parameters | nuisance] and whiten.
        let whiten = |m: &DMatrix<f64>| {
            DMatrix::from_fn(m.nrows(), n, |i, j| {
                let source = if j < k { nn + j } else { j - k };
                m[(i, source)] * sigma[j]
            })
        };
        let mut lambda0 = DMatrix::identity(n, n);
        for i in 0..k {
            for j in 0..k {
                lambda0[(i, j)] += sigma[i] * internal[(i, j)] * sigma[j];
            }
        }
        let priors = whiten(&candidates.priors);
        lambda0 += priors.transpose() * &priors;
        let rows: Vec<DMatrix<f64>> = candidates.records.iter().map(whiten).collect();
        let g: Vec<DMatrix<f64>> = eval
            .iter()
            .map(|pose| {
                Ok(model
                    .spindle_point(&vec![0.0; k], pose, &Effector::default())?
                    .1)
            })
            .collect::<Result<_, StudyError>>()?;
        let e = g.len().max(1) as f64;
        let mean = g.iter().fold(DMatrix::zeros(3, k), |a, b| a + b) / e;
        let mut touch_off = DMatrix::zeros(n, n);
        let mut raw = DMatrix::zeros(n, n);
        let d = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            k,
            sigma[..k].iter().copied(),
        ));
        for ge in &g {
            let a = ge * &d;
            let b = (ge - &mean) * &d;
            let mut view = raw.view_mut((0, 0), (k, k));
            view += a.transpose() * &a / e;
            let mut view = touch_off.view_mut((0, 0), (k, k));
            view += b.transpose() * &b / e;
        }
        Ok(PlanProblem {
            lambda0,
            rows,
            touch_off,
            raw,
        })
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The posterior information of a selection.
    fn lambda(&self, selection: &[usize]) -> DMatrix<f64> {
        let mut l = self.lambda0.clone();
        for &c in selection {
            l += self.rows[c].transpose() * &self.rows[c];
        }
        l
    }

    fn covariance(lambda: &DMatrix<f64>) -> Option<DMatrix<f64>> {
        lambda.clone().cholesky().map(|c| c.inverse())
    }

    /// `(raw, after touch-off)` RMS predicted tool-tip standard deviation of
    /// a selection, um.
    pub fn rms_um(&self, selection: &[usize]) -> (f64, f64) {
        match Self::covariance(&self.lambda(selection)) {
            Some(s) => (
                1e3 * (&self.raw * &s).trace().max(0.0).sqrt(),
                1e3 * (&self.touch_off * &s).trace().max(0.0).sqrt(),
            ),
            None => (f64::INFINITY, f64::INFINITY),
        }
    }
}

impl ExchangeCriterion for PlanProblem {
    type State = DMatrix<f64>;

    fn candidates(&self) -> usize {
        self.rows.len()
    }

    fn state(&self, selection: &[usize]) -> DMatrix<f64> {
        self.lambda(selection)
    }

    fn value(&self, lambda: &DMatrix<f64>) -> f64 {
        match Self::covariance(lambda) {
            Some(s) => -(&self.touch_off * s).trace(),
            None => f64::NEG_INFINITY,
        }
    }

    fn without(&self, lambda: &DMatrix<f64>, c: usize) -> DMatrix<f64> {
        lambda - self.rows[c].transpose() * &self.rows[c]
    }

    fn with(&self, lambda: &DMatrix<f64>, c: usize) -> DMatrix<f64> {
        lambda + self.rows[c].transpose() * &self.rows[c]
    }

    fn values_with(&self, lambda: &DMatrix<f64>, candidates: &[usize]) -> Vec<f64> {
        let Some(sigma) = Self::covariance(lambda) else {
            return vec![f64::NEG_INFINITY; candidates.len()];
        };
        let phi = (&self.touch_off * &sigma).trace();
        candidates
            .par_iter()
            .map(|&c| {
                let a = &self.rows[c];
                let u = &sigma * a.transpose();
                let s = DMatrix::identity(a.nrows(), a.nrows()) + a * &u;
                let m = u.transpose() * &self.touch_off * &u;
                match s.cholesky() {
                    Some(ch) => -(phi - ch.solve(&m).trace()),
                    None => f64::NEG_INFINITY,
                }
            })
            .collect()
    }
}

/// One row of the predicted accuracy against `k`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PlanRow {
    /// Number of external measurements.
    pub k: usize,
    /// Planned: RMS predicted tool-tip standard deviation after touch-off, um.
    pub planned_um: f64,
    /// Planned, raw (no touch-off), um.
    pub planned_raw_um: f64,
    /// Median over random selections of `k` candidates, um (`None` when no
    /// baseline was asked for).
    pub random_median_um: Option<f64>,
    /// The planned candidates (indices).
    pub selection: Vec<usize>,
}

/// The predicted accuracy against `k`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Plan {
    /// The prior alone, um (after touch-off).
    pub prior_only_um: f64,
    /// The internal campaign alone (with the prior), um.
    pub internal_only_um: f64,
    /// One row per requested `k`, ascending.
    pub rows: Vec<PlanRow>,
}

/// Plans `ks` measurements each: the greedy path to the largest `k`, then
/// the exchange (at most `passes` passes) at each; `random_draws` random
/// selections per `k` (seeded, PCG-64 MCG) for the baseline.
pub fn plan(
    problem: &PlanProblem,
    ks: &[usize],
    passes: usize,
    random_draws: usize,
    seed: u64,
) -> Result<Plan, StudyError> {
    let mut ks: Vec<usize> = ks.to_vec();
    ks.sort_unstable();
    ks.dedup();
    let largest = ks.last().copied().unwrap_or(0);
    if largest > problem.len() {
        return Err(StudyError::Invalid(format!(
            "{largest} measurements asked for, but only {} candidates",
            problem.len()
        )));
    }
    let path = greedy(problem, &[], largest);
    let prior_only = {
        let mut p = problem.clone();
        p.lambda0 = DMatrix::identity(p.lambda0.nrows(), p.lambda0.ncols());
        p.rms_um(&[]).1
    };
    let rows = ks
        .iter()
        .map(|&k| {
            let selection = exchange_with(problem, &path[..k], passes).indices;
            let (raw, touched) = problem.rms_um(&selection);
            let random_median_um = (random_draws > 0).then(|| {
                let mut values: Vec<f64> = (0..random_draws)
                    .into_par_iter()
                    .map(|d| {
                        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ ((k as u64) << 32) ^ d as u64);
                        let pick = sample(&mut rng, problem.len(), k).into_vec();
                        problem.rms_um(&pick).1
                    })
                    .collect();
                values.sort_by(f64::total_cmp);
                quantile(&values, 0.5)
            });
            PlanRow {
                k,
                planned_um: touched,
                planned_raw_um: raw,
                random_median_um,
                selection,
            }
        })
        .collect();
    Ok(Plan {
        prior_only_um: prior_only,
        internal_only_um: problem.rms_um(&[]).1,
        rows,
    })
}

/// The information of an internal campaign at the platform points
/// `targets_mm` (commanded by the nominal IK) on the global parameters of
/// `model`, with the machine's sensor noise ([`information`]).
pub fn internal_information(
    model: &FusedModel,
    targets_mm: &[Vector3<f64>],
) -> Result<DMatrix<f64>, StudyError> {
    let m = model.nominal();
    let poses = targets_mm
        .iter()
        .map(|r| {
            Ok(MeasuredPose {
                commands_mm: m.inverse(r)?.legs_mm,
                ..Default::default()
            })
        })
        .collect::<Result<_, StudyError>>()?;
    let data = tricept_data::Dataset {
        poses,
        source: "internal campaign".into(),
    };
    Ok(information(
        model,
        &[Source::internal(&data, m.sensors.logged_sigma())],
    )?)
}

/// Ballbar candidates: `n` ball positions spread (Fibonacci lattice) over
/// the cap of the sphere of radius `length_mm` about `pivot_mm` facing the
/// machine (up to 70 deg from -z), each with the tool tilted 0.2-0.5 rad
/// in a turning direction, solved by the nominal tool IK; unreachable ones
/// are left out.
pub fn ballbar_candidates(
    nominal: &Machine,
    pivot_mm: &Vector3<f64>,
    length_mm: f64,
    n: usize,
) -> Vec<ExternalPose> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let cap = 70f64.to_radians().cos();
    (0..n)
        .filter_map(|j| {
            let f = (j as f64 + 0.5) / n as f64;
            let cos_polar = 1.0 - f * (1.0 - cap);
            let sin_polar = (1.0 - cos_polar * cos_polar).sqrt();
            let azimuth = golden * j as f64;
            let u = Vector3::new(
                sin_polar * azimuth.cos(),
                sin_polar * azimuth.sin(),
                -cos_polar,
            );
            let tilt = 0.2 + 0.3 * ((j * 7) % 4) as f64 / 3.0;
            let turn = std::f64::consts::TAU * ((j * 3) % 8) as f64 / 8.0;
            let axis = Vector3::new(tilt.sin() * turn.cos(), tilt.sin() * turn.sin(), tilt.cos());
            let ik = nominal
                .tool_inverse(&(pivot_mm + u * length_mm), &axis, HeadBranch::default())
                .ok()?;
            Some(ExternalPose {
                commands_mm: ik.legs_mm,
                head_rad: ik.head_rad,
            })
        })
        .collect()
}

/// The nominal tool tips at `poses`.
fn nominal_tips(
    model: &FusedModel,
    poses: &[ExternalPose],
) -> Result<Vec<Vector3<f64>>, StudyError> {
    let p = vec![0.0; model.len()];
    poses
        .iter()
        .map(|pose| Ok(model.spindle_point(&p, pose, &Effector::default())?.0))
        .collect()
}

/// Tracker data at `poses` as the nominal machine would give them (frame
/// identity), for [`design_rows`].
pub fn nominal_tracker_data(
    model: &FusedModel,
    poses: &[ExternalPose],
) -> Result<TrackerData, StudyError> {
    let records = poses
        .iter()
        .zip(nominal_tips(model, poses)?)
        .map(|(pose, x)| TrackerPoint {
            pose: *pose,
            position_mm: x.into(),
            setup: 1,
            ..Default::default()
        })
        .collect();
    Ok(ExternalData {
        records,
        source: "candidates".into(),
    })
}

/// Ballbar data at `poses` as the nominal machine would give them, for
/// [`design_rows`].
pub fn nominal_ballbar_data(
    model: &FusedModel,
    poses: &[ExternalPose],
    pivot_mm: &Vector3<f64>,
) -> Result<BallbarData, StudyError> {
    let records = poses
        .iter()
        .zip(nominal_tips(model, poses)?)
        .map(|(pose, x)| BallbarReading {
            pose: *pose,
            length_mm: (x - pivot_mm).norm(),
            setup: 1,
            ..Default::default()
        })
        .collect();
    Ok(ExternalData {
        records,
        source: "candidates".into(),
    })
}

/// [`design_rows`] with the study's error type.
pub fn candidate_rows(
    model: &FusedModel,
    source: &tricept_ident::fusion::Source,
) -> Result<DesignRows, StudyError> {
    Ok(design_rows(model, source)?)
}
