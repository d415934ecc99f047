//! What the sources of a fused identification can see, alone and together,
//! and what it means for the tool tip.
//!
//! Everything is computed on the weighted problems at the starting point
//! (each source's nuisance projected out, columns scaled to unit norm),
//! like [`crate::report::IdentifiabilityReport`]:
//!
//! - **each source alone and the union**: rank, unidentifiable and weak
//!   combinations (one `IdentifiabilityReport` each);
//! - **made visible**: with an internal source, which parameters it holds
//!   at the prior alone but the union with each other source determines;
//! - **named quantities**: every head and effect parameter and
//!   `dq1 + dq2 + dq3` (the internal weak direction's core), each a linear
//!   function `c . p` of the parameters; its standard deviation per source
//!   and in the union when the source can see it (`c` orthogonal to the
//!   source's null space, checked on the rank-revealing basis; otherwise
//!   reported as invisible, never as a pseudo-inverse number);
//! - **tool-tip impact** of every weak combination (per standard deviation
//!   along it) and every invisible one (with its largest term at its
//!   parameter's typical size, [`FusedModel::typical_sizes`]): the RMS over
//!   the evaluation poses of the tool tip's displacement, raw and after
//!   touch-off (the mean displacement removed: what locating the part with
//!   the machine itself makes irrelevant);
//! - **the tool tip's and the tool axis' predicted uncertainty** over the
//!   evaluation poses (the tip raw and after touch-off), from the
//!   covariance of the estimate and, for every parameter held at its prior,
//!   its invisible combination at the parameter's typical size: the data
//!   do not calibrate it, so the machine keeps an error of that size along
//!   it. The held parameters that move the tip or the axis are named.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use serde_json::Value;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_model::head_errors::Effector;
use tricept_numerics::lsq::{RankDecision, ReducedProblem};

use crate::error::IdentError;
use crate::fusion::model::FusedModel;
use crate::fusion::options::FusionOptions;
use crate::fusion::source::{Source, SourceKind};
use crate::report::{Combination, IdentifiabilityReport, NamedValues, combination};

/// One source's identifiability on its own.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceVisibility {
    /// The source's label.
    pub label: String,
    /// Its identifiability report (its own nuisance projected out).
    pub report: IdentifiabilityReport,
}

/// What one external source adds to the internal data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MadeVisible {
    /// The external source's label.
    pub label: String,
    /// Rank of the internal data alone.
    pub internal_rank: usize,
    /// Rank of the internal data with this source.
    pub rank_with_internal: usize,
    /// Parameters the internal data hold at the prior that the union with
    /// this source determines.
    pub parameters: Vec<String>,
}

/// A named linear function of the parameters and how well each source
/// determines it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NamedQuantity {
    /// Name (a parameter's, or a sum such as `dq1 + dq2 + dq3`).
    pub name: String,
    /// Standard deviation by source label (`null`: invisible to it), in the
    /// quantity's unit.
    pub std_dev: NamedValues,
    /// Standard deviation in the union (`None`: invisible).
    pub union: Option<f64>,
    /// `std_dev[internal] / union` (`None` when either is invisible).
    pub gain: Option<f64>,
}

/// How much a combination of parameters moves the tool tip.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TipImpact {
    /// `union` or a source label: whose weak or invisible combination.
    pub scope: String,
    /// The combination (largest coefficient 1).
    pub combination: Combination,
    /// True for a weak combination (impact per standard deviation along
    /// it); false for an invisible one (impact when its largest term is at
    /// its parameter's typical size, [`FusedModel::typical_sizes`]).
    pub per_std_dev: bool,
    /// RMS tool-tip displacement over the evaluation poses, um.
    pub raw_um: f64,
    /// The same after touch-off (mean displacement removed), um.
    pub touch_off_um: f64,
    /// RMS rotation of the tool axis over the evaluation poses, arcsec.
    pub axis_arcsec: f64,
    /// Whether `touch_off_um` is below the harmless threshold (harmless to
    /// the tool tip; `axis_arcsec` says what it does to the tool axis).
    pub harmless: bool,
}

