//! The fast Monte Carlo path: one factorisation per encoder grade, then
//! every trial's noise through two small products and the plane's norms, in
//! SIMD lanes (the trial kernel, `kernel.rs`).
//!
//! The identification matrix depends only on the poses (not on the noise),
//! so around the noise-free estimate `p*` the estimate of a trial is
//! `p* + M z`, where `z` is the trial's standard-normal noise of the weighted
//! readings and `M` the parameter rows of the pseudo-inverse of the weighted
//! `[offsets | J E]` restricted to the identifiable columns (computed once
//! from a thin QR). `M z` is sampled exactly through the triangular factor
//! of `M M^T` ([`LinearEstimator::new`]), a block of trials at a time. `p*` itself comes from the exact nonlinear
//! identification of the noise-free readings, so the deterministic part
//! (unidentifiable parameters held at zero, second-order effects) is exact;
//! only the noise is propagated to first order, which the exact path checks.
//! The compensated error on the plane is `dr0 - G (p_hat - p*)`, with `dr0`
//! the exact map for `p*` and `G` the first-order platform-position Jacobian.
//!
//! Trials run in blocks of [`BLOCK`]; each block has its own generator
//! seeded from (seed, grade, block), so results are bit-identical at any
//! thread count.

use faer::Mat;
use rayon::prelude::*;
use tricept_engine::{
    IdentifyOptions, identify::Design, identify::Start, identify::design, identify::identify_from,
    model::GeometricModel, model::ReadingModel,
};
use tricept_kinematics::up_limb::UpJoints;
use tricept_model::{jacobian::position_error_jacobian, volumetric::volumetric_errors};

use crate::kernel::Kernel;
use crate::rng::block_rng;
use crate::scenario::Scenario;
use crate::{StudyError, results::TrialResult};

/// Trials per block (the unit of parallel work and of seeding).
pub const BLOCK: usize = 512;

/// `trials` results computed a block of [`BLOCK`] trials at a time in
/// parallel, `per_block(block, n)` giving the `n` results of block `block`,
/// collected in block order (the same result at any thread count).
fn in_blocks<T: Send>(trials: usize, per_block: impl Fn(u64, usize) -> Vec<T> + Sync) -> Vec<T> {
    let blocks = trials.div_ceil(BLOCK);
    let results: Vec<Vec<T>> = (0..blocks)
        .into_par_iter()
        .map(|b| per_block(b as u64, BLOCK.min(trials - b * BLOCK)))
        .collect();
    results.into_iter().flatten().collect()
}

/// An estimator that is linear in the noise: `p_hat = p* + M z` on the
/// parameters `columns` (the others stay at `p*`), with the compensated
/// plane error `dr0 - G (p_hat - p*)`.
#[derive(Debug, Clone)]
pub struct LinearEstimator {
    /// The estimate without noise.
    pub p_star: Vec<f64>,
    /// Parameters that move with the noise (the identifiable ones).
    pub columns: Vec<usize>,
    /// `T` (columns x columns) with `T T^T = M M^T`, where `M` (columns x
    /// m) maps the readings' standard-normal noise to the estimate (see
    /// [`LinearEstimator::new`]).
    pub factor: Mat<f64>,
    /// `G` (3 n_plane x columns): first-order platform error on the plane
    /// per unit of each parameter.
    pub plane_jacobian: Mat<f64>,
    /// `dr0` (3 n_plane): compensated error on the plane with `p*`.
    pub plane_clean: Vec<f64>,
}

/// Everything the fast path needs for one encoder grade.
#[derive(Debug, Clone)]
pub struct GradeModel {
    /// Encoder grade, arcsec.
    pub grade_arcsec: f64,
    /// Logged noise `[phi, theta, s]`.
    pub sigma: [f64; 3],
    /// Rank decision and report for this grade's weighting.
    pub design: Design,
    /// Offsets estimated with `p*`.
    pub offsets_star: [f64; 3],
    /// The estimator around the exact noise-free estimate.
    pub estimator: LinearEstimator,
}

