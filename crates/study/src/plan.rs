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
//! **The tool axis.** With known extensions along the tool among the
//! candidates (`tricept plan --extensions 0,100`), the criterion adds the
//! mean squared predicted tool-axis error times `(100 mm)^2` (the axis seen
//! as the error of a point 100 mm up the tool), so that the plan fixes the
//! tool's direction too; [`PlanProblem::axis_arcsec`] predicts it for any
//! selection.
//!
//! **Redundancy.** A plan is only as good as what its measurements can
//! check: [`PlanProblem::redundancy`] is the degrees of freedom the
//! selection's rows keep in the (prior-free) fused fit with the internal
//! campaign, `sum (1 - h_ii)` over them, as
//! [`tricept_engine::fusion::SourceFit::redundancy`]; a selection below the
//! source's [`DesignRows::min_redundancy`] (6 per tracker station, 4 per
//! ballbar setup or touched sphere) fits whatever its rows hold.
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
    external::BallbarData, external::BallbarReading, external::ExternalData,
    external::ExternalPose, external::TouchData, external::TouchReading, external::TrackerData,
    external::TrackerPoint,
};
use tricept_engine::fusion::{DesignRows, FusedModel, Source, design_rows, information_factor};
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{Machine, head::HeadBranch};
use tricept_model::head_errors::Effector;
use tricept_numerics::linalg::TriangularAccumulator;
use tricept_numerics::lsq::{DEFAULT_RANK_TOLERANCE, ReducedProblem};

use crate::StudyError;
use crate::optimise::{ExchangeCriterion, exchange_with, greedy};
use tricept_numerics::stats::quantile;

/// Prior standard deviation of an instrument's nuisance parameter: what a
/// closed-form start leaves (10 mrad for an angle, 10 mm for a length).
fn nuisance_prior(name: &str) -> f64 {
    if name.ends_with("_rad") { 0.01 } else { 10.0 }
}

/// The lever over which the tool axis enters the criterion, mm.
pub const AXIS_LEVER_MM: f64 = 100.0;

/// The planning problem in whitened coordinates (see the module docs).
#[derive(Debug, Clone)]
pub struct PlanProblem {
    /// `I + D F D` (parameters first, then the instrument's nuisance).
    lambda0: DMatrix<f64>,
    /// Whitened rows of each candidate (`r x n`).
    rows: Vec<DMatrix<f64>>,
    /// The criterion's weight (`n x n`, mm^2): the tip after touch-off, and
    /// the axis times the lever squared when asked for.
    criterion: DMatrix<f64>,
    /// The tip after touch-off (`n x n`, mm^2).
    touch_off: DMatrix<f64>,
    /// The same without touch-off (raw tool tip).
    raw: DMatrix<f64>,
    /// The tool axis (`n x n`, rad^2).
    axis: DMatrix<f64>,
    /// The internal campaign's information factor (`r x k`).
    internal: DMatrix<f64>,
    /// The candidates' unwhitened rows and priors.
    design: DesignRows,
    /// Typical sizes of the parameters (the rank rule's pivot weights).
    typical: Vec<f64>,
}

