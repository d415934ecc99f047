//! `cargo xtask hybrid`: what fusing the self-calibration with a few
//! external measurements gains at the tool tip, measured on simulated
//! machines (docs/hybrid.md).
//!
//! For every scenario (the plant's hidden effects: none, compliance,
//! leg-lead, scale-gain, all three) and every machine (class-1 errors of
//! 0.25-0.5 mm with random signs, head errors of 0.5-1 typical sizes), the
//! internal campaign (75-pose grid, paper noise) and one instrument's
//! measurements at every candidate pose are simulated once; then, for each
//! `k`, five methods are fitted to the same data and judged by the error of
//! the tool tip over 408 tool poses when commanded through the fitted
//! model's tool-pose IK:
//!
//! - (a) self-calibration alone (the head nominal: it cannot do better);
//! - (b) the instrument alone on the fusion's `k` planned poses;
//! - (b') the instrument alone on its own `k` planned poses (the fair
//!   comparison);
//! - (c) fusion, geometric model (`paper15 + head13`);
//! - (d) fusion with the effects `tricept diagnose` names on the internal
//!   data (never the truth).
//!
//! The plans (`tricept_study::plan`) depend on the nominal design only and
//! are computed once per instrument, with the redundancy each planned `k`
//! leaves (`k*` counts only checkable campaigns). Every fusion records its
//! own prediction (tool tip after touch-off and tool axis, the held
//! parameters at their typical sizes) beside what it delivers; scenario
//! `none` runs again with head errors at twice the typical sizes, so that
//! the predictions are measured at the head table's sizes and at 2x.
//! Instruments: a tracker, a ballbar, touch-offs on one reference sphere.
//! Everything is seeded; machines run in parallel and are collected in
//! order.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use serde_json::{Value, json};
use tricept_data::{external::ExternalData, external::ExternalPose};
use tricept_diagnose::{DiagnoseOptions, diagnose};
use tricept_engine::fusion::{
    BallbarOptions, FusedModel, FusionOptions, Source, TouchOptions, TrackerOptions, TrackerTarget,
    head_angle_poses, identify_fused,
};
use tricept_ident::advanced::ParameterSet;
use tricept_ident::advanced::plot::{Axes, Curve, Reference, curves};
use tricept_ident::effects::EffectName;
use tricept_ident::kinematics::HeadBranch;
use tricept_kinematics::Machine;
use tricept_model::effects::stiffness_for_platform_deflection;
use tricept_model::head_errors::Effector;
use tricept_numerics::stats::quantile;
use tricept_plant::{
    Campaign, Effect, Plant, instruments::Ballbar, instruments::TouchFeature,
    instruments::TouchProbe, instruments::TouchTarget, instruments::Tracker, random_head_errors,
};
use tricept_study::plan::{
    PlanProblem, candidate_rows, internal_factor, nominal_ballbar_data, nominal_touch_data,
    nominal_tracker_data, plan, sphere_candidates,
};

/// Which instruments to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Which {
    /// A laser tracker, target at the tool tip.
    Tracker,
    /// A ballbar.
    Ballbar,
    /// Touch-offs on a reference sphere.
    Touch,
    /// Tracker and ballbar.
    Both,
    /// Tracker, ballbar and touch-offs, one after the other.
    All,
}

/// `cargo xtask hybrid`.
#[derive(Debug, Args)]
pub struct HybridArgs {
    /// Machines per scenario.
    #[arg(long, default_value_t = 20)]
    pub machines: usize,
    /// Master seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Instruments.
    #[arg(long, value_enum, default_value = "all")]
    pub instrument: Which,
    /// Numbers of external measurements.
    #[arg(long, value_delimiter = ',', default_value = "3,5,8,12,20,30,50")]
    pub k: Vec<usize>,
    /// Directory of the figures and `hybrid.json`.
    #[arg(long, default_value = "docs/figures/hybrid")]
    pub out: PathBuf,
}

/// The accuracy the falsification criteria are judged at, um.
const EPSILON_UM: f64 = 25.0;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scenario {
    None,
    Compliance,
    LegLead,
    ScaleGain,
    All,
}

impl Scenario {
    const ALL: [Scenario; 5] = [
        Scenario::None,
        Scenario::Compliance,
        Scenario::LegLead,
        Scenario::ScaleGain,
        Scenario::All,
    ];

