//! A batch of machines calibrated together: the hierarchical model of
//! `docs/fleet.md`.
//!
//! 1. Every machine alone ([`OwnFit`]): its own calibration and exit code.
//!    A machine whose own data do not fit (exit 3 or 4, or data that cannot
//!    be identified) is reported and kept out of the batch estimates; so is
//!    one whose campaign cannot determine every parameter the batch does.
//! 2. The batch's rank decision over every machine's poses
//!    ([`batch_design`]): what no machine sees (`dyA3` with the x-first UP
//!    limb) is held for the batch too, by name.
//! 3. The spread by REML on the machines' own calibrations
//!    ([`crate::reml`]), and the outlier test: each machine's estimate
//!    against the mean of the others, `T = r^T (V_m + S_-m^-1)^-1 r`,
//!    chi-square with `r` degrees of freedom in a batch of one population
//!    when the spread is known; estimated from `M - 1` other machines, `T
//!    / r` is taken against `F(r, M - 2)`, and beside it the largest
//!    single parameter's `z^2` against `F(1, M - 2)` times `r` (a fault
//!    in one joint, which `T` dilutes), the smaller p-value doubled. The
//!    worst machine whose p-value is below the Bonferroni level `alpha /
//!    M` leaves the batch, the spread is estimated again, until
//!    none is beyond it (a machine set aside comes back when the final
//!    batch takes it). A machine inside inflates the spread it is tested
//!    against (masking: one machine at 12 spreads among 20 nearly triples
//!    it), so the three most distant members of each round, by `T` and by
//!    a robust scale (the median absolute deviation), are tested against
//!    the spread of the others (deleted). A parameter of a
//!    machine is a *deviate* when its own `z` is beyond the two-sided
//!    Student criterion (`z^2` against `F(1, M - 2)`) at `alpha / (r M)`.
//! 4. The joint fit of every member's readings on the sparse core
//!    ([`crate::joint`]): the batch mean, each member's parameters with
//!    the batch as its prior, their covariances.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_engine::{IdentifyOptions, accuracy::AccuracyModel, model::ReadingModel};
pub use tricept_numerics::sparse::{SolveStats, SolverKind};
use tricept_numerics::stats::{chi2_sf, median};

use crate::error::FleetError;
use crate::joint::{JointFit, JointInput};
use crate::own::{EXIT_INADEQUATE, EXIT_NOT_CONVERGED, EXIT_OK, OwnFit, batch_design};
use crate::reml::{Distance, Spread, Summary, leave_one_out, reml};

/// How a batch is calibrated.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchOptions {
    /// Family-wise level of the outlier and deviate tests (default 0.001,
    /// the adequacy level of every fit).
    pub alpha: f64,
    /// The factorisation of the joint fit's steps.
    pub kind: SolverKind,
    /// Gauss-Newton iterations of the joint fit at most.
    pub max_iterations: u32,
    /// The largest share of machines the outlier test may set aside before
    /// the batch is declared not one population (default 0.2).
    pub max_outlier_share: f64,
}

impl Default for BatchOptions {
    fn default() -> BatchOptions {
        BatchOptions {
            alpha: 1e-3,
            kind: SolverKind::Schur,
            max_iterations: 20,
            max_outlier_share: 0.2,
        }
    }
}

/// The fewest machines whose data fit for a batch to be estimated.
pub const MIN_MACHINES: usize = 3;

/// One machine's place in the batch.
#[derive(Debug, Clone)]
pub struct MachineOutcome {
    /// Its own calibration.
    pub own: OwnFit,
    /// Whether it is in the batch estimates.
    pub in_batch: bool,
    /// Why it is not (its own data, its campaign, or the outlier test).
    pub kept_out: Option<String>,
    /// Whether the outlier test set it aside.
    pub outlier: bool,
    /// Its distance from the rest (machines whose data fit).
    pub distance: Option<Distance>,
    /// `P(chi2_r > T)` of that distance.
    pub p_value: Option<f64>,
    /// Its parameters beyond the spread (names).
    pub deviates: Vec<String>,
    /// Its estimate (all `k`): the joint fit's for a member, its own
    /// otherwise.
    pub estimate: Vec<f64>,
    /// Standard deviations (`None`: held, or no fit).
    pub std_dev: Vec<Option<f64>>,
    /// Its sensor offsets.
    pub offsets: [f64; 3],
}

