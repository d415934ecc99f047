//! `tricept plan`: which few tracker points or ballbar readings to take,
//! given the internal campaign, so that the tool tip is best known after
//! touch-off; and the predicted accuracy against their number
//! (`tricept_study::plan`).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use nalgebra::Vector3;
use serde_json::json;
use tricept_data::{ExternalData, PlannedPose};
use tricept_ident::fusion::{Source, TrackerOptions, TrackerTarget, head_angle_poses, information};
use tricept_study::plan::{
    PlanProblem, ballbar_candidates, candidate_rows, internal_information, nominal_ballbar_data,
    nominal_tracker_data, plan,
};

use crate::args::{MachineArgs, NoiseArgs, ParamArgs, machine_with_noise, pose_targets, read_data};
use crate::cli_error::CliError;
use crate::fusion_cmd::{
    eval_options, fused_model, fusion_error, parse_head_angles, parse_numbers, positive,
};
use crate::limits;

/// The instrument to plan for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Instrument {
    /// A laser tracker or CMM on a target in the spindle.
    Tracker,
    /// A ballbar from the spindle ball to a pivot on the table.
    Ballbar,
}

/// `tricept plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The instrument.
    #[arg(long, value_enum)]
    pub instrument: Instrument,
    /// Numbers of measurements to plan for, comma-separated.
    #[arg(long, default_value = "3,5,8,12,20,30,50", value_delimiter = ',')]
    pub k: Vec<usize>,
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
    /// Noise of the instrument, um (default: 10 for a tracker coordinate,
    /// 1 for a ballbar reading).
    #[arg(long, value_name = "UM")]
    pub sigma_um: Option<f64>,
    /// A tracker target `tip` (at the tool tip, 5 um) or `free`.
    #[arg(long, default_value = "tip", value_name = "tip|free")]
    pub tracker_target: String,
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
    /// Number of ballbar candidate ball positions.
    #[arg(long, default_value_t = 300, value_name = "N")]
    pub ballbar_candidates: usize,
    /// Effects in the model (as for `identify --effects`).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub effects: Vec<String>,
    /// The accuracy to reach, um: the report names the smallest planned k
    /// that predicts it.
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
    pub eval_grid: String,
    /// Head angles of the evaluation grid, deg.
    #[arg(long, default_value = "0,90,180,270:15,35", value_name = "H1S:H2S")]
    pub eval_head_angles_deg: String,
    /// Write the planned poses for the largest k (CSV
    /// `q1,q2,q3,h1,h2,x,y,z[,length]`, nominal tool tip and bar length).
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept plan`.
pub fn run(a: &PlanArgs) -> Result<u8, CliError> {
    let m = machine_with_noise(&a.machine, &a.noise)?;
    let set = a.params.set()?;
    let model = fused_model(&m, &set, &a.effects, Some("head13"))?;
    let options = eval_options(&m, &a.eval_grid, &a.eval_head_angles_deg)?;
    if a.k.is_empty() || a.k.contains(&0) {
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
            let f = information(&model, &[Source::internal(&data, m.sensors.logged_sigma())])
                .map_err(fusion_error)?;
            (f, data.poses.len())
        }
        None => {
            let targets = pose_targets(&a.poses, &m)?;
            let f = internal_information(&model, &targets)
                .map_err(|e| CliError::input(format!("--poses {}: {e}", a.poses)))?;
            (f, targets.len())
        }
    };
    let (poses, source, pivot) = match a.instrument {
        Instrument::Tracker => {
            let (h1, h2) = parse_head_angles("--head-angles-deg", &a.head_angles_deg)?;
            let points = pose_targets(&a.candidates, &m)?;
            let count = points.len() * h1.len() * h2.len();
            if count > limits::MAX_CANDIDATES {
                return Err(CliError::input(format!(
                    "--candidates {} with --head-angles-deg {}: {count} candidate poses; at most {}",
                    a.candidates,
                    a.head_angles_deg,
                    limits::MAX_CANDIDATES
                )));
            }
            let poses = head_angle_poses(&m, &points, &h1, &h2);
            let target = match a.tracker_target.as_str() {
                "tip" => TrackerTarget::Known {
                    offset_mm: [0.0; 3],
                    sigma_um: 5.0,
                },
                "free" => TrackerTarget::Free,
                other => {
                    return Err(CliError::input(format!(
                        "--tracker-target: expected tip or free, got `{other}`"
                    )));
                }
            };
            let data = nominal_tracker_data(&model, &poses).map_err(study_error)?;
            let options = TrackerOptions {
                sigma_um: positive("--sigma-um", a.sigma_um.unwrap_or(10.0))?,
                target,
            };
            let source = Source::tracker(&data, &options).map_err(fusion_error)?;
            (poses, source, None)
        }
        Instrument::Ballbar => {
            let p = parse_numbers("--ballbar-pivot-mm", &a.ballbar_pivot_mm, 3)?;
            let pivot = Vector3::new(p[0], p[1], p[2]);
            let length = positive("--ballbar-length-mm", a.ballbar_length_mm)?;
            if a.ballbar_candidates > limits::MAX_CANDIDATES {
                return Err(CliError::input(format!(
                    "--ballbar-candidates: {}; at most {}",
                    a.ballbar_candidates,
                    limits::MAX_CANDIDATES
                )));
            }
            let poses = ballbar_candidates(&m, &pivot, length, a.ballbar_candidates);
            if poses.len() < 4 {
                return Err(CliError::input(format!(
                    "--ballbar-pivot-mm {}: the machine reaches only {} ball positions around this pivot",
                    a.ballbar_pivot_mm,
                    poses.len()
                )));
            }
            let data = nominal_ballbar_data(&model, &poses, &pivot).map_err(study_error)?;
            let options = tricept_ident::fusion::BallbarOptions {
                sigma_um: positive("--sigma-um", a.sigma_um.unwrap_or(1.0))?,
                ..Default::default()
            };
            let source = Source::ballbar(&data, &options).map_err(fusion_error)?;
            (poses, source, Some(pivot))
        }
    };
    let rows = candidate_rows(&model, &source).map_err(study_error)?;
    let problem =
        PlanProblem::new(&model, &f_int, &rows, &options.eval_poses).map_err(study_error)?;
    let result = plan(&problem, &a.k, a.passes, a.random_baseline, a.seed).map_err(study_error)?;
    let reached = a
        .target_um
        .and_then(|t| result.rows.iter().find(|r| r.planned_um <= t).map(|r| r.k));
    if let (Some(path), Some(last)) = (&a.out, result.rows.last()) {
        let p = vec![0.0; model.len()];
        let records = last
            .selection
            .iter()
            .map(|&c| {
                let (x, _) = model
                    .spindle_point(&p, &poses[c], &Default::default())
                    .map_err(fusion_error)?;
                Ok(PlannedPose {
                    pose: poses[c],
                    extension_mm: 0.0,
                    tip_mm: Some(x.into()),
                    length_mm: pivot.map(|c| (x - c).norm()),
                    line: 0,
                })
            })
            .collect::<Result<Vec<_>, CliError>>()?;
        let comments = vec![format!(
            "planned by tricept {} for a {:?}: {} measurements, RMS predicted tool-tip sd after touch-off {:.1} um",
            env!("CARGO_PKG_VERSION"),
            a.instrument,
            last.k,
            last.planned_um
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
                "criterion": "RMS over the evaluation poses of the predicted tool-tip standard deviation after touch-off, um",
                "prior_only_um": result.prior_only_um,
                "internal_only_um": result.internal_only_um,
                "rows": result.rows.iter().map(|r| json!({
                    "k": r.k, "planned_um": r.planned_um, "planned_raw_um": r.planned_raw_um,
                    "random_median_um": r.random_median_um,
                })).collect::<Vec<_>>(),
                "target_um": a.target_um,
                "k_for_target": reached,
            })
        );
    } else {
        outln!(
            "{:?}: {} candidates; criterion: RMS predicted tool-tip sd after touch-off over {} tool poses (um)",
            a.instrument,
            poses.len(),
            options.eval_poses.len()
        );
        outln!(
            "prior only {:.1} um; internal campaign ({} poses) alone {:.1} um",
            result.prior_only_um,
            internal_poses,
            result.internal_only_um
        );
        outln!(
            "{:>4} {:>10} {:>10} {:>14}",
            "k",
            "planned",
            "raw",
            "random median"
        );
        for r in &result.rows {
            outln!(
                "{:>4} {:>10.1} {:>10.1} {:>14}",
                r.k,
                r.planned_um,
                r.planned_raw_um,
                r.random_median_um.map_or("-".into(), |v| format!("{v:.1}"))
            );
        }
        if let Some(t) = a.target_um {
            match reached {
                Some(k) => outln!("{t} um is predicted with {k} planned measurements"),
                None => outln!("{t} um is not predicted with any k asked for"),
            }
        }
        outln!(
            "note: a linear-Gaussian prediction of variance only; an unmodelled effect's bias is not in it (docs/hybrid.md)"
        );
    }
    Ok(0)
}

fn study_error(e: tricept_study::StudyError) -> CliError {
    match e {
        tricept_study::StudyError::Ident(e) => fusion_error(e),
        tricept_study::StudyError::Invalid(m) => CliError::input(m),
        e => CliError::other(e.to_string()),
    }
}
