//! The diagnosis' model deployed into a machine file: the terms of the
//! final model worth deploying ([`crate::report::ModelTerm::deployed`]) refitted on
//! the poses the diagnosis kept, so that the geometry is de-biased by
//! every one of them, generic terms included, and every fitted parameter
//! put where the registry says it goes
//! ([`tricept_model::effects::EffectSpec::deployment`],
//! [`tricept_model::effects::GenericSpec::deployment`]): the machine's
//! leg effects, its UP limb, the controller parameters, the per-leg
//! compensation tables of the leg errors that are functions of the leg
//! command (a ball-screw pitch error, a curved screw, a worn segment), or, for
//! sensor-side and time terms, only the calibration record.

use std::sync::Arc;

use tricept_data::{Dataset, MeasuredPose};
use tricept_engine::{Identification, IdentifyOptions, identify, model::GeometricModel};
use tricept_kinematics::Machine;
use tricept_kinematics::description::{
    ControllerDescription, LegTableDescription, MAX_TABLE_POINTS, MAX_TABLE_SLOPE_UM_PER_MM,
};
use tricept_model::ParameterSet;
use tricept_model::effects::{Basis, CHANNELS, CauseName, Deployment, GenericFamily};

use crate::error::DeployError;
use crate::model::ExtendedModel;
use crate::report::{Diagnosis, ModelTerm};
use crate::terms::{Frame, GenericTerm, Scope, Term};

/// The deployable model of a diagnosis, refitted on its clean poses for
/// the record's offsets, covariance and fit quality.
#[derive(Debug, Clone)]
pub struct Deployed {
    /// The deployed model's identification (its names: the geometric
    /// parameters, then each term's `effect.parameter`).
    pub id: Identification,
    /// The calibrated machine: geometry, class-2 effects, leg effects and
    /// compensation tables. Its own kinematics ignore the leg effects it
    /// carries: command it through
    /// [`ExtendedMachine`](tricept_model::ExtendedMachine), which applies
    /// them (the door's `kinematics::Machine`).
    pub geometry: Machine,
    /// The controller parameters of the dynamic effects, when any is named.
    pub controller: Option<ControllerDescription>,
    /// What the machine file applies, one line per term (where it goes).
    pub applied: Vec<String>,
    /// What it only records: sensor corrections, time terms, and the terms
    /// seen but not worth deploying, one line each.
    pub recorded: Vec<String>,
    /// The deployed model `id` was fitted with.
    pub model: ExtendedModel,
    /// The poses it was fitted on.
    pub clean: Dataset,
}

