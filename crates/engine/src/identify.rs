//! Identification: the parameters and sensor offsets that best explain
//! measured readings, on the exact model.
//!
//! The unknowns are the model parameters `p` and the three sensor zero
//! offsets `c`; the readings of pose `j` are modelled as
//! `y_j = g(q_j; p) + c + noise`, with `g` the exact FK of the model (never
//! its linearisation). The paper removes the offsets by differencing every
//! pose against one reference pose (eq. 10); here they are estimated
//! jointly. Both give the same offset-free equations, but differencing
//! correlates every difference through the reference pose's noise, which
//! ordinary least squares then ignores; joint estimation is the
//! minimum-variance (Gauss-Markov) treatment and does not depend on which
//! pose is chosen as the reference.
//!
//! The solver is Gauss-Newton with step halving on the exact model, on the
//! rows weighted by `1/sigma` of each logged reading. The rank decision
//! (which parameters the data can see; [`tricept_numerics::lsq`]) is taken once, at the
//! starting point, and kept: a parameter that is unidentifiable to first
//! order is held at its prior rather than fitted to second-order effects.
//! (On the x-first machine `dyA3` is such a parameter: its second-order
//! cross term with `dzB3` has the shape of `dyB3`'s first-order effect, so a
//! large `dyA3` biases `dyB3` by about `-dyA3 dzB3 / q4` (and every other
//! parameter by less) without any trace in the residual, and freeing `dyA3`
//! recovers neither its value nor its sign; see `docs/identifiability.md`.)

use nalgebra::DMatrix;
use serde_json::{Map, Value};
use tricept_data::{Dataset, MeasuredPose};
use tricept_kinematics::up_limb::UpJoints;

use crate::campaigns::Campaigns;
use crate::error::IdentError;
use crate::evaluate::{Evaluation, evaluate};
use crate::gauss_newton::{Iteration, Run, iterate};
use crate::model::ReadingModel;
use crate::options::IdentifyOptions;
use crate::prior::{Prior, PriorFit};
use crate::report::{IdentifiabilityReport, NamedValues};
use tricept_numerics::lsq::{RankDecision, ReducedProblem};

mod design;
pub use design::{Design, design, identifiability};
pub(crate) use design::{check_size, decide_design};

/// What a caller knows about one data set before identifying it: where to
/// start, per-pose weights and FK seeds, and a rank decision taken earlier
/// for the same poses. Everything is optional ([`Start::default`]: the
/// nominal machine, equal weights, cold FK starts, the rank decided from
/// the data) and checked against the data set: a vector of the wrong
/// length is an [`IdentError::Invalid`], never a panic.
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, identify::Start, identify::identify_from};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&Campaign::grid(&m, 1))
///     .unwrap();
/// let model = GeometricModel::new(m.clone(), set.clone());
/// let options = IdentifyOptions::for_machine(&m);
/// // Start at Table 2 itself (an earlier calibration, say).
/// let start = Start { parameters: Some(set.table2()), ..Start::default() };
/// let id = identify_from(&model, &data, &options, &start).unwrap();
/// assert!(id.converged);
/// // A weight per pose, but one short: refused.
/// let short = Start { pose_weights: Some(vec![1.0; 74]), ..Start::default() };
/// assert!(identify_from(&model, &data, &options, &short).is_err());
/// ```
#[derive(Debug, Clone, Default)]
pub struct Start {
    /// Starting parameter values (default zero: the nominal machine).
    pub parameters: Option<Vec<f64>>,
    /// Per-pose weights multiplying `1/sigma` (default all one).
    pub pose_weights: Option<Vec<f64>>,
    /// FK starting points, one per pose (default: cold starts).
    pub fk_seeds: Option<Vec<UpJoints>>,
    /// A rank decision and report computed once for these poses and this
    /// noise ([`design`]), reused instead of deciding again (Monte Carlo
    /// studies).
    pub design: Option<Design>,
}

