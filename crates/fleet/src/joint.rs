//! The joint fit of a batch: every reading of every member machine at once,
//! on the exact model, by Gauss-Newton on the block-arrow problem of
//! [`tricept_numerics::sparse`].
//!
//! Unknowns: per machine its three sensor offsets and its parameters whose
//! spread is above zero (*locals*), and the batch mean `mu` (*globals*). A
//! parameter whose spread is zero is `mu` itself on every machine: its
//! Jacobian columns go to the global column. Rows: every reading weighted
//! by `1/sigma`, and per machine one prior row per spread parameter,
//! `(p_mk - mu_k) / tau_k = 0`. The step is halved until the total
//! chi-square (readings, the offsets re-fitted, and prior rows) does not
//! rise; the fit has converged when every step is below 1e-3 of the
//! unknown's standard deviation. The covariances (each machine's
//! parameters with the mean's uncertainty, the mean's) come from the block
//! elimination at the last point, whichever factorisation solved the steps.

use std::time::Instant;

use nalgebra::DMatrix;
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_engine::model::ReadingModel;
use tricept_kinematics::up_limb::UpJoints;
use tricept_numerics::sparse::{
    BlockProblem, ReducedBlock, RowBlock, SolveStats, SolverKind, solve_globals,
};

use crate::error::FleetError;

/// What the joint fit starts from and how it is weighted.
pub struct JointInput<'a> {
    /// The reading model (its parameters: the batch's set).
    pub model: &'a dyn ReadingModel,
    /// Each member's poses (gross readings removed).
    pub data: Vec<&'a Dataset>,
    /// Each member's starting parameters (all `k`; its own estimate).
    pub start: Vec<Vec<f64>>,
    /// The identifiable parameters' indices (the others are held at zero).
    pub identifiable: &'a [usize],
    /// The spread `tau_k^2` of each identifiable parameter, mm^2 (zero:
    /// the parameter is the batch mean on every machine).
    pub spread_variance: &'a [f64],
    /// The mean to start from.
    pub mean_start: Vec<f64>,
    /// Per member the standard deviation scale of each identifiable
    /// parameter, and last the mean's: the convergence test's units.
    pub scales: Vec<Vec<f64>>,
    /// The logged noise `[phi, theta, s]`.
    pub sigma: [f64; 3],
    /// The factorisation of the steps.
    pub kind: SolverKind,
    /// Gauss-Newton iterations at most.
    pub max_iterations: u32,
}

/// The joint fit.
#[derive(Debug, Clone)]
pub struct JointFit {
    /// Each member's parameters (all `k`, held ones at zero).
    pub parameters: Vec<Vec<f64>>,
    /// Each member's sensor offsets `[phi, theta, s]`.
    pub offsets: Vec<[f64; 3]>,
    /// The batch mean (identifiable parameters).
    pub mean: Vec<f64>,
    /// Its covariance.
    pub mean_covariance: DMatrix<f64>,
    /// Each member's covariance of its identifiable parameters, the mean's
    /// uncertainty included.
    pub covariances: Vec<DMatrix<f64>>,
    /// Each member's readings' chi-square.
    pub chi_square_readings: Vec<f64>,
    /// The prior rows' chi-square.
    pub chi_square_prior: f64,
    /// Readings in all.
    pub readings: usize,
    /// The last step's solve (its size), with `seconds` the time of every
    /// step's solve together.
    pub stats: SolveStats,
    /// Wall time of the whole fit (evaluations of the exact model
    /// included), s.
    pub fit_seconds: f64,
    /// Gauss-Newton iterations.
    pub iterations: u32,
    /// Whether the iteration met its tolerance.
    pub converged: bool,
}

/// One member evaluated at its parameters: its rows and chi-square parts.
struct Evaluated {
    block: RowBlock,
    chi_square_readings: f64,
    chi_square_prior: f64,
    offsets: [f64; 3],
}

/// The column layout: which identifiable parameters are local.
struct Layout<'a> {
    identifiable: &'a [usize],
    /// Per identifiable parameter its local position (after the three
    /// offsets), `None` when it is global (zero spread).
    local: Vec<Option<usize>>,
    tau: Vec<f64>,
}