/// Fits the diagnosis' deployed model (the terms of the final model worth
/// deploying, [`Diagnosis::model_terms`], on the geometric model) on the
/// poses it kept, with the rank decision of `rank_reference` when
/// `nominal` is itself calibrated, and puts every parameter where it goes
/// in a machine file: the effects of the vocabulary as their specs say,
/// the generic leg terms that are functions of the leg command as per-leg
/// compensation tables (linear interpolation over the campaign's stroke of
/// each leg, the end values beyond it), the reading terms as sensor
/// corrections and the legs' drift as a time term, both recorded only.
///
/// # Example
/// ```
/// use tricept_diagnose::{DiagnoseOptions, deploy, diagnose};
/// use tricept_kinematics::Machine;
/// use tricept_model::ExtendedMachine;
/// let nominal = Machine::paper();
/// let data = tricept_data::read_path("../../fixtures/data/diagnose-hidden-effect.csv".as_ref()).unwrap();
/// let d = diagnose(&nominal, &data, &DiagnoseOptions::for_machine(&nominal)).unwrap();
/// assert!(d.final_adequate);
/// let deployed = deploy(&nominal, None, &data, &d).unwrap();
/// // The compliance the diagnosis named is in the machine's leg effects
/// // (the file was simulated with 33.6 N/um at 1 m: 29.8 um/kN).
/// let c = deployed.geometry.leg_effects.compliance_um_per_kn_at_1m;
/// assert!((c - 1000.0 / 33.6).abs() < 2.0, "{c}");
/// // The calibrated machine with its leg effects, ready for IK.
/// let machine = ExtendedMachine::new(deployed.geometry);
/// let q = machine.inverse(&nalgebra::Vector3::new(0.0, 0.0, 750.0)).unwrap().legs_mm;
/// assert!(q.iter().all(|q| (q - 773.4).abs() < 1.0));
/// ```
pub fn deploy(
    nominal: &Machine,
    rank_reference: Option<&Machine>,
    data: &Dataset,
    diagnosis: &Diagnosis,
) -> Result<Deployed, DeployError> {
    let flagged = diagnosis.outlier_lines();
    let clean = data.subset(|j| !flagged.contains(&data.poses[j].line));
    let frame = Arc::new(Frame::of(nominal, data));
    let mut recorded = Vec::new();
    let mut terms = Vec::new();
    for t in &diagnosis.model_terms {
        match (t.deployed, term_of(t)) {
            (true, Some(term)) => terms.push(term),
            (false, _) => recorded.push(format!(
                "{}: seen, not worth deploying (out-of-sample benefit {} mm, improvement {} mm, expected rms {} mm with it, {} mm without); kept back because {}; not in the deployed model",
                t.description,
                plus_minus(t.holdout_benefit_mm, t.holdout_benefit_sd_mm),
                plus_minus(t.improvement_mm, t.improvement_sd_mm),
                number(t.expected_rms_with_mm),
                number(t.expected_rms_without_mm),
                t.kept_back_because.as_deref().unwrap_or("the deploy rule"),
            )),
            (true, None) => return Err(DeployError::NotDeployable(t.description.clone())),
        }
    }
    let mut geometric = GeometricModel::new(nominal.clone(), ParameterSet::paper15());
    if let Some(reference) = rank_reference {
        geometric = geometric.with_rank_reference(reference.clone());
    }
    let model = ExtendedModel::with_terms(geometric, &terms, frame.clone());
    let id = identify(&model, &clean, &IdentifyOptions::for_machine(nominal))?;
    let mut machine = model.machine_at(&id.estimate);
    let mut controller: Option<ControllerDescription> = None;
    let mut applied = Vec::new();
    for (term, at) in terms.iter().zip(model.offsets()) {
        match term {
            Term::Catalogue(e) => {
                for index in 0..e.parameter_count() {
                    let name = id.names.get(at + index).map_or("", String::as_str);
                    let value = id.estimate.get(at + index).copied().unwrap_or(f64::NAN);
                    if !e.deploy(index, value, &mut machine, &mut controller) {
                        return Err(DeployError::NotDeployable(name.to_string()));
                    }
                }
                let line = format!("{e}: {}", e.spec().deployment.label());
                match e.spec().deployment {
                    Deployment::Sensor => recorded.push(line),
                    _ => applied.push(line),
                }
            }
            Term::Generic(g) => match g.family.spec().deployment {
                Deployment::LegTable => {}
                Deployment::Sensor => recorded.push(format!(
                    "{}: a sensor correction of the {} reading (calibration.effects); it changes the readings, not where the platform goes",
                    g.label(),
                    CHANNELS[g.channel().unwrap_or(0)]
                )),
                _ => recorded.push(format!(
                    "{}: a time term, recorded under calibration.effects, not applied: the geometry is the machine's at the campaign's middle{}",
                    g.label(),
                    frame
                        .order
                        .filter(|o| o.uses_time)
                        .map_or(String::new(), |o| format!(
                            " (time_s {:.0})",
                            0.5 * (o.first + o.last)
                        ))
                )),
            },
        }
    }
    let tables = leg_tables(&model, &id.estimate, &frame, nominal, &machine)?;
    for t in &tables {
        applied.push(format!("leg {} compensation table: {}", t.leg, t.source));
    }
    for t in tables {
        machine.leg_effects.tables.retain(|old| old.leg != t.leg);
        machine.leg_effects.tables.push(t);
    }
    machine.leg_effects.tables.sort_by_key(|t| t.leg);
    Ok(Deployed {
        id,
        geometry: machine,
        controller,
        applied,
        recorded,
        model,
        clean,
    })
}

