//! Plan (`tricept plan`): which few tracker points, ballbar readings or
//! touch-offs to take, given the internal campaign, so that the tool tip
//! (and with known extensions the tool axis) is best known after touch-off;
//! the predicted accuracy against their number, the redundancy each leaves
//! to check the fit, and the recommended number ([`Instrument::Tracker`],
//! [`Instrument::Ballbar`], [`Instrument::Touch`]); or the fewest poses of
//! a check of a calibrated machine that detect a stated change
//! ([`Instrument::Check`]).
//!
//! # Example
//! ```no_run
//! use tricept_ident::plan::{Instrument, PlanRequest, plan};
//! let planned = plan(PlanRequest::new(Instrument::Tracker))?;
//! assert!(planned.machine_warnings().is_empty());
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::fmt::Write as _;
use std::path::PathBuf;

use nalgebra::{DMatrix, Vector3};
use serde_json::{Value, json};
use tricept_data::external::{ExternalData, PlannedPose, write_external_path};
use tricept_engine::fusion::{FusedModel, Source, TrackerOptions, information_factor};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
use tricept_model::effects::EffectName;
use tricept_study::plan::{
    Plan as StudyPlan, PlanProblem, PlanRow, candidate_rows, internal_factor, plan as study_plan,
    sphere_candidates,
};
use tricept_study::plan_sources::{Candidate, ballbar_source, touch_source, tracker_source};

use crate::Setting;
use crate::calibrate::values::{
    EvalGrid, HeadModel, TrackerTargetSpec, eval_options, fused_model, head_angles_text,
};
use crate::calibrate::write_text;
use crate::data_input::DataInput;
use crate::error::Error;
use crate::inputs::{HeadAngles, LoadedMachine, Poses, Triple, positive};
use crate::limits;
use crate::machine_input::MachineInput;

/// A line of a report (`writeln!` whose result, always `Ok` on a
/// `String`, is dropped).
macro_rules! wln {
    ($s:expr, $($arg:tt)*) => {{
        let _ = writeln!($s, $($arg)*);
    }};
}

/// The instrument to plan for.
///
/// # Example
/// ```
/// use tricept_ident::plan::{Instrument, PlanRequest};
/// let request = PlanRequest::new(Instrument::Ballbar);
/// assert_eq!(request.instrument, Instrument::Ballbar);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Instrument {
    /// A laser tracker or CMM on a target in the spindle.
    Tracker,
    /// A ballbar from the spindle ball to a pivot on the table.
    Ballbar,
    /// A touch probe in the spindle on a reference sphere.
    Touch,
    /// A check of the calibrated machine from its own sensors: the fewest
    /// poses that detect a stated change.
    Check,
}