impl Start {
    /// The same start restricted to the poses whose index passes `keep`
    /// (the per-pose vectors follow the data set's [`Dataset::subset`]).
    ///
    /// # Example
    /// ```
    /// use tricept_engine::identify::Start;
    /// let s = Start { pose_weights: Some(vec![1.0, 2.0, 3.0]), ..Start::default() };
    /// assert_eq!(s.subset(|j| j != 1).pose_weights, Some(vec![1.0, 3.0]));
    /// ```
    pub fn subset(&self, keep: impl Fn(usize) -> bool) -> Start {
        fn pick<T: Clone>(v: &Option<Vec<T>>, keep: &impl Fn(usize) -> bool) -> Option<Vec<T>> {
            v.as_ref().map(|v| {
                v.iter()
                    .enumerate()
                    .filter(|(j, _)| keep(*j))
                    .map(|(_, x)| x.clone())
                    .collect()
            })
        }
        Start {
            parameters: self.parameters.clone(),
            pose_weights: pick(&self.pose_weights, &keep),
            fk_seeds: pick(&self.fk_seeds, &keep),
            // A rank decision belongs to the pose set it was taken on.
            design: None,
        }
    }
}

/// Residual statistics of a fit.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let set = ParameterSet::paper15();
let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
    .simulate(&tricept_plant::Campaign::grid(&m, 1))
    .unwrap();
let id = tricept_engine::identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
// The model explains the data to the noise: chi-square per degree of freedom near 1.
assert!((id.stats.reduced_chi_square - 1.0).abs() < 0.3);
assert_eq!(id.stats.dof, 3 * 75 - 14 - 3);
```
"#
)]
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ResidualStats {
    /// RMS of the residuals `[phi, theta, s]` (rad, rad, mm).
    pub rms: [f64; 3],
    /// Weighted sum of squared residuals (chi-square), the prior's share
    /// included when the model has one ([`Identification::prior_fit`]).
    pub chi_square: f64,
    /// Degrees of freedom: readings - identified parameters - 3 offsets
    /// per campaign (+ the parameters a prior covers).
    pub dof: usize,
    /// `chi_square / dof`: about 1 when the model and noise levels are right.
    pub reduced_chi_square: f64,
    /// Largest residual in noise standard deviations, and its pose index
    /// (0-based; [`Identification::lines`] gives its file line).
    pub max_standardised: (f64, usize),
}

/// The result of [`identify`].
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let set = ParameterSet::paper15();
let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
    .simulate(&tricept_plant::Campaign::grid(&m, 1))
    .unwrap();
let id = tricept_engine::identify(&model, &data, &IdentifyOptions::for_machine(&m)).unwrap();
let json = id.to_json();
assert_eq!(json["rank"], 14);
assert!(json["dq1"].is_number() && json["std_dev"]["dq1"].is_number());
```
"#
)]
#[derive(Debug, Clone)]
pub struct Identification {
    /// Parameter names.
    pub names: Vec<String>,
    /// Estimated parameter values (fixed parameters at their prior).
    pub estimate: Vec<f64>,
    /// Standard deviations from the covariance (`None` for fixed parameters).
    pub std_dev: Vec<Option<f64>>,
    /// Covariance of the parameters (`k x k`, zero rows and columns for
    /// fixed parameters), in the parameters' units squared.
    pub covariance: DMatrix<f64>,
    /// Estimated sensor zero offsets `[phi, theta, s]` (rad, rad, mm) of
    /// the first campaign (the only one of a single file).
    pub offsets: [f64; 3],
    /// Their standard deviations.
    pub offsets_std_dev: [f64; 3],
    /// Every campaign's offsets, ascending campaign number (one entry for
    /// a single file, equal to `offsets`).
    pub campaign_offsets: Vec<CampaignOffsets>,
    /// The prior's share of the chi-square, when the model has a prior.
    pub prior_fit: Option<PriorFit>,
    /// Identifiability of the problem at the starting point.
    pub report: IdentifiabilityReport,
    /// Residuals `y - g(p) - c` of every pose (rad, rad, mm).
    pub residuals: Vec<[f64; 3]>,
    /// Residual statistics.
    pub stats: ResidualStats,
    /// Gauss-Newton iterations performed.
    pub iterations: u32,
    /// Whether the iteration met its tolerance.
    pub converged: bool,
    /// The line of each pose in its data file (0 where there is none).
    pub lines: Vec<u64>,
    /// The rank decision taken at the start and used throughout.
    design: Design,
    /// Covariance of `[offsets | parameters]` (`3 c + k` square, three
    /// offsets per campaign), for the gross-error screen's hat matrix.
    pub(crate) full_covariance: faer::Mat<f64>,
    /// The campaigns fitted, whose offsets come first in `full_covariance`.
    pub(crate) campaigns: Campaigns,
}