/// The tool tip's predicted standard deviation over the evaluation poses:
/// the estimate's covariance plus every held parameter's invisible
/// combination at its typical size.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToolTipPrediction {
    /// Number of evaluation poses.
    pub poses: usize,
    /// RMS over the poses of the tip's standard deviation (square root of
    /// the covariance's trace), um.
    pub raw_rms_um: f64,
    /// Largest over the poses, um.
    pub raw_max_um: f64,
    /// RMS after touch-off, um.
    pub touch_off_rms_um: f64,
    /// Largest after touch-off, um.
    pub touch_off_max_um: f64,
    /// The held parameters' share of `raw_rms_um` (their typical sizes
    /// alone), um.
    pub held_raw_rms_um: f64,
    /// The held parameters' share of `touch_off_rms_um`, um.
    pub held_touch_off_rms_um: f64,
    /// Parameters held at nominal whose invisible combination, at typical
    /// size, moves the tool tip by the harmless threshold or more: the tip
    /// is not calibrated in those directions (they are in the numbers
    /// above at their typical size, not at what this machine has).
    pub held_moving_tip: Vec<String>,
}

/// The tool axis' predicted standard deviation over the evaluation poses
/// (the same covariance as [`ToolTipPrediction`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToolAxisPrediction {
    /// Number of evaluation poses.
    pub poses: usize,
    /// RMS over the poses of the axis direction's standard deviation, arcsec.
    pub rms_arcsec: f64,
    /// Largest over the poses, arcsec.
    pub max_arcsec: f64,
    /// The held parameters' share of `rms_arcsec`, arcsec.
    pub held_rms_arcsec: f64,
    /// Held parameters whose invisible combination, at typical size, turns
    /// the axis by [`HARMLESS_AXIS_ARCSEC`] or more.
    pub held_moving_axis: Vec<String>,
}

/// An invisible combination that turns the tool axis by less than this, at
/// typical size, is not named as moving it, arcsec.
pub const HARMLESS_AXIS_ARCSEC: f64 = 5.0;

/// The extension along the tool over which the axis is differentiated, mm
/// (the axis' Jacobian is exact for any length: the extension runs along
/// the actual tool axis).
const AXIS_LEVER_MM: f64 = 100.0;

/// The fused identifiability report (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FusionReport {
    /// The union of every source.
    pub union: IdentifiabilityReport,
    /// Each source alone.
    pub sources: Vec<SourceVisibility>,
    /// What each external source adds to the internal data.
    pub made_visible: Vec<MadeVisible>,
    /// Named quantities, per source and in the union.
    pub named: Vec<NamedQuantity>,
    /// Tool-tip impact of the weak combinations of the union and of the
    /// internal data alone.
    pub weak: Vec<TipImpact>,
    /// Tool-tip impact of the union's invisible combinations.
    pub invisible: Vec<TipImpact>,
    /// The tool tip's predicted uncertainty.
    pub tool_tip: ToolTipPrediction,
    /// The tool axis' predicted uncertainty.
    pub tool_axis: ToolAxisPrediction,
}

/// A reduced problem's rank decision and the covariance of its global
/// parameters (basic solution: held parameters zero).
struct Decided {
    decision: RankDecision,
    covariance: DMatrix<f64>,
    report: IdentifiabilityReport,
}

fn decide(
    names: &[String],
    typical: &[f64],
    problem: &ReducedProblem,
    records: usize,
    options: &FusionOptions,
) -> Result<Decided, IdentError> {
    let decision = problem
        .decide_weighted(options.rank_tolerance, Some(typical))
        .ok_or(IdentError::Numerical("SVD did not converge"))?;
    let solution = problem.solve(&decision);
    let nn = problem.n_nuisance;
    let k = problem.k;
    let report = IdentifiabilityReport::new(
        names,
        &decision,
        &solution,
        nn,
        problem.rows,
        records,
        options.weak_threshold,
    );
    Ok(Decided {
        covariance: DMatrix::from_fn(k, k, |a, b| solution.covariance[(nn + a, nn + b)]),
        decision,
        report,
    })
}

