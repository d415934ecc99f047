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

use faer::Mat;
use nalgebra::DMatrix;
use serde_json::{Map, Value, json};
use tricept_data::ExternalPose;
use tricept_kinematics::{Machine, UpJoints};
use tricept_numerics::linalg::{TriangularAccumulator, r_factor, svd_values_and_vectors};
use tricept_numerics::lsq::{DEFAULT_RANK_TOLERANCE, RankDecision, ReducedProblem, Solution};

use crate::error::IdentError;
use crate::fusion::model::{FusedModel, LegContext};
use crate::fusion::report::{FusionReport, build_report};
use crate::fusion::source::{Nuisance, Sink, Source};
use crate::gauss_newton::{Iteration, Run, iterate};
use crate::report::IdentifiabilityReport;

/// Settings of [`identify_fused`].
///
/// # Example
/// ```
/// use tricept_ident::fusion::FusionOptions;
/// let o = FusionOptions::for_machine(&tricept_kinematics::Machine::paper());
/// // 51 platform points x 4 x 2 head angle pairs.
/// assert_eq!(o.eval_poses.len(), 408);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FusionOptions {
    /// Relative singular-value tolerance of the rank decision.
    pub rank_tolerance: f64,
    /// `s_i / s_1` below which an identifiable direction is reported weak.
    pub weak_threshold: f64,
    /// Gauss-Newton iteration limit.
    pub max_iterations: u32,
    /// Tool poses over which the tool tip's predicted uncertainty and the
    /// tip impact of weak combinations are reported.
    pub eval_poses: Vec<ExternalPose>,
    /// A weak or invisible combination that moves the tool tip, after
    /// touch-off, by less than this per standard deviation (per unit
    /// coefficient when invisible) is reported as nearly harmless, um.
    pub harmless_um: f64,
}

impl FusionOptions {
    /// Defaults: the rank tolerance and weak threshold of
    /// [`crate::IdentifyOptions`], 30 iterations, 5 um, and the evaluation
    /// grid [`evaluation_poses`] with 2 rings of 8 on 3 levels and head
    /// angles `h1` in {0, 90, 180, 270} deg, `h2` in {15, 35} deg (away
    /// from the head singularity at `h2 = 0`, where a calibrated head may
    /// not point exactly along its first axis).
    pub fn for_machine(machine: &Machine) -> FusionOptions {
        FusionOptions {
            rank_tolerance: DEFAULT_RANK_TOLERANCE,
            weak_threshold: 1e-2,
            max_iterations: 30,
            eval_poses: evaluation_poses(
                machine,
                (2, 8, 3),
                &[0.0, 90.0, 180.0, 270.0],
                &[15.0, 35.0],
            ),
            harmless_um: 5.0,
        }
    }
}

/// Tool poses for evaluation: the platform points of the workspace's
/// `polar_grid(rings, per_ring, levels)` with every pair of head angles from
/// `h1_deg` x `h2_deg` ([`head_angle_poses`]).
pub fn evaluation_poses(
    machine: &Machine,
    (rings, per_ring, levels): (usize, usize, usize),
    h1_deg: &[f64],
    h2_deg: &[f64],
) -> Vec<ExternalPose> {
    let points = machine.workspace.polar_grid(rings, per_ring, levels);
    head_angle_poses(machine, &points, h1_deg, h2_deg)
}

/// Each platform point (commanded by the nominal IK) with each pair of head
/// angles from `h1_deg` x `h2_deg` (degrees): evaluation poses, tracker
/// candidates. Points the IK cannot reach are left out.
///
/// # Example
/// ```
/// use tricept_ident::fusion::head_angle_poses;
/// let m = tricept_kinematics::Machine::paper();
/// let poses = head_angle_poses(&m, &[nalgebra::Vector3::new(0.0, 0.0, 750.0)], &[0.0, 90.0], &[30.0]);
/// assert_eq!(poses.len(), 2);
/// assert!((poses[1].head_rad[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
pub fn head_angle_poses(
    machine: &Machine,
    platform_mm: &[nalgebra::Vector3<f64>],
    h1_deg: &[f64],
    h2_deg: &[f64],
) -> Vec<ExternalPose> {
    let mut out = Vec::new();
    for r in platform_mm {
        let Ok(ik) = machine.inverse(r) else {
            continue;
        };
        for h1 in h1_deg {
            for h2 in h2_deg {
                out.push(ExternalPose {
                    commands_mm: ik.legs_mm,
                    head_rad: [h1.to_radians(), h2.to_radians()],
                });
            }
        }
    }
    out
}

