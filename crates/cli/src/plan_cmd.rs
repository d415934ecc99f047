//! `tricept plan`: which few tracker points, ballbar readings or touch-offs
//! to take, given the internal campaign, so that the tool tip (and with
//! known extensions the tool axis) is best known after touch-off; the
//! predicted accuracy against their number, the redundancy each leaves to
//! check the fit, and the recommended number (`tricept_study::plan`).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use nalgebra::Vector3;
use serde_json::json;
use tricept_data::{ExternalData, PlannedPose};
use tricept_engine::fusion::{Source, TrackerOptions, head_angle_poses, information_factor};
use tricept_study::plan::{
    PlanProblem, candidate_rows, internal_factor, nominal_ballbar_data, nominal_touch_data,
    nominal_tracker_data, plan, sphere_candidates, with_extensions,
};

use crate::args::parse_head_angles;
use crate::args::{
    MachineArgs, NoiseArgs, ParamArgs, TouchSphereArgs, machine_with_noise, pose_targets, read_data,
};
use crate::cli_error::CliError;
use tricept_ident::limits;
use tricept_ident::{
    EffectNames, EvalGrid, HeadAngles, HeadModel, TrackerTargetSpec, eval_options, fused_model,
    parse_numbers, positive,
};

/// The instrument to plan for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Instrument {
    /// A laser tracker or CMM on a target in the spindle.
    Tracker,
    /// A ballbar from the spindle ball to a pivot on the table.
    Ballbar,
    /// A touch probe in the spindle on a reference sphere.
    Touch,
    /// A check of the calibrated machine from its own sensors (`tricept
    /// check`): the fewest poses that detect a stated change.
    Check,
}