impl Layout<'_> {
    fn n_local(&self) -> usize {
        3 + self.local.iter().flatten().count()
    }
}

/// Member `p` (all `k`) evaluated with the batch mean `mean`.
fn evaluate(
    model: &dyn ReadingModel,
    data: &Dataset,
    p: &[f64],
    mean: &[f64],
    seeds: &mut [Option<UpJoints>],
    layout: &Layout<'_>,
    sigma: &[f64; 3],
) -> Result<Evaluated, FleetError> {
    let k = p.len();
    let r = layout.identifiable.len();
    let l = layout.n_local();
    let spread: Vec<(usize, usize)> = layout
        .local
        .iter()
        .enumerate()
        .filter_map(|(a, pos)| pos.map(|pos| (a, pos)))
        .collect();
    let n = data.poses.len();
    let mut rows = faer::Mat::<f64>::zeros(3 * n + spread.len(), l + r + 1);
    let predictor = model.at(p);
    let mut jac = vec![0.0; 3 * k];
    let mut residuals = Vec::with_capacity(n);
    for (j, (pose, seed)) in data.poses.iter().zip(seeds.iter_mut()).enumerate() {
        let g =
            predictor
                .predict(pose, seed, &mut jac)
                .map_err(|e| FleetError::Identification {
                    source_name: data.source.clone(),
                    error: tricept_engine::IdentError::Kinematics {
                        pose: j,
                        line: pose.line,
                        source: e,
                    },
                })?;
        let y = pose.readings.to_array();
        let res: [f64; 3] = std::array::from_fn(|c| y[c] - g[c]);
        for c in 0..3 {
            let w = 1.0 / sigma[c];
            let i = 3 * j + c;
            rows[(i, c)] = w;
            for (a, &col) in layout.identifiable.iter().enumerate() {
                let at = match layout.local[a] {
                    Some(pos) => pos,
                    None => l + a,
                };
                rows[(i, at)] = w * jac[c * k + col];
            }
            rows[(i, l + r)] = w * res[c];
        }
        residuals.push(res);
    }
    // The offsets that fit best at p, and the readings' chi-square there.
    let nf = n.max(1) as f64;
    let offsets: [f64; 3] =
        std::array::from_fn(|c| residuals.iter().map(|x| x[c]).sum::<f64>() / nf);
    let chi_square_readings = residuals
        .iter()
        .map(|x| {
            (0..3)
                .map(|c| ((x[c] - offsets[c]) / sigma[c]).powi(2))
                .sum::<f64>()
        })
        .sum();
    let mut chi_square_prior = 0.0;
    for (t, &(a, pos)) in spread.iter().enumerate() {
        let i = 3 * n + t;
        let w = 1.0 / layout.tau[a];
        let gap = p[layout.identifiable[a]] - mean[a];
        rows[(i, pos)] = w;
        rows[(i, l + a)] = -w;
        rows[(i, l + r)] = -w * gap;
        chi_square_prior += (w * gap).powi(2);
    }
    Ok(Evaluated {
        block: RowBlock::new(l, rows),
        chi_square_readings,
        chi_square_prior,
        offsets,
    })
}

/// The state at one point: every member evaluated.
struct Point {
    parameters: Vec<Vec<f64>>,
    mean: Vec<f64>,
    evaluated: Vec<Evaluated>,
    seeds: Vec<Vec<Option<UpJoints>>>,
}

impl Point {
    fn cost(&self) -> f64 {
        self.evaluated
            .iter()
            .map(|e| e.chi_square_readings + e.chi_square_prior)
            .sum()
    }
}