/// `value +- sd`, or "not computed".
fn plus_minus(value: Option<f64>, sd: Option<f64>) -> String {
    match (value, sd) {
        (Some(v), Some(sd)) => format!("{v:.4} +- {sd:.4}"),
        _ => "not computed".into(),
    }
}

/// `value` for a record line (mm, 4 decimals), or "not computed".
fn number(value: Option<f64>) -> String {
    value.map_or_else(|| "not computed".into(), |v| format!("{v:.4}"))
}

/// The term of a model term of the report.
fn term_of(t: &ModelTerm) -> Option<Term> {
    match t.effect {
        CauseName::Catalogue(e) => Some(Term::Catalogue(e)),
        CauseName::Generic(family) => {
            let scope = match (t.legs.as_slice(), t.channel) {
                ([leg], None) => Scope::Leg(leg.checked_sub(1)?),
                ([1, 2, 3], None) => Scope::AllLegs,
                ([], Some(c)) => Scope::Channel(c),
                _ => return None,
            };
            Some(Term::Generic(GenericTerm {
                family,
                scope,
                period_mm: t.period_mm,
                edges_mm: t.edges_mm,
            }))
        }
    }
}

/// Points per period of the finest periodic term in a table: linear
/// interpolation then misses a sine of amplitude `A` by at most
/// `A (pi / 24)^2 / 2`, 0.9 % of `A` (0.03 um for a 4 um pitch error).
const POINTS_PER_PERIOD: f64 = 24.0;

/// Points of a table without a periodic term (a polynomial over the
/// stroke).
const POINTS_OVER_STROKE: f64 = 200.0;

/// The finest spacing of a table with a step, mm: linear interpolation
/// ramps a step over the one spacing that holds its edge and is exact
/// elsewhere; finer than the edge is known (about a millimetre at 80
/// poses over a 400 mm stroke) helps nothing.
const STEP_SPACING_MM: f64 = 0.05;

/// The share of [`MAX_TABLE_SLOPE_UM_PER_MM`] a step's ramp may take (the
/// rest is left to the table's other terms).
const STEP_SLOPE_SHARE: f64 = 0.5;

