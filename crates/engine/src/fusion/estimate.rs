//! The joint estimation: every source's rows, each weighted by its own
//! noise, in one weighted least-squares problem on the exact model.
//!
//! Each source folds its rows into its own triangular factor over
//! `[its nuisance | global parameters | residual]`; the union's factor is
//! the QR of those factors stacked in the global column order (all
//! nuisance first), so memory stays `O(k^2)` per source and each source's
//! own problem is at hand for the report. The rank decision is taken once,
//! on the union at the starting point (nominal machine, nuisance from the
//! closed-form fits), after checking that every source's own nuisance is
//! determined by its data. Then Gauss-Newton with step halving (the
//! iteration of [`crate::identify`]): a step moves the global parameters
//! and the nuisance that is carried between evaluations.
//!
//! With one internal source and no head or effects this is exactly
//! [`crate::identify`] (bit for bit; tested).
//!
//! Each fit ends with every source's redundancy (its degrees of freedom:
//! `sum (1 - h_ii)` over its rows, `h` the hat matrix of the union), the
//! deleted residual of every record and the verdict
//! ([`crate::fusion::identify_fused`] wraps it in the screen and the
//! likely-cause search).

use faer::Mat;
use nalgebra::{DMatrix, DVector};
use serde_json::Value;
use tricept_kinematics::up_limb::UpJoints;
use tricept_numerics::linalg::svd_values_and_vectors;
use tricept_numerics::lsq::{HatFactor, RankDecision, ReducedProblem, Solution};

use crate::error::IdentError;
use crate::fusion::model::{FusedModel, LegContext};
use crate::fusion::options::FusionOptions;
use crate::fusion::report::build_report;
use crate::fusion::result::{Fusion, RecordCheck, SourceFit, judge};
use crate::fusion::source::{KeptRows, Nuisance, Sink, Source};
use crate::gauss_newton::{Iteration, Run, iterate};
use crate::report::IdentifiabilityReport;

/// The fixed parts of a fused problem.
pub(crate) struct Problem<'a> {
    pub model: &'a FusedModel,
    pub sources: &'a [Source],
    contexts: Vec<Vec<LegContext>>,
    /// First union nuisance column of each source.
    pub offsets: Vec<usize>,
    pub n_nuisance: usize,
    /// Which records of each source are in the fit.
    pub active: &'a [Vec<bool>],
}

/// Seeds and carried nuisance of every source.
#[derive(Clone)]
pub(crate) struct State {
    seeds: Vec<Vec<Option<UpJoints>>>,
    nuisance: Vec<Nuisance>,
}

/// One evaluation: the union problem, each source's own, and each source's
/// standardised residuals (of the records in the fit).
pub(crate) struct Evaluation {
    pub union: ReducedProblem,
    pub parts: Vec<ReducedProblem>,
    pub standardised: Vec<Vec<(usize, f64, f64)>>,
    /// Every source's weighted rows (of records outside the fit too).
    pub kept: Vec<KeptRows>,
}

impl Problem<'_> {
    pub fn nuisance_len(&self, s: usize) -> usize {
        let end = self.offsets.get(s + 1).copied().unwrap_or(self.n_nuisance);
        end - self.offsets[s]
    }

    /// The union of the sources' factors, in the global column order.
    fn merge(&self, parts: &[ReducedProblem]) -> ReducedProblem {
        if parts.len() == 1 {
            return parts[0].clone();
        }
        ReducedProblem::merge(&parts.iter().collect::<Vec<_>>())
    }
}