/// Standard deviation of `c . p` under a decision, or `None` when `c` is
/// not orthogonal to the null space (the data cannot see it).
fn functional_std(decision: &RankDecision, covariance: &DMatrix<f64>, c: &[f64]) -> Option<f64> {
    // In the column-scaled coordinates of the rank decision, where the
    // comparison does not depend on units: c / scale against n * scale.
    let scale = &decision.column_scale;
    let norm = |v: &mut dyn Iterator<Item = f64>| v.map(|x| x * x).sum::<f64>().sqrt();
    let c_norm = norm(&mut c.iter().zip(scale).map(|(a, s)| a / s));
    for n in decision.null_space_basis() {
        let dot: f64 = c.iter().zip(&n).map(|(a, b)| a * b).sum();
        let n_norm = norm(&mut n.iter().zip(scale).map(|(a, s)| a * s));
        if dot.abs() > 1e-6 * c_norm * n_norm {
            return None;
        }
    }
    let v = DVector::from_column_slice(c);
    Some((v.transpose() * covariance * &v)[(0, 0)].max(0.0).sqrt())
}

/// Per evaluation pose, a `3 x k` Jacobian.
type PoseJacobians = Vec<DMatrix<f64>>;

/// The tool tip's and the tool axis' Jacobians over the evaluation poses
/// at `p` (3 x k each; the axis' in rad per unit).
fn tip_and_axis_jacobians(
    model: &FusedModel,
    p: &[f64],
    options: &FusionOptions,
) -> Result<(PoseJacobians, PoseJacobians), IdentError> {
    let lever = Effector {
        extension_mm: AXIS_LEVER_MM,
        ..Effector::default()
    };
    let jacobians = model
        .spindle_jacobians(p, &options.eval_poses, &[Effector::default(), lever])
        .map_err(|e| match e {
            IdentError::Kinematics { pose, source, .. } => {
                IdentError::Invalid(format!("evaluation pose {}: {source}", pose + 1))
            }
            e => e,
        })?;
    Ok(jacobians
        .into_iter()
        .map(|mut g| {
            let g1 = g.pop().unwrap_or_default();
            let g0 = g.pop().unwrap_or_default();
            let axis = (g1 - &g0) / AXIS_LEVER_MM;
            (g0, axis)
        })
        .unzip())
}

/// `(raw, after touch-off)` RMS over the poses of `G_e v`, in the units of
/// `G v` (mm).
fn impact(g: &[DMatrix<f64>], mean: &DMatrix<f64>, v: &[f64]) -> (f64, f64) {
    let v = DVector::from_column_slice(v);
    let n = g.len().max(1) as f64;
    let centre = mean * &v;
    let (mut raw, mut touched) = (0.0, 0.0);
    for ge in g {
        let d = ge * &v;
        raw += d.norm_squared();
        touched += (d - &centre).norm_squared();
    }
    ((raw / n).sqrt(), (touched / n).sqrt())
}

/// The Jacobians `G_e` (3 x k each) stacked into one `3E x k` matrix,
/// each centred on `mean` when given (after touch-off).
fn stacked(g: &[DMatrix<f64>], mean: Option<&DMatrix<f64>>) -> DMatrix<f64> {
    let k = g.first().map_or(0, |x| x.ncols());
    DMatrix::from_fn(3 * g.len(), k, |r, c| {
        g[r / 3][(r % 3, c)] - mean.map_or(0.0, |m| m[(r % 3, c)])
    })
}