fn evaluate_all(
    input: &JointInput<'_>,
    layout: &Layout<'_>,
    parameters: Vec<Vec<f64>>,
    mean: Vec<f64>,
    mut seeds: Vec<Vec<Option<UpJoints>>>,
) -> Result<Point, FleetError> {
    let evaluated = input
        .data
        .par_iter()
        .zip(&parameters)
        .zip(seeds.par_iter_mut())
        .map(|((data, p), seeds)| {
            evaluate(input.model, data, p, &mean, seeds, layout, &input.sigma)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Point {
        parameters,
        mean,
        evaluated,
        seeds,
    })
}

/// A step: the globals' and every member's locals', and the solve's
/// statistics.
type Step = (Vec<f64>, Vec<Vec<f64>>, SolveStats);

/// The step at a point: globals and every member's locals, and the
/// solve's statistics.
fn step(point: &Point, input: &JointInput<'_>, r: usize) -> Result<Step, FleetError> {
    if input.kind != SolverKind::Schur {
        let problem = BlockProblem {
            n_global: r,
            blocks: point.evaluated.iter().map(|e| e.block.clone()).collect(),
        };
        let s = problem.solve(input.kind)?;
        return Ok((s.global, s.local, s.stats));
    }
    let start = Instant::now();
    let reduced = reduce(point, r)?;
    let norms = global_norms(point, r);
    let (global, _, _) = solve_globals(&reduced, &norms)?;
    let local = reduced
        .par_iter()
        .map(|b| b.local_solution(&global))
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    Ok((
        global,
        local,
        SolveStats {
            kind: SolverKind::Schur,
            unknowns: point
                .evaluated
                .iter()
                .map(|e| e.block.n_local)
                .sum::<usize>()
                + r,
            nonzeros: nonzeros(point),
            rows: point.evaluated.iter().map(|e| e.block.rows.nrows()).sum(),
            seconds,
        },
    ))
}

fn reduce(point: &Point, r: usize) -> Result<Vec<ReducedBlock>, FleetError> {
    Ok(point
        .evaluated
        .par_iter()
        .enumerate()
        .map(|(i, e)| ReducedBlock::new(&e.block, r, i))
        .collect::<Result<Vec<_>, _>>()?)
}

fn global_norms(point: &Point, r: usize) -> Vec<f64> {
    (0..r)
        .map(|a| {
            point
                .evaluated
                .iter()
                .map(|e| {
                    let b = &e.block;
                    (0..b.rows.nrows())
                        .map(|i| b.rows[(i, b.n_local + a)].powi(2))
                        .sum::<f64>()
                })
                .sum::<f64>()
                .sqrt()
        })
        .collect()
}

fn nonzeros(point: &Point) -> usize {
    point
        .evaluated
        .par_iter()
        .map(|e| {
            let b = &e.block.rows;
            let n = b.ncols() - 1;
            (0..b.nrows())
                .map(|i| (0..n).filter(|&j| b[(i, j)] != 0.0).count())
                .sum::<usize>()
        })
        .sum()
}

/// The block problem of the joint fit's first step, at its start (for
/// benchmarks and peers: the same normal equations every solver kind
/// sees).
pub fn first_step_problem(input: &JointInput<'_>) -> Result<BlockProblem, FleetError> {
    let (_, point) = start(input)?;
    let r = input.identifiable.len();
    Ok(BlockProblem {
        n_global: r,
        blocks: point.evaluated.into_iter().map(|e| e.block).collect(),
    })
}

/// The layout of `input`'s unknowns and its first point evaluated.
fn start<'a>(input: &'a JointInput<'a>) -> Result<(Layout<'a>, Point), FleetError> {
    let r = input.identifiable.len();
    let members = input.data.len();
    if input.start.len() != members
        || input.scales.len() != members + 1
        || input.spread_variance.len() != r
    {
        return Err(FleetError::Input(
            "a joint fit's inputs of different lengths".into(),
        ));
    }
    let mut local = vec![None; r];
    let mut at = 3;
    for (a, v) in input.spread_variance.iter().enumerate() {
        if *v > 0.0 {
            local[a] = Some(at);
            at += 1;
        }
    }
    let layout = Layout {
        identifiable: input.identifiable,
        local,
        tau: input
            .spread_variance
            .iter()
            .map(|v| v.max(0.0).sqrt())
            .collect(),
    };
    // A parameter of no spread is the mean on every machine from the start.
    let mut parameters = input.start.clone();
    for p in &mut parameters {
        for (a, &j) in input.identifiable.iter().enumerate() {
            if layout.local[a].is_none() {
                p[j] = input.mean_start[a];
            }
        }
    }
    let seeds: Vec<Vec<Option<UpJoints>>> = input
        .data
        .iter()
        .map(|d| vec![None; d.poses.len()])
        .collect();
    let point = evaluate_all(input, &layout, parameters, input.mean_start.clone(), seeds)?;
    Ok((layout, point))
}

