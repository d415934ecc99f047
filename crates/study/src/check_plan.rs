//! Planning a check (`tricept plan --instrument check`): the fewest poses
//! whose check detects a stated change of any single leg or joint
//! parameter with a stated power.
//!
//! A change of one of the 21 joint and length parameters `t` (the base and
//! platform joints' coordinates, the leg lengths) of size `D_t` moves the
//! platform by `D_t mean_r |P21(r)[:, t]|` on average over the workspace;
//! the size to detect is the one that moves it by `--detect-um` (default
//! 20 um). The check's test of that parameter alone has the non-centrality
//! `lambda_t = D_t^2 G_tt`, where `G` is the information of the check's
//! poses with the sensor offsets and the calibration's own uncertainty
//! projected out (as in [`tricept_check::check`](fn@tricept_check::check)): the campaign detects
//! the change with power `chi2_power(lambda_t, 1, level)` at the check's
//! family-wise level. The poses are chosen from the workspace's candidate
//! grid ([`crate::optimise::candidate_grid`]) to maximise the smallest
//! `lambda_t` over the parameters the check can see, by the sequential
//! exchange of [`crate::optimise`]; the number of poses grows from 4 until
//! every seen parameter reaches the power, or the budget is spent.

use nalgebra::{DMatrix, DVector, Vector3};
use serde::Serialize;
use tricept_check::{Reference, candidates::Candidate, check::family_level, check::leg_ranges};
use tricept_kinematics::Machine;
use tricept_model::{
    jacobian::error_jacobian, jacobian::position_error_jacobian, params::FULL21_NAMES,
    params::N_FULL,
};
use tricept_numerics::stats::chi2_power;

use crate::StudyError;
use crate::optimise::{ExchangeCriterion, candidate_grid, exchange_with, greedy};

/// What a planned check detects of one parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterDetection {
    /// `dxB1`, `dq2`, ...
    pub name: String,
    /// The change that moves the platform by the stated size, mm.
    pub target_mm: f64,
    /// The smallest change the check detects with the stated power, mm
    /// (`None`: the check cannot see this parameter).
    pub detectable_mm: Option<f64>,
    /// The same as a mean platform error over the workspace, um.
    pub detectable_platform_um: Option<f64>,
    /// The power against a change of `target_mm`.
    pub power: Option<f64>,
}

/// A planned check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckPlan {
    /// Number of poses.
    pub poses: usize,
    /// Their platform targets, mm.
    pub targets_mm: Vec<Vector3<f64>>,
    /// Whether every seen parameter reaches the power within the budget.
    pub reached: bool,
    /// Per parameter.
    pub parameters: Vec<ParameterDetection>,
}

/// The information of a selection, as running sums of the Gram matrix over
/// `[offsets | calibration directions | 21 parameters]`.
#[derive(Clone)]
struct Sums {
    gram: DMatrix<f64>,
}

struct Detection<'a> {
    /// Per candidate pose, its Gram contribution.
    blocks: &'a [DMatrix<f64>],
    /// The calibration's prior rows' Gram.
    prior: &'a DMatrix<f64>,
    /// Width of the nuisance block (offsets and calibration directions).
    n: usize,
    /// Squared target sizes of the seen parameters (index, D_t^2).
    targets: &'a [(usize, f64)],
}

impl Detection<'_> {
    /// `G_tt` of every parameter (the Schur complement's diagonal).
    fn information(&self, s: &Sums) -> Option<Vec<f64>> {
        let n = self.n;
        let w = s.gram.ncols();
        let m_nn = s.gram.view((0, 0), (n, n)).into_owned();
        let chol = m_nn.cholesky()?;
        let m_nt = s.gram.view((0, n), (n, w - n)).into_owned();
        let x = chol.l().solve_lower_triangular(&m_nt)?;
        Some(
            (0..w - n)
                .map(|t| s.gram[(n + t, n + t)] - x.column(t).norm_squared())
                .collect(),
        )
    }
}

impl ExchangeCriterion for Detection<'_> {
    type State = Sums;

    fn candidates(&self) -> usize {
        self.blocks.len()
    }

    fn state(&self, selection: &[usize]) -> Sums {
        let mut gram = self.prior.clone();
        for &j in selection {
            gram += &self.blocks[j];
        }
        Sums { gram }
    }

    fn value(&self, state: &Sums) -> f64 {
        match self.information(state) {
            Some(g) => self
                .targets
                .iter()
                .map(|&(t, d2)| d2 * g[t].max(0.0))
                .fold(f64::INFINITY, f64::min),
            None => f64::NEG_INFINITY,
        }
    }

    fn without(&self, state: &Sums, c: usize) -> Sums {
        Sums {
            gram: &state.gram - &self.blocks[c],
        }
    }

    fn with(&self, state: &Sums, c: usize) -> Sums {
        Sums {
            gram: &state.gram + &self.blocks[c],
        }
    }
}