/// `tricept plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The instrument.
    #[arg(long, value_enum)]
    pub instrument: Instrument,
    /// Numbers of measurements to plan for, comma-separated (default
    /// 3,5,8,12,20,30,50; for a check, the largest number of poses it may
    /// take, default 20).
    #[arg(long, value_delimiter = ',')]
    pub k: Vec<usize>,
    /// For a check: the change to detect, as the mean platform error it
    /// causes over the workspace, um (from any single joint or length
    /// parameter).
    #[arg(long, default_value_t = 20.0, value_name = "UM")]
    pub detect_um: f64,
    /// For a check: the power with which it is detected.
    #[arg(long, default_value_t = tricept_check::DEFAULT_POWER, value_name = "P")]
    pub power: f64,
    /// The internal campaign's measured-data file (only its commands are
    /// used); default: the pose set of --poses.
    #[arg(long, value_name = "FILE.csv")]
    pub data: Option<PathBuf>,
    /// The internal campaign's pose set when no --data is given.
    #[arg(long, default_value = "grid")]
    pub poses: String,
    /// Candidate platform points of a tracker (a pose-set spec).
    #[arg(long, default_value = "grid:2,8,3")]
    pub candidates: String,
    /// Candidate head angles of a tracker, deg: `H1,H1,...:H2,H2,...`.
    #[arg(
        long,
        default_value = "0,60,120,180,240,300:-45,-25,25,45",
        value_name = "H1S:H2S"
    )]
    pub head_angles_deg: String,
    /// Known extensions of the tracker target along the tool, mm: every
    /// candidate pose is offered at each; with two or more the plan fixes
    /// the tool's direction too (its criterion adds the tool axis).
    #[arg(
        long,
        default_value = "0",
        value_delimiter = ',',
        value_name = "MM,..."
    )]
    pub extensions: Vec<f64>,
    /// Noise of a tracker coordinate, um.
    #[arg(long, default_value_t = 10.0, value_name = "UM")]
    pub tracker_sigma_um: f64,
    /// Noise of a ballbar reading, um.
    #[arg(long, default_value_t = 1.0, value_name = "UM")]
    pub ballbar_sigma_um: f64,
    /// The instrument's noise (old name of the three flags above).
    #[arg(long, hide = true, value_name = "UM")]
    pub sigma_um: Option<f64>,
    /// Where the tracker's target sits (required for a tracker; no
    /// default): `tip`, `X,Y,Z` (a known offset, mm, spindle frame at zero
    /// head angles) or `free`.
    #[arg(long, value_name = "tip|X,Y,Z|free", allow_hyphen_values = true)]
    pub tracker_target: Option<TrackerTargetSpec>,
    /// Standard deviation of a known target offset, um.
    #[arg(long, default_value_t = 5.0, value_name = "UM")]
    pub tracker_target_sigma_um: f64,
    /// The ballbar's pivot, mm.
    #[arg(
        long,
        default_value = "0,0,1250",
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub ballbar_pivot_mm: String,
    /// The ballbar's nominal length, mm.
    #[arg(long, default_value_t = 150.0, value_name = "MM")]
    pub ballbar_length_mm: f64,
    /// Number of ballbar (or touch) candidate positions.
    #[arg(long, default_value_t = 300, value_name = "N")]
    pub ballbar_candidates: usize,
    /// The reference sphere (touch-offs).
    #[command(flatten)]
    pub touch: TouchSphereArgs,
    /// Effects in the model (as for `identify --effects`).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub effects: Vec<EffectNames>,
    /// The accuracy to reach, um: the report recommends the smallest
    /// planned k that predicts it and leaves its rows enough redundancy to
    /// check the fit.
    #[arg(long, value_name = "UM")]
    pub target_um: Option<f64>,
    /// Random selections per k for the baseline (0: none).
    #[arg(long, default_value_t = 50, value_name = "N")]
    pub random_baseline: usize,
    /// Seed of the random baseline.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Exchange passes at each k.
    #[arg(long, default_value_t = 10, value_name = "N")]
    pub passes: usize,
    /// Evaluation grid of the tool tip (as for `identify`).
    #[arg(long, default_value = "2,8,3", value_name = "RINGS,PER_RING,LEVELS")]
    pub eval_grid: EvalGrid,
    /// Head angles of the evaluation grid, deg.
    #[arg(long, default_value = "0,90,180,270:15,35", value_name = "H1S:H2S")]
    pub eval_head_angles_deg: HeadAngles,
    /// Write the planned poses for the largest k (CSV
    /// `q1,q2,q3,h1,h2[,extension_mm],x,y,z[,length][,feature]`: nominal
    /// tool tip, bar length, feature touched).
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// The instrument's noise: its own flag, or the old `--sigma-um`.
fn instrument_sigma(a: &PlanArgs, own: f64, flag: &str) -> Result<f64, CliError> {
    match a.sigma_um {
        Some(v) => positive("--sigma-um", v),
        None => positive(flag, own),
    }
}

/// The features file of a touch plan: one sphere (id 1) and the stylus.
pub fn touch_features(
    sphere_radius_mm: f64,
    stylus_radius_mm: f64,
    stylus_sigma_um: f64,
) -> tricept_data::Features {
    tricept_data::Features {
        stylus: tricept_data::Stylus {
            radius_mm: stylus_radius_mm,
            radius_sigma_um: stylus_sigma_um,
        },
        features: vec![tricept_data::Feature::Sphere {
            id: 1,
            radius_mm: sphere_radius_mm,
            radius_sigma_um: 0.5,
        }],
    }
}