impl Iteration for Problem<'_> {
    type State = State;
    type Eval = Evaluation;

    fn evaluate(&self, p: &[f64], state: &mut State) -> Result<Evaluation, IdentError> {
        let at = self.model.at(p);
        let k = self.model.len();
        let mut parts = Vec::with_capacity(self.sources.len());
        let mut standardised = Vec::with_capacity(self.sources.len());
        let mut kept = Vec::with_capacity(self.sources.len());
        for (s, source) in self.sources.iter().enumerate() {
            let rows = source.rows();
            let mut sink =
                Sink::new(self.nuisance_len(s), k, rows.data_rows()).with_active(&self.active[s]);
            rows.evaluate(
                &at,
                &self.contexts[s],
                &state.nuisance[s],
                &mut state.seeds[s],
                &mut sink,
            )
            .map_err(|e| in_source(source, e))?;
            let (part, z, rows) = sink.finish();
            parts.push(part);
            standardised.push(z);
            kept.push(rows);
        }
        Ok(Evaluation {
            union: self.merge(&parts),
            parts,
            standardised,
            kept,
        })
    }

    fn problem<'e>(&self, eval: &'e Evaluation) -> &'e ReducedProblem {
        &eval.union
    }

    fn trial_state(&self, state: &State, solution: &Solution, t: f64) -> State {
        let mut trial = state.clone();
        for (s, source) in self.sources.iter().enumerate() {
            let rows = source.rows();
            if rows.linear_nuisance() {
                continue;
            }
            let at = self.offsets[s];
            let step: Vec<f64> = solution.nuisance[at..at + self.nuisance_len(s)]
                .iter()
                .map(|v| t * v)
                .collect();
            rows.retract(&mut trial.nuisance[s], &step);
        }
        trial
    }

    fn nuisance_step_within(&self, solution: &Solution, fraction: f64) -> bool {
        self.sources.iter().enumerate().all(|(s, source)| {
            source.rows().linear_nuisance()
                || (self.offsets[s]..self.offsets[s] + self.nuisance_len(s)).all(|j| {
                    let sd = solution.covariance[(j, j)].max(0.0).sqrt();
                    solution.nuisance[j].abs() <= (fraction * sd).max(1e-12)
                })
        })
    }
}

/// An error of a source's evaluation, named after the source's file.
pub(crate) fn in_source(source: &Source, e: IdentError) -> IdentError {
    match e {
        IdentError::Kinematics {
            line, source: k, ..
        } => IdentError::Source {
            file: source.file().to_string(),
            line: Some(line),
            message: format!("the commands of this record cannot be reached: {k}"),
        },
        e => e,
    }
}

/// One fit of `model` to the records of `sources` marked in `active`, judged
/// (redundancy, record checks, verdict, plausibility) but not screened.
pub(crate) fn fit_masked(
    model: &FusedModel,
    sources: &[Source],
    active: &[Vec<bool>],
    options: &FusionOptions,
) -> Result<Fusion, IdentError> {
    check_counts(model, sources, active)?;
    let (offsets, n_nuisance) = nuisance_layout(sources);
    let started = start(model, sources, offsets, n_nuisance, active)?;
    fit_started(started, options)
}

/// Each source's first union nuisance column, and their total.
pub(crate) fn nuisance_layout(sources: &[Source]) -> (Vec<usize>, usize) {
    let mut offsets = Vec::with_capacity(sources.len());
    let mut n_nuisance = 0;
    for s in sources {
        offsets.push(n_nuisance);
        n_nuisance += s.rows().nuisance_names().len();
    }
    (offsets, n_nuisance)
}

/// Refuses fewer rows in the fit than unknowns.
pub(crate) fn check_counts(
    model: &FusedModel,
    sources: &[Source],
    active: &[Vec<bool>],
) -> Result<(), IdentError> {
    let k = model.len();
    let (_, n_nuisance) = nuisance_layout(sources);
    let in_fit = |s: usize| active[s].iter().filter(|a| **a).count();
    let data_rows: usize = sources
        .iter()
        .enumerate()
        .map(|(s, src)| in_fit(s) * src.rows().rows_per_record())
        .sum();
    let prior_rows: usize = sources.iter().map(|s| s.rows().prior_rows()).sum();
    if data_rows + prior_rows < n_nuisance + k + 1 {
        let records: usize = (0..sources.len()).map(in_fit).sum();
        return Err(IdentError::Source {
            file: sources
                .iter()
                .map(|s| s.file().to_string())
                .collect::<Vec<_>>()
                .join(", "),
            line: None,
            message: format!(
                "too few measurements: {records} records give {data_rows} values and {prior_rows} priors for {} unknowns ({k} parameters, {n_nuisance} nuisance)",
                n_nuisance + k
            ),
        });
    }
    Ok(())
}