/// A source whose reduced chi-square exceeds this is not explained by the
/// model and its stated noise (a warning, and [`Fusion::is_trustworthy`]
/// false): the model misses an effect, or the noise is 1.7 times larger
/// than stated.
pub const UNEXPLAINED_REDUCED_CHI_SQUARE: f64 = 3.0;

/// The fit of one source.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SourceFit {
    /// Label (prefix of its nuisance names).
    pub label: String,
    /// Kind of instrument.
    pub kind: crate::fusion::SourceKind,
    /// File the records came from.
    pub file: String,
    /// Records.
    pub records: usize,
    /// Data rows.
    pub rows: usize,
    /// Nuisance parameter names (with the label).
    pub nuisance_names: Vec<String>,
    /// Their estimates (rotations as rotation vectors, rad).
    pub nuisance: Vec<f64>,
    /// Their standard deviations.
    pub nuisance_std_dev: Vec<f64>,
    /// Sum of squared standardised residuals of the data rows.
    pub chi_square: f64,
    /// This source's share of the degrees of freedom: its rows less its
    /// nuisance, less the global rank in proportion to its rows (a guide).
    pub dof_share: f64,
    /// `chi_square / dof_share`: about 1 when the model and the stated
    /// noise explain this source.
    pub reduced_chi_square: f64,
    /// RMS residual, um (external sources; `None` for the internal one,
    /// whose rows mix rad and mm).
    pub rms_um: Option<f64>,
    /// Largest standardised residual and the line of its record.
    pub max_standardised: (f64, u64),
    /// Fitted geometry beyond the nuisance values (touch-offs: the unit
    /// normal of each plane, `plane_normals`); `null` when there is none.
    pub extra: Value,
}

/// The result of [`identify_fused`].
#[derive(Debug, Clone)]
pub struct Fusion {
    /// Global parameter names `[module | effects | head]`.
    pub names: Vec<String>,
    /// Estimates (held parameters at their prior, zero).
    pub estimate: Vec<f64>,
    /// Standard deviations (`None` for held parameters).
    pub std_dev: Vec<Option<f64>>,
    /// Covariance of the global parameters (zero rows and columns for held
    /// ones).
    pub covariance: DMatrix<f64>,
    /// Each source's fit.
    pub sources: Vec<SourceFit>,
    /// What the sources, alone and together, can see.
    pub report: FusionReport,
    /// Gauss-Newton iterations.
    pub iterations: u32,
    /// Whether the iteration met its tolerance.
    pub converged: bool,
    /// Problems a user must read: a source the model does not explain, a
    /// tool tip that is not calibrated, no convergence.
    pub warnings: Vec<String>,
}

/// The fixed parts of a fused problem.
struct Problem<'a> {
    model: &'a FusedModel,
    sources: &'a [Source],
    contexts: Vec<Vec<LegContext>>,
    /// First union nuisance column of each source.
    offsets: Vec<usize>,
    n_nuisance: usize,
}

/// Seeds and carried nuisance of every source.
#[derive(Clone)]
struct State {
    seeds: Vec<Vec<Option<UpJoints>>>,
    nuisance: Vec<Nuisance>,
}

/// One evaluation: the union problem, each source's own, and each source's
/// standardised residuals.
struct Evaluation {
    union: ReducedProblem,
    parts: Vec<ReducedProblem>,
    standardised: Vec<Vec<(usize, f64, f64)>>,
}