/// What to plan. The defaults are `tricept plan`'s.
///
/// # Example
/// ```
/// use tricept_ident::plan::{Instrument, PlanRequest};
/// let request = PlanRequest::new(Instrument::Touch);
/// assert!(request.k.is_empty()); // the default numbers of measurements
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct PlanRequest {
    /// The instrument.
    pub instrument: Instrument,
    /// Numbers of measurements to plan for (empty: 3,5,8,12,20,30,50; for
    /// a check, the largest number of poses it may take, default 20).
    pub k: Vec<usize>,
    /// For a check: the change to detect, as mean platform error, um.
    pub detect_um: f64,
    /// For a check: the power with which it is detected.
    pub power: f64,
    /// The internal campaign's data (only its commands are used).
    pub data: Option<DataInput>,
    /// The internal campaign's pose set when no data are given (default
    /// `grid`).
    pub poses: Option<Poses>,
    /// Candidate platform points of a tracker (default `grid:2,8,3`).
    pub candidates: Option<Poses>,
    /// Candidate head angles of a tracker, deg.
    pub head_angles_deg: HeadAngles,
    /// Known extensions of the tracker target along the tool, mm.
    pub extensions: Vec<f64>,
    /// Noise of a tracker coordinate, um.
    pub tracker_sigma_um: f64,
    /// Noise of a ballbar reading, um.
    pub ballbar_sigma_um: f64,
    /// The instrument's noise, um (overrides the three noise fields).
    pub sigma_um: Option<f64>,
    /// Where the tracker's target sits (required for a tracker).
    pub tracker_target: Option<TrackerTargetSpec>,
    /// Standard deviation of a known target offset, um.
    pub tracker_target_sigma_um: f64,
    /// The ballbar's pivot, mm.
    pub ballbar_pivot_mm: Triple,
    /// The ballbar's nominal length, mm.
    pub ballbar_length_mm: f64,
    /// Number of ballbar (or touch) candidate positions.
    pub ballbar_candidates: usize,
    /// The reference sphere's centre, mm (touch-offs).
    pub touch_sphere_mm: Triple,
    /// The reference sphere's radius, mm.
    pub touch_sphere_radius_mm: f64,
    /// The stylus' nominal radius, mm.
    pub touch_stylus_radius_mm: f64,
    /// Standard deviation of the stylus radius, um.
    pub touch_stylus_sigma_um: f64,
    /// Noise of a touch along the surface normal, um.
    pub touch_sigma_um: f64,
    /// Effects in the model.
    pub effects: Vec<EffectName>,
    /// The accuracy to reach, um.
    pub target_um: Option<f64>,
    /// Random selections per k for the baseline (0: none).
    pub random_baseline: usize,
    /// Seed of the random baseline.
    pub seed: u64,
    /// Exchange passes at each k.
    pub passes: usize,
    /// Evaluation grid of the tool tip.
    pub eval_grid: EvalGrid,
    /// Head angles of the evaluation grid, deg.
    pub eval_head_angles_deg: HeadAngles,
    /// Where the planned poses are to be written ([`Plan::write_out`]).
    pub out: Option<PathBuf>,
    /// The machine (default: the embedded Table 1 machine).
    pub machine: MachineInput,
    /// The module's parameter set.
    pub parameter_set: ParameterSet,
}

impl PlanRequest {
    /// A plan for `instrument` with `tricept plan`'s defaults.
    pub fn new(instrument: Instrument) -> PlanRequest {
        PlanRequest {
            instrument,
            k: Vec::new(),
            detect_um: 20.0,
            power: tricept_check::check::DEFAULT_POWER,
            data: None,
            poses: None,
            candidates: None,
            head_angles_deg: HeadAngles {
                h1_deg: vec![0.0, 60.0, 120.0, 180.0, 240.0, 300.0],
                h2_deg: vec![-45.0, -25.0, 25.0, 45.0],
            },
            extensions: vec![0.0],
            tracker_sigma_um: 10.0,
            ballbar_sigma_um: 1.0,
            sigma_um: None,
            tracker_target: None,
            tracker_target_sigma_um: 5.0,
            ballbar_pivot_mm: Triple([0.0, 0.0, 1250.0]),
            ballbar_length_mm: 150.0,
            ballbar_candidates: 300,
            touch_sphere_mm: Triple([0.0, 0.0, 1150.0]),
            touch_sphere_radius_mm: 12.7,
            touch_stylus_radius_mm: 1.0,
            touch_stylus_sigma_um: 2.0,
            touch_sigma_um: 1.5,
            effects: Vec::new(),
            target_um: None,
            random_baseline: 50,
            seed: 1,
            passes: 10,
            eval_grid: EvalGrid::default(),
            eval_head_angles_deg: HeadAngles {
                h1_deg: vec![0.0, 90.0, 180.0, 270.0],
                h2_deg: vec![15.0, 35.0],
            },
            out: None,
            machine: MachineInput::default(),
            parameter_set: ParameterSet::paper15(),
        }
    }

    /// The internal campaign's pose set.
    fn poses_or_grid(&self) -> Result<Poses, Error> {
        match &self.poses {
            Some(p) => Ok(p.clone()),
            None => "grid".parse(),
        }
    }