/// The fit from a problem's start ([`start`]): the rank decision, the
/// iteration, the judged result.
pub(crate) fn fit_started(
    (problem, state, eval): (Problem<'_>, State, Evaluation),
    options: &FusionOptions,
) -> Result<Fusion, IdentError> {
    let (model, sources, active) = (problem.model, problem.sources, problem.active);
    let k = model.len();
    let (offsets, n_nuisance) = (problem.offsets.clone(), problem.n_nuisance);
    let in_fit = |s: usize| active[s].iter().filter(|a| **a).count();
    // The rank decision: on this model, or on its reference (the nominal
    // machine of a calibrated one) with the same sources; which parameter
    // of an invisible set is held is chosen on the columns scaled by the
    // parameters' typical sizes (the one whose typical size the data would
    // see least).
    let reference = match model.rank_reference() {
        Some(r) => Some(start(r, sources, offsets, n_nuisance, active)?.2),
        None => None,
    };
    let names = model.names().to_vec();
    let typical = model.typical_sizes();
    let decision = reference
        .as_ref()
        .unwrap_or(&eval)
        .union
        .decide_weighted(options.rank_tolerance, Some(&typical))
        .ok_or(IdentError::Numerical("SVD did not converge"))?;
    let first = eval.union.solve(&decision);
    let records: usize = (0..sources.len()).map(in_fit).sum();
    let union_report = IdentifiabilityReport::new(
        &names,
        &decision,
        &first,
        n_nuisance,
        eval.union.rows,
        records,
        options.weak_threshold,
    );
    let start_parts = eval.parts.clone();
    let mut run = Run {
        p: vec![0.0; k],
        state,
        eval,
        solution: first,
        iterations: 0,
        converged: false,
    };
    iterate(&problem, &mut run, &decision, options.max_iterations);
    finish(
        &problem,
        run,
        &decision,
        union_report,
        &start_parts,
        options,
    )
}

/// The problem of `model` on `sources`, its starting state (nuisance
/// initialised from the records in the fit at zero errors) and its
/// evaluation there.
pub(crate) fn start<'a>(
    model: &'a FusedModel,
    sources: &'a [Source],
    offsets: Vec<usize>,
    n_nuisance: usize,
    active: &'a [Vec<bool>],
) -> Result<(Problem<'a>, State, Evaluation), IdentError> {
    let contexts = sources
        .iter()
        .map(|source| source.leg_contexts(model))
        .collect::<Result<Vec<_>, _>>()?;
    let problem = Problem {
        model,
        sources,
        contexts,
        offsets,
        n_nuisance,
        active,
    };
    let p = vec![0.0; model.len()];
    let mut state = State {
        seeds: sources.iter().map(|s| vec![None; s.records()]).collect(),
        nuisance: Vec::with_capacity(sources.len()),
    };
    {
        let at = model.at(&p);
        for (s, source) in sources.iter().enumerate() {
            let nu = source
                .rows()
                .initial(&at, &problem.contexts[s], &mut state.seeds[s], &active[s])
                .map_err(|e| in_source(source, e))?;
            state.nuisance.push(nu);
        }
    }
    let eval = problem.evaluate(&p, &mut state)?;
    for (s, source) in sources.iter().enumerate() {
        check_nuisance(source, &eval.parts[s])?;
    }
    Ok((problem, state, eval))
}