impl Problem<'_> {
    fn nuisance_len(&self, s: usize) -> usize {
        let end = self.offsets.get(s + 1).copied().unwrap_or(self.n_nuisance);
        end - self.offsets[s]
    }

    /// The union of the sources' factors, in the global column order.
    fn merge(&self, parts: &[ReducedProblem]) -> ReducedProblem {
        if parts.len() == 1 {
            return parts[0].clone();
        }
        merge(&parts.iter().collect::<Vec<_>>())
    }
}

/// The union of reduced problems over the same global parameters: their
/// factors stacked with every nuisance block first (in order) and factored
/// again.
pub(crate) fn merge(parts: &[&ReducedProblem]) -> ReducedProblem {
    let k = parts.first().map_or(0, |p| p.k);
    let n_nuisance: usize = parts.iter().map(|p| p.n_nuisance).sum();
    let width = n_nuisance + k + 1;
    let height: usize = parts.iter().map(|p| p.r.nrows()).sum();
    let mut stacked = Mat::<f64>::zeros(height, width);
    let (mut row, mut offset) = (0, 0);
    for part in parts {
        let nn = part.n_nuisance;
        for i in 0..part.r.nrows() {
            for j in 0..part.r.ncols() {
                let col = if j < nn {
                    offset + j
                } else {
                    n_nuisance + (j - nn)
                };
                stacked[(row + i, col)] = part.r[(i, j)];
            }
        }
        row += part.r.nrows();
        offset += nn;
    }
    ReducedProblem {
        r: r_factor(stacked.as_ref()),
        n_nuisance,
        k,
        rows: parts.iter().map(|p| p.rows).sum(),
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
        for (s, source) in self.sources.iter().enumerate() {
            let rows = source.rows();
            let mut sink = Sink::new(self.nuisance_len(s), k, rows.data_rows());
            rows.evaluate(
                &at,
                &self.contexts[s],
                &state.nuisance[s],
                &mut state.seeds[s],
                &mut sink,
            )
            .map_err(|e| in_source(source, e))?;
            let (part, z) = sink.finish();
            parts.push(part);
            standardised.push(z);
        }
        Ok(Evaluation {
            union: self.merge(&parts),
            parts,
            standardised,
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
fn in_source(source: &Source, e: IdentError) -> IdentError {
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

/// Fits the parameters of `model` and every source's nuisance to all
/// sources at once (see the module docs).
///
/// # Example
/// ```
/// use tricept_ident::fusion::{FusedModel, FusionOptions, Source, identify_fused};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&tricept_plant::Campaign::grid(&m, 1))
///     .unwrap();
/// // The internal data alone, head in the model: the head is invisible.
/// let model = FusedModel::new(m.clone(), set, &[], true).unwrap();
/// let fit = identify_fused(&model, &[Source::internal(&data, m.sensors.logged_sigma())],
///     &FusionOptions::for_machine(&m)).unwrap();
/// assert_eq!(fit.report.union.rank, 14);
/// assert!(fit.report.union.fixed.contains(&"tool_length_mm".to_string()));
/// ```
pub fn identify_fused(
    model: &FusedModel,
    sources: &[Source],
    options: &FusionOptions,
) -> Result<Fusion, IdentError> {
    if sources.is_empty() {
        return Err(IdentError::Invalid("no data source".into()));
    }
    for (s, a) in sources.iter().enumerate() {
        if sources[..s].iter().any(|b| b.label() == a.label()) {
            return Err(IdentError::Invalid(format!(
                "two sources are labelled `{}`: label them apart (Source::with_label)",
                a.label()
            )));
        }
    }
    let k = model.len();
    let mut offsets = Vec::with_capacity(sources.len());
    let mut n_nuisance = 0;
    for s in sources {
        offsets.push(n_nuisance);
        n_nuisance += s.rows().nuisance_names().len();
    }
    let data_rows: usize = sources.iter().map(|s| s.rows().data_rows()).sum();
    let prior_rows: usize = sources.iter().map(|s| s.rows().prior_rows()).sum();
    if data_rows + prior_rows < n_nuisance + k + 1 {
        let records: usize = sources.iter().map(|s| s.records()).sum();
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
    let (problem, state, eval) = start(model, sources, offsets.clone(), n_nuisance)?;
    // The rank decision: on this model, or on its reference (the nominal
    // machine of a calibrated one) with the same sources.
    let reference = match model.rank_reference() {
        Some(r) => Some(start(r, sources, offsets, n_nuisance)?.2),
        None => None,
    };
    let names = model.names().to_vec();
    let decision = reference
        .as_ref()
        .unwrap_or(&eval)
        .union
        .decide(options.rank_tolerance)
        .ok_or(IdentError::Numerical("SVD did not converge"))?;
    let first = eval.union.solve(&decision);
    let records: usize = sources.iter().map(|s| s.records()).sum();
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
/// initialised from the data at zero errors) and its evaluation there.
fn start<'a>(
    model: &'a FusedModel,
    sources: &'a [Source],
    offsets: Vec<usize>,
    n_nuisance: usize,
) -> Result<(Problem<'a>, State, Evaluation), IdentError> {
    let mut contexts = Vec::with_capacity(sources.len());
    for source in sources {
        let rows = source.rows();
        let ctx = (0..rows.records())
            .map(|j| {
                model
                    .leg_context(&rows.pose(j).commands_mm)
                    .map_err(|e| IdentError::Source {
                        file: source.file().to_string(),
                        line: Some(rows.line(j)),
                        message: format!("the commands of this record cannot be reached: {e}"),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        contexts.push(ctx);
    }
    let problem = Problem {
        model,
        sources,
        contexts,
        offsets,
        n_nuisance,
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
                .initial(&at, &problem.contexts[s], &mut state.seeds[s])
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
    let data_rows: usize = problem.sources.iter().map(|s| s.rows().data_rows()).sum();
    let mut sources = Vec::with_capacity(problem.sources.len());
    let mut warnings = Vec::new();
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
        let nuisance_std_dev = (at..at + n_s)
            .map(|j| solution.covariance[(j, j)].max(0.0).sqrt())
            .collect();
        // The residuals at the estimate (the final evaluation: the run ends on it),
        // with a linear nuisance's values taken off.
        let mut z = eval.standardised[s].clone();
        if rows.linear_nuisance() {
            rows.take_off_linear_nuisance(&mut z, step);
        }
        let chi_square: f64 = z.iter().map(|(_, v, _)| v * v).sum();
        let n_rows = rows.data_rows();
        let dof_share =
            n_rows as f64 - n_s as f64 - decision.rank as f64 * n_rows as f64 / data_rows as f64;
        let reduced = if dof_share > 0.0 {
            chi_square / dof_share
        } else {
            f64::NAN
        };
        let (max_z, max_record) = z.iter().fold((0.0f64, 0usize), |acc, (r, v, _)| {
            if v.abs() > acc.0 { (v.abs(), *r) } else { acc }
        });
        let rms_um = rows.residual_unit_um().map(|unit| {
            let sum: f64 = z.iter().map(|(_, _, raw)| raw * raw).sum();
            unit * (sum / z.len().max(1) as f64).sqrt()
        });
        if reduced > UNEXPLAINED_REDUCED_CHI_SQUARE {
            warnings.push(format!(
                "the model does not explain {} ({}): reduced chi-square {reduced:.1}; run `tricept diagnose` on the internal data and add the effects it names (--effects), or check this instrument's sigma",
                source.label(),
                source.file()
            ));
        }
        sources.push(SourceFit {
            label: source.label().to_string(),
            kind: source.kind(),
            file: source.file().to_string(),
            records: rows.records(),
            rows: n_rows,
            nuisance_names: source.nuisance_names(),
            nuisance,
            nuisance_std_dev,
            chi_square,
            dof_share,
            reduced_chi_square: reduced,
            rms_um,
            max_standardised: (max_z, rows.line(max_record)),
            extra,
        });
    }
    if !converged {
        warnings.push(format!(
            "Gauss-Newton did not converge in {iterations} iterations: the estimate is not trustworthy"
        ));
    }
    let report = build_report(
        model,
        problem.sources,
        start_parts,
        decision,
        union_report,
        &estimate,
        &covariance,
        options,
    )?;
    warnings.extend(report.warnings());
    Ok(Fusion {
        names: model.names().to_vec(),
        estimate,
        std_dev,
        covariance,
        sources,
        report,
        iterations,
        converged,
        warnings,
    })
}

/// The weighted rows of one source at the nominal machine, with its
/// nuisance at its starting values: what planning scores candidate
/// measurements with (the rows' Jacobians do not depend on the measured
/// values, only on where the machine stood).
#[derive(Debug, Clone, PartialEq)]
pub struct DesignRows {
    /// The source's nuisance parameter names (with its label).
    pub nuisance_names: Vec<String>,
    /// Per record, its rows `[nuisance | global parameters]`, each weighted
    /// by `1 / sigma` (`rows per record x (nuisance + parameters)`).
    pub records: Vec<DMatrix<f64>>,
    /// The source's prior rows (bar length, target offset, stylus), weighted.
    pub priors: DMatrix<f64>,
}

/// The rows of `source` at the nominal machine (see [`DesignRows`]).
pub fn design_rows(model: &FusedModel, source: &Source) -> Result<DesignRows, IdentError> {
    let k = model.len();
    let p = vec![0.0; k];
    let at = model.at(&p);
    let rows = source.rows();
    let contexts = (0..rows.records())
        .map(|j| {
            model
                .leg_context(&rows.pose(j).commands_mm)
                .map_err(|e| IdentError::Source {
                    file: source.file().to_string(),
                    line: Some(rows.line(j)),
                    message: format!("the commands of this record cannot be reached: {e}"),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut seeds = vec![None; rows.records()];
    let nu = rows
        .initial(&at, &contexts, &mut seeds)
        .map_err(|e| in_source(source, e))?;
    let nn = nu.values.len();
    let mut sink = Sink::keeping(nn, k, rows.data_rows());
    rows.evaluate(&at, &contexts, &nu, &mut seeds, &mut sink)
        .map_err(|e| in_source(source, e))?;
    let kept = sink.take_kept();
    let width = nn + k;
    let mut records: Vec<Vec<f64>> = vec![Vec::new(); rows.records()];
    let mut priors = Vec::new();
    for (record, row) in kept {
        match record {
            Some(j) => records[j].extend_from_slice(&row[..width]),
            None => priors.extend_from_slice(&row[..width]),
        }
    }
    Ok(DesignRows {
        nuisance_names: source.nuisance_names(),
        records: records
            .into_iter()
            .map(|r| DMatrix::from_row_slice(r.len() / width.max(1), width, &r))
            .collect(),
        priors: DMatrix::from_row_slice(priors.len() / width.max(1), width, &priors),
    })
}

/// The information the `sources` together carry on the global parameters
/// at the nominal machine, their nuisance projected out: `R^T R` of the
/// union's parameter block (`k x k`, in the parameters' units).
///
/// # Example
/// ```
/// use tricept_ident::fusion::{FusedModel, Source, information};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let model = FusedModel::new(m.clone(), tricept_model::ParameterSet::paper15(), &[], true).unwrap();
/// let poses = m.workspace.polar_grid(3, 8, 3).iter()
///     .map(|r| tricept_data::MeasuredPose { commands_mm: m.inverse(r).unwrap().legs_mm, ..Default::default() })
///     .collect();
/// let data = tricept_data::Dataset { poses, source: "grid".into() };
/// let f = information(&model, &[Source::internal(&data, m.sensors.logged_sigma())]).unwrap();
/// // The UP limb's readings carry nothing on the head.
/// let head = model.index_of("tool_length_mm").unwrap();
/// assert_eq!(f[(head, head)], 0.0);
/// assert!(f[(0, 0)] > 0.0);
/// ```
pub fn information(model: &FusedModel, sources: &[Source]) -> Result<DMatrix<f64>, IdentError> {
    let k = model.len();
    let parts = sources
        .iter()
        .map(|source| {
            let d = design_rows(model, source)?;
            let nn = d.nuisance_names.len();
            let mut acc = TriangularAccumulator::new(nn + k);
            for m in d.records.iter().chain(std::iter::once(&d.priors)) {
                for i in 0..m.nrows() {
                    let row: Vec<f64> = m.row(i).iter().copied().collect();
                    acc.push_row(&row);
                }
            }
            Ok((nn, acc.finish()))
        })
        .collect::<Result<Vec<_>, IdentError>>()?;
    let mut f = DMatrix::zeros(k, k);
    for (nn, r) in parts {
        let block = DMatrix::from_fn(k, k, |i, j| r[(nn + i, nn + j)]);
        f += block.transpose() * block;
    }
    Ok(f)
}

impl Fusion {
    /// Whether the fit converged and the model explains every source
    /// (reduced chi-square at most [`UNEXPLAINED_REDUCED_CHI_SQUARE`]). A
    /// fit that is not must not be deployed as it stands.
    pub fn is_trustworthy(&self) -> bool {
        self.converged
            && self
                .sources
                .iter()
                .all(|s| s.reduced_chi_square <= UNEXPLAINED_REDUCED_CHI_SQUARE)
    }

    /// Index of a global parameter by name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// JSON: every global parameter at the top level (as `identify`), with
    /// `std_dev`, `groups`, `sources`, the identifiability report of the
    /// union and of each source (`visibility`), `tool_tip`, `warnings`.
    pub fn to_json(&self, model: &FusedModel) -> Value {
        let mut m = Map::new();
        for (n, v) in self.names.iter().zip(&self.estimate) {
            m.insert(n.clone(), (*v).into());
        }
        m.insert(
            "std_dev".into(),
            Value::Object(
                self.names
                    .iter()
                    .zip(&self.std_dev)
                    .map(|(n, s)| (n.clone(), s.map_or(Value::Null, Value::from)))
                    .collect(),
            ),
        );
        let group = |r: std::ops::Range<usize>| -> Value {
            self.names[r].iter().cloned().map(Value::from).collect()
        };
        m.insert(
            "groups".into(),
            json!({"module": group(model.module_range()), "effects": group(model.effect_range()), "head": group(model.head_range())}),
        );
        m.insert(
            "sources".into(),
            Value::Array(
                self.sources
                    .iter()
                    .map(|s| {
                        let mut v = serde_json::to_value(s).unwrap_or(Value::Null);
                        if let Value::Object(o) = &mut v {
                            o.insert(
                                "nuisance".into(),
                                Value::Object(
                                    s.nuisance_names
                                        .iter()
                                        .zip(&s.nuisance)
                                        .map(|(n, x)| (n.clone(), Value::from(*x)))
                                        .collect(),
                                ),
                            );
                            o.insert(
                                "nuisance_std_dev".into(),
                                Value::Object(
                                    s.nuisance_names
                                        .iter()
                                        .zip(&s.nuisance_std_dev)
                                        .map(|(n, x)| (n.clone(), Value::from(*x)))
                                        .collect(),
                                ),
                            );
                            o.remove("nuisance_names");
                            o.insert(
                                "max_standardised".into(),
                                json!({"value": s.max_standardised.0, "line": s.max_standardised.1}),
                            );
                        }
                        v
                    })
                    .collect(),
            ),
        );
        if let Value::Object(r) = self.report.union.to_json() {
            for (key, v) in r {
                m.insert(key, v);
            }
        }
        m.insert("visibility".into(), self.report.to_json());
        m.insert("iterations".into(), self.iterations.into());
        m.insert("converged".into(), self.converged.into());
        m.insert(
            "warnings".into(),
            Value::Array(self.warnings.iter().cloned().map(Value::from).collect()),
        );
        Value::Object(m)
    }
}