/// The joint fit (module docs).
pub fn fit(input: &JointInput<'_>) -> Result<JointFit, FleetError> {
    let started = Instant::now();
    let r = input.identifiable.len();
    let members = input.data.len();
    let (layout, mut point) = start(input)?;
    let mut solve_seconds = 0.0;
    let mut stats = None;
    let mut converged = false;
    let mut iterations = 0;
    for it in 1..=input.max_iterations {
        iterations = it;
        let (d_global, d_local, s) = step(&point, input, r)?;
        solve_seconds += s.seconds;
        stats = Some(s);
        let moves = |t: f64| -> (Vec<Vec<f64>>, Vec<f64>) {
            let mean: Vec<f64> = point
                .mean
                .iter()
                .zip(&d_global)
                .map(|(m, d)| m + t * d)
                .collect();
            let parameters = point
                .parameters
                .iter()
                .zip(&d_local)
                .map(|(p, dl)| {
                    let mut p = p.clone();
                    for (a, &j) in input.identifiable.iter().enumerate() {
                        p[j] += t * match layout.local[a] {
                            Some(pos) => dl[pos],
                            None => d_global[a],
                        };
                    }
                    p
                })
                .collect();
            (parameters, mean)
        };
        let small = {
            let within = |d: f64, sd: f64| d.abs() <= (1e-3 * sd).max(1e-12);
            (0..r).all(|a| within(d_global[a], input.scales[members][a]))
                && d_local.iter().zip(&input.scales).all(|(dl, sd)| {
                    (0..r).all(|a| layout.local[a].is_none_or(|pos| within(dl[pos], sd[a])))
                })
        };
        if small {
            converged = true;
            break;
        }
        let cost = point.cost();
        let mut t = 1.0;
        let accepted = loop {
            let (parameters, mean) = moves(t);
            let trial = evaluate_all(input, &layout, parameters, mean, point.seeds.clone());
            if let Ok(trial) = trial
                && trial.cost() <= cost * (1.0 + 1e-12) + 1e-300
            {
                break Some(trial);
            }
            t *= 0.5;
            if t < 1e-6 {
                break None;
            }
        };
        match accepted {
            Some(next) => point = next,
            None => break,
        }
    }
    // The covariances at the last point, by block elimination.
    let reduced = reduce(&point, r)?;
    let (_, mean_cov, _) = solve_globals(&reduced, &global_norms(&point, r))?;
    let covariances = reduced
        .par_iter()
        .map(|b| member_covariance(b, mean_cov.as_ref(), &layout))
        .collect();
    let mean_covariance = DMatrix::from_fn(r, r, |i, j| mean_cov[(i, j)]);
    let stats = match stats {
        Some(mut s) => {
            s.seconds = solve_seconds;
            s
        }
        None => step(&point, input, r)?.2,
    };
    Ok(JointFit {
        offsets: point.evaluated.iter().map(|e| e.offsets).collect(),
        chi_square_readings: point
            .evaluated
            .iter()
            .map(|e| e.chi_square_readings)
            .collect(),
        chi_square_prior: point.evaluated.iter().map(|e| e.chi_square_prior).sum(),
        readings: input.data.iter().map(|d| 3 * d.poses.len()).sum(),
        parameters: point.parameters,
        mean: point.mean,
        mean_covariance,
        covariances,
        stats,
        fit_seconds: started.elapsed().as_secs_f64(),
        iterations,
        converged,
    })
}

/// A member's covariance of its identifiable parameters: its local ones
/// from the block, those of no spread from the mean's.
fn member_covariance(
    b: &ReducedBlock,
    mean_cov: faer::MatRef<'_, f64>,
    layout: &Layout<'_>,
) -> DMatrix<f64> {
    let local = b.local_covariance(mean_cov);
    let cross = b.cross_covariance(mean_cov);
    let r = layout.identifiable.len();
    DMatrix::from_fn(r, r, |a, c| match (layout.local[a], layout.local[c]) {
        (Some(i), Some(j)) => local[(i, j)],
        (Some(i), None) => cross[(i, c)],
        (None, Some(j)) => cross[(j, a)],
        (None, None) => mean_cov[(a, c)],
    })
}