/// The fewest poses, up to `budget`, whose check detects a change moving
/// the platform by `detect_um` (mean over the workspace) in any single seen
/// parameter with `power`, at the family-wise false-alarm probability
/// `alpha` (see the module docs).
///
/// # Example
/// ```
/// use nalgebra::DMatrix;
/// use tricept_check::Reference;
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let r = Reference::new(m, ParameterSet::paper15(), DMatrix::from_diagonal_element(15, 15, 1e-4), [0.0; 3], None).unwrap();
/// let plan = tricept_study::check_plan::plan_check(&r, 20.0, 0.95, 0.01, 20).unwrap();
/// assert!(plan.poses <= 20);
/// let of = |n: &str| plan.parameters.iter().find(|p| p.name == n).unwrap();
/// // The base joints' x and y are seen to a few um,
/// assert!(of("dxB1").power.unwrap() > 0.95);
/// // and the platform joint the UP limb's sensors cannot see is said to be.
/// assert!(of("dyA3").detectable_mm.is_none());
/// ```
pub fn plan_check(
    reference: &Reference,
    detect_um: f64,
    power: f64,
    alpha: f64,
    budget: usize,
) -> Result<CheckPlan, StudyError> {
    let machine = reference.machine();
    let sigma = machine.sensors.logged_sigma();
    let prior = reference.prior_directions();
    let set = reference.parameter_set();
    let k = set.len();
    let n = 3 + prior.len();
    let w = n + N_FULL;
    let grid = candidate_grid(machine);
    let mut block = vec![0.0; 3 * k];
    let mut blocks = Vec::with_capacity(grid.len());
    for r in &grid {
        let up = machine.inverse(r)?.up;
        let j21 = error_jacobian(machine, &up)?;
        set.project(3, |row, f| j21[(row, f)], &mut block);
        let mut b = DMatrix::zeros(3, w);
        for c in 0..3 {
            let s = 1.0 / sigma[c];
            b[(c, c)] = s;
            for (t, (_, u)) in prior.iter().enumerate() {
                b[(c, 3 + t)] = s * (0..k).map(|i| block[c * k + i] * u[i]).sum::<f64>();
            }
            for f in 0..N_FULL {
                b[(c, n + f)] = s * j21[(c, f)];
            }
        }
        blocks.push(b.transpose() * b);
    }
    let mut prior_gram = DMatrix::zeros(w, w);
    for (t, (lambda, _)) in prior.iter().enumerate() {
        prior_gram[(3 + t, 3 + t)] = 1.0 / lambda;
    }
    let mean_col = platform_columns(machine)?;
    let target_mm = mean_col.map(|c| {
        if c > 0.0 {
            detect_um * 1e-3 / c
        } else {
            f64::INFINITY
        }
    });
    // The parameters a check can see at all (from the whole grid), below
    // the tolerance: the others are reported as not seen.
    let all = Detection {
        blocks: &blocks,
        prior: &prior_gram,
        n,
        targets: &[],
    };
    let everything: Vec<usize> = (0..blocks.len()).collect();
    let g_all = all
        .information(&all.state(&everything))
        .unwrap_or_else(|| vec![0.0; N_FULL]);
    let seen: Vec<usize> = (0..N_FULL)
        .filter(|&t| g_all[t] > 0.0 && 1.0 / g_all[t].sqrt() < 0.25)
        .collect();
    let targets: Vec<(usize, f64)> = seen.iter().map(|&t| (t, target_mm[t].powi(2))).collect();
    let criterion = Detection {
        blocks: &blocks,
        prior: &prior_gram,
        n,
        targets: &targets,
    };
    let level = family_level(
        alpha,
        &Candidate::all(leg_ranges(machine)?, reference.temperature_c(), false),
    );
    let needed =
        tricept_numerics::stats::required_noncentrality(1.0, level, power).unwrap_or(f64::INFINITY);
    let budget = budget.clamp(4, grid.len());
    // The smallest count that reaches the power, by bisection (the
    // criterion grows with the poses); the budget when none does.
    let select = |poses: usize| -> (Vec<usize>, bool) {
        let start: Vec<usize> = (0..4).map(|i| i * grid.len() / 4).collect();
        let seeded = greedy(&criterion, &start, poses);
        let selection = exchange_with(&criterion, &seeded, 3);
        let reached = selection.value >= needed;
        (selection.indices, reached)
    };
    let mut best = select(budget);
    if best.1 {
        let (mut lo, mut hi) = (4, budget);
        while lo < hi {
            let mid = (lo + hi) / 2;
            let s = select(mid);
            if s.1 {
                hi = mid;
                best = s;
            } else {
                lo = mid + 1;
            }
        }
    }
    let indices = best.0;
    let g = criterion
        .information(&criterion.state(&indices))
        .unwrap_or_else(|| vec![0.0; N_FULL]);
    let parameters: Vec<ParameterDetection> = (0..N_FULL)
        .map(|t| {
            let is_seen = seen.contains(&t) && g.get(t).is_some_and(|&v| v > 0.0);
            let detectable_mm = is_seen.then(|| (needed / g[t]).sqrt());
            ParameterDetection {
                name: FULL21_NAMES[t].to_string(),
                target_mm: target_mm[t],
                detectable_mm,
                detectable_platform_um: detectable_mm.map(|d| d * mean_col[t] * 1e3),
                power: is_seen.then(|| chi2_power(target_mm[t].powi(2) * g[t], 1.0, level)),
            }
        })
        .collect();
    let reached = parameters
        .iter()
        .filter_map(|p| p.power)
        .all(|p| p >= power);
    Ok(CheckPlan {
        poses: indices.len(),
        targets_mm: indices.iter().map(|&i| grid[i]).collect(),
        reached,
        parameters,
    })
}

/// `mean_r |P21(r)[:, t]|` over the workspace's evaluation grid (mm/mm).
fn platform_columns(machine: &Machine) -> Result<[f64; N_FULL], StudyError> {
    let points = tricept_engine::accuracy::accuracy_points(machine);
    let mut sum = [0.0; N_FULL];
    for r in &points {
        let up = machine.inverse(r)?.up;
        let p21 = position_error_jacobian(&machine.legs_at(&up))?;
        for (t, s) in sum.iter_mut().enumerate() {
            *s += DVector::from_fn(3, |c, _| p21[(c, t)]).norm();
        }
    }
    Ok(sum.map(|s| s / points.len() as f64))
}