/// RMS and largest over the poses of `sqrt(tr(G_e C G_e^T))` for the
/// stacked Jacobians `g` ([`stacked`]): one matrix product.
fn spread(g: &DMatrix<f64>, c: &DMatrix<f64>) -> (f64, f64) {
    let gc = g * c;
    let poses = g.nrows() / 3;
    let (mut sum, mut max) = (0.0f64, 0.0f64);
    for e in 0..poses {
        let a: f64 = (3 * e..3 * e + 3)
            .map(|r| gc.row(r).dot(&g.row(r)))
            .sum::<f64>()
            .max(0.0);
        sum += a;
        max = max.max(a.sqrt());
    }
    ((sum / poses.max(1) as f64).sqrt(), max)
}

/// The tool's roll about its own axis, which the head's 13 parameters do
/// not carry (a point on the tool sees none of it), at its typical size, as
/// tool-tip combinations: one per source that measures a point at a stated
/// offset `o` from the tip (a known tracker target, a ballbar's ball). The
/// point turns with the roll by `roll (d x o)`, constant in the spindle
/// frame, which the fit reads as a tool-tip shift: the tip keeps it. The
/// typical roll is a second-axis tilt's (`ax2_tilt_a_rad`): a real head's
/// second axis tilted along the axes' common normal turns the tool about the
/// first axis, which at zero angles is the tool's (the 13 parameters take
/// it as an `h1` zero and a tip shift, exact for points on the tool).
fn roll_combinations(model: &FusedModel, sources: &[Source]) -> Vec<DVector<f64>> {
    let (Some(head), Some(first)) = (model.head(), model.head_range().next()) else {
        return Vec::new();
    };
    let k = model.len();
    let typical = model.typical_sizes();
    let column = |name: &str| model.index_of(name);
    let (Some(tilt), Some(length), Some(shift_e), Some(shift_w)) = (
        column("ax2_tilt_a_rad"),
        column("tool_length_mm"),
        column("tool_shift_e_mm"),
        column("tool_shift_w_mm"),
    ) else {
        return Vec::new();
    };
    // The tool frame `d, e, w` (spindle frame at zero head angles): the
    // tip's derivatives with respect to the tool's three shifts, turned
    // back by the spindle's rotation.
    let h = [0.0, 0.0];
    let at = head.at(&vec![0.0; head.len()]);
    let (_, jac) = at.point_jacobian(h, &Effector::default());
    let back = at.spindle_rotation(h).transpose();
    let frame = [length, shift_e, shift_w].map(|j| back * jac.column(j - first));
    let d = frame[0];
    sources
        .iter()
        .filter_map(Source::stated_offset_mm)
        .map(|o| {
            let turn = d.cross(&o) * typical[tilt];
            let mut n = DVector::zeros(k);
            for (j, f) in [length, shift_e, shift_w].into_iter().zip(&frame) {
                n[j] = f.dot(&turn);
            }
            n
        })
        .collect()
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn build_report(
    model: &FusedModel,
    sources: &[Source],
    start_parts: &[ReducedProblem],
    union_decision: &RankDecision,
    union_report: IdentifiabilityReport,
    estimate: &[f64],
    covariance: &DMatrix<f64>,
    options: &FusionOptions,
) -> Result<(FusionReport, Vec<String>), IdentError> {
    let names = model.names();
    let k = names.len();
    let typical = model.typical_sizes();
    let alone: Vec<Decided> = sources
        .iter()
        .zip(start_parts)
        .map(|(s, part)| decide(names, &typical, part, s.records(), options))
        .collect::<Result<_, _>>()?;
    let internal = sources
        .iter()
        .position(|s| s.kind() == SourceKind::Internal);

    let mut made_visible = Vec::new();
    if let Some(i) = internal {
        for (s, source) in sources.iter().enumerate() {
            if s == i {
                continue;
            }
            let both = ReducedProblem::merge(&[&start_parts[i], &start_parts[s]]);
            let d = decide(
                names,
                &typical,
                &both,
                sources[i].records() + source.records(),
                options,
            )?;
            made_visible.push(MadeVisible {
                label: source.label().to_string(),
                internal_rank: alone[i].decision.rank,
                rank_with_internal: d.decision.rank,
                parameters: alone[i]
                    .decision
                    .fixed
                    .iter()
                    .filter(|j| d.decision.identifiable.contains(j))
                    .map(|&j| names[j].clone())
                    .collect(),
            });
        }
    }

    let mut functionals: Vec<(String, Vec<f64>)> = Vec::new();
    let dq: Vec<usize> = ["dq1", "dq2", "dq3"]
        .iter()
        .filter_map(|n| model.index_of(n))
        .collect();
    if dq.len() == 3 {
        let mut c = vec![0.0; k];
        dq.iter().for_each(|&j| c[j] = 1.0);
        functionals.push(("dq1 + dq2 + dq3".into(), c));
    }
    for j in model.effect_range().chain(model.head_range()) {
        let mut c = vec![0.0; k];
        c[j] = 1.0;
        functionals.push((names[j].clone(), c));
    }
    let named = functionals
        .into_iter()
        .map(|(name, c)| {
            let per: Vec<Option<f64>> = alone
                .iter()
                .map(|d| functional_std(&d.decision, &d.covariance, &c))
                .collect();
            let union = functional_std(union_decision, covariance, &c);
            let labels: Vec<String> = sources.iter().map(|s| s.label().to_string()).collect();
            let gain = internal.and_then(|i| per[i]).zip(union).map(|(a, b)| a / b);
            NamedQuantity {
                name,
                std_dev: NamedValues::new(&labels, &per),
                union,
                gain,
            }
        })
        .collect();

    // At the estimate; a wild estimate whose machine cannot reach an
    // evaluation pose is judged at the nominal machine instead (and said so).
    let mut warnings = Vec::new();
    let (g, ga) = match tip_and_axis_jacobians(model, estimate, options) {
        Ok(g) => g,
        Err(e) => {
            warnings.push(format!(
                "the fitted machine cannot reach every evaluation pose ({e}): the estimate is far from the nominal machine; the predictions are taken at the nominal machine"
            ));
            tip_and_axis_jacobians(model, &vec![0.0; k], options)?
        }
    };
    let n_poses = g.len().max(1) as f64;
    let mean = g.iter().fold(DMatrix::zeros(3, k), |a, b| a + b) / n_poses;
    let axis_mean = DMatrix::zeros(3, k);
    let harmless = |touch_off_um: f64| touch_off_um < options.harmless_um;
    let mut weak = Vec::new();
    let mut scopes: Vec<(String, &RankDecision, &IdentifiabilityReport)> =
        vec![("union".to_string(), union_decision, &union_report)];
    if let Some(i) = internal
        && sources.len() > 1
    {
        scopes.push((
            sources[i].label().to_string(),
            &alone[i].decision,
            &alone[i].report,
        ));
    }
    for (scope, d, report) in &scopes {
        let top = d.singular_values.first().copied().unwrap_or(0.0);
        for i in 0..d.rank {
            let s = d.singular_values[i];
            if s >= report.weak_threshold * top {
                continue;
            }
            let v: Vec<f64> = d.direction(i).iter().map(|x| x / s).collect();
            let (raw, touched) = impact(&g, &mean, &v);
            let (axis, _) = impact(&ga, &axis_mean, &v);
            weak.push(TipImpact {
                scope: scope.clone(),
                combination: combination(names, &v, s, None),
                per_std_dev: true,
                raw_um: 1e3 * raw,
                touch_off_um: 1e3 * touched,
                axis_arcsec: axis / RAD_PER_ARCSEC,
                harmless: harmless(1e3 * touched),
            });
        }
    }
    let null = union_decision.null_space_basis();
    let invisible: Vec<TipImpact> = null
        .iter()
        .zip(&union_decision.singular_values[union_decision.rank..])
        .map(|(v, s)| {
            let largest = v
                .iter()
                .zip(&typical)
                .fold(0.0f64, |a, (b, t)| a.max((b / t).abs()));
            let unit: Vec<f64> = v.iter().map(|x| x / largest).collect();
            let (raw, touched) = impact(&g, &mean, &unit);
            let (axis, _) = impact(&ga, &axis_mean, &unit);
            TipImpact {
                scope: "union".into(),
                combination: combination(names, v, *s, None),
                per_std_dev: false,
                raw_um: 1e3 * raw,
                touch_off_um: 1e3 * touched,
                axis_arcsec: axis / RAD_PER_ARCSEC,
                harmless: harmless(1e3 * touched),
            }
        })
        .collect();

    // The held parameters at their typical sizes: the basic solution holds
    // each at zero, so the machine keeps its true value along the
    // parameter's invisible combination (vector f moves held parameter f by
    // one and the rest so that no source sees it).
    let mut held_cov = DMatrix::zeros(k, k);
    for (v, &f) in null.iter().zip(&union_decision.fixed) {
        let n = DVector::from_column_slice(v) * typical[f];
        held_cov += &n * n.transpose();
    }
    for n in roll_combinations(model, sources) {
        held_cov += &n * n.transpose();
    }
    let total = covariance + &held_cov;
    let (raw, touched, axis) = (
        stacked(&g, None),
        stacked(&g, Some(&mean)),
        stacked(&ga, None),
    );
    let (raw_rms, raw_max) = spread(&raw, &total);
    let (touched_rms, touched_max) = spread(&touched, &total);
    let (held_raw, _) = spread(&raw, &held_cov);
    let (held_touched, _) = spread(&touched, &held_cov);
    let (axis_rms, axis_max) = spread(&axis, &total);
    let (held_axis, _) = spread(&axis, &held_cov);
    // A held parameter leaves the tip (the axis) uncalibrated when its
    // invisible combination, at typical size, moves the tip more than is
    // harmless (turns the axis by HARMLESS_AXIS_ARCSEC or more).
    let held_moving = |keep: &dyn Fn(&TipImpact) -> bool| -> Vec<String> {
        union_decision
            .fixed
            .iter()
            .zip(&invisible)
            .filter(|(_, t)| keep(t))
            .map(|(&j, _)| names[j].clone())
            .collect()
    };
    let held_moving_tip = held_moving(&|t| t.raw_um >= options.harmless_um);
    let held_moving_axis = held_moving(&|t| t.axis_arcsec >= HARMLESS_AXIS_ARCSEC);
    Ok((
        FusionReport {
            union: union_report,
            sources: sources
                .iter()
                .zip(alone)
                .map(|(s, d)| SourceVisibility {
                    label: s.label().to_string(),
                    report: d.report,
                })
                .collect(),
            made_visible,
            named,
            weak,
            invisible,
            tool_tip: ToolTipPrediction {
                poses: g.len(),
                raw_rms_um: 1e3 * raw_rms,
                raw_max_um: 1e3 * raw_max,
                touch_off_rms_um: 1e3 * touched_rms,
                touch_off_max_um: 1e3 * touched_max,
                held_raw_rms_um: 1e3 * held_raw,
                held_touch_off_rms_um: 1e3 * held_touched,
                held_moving_tip,
            },
            tool_axis: ToolAxisPrediction {
                poses: ga.len(),
                rms_arcsec: axis_rms / RAD_PER_ARCSEC,
                max_arcsec: axis_max / RAD_PER_ARCSEC,
                held_rms_arcsec: held_axis / RAD_PER_ARCSEC,
                held_moving_axis,
            },
        },
        warnings,
    ))
}

impl FusionReport {
    /// Warnings a user must read: held parameters that move the tool tip,
    /// and a tool axis predicted above `axis_arcsec`.
    pub fn warnings(&self, axis_arcsec: f64) -> Vec<String> {
        let mut out = Vec::new();
        let held = &self.tool_tip.held_moving_tip;
        if !held.is_empty() {
            out.push(format!(
                "the tool tip is not calibrated in every direction: {} held at nominal (no source sees {}); the predicted tool-tip uncertainty includes {} at typical size ({:.1} um raw, {:.1} um after touch-off)",
                held.join(", "),
                if held.len() == 1 { "it" } else { "them" },
                if held.len() == 1 { "it" } else { "them" },
                self.tool_tip.held_raw_rms_um,
                self.tool_tip.held_touch_off_rms_um
            ));
        }
        let a = &self.tool_axis;
        if a.rms_arcsec > axis_arcsec {
            let held = if a.held_moving_axis.is_empty() {
                String::new()
            } else {
                format!(
                    " ({} held at nominal: {:.0} arcsec of it)",
                    a.held_moving_axis.join(", "),
                    a.held_rms_arcsec
                )
            };
            out.push(format!(
                "the tool axis is predicted to {:.0} arcsec rms (max {:.0}), above {axis_arcsec} arcsec{held}: tool-tip data do not calibrate the tool's direction; measure a tracker target at two known extensions along the tool (column `extension_mm`, e.g. 0 and 100 mm: a tracker plan with extensions 0,100)",
                a.rms_arcsec, a.max_arcsec
            ));
        }
        out
    }

    /// The report as JSON (`union`, `per_source`, `made_visible`, `named`,
    /// `weak`, `invisible`, `tool_tip`, `tool_axis`).
    pub fn to_json(&self) -> Value {
        let mut v = serde_json::to_value(self).unwrap_or(Value::Null);
        if let Value::Object(o) = &mut v
            && let Some(s) = o.remove("sources")
        {
            o.insert("per_source".into(), s);
        }
        v
    }

    /// A human-readable summary.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let ranks: Vec<String> = self
            .sources
            .iter()
            .map(|v| format!("{} {}/{}", v.label, v.report.rank, v.report.n_params))
            .collect();
        s.push_str(&format!(
            "rank: {}, union {}/{} (tolerance {:.0e})\n",
            ranks.join(", "),
            self.union.rank,
            self.union.n_params,
            self.union.rank_tolerance
        ));
        for m in &self.made_visible {
            s.push_str(&format!(
                "made visible by {} (internal rank {} -> {}): {}\n",
                m.label,
                m.internal_rank,
                m.rank_with_internal,
                if m.parameters.is_empty() {
                    "nothing".to_string()
                } else {
                    m.parameters.join(" ")
                }
            ));
        }
        if !self.invisible.is_empty() {
            s.push_str(
                "still invisible (held at the prior), tool-tip impact at the parameters' typical size:\n",
            );
            for t in &self.invisible {
                s.push_str(&format!(
                    "  {}   raw {:.1} um, after touch-off {:.1} um, axis {:.1} arcsec{}\n",
                    t.combination.to_text(),
                    t.raw_um,
                    t.touch_off_um,
                    t.axis_arcsec,
                    match (t.harmless, t.axis_arcsec >= HARMLESS_AXIS_ARCSEC) {
                        (true, false) => ": harmless",
                        (true, true) => ": harmless to the tip, not to the tool axis",
                        _ => "",
                    }
                ));
            }
        }
        if !self.weak.is_empty() {
            s.push_str("weak combinations, tool-tip impact per standard deviation:\n");
            for t in &self.weak {
                s.push_str(&format!(
                    "  [{}] {}\n      raw {:.1} um, after touch-off {:.1} um, axis {:.1} arcsec{}\n",
                    t.scope,
                    t.combination.to_text(),
                    t.raw_um,
                    t.touch_off_um,
                    t.axis_arcsec,
                    if t.harmless {
                        ": nearly harmless to the tool tip"
                    } else {
                        ""
                    }
                ));
            }
        }
        if !self.named.is_empty() {
            let labels: Vec<&str> = self.sources.iter().map(|v| v.label.as_str()).collect();
            s.push_str(&format!(
                "standard deviations ({} | union; - = invisible):\n",
                labels.join(" | ")
            ));
            let show = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.3e}"));
            for q in &self.named {
                let per: Vec<String> = q.std_dev.0.iter().map(|(_, v)| show(*v)).collect();
                s.push_str(&format!(
                    "  {:<34} {} | {}\n",
                    q.name,
                    per.join(" | "),
                    show(q.union)
                ));
            }
        }
        let t = &self.tool_tip;
        s.push_str(&format!(
            "predicted tool tip ({} poses): raw rms {:.1} um (max {:.1}), after touch-off rms {:.1} um (max {:.1}); held parameters at typical size: {:.1} um raw, {:.1} um after touch-off\n",
            t.poses,
            t.raw_rms_um,
            t.raw_max_um,
            t.touch_off_rms_um,
            t.touch_off_max_um,
            t.held_raw_rms_um,
            t.held_touch_off_rms_um
        ));
        let a = &self.tool_axis;
        s.push_str(&format!(
            "predicted tool axis ({} poses): rms {:.1} arcsec (max {:.1}); held parameters at typical size: {:.1} arcsec\n",
            a.poses, a.rms_arcsec, a.max_arcsec, a.held_rms_arcsec
        ));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fusion::{TrackerOptions, TrackerTarget};
    use tricept_kinematics::Machine;
    use tricept_model::ParameterSet;

    /// Three tracker points whose target is stated at `offset_mm`.
    fn tracker(offset_mm: [f64; 3]) -> Source {
        let csv = "q1,q2,q3,h1,h2,x,y,z\n800,800,800,0,0,1,2,3\n810,800,800,0,0,1,5,3\n800,820,800,0,0,4,2,3\n";
        let data = tricept_data::external::read_external_from(csv.as_bytes(), "t.csv").unwrap();
        let options = TrackerOptions {
            sigma_um: 10.0,
            target: TrackerTarget::Known {
                offset_mm,
                sigma_um: 5.0,
            },
        };
        Source::tracker(&data, &options).unwrap()
    }

    #[test]
    fn a_stated_offset_across_the_tool_turns_with_its_roll() {
        // The Table 1 machine's head (fixtures/machines/tricept-paper.json):
        // the tool along z' at zero angles, the second axis along x', so the
        // tool frame is d = z', e = x', w = y'. A target at o = (16, -6, 10) mm turns by
        // r (d x o) = r (6, 16, 0): a tip shift of 6 r along e and 16 r
        // along w, at the typical axis tilt r = 0.3 mrad.
        let model = FusedModel::new(Machine::paper(), ParameterSet::paper15(), &[], true).unwrap();
        let rolls = roll_combinations(&model, &[tracker([16.0, -6.0, 10.0])]);
        assert_eq!(rolls.len(), 1);
        let at = |name: &str| rolls[0][model.index_of(name).unwrap()];
        assert!(
            (at("tool_shift_e_mm") - 6.0 * 3e-4).abs() < 1e-12,
            "{}",
            rolls[0]
        );
        assert!(
            (at("tool_shift_w_mm") - 16.0 * 3e-4).abs() < 1e-12,
            "{}",
            rolls[0]
        );
        assert!(at("tool_length_mm").abs() < 1e-12);
        let others: f64 = rolls[0].iter().map(|v| v * v).sum::<f64>()
            - at("tool_shift_e_mm").powi(2)
            - at("tool_shift_w_mm").powi(2);
        assert!(others.abs() < 1e-20);
        // Along the tool the roll moves nothing; a target at the tip and a
        // free one have no stated offset; a nominal head has no roll.
        let along = roll_combinations(&model, &[tracker([0.0, 0.0, 20.0])]);
        assert!(along[0].norm() < 1e-12);
        assert!(roll_combinations(&model, &[tracker([0.0; 3])]).is_empty());
        let nominal =
            FusedModel::new(Machine::paper(), ParameterSet::paper15(), &[], false).unwrap();
        assert!(roll_combinations(&nominal, &[tracker([16.0, -6.0, 10.0])]).is_empty());
    }
}