/// Refuses a source whose own nuisance its data cannot determine.
fn check_nuisance(source: &Source, part: &ReducedProblem) -> Result<(), IdentError> {
    let nn = part.n_nuisance;
    if nn == 0 {
        return Ok(());
    }
    let block = part.r.as_ref().submatrix(0, 0, nn, nn);
    let scale: Vec<f64> = (0..nn)
        .map(|j| {
            let n = (0..nn).map(|i| block[(i, j)].powi(2)).sum::<f64>().sqrt();
            if n > 0.0 { n } else { 1.0 }
        })
        .collect();
    let scaled = Mat::from_fn(nn, nn, |i, j| block[(i, j)] / scale[j]);
    let Some((s, v)) = svd_values_and_vectors(scaled.as_ref()) else {
        return Err(IdentError::Numerical("SVD did not converge"));
    };
    let top = s.first().copied().unwrap_or(0.0);
    let last = nn - 1;
    if s[last] > 1e-8 * top && s[last] > 0.0 {
        return Ok(());
    }
    let names = source.nuisance_names();
    let coefficients: Vec<f64> = (0..nn).map(|j| v[(j, last)] / scale[j]).collect();
    let largest = coefficients.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let combination = names
        .iter()
        .zip(&coefficients)
        .filter(|(_, c)| c.abs() > 1e-3 * largest)
        .map(|(n, c)| format!("{:+.3} {n}", c / largest))
        .collect::<Vec<_>>()
        .join(" ");
    Err(IdentError::NuisanceUnidentifiable {
        file: source.file().to_string(),
        combination: format!("the combination {combination}"),
        hint: source.rows().nuisance_hint().to_string(),
    })
}

/// The checks of every record of every source at the end of a run: each
/// record's weighted residual after the last step and its block of the
/// union's hat matrix ([`RecordCheck`]), and each source's redundancy
/// `sum (1 - h_ii)` over its data rows in the fit.
fn record_checks(
    problem: &Problem<'_>,
    rows: &[KeptRows],
    hat: &HatFactor,
    solution: &Solution,
) -> (Vec<Vec<RecordCheck>>, Vec<f64>) {
    let k = problem.model.len();
    let width = problem.n_nuisance + k;
    let mut checks = Vec::with_capacity(rows.len());
    let mut redundancy = Vec::with_capacity(rows.len());
    for (s, source_rows) in rows.iter().enumerate() {
        let source = problem.sources[s].rows();
        let nn = problem.nuisance_len(s);
        let at = problem.offsets[s];
        let n = source.records();
        let mut e: Vec<Vec<f64>> = vec![Vec::new(); n];
        let mut w: Vec<Vec<Vec<f64>>> = vec![Vec::new(); n];
        // The data rows in the union's column order, whitened at once.
        let mut records = Vec::new();
        let mut union_rows: Vec<Vec<f64>> = Vec::new();
        for (record, row) in source_rows.iter() {
            let Some(j) = record else { continue };
            let mut u = vec![0.0; width];
            u[at..at + nn].copy_from_slice(&row[..nn]);
            u[problem.n_nuisance..].copy_from_slice(&row[nn..nn + k]);
            e[j].push(row[nn + k] - HatFactor::predict(&u, solution));
            records.push(j);
            union_rows.push(u);
        }
        let slices: Vec<&[f64]> = union_rows.iter().map(|u| u.as_slice()).collect();
        let whitened = hat.whiten_rows(&slices);
        for (i, &j) in records.iter().enumerate() {
            w[j].push((0..whitened.ncols()).map(|c| whitened[(i, c)]).collect());
        }
        let mut red = 0.0;
        let list: Vec<RecordCheck> = (0..n)
            .map(|j| {
                let active = problem.active[s][j];
                let m = e[j].len();
                let h = DMatrix::from_fn(m, m, |a, b| {
                    w[j][a].iter().zip(&w[j][b]).map(|(x, y)| x * y).sum()
                });
                let leverage = h.trace();
                if active {
                    red += m as f64 - leverage;
                }
                let sign = if active { -1.0 } else { 1.0 };
                let quadratic = checked_quadratic(&h, sign, &e[j]);
                RecordCheck {
                    line: source.line(j),
                    active,
                    rows: m,
                    leverage,
                    quadratic: if quadratic.is_finite() {
                        quadratic.max(0.0)
                    } else {
                        f64::INFINITY
                    },
                }
            })
            .collect();
        checks.push(list);
        // A saturated source's leverages are 1 to rounding: never below 0.
        redundancy.push(red.max(0.0));
    }
    (checks, redundancy)
}