/// One campaign's sensor zero offsets in a fit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CampaignOffsets {
    /// The campaign ([`tricept_data::MeasuredPose::campaign`]).
    pub campaign: u32,
    /// `[phi, theta, s]` (rad, rad, mm).
    pub offsets: [f64; 3],
    /// Their standard deviations.
    pub std_dev: [f64; 3],
}

/// Identifies the parameters of `model` from `data`.
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, identify};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
///
/// let machine = Machine::paper();
/// let set = ParameterSet::paper15();
/// let truth = set.table2();
/// let data = Plant::geometric(machine.clone(), set.to_errors(&truth))
///     .simulate(&Campaign::grid(&machine, 1))
///     .unwrap();
/// let model = GeometricModel::new(machine.clone(), set.clone());
/// let id = identify(&model, &data, &IdentifyOptions::for_machine(&machine)).unwrap();
/// // dq2 = 0.7 mm in Table 2, recovered to a few standard deviations:
/// let j = set.index_of("dq2").unwrap();
/// assert!((id.estimate[j] - truth[j]).abs() < 4.0 * id.std_dev[j].unwrap());
/// // With the paper's x-first U joint, dyA3 is invisible to the sensors:
/// assert_eq!(id.report.fixed, vec!["dyA3".to_string()]);
/// ```
pub fn identify(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
) -> Result<Identification, IdentError> {
    identify_from(model, data, options, &Start::default())
}

/// [`identify`] from a [`Start`]: a starting point, pose weights, FK seeds
/// or a rank decision taken earlier, each checked against `data`.
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, identify::Start, identify::design, identify::identify_from};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&Campaign::grid(&m, 1))
///     .unwrap();
/// let model = GeometricModel::new(m.clone(), set);
/// let options = IdentifyOptions::for_machine(&m);
/// // Decide the rank once for the pose set, then reuse the decision.
/// let d = design(&model, &[0.0; 15], &data.poses, &options).unwrap();
/// let start = Start { design: Some(d), ..Start::default() };
/// let id = identify_from(&model, &data, &options, &start).unwrap();
/// assert_eq!(id.design().rank(), 14);
/// ```
pub fn identify_from(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
    start: &Start,
) -> Result<Identification, IdentError> {
    Ok(fit(model, data, options, start, None)?.0)
}

/// The model evaluated over a data set at a starting point, with the FK
/// solutions found: the first evaluation of a fit, when a caller has made
/// it already (the gross-error screen's robust start).
pub(crate) struct FirstEvaluation {
    eval: Evaluation,
    seeds: Vec<Option<UpJoints>>,
}

impl FirstEvaluation {
    /// `model` at `p` over `poses`, from cold FK starts.
    pub(crate) fn new(
        model: &dyn ReadingModel,
        p: &[f64],
        poses: &[MeasuredPose],
        sigma: &[f64; 3],
    ) -> Result<FirstEvaluation, IdentError> {
        let mut seeds = vec![None; poses.len()];
        let eval = evaluate(model, p, poses, sigma, None, &mut seeds)?;
        Ok(FirstEvaluation { eval, seeds })
    }

    /// `y - g(p)` of every pose (rad, rad, mm).
    pub(crate) fn residuals(&self) -> &[[f64; 3]] {
        &self.eval.residuals
    }
}