    fn name(self) -> &'static str {
        match self {
            Scenario::None => "none",
            Scenario::Compliance => "compliance",
            Scenario::LegLead => "leg-lead",
            Scenario::ScaleGain => "scale-gain",
            Scenario::All => "all",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Instrument {
    Tracker,
    Ballbar,
    Touch,
}

impl Instrument {
    fn name(self) -> &'static str {
        match self {
            Instrument::Tracker => "tracker",
            Instrument::Ballbar => "ballbar",
            Instrument::Touch => "touch",
        }
    }
}

/// The reference sphere of the touch-offs: nominal centre, mm.
fn sphere() -> Vector3<f64> {
    Vector3::new(0.0, 0.0, 1150.0)
}

/// Its radius and the stylus', mm.
const SPHERE_RADIUS_MM: f64 = 12.7;
const STYLUS_RADIUS_MM: f64 = 1.0;

/// The features file of the touch-offs.
fn touch_features() -> tricept_data::external::Features {
    tricept_data::external::Features {
        stylus: tricept_data::external::Stylus {
            radius_mm: STYLUS_RADIUS_MM,
            radius_sigma_um: 2.0,
        },
        features: vec![tricept_data::external::Feature::Sphere {
            id: 1,
            radius_mm: SPHERE_RADIUS_MM,
            radius_sigma_um: 0.5,
        }],
    }
}

/// The methods compared (see the module docs).
const METHODS: [&str; 5] = [
    "(a) self-calibration alone",
    "(b) external alone, fusion's poses",
    "(b') external alone, own plan",
    "(c) fusion, geometric",
    "(d) fusion + diagnosed effects",
];
/// The free-target row (tracker, scenario none).
const FREE_TARGET: &str = "(c) fusion, tracker target free";

/// Tool-tip error of one fit over the evaluation poses, um (the axis in
/// arcsec), and what the fit predicted for them.
#[derive(Debug, Clone, Copy, PartialEq)]
struct TipError {
    raw_mean: f64,
    raw_max: f64,
    touch_off_mean: f64,
    touch_off_max: f64,
    touch_off_rms: f64,
    axis_rms_arcsec: f64,
    predicted_touch_off_rms: f64,
    predicted_axis_arcsec: f64,
    checkable: bool,
    trustworthy: bool,
}

/// The pivot of the ballbar, mm: under the workspace's centre, 1250 mm
/// from the base.
fn pivot() -> Vector3<f64> {
    Vector3::new(0.0, 0.0, 1250.0)
}

/// A plant: class-1 errors of 0.25-0.5 mm with random signs, head errors
/// of `head_scale` times 0.5-1 typical sizes, and the scenario's effects.
fn plant(m: &Machine, scenario: Scenario, seed: u64, head_scale: f64) -> Plant {
    let set = ParameterSet::paper15();
    let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x3a17_0c1a);
    let mut draw = |lo: f64, hi: f64| {
        let size = lo + (hi - lo) * rng.random::<f64>();
        if rng.random::<bool>() { size } else { -size }
    };
    let module: Vec<f64> = (0..set.len()).map(|_| draw(0.25, 0.5)).collect();
    let lead = [draw(50.0, 150.0), draw(50.0, 150.0), draw(50.0, 150.0)];
    let gain = draw(50.0, 150.0);
    let mut p = Plant::geometric(m.clone(), set.to_errors(&module));
    p.head_errors = random_head_errors(head_scale, seed);
    let compliance = Effect::from(tricept_plant::effects::Compliance {
        stiffness_n_per_um_at_1m: stiffness_for_platform_deflection(m, 12.0),
    });
    p.effects = match scenario {
        Scenario::None => vec![],
        Scenario::Compliance => vec![compliance],
        Scenario::LegLead => vec![Effect::from(tricept_plant::effects::LegLead { ppm: lead })],
        Scenario::ScaleGain => vec![Effect::from(tricept_plant::effects::ScaleGain {
            ppm: gain,
        })],
        Scenario::All => vec![
            compliance,
            Effect::from(tricept_plant::effects::LegLead { ppm: lead }),
            Effect::from(tricept_plant::effects::ScaleGain { ppm: gain }),
        ],
    };
    p
}

/// The tool-tip error of the machine of `model` at `estimate` on `plant`:
/// each evaluation pose's nominal tool pose is the target, commanded
/// through the model's tool-pose IK (leg effects inverted), reached by the
/// plant's actual machine.
fn tip_error(
    plant: &Plant,
    model: &FusedModel,
    fit: &tricept_engine::fusion::Fusion,
    eval: &[ExternalPose],
) -> Option<TipError> {
    let nominal = &plant.nominal;
    let zero = vec![0.0; model.len()];
    let lever = Effector {
        extension_mm: 100.0,
        ..Effector::default()
    };
    let mut errors = Vec::with_capacity(eval.len());
    let mut axis2 = 0.0;
    for pose in eval {
        let (tip, _) = model
            .spindle_point(&zero, pose, &Effector::default())
            .ok()?;
        let up = nominal.forward(&pose.commands_mm).ok()?.up;
        let axis = nominal.tool_forward(&up, pose.head_rad).axis;
        let command = model
            .tool_commands(
                &fit.estimate,
                &tip,
                &axis,
                HeadBranch::Nearest(pose.head_rad),
            )
            .ok()?;
        let reached = plant
            .spindle_point(&command.commands_mm, command.head_rad, &Effector::default())
            .ok()?;
        let up_the_tool = plant
            .spindle_point(&command.commands_mm, command.head_rad, &lever)
            .ok()?;
        axis2 += (up_the_tool - reached).angle(&axis).powi(2);
        errors.push(reached - tip);
    }
    let n = errors.len() as f64;
    let mean = errors.iter().sum::<Vector3<f64>>() / n;
    let raw: Vec<f64> = errors.iter().map(|e| 1e3 * e.norm()).collect();
    let touched: Vec<f64> = errors.iter().map(|e| 1e3 * (e - mean).norm()).collect();
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    Some(TipError {
        raw_mean: raw.iter().sum::<f64>() / n,
        raw_max: max(&raw),
        touch_off_mean: touched.iter().sum::<f64>() / n,
        touch_off_max: max(&touched),
        touch_off_rms: (touched.iter().map(|t| t * t).sum::<f64>() / n).sqrt(),
        axis_rms_arcsec: (axis2 / n).sqrt() / tricept_kinematics::units::RAD_PER_ARCSEC,
        predicted_touch_off_rms: fit.report.tool_tip.touch_off_rms_um,
        predicted_axis_arcsec: fit.report.tool_axis.rms_arcsec,
        checkable: fit.verdict.checkable,
        trustworthy: fit.is_trustworthy(),
    })
}