/// `G`: platform position error on the plane per unit of each parameter in
/// `columns`, first order at the nominal machine (3 n_plane x columns).
pub fn plane_jacobian(s: &Scenario, columns: &[usize]) -> Result<Mat<f64>, StudyError> {
    let k = s.set.len();
    let mut block = vec![0.0; 3 * k];
    let mut g = Mat::<f64>::zeros(3 * s.plane_mm.len(), columns.len());
    for (t, r) in s.plane_mm.iter().enumerate() {
        let up = s.nominal.inverse(r)?.up;
        let jp = position_error_jacobian(&s.nominal.legs_at(&up))?;
        s.set.project(3, |row, f| jp[(row, f)], &mut block);
        for (u, &col) in columns.iter().enumerate() {
            for row in 0..3 {
                g[(3 * t + row, u)] = block[row * k + col];
            }
        }
    }
    Ok(g)
}

/// The geometric model of a scenario.
pub fn model_of(s: &Scenario) -> GeometricModel {
    GeometricModel::new(s.nominal.clone(), s.set.clone())
}

/// Identification options for `s` at `grade_arcsec`.
pub fn options_for(s: &Scenario, grade_arcsec: f64) -> IdentifyOptions {
    IdentifyOptions::with_sigma(s.logged_sigma(grade_arcsec))
}

/// The start of every identification of `s`: FK seeds at the true joints
/// and the shared rank decision when given.
pub fn start_for(s: &Scenario, design: Option<&Design>) -> Start {
    Start {
        design: design.cloned(),
        fk_seeds: Some(s.true_up.clone()),
        ..Start::default()
    }
}

impl GradeModel {
    /// Prepares the fast path of `s` for an encoder of `grade_arcsec`.
    pub fn new(s: &Scenario, grade_arcsec: f64) -> Result<GradeModel, StudyError> {
        let model = model_of(s);
        let k = s.set.len();
        let options = options_for(s, grade_arcsec);
        let design = design(&model, &vec![0.0; k], &s.clean, &options)?;
        let clean = tricept_data::Dataset {
            poses: s.clean.clone(),
            source: "noise-free".into(),
        };
        let id = identify_from(&model, &clean, &options, &start_for(s, Some(&design)))?;
        let p_star = id.estimate.clone();
        let sigma = options.sigma;
        let ident = design.identifiable().to_vec();

        // Weighted [offsets | J E] at p*, identifiable columns only.
        let predictor = model.at(&p_star);
        let m = s.rows();
        let q = 3 + ident.len();
        let mut a = Mat::<f64>::zeros(m, q);
        let mut jac = vec![0.0; 3 * k];
        for (j, pose) in s.clean.iter().enumerate() {
            let mut seed: Option<UpJoints> = Some(s.true_up[j]);
            predictor
                .predict(pose, &mut seed, &mut jac)
                .map_err(|e| StudyError::Invalid(format!("pose {}: {e}", j + 1)))?;
            for c in 0..3 {
                let w = 1.0 / sigma[c];
                a[(3 * j + c, c)] = w;
                for (t, &col) in ident.iter().enumerate() {
                    a[(3 * j + c, 3 + t)] = w * jac[c * k + col];
                }
            }
        }
        let qr = a.qr();
        let q_thin = qr.compute_thin_Q();
        let r = qr.thin_R().to_owned();
        let r_inv = tricept_numerics::linalg::invert_upper(r.as_ref());
        let pinv = &r_inv * q_thin.transpose(); // q x m
        let operator = pinv.as_ref().subrows(3, ident.len()).to_owned();

        // The plane: exact compensated error at p*, first-order Jacobian.
        let identified = model.machine_at(&p_star);
        let clean_map = volumetric_errors(&identified, &s.actual, &s.plane_mm)?;
        let plane_clean: Vec<f64> = clean_map
            .errors_mm
            .iter()
            .flat_map(|e| [e.x, e.y, e.z])
            .collect();
        Ok(GradeModel {
            grade_arcsec,
            sigma,
            offsets_star: id.offsets,
            estimator: LinearEstimator::new(
                p_star,
                ident.clone(),
                operator,
                plane_jacobian(s, &ident)?,
                plane_clean,
            ),
            design,
        })
    }
}