/// [`identify_from`], optionally from its first evaluation made already
/// (at the start's parameters, from cold FK starts, without weights: the
/// caller's promise), and with the FK solutions at the estimate.
pub(crate) fn fit(
    model: &dyn ReadingModel,
    data: &Dataset,
    options: &IdentifyOptions,
    start: &Start,
    first_eval: Option<FirstEvaluation>,
) -> Result<(Identification, Vec<Option<UpJoints>>), IdentError> {
    let names = model.names().to_vec();
    let k = names.len();
    let poses = &data.poses;
    let prior = model.prior();
    check_size(poses, k, prior.as_ref().map_or(0, Prior::dimension))?;
    let mismatch = |what: &str, found: usize, expected: usize| {
        IdentError::Invalid(format!("{found} {what} for {expected}"))
    };
    if let Some(w) = &start.pose_weights {
        if w.len() != poses.len() {
            return Err(mismatch("pose weights", w.len(), poses.len()));
        }
        if w.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(IdentError::Invalid(
                "pose weights must be finite and non-negative".into(),
            ));
        }
    }
    let weights = start.pose_weights.as_deref();
    let p = match &start.parameters {
        Some(v) if v.len() == k => v.clone(),
        Some(v) => return Err(mismatch("starting values", v.len(), k)),
        None => vec![0.0; k],
    };
    let mut seeds: Vec<Option<UpJoints>> = match &start.fk_seeds {
        Some(s) if s.len() == poses.len() => s.iter().copied().map(Some).collect(),
        Some(s) => return Err(mismatch("FK seeds", s.len(), poses.len())),
        None => vec![None; poses.len()],
    };
    let eval = match first_eval {
        Some(f) if f.seeds.len() == poses.len() => {
            seeds = f.seeds;
            f.eval
        }
        _ => evaluate(model, &p, poses, &options.sigma, weights, &mut seeds)?,
    };
    let (decision, report, first) = match &start.design {
        Some(d) if d.decision.column_scale.len() == k => {
            let first = eval.problem.solve(&d.decision);
            (d.decision.clone(), d.report.clone(), first)
        }
        Some(d) => {
            return Err(mismatch(
                "parameters in the reused design",
                d.decision.column_scale.len(),
                k,
            ));
        }
        None => {
            let d = match model.rank_reference() {
                Some(reference) if reference.names() == names.as_slice() => {
                    design(reference, &vec![0.0; k], poses, options)?
                }
                Some(reference) => {
                    return Err(IdentError::Invalid(format!(
                        "the rank reference has parameters {:?}, the model {:?}",
                        reference.names(),
                        names
                    )));
                }
                None => decide_design(&names, &eval, poses.len(), options)?,
            };
            let first = eval.problem.solve(&d.decision);
            (d.decision, d.report, first)
        }
    };

    let problem = Problem {
        model,
        poses,
        options,
        weights,
    };
    let mut state = Run {
        p,
        state: seeds,
        eval,
        solution: first,
        iterations: 0,
        converged: false,
    };
    iterate(&problem, &mut state, &decision, options.max_iterations);

    let seeds = std::mem::take(&mut state.state);
    let fitted = Fitted {
        decision,
        report,
        weights,
        poses,
        prior,
    };
    Ok((finish(names, state, fitted, options), seeds))
}

/// The fixed parts of an identification problem.
struct Problem<'a> {
    model: &'a dyn ReadingModel,
    poses: &'a [MeasuredPose],
    options: &'a IdentifyOptions,
    weights: Option<&'a [f64]>,
}

impl Iteration for Problem<'_> {
    type State = Vec<Option<UpJoints>>;
    type Eval = Evaluation;

    fn evaluate(&self, p: &[f64], seeds: &mut Self::State) -> Result<Evaluation, IdentError> {
        evaluate(
            self.model,
            p,
            self.poses,
            &self.options.sigma,
            self.weights,
            seeds,
        )
    }

    fn problem<'e>(&self, eval: &'e Evaluation) -> &'e ReducedProblem {
        &eval.problem
    }
}

/// What a fit was made of besides its iteration: the rank decision and
/// report, the pose weights, the poses and the model's prior.
struct Fitted<'a> {
    decision: RankDecision,
    report: IdentifiabilityReport,
    weights: Option<&'a [f64]>,
    poses: &'a [MeasuredPose],
    prior: Option<Prior>,
}