/// The plans of one instrument: candidate poses, the fusion's and the
/// instrument-alone selection for every `k`, and the predicted curves.
struct Plans {
    candidates: Vec<ExternalPose>,
    fusion: Vec<Vec<usize>>,
    alone: Vec<Vec<usize>>,
    /// Whether each `k` of the fusion's plan leaves its rows the
    /// redundancy to check the fit.
    checkable: Vec<bool>,
    predicted: Value,
}

fn instrument_source(
    instrument: Instrument,
    model: &FusedModel,
    poses: &[ExternalPose],
) -> Result<Source, String> {
    match instrument {
        Instrument::Tracker => {
            let at: Vec<(ExternalPose, f64)> = poses.iter().map(|p| (*p, 0.0)).collect();
            let data = nominal_tracker_data(model, &at).map_err(|e| e.to_string())?;
            Source::tracker(
                &data,
                &tracker_options(TrackerTarget::Known {
                    offset_mm: [0.0; 3],
                    sigma_um: 5.0,
                }),
            )
            .map_err(|e| e.to_string())
        }
        Instrument::Ballbar => {
            let data = nominal_ballbar_data(model, poses, &pivot()).map_err(|e| e.to_string())?;
            Source::ballbar(&data, &BallbarOptions::default()).map_err(|e| e.to_string())
        }
        Instrument::Touch => {
            let data = nominal_touch_data(poses, 1).map_err(|e| e.to_string())?;
            Source::touch(&data, &touch_features(), &TouchOptions::default())
                .map_err(|e| e.to_string())
        }
    }
}

fn tracker_options(target: TrackerTarget) -> TrackerOptions {
    TrackerOptions {
        sigma_um: 10.0,
        target,
    }
}

fn plans(instrument: Instrument, m: &Machine, ks: &[usize]) -> Result<Plans, String> {
    let model = FusedModel::new(m.clone(), ParameterSet::paper15(), &[], true)
        .map_err(|e| e.to_string())?;
    let candidates = match instrument {
        Instrument::Tracker => head_angle_poses(
            m,
            &m.workspace.polar_grid(2, 8, 3),
            &[0.0, 60.0, 120.0, 180.0, 240.0, 300.0],
            &[-45.0, -25.0, 25.0, 45.0],
        ),
        Instrument::Ballbar => sphere_candidates(m, &pivot(), 150.0, 300),
        Instrument::Touch => {
            sphere_candidates(m, &sphere(), SPHERE_RADIUS_MM + STYLUS_RADIUS_MM, 300)
        }
    };
    let f_int =
        internal_factor(&model, &m.workspace.polar_grid(3, 8, 3)).map_err(|e| e.to_string())?;
    let rows = candidate_rows(&model, &instrument_source(instrument, &model, &candidates)?)
        .map_err(|e| e.to_string())?;
    let eval = FusionOptions::for_machine(m).eval_poses;
    let fused = PlanProblem::new(&model, &f_int, &rows, &eval).map_err(|e| e.to_string())?;
    let zero = nalgebra::DMatrix::zeros(0, model.len());
    let lone = PlanProblem::new(&model, &zero, &rows, &eval).map_err(|e| e.to_string())?;
    let (a, b) = rayon::join(
        || plan(&fused, ks, 10, 50, 1),
        || plan(&lone, ks, 10, 50, 1),
    );
    let (a, b) = (a.map_err(|e| e.to_string())?, b.map_err(|e| e.to_string())?);
    let row = |r: &tricept_study::plan::PlanRow| {
        json!({"k": r.k, "planned_um": r.planned_um, "random_median_um": r.random_median_um,
            "axis_arcsec": r.axis_arcsec, "redundancy": r.redundancy, "checkable": r.checkable})
    };
    let predicted = json!({
        "prior_only_um": a.prior_only_um,
        "internal_only_um": a.internal_only_um,
        "internal_only_axis_arcsec": a.internal_only_axis_arcsec,
        "min_redundancy": a.min_redundancy,
        "fusion": a.rows.iter().map(row).collect::<Vec<_>>(),
        "alone": b.rows.iter().map(row).collect::<Vec<_>>(),
    });
    Ok(Plans {
        candidates,
        checkable: a.rows.iter().map(|r| r.checkable).collect(),
        fusion: a.rows.into_iter().map(|r| r.selection).collect(),
        alone: b.rows.into_iter().map(|r| r.selection).collect(),
        predicted,
    })
}

/// The tip error of one fit, or why there is none.
type Fit = Result<TipError, &'static str>;

/// Everything measured on one machine: per method and k, the tip error.
struct MachineResult {
    /// `errors[method][k index]`.
    errors: Vec<Vec<Fit>>,
    free_target: Vec<Fit>,
    named_effects: Vec<EffectName>,
}