impl PlanProblem {
    /// The problem for `model` with the internal campaign's information
    /// factor `internal` (`r x k` with information `R^T R`,
    /// [`tricept_engine::fusion::information_factor`], [`internal_factor`];
    /// zero rows for none), candidate measurements `candidates` (one
    /// instrument's [`DesignRows`]) and the tool poses `eval` the criterion
    /// averages over.
    pub fn new(
        model: &FusedModel,
        internal: &DMatrix<f64>,
        candidates: &DesignRows,
        eval: &[ExternalPose],
    ) -> Result<PlanProblem, StudyError> {
        let k = model.len();
        let nn = candidates.nuisance_names.len();
        if internal.ncols() != k {
            return Err(StudyError::Invalid(format!(
                "the internal information factor has {} columns, expected {k}",
                internal.ncols()
            )));
        }
        let information = internal.transpose() * internal;
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
                lambda0[(i, j)] += sigma[i] * information[(i, j)] * sigma[j];
            }
        }
        let priors = whiten(&candidates.priors);
        lambda0 += priors.transpose() * &priors;
        let rows: Vec<DMatrix<f64>> = candidates.records.iter().map(whiten).collect();
        let lever = Effector {
            extension_mm: AXIS_LEVER_MM,
            ..Effector::default()
        };
        let mut g = Vec::with_capacity(eval.len());
        let mut ga = Vec::with_capacity(eval.len());
        for mut pair in
            model.spindle_jacobians(&vec![0.0; k], eval, &[Effector::default(), lever])?
        {
            let g1 = pair.pop().unwrap_or_default();
            let g0 = pair.pop().unwrap_or_default();
            ga.push((g1 - &g0) / AXIS_LEVER_MM);
            g.push(g0);
        }
        let e = g.len().max(1) as f64;
        let mean = g.iter().fold(DMatrix::zeros(3, k), |a, b| a + b) / e;
        let mut touch_off = DMatrix::zeros(n, n);
        let mut raw = DMatrix::zeros(n, n);
        let mut axis = DMatrix::zeros(n, n);
        let d = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            k,
            sigma[..k].iter().copied(),
        ));
        for (ge, gae) in g.iter().zip(&ga) {
            let a = ge * &d;
            let b = (ge - &mean) * &d;
            let c = gae * &d;
            let mut view = raw.view_mut((0, 0), (k, k));
            view += a.transpose() * &a / e;
            let mut view = touch_off.view_mut((0, 0), (k, k));
            view += b.transpose() * &b / e;
            let mut view = axis.view_mut((0, 0), (k, k));
            view += c.transpose() * &c / e;
        }
        Ok(PlanProblem {
            lambda0,
            rows,
            criterion: touch_off.clone(),
            touch_off,
            raw,
            axis,
            internal: internal.clone(),
            design: candidates.clone(),
            typical: model.typical_sizes(),
        })
    }

    /// The same problem with the tool axis in the criterion: the tip after
    /// touch-off plus the axis times [`AXIS_LEVER_MM`] squared (what
    /// `tricept plan --extensions` plans for).
    pub fn with_tool_axis(mut self) -> PlanProblem {
        self.criterion = &self.touch_off + &self.axis * (AXIS_LEVER_MM * AXIS_LEVER_MM);
        self
    }

    /// RMS predicted tool-axis standard deviation of a selection, arcsec.
    pub fn axis_arcsec(&self, selection: &[usize]) -> f64 {
        match Self::covariance(&self.lambda(selection)) {
            Some(s) => (&self.axis * &s).trace().max(0.0).sqrt() / RAD_PER_ARCSEC,
            None => f64::INFINITY,
        }
    }

    /// The redundancy of a selection (see the module docs): the degrees of
    /// freedom its rows keep in the prior-free fit with the internal
    /// campaign and the source's own priors.
    pub fn redundancy(&self, selection: &[usize]) -> f64 {
        let nn = self.design.nuisance_names.len();
        let k = self.internal.ncols();
        let width = nn + k;
        let mut acc = TriangularAccumulator::new(width + 1);
        let mut row = vec![0.0; width + 1];
        for i in 0..self.internal.nrows() {
            row.iter_mut().for_each(|v| *v = 0.0);
            for j in 0..k {
                row[nn + j] = self.internal[(i, j)];
            }
            acc.push_row(&row);
        }
        let selected: Vec<Vec<f64>> = selection
            .iter()
            .flat_map(|&c| {
                let m = &self.design.records[c];
                (0..m.nrows()).map(move |i| m.row(i).iter().copied().collect::<Vec<f64>>())
            })
            .collect();
        let priors = &self.design.priors;
        for x in selected
            .iter()
            .cloned()
            .chain((0..priors.nrows()).map(|i| priors.row(i).iter().copied().collect()))
        {
            row[..width].copy_from_slice(&x);
            row[width] = 0.0;
            acc.push_row(&row);
        }
        let problem = ReducedProblem {
            rows: acc.rows(),
            r: acc.finish(),
            n_nuisance: nn,
            k,
        };
        let Some(decision) = problem.decide_weighted(DEFAULT_RANK_TOLERANCE, Some(&self.typical))
        else {
            return 0.0;
        };
        let hat = problem.hat_factor(&decision);
        let redundancy: f64 = selected
            .iter()
            .map(|x| 1.0 - hat.whiten(x).iter().map(|w| w * w).sum::<f64>())
            .sum();
        // Below one row per unknown the rounding of saturated leverages can
        // leave a small negative sum: nothing is redundant.
        redundancy.max(0.0)
    }

    /// The redundancy a selection needs to check a fit.
    pub fn min_redundancy(&self) -> f64 {
        self.design.min_redundancy
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
            Some(s) => -(&self.criterion * s).trace(),
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
        let phi = (&self.criterion * &sigma).trace();
        candidates
            .par_iter()
            .map(|&c| {
                let a = &self.rows[c];
                let u = &sigma * a.transpose();
                let s = DMatrix::identity(a.nrows(), a.nrows()) + a * &u;
                let m = u.transpose() * &self.criterion * &u;
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
    /// Planned: RMS predicted tool-axis standard deviation, arcsec.
    pub axis_arcsec: f64,
    /// The planned selection's redundancy ([`PlanProblem::redundancy`]).
    pub redundancy: f64,
    /// Whether it reaches the source's minimum redundancy.
    pub checkable: bool,
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
    /// The internal campaign alone: the tool axis, arcsec.
    pub internal_only_axis_arcsec: f64,
    /// The redundancy a selection needs to check a fit.
    pub min_redundancy: f64,
    /// One row per requested `k`, ascending.
    pub rows: Vec<PlanRow>,
}

impl Plan {
    /// The smallest planned `k` whose selection is checkable and, when a
    /// target is given, predicts at most `target_um` after touch-off (and,
    /// with `axis_arcsec`, at most that on the tool axis).
    ///
    /// # Example
    /// ```
    /// use tricept_study::plan::{Plan, PlanRow};
    /// let row = |k, um, red| PlanRow { k, planned_um: um, planned_raw_um: um, random_median_um: None,
    ///     axis_arcsec: 10.0, redundancy: red, checkable: red >= 6.0, selection: vec![] };
    /// let plan = Plan { prior_only_um: 700.0, internal_only_um: 300.0, internal_only_axis_arcsec: 90.0,
    ///     min_redundancy: 6.0, rows: vec![row(5, 23.0, 0.0), row(12, 13.0, 19.0), row(30, 10.0, 70.0)] };
    /// // k = 5 reaches 25 um but nothing in it can be checked.
    /// assert_eq!(plan.recommended(Some(25.0), None), Some(12));
    /// assert_eq!(plan.recommended(Some(11.0), None), Some(30));
    /// assert_eq!(plan.recommended(Some(5.0), None), None);
    /// ```
    pub fn recommended(&self, target_um: Option<f64>, axis_arcsec: Option<f64>) -> Option<usize> {
        self.rows
            .iter()
            .find(|r| {
                r.checkable
                    && target_um.is_none_or(|t| r.planned_um <= t)
                    && axis_arcsec.is_none_or(|a| r.axis_arcsec <= a)
            })
            .map(|r| r.k)
    }
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
            let redundancy = problem.redundancy(&selection);
            PlanRow {
                k,
                planned_um: touched,
                planned_raw_um: raw,
                random_median_um,
                axis_arcsec: problem.axis_arcsec(&selection),
                redundancy,
                checkable: redundancy >= problem.min_redundancy() - 1e-9,
                selection,
            }
        })
        .collect();
    Ok(Plan {
        prior_only_um: prior_only,
        internal_only_um: problem.rms_um(&[]).1,
        internal_only_axis_arcsec: problem.axis_arcsec(&[]),
        min_redundancy: problem.min_redundancy(),
        rows,
    })
}