    /// The tracker's candidate points.
    fn candidates_or_grid(&self) -> Result<Poses, Error> {
        match &self.candidates {
            Some(p) => Ok(p.clone()),
            None => "grid:2,8,3".parse(),
        }
    }
}

crate::request::setters!(PlanRequest {
    k: Vec<usize>,
    detect_um: f64,
    power: f64,
    data: some into DataInput,
    poses: some Poses,
    candidates: some Poses,
    head_angles_deg: HeadAngles,
    extensions: Vec<f64>,
    tracker_sigma_um: f64,
    ballbar_sigma_um: f64,
    sigma_um: some f64,
    tracker_target: some TrackerTargetSpec,
    tracker_target_sigma_um: f64,
    ballbar_pivot_mm: Triple,
    ballbar_length_mm: f64,
    ballbar_candidates: usize,
    touch_sphere_mm: Triple,
    touch_sphere_radius_mm: f64,
    touch_stylus_radius_mm: f64,
    touch_stylus_sigma_um: f64,
    touch_sigma_um: f64,
    effects: Vec<EffectName>,
    target_um: some f64,
    random_baseline: usize,
    seed: u64,
    passes: usize,
    eval_grid: EvalGrid,
    eval_head_angles_deg: HeadAngles,
    out: some into PathBuf,
    machine: into MachineInput,
    parameter_set: ParameterSet,
});

/// The poses to write: planned external measurements, or a check's
/// commands.
#[derive(Debug, Clone)]
enum OutFile {
    Planned {
        records: Vec<PlannedPose>,
        comments: Vec<String>,
    },
    Check(String),
}

/// A plan: its JSON, its text report and the poses to take.
///
/// # Example
/// ```no_run
/// use tricept_ident::plan::{Instrument, PlanRequest, plan};
/// let planned = plan(PlanRequest::new(Instrument::Tracker))?;
/// assert!(planned.machine_warnings().is_empty());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Plan {
    json: Value,
    text: String,
    out: Option<OutFile>,
    warnings: Vec<String>,
}

crate::outcome::outcome!(Plan);

impl Plan {
    /// Always 0: a plan has no verdict.
    pub fn exit_code(&self) -> u8 {
        crate::error::EXIT_OK
    }

    /// Always `None`: a plan has no verdict.
    pub fn reason(&self) -> Option<&str> {
        None
    }

    /// The JSON `tricept plan --json` prints (`format_version` first).
    pub fn to_json(&self) -> Value {
        crate::outcome::versioned(self.json.clone())
    }

    /// The warnings of the machine file loaded.
    pub fn machine_warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The text report (what `tricept plan` prints).
    pub fn report(&self) -> String {
        self.text.clone()
    }

    /// Writes the planned poses (of the largest k) atomically to `path`;
    /// `false` when there is nothing to write.
    pub fn write_out(&self, path: &std::path::Path) -> Result<bool, Error> {
        match &self.out {
            None => Ok(false),
            Some(OutFile::Check(text)) => write_text(path, text).map(|()| true),
            Some(OutFile::Planned { records, comments }) => write_external_path(
                path,
                &ExternalData {
                    records: records.clone(),
                    source: String::new(),
                },
                comments,
            )
            .map(|()| true)
            .map_err(|e| Error::not_written(path, &e)),
        }
    }
}

/// The instrument's noise: its own setting, or the old `sigma_um`.
fn instrument_sigma(a: &PlanRequest, own: f64, setting: Setting) -> Result<f64, Error> {
    match a.sigma_um {
        Some(v) => positive(Setting::SigmaUm, v),
        None => positive(setting, own),
    }
}