fn run_machine(
    instrument: Instrument,
    (scenario, head_scale): (Scenario, f64),
    seed: u64,
    m: &Machine,
    plans: &Plans,
    ks: &[usize],
) -> MachineResult {
    let p = plant(m, scenario, seed, head_scale);
    let eval = FusionOptions::for_machine(m).eval_poses;
    let mut options = FusionOptions::for_machine(m);
    // What is measured is the accuracy; the likely-cause search of an
    // unexplained fit (the geometric fusion with hidden effects) would only
    // cost time.
    options.likely_causes = false;
    let data = match p.simulate(&Campaign::grid(m, seed)) {
        Ok(d) => d,
        Err(_) => {
            return MachineResult {
                errors: vec![vec![Err("simulation failed"); ks.len()]; METHODS.len()],
                free_target: vec![Err("simulation failed"); ks.len()],
                named_effects: Vec::new(),
            };
        }
    };
    let internal = || Source::internal(&data, m.sensors.logged_sigma());
    let tracker = Tracker {
        frame: nalgebra::Isometry3::new(
            Vector3::new(1500.0, -800.0, 200.0),
            Vector3::new(0.1, 0.2, 0.3),
        ),
        target_offset_mm: Vector3::zeros(),
        sigma_um: 10.0,
        setup: 1,
    };
    let bar = Ballbar {
        pivot_mm: pivot(),
        length_error_um: 0.5,
        ball_offset_mm: Vector3::zeros(),
        sigma_um: 1.0,
        setup: 1,
    };
    let all: Vec<(ExternalPose, f64)> = plans.candidates.iter().map(|c| (*c, 0.0)).collect();
    let tracker_data = (instrument == Instrument::Tracker)
        .then(|| tracker.measure(&p, &all, seed))
        .transpose()
        .ok()
        .flatten();
    let ballbar_data = (instrument == Instrument::Ballbar)
        .then(|| bar.measure(&p, &plans.candidates, seed))
        .transpose()
        .ok()
        .flatten();
    let probe = TouchProbe {
        stylus_radius_mm: STYLUS_RADIUS_MM,
        stylus_radius_error_um: 1.0,
        stylus_radius_sigma_um: 2.0,
        sigma_um: 1.5,
        features: vec![TouchFeature::Sphere {
            id: 1,
            centre_mm: sphere() + Vector3::new(0.3, -0.2, 0.1),
            radius_mm: SPHERE_RADIUS_MM,
        }],
    };
    let touch_data = (instrument == Instrument::Touch)
        .then(|| {
            let targets: Vec<TouchTarget> = plans
                .candidates
                .iter()
                .filter_map(|pose| {
                    let up = m.forward(&pose.commands_mm).ok()?.up;
                    let tool = m.tool_forward(&up, pose.head_rad);
                    Some(TouchTarget {
                        feature: 1,
                        tip_mm: tool.tip_mm,
                        axis: tool.axis,
                        approach: (sphere() - tool.tip_mm).normalize(),
                    })
                })
                .collect();
            probe.measure(&p, &targets, seed)
        })
        .transpose()
        .ok()
        .flatten();
    let external = |selection: &[usize], target: TrackerTarget| -> Option<Source> {
        match instrument {
            Instrument::Tracker => {
                let d = tracker_data.as_ref()?;
                let sub = ExternalData {
                    records: selection.iter().map(|&c| d.records[c]).collect(),
                    source: "tracker".into(),
                };
                Source::tracker(&sub, &tracker_options(target)).ok()
            }
            Instrument::Ballbar => {
                let d = ballbar_data.as_ref()?;
                let sub = ExternalData {
                    records: selection.iter().map(|&c| d.records[c]).collect(),
                    source: "ballbar".into(),
                };
                Source::ballbar(&sub, &BallbarOptions::default()).ok()
            }
            Instrument::Touch => {
                let d = touch_data.as_ref()?;
                if d.records.len() != plans.candidates.len() {
                    return None;
                }
                let sub = ExternalData {
                    records: selection.iter().map(|&c| d.records[c]).collect(),
                    source: "touch".into(),
                };
                Source::touch(&sub, &touch_features(), &TouchOptions::default()).ok()
            }
        }
    };
    let tip = TrackerTarget::Known {
        offset_mm: [0.0; 3],
        sigma_um: 5.0,
    };
    let set = ParameterSet::paper15();
    let geometric = FusedModel::new(m.clone(), set.clone(), &[], true).ok();
    let module_only = FusedModel::new(m.clone(), set.clone(), &[], false).ok();
    let named: Vec<EffectName> = diagnose(m, &data, &DiagnoseOptions::for_machine(m))
        .map(|d| {
            d.model_effects()
                .into_iter()
                .filter(|e| e.spec().fused)
                .collect()
        })
        .unwrap_or_default();
    let diagnosed = FusedModel::new(m.clone(), set, &named, true).ok();
    let fit = |model: &Option<FusedModel>, sources: Vec<Option<Source>>| -> Fit {
        let model = model.as_ref().ok_or("model")?;
        let sources: Vec<Source> = sources
            .into_iter()
            .collect::<Option<_>>()
            .ok_or("instrument data unusable")?;
        let f = identify_fused(model, &sources, &options).map_err(|e| match e {
            tricept_engine::IdentError::Source { message, .. }
                if message.starts_with("too few") =>
            {
                "too few measurements for the unknowns"
            }
            tricept_engine::IdentError::NuisanceUnidentifiable { .. } => {
                "the instrument's nuisance is undetermined"
            }
            _ => "identification failed",
        })?;
        tip_error(&p, model, &f, &eval).ok_or("tool-pose IK failed")
    };
    let self_calibration = fit(&module_only, vec![Some(internal())]);
    let mut errors: Vec<Vec<Fit>> = vec![vec![Err("not run"); ks.len()]; METHODS.len()];
    let mut free_target: Vec<Fit> = vec![Err("not run"); ks.len()];
    for (i, _) in ks.iter().enumerate() {
        let (fs, own) = (&plans.fusion[i], &plans.alone[i]);
        errors[0][i] = self_calibration;
        // Touch-offs on one sphere alone cannot calibrate the module.
        if instrument != Instrument::Touch {
            errors[1][i] = fit(&geometric, vec![external(fs, tip)]);
            errors[2][i] = fit(&geometric, vec![external(own, tip)]);
        }
        errors[3][i] = fit(&geometric, vec![Some(internal()), external(fs, tip)]);
        errors[4][i] = fit(&diagnosed, vec![Some(internal()), external(fs, tip)]);
        if instrument == Instrument::Tracker && scenario == Scenario::None {
            free_target[i] = fit(
                &geometric,
                vec![Some(internal()), external(fs, TrackerTarget::Free)],
            );
        }
    }
    MachineResult {
        errors,
        free_target,
        named_effects: named,
    }
}