/// The information factor of an internal campaign at the platform points
/// `targets_mm` (commanded by the nominal IK) on the global parameters of
/// `model`, with the machine's sensor noise ([`information_factor`]): what
/// [`PlanProblem::new`] takes.
pub fn internal_factor(
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
    Ok(information_factor(
        model,
        &[Source::internal(&data, m.sensors.logged_sigma())],
    )?)
}

/// The information of an internal campaign ([`internal_factor`] `R`, as
/// `R^T R`).
pub fn internal_information(
    model: &FusedModel,
    targets_mm: &[Vector3<f64>],
) -> Result<DMatrix<f64>, StudyError> {
    let r = internal_factor(model, targets_mm)?;
    Ok(r.transpose() * r)
}

/// Candidates on a sphere: `n` tool-tip positions spread (Fibonacci
/// lattice) over the cap of the sphere of radius `radius_mm` about
/// `centre_mm` facing the machine (up to 70 deg from -z), each with the
/// tool tilted 0.2-0.5 rad in a turning direction, solved by the nominal
/// tool IK; unreachable ones are left out. A ballbar's ball positions about
/// its pivot (radius: the bar's length), or a probe's stylus centres on a
/// reference sphere (radius: sphere plus stylus).
pub fn sphere_candidates(
    nominal: &Machine,
    centre_mm: &Vector3<f64>,
    radius_mm: f64,
    n: usize,
) -> Vec<ExternalPose> {
    let pivot_mm = centre_mm;
    let length_mm = radius_mm;
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

/// The nominal tool tips at `poses`, each `extension_mm` up the tool.
fn nominal_tips(
    model: &FusedModel,
    poses: &[(ExternalPose, f64)],
) -> Result<Vec<Vector3<f64>>, StudyError> {
    let p = vec![0.0; model.len()];
    poses
        .iter()
        .map(|(pose, extension_mm)| {
            let effector = Effector {
                extension_mm: *extension_mm,
                ..Effector::default()
            };
            Ok(model.spindle_point(&p, pose, &effector)?.0)
        })
        .collect()
}

/// Every pose with every extension (pose-major): tracker candidates.
///
/// # Example
/// ```
/// use tricept_data::external::ExternalPose;
/// let c = tricept_study::plan::with_extensions(&[ExternalPose::default(); 2], &[0.0, 100.0]);
/// assert_eq!(c.iter().map(|x| x.1).collect::<Vec<_>>(), vec![0.0, 100.0, 0.0, 100.0]);
/// ```
pub fn with_extensions(poses: &[ExternalPose], extensions_mm: &[f64]) -> Vec<(ExternalPose, f64)> {
    poses
        .iter()
        .flat_map(|p| extensions_mm.iter().map(move |e| (*p, *e)))
        .collect()
}

/// Tracker data at `(pose, extension)` candidates as the nominal machine
/// would give them (frame identity), for [`design_rows`].
pub fn nominal_tracker_data(
    model: &FusedModel,
    poses: &[(ExternalPose, f64)],
) -> Result<TrackerData, StudyError> {
    let records = poses
        .iter()
        .zip(nominal_tips(model, poses)?)
        .map(|((pose, extension_mm), x)| TrackerPoint {
            pose: *pose,
            position_mm: x.into(),
            extension_mm: *extension_mm,
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
    let at: Vec<(ExternalPose, f64)> = poses.iter().map(|p| (*p, 0.0)).collect();
    let records = poses
        .iter()
        .zip(nominal_tips(model, &at)?)
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

/// Touch-offs on a reference sphere (feature `feature`) at `poses` as the
/// nominal machine would give them, for [`design_rows`] with the features
/// file `features` (which declares the sphere).
pub fn nominal_touch_data(poses: &[ExternalPose], feature: u32) -> Result<TouchData, StudyError> {
    let records = poses
        .iter()
        .map(|pose| TouchReading {
            pose: *pose,
            feature,
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
    source: &tricept_engine::fusion::Source,
) -> Result<DesignRows, StudyError> {
    Ok(design_rows(model, source)?)
}