impl LinearEstimator {
    /// An estimator `p_hat = p* + M z`, `z ~ N(0, I_m)` the weighted noise of
    /// the `m` readings. With the thin QR `M^T = Q R`, `M z = R^T (Q^T z)`
    /// and `Q^T z ~ N(0, I_q)` exactly (Q has orthonormal columns), so a
    /// trial draws `q` normals instead of `m` (15 instead of 225 for the
    /// default pose set): the same distribution, an order of magnitude
    /// less sampling. The exact path, which draws every reading's noise,
    /// checks it.
    pub fn new(
        p_star: Vec<f64>,
        columns: Vec<usize>,
        operator: Mat<f64>,
        plane_jacobian: Mat<f64>,
        plane_clean: Vec<f64>,
    ) -> LinearEstimator {
        let q = operator.nrows();
        let r = tricept_numerics::linalg::r_factor(operator.transpose());
        let factor = Mat::from_fn(q, q, |i, j| r[(j, i)]);
        LinearEstimator {
            p_star,
            columns,
            factor,
            plane_jacobian,
            plane_clean,
        }
    }

    /// Runs `trials` fast-path trials; `grade_index` enters the seeding.
    pub fn run(
        &self,
        s: &Scenario,
        trials: usize,
        seed: u64,
        grade_index: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Vec<TrialResult> {
        let mut offset = Vec::with_capacity(self.columns.len());
        let mut moving = vec![false; s.truth.len()];
        for &col in &self.columns {
            offset.push(s.truth[col] - self.p_star[col]);
            moving[col] = true;
        }
        let held = (0..s.truth.len().min(self.p_star.len()))
            .filter(|&i| !moving[i])
            .map(|i| (s.truth[i] - self.p_star[i]).abs())
            .sum();
        let kernel = self.kernel(offset, held, s.truth.len());
        in_blocks(trials, |block, n| {
            let mut rng = block_rng(seed, grade_index, block);
            let out = kernel.trials(&mut rng, n, true);
            progress(n as u64);
            out
        })
    }

    /// The trial kernel of this estimator, `mu` measured as `(held +
    /// sum_u |offset_u - dp_u|) / n_params`.
    fn kernel(&self, offset: Vec<f64>, held: f64, n_params: usize) -> Kernel {
        Kernel::new(
            |u, k| self.factor[(u, k)],
            self.factor.nrows(),
            |r, u| self.plane_jacobian[(r, u)],
            self.plane_clean.clone(),
            offset,
            held,
            n_params,
        )
    }

    /// The part of `mu` that is noise alone, `||p_hat - p*||_1 / n_params`,
    /// for `trials` trials drawn exactly as [`LinearEstimator::run`] draws
    /// them (same seed, same `grade_index`: the same trials). Two
    /// estimators with the same number of columns, run with the same seed,
    /// see the same standard-normal draws (common random numbers).
    ///
    /// # Example
    /// ```
    /// use tricept_kinematics::Machine;
    /// use tricept_study::{fast::GradeModel, Scenario};
    /// let m = Machine::paper();
    /// let s = Scenario::paper(m.clone(), m.workspace.polar_grid(2, 8, 3)).unwrap();
    /// let g = GradeModel::new(&s, 2.0).unwrap();
    /// let noise = g.estimator.noise_mu(15, 1000, 1, 0);
    /// let full = g.estimator.run(&s, 1000, 1, 0, &|_| {});
    /// // mu = |truth - p* - dp|_1 / 15 and noise part = |dp|_1 / 15:
    /// // they differ by at most mu(p*).
    /// let bias = tricept_model::params::residual_mu(&s.truth, &g.estimator.p_star);
    /// for (a, t) in noise.iter().zip(&full) {
    ///     assert!((a - t.mu_mm).abs() <= bias + 1e-12);
    /// }
    /// ```
    pub fn noise_mu(
        &self,
        n_params: usize,
        trials: usize,
        seed: u64,
        grade_index: u64,
    ) -> Vec<f64> {
        let kernel = self.kernel(vec![0.0; self.columns.len()], 0.0, n_params);
        in_blocks(trials, |block, n| {
            let mut rng = block_rng(seed, grade_index, block);
            kernel
                .trials(&mut rng, n, false)
                .into_iter()
                .map(|t| t.mu_mm)
                .collect()
        })
    }
}