/// A batch calibrated (module docs).
#[derive(Debug, Clone)]
pub struct Batch {
    /// Parameter names.
    pub names: Vec<String>,
    /// Indices of the identifiable parameters (the rest held at zero).
    pub identifiable: Vec<usize>,
    /// The batch's null directions (parameter units), by the rank decision.
    pub unidentifiable: Vec<Vec<f64>>,
    /// Every machine, in the order given.
    pub machines: Vec<MachineOutcome>,
    /// The REML spread of the members.
    pub spread: Spread,
    /// The joint fit of the members.
    pub joint: JointFit,
    /// Warnings (machines kept out, a batch of more than one population).
    pub warnings: Vec<String>,
    /// More machines beyond the outlier test than `max_outlier_share`.
    pub not_one_population: bool,
}

impl Batch {
    /// Indices of the held parameters.
    pub fn held(&self) -> Vec<usize> {
        (0..self.names.len())
            .filter(|j| !self.identifiable.contains(j))
            .collect()
    }

    /// The data files of the outlier machines.
    pub fn outliers(&self) -> Vec<&str> {
        self.machines
            .iter()
            .filter(|m| m.outlier)
            .map(|m| m.own.source.as_str())
            .collect()
    }

    /// How many machines are in the batch estimates.
    pub fn members(&self) -> usize {
        self.machines.iter().filter(|m| m.in_batch).count()
    }

    /// 0: every machine fits and belongs; 3: a machine is kept out (its own
    /// data, or an outlier), or the batch is not one population; 4: the
    /// joint fit or the spread's estimate did not converge.
    pub fn exit_code(&self) -> u8 {
        if !(self.joint.converged && self.spread.converged) {
            EXIT_NOT_CONVERGED
        } else if self.not_one_population || self.machines.iter().any(|m| !m.in_batch) {
            EXIT_INADEQUATE
        } else {
            EXIT_OK
        }
    }

    /// The batch mean (all `k`, held at zero) and its standard deviations
    /// (`None`: held).
    pub fn mean(&self) -> (Vec<f64>, Vec<Option<f64>>) {
        let k = self.names.len();
        let mut mean = vec![0.0; k];
        let mut sd = vec![None; k];
        for (a, &j) in self.identifiable.iter().enumerate() {
            mean[j] = self.joint.mean[a];
            sd[j] = Some(self.joint.mean_covariance[(a, a)].max(0.0).sqrt());
        }
        (mean, sd)
    }

    /// The spread of every parameter (`None`: held), mm.
    pub fn spread_mm(&self) -> Vec<Option<f64>> {
        self.per_parameter(self.spread.spread_mm())
    }

    /// A 95 % upper bound of every parameter's spread (`None`: held), mm.
    pub fn spread_upper_mm(&self) -> Vec<Option<f64>> {
        self.per_parameter(self.spread.spread_upper_mm())
    }

    fn per_parameter(&self, values: Vec<f64>) -> Vec<Option<f64>> {
        let mut out = vec![None; self.names.len()];
        for (a, &j) in self.identifiable.iter().enumerate() {
            out[j] = Some(values[a]);
        }
        out
    }

    /// The block problem of the joint fit's first step (the members at
    /// their own estimates, the mean at the spread's): the normal
    /// equations every solver kind solves, for benchmarks and peers.
    pub fn first_step_problem(
        &self,
        model: &dyn ReadingModel,
        sigma: [f64; 3],
    ) -> Result<tricept_numerics::sparse::BlockProblem, FleetError> {
        let r = self.identifiable.len();
        let members: Vec<&MachineOutcome> = self.machines.iter().filter(|m| m.in_batch).collect();
        let mut scales: Vec<Vec<f64>> = vec![vec![1.0; r]; members.len()];
        scales.push(vec![1.0; r]);
        let input = JointInput {
            model,
            data: members.iter().map(|m| &m.own.kept).collect(),
            start: members
                .iter()
                .map(|m| {
                    m.own
                        .id
                        .as_ref()
                        .map_or_else(Vec::new, |id| id.estimate.clone())
                })
                .collect(),
            identifiable: &self.identifiable,
            spread_variance: &self.spread.variance,
            mean_start: self.spread.mean.iter().copied().collect(),
            scales,
            sigma,
            kind: SolverKind::Schur,
            max_iterations: 1,
        };
        crate::joint::first_step_problem(&input)
    }