/// Plans as `request` says.
///
/// # Example
/// ```no_run
/// use tricept_ident::plan::{Instrument, PlanRequest, plan};
/// let planned = plan(PlanRequest::new(Instrument::Tracker))?;
/// assert!(planned.machine_warnings().is_empty());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn plan(request: PlanRequest) -> Result<Plan, Error> {
    let a = &request;
    let default_k = [3, 5, 8, 12, 20, 30, 50];
    let k: &[usize] = if a.k.is_empty() { &default_k } else { &a.k };
    let loaded = a.machine.clone().load()?;
    let m = loaded.machine().clone();
    let set = a.parameter_set.clone();
    let model = fused_model(&m, &set, &a.effects, HeadModel::Head13)?;
    let options = eval_options(&m, a.eval_grid, &a.eval_head_angles_deg)?;
    check_sizes(a, k)?;
    let (f_int, internal_poses) = internal_information(a, &m, &model)?;
    if a.instrument == Instrument::Check {
        return check_plan(a, &loaded);
    }
    let (poses, source, centre) = candidates(a, &m, &model)?;
    let axis = a.instrument == Instrument::Tracker && {
        let mut e = a.extensions.clone();
        e.sort_by(f64::total_cmp);
        e.dedup();
        e.len() >= 2
    };
    let rows = candidate_rows(&model, &source)?;
    let mut problem = PlanProblem::new(&model, &f_int, &rows, &options.eval_poses)?;
    if axis {
        problem = problem.with_tool_axis();
    }
    let result = study_plan(&problem, k, a.passes, a.random_baseline, a.seed)?;
    let out = match (&a.out, result.rows.last()) {
        (Some(_), Some(last)) => Some(planned_poses(a, &model, &poses, centre, last)?),
        _ => None,
    };
    let (json, text) = report(
        a,
        &result,
        poses.len(),
        axis,
        options.eval_poses.len(),
        internal_poses,
    );
    Ok(Plan {
        json,
        text,
        out,
        warnings: loaded.warnings().to_vec(),
    })
}

/// Refuses sizes no plan can use.
fn check_sizes(a: &PlanRequest, k: &[usize]) -> Result<(), Error> {
    if k.contains(&0) {
        return Err(Error::invalid(
            Setting::K,
            "expected positive whole numbers",
        ));
    }
    if let Some(t) = a.target_um
        && !(t.is_finite() && t > 0.0)
    {
        return Err(Error::invalid(
            Setting::TargetUm,
            format!("the accuracy to reach must be a positive number of um, got {t}"),
        ));
    }
    for (setting, n, max) in [
        (Setting::Passes, a.passes, limits::MAX_PASSES),
        (
            Setting::RandomBaseline,
            a.random_baseline,
            limits::MAX_RANDOM_BASELINE,
        ),
    ] {
        if n > max {
            return Err(Error::invalid(setting, format!("{n}; at most {max}")));
        }
    }
    Ok(())
}

/// The information of the internal campaign (its data's commands, or its
/// pose set) and its number of poses.
fn internal_information(
    a: &PlanRequest,
    m: &Machine,
    model: &FusedModel,
) -> Result<(DMatrix<f64>, usize), Error> {
    Ok(match &a.data {
        Some(path) => {
            let data = path.load(m)?;
            let f =
                information_factor(model, &[Source::internal(&data, m.sensors.logged_sigma())])?;
            (f, data.poses.len())
        }
        None => {
            let poses = a.poses_or_grid()?;
            let targets = poses.targets(m)?;
            let f = internal_factor(model, &targets)
                .map_err(|e| Error::invalid_value(Setting::Poses, &poses, e))?;
            (f, targets.len())
        }
    })
}

/// The candidates of an instrument, its nominal source and the centre of a
/// ballbar's pivot or a touched sphere, mm.
type Candidates = (Vec<Candidate>, Source, Option<Vector3<f64>>);