/// Median, 10 % and 90 % quantiles of the available values.
fn summary(values: impl Iterator<Item = Option<f64>>) -> Option<(f64, f64, f64, usize)> {
    let all: Vec<Option<f64>> = values.collect();
    let mut v: Vec<f64> = all.iter().flatten().copied().collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some((
        quantile(&v, 0.5),
        quantile(&v, 0.1),
        quantile(&v, 0.9),
        all.len() - v.len(),
    ))
}

fn stats_json(s: Option<(f64, f64, f64, usize)>) -> Value {
    match s {
        Some((m, lo, hi, failed)) => {
            json!({"median": m, "p10": lo, "p90": hi, "not_fitted": failed})
        }
        None => Value::Null,
    }
}

/// The smallest k whose median touch-off mean error is within EPSILON_UM
/// and whose planned campaign can be checked (`checkable`, per k).
fn k_star(ks: &[usize], medians: &[Option<f64>], checkable: &[bool]) -> Option<usize> {
    ks.iter()
        .zip(medians)
        .zip(checkable)
        .find(|((_, m), c)| **c && m.is_some_and(|v| v <= EPSILON_UM))
        .map(|((k, _), _)| *k)
}

/// RMS over the machines of `f` of the fits that exist.
fn rms_of(
    machines: &[MachineResult],
    method: usize,
    i: usize,
    f: fn(&TipError) -> f64,
) -> Option<f64> {
    let v: Vec<f64> = machines
        .iter()
        .filter_map(|r| r.errors[method][i].as_ref().ok().map(f))
        .collect();
    (!v.is_empty()).then(|| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt())
}

/// Predicted against delivered for the geometric fusion (c) without hidden
/// effects, at the head table's sizes and at twice them.
fn predictions_table(
    instrument: Instrument,
    ks: &[usize],
    once: &[MachineResult],
    doubled: &[MachineResult],
    plans: &Plans,
) -> String {
    let mut s = format!(
        "\n### {}: predicted against delivered (no hidden effect, fusion (c); RMS over {} machines)\n\n",
        instrument.name(),
        once.len()
    );
    s.push_str("| head errors | k | plan checkable | tip after touch-off, predicted um | delivered um | ratio | tool axis, predicted arcsec | delivered arcsec | trusted |\n|---|---|---|---|---|---|---|---|---|\n");
    let show = |v: Option<f64>, digits: usize| v.map_or("-".into(), |x| format!("{x:.digits$}"));
    for (scale, machines) in [("x1", once), ("x2", doubled)] {
        for (i, k) in ks.iter().enumerate() {
            if ![5, 12, 30].contains(k) {
                continue;
            }
            let p = rms_of(machines, 3, i, |e| e.predicted_touch_off_rms);
            let d = rms_of(machines, 3, i, |e| e.touch_off_rms);
            let pa = rms_of(machines, 3, i, |e| e.predicted_axis_arcsec);
            let da = rms_of(machines, 3, i, |e| e.axis_rms_arcsec);
            let trusted = machines
                .iter()
                .filter(|r| r.errors[3][i].as_ref().is_ok_and(|e| e.trustworthy))
                .count();
            s.push_str(&format!(
                "| {scale} | {k} | {} | {} | {} | {} | {} | {} | {trusted}/{} |\n",
                if plans.checkable[i] { "yes" } else { "**no**" },
                show(p, 1),
                show(d, 1),
                match (p, d) {
                    (Some(p), Some(d)) => format!("{:.2}", d / p),
                    _ => "-".into(),
                },
                show(pa, 0),
                show(da, 0),
                machines.len()
            ));
        }
    }
    s
}