fn finish(
    names: Vec<String>,
    state: Run<Vec<Option<UpJoints>>, Evaluation>,
    fitted: Fitted<'_>,
    options: &IdentifyOptions,
) -> Identification {
    let Run {
        p,
        eval,
        solution,
        iterations,
        converged,
        ..
    } = state;
    let Fitted {
        decision,
        report,
        weights,
        poses,
        prior,
    } = fitted;
    let k = names.len();
    let campaigns = Campaigns::of(poses);
    let nn = campaigns.nuisance();
    // The iteration ends on an evaluated point: its step is zero (and the
    // offsets re-fitted at p), except for the linearised estimator
    // (`max_iterations` 0), whose one step from the start is its estimate.
    let estimate: Vec<f64> = p
        .iter()
        .zip(&solution.parameters)
        .map(|(a, b)| a + b)
        .collect();
    let campaign_offsets: Vec<CampaignOffsets> = campaigns
        .ids()
        .iter()
        .enumerate()
        .map(|(i, &campaign)| CampaignOffsets {
            campaign,
            offsets: std::array::from_fn(|c| solution.nuisance[3 * i + c]),
            std_dev: std::array::from_fn(|c| {
                solution.covariance[(3 * i + c, 3 * i + c)].max(0.0).sqrt()
            }),
        })
        .collect();
    let std_dev = (0..k)
        .map(|j| {
            if decision.fixed.contains(&j) {
                None
            } else {
                Some(solution.covariance[(nn + j, nn + j)].max(0.0).sqrt())
            }
        })
        .collect();
    let covariance = DMatrix::from_fn(k, k, |a, b| solution.covariance[(nn + a, nn + b)]);
    let residuals: Vec<[f64; 3]> = eval
        .residuals
        .iter()
        .zip(poses)
        .map(|(r, pose)| {
            let o = &campaign_offsets[campaigns.index(pose).unwrap_or(0)].offsets;
            [0, 1, 2].map(|c| r[c] - o[c])
        })
        .collect();
    let n = residuals.len().max(1) as f64;
    let rms = [0, 1, 2].map(|c| (residuals.iter().map(|r| r[c] * r[c]).sum::<f64>() / n).sqrt());
    let mut chi_square = 0.0;
    let mut max_standardised = (0.0, 0);
    for (j, r) in residuals.iter().enumerate() {
        let w = weights.and_then(|w| w.get(j)).copied().unwrap_or(1.0);
        for c in 0..3 {
            let z = r[c] / options.sigma[c];
            chi_square += (w * z) * (w * z);
            if z.abs() > max_standardised.0 {
                max_standardised = (z.abs(), j);
            }
        }
    }
    let prior_fit = prior.map(|prior| PriorFit {
        chi_square: prior.chi_square(&estimate),
        dof: prior.dimension(),
    });
    chi_square += prior_fit.map_or(0.0, |f| f.chi_square);
    let dof =
        (3 * residuals.len() + prior_fit.map_or(0, |f| f.dof)).saturating_sub(decision.rank + nn);
    let lines = poses.iter().map(|p| p.line).collect();
    Identification {
        names,
        estimate,
        std_dev,
        covariance,
        offsets: campaign_offsets[0].offsets,
        offsets_std_dev: campaign_offsets[0].std_dev,
        campaign_offsets,
        prior_fit,
        report: report.clone(),
        residuals,
        stats: ResidualStats {
            rms,
            chi_square,
            dof,
            reduced_chi_square: if dof > 0 {
                chi_square / dof as f64
            } else {
                f64::NAN
            },
            max_standardised,
        },
        iterations,
        converged,
        lines,
        design: Design { decision, report },
        full_covariance: solution.covariance,
        campaigns,
    }
}

impl Identification {
    /// Per campaign fitted, its offsets and the covariance of `[its
    /// offsets | identifiable parameters]` (row-major, `q x q` with `q = 3 +
    /// rank`): the columns the rows of its poses touch. Index them with
    /// [`Identification::campaign_of`].
    pub(crate) fn campaign_blocks(&self) -> Vec<([f64; 3], Vec<f64>)> {
        let nn = self.campaigns.nuisance();
        let c = &self.full_covariance;
        self.campaign_offsets
            .iter()
            .enumerate()
            .map(|(i, o)| {
                let columns: Vec<usize> = (3 * i..3 * i + 3)
                    .chain(self.design.identifiable().iter().map(|&j| nn + j))
                    .collect();
                let q = columns.len();
                let cov = (0..q * q)
                    .map(|t| c[(columns[t / q], columns[t % q])])
                    .collect();
                (o.offsets, cov)
            })
            .collect()
    }