/// The candidate poses of the instrument, its nominal source and the
/// centre of a ballbar's pivot or a touched sphere.
fn candidates(a: &PlanRequest, m: &Machine, model: &FusedModel) -> Result<Candidates, Error> {
    Ok(match a.instrument {
        Instrument::Check => {
            return Err(Error::input("plan: a check has no candidate measurements"));
        }
        Instrument::Tracker => {
            let target = TrackerTargetSpec::required(a.tracker_target, a.tracker_target_sigma_um)?;
            let (h1, h2) = (&a.head_angles_deg.h1_deg, &a.head_angles_deg.h2_deg);
            if a.extensions
                .iter()
                .any(|e| !e.is_finite() || e.abs() > 1000.0)
            {
                return Err(Error::invalid(
                    Setting::Extensions,
                    "expected extensions along the tool in mm, within ±1000",
                ));
            }
            let candidates = a.candidates_or_grid()?;
            let points = candidates.targets(m)?;
            let count = points.len() * h1.len() * h2.len() * a.extensions.len().max(1);
            if count > limits::MAX_CANDIDATES {
                return Err(Error::invalid_value(
                    Setting::Candidates,
                    &candidates,
                    format!(
                        "with the head angles {} deg: {count} candidate poses; at most {}",
                        head_angles_text(&a.head_angles_deg),
                        limits::MAX_CANDIDATES
                    ),
                ));
            }
            let options = TrackerOptions {
                sigma_um: instrument_sigma(a, a.tracker_sigma_um, Setting::TrackerSigmaUm)?,
                target,
            };
            let (poses, source) =
                tracker_source(model, m, &points, (h1, h2), &a.extensions, &options)?;
            (poses, source, None)
        }
        Instrument::Ballbar | Instrument::Touch => {
            let touch = a.instrument == Instrument::Touch;
            let (setting, Triple(p)) = if touch {
                (Setting::TouchSphereMm, a.touch_sphere_mm)
            } else {
                (Setting::BallbarPivotMm, a.ballbar_pivot_mm)
            };
            let centre = Vector3::new(p[0], p[1], p[2]);
            let text = format!("{},{},{}", p[0], p[1], p[2]);
            let radius = if touch {
                positive(Setting::TouchSphereRadiusMm, a.touch_sphere_radius_mm)?
                    + positive(Setting::TouchStylusRadiusMm, a.touch_stylus_radius_mm)?
            } else {
                positive(Setting::BallbarLengthMm, a.ballbar_length_mm)?
            };
            if a.ballbar_candidates > limits::MAX_CANDIDATES {
                return Err(Error::invalid(
                    Setting::BallbarCandidates,
                    format!(
                        "{}; at most {}",
                        a.ballbar_candidates,
                        limits::MAX_CANDIDATES
                    ),
                ));
            }
            let poses = sphere_candidates(m, &centre, radius, a.ballbar_candidates);
            if poses.len() < 4 {
                return Err(Error::invalid_value(
                    setting,
                    text,
                    format!(
                        "the machine reaches only {} positions around this point",
                        poses.len()
                    ),
                ));
            }
            let source = if touch {
                let stylus = (
                    a.touch_stylus_radius_mm,
                    positive(Setting::TouchStylusSigmaUm, a.touch_stylus_sigma_um)?,
                );
                let options = tricept_engine::fusion::TouchOptions {
                    sigma_um: instrument_sigma(a, a.touch_sigma_um, Setting::TouchSigmaUm)?,
                };
                touch_source(&poses, a.touch_sphere_radius_mm, stylus, &options)?
            } else {
                let options = tricept_engine::fusion::BallbarOptions {
                    sigma_um: instrument_sigma(a, a.ballbar_sigma_um, Setting::BallbarSigmaUm)?,
                    ..Default::default()
                };
                ballbar_source(model, &poses, &centre, &options)?
            };
            let poses = poses.into_iter().map(|p| (p, 0.0)).collect();
            (poses, source, Some(centre))
        }
    })
}

/// The planned poses of the largest k, to write.
fn planned_poses(
    a: &PlanRequest,
    model: &FusedModel,
    poses: &[Candidate],
    centre: Option<Vector3<f64>>,
    last: &PlanRow,
) -> Result<OutFile, Error> {
    let records = tricept_study::plan_sources::planned_poses(
        model,
        poses,
        &last.selection,
        centre.filter(|_| a.instrument == Instrument::Ballbar),
        (a.instrument == Instrument::Touch).then_some(1),
    )?;
    let comments = vec![format!(
        "planned by tricept {} for a {:?}: {} measurements, RMS predicted tool-tip sd after touch-off {:.1} um, tool axis {:.1} arcsec, redundancy {:.1}",
        env!("CARGO_PKG_VERSION"),
        a.instrument,
        last.k,
        last.planned_um,
        last.axis_arcsec,
        last.redundancy
    )];
    Ok(OutFile::Planned { records, comments })
}