/// Runs the experiment.
pub fn run(a: HybridArgs) -> Result<(), String> {
    let m = Machine::paper();
    let mut ks = a.k.clone();
    ks.sort_unstable();
    ks.dedup();
    if ks.is_empty() || ks[0] == 0 {
        return Err("--k: expected positive whole numbers".into());
    }
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let instruments: Vec<Instrument> = match a.instrument {
        Which::Tracker => vec![Instrument::Tracker],
        Which::Ballbar => vec![Instrument::Ballbar],
        Which::Touch => vec![Instrument::Touch],
        Which::Both => vec![Instrument::Tracker, Instrument::Ballbar],
        Which::All => vec![Instrument::Tracker, Instrument::Ballbar, Instrument::Touch],
    };
    let started = std::time::Instant::now();
    let mut results = Vec::new();
    let mut markdown = String::new();
    for instrument in instruments {
        let plans = plans(instrument, &m, &ks)?;
        eprintln!(
            "{}: plans ready ({} candidates) after {:.1} s",
            instrument.name(),
            plans.candidates.len(),
            started.elapsed().as_secs_f64()
        );
        let run_all = |scenario: Scenario, scale: f64| -> Vec<MachineResult> {
            let machines: Vec<MachineResult> = (0..a.machines as u64)
                .into_par_iter()
                .map(|i| {
                    run_machine(
                        instrument,
                        (scenario, scale),
                        a.seed * 1000 + i,
                        &m,
                        &plans,
                        &ks,
                    )
                })
                .collect();
            eprintln!(
                "{} / {} (head errors x{scale}): {} machines after {:.1} s",
                instrument.name(),
                scenario.name(),
                machines.len(),
                started.elapsed().as_secs_f64()
            );
            machines
        };
        let mut per_scenario = Vec::new();
        for scenario in Scenario::ALL {
            per_scenario.push((scenario, run_all(scenario, 1.0)));
        }
        // The predictions at twice the head table's sizes (no hidden effect).
        let doubled = run_all(Scenario::None, 2.0);
        markdown.push_str(&report(instrument, &ks, &per_scenario, &plans, &a)?);
        markdown.push_str(&predictions_table(
            instrument,
            &ks,
            &per_scenario[0].1,
            &doubled,
            &plans,
        ));
        results.push(json_of(instrument, &ks, &per_scenario, &doubled, &plans));
    }
    let inputs = json!({
        "command": format!("cargo xtask hybrid --machines {} --seed {} --instrument {:?}", a.machines, a.seed, a.instrument).to_lowercase(),
        "machines_per_scenario": a.machines,
        "seed": a.seed,
        "k": ks,
        "class1_errors_mm": "U[0.25, 0.5] with random signs (paper15)",
        "head_errors": "random_head_errors(1.0, seed): U[0.5, 1] x typical size with random signs; scenario none again at random_head_errors(2.0, seed)",
        "effects": {"compliance": "12 um sag at the workspace centre", "leg-lead": "±U[50, 150] ppm per leg", "scale-gain": "±U[50, 150] ppm"},
        "internal": "75-pose grid, 0.8 arcsec / 0.5 um per reading, mean of 3",
        "tracker": "10 um per coordinate, target at the tool tip known to 5 um (free-target row: target offset unknown)",
        "ballbar": "1 um, 150 mm, pivot (0, 0, 1250) mm, length certified to 1 um, true length error 0.5 um",
        "touch": "1.5 um per touch on one sphere of 12.7 mm (nominal centre (0, 0, 1150) mm, true centre 0.37 mm off), stylus 1 mm known to 2 um (true 1 um larger)",
        "evaluation": "408 tool poses: polar_grid(2, 8, 3) x h1 {0, 90, 180, 270} deg x h2 {15, 35} deg; error = actual tip - nominal target, commanded by the fitted model's tool-pose IK",
        "epsilon_um": EPSILON_UM,
    });
    let path = a.out.join("hybrid.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&json!({"inputs": inputs, "results": results}))
            .unwrap_or_default(),
    )
    .map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{markdown}");
    eprintln!(
        "done in {:.1} s; wrote {}",
        started.elapsed().as_secs_f64(),
        path.display()
    );
    Ok(())
}

fn medians(ks: &[usize], machines: &[MachineResult], method: usize) -> Vec<Option<f64>> {
    (0..ks.len())
        .map(|i| {
            summary(
                machines
                    .iter()
                    .map(|r| r.errors[method][i].as_ref().ok().map(|e| e.touch_off_mean)),
            )
            .map(|s| s.0)
        })
        .collect()
}