    /// The position of `pose`'s campaign among the fit's campaigns
    /// (`None`: a campaign the fit did not see).
    pub(crate) fn campaign_of(&self, pose: &MeasuredPose) -> Option<usize> {
        self.campaigns.index(pose)
    }

    /// The rank decision taken at the start and kept throughout (rank,
    /// identifiable and fixed parameters, singular directions).
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// JSON with the contract keys: every parameter name with its estimate
    /// (mm), `std_dev`, `rank`, `n_params`, `unidentifiable`,
    /// `singular_values`, `condition_number`, `observability`, residual
    /// statistics (poses numbered from 1, with their file line), the
    /// [`Verdict`](crate::verdict::Verdict) (`converged`, `adequate`, `warnings`),
    /// and more.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions, identify};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let set = ParameterSet::paper15();
let data = tricept_plant::Plant::geometric(m.clone(), set.to_errors(&set.table2()))
    .simulate(&tricept_plant::Campaign::grid(&m, 1))
    .unwrap();
let id = identify(&GeometricModel::new(m.clone(), set), &data, &IdentifyOptions::for_machine(&m)).unwrap();
let j = id.to_json();
// dq1 lies along the weakest direction; judge it by its own uncertainty.
let (dq1, sd) = (j["dq1"].as_f64().unwrap(), j["std_dev"]["dq1"].as_f64().unwrap());
assert!((dq1 - 0.45).abs() < 4.0 * sd, "{dq1} ± {sd}");
assert_eq!(j["rank"], 14);
```
"#
    )]
    pub fn to_json(&self) -> Value {
        let mut m = Map::new();
        for (n, v) in self.names.iter().zip(&self.estimate) {
            m.insert(n.clone(), (*v).into());
        }
        m.insert(
            "std_dev".into(),
            serde_json::to_value(NamedValues::new(&self.names, &self.std_dev))
                .unwrap_or(Value::Null),
        );
        m.insert(
            "offsets".into(),
            serde_json::json!({
                "phi_rad": self.offsets[0], "theta_rad": self.offsets[1], "s_mm": self.offsets[2],
                "std_dev": {"phi_rad": self.offsets_std_dev[0], "theta_rad": self.offsets_std_dev[1], "s_mm": self.offsets_std_dev[2]},
            }),
        );
        if let Value::Object(report) = self.report.to_json() {
            for (k, v) in report {
                m.insert(k, v);
            }
        }
        m.insert(
            "residuals".into(),
            serde_json::json!({
                "rms_phi_arcsec": self.stats.rms[0] / tricept_kinematics::units::RAD_PER_ARCSEC,
                "rms_theta_arcsec": self.stats.rms[1] / tricept_kinematics::units::RAD_PER_ARCSEC,
                "rms_s_um": self.stats.rms[2] * 1e3,
                "chi_square": self.stats.chi_square,
                "dof": self.stats.dof,
                "reduced_chi_square": self.stats.reduced_chi_square,
                "max_standardised": self.stats.max_standardised.0,
                "max_standardised_pose": self.stats.max_standardised.1 + 1,
                "max_standardised_line": self.lines.get(self.stats.max_standardised.1).copied().unwrap_or(0),
            }),
        );
        m.insert("iterations".into(), self.iterations.into());
        let verdict = self.verdict();
        m.insert("converged".into(), verdict.converged.into());
        m.insert("adequate".into(), verdict.adequate.into());
        m.insert(
            "chi_square_p_value".into(),
            verdict.chi_square_p_value.into(),
        );
        m.insert(
            "consistent_with_machine".into(),
            (!verdict.inconsistent).into(),
        );
        m.insert("warnings".into(), verdict.warnings.into());
        Value::Object(m)
    }
}