/// The JSON and the text report of an instrument's plan.
fn report(
    a: &PlanRequest,
    result: &StudyPlan,
    candidates: usize,
    axis: bool,
    eval_poses: usize,
    internal_poses: usize,
) -> (Value, String) {
    let recommended = result.recommended(a.target_um, None);
    let json = json!({
        "instrument": format!("{:?}", a.instrument).to_lowercase(),
        "candidates": candidates,
        "criterion": if axis {
            "RMS over the evaluation poses of the predicted tool-tip standard deviation after touch-off and of the tool axis' times 100 mm, um"
        } else {
            "RMS over the evaluation poses of the predicted tool-tip standard deviation after touch-off, um"
        },
        "prior_only_um": result.prior_only_um,
        "internal_only_um": result.internal_only_um,
        "internal_only_axis_arcsec": result.internal_only_axis_arcsec,
        "min_redundancy": result.min_redundancy,
        "rows": result.rows.iter().map(|r| json!({
            "k": r.k, "planned_um": r.planned_um, "planned_raw_um": r.planned_raw_um,
            "random_median_um": r.random_median_um, "axis_arcsec": r.axis_arcsec,
            "redundancy": r.redundancy, "checkable": r.checkable,
        })).collect::<Vec<_>>(),
        "target_um": a.target_um,
        "k_for_target": a.target_um.and(recommended),
        "recommended_k": recommended,
    });
    let mut text = String::new();
    {
        let s = &mut text;
        wln!(
            s,
            "{:?}: {} candidates; criterion: RMS predicted tool-tip sd after touch-off{} over {} tool poses (um)",
            a.instrument,
            candidates,
            if axis { " and tool axis x 100 mm" } else { "" },
            eval_poses
        );
        wln!(
            s,
            "prior only {:.1} um; internal campaign ({} poses) alone {:.1} um, tool axis {:.1} arcsec",
            result.prior_only_um,
            internal_poses,
            result.internal_only_um,
            result.internal_only_axis_arcsec
        );
        wln!(
            s,
            "{:>4} {:>10} {:>10} {:>14} {:>12} {:>11}",
            "k",
            "planned",
            "raw",
            "random median",
            "axis arcsec",
            "redundancy"
        );
        for r in &result.rows {
            wln!(
                s,
                "{:>4} {:>10.1} {:>10.1} {:>14} {:>12.1} {:>11}",
                r.k,
                r.planned_um,
                r.planned_raw_um,
                r.random_median_um.map_or("-".into(), |v| format!("{v:.1}")),
                r.axis_arcsec,
                format!(
                    "{:.1}{}",
                    r.redundancy.max(0.0),
                    if r.checkable { "" } else { " (!)" }
                )
            );
        }
        if result.rows.iter().any(|r| !r.checkable) {
            wln!(
                s,
                "(!): fewer than {:.0} redundant rows: the fit could not check these measurements (a gross error or a wrong file would go unseen)",
                result.min_redundancy
            );
        }
        match (a.target_um, recommended) {
            (Some(t), Some(k)) => wln!(
                s,
                "recommended: {k} planned measurements (the smallest k asked for that predicts {t} um and leaves {:.0} redundant rows)",
                result.min_redundancy
            ),
            (Some(t), None) => {
                wln!(
                    s,
                    "{t} um is not predicted with enough redundancy by any k asked for"
                )
            }
            (None, Some(k)) => wln!(
                s,
                "recommended: at least {k} measurements (the smallest k asked for that leaves {:.0} redundant rows; an accuracy target (target_um) adds one)",
                result.min_redundancy
            ),
            (None, None) => wln!(s, "no k asked for leaves enough redundant rows"),
        }
        wln!(
            s,
            "note: a linear-Gaussian prediction of variance only; an unmodelled effect's bias is not in it (docs/hybrid.md)"
        );
    }
    (json, text)
}

