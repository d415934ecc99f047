//! The design of a pose set: the rank decision (which parameters the data
//! can see) and the identifiability report, taken once before any data
//! ([`design`], [`identifiability`]) or at an identification's starting
//! point, and the check that a campaign has enough readings and distinct
//! poses for its unknowns.

use tricept_data::MeasuredPose;
use tricept_numerics::lsq::RankDecision;

use crate::campaigns::Campaigns;
use crate::error::IdentError;
use crate::evaluate::{Evaluation, evaluate};
use crate::model::ReadingModel;
use crate::options::IdentifyOptions;
use crate::report::IdentifiabilityReport;

/// The rank decision and identifiability report of a pose set under a
/// noise model, computed once ([`design`]) and reused by many
/// identifications ([`crate::identify::Start::design`]).
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
let poses: Vec<tricept_data::MeasuredPose> = m
    .workspace
    .polar_grid(3, 8, 3)
    .iter()
    .map(|r| tricept_data::MeasuredPose {
        commands_mm: m.inverse(r).unwrap().legs_mm,
        ..Default::default()
    })
    .collect();
let d = tricept_engine::identify::design(&model, &[0.0; 15], &poses, &IdentifyOptions::for_machine(&m)).unwrap();
assert_eq!(d.rank(), 14);
assert_eq!(d.report().fixed, vec!["dyA3".to_string()]);
assert_eq!(d.fixed(), &[11]); // dyA3's index in paper15
```
"#
)]
#[derive(Debug, Clone)]
pub struct Design {
    pub(crate) decision: RankDecision,
    pub(crate) report: IdentifiabilityReport,
}

impl Design {
    /// The identifiability report of the pose set.
    pub fn report(&self) -> &IdentifiabilityReport {
        &self.report
    }

    /// Numerical rank.
    pub fn rank(&self) -> usize {
        self.decision.rank
    }

    /// Indices of the parameters estimated (ascending).
    pub fn identifiable(&self) -> &[usize] {
        &self.decision.identifiable
    }

    /// Indices of the parameters held at their prior (ascending).
    pub fn fixed(&self) -> &[usize] {
        &self.decision.fixed
    }

    /// The `i`-th right singular direction of the column-scaled design
    /// (`0`: the best determined), in parameter units; `None` beyond the
    /// number of parameters. Directions `rank()..` span what the data
    /// cannot see; direction `rank() - 1` is the weakest one they can.
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
let id = identify(&GeometricModel::new(m.clone(), set.clone()), &data, &IdentifyOptions::for_machine(&m)).unwrap();
// The weakest visible direction moves the three leg lengths together.
let d = id.design();
let v = d.direction(d.rank() - 1).unwrap();
let dq = ["dq1", "dq2", "dq3"].map(|n| v[set.index_of(n).unwrap()]);
assert!(dq.iter().all(|x| x.signum() == dq[0].signum()));
```
"#
    )]
    pub fn direction(&self, i: usize) -> Option<Vec<f64>> {
        (i < self.decision.column_scale.len()).then(|| self.decision.direction(i))
    }
}

/// Checks that there are enough readings, and enough distinct poses, for
/// the unknowns: repeated commands average the noise but add no geometry.
pub(crate) fn check_size(
    poses: &[MeasuredPose],
    k: usize,
    prior_rows: usize,
) -> Result<(), IdentError> {
    let n_poses = poses.len();
    let unknowns = (k + Campaigns::of(poses).nuisance()).saturating_sub(prior_rows);
    let needed = (unknowns.div_ceil(3) + 1).max(2);
    if 3 * n_poses < unknowns + 1 {
        return Err(IdentError::TooFewPoses {
            poses: n_poses,
            readings: 3 * n_poses,
            unknowns,
            needed,
        });
    }
    let distinct = distinct_commands(poses, needed);
    if distinct < needed {
        return Err(IdentError::TooFewDistinctPoses {
            poses: n_poses,
            distinct,
            unknowns,
            needed,
        });
    }
    Ok(())
}

/// The number of distinct command triples among `poses`, counted up to
/// `enough` (the count stops there: a large file costs one pass).
fn distinct_commands(poses: &[MeasuredPose], enough: usize) -> usize {
    let mut seen: Vec<[u64; 3]> = Vec::with_capacity(enough);
    for p in poses {
        let key = p.commands_mm.map(f64::to_bits);
        if !seen.contains(&key) {
            seen.push(key);
            if seen.len() >= enough {
                break;
            }
        }
    }
    seen.len()
}

/// Rank decision and report from one evaluation.
pub(crate) fn decide_design(
    names: &[String],
    eval: &Evaluation,
    n_poses: usize,
    options: &IdentifyOptions,
) -> Result<Design, IdentError> {
    let decision = eval
        .problem
        .decide(options.rank_tolerance)
        .ok_or(IdentError::Numerical("SVD did not converge"))?;
    let solution = eval.problem.solve(&decision);
    let report = IdentifiabilityReport::new(
        names,
        &decision,
        &solution,
        eval.problem.n_nuisance,
        eval.problem.rows,
        n_poses,
        options.weak_threshold,
    );
    Ok(Design { decision, report })
}

/// The rank decision and report of a pose set (see [`identifiability`]),
/// for reuse through [`crate::identify::Start::design`].
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let poses: Vec<tricept_data::MeasuredPose> = m
///     .workspace
///     .polar_grid(3, 8, 3)
///     .iter()
///     .map(|r| tricept_data::MeasuredPose { commands_mm: m.inverse(r).unwrap().legs_mm, ..Default::default() })
///     .collect();
/// let opts = IdentifyOptions::for_machine(&m);
/// let d = tricept_engine::identify::design(&model, &[0.0; 15], &poses, &opts).unwrap();
/// assert_eq!(d.report().fixed, vec!["dyA3".to_string()]);
/// ```
pub fn design(
    model: &dyn ReadingModel,
    p: &[f64],
    poses: &[MeasuredPose],
    options: &IdentifyOptions,
) -> Result<Design, IdentError> {
    let prior_rows = model.prior().map_or(0, |p| p.dimension());
    check_size(poses, model.names().len(), prior_rows)?;
    let mut seeds = vec![None; poses.len()];
    if p.len() != model.names().len() {
        return Err(IdentError::Invalid(format!(
            "{} parameter values for {} parameters",
            p.len(),
            model.names().len()
        )));
    }
    let eval = evaluate(model, p, poses, &options.sigma, None, &mut seeds)?;
    decide_design(model.names(), &eval, poses.len(), options)
}

/// The identifiability of a pose set before any data is taken: the
/// identification matrix of `model` at `p` (usually zero) for the commands
/// of `poses`, with the given logged noise.
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// let m = Machine::paper();
/// let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
/// let poses: Vec<tricept_data::MeasuredPose> = m
///     .workspace
///     .polar_grid(3, 8, 3)
///     .iter()
///     .map(|r| tricept_data::MeasuredPose {
///         commands_mm: m.inverse(r).unwrap().legs_mm,
///         ..Default::default()
///     })
///     .collect();
/// let report = tricept_engine::identify::identifiability(&model, &[0.0; 15], &poses, &IdentifyOptions::for_machine(&m)).unwrap();
/// assert_eq!(report.unidentifiable[0].to_text(), "1.000 dyA3");
/// ```
pub fn identifiability(
    model: &dyn ReadingModel,
    p: &[f64],
    poses: &[MeasuredPose],
    options: &IdentifyOptions,
) -> Result<IdentifiabilityReport, IdentError> {
    Ok(design(model, p, poses, options)?.report)
}