    /// What the batch says of a new machine of it, before its data: the
    /// mean (all `k`) and, over the identifiable parameters, the covariance
    /// of a machine's parameters: its spread at the 95 % upper bound (the
    /// spread is itself estimated from few machines) plus the mean's
    /// uncertainty.
    pub fn predictive(&self) -> (Vec<f64>, DMatrix<f64>) {
        let upper = self.spread.spread_upper_mm();
        let mut cov = self.joint.mean_covariance.clone();
        for (a, u) in upper.iter().enumerate() {
            cov[(a, a)] += u * u;
        }
        (self.mean().0, cov)
    }
}

/// Calibrates the machines of `datasets` (one data set each) as a batch
/// of `model` (module docs); `accuracy` judges each campaign's worth as
/// `identify` does.
pub fn calibrate_batch(
    model: &dyn ReadingModel,
    datasets: &[Dataset],
    options: &IdentifyOptions,
    accuracy: &AccuracyModel,
    batch: &BatchOptions,
) -> Result<Batch, FleetError> {
    let names = model.names().to_vec();
    let own: Vec<OwnFit> = datasets
        .par_iter()
        .map(|d| OwnFit::new(model, d, options, accuracy))
        .collect();
    let fitting: Vec<&Dataset> = own.iter().filter(|o| o.fits()).map(|o| &o.kept).collect();
    if fitting.len() < MIN_MACHINES {
        return Err(FleetError::Input(format!(
            "a batch needs at least {MIN_MACHINES} machines whose own data fit; {} of {} do",
            fitting.len(),
            own.len()
        )));
    }
    let design = batch_design(model, &fitting, options)?;
    let identifiable = design.identifiable.clone();
    let r = identifiable.len();
    // Machines that can enter: data that fit, every batch parameter seen.
    let candidate: Vec<Option<String>> = own
        .iter()
        .map(|o| match &o.id {
            _ if !o.fits() => Some(o.reason.clone().unwrap_or_default()),
            Some(id) if id.design().identifiable() != identifiable.as_slice() => {
                Some("its campaign cannot determine every parameter the batch does".to_string())
            }
            _ => None,
        })
        .collect();
    let candidates: Vec<usize> = (0..own.len()).filter(|&i| candidate[i].is_none()).collect();
    if candidates.len() < MIN_MACHINES {
        return Err(FleetError::Input(format!(
            "a batch needs at least {MIN_MACHINES} machines that determine its parameters; {} do",
            candidates.len()
        )));
    }
    let summaries: Vec<Summary> = candidates
        .iter()
        .map(|&i| summary(&own[i], &identifiable))
        .collect();
    let (member, spread, distances, not_one_population) =
        screen_outliers(&summaries, batch.alpha, batch.max_outlier_share)?;
    let deviate_level = batch.alpha / (r * candidates.len()) as f64;

    // The joint fit of the members.
    let members: Vec<usize> = (0..candidates.len()).filter(|&c| member[c]).collect();
    let mean_sd: Vec<f64> = (0..r)
        .map(|a| spread.mean_covariance[(a, a)].max(0.0).sqrt())
        .collect();
    let mut scales: Vec<Vec<f64>> = members
        .iter()
        .map(|&c| {
            (0..r)
                .map(|a| summaries[c].covariance[(a, a)].max(0.0).sqrt())
                .collect()
        })
        .collect();
    scales.push(mean_sd);
    let input = JointInput {
        model,
        data: members.iter().map(|&c| &own[candidates[c]].kept).collect(),
        start: members
            .iter()
            .map(|&c| {
                own[candidates[c]]
                    .id
                    .as_ref()
                    .map_or_else(Vec::new, |id| id.estimate.clone())
            })
            .collect(),
        identifiable: &identifiable,
        spread_variance: &spread.variance,
        mean_start: spread.mean.iter().copied().collect(),
        scales,
        sigma: options.sigma,
        kind: batch.kind,
        max_iterations: batch.max_iterations,
    };
    let joint = crate::joint::fit(&input)?;

    let mut warnings = Vec::new();
    let machines = own
        .into_iter()
        .enumerate()
        .map(|(i, o)| {
            let c = candidates.iter().position(|&x| x == i);
            let m = c.and_then(|c| members.iter().position(|&x| x == c));
            let distance = c.map(|c| distances[c].clone());
            let p_value = distance.as_ref().map(distance_p_value);
            let outlier = c.is_some_and(|c| !member[c]);
            let deviates = distance
                .as_ref()
                .map(|d| {
                    identifiable
                        .iter()
                        .zip(&d.z)
                        .filter(|(_, z)| chi2_sf(z.powi(2), 1.0) < deviate_level)
                        .map(|(&j, _)| names[j].clone())
                        .collect()
                })
                .unwrap_or_default();
            let kept_out = match (&candidate[i], outlier) {
                (Some(why), _) => Some(why.clone()),
                (None, true) => Some(format!(
                    "it does not belong to the batch: its estimate is chi2 {:.1} on {r} from the others' mean beyond the spread (p = {:.1e})",
                    distance.as_ref().map_or(0.0, |d| d.chi_square),
                    p_value.unwrap_or(0.0)
                )),
                (None, false) => None,
            };
            if let Some(why) = &kept_out {
                warnings.push(format!("{} is kept out of the batch: {why}", o.source));
            }
            let (estimate, std_dev, offsets) = match (m, &o.id) {
                (Some(m), _) => {
                    let mut sd = vec![None; names.len()];
                    for (a, &j) in identifiable.iter().enumerate() {
                        sd[j] = Some(joint.covariances[m][(a, a)].max(0.0).sqrt());
                    }
                    (joint.parameters[m].clone(), sd, joint.offsets[m])
                }
                (None, Some(id)) => (id.estimate.clone(), id.std_dev.clone(), id.offsets),
                (None, None) => (vec![f64::NAN; names.len()], vec![None; names.len()], [f64::NAN; 3]),
            };
            MachineOutcome {
                in_batch: m.is_some(),
                kept_out,
                outlier,
                distance,
                p_value,
                deviates,
                estimate,
                std_dev,
                offsets,
                own: o,
            }
        })
        .collect();
    if not_one_population {
        warnings.push(format!(
            "more than {:.0} % of the machines are beyond the outlier test: the batch may not be one population (docs/fleet.md, when not to use it)",
            100.0 * batch.max_outlier_share
        ));
    }
    Ok(Batch {
        unidentifiable: design.null_space_basis(),
        names,
        identifiable,
        machines,
        spread,
        joint,
        warnings,
        not_one_population,
    })
}