/// `tricept plan --instrument check`: the fewest poses, up to `--k` (default
/// 20), whose check detects a change of `--detect-um` of platform error in
/// any single parameter with `--power` (`tricept_study::check_plan`).
fn check_plan(a: &PlanRequest, loaded: &LoadedMachine) -> Result<Plan, Error> {
    let Some(path) = loaded.path() else {
        return Err(Error::invalid(
            Setting::Machine,
            "a check's plan needs a calibrated machine file (a check is planned for a calibrated machine and its record)",
        ));
    };
    let budget = match a.k.as_slice() {
        [] => 20,
        k if k.contains(&0) => {
            return Err(Error::invalid(
                Setting::K,
                "expected positive whole numbers",
            ));
        }
        k => k.iter().copied().max().unwrap_or(20),
    };
    if budget > limits::MAX_CANDIDATES {
        return Err(Error::invalid(
            Setting::K,
            format!("{budget} poses; at most {}", limits::MAX_CANDIDATES),
        ));
    }
    if !(a.detect_um.is_finite() && a.detect_um > 0.0) {
        return Err(Error::invalid(
            Setting::DetectUm,
            format!(
                "the change to detect must be a positive number of um, got {}",
                a.detect_um
            ),
        ));
    }
    if !(a.power > 0.0 && a.power < 1.0) {
        return Err(Error::invalid(
            Setting::Power,
            format!("must lie between 0 and 1, got {}", a.power),
        ));
    }
    let reference = tricept_check::Reference::from_description(loaded.description())
        .map_err(|e| Error::input(format!("{}: {e}", path.display())))?;
    let p = tricept_study::check_plan::plan_check(
        &reference,
        a.detect_um,
        a.power,
        tricept_check::check::DEFAULT_ALPHA,
        budget,
    )?;
    let mut out = None;
    if a.out.is_some() {
        let text = tricept_study::plan_sources::check_poses_csv(
            loaded.machine(),
            &loaded.description().name,
            &p.targets_mm,
        )
        .map_err(|e| Error::with_context("plan", e))?;
        out = Some(OutFile::Check(text));
    }
    let json = json!({
        "instrument": "check",
        "detect_um": a.detect_um,
        "power": a.power,
        "poses": p.poses,
        "reached": p.reached,
        "targets_mm": p.targets_mm.iter().map(|r| [r.x, r.y, r.z]).collect::<Vec<_>>(),
        "parameters": p.parameters,
    });
    let mut text = String::new();
    {
        let s = &mut text;
        wln!(
            s,
            "check of `{}`: {} poses {} a change of {} um of platform error in any single parameter with power {}{}",
            loaded.description().name,
            p.poses,
            if p.reached { "detect" } else { "do NOT detect" },
            a.detect_um,
            a.power,
            if p.reached {
                String::new()
            } else {
                format!(
                    " (the budget of {budget} poses (k) is spent; more poses or a larger change to detect (detect_um))"
                )
            }
        );
        wln!(
            s,
            "{:>6} {:>14} {:>18} {:>22} {:>8}",
            "param",
            "target um",
            "detectable um",
            "as platform error um",
            "power"
        );
        for d in &p.parameters {
            match (d.detectable_mm, d.detectable_platform_um, d.power) {
                (Some(det), Some(plat), Some(power)) => wln!(
                    s,
                    "{:>6} {:>14.1} {:>18.1} {:>22.1} {:>8.3}",
                    d.name,
                    d.target_mm * 1e3,
                    det * 1e3,
                    plat,
                    power
                ),
                _ => wln!(
                    s,
                    "{:>6} {:>14} {:>18} {:>22} {:>8}",
                    d.name,
                    "-",
                    "not seen",
                    "-",
                    "-"
                ),
            }
        }
    }
    Ok(Plan {
        json,
        text,
        out,
        warnings: loaded.warnings().to_vec(),
    })
}