/// `e^T (I + sign H)^-1 e` over the directions the other records check: a
/// direction with leverage 1 (an eigenvalue of `I - H` near 0) is fitted
/// exactly whatever it holds and tests nothing. Closed form for one row,
/// a fixed-size eigen-decomposition for three.
fn checked_quadratic(h: &DMatrix<f64>, sign: f64, e: &[f64]) -> f64 {
    const CHECKED: f64 = 1e-6;
    match e.len() {
        1 => {
            let d = 1.0 + sign * h[(0, 0)];
            if d > CHECKED { e[0] * e[0] / d } else { 0.0 }
        }
        3 => {
            let m =
                nalgebra::Matrix3::from_fn(|a, b| f64::from(u8::from(a == b)) + sign * h[(a, b)]);
            let eig = m.symmetric_eigen();
            let ev = nalgebra::Vector3::new(e[0], e[1], e[2]);
            (0..3)
                .filter(|&i| eig.eigenvalues[i] > CHECKED)
                .map(|i| eig.eigenvectors.column(i).dot(&ev).powi(2) / eig.eigenvalues[i])
                .sum()
        }
        n => {
            let m: DMatrix<f64> = DMatrix::identity(n, n) + h * sign;
            let eig = m.symmetric_eigen();
            let ev = DVector::from_column_slice(e);
            (0..n)
                .filter(|&i| eig.eigenvalues[i] > CHECKED)
                .map(|i| eig.eigenvectors.column(i).dot(&ev).powi(2) / eig.eigenvalues[i])
                .sum()
        }
    }
}

fn finish(
    problem: &Problem<'_>,
    run: Run<State, Evaluation>,
    decision: &RankDecision,
    union_report: IdentifiabilityReport,
    start_parts: &[ReducedProblem],
    options: &FusionOptions,
) -> Result<Fusion, IdentError> {
    let model = problem.model;
    let k = model.len();
    let nn = problem.n_nuisance;
    let Run {
        p,
        state,
        eval,
        solution,
        iterations,
        converged,
    } = run;
    let estimate: Vec<f64> = p
        .iter()
        .zip(&solution.parameters)
        .map(|(a, b)| a + b)
        .collect();
    let std_dev: Vec<Option<f64>> = (0..k)
        .map(|j| {
            (!decision.fixed.contains(&j))
                .then(|| solution.covariance[(nn + j, nn + j)].max(0.0).sqrt())
        })
        .collect();
    let covariance = DMatrix::from_fn(k, k, |a, b| solution.covariance[(nn + a, nn + b)]);
    let hat = eval.union.hat_factor(decision);
    let (checks, redundancy) = record_checks(problem, &eval.kept, &hat, &solution);
    let mut sources = Vec::with_capacity(problem.sources.len());
    for (s, source) in problem.sources.iter().enumerate() {
        let rows = source.rows();
        let at = problem.offsets[s];
        let n_s = problem.nuisance_len(s);
        let step = &solution.nuisance[at..at + n_s];
        let (nuisance, extra) = if rows.linear_nuisance() {
            (step.to_vec(), Value::Null)
        } else {
            let mut nu = state.nuisance[s].clone();
            rows.retract(&mut nu, step);
            (rows.report_values(&nu), rows.report_extra(&nu))
        };
        let nuisance_std_dev: Vec<f64> = (at..at + n_s)
            .map(|j| solution.covariance[(j, j)].max(0.0).sqrt())
            .collect();
        // The residuals at the estimate (the final evaluation: the run ends on it),
        // with a linear nuisance's values taken off.
        let mut z = eval.standardised[s].clone();
        if rows.linear_nuisance() {
            rows.take_off_linear_nuisance(&mut z, step);
        }
        sources.push(SourceFit::new(
            source,
            &problem.active[s],
            &z,
            redundancy[s],
            (nuisance, nuisance_std_dev, extra),
        ));
    }
    let (report, reference_warning) = build_report(
        model,
        problem.sources,
        start_parts,
        decision,
        union_report,
        &estimate,
        &covariance,
        options,
    )?;
    let implausible = judge(
        model,
        &estimate,
        &std_dev,
        problem.sources,
        &sources,
        options,
    );
    Ok(Fusion::assemble(
        model,
        estimate,
        std_dev,
        covariance,
        sources,
        report,
        (iterations, converged),
        implausible,
        checks,
        reference_warning,
        options,
    ))
}