/// One machine's own estimate and covariance over the identifiable
/// parameters.
fn summary(o: &OwnFit, identifiable: &[usize]) -> Summary {
    let r = identifiable.len();
    match &o.id {
        Some(id) => Summary {
            estimate: DVector::from_fn(r, |a, _| id.estimate[identifiable[a]]),
            covariance: DMatrix::from_fn(r, r, |a, b| {
                id.covariance[(identifiable[a], identifiable[b])]
            }),
        },
        None => Summary {
            estimate: DVector::from_element(r, f64::NAN),
            covariance: DMatrix::identity(r, r),
        },
    }
}

/// How many of the most distant members (by their distance, and by a
/// robust scale) the outlier screen tests against the spread of the
/// others, each round.
const DELETED_CANDIDATES: usize = 3;

/// The p-value of a machine's distance from the others, two tests
/// Bonferroni-combined: `T` against `chi2_r` sees a machine off a little
/// in many parameters; the largest `z_k^2` against `chi2_1`, times `r`,
/// one off in one parameter (an assembly fault is usually one joint), which
/// `T` dilutes over `r` degrees of freedom. Both are taken at the spread's
/// 95 % upper bound ([`spread_for_tests`]).
fn distance_p_value(d: &Distance) -> f64 {
    let r = d.dof as f64;
    let overall = chi2_sf(d.chi_square, r);
    let largest = d.z.iter().map(|z| z * z).fold(0.0, f64::max);
    let single = (r * chi2_sf(largest, 1.0)).min(1.0);
    (2.0 * overall.min(single)).min(1.0)
}

/// The spread a machine is tested against: each `tau_k^2` at its 95 %
/// upper bound. The spread is estimated from the machines themselves (at
/// 20 machines it is known to a third of itself); tested at the estimate,
/// 3 of 570 clean machines of the tally were named (docs/fleet.md).
fn spread_for_tests(spread: &Spread) -> Vec<f64> {
    spread.spread_upper_mm().iter().map(|t| t * t).collect()
}