fn json_of(
    instrument: Instrument,
    ks: &[usize],
    per_scenario: &[(Scenario, Vec<MachineResult>)],
    doubled: &[MachineResult],
    plans: &Plans,
) -> Value {
    let predictions = |machines: &[MachineResult]| -> Value {
        ks.iter()
            .enumerate()
            .map(|(i, k)| {
                json!({
                    "k": k,
                    "plan_checkable": plans.checkable[i],
                    "predicted_touch_off_rms_um": rms_of(machines, 3, i, |e| e.predicted_touch_off_rms),
                    "delivered_touch_off_rms_um": rms_of(machines, 3, i, |e| e.touch_off_rms),
                    "predicted_axis_arcsec": rms_of(machines, 3, i, |e| e.predicted_axis_arcsec),
                    "delivered_axis_arcsec": rms_of(machines, 3, i, |e| e.axis_rms_arcsec),
                    "trusted": machines.iter().filter(|r| r.errors[3][i].as_ref().is_ok_and(|e| e.trustworthy)).count(),
                    "checkable": machines.iter().filter(|r| r.errors[3][i].as_ref().is_ok_and(|e| e.checkable)).count(),
                })
            })
            .collect()
    };
    let scenarios: Vec<Value> = per_scenario
        .iter()
        .map(|(scenario, machines)| {
            let methods: Vec<Value> = METHODS
                .iter()
                .enumerate()
                .map(|(j, name)| {
                    let rows: Vec<Value> = ks
                        .iter()
                        .enumerate()
                        .map(|(i, k)| {
                            let get = |f: fn(&TipError) -> f64| {
                                stats_json(summary(machines.iter().map(|r| r.errors[j][i].as_ref().ok().map(f))))
                            };
                            let mut reasons = std::collections::BTreeMap::new();
                            for r in machines {
                                if let Err(why) = &r.errors[j][i] {
                                    *reasons.entry(*why).or_insert(0usize) += 1;
                                }
                            }
                            json!({
                                "k": k,
                                "not_fitted": reasons,
                                "touch_off_mean_um": get(|e| e.touch_off_mean),
                                "touch_off_max_um": get(|e| e.touch_off_max),
                                "raw_mean_um": get(|e| e.raw_mean),
                                "raw_max_um": get(|e| e.raw_max),
                            })
                        })
                        .collect();
                    json!({"method": name, "rows": rows})
                })
                .collect();
            let mut named = std::collections::BTreeMap::new();
            for r in machines {
                let mut names: Vec<&str> = r.named_effects.iter().map(|e| e.as_str()).collect();
                names.sort_unstable();
                let key = if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join("+")
                };
                *named.entry(key).or_insert(0usize) += 1;
            }
            json!({
                "scenario": scenario.name(),
                "methods": methods,
                "diagnosed_effects": named,
                "free_target": ks.iter().enumerate().map(|(i, k)| json!({
                    "k": k,
                    "touch_off_mean_um": stats_json(summary(machines.iter().map(|r| r.free_target[i].as_ref().ok().map(|e| e.touch_off_mean)))),
                    "raw_mean_um": stats_json(summary(machines.iter().map(|r| r.free_target[i].as_ref().ok().map(|e| e.raw_mean)))),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({
        "instrument": instrument.name(),
        "predicted": plans.predicted,
        "scenarios": scenarios,
        "predictions_fusion_c": {
            "head_errors_x1": predictions(&per_scenario[0].1),
            "head_errors_x2": predictions(doubled),
        },
    })
}

fn report(
    instrument: Instrument,
    ks: &[usize],
    per_scenario: &[(Scenario, Vec<MachineResult>)],
    plans: &Plans,
    a: &HybridArgs,
) -> Result<String, String> {
    let mut s = String::new();
    let show = |v: Option<(f64, f64, f64, usize)>| match v {
        Some((m, lo, hi, failed)) => {
            let fails = if failed > 0 {
                format!(" ({failed} not fitted)")
            } else {
                String::new()
            };
            format!("{m:.0} [{lo:.0}-{hi:.0}]{fails}")
        }
        None => "-".into(),
    };
    let table_ks: Vec<usize> = [5, 12, 30].into_iter().filter(|k| ks.contains(k)).collect();
    s.push_str(&format!(
        "\n### {}: mean tool-tip error after touch-off, um (median [10-90 %] over {} machines)\n\n",
        instrument.name(),
        a.machines
    ));
    s.push_str("| scenario | method |");
    for k in &table_ks {
        s.push_str(&format!(" k = {k} |"));
    }
    s.push_str("\n|---|---|");
    s.push_str(&"---|".repeat(table_ks.len()));
    s.push('\n');
    let methods: Vec<usize> = if instrument == Instrument::Touch {
        vec![0, 3, 4]
    } else {
        (0..METHODS.len()).collect()
    };
    for (scenario, machines) in per_scenario {
        for &j in &methods {
            let name = METHODS[j];
            s.push_str(&format!("| {} | {name} |", scenario.name()));
            for k in &table_ks {
                let i = ks.iter().position(|x| x == k).unwrap_or(0);
                s.push_str(&format!(
                    " {} |",
                    show(summary(machines.iter().map(|r| {
                        r.errors[j][i].as_ref().ok().map(|e| e.touch_off_mean)
                    })))
                ));
            }
            s.push('\n');
        }
        if instrument == Instrument::Tracker && *scenario == Scenario::None {
            s.push_str(&format!("| none | {FREE_TARGET} (raw / after touch-off) |"));
            for k in &table_ks {
                let i = ks.iter().position(|x| x == k).unwrap_or(0);
                let raw = summary(
                    machines
                        .iter()
                        .map(|r| r.free_target[i].as_ref().ok().map(|e| e.raw_mean)),
                );
                let touched = summary(
                    machines
                        .iter()
                        .map(|r| r.free_target[i].as_ref().ok().map(|e| e.touch_off_mean)),
                );
                s.push_str(&format!(" {} / {} |", show(raw), show(touched)));
            }
            s.push('\n');
        }
    }
    let unchecked: Vec<String> = ks
        .iter()
        .zip(&plans.checkable)
        .filter(|(_, c)| !**c)
        .map(|(k, _)| k.to_string())
        .collect();
    if !unchecked.is_empty() {
        s.push_str(&format!(
            "\nThe planned campaigns of k = {} leave fewer redundant rows than it takes to check them (`tricept plan`); `identify` ends them with exit code 3.\n",
            unchecked.join(", ")
        ));
    }
    if instrument == Instrument::Touch {
        return Ok(s);
    }
    s.push_str(&format!(
        "\n### {}: the claims, judged at {EPSILON_UM} um (k* = smallest k with a median within it and a campaign its fit can check)\n\n",
        instrument.name()
    ));
    s.push_str("| scenario | (a) | (d) at k = 8 | k* (b') | k* (c) | k* (d) | k*(b') / k*(d) | claim 1 | claim 2 | (c) worse than (b') at k |\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (scenario, machines) in per_scenario {
        let a_med = medians(ks, machines, 0)[0];
        let d = medians(ks, machines, 4);
        let at8 = ks.iter().position(|k| *k == 8).and_then(|i| d[i]);
        // The instrument alone: its own plan's checkability is not recorded;
        // its fit needs every row anyway (at least 12 points or 32 readings).
        let all = vec![true; ks.len()];
        let (kb, kc, kd) = (
            k_star(ks, &medians(ks, machines, 2), &all),
            k_star(ks, &medians(ks, machines, 3), &plans.checkable),
            k_star(ks, &d, &plans.checkable),
        );
        let fmt_k = |k: Option<usize>| {
            k.map_or(format!("> {}", ks.last().copied().unwrap_or(0)), |k| {
                k.to_string()
            })
        };
        let claim1 = match (kd, a_med, at8) {
            (Some(k), Some(a8), Some(d8)) if k <= 12 && a8 >= 5.0 * d8 => "holds",
            _ => "**false**",
        };
        let ratio = match (kb, kd) {
            (Some(b), Some(d)) => Some(b as f64 / d as f64),
            (None, Some(d)) => Some(ks.last().copied().unwrap_or(0) as f64 / d as f64),
            _ => None,
        };
        let claim2 = match (ratio, kb) {
            (Some(r), Some(_)) if r >= 3.0 => "holds".to_string(),
            (Some(r), None) if r >= 3.0 => "holds (k*(b') beyond the list)".to_string(),
            _ => "**false**".to_string(),
        };
        let (c, b) = (medians(ks, machines, 3), medians(ks, machines, 2));
        let worse: Vec<String> = ks
            .iter()
            .zip(c.iter().zip(&b))
            .filter(|(_, (c, b))| matches!((c, b), (Some(c), Some(b)) if c > b))
            .map(|(k, _)| k.to_string())
            .collect();
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {claim1} | {claim2} | {} |\n",
            scenario.name(),
            a_med.map_or("-".into(), |v| format!("{v:.0}")),
            at8.map_or("-".into(), |v| format!("{v:.0}")),
            fmt_k(kb),
            fmt_k(kc),
            fmt_k(kd),
            ratio.map_or("-".into(), |r| format!(
                "{}{r:.1}",
                if kb.is_none() { ">= " } else { "" }
            )),
            if worse.is_empty() {
                "none".into()
            } else {
                worse.join(", ")
            },
        ));
    }
    // The figures: the curves against k for the scenarios none and all.
    for (scenario, machines) in per_scenario
        .iter()
        .filter(|(s, _)| matches!(s, Scenario::None | Scenario::All))
    {
        let x: Vec<f64> = ks.iter().map(|k| *k as f64).collect();
        let curves_of: Vec<Curve> = (0..METHODS.len())
            .filter_map(|j| {
                let stats: Vec<Option<(f64, f64, f64, usize)>> = (0..ks.len())
                    .map(|i| {
                        summary(
                            machines
                                .iter()
                                .map(|r| r.errors[j][i].as_ref().ok().map(|e| e.touch_off_mean)),
                        )
                    })
                    .collect();
                let points: Vec<(f64, (f64, f64, f64, usize))> = x
                    .iter()
                    .zip(&stats)
                    .filter_map(|(x, s)| s.map(|s| (*x, s)))
                    .collect();
                (!points.is_empty()).then(|| Curve {
                    name: METHODS[j].to_string(),
                    x: points.iter().map(|p| p.0).collect(),
                    y: points.iter().map(|p| p.1.0).collect(),
                    band: Some(points.iter().map(|p| (p.1.1, p.1.2)).collect()),
                })
            })
            .collect();
        let path: PathBuf = a.out.join(format!(
            "tool-tip-vs-k-{}-{}.svg",
            instrument.name(),
            scenario.name()
        ));
        let title = format!(
            "{}, scenario {}: tool-tip error after touch-off (um, {} machines)",
            instrument.name(),
            scenario.name(),
            a.machines
        );
        curves(
            Path::new(&path),
            &Axes {
                title: &title,
                x_label: "external measurements k",
                y_label: "mean tool-tip error after touch-off, um",
                log_x: true,
                log_y: true,
            },
            &curves_of,
            &[Reference {
                name: format!("{EPSILON_UM} um"),
                y: EPSILON_UM,
            }],
            &[],
        )
        .map_err(|e| e.to_string())?;
    }
    Ok(s)
}