/// `tricept plan`.
pub fn run(a: &PlanArgs) -> Result<u8, CliError> {
    let default_k = [3, 5, 8, 12, 20, 30, 50];
    let k: &[usize] = if a.k.is_empty() { &default_k } else { &a.k };
    let m = machine_with_noise(&a.machine, &a.noise)?;
    let set = a.params.set()?;
    let effects = crate::args::effect_names(&a.effects);
    let model = fused_model(&m, &set, &effects, HeadModel::Head13)?;
    let options = eval_options(&m, a.eval_grid, &a.eval_head_angles_deg)?;
    if k.contains(&0) {
        return Err(CliError::input("--k: expected positive whole numbers"));
    }
    if let Some(t) = a.target_um
        && !(t.is_finite() && t > 0.0)
    {
        return Err(CliError::input(format!(
            "--target-um: the accuracy to reach must be a positive number of um, got {t}"
        )));
    }
    for (flag, n, max) in [
        ("--passes", a.passes, limits::MAX_PASSES),
        (
            "--random-baseline",
            a.random_baseline,
            limits::MAX_RANDOM_BASELINE,
        ),
    ] {
        if n > max {
            return Err(CliError::input(format!("{flag}: {n}; at most {max}")));
        }
    }
    let (f_int, internal_poses) = match &a.data {
        Some(path) => {
            let data = read_data(path, &m)?;
            let f =
                information_factor(&model, &[Source::internal(&data, m.sensors.logged_sigma())])?;
            (f, data.poses.len())
        }
        None => {
            let targets = pose_targets(&a.poses, &m)?;
            let f = internal_factor(&model, &targets)
                .map_err(|e| CliError::input(format!("--poses {}: {e}", a.poses)))?;
            (f, targets.len())
        }
    };
    let (poses, source, centre) = match a.instrument {
        Instrument::Check => return run_check_plan(a),
        Instrument::Tracker => {
            let target = TrackerTargetSpec::required(a.tracker_target, a.tracker_target_sigma_um)?;
            let (h1, h2) = parse_head_angles("--head-angles-deg", &a.head_angles_deg)?;
            if a.extensions
                .iter()
                .any(|e| !e.is_finite() || e.abs() > 1000.0)
            {
                return Err(CliError::input(
                    "--extensions: expected extensions along the tool in mm, within ±1000",
                ));
            }
            let points = pose_targets(&a.candidates, &m)?;
            let count = points.len() * h1.len() * h2.len() * a.extensions.len().max(1);
            if count > limits::MAX_CANDIDATES {
                return Err(CliError::input(format!(
                    "--candidates {} with --head-angles-deg {}: {count} candidate poses; at most {}",
                    a.candidates,
                    a.head_angles_deg,
                    limits::MAX_CANDIDATES
                )));
            }
            let poses = with_extensions(&head_angle_poses(&m, &points, &h1, &h2), &a.extensions);
            let data = nominal_tracker_data(&model, &poses)?;
            let options = TrackerOptions {
                sigma_um: instrument_sigma(a, a.tracker_sigma_um, "--tracker-sigma-um")?,
                target,
            };
            let source = Source::tracker(&data, &options)?;
            (poses, source, None)
        }
        Instrument::Ballbar | Instrument::Touch => {
            let touch = a.instrument == Instrument::Touch;
            let (flag, text) = if touch {
                ("--touch-sphere-mm", &a.touch.touch_sphere_mm)
            } else {
                ("--ballbar-pivot-mm", &a.ballbar_pivot_mm)
            };
            let p = parse_numbers(flag, text, 3)?;
            let centre = Vector3::new(p[0], p[1], p[2]);
            let radius = if touch {
                positive("--touch-sphere-radius-mm", a.touch.touch_sphere_radius_mm)?
                    + positive("--touch-stylus-radius-mm", a.touch.touch_stylus_radius_mm)?
            } else {
                positive("--ballbar-length-mm", a.ballbar_length_mm)?
            };
            if a.ballbar_candidates > limits::MAX_CANDIDATES {
                return Err(CliError::input(format!(
                    "--ballbar-candidates: {}; at most {}",
                    a.ballbar_candidates,
                    limits::MAX_CANDIDATES
                )));
            }
            let poses = sphere_candidates(&m, &centre, radius, a.ballbar_candidates);
            if poses.len() < 4 {
                return Err(CliError::input(format!(
                    "{flag} {text}: the machine reaches only {} positions around this point",
                    poses.len()
                )));
            }
            let source = if touch {
                let data = nominal_touch_data(&poses, 1)?;
                let features = touch_features(
                    a.touch.touch_sphere_radius_mm,
                    a.touch.touch_stylus_radius_mm,
                    positive("--touch-stylus-sigma-um", a.touch.touch_stylus_sigma_um)?,
                );
                let options = tricept_engine::fusion::TouchOptions {
                    sigma_um: instrument_sigma(a, a.touch.touch_sigma_um, "--touch-sigma-um")?,
                };
                Source::touch(&data, &features, &options)?
            } else {
                let data = nominal_ballbar_data(&model, &poses, &centre)?;
                let options = tricept_engine::fusion::BallbarOptions {
                    sigma_um: instrument_sigma(a, a.ballbar_sigma_um, "--ballbar-sigma-um")?,
                    ..Default::default()
                };
                Source::ballbar(&data, &options)?
            };
            let poses = poses.into_iter().map(|p| (p, 0.0)).collect();
            (poses, source, Some(centre))
        }
    };
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
    let result = plan(&problem, k, a.passes, a.random_baseline, a.seed)?;
    let recommended = result.recommended(a.target_um, None);
    if let (Some(path), Some(last)) = (&a.out, result.rows.last()) {
        let p = vec![0.0; model.len()];
        let records = last
            .selection
            .iter()
            .map(|&c| {
                let (pose, extension_mm) = poses[c];
                let effector = tricept_model::Effector {
                    extension_mm,
                    ..Default::default()
                };
                let (x, _) = model.spindle_point(&p, &pose, &effector)?;
                Ok(PlannedPose {
                    pose,
                    extension_mm,
                    tip_mm: Some(x.into()),
                    length_mm: match a.instrument {
                        Instrument::Ballbar => centre.map(|c| (x - c).norm()),
                        _ => None,
                    },
                    feature: (a.instrument == Instrument::Touch).then_some(1),
                    line: 0,
                })
            })
            .collect::<Result<Vec<_>, CliError>>()?;
        let comments = vec![format!(
            "planned by tricept {} for a {:?}: {} measurements, RMS predicted tool-tip sd after touch-off {:.1} um, tool axis {:.1} arcsec, redundancy {:.1}",
            env!("CARGO_PKG_VERSION"),
            a.instrument,
            last.k,
            last.planned_um,
            last.axis_arcsec,
            last.redundancy
        )];
        crate::files::written(
            path,
            tricept_data::write_external_path(
                path,
                &ExternalData {
                    records,
                    source: String::new(),
                },
                &comments,
            ),
        )?;
    }
    if a.machine.json {
        outln!(
            "{}",
            json!({
                "instrument": format!("{:?}", a.instrument).to_lowercase(),
                "candidates": poses.len(),
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
            })
        );
    } else {
        outln!(
            "{:?}: {} candidates; criterion: RMS predicted tool-tip sd after touch-off{} over {} tool poses (um)",
            a.instrument,
            poses.len(),
            if axis { " and tool axis x 100 mm" } else { "" },
            options.eval_poses.len()
        );
        outln!(
            "prior only {:.1} um; internal campaign ({} poses) alone {:.1} um, tool axis {:.1} arcsec",
            result.prior_only_um,
            internal_poses,
            result.internal_only_um,
            result.internal_only_axis_arcsec
        );
        outln!(
            "{:>4} {:>10} {:>10} {:>14} {:>12} {:>11}",
            "k",
            "planned",
            "raw",
            "random median",
            "axis arcsec",
            "redundancy"
        );
        for r in &result.rows {
            outln!(
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
            outln!(
                "(!): fewer than {:.0} redundant rows: the fit could not check these measurements (a gross error or a wrong file would go unseen)",
                result.min_redundancy
            );
        }
        match (a.target_um, recommended) {
            (Some(t), Some(k)) => outln!(
                "recommended: {k} planned measurements (the smallest k asked for that predicts {t} um and leaves {:.0} redundant rows)",
                result.min_redundancy
            ),
            (Some(t), None) => {
                outln!("{t} um is not predicted with enough redundancy by any k asked for")
            }
            (None, Some(k)) => outln!(
                "recommended: at least {k} measurements (the smallest k asked for that leaves {:.0} redundant rows; --target-um adds an accuracy target)",
                result.min_redundancy
            ),
            (None, None) => outln!("no k asked for leaves enough redundant rows"),
        }
        outln!(
            "note: a linear-Gaussian prediction of variance only; an unmodelled effect's bias is not in it (docs/hybrid.md)"
        );
    }
    Ok(0)
}

/// `tricept plan --instrument check`: the fewest poses, up to `--k` (default
/// 20), whose check detects a change of `--detect-um` of platform error in
/// any single parameter with `--power` (`tricept_study::check_plan`).
fn run_check_plan(a: &PlanArgs) -> Result<u8, CliError> {
    let Some(path) = &a.machine.machine else {
        return Err(CliError::input(
            "plan --instrument check: --machine CALIBRATED.json is needed (a check is planned for a calibrated machine and its record)",
        ));
    };
    let budget = match a.k.as_slice() {
        [] => 20,
        k if k.contains(&0) => {
            return Err(CliError::input("--k: expected positive whole numbers"));
        }
        k => k.iter().copied().max().unwrap_or(20),
    };
    if budget > limits::MAX_CANDIDATES {
        return Err(CliError::input(format!(
            "--k: {budget} poses; at most {}",
            limits::MAX_CANDIDATES
        )));
    }
    if !(a.detect_um.is_finite() && a.detect_um > 0.0) {
        return Err(CliError::input(format!(
            "--detect-um: the change to detect must be a positive number of um, got {}",
            a.detect_um
        )));
    }
    if !(a.power > 0.0 && a.power < 1.0) {
        return Err(CliError::input(format!(
            "--power: must lie between 0 and 1, got {}",
            a.power
        )));
    }
    let loaded = crate::args::load_with_noise(&a.machine, &a.noise)?;
    let reference = tricept_check::Reference::from_description(loaded.description())
        .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
    let p = tricept_study::check_plan::plan_check(
        &reference,
        a.detect_um,
        a.power,
        tricept_check::DEFAULT_ALPHA,
        budget,
    )?;
    if let Some(out) = &a.out {
        let m = loaded.machine();
        let mut records = Vec::with_capacity(p.targets_mm.len());
        for r in &p.targets_mm {
            let q = m
                .inverse(r)
                .map_err(|e| CliError::with_context("plan", &e))?
                .legs_mm;
            records.push(format!(
                "{},{},{},{},{},{}",
                r.x, r.y, r.z, q[0], q[1], q[2]
            ));
        }
        let text = format!(
            "# tricept plan --instrument check: {} poses for `{}`; drive the machine to the commands q1,q2,q3 (mm) and log its readings\nx,y,z,q1,q2,q3\n{}\n",
            p.poses,
            loaded.description().name,
            records.join("\n")
        );
        crate::files::write_text(out, &text)?;
    }
    if a.machine.json {
        outln!(
            "{}",
            json!({
                "instrument": "check",
                "detect_um": a.detect_um,
                "power": a.power,
                "poses": p.poses,
                "reached": p.reached,
                "targets_mm": p.targets_mm.iter().map(|r| [r.x, r.y, r.z]).collect::<Vec<_>>(),
                "parameters": p.parameters,
            })
        );
    } else {
        outln!(
            "check of `{}`: {} poses {} a change of {} um of platform error in any single parameter with power {}{}",
            loaded.description().name,
            p.poses,
            if p.reached { "detect" } else { "do NOT detect" },
            a.detect_um,
            a.power,
            if p.reached {
                String::new()
            } else {
                format!(" (the budget --k {budget} is spent; more poses or a larger --detect-um)")
            }
        );
        outln!(
            "{:>6} {:>14} {:>18} {:>22} {:>8}",
            "param",
            "target um",
            "detectable um",
            "as platform error um",
            "power"
        );
        for d in &p.parameters {
            match (d.detectable_mm, d.detectable_platform_um, d.power) {
                (Some(det), Some(plat), Some(power)) => outln!(
                    "{:>6} {:>14.1} {:>18.1} {:>22.1} {:>8.3}",
                    d.name,
                    d.target_mm * 1e3,
                    det * 1e3,
                    plat,
                    power
                ),
                _ => outln!(
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
    Ok(0)
}