/// The compensation table of each leg that a generic leg term of the
/// model (at parameters `p`) acts on: its extra length at equally spaced
/// commands over the campaign's stroke of the leg, the sum of every such
/// term, plus the table `machine` already has for the leg (a calibrated
/// nominal's).
fn leg_tables(
    model: &ExtendedModel,
    p: &[f64],
    frame: &Frame,
    nominal: &Machine,
    machine: &Machine,
) -> Result<Vec<LegTableDescription>, DeployError> {
    let mut out = Vec::new();
    for leg in 0..3 {
        let on_leg: Vec<(&GenericTerm, usize)> = model
            .terms()
            .iter()
            .zip(model.offsets())
            .filter_map(|(t, at)| match t {
                Term::Generic(g)
                    if matches!(g.family.spec().deployment, Deployment::LegTable)
                        && g.legs().contains(&leg) =>
                {
                    Some((g, at))
                }
                _ => None,
            })
            .collect();
        if on_leg.is_empty() {
            continue;
        }
        let [lo, hi] = frame.leg_range_mm[leg];
        let stroke = hi - lo;
        let finest = on_leg
            .iter()
            .filter_map(|(g, _)| g.period_mm)
            .fold(f64::INFINITY, f64::min);
        // A step's ramp: one spacing, no steeper than its share of the
        // slope a table may have.
        let edges: Vec<(f64, f64)> = on_leg
            .iter()
            .filter_map(|(g, at)| {
                let [a, b] = g.edges_mm?;
                let um = p.get(*at).copied().unwrap_or(0.0);
                Some([(a, um), (b, um)])
            })
            .flatten()
            .filter(|(e, _)| *e > lo && *e < hi)
            .collect();
        let ramp = edges
            .iter()
            .map(|(_, um)| {
                STEP_SPACING_MM.max(um.abs() / (STEP_SLOPE_SHARE * MAX_TABLE_SLOPE_UM_PER_MM))
            })
            .fold(f64::INFINITY, f64::min);
        let step = (finest / POINTS_PER_PERIOD)
            .min(stroke / POINTS_OVER_STROKE)
            .min(ramp);
        let points = (stroke / step).ceil() + 1.0;
        if !(stroke > 0.0 && points.is_finite() && points <= MAX_TABLE_POINTS as f64) {
            return Err(DeployError::NotDeployable(format!(
                "leg {}'s compensation table: {points} points over the campaign's stroke of {stroke} mm (2 to {MAX_TABLE_POINTS})",
                leg + 1
            )));
        }
        let points = points as usize;
        let step = stroke / (points - 1) as f64;
        let extra_um = |q: f64| -> Result<f64, DeployError> {
            let pose = MeasuredPose {
                commands_mm: [q; 3],
                // The default's: no approach direction, time or temperature.
                ..Default::default()
            };
            let mut mm = machine.leg_effects.table_extra_mm(&pose.commands_mm)[leg];
            for (g, at) in &on_leg {
                for (k, basis, v) in Term::Generic(**g)
                    .leg_entries(frame, nominal, &pose)
                    .map_err(|e| {
                        DeployError::NotDeployable(format!("leg {} table: {e}", leg + 1))
                    })?
                {
                    if basis == Basis::Leg(leg) {
                        mm += p.get(at + k).copied().unwrap_or(0.0) * v;
                    }
                }
            }
            Ok(mm * 1e3)
        };
        let values = (0..points)
            .map(|k| extra_um(lo + step * k as f64))
            .collect::<Result<Vec<f64>, _>>()?;
        let mut table = LegTableDescription::new(leg as u8 + 1, lo, step, values);
        // The interpolation error, measured at the midpoints away from a
        // step's edges, and on both sides of each edge (where it is
        // largest: the table ramps over the spacing that holds the edge).
        let error = |q: f64| -> Result<f64, DeployError> {
            Ok((table.extra_mm(q) * 1e3 - extra_um(q)?).abs())
        };
        let mut worst: f64 = 0.0;
        for k in 0..points - 1 {
            let (from, to) = (lo + step * k as f64, lo + step * (k + 1) as f64);
            if edges.iter().any(|(e, _)| (from..=to).contains(e)) {
                continue;
            }
            worst = worst.max(error(0.5 * (from + to))?);
        }
        // Beside an edge: at the neighbouring numbers on either side, the
        // one-sided limits of the error (the table is continuous there).
        let mut at_edges: f64 = 0.0;
        for (e, _) in &edges {
            for q in [e.next_down(), e.next_up()] {
                at_edges = at_edges.max(error(q)?);
            }
        }
        let names: Vec<String> = on_leg.iter().map(|(g, _)| g.label()).collect();
        let periodic = on_leg
            .iter()
            .any(|(g, _)| g.family == GenericFamily::LegPeriodic);
        let edge_note = if edges.is_empty() {
            String::new()
        } else {
            let at: Vec<String> = edges.iter().map(|(e, _)| format!("{e:.3}")).collect();
            format!(
                "; at a step's edge ({} mm), within the {step:.4} mm spacing that holds it, up to {at_edges:.3} um",
                at.join(", ")
            )
        };
        table.source = format!(
            "{} on {points} points every {step:.4} mm over the campaign's stroke {lo:.3} to {hi:.3} mm, linear interpolation (largest interpolation error {worst:.3} um{edge_note}), the end values beyond{}",
            names.join(" + "),
            if periodic {
                " (a periodic error is known only where the campaign measured it)"
            } else {
                ""
            }
        );
        out.push(table);
    }
    Ok(out)
}