/// Each member's largest deviation from the members' median, per
/// parameter in units of 1.4826 times the median absolute deviation (not
/// inflated by one machine far off); 0 for machines that are not members.
fn robust_scores(summaries: &[Summary], member: &[bool]) -> Vec<f64> {
    let r = summaries.first().map_or(0, |s| s.estimate.len());
    let mut scores = vec![0.0f64; summaries.len()];
    for k in 0..r {
        let mut values: Vec<f64> = summaries
            .iter()
            .zip(member)
            .filter(|(_, m)| **m)
            .map(|(s, _)| s.estimate[k])
            .collect();
        let centre = median(&mut values);
        let mut deviations: Vec<f64> = values.iter().map(|v| (v - centre).abs()).collect();
        let scale = 1.4826 * median(&mut deviations);
        if scale.is_nan() || scale <= 0.0 {
            continue;
        }
        for (i, s) in summaries.iter().enumerate() {
            if member[i] {
                scores[i] = scores[i].max((s.estimate[k] - centre).abs() / scale);
            }
        }
    }
    scores
}

/// The outlier screen (module docs, step 3): membership, the members'
/// spread, every candidate's distance from the members, and whether more
/// than `max_share` of them were set aside (then nobody is).
type Screened = (Vec<bool>, Spread, Vec<Distance>, bool);

fn screen_outliers(
    summaries: &[Summary],
    alpha: f64,
    max_share: f64,
) -> Result<Screened, FleetError> {
    let n = summaries.len();
    let level = alpha / n as f64;
    let cap = ((max_share * n as f64).floor() as usize).min(n - MIN_MACHINES);
    let fit = |member: &[bool]| -> Result<(Spread, Vec<Distance>), FleetError> {
        let inside: Vec<Summary> = summaries
            .iter()
            .zip(member)
            .filter(|(_, m)| **m)
            .map(|(s, _)| s.clone())
            .collect();
        let spread = reml(&inside)?;
        let distances = leave_one_out(summaries, &spread_for_tests(&spread), member)?;
        Ok((spread, distances))
    };
    let mut member = vec![true; n];
    let mut seen: Vec<Vec<bool>> = Vec::new();
    let (mut spread, mut distances) = fit(&member)?;
    while !seen.contains(&member) {
        seen.push(member.clone());
        // A machine set aside comes back when the batch takes it.
        let back: Vec<usize> = (0..n)
            .filter(|&m| !member[m] && distance_p_value(&distances[m]) >= level)
            .collect();
        let next = if back.is_empty() {
            // The spread with a machine inside is inflated by that machine
            // (masking): the most distant members are tested against the
            // spread of the others (a deleted statistic, as the screen of
            // gross readings studentises externally).
            let mut order: Vec<usize> = (0..n).filter(|&m| member[m]).collect();
            order.sort_by(|a, b| {
                distances[*b]
                    .chi_square
                    .total_cmp(&distances[*a].chi_square)
            });
            // A machine far off in one parameter can hide behind the spread
            // it inflates: the most distant by a robust scale are tested too.
            let robust = robust_scores(summaries, &member);
            let mut by_robust: Vec<usize> = order.clone();
            by_robust.sort_by(|a, b| robust[*b].total_cmp(&robust[*a]));
            let mut tested: Vec<usize> = order.iter().take(DELETED_CANDIDATES).copied().collect();
            for m in by_robust.into_iter().take(DELETED_CANDIDATES) {
                if !tested.contains(&m) {
                    tested.push(m);
                }
            }
            let mut worst: Option<(usize, f64)> = None;
            // The spread of the others needs at least MIN_MACHINES of them:
            // a batch of three is not screened.
            if order.len() <= MIN_MACHINES {
                tested.clear();
            }
            for &m in &tested {
                let mut without = member.clone();
                without[m] = false;
                let p = distance_p_value(&fit(&without)?.1[m]);
                if p < level && worst.is_none_or(|w| p < w.1) {
                    worst = Some((m, p));
                }
            }
            match worst {
                Some((w, _)) if member.iter().filter(|x| !**x).count() < cap + 1 => {
                    let mut next = member.clone();
                    next[w] = false;
                    next
                }
                _ => break,
            }
        } else {
            let mut next = member.clone();
            back.iter().for_each(|&m| next[m] = true);
            next
        };
        member = next;
        (spread, distances) = fit(&member)?;
    }
    let out = member.iter().filter(|x| !**x).count();
    if out > cap {
        let all = vec![true; n];
        let (spread, distances) = fit(&all)?;
        return Ok((all, spread, distances, true));
    }
    Ok((member, spread, distances, false))
}
