//! `tricept simulate`: a measured-data CSV from a simulated machine.

use std::path::PathBuf;

use clap::Args;
use tricept_engine::GeometricModel;
use tricept_plant::{Campaign, Plant, PoseOrder};

use crate::args::{
    MachineArgs, NoiseArgs, ParamArgs, TouchSphereArgs, TruthArgs, machine_with_noise,
    parse_errors, pose_targets,
};
use crate::cli_error::CliError;
use tricept_ident::{parse_effects, parse_numbers, positive};

/// `tricept simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub truth: TruthArgs,
    /// Pose set (as for `identifiability`; positions in mm).
    #[arg(long, default_value = "grid")]
    pub poses: String,
    /// Seed of the sensor noise (a whole number).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub seed: u64,
    /// Visit every pose twice, approaching from both directions.
    #[arg(long)]
    pub both_directions: bool,
    /// Revisit the first N targets at the end of the campaign (separate
    /// visits of the same commands: what `diagnose --noise-from-data` uses).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub revisit: usize,
    /// Make the true noise this many times the machine's stated noise
    /// (vibration, a sensor worse than its data sheet).
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub noise_factor: f64,
    /// Output file (default: stdout; with --json, a summary goes to stdout).
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    /// Head errors of the simulated machine: `zero`, `random:SCALE[,SEED]`
    /// (each of the 13 parameters SCALE times its typical size, times 0.5-1,
    /// random sign), or a JSON file `{name: value}` (docs/hybrid.md).
    #[arg(long, default_value = "zero", value_name = "HEAD")]
    pub head_errors: String,
    /// Also write laser-tracker points (CSV) measured at the poses of
    /// --tracker-poses.
    #[arg(long, value_name = "FILE.csv")]
    pub tracker_out: Option<PathBuf>,
    /// Poses for the tracker (CSV `q1,q2,q3,h1,h2[,extension_mm]`, as
    /// `tricept plan --out` writes them).
    #[arg(long, value_name = "FILE.csv")]
    pub tracker_poses: Option<PathBuf>,
    /// The tracker's frame: translation (mm) and rotation vector (rad) that
    /// map the machine's base frame into the tracker's.
    #[arg(
        long,
        default_value = "1500,-800,200,0.1,0.2,0.3",
        value_name = "X,Y,Z,RX,RY,RZ",
        allow_hyphen_values = true
    )]
    pub tracker_frame_mm_rad: String,
    /// The tracker target's offset from the tool tip, mm (spindle frame at
    /// zero head angles).
    #[arg(
        long,
        default_value = "0,0,0",
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub tracker_target_mm: String,
    /// Noise of a tracker coordinate, um.
    #[arg(long, default_value_t = 10.0, value_name = "UM")]
    pub tracker_sigma_um: f64,
    /// Also write ballbar readings (CSV) at the poses of --ballbar-poses.
    #[arg(long, value_name = "FILE.csv")]
    pub ballbar_out: Option<PathBuf>,
    /// Poses for the ballbar (CSV `q1,q2,q3,h1,h2`).
    #[arg(long, value_name = "FILE.csv")]
    pub ballbar_poses: Option<PathBuf>,
    /// The ballbar's pivot on the table, mm.
    #[arg(
        long,
        default_value = "0,0,1250",
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub ballbar_pivot_mm: String,
    /// The bar's reading minus the true distance, um.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "UM",
        allow_hyphen_values = true
    )]
    pub ballbar_length_error_um: f64,
    /// Noise of a ballbar reading, um.
    #[arg(long, default_value_t = 1.0, value_name = "UM")]
    pub ballbar_sigma_um: f64,
    /// Also write touch-offs (CSV) at the planned touches of --touch-poses
    /// (needs --features-out).
    #[arg(long, value_name = "FILE.csv")]
    pub touch_out: Option<PathBuf>,
    /// The features file of the touch-offs (JSON: the stylus and the
    /// reference sphere, as a user would write it).
    #[arg(long, value_name = "FILE.json")]
    pub features_out: Option<PathBuf>,
    /// Planned touches (CSV `q1,q2,q3,h1,h2,x,y,z,feature`, as `tricept plan
    /// --instrument touch --out` writes them).
    #[arg(long, value_name = "FILE.csv")]
    pub touch_poses: Option<PathBuf>,
    /// The reference sphere as it truly is (feature 1), the stylus' nominal
    /// radius and noise.
    #[command(flatten)]
    pub touch: TouchSphereArgs,
    /// The stylus' true radius minus the nominal one, um.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "UM",
        allow_hyphen_values = true
    )]
    pub touch_stylus_error_um: f64,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept simulate`.
pub fn run(a: &SimulateArgs) -> Result<u8, CliError> {
    if a.machine.json && a.out.is_none() {
        return Err(CliError::input(
            "--json: needs --out FILE.csv (without it the CSV itself goes to stdout)",
        ));
    }
    let m = machine_with_noise(&a.machine, &a.noise)?;
    let set = a.params.set()?;
    let truth = a.truth.truth.as_deref().unwrap_or("table2");
    let values = parse_errors(truth, &set)?;
    let targets = pose_targets(&a.poses, &m)?;
    let mut campaign = Campaign::from_targets(&m, targets, a.seed);
    if a.both_directions {
        campaign.order = PoseOrder::BothDirections;
    }
    if !(a.noise_factor.is_finite() && a.noise_factor > 0.0) {
        return Err(CliError::input(format!(
            "--noise-factor: must be a positive number, got {}",
            a.noise_factor
        )));
    }
    campaign.revisits = a.revisit;
    campaign.noise_factor = a.noise_factor;
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&values));
    plant.effects = parse_effects(&a.truth.truth_effects)?;
    plant.head_errors = parse_head_errors(&a.head_errors, &m)?;
    let data = plant
        .simulate(&campaign)
        .map_err(|e| CliError::input(format!("simulate: {e}")))?;
    let model = GeometricModel::new(m.clone(), set.clone());
    let mut comments = vec![
        format!(
            "simulated by tricept {} on `{}`",
            env!("CARGO_PKG_VERSION"),
            m.name
        ),
        format!(
            "pose set `{}` ({} poses{}{}), seed {}",
            a.poses,
            data.poses.len(),
            if a.both_directions {
                ", both approach directions"
            } else {
                ""
            },
            if a.revisit > 0 {
                format!(", the first {} revisited at the end", a.revisit)
            } else {
                String::new()
            },
            a.seed
        ),
        format!(
            "noise per reading: {:.3} arcsec, {:.3} um, mean of {}{}",
            m.sensors.angle_rad / tricept_kinematics::units::RAD_PER_ARCSEC,
            m.sensors.length_mm * 1e3,
            m.sensors.readings_per_pose,
            if a.noise_factor == 1.0 {
                String::new()
            } else {
                format!(" (stated; the true noise is {} times it)", a.noise_factor)
            }
        ),
        format!(
            "true errors ({}, mm): {}",
            model.parameter_set().label(),
            serde_json::Value::Object(set.values_to_map(&values))
        ),
        format!(
            "sensor zero offsets (phi rad, theta rad, s mm): {:?}",
            plant.sensor_offsets
        ),
    ];
    for e in &plant.effects {
        comments.push(format!(
            "effect: {}",
            serde_json::to_string(e).unwrap_or_default()
        ));
    }
    if !plant.head_errors.is_empty() {
        comments.push(format!(
            "head errors (head13): {}",
            serde_json::Value::Object(
                tricept_model::HeadParameterSet::head13(&m.head).values_to_map(&plant.head_errors)
            )
        ));
    }
    simulate_external(a, &plant, &comments)?;
    match &a.out {
        Some(path) => {
            crate::files::written(path, tricept_data::write_path(path, &data, &comments))?;
            if a.machine.json {
                outln!(
                    "{}",
                    serde_json::json!({
                        "out": path.display().to_string(),
                        "poses": data.poses.len(),
                        "seed": a.seed,
                        "machine": m.name,
                        "parameter_set": set.label(),
                        "truth_mm": serde_json::Value::Object(set.values_to_map(&values)),
                        "truth_effects": plant.effects,
                        "sensor_offsets": {"phi_rad": plant.sensor_offsets[0], "theta_rad": plant.sensor_offsets[1], "s_mm": plant.sensor_offsets[2]},
                    })
                );
            } else {
                errln!(
                    "{} poses to {} (machine `{}`, true errors `{truth}`, {} effect(s), seed {})",
                    data.poses.len(),
                    path.display(),
                    m.name,
                    plant.effects.len(),
                    a.seed
                );
            }
        }
        // A closed stdout (`| head`) is not an error: the writer swallows it.
        None => tricept_data::write_to(
            std::io::BufWriter::new(crate::output::Stdout),
            &data,
            &comments,
        )
        .map_err(|e| CliError::other(format!("stdout: {e}")))?,
    }
    Ok(0)
}

/// Parses `--head-errors`.
fn parse_head_errors(spec: &str, m: &tricept_kinematics::Machine) -> Result<Vec<f64>, CliError> {
    let flag = "--head-errors";
    match spec {
        "zero" => Ok(Vec::new()),
        s if s.starts_with("random:") => {
            let parts: Vec<&str> = s["random:".len()..].split(',').collect();
            let scale: f64 = parts[0]
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && (0.0..=100.0).contains(v))
                .ok_or_else(|| {
                    CliError::input(format!(
                        "{flag} `{s}`: expected random:SCALE[,SEED] with SCALE (times the typical sizes) from 0 to 100"
                    ))
                })?;
            let seed: u64 = match parts.get(1) {
                Some(t) => t.parse().map_err(|_| {
                    CliError::input(format!("{flag} `{s}`: SEED must be a whole number"))
                })?,
                None => 0,
            };
            Ok(tricept_plant::random_head_errors(scale, seed))
        }
        path => {
            let text = tricept_data::read_json_text(std::path::Path::new(path))
                .map_err(|e| CliError::input(format!("{flag}: {path}: {e}")))?;
            tricept_model::HeadParameterSet::head13(&m.head)
                .parse_values(&text)
                .map_err(|e| CliError::input(format!("{flag}: {path}: {e}")))
        }
    }
}

/// The poses of a poses file (every record with its extension).
fn read_poses(path: &std::path::Path) -> Result<Vec<(tricept_data::ExternalPose, f64)>, CliError> {
    Ok(
        tricept_data::read_external_path::<tricept_data::PlannedPose>(path)
            .map_err(|e| CliError::input(e.to_string()))?
            .records
            .iter()
            .map(|p| (p.pose, p.extension_mm))
            .collect(),
    )
}

/// Writes the external instruments' files that were asked for.
fn simulate_external(a: &SimulateArgs, plant: &Plant, comments: &[String]) -> Result<(), CliError> {
    let failed = |e: tricept_plant::PlantError| CliError::input(format!("simulate: {e}"));
    match (&a.tracker_out, &a.tracker_poses) {
        (Some(out), Some(poses)) => {
            let f = parse_numbers("--tracker-frame-mm-rad", &a.tracker_frame_mm_rad, 6)?;
            let t = parse_numbers("--tracker-target-mm", &a.tracker_target_mm, 3)?;
            let tracker = tricept_plant::Tracker {
                frame: nalgebra::Isometry3::new(
                    nalgebra::Vector3::new(f[0], f[1], f[2]),
                    nalgebra::Vector3::new(f[3], f[4], f[5]),
                ),
                target_offset_mm: nalgebra::Vector3::new(t[0], t[1], t[2]),
                sigma_um: positive("--tracker-sigma-um", a.tracker_sigma_um)?,
                setup: 1,
            };
            let data = tracker
                .measure(plant, &read_poses(poses)?, a.seed)
                .map_err(failed)?;
            let mut c = comments.to_vec();
            c.push(format!(
                "tracker: frame (mm, rad) {}, target offset (mm) {}, {} um per coordinate",
                a.tracker_frame_mm_rad, a.tracker_target_mm, a.tracker_sigma_um
            ));
            crate::files::written(out, tricept_data::write_external_path(out, &data, &c))?;
        }
        (None, None) => {}
        _ => {
            return Err(CliError::input(
                "--tracker-out and --tracker-poses go together",
            ));
        }
    }
    match (&a.ballbar_out, &a.ballbar_poses) {
        (Some(out), Some(poses)) => {
            let p = parse_numbers("--ballbar-pivot-mm", &a.ballbar_pivot_mm, 3)?;
            let bar = tricept_plant::Ballbar {
                pivot_mm: nalgebra::Vector3::new(p[0], p[1], p[2]),
                length_error_um: a.ballbar_length_error_um,
                ball_offset_mm: nalgebra::Vector3::zeros(),
                sigma_um: positive("--ballbar-sigma-um", a.ballbar_sigma_um)?,
                setup: 1,
            };
            let poses: Vec<_> = read_poses(poses)?.into_iter().map(|(p, _)| p).collect();
            let data = bar.measure(plant, &poses, a.seed).map_err(failed)?;
            let mut c = comments.to_vec();
            c.push(format!(
                "ballbar: pivot (mm) {}, length error {} um, {} um per reading",
                a.ballbar_pivot_mm, a.ballbar_length_error_um, a.ballbar_sigma_um
            ));
            crate::files::written(out, tricept_data::write_external_path(out, &data, &c))?;
        }
        (None, None) => {}
        _ => {
            return Err(CliError::input(
                "--ballbar-out and --ballbar-poses go together",
            ));
        }
    }
    match (&a.touch_out, &a.features_out, &a.touch_poses) {
        (Some(out), Some(features_out), Some(poses)) => {
            simulate_touches(a, plant, comments, out, features_out, poses)?
        }
        (None, None, None) => {}
        _ => {
            return Err(CliError::input(
                "--touch-out, --features-out and --touch-poses go together",
            ));
        }
    }
    Ok(())
}

/// Writes simulated touch-offs on the reference sphere at the planned
/// touches, and the features file a user would write.
fn simulate_touches(
    a: &SimulateArgs,
    plant: &Plant,
    comments: &[String],
    out: &std::path::Path,
    features_out: &std::path::Path,
    poses: &std::path::Path,
) -> Result<(), CliError> {
    let c = parse_numbers("--touch-sphere-mm", &a.touch.touch_sphere_mm, 3)?;
    let centre = nalgebra::Vector3::new(c[0], c[1], c[2]);
    let probe = tricept_plant::TouchProbe {
        stylus_radius_mm: positive("--touch-stylus-radius-mm", a.touch.touch_stylus_radius_mm)?,
        stylus_radius_error_um: a.touch_stylus_error_um,
        stylus_radius_sigma_um: positive("--touch-stylus-sigma-um", a.touch.touch_stylus_sigma_um)?,
        sigma_um: positive("--touch-sigma-um", a.touch.touch_sigma_um)?,
        features: vec![tricept_plant::TouchFeature::Sphere {
            id: 1,
            centre_mm: centre,
            radius_mm: positive("--touch-sphere-radius-mm", a.touch.touch_sphere_radius_mm)?,
        }],
    };
    let planned = tricept_data::read_external_path::<tricept_data::PlannedPose>(poses)
        .map_err(|e| CliError::input(e.to_string()))?;
    let nominal = &plant.nominal;
    let targets = planned
        .records
        .iter()
        .map(|p| {
            let at = |e: tricept_kinematics::KinematicsError| {
                CliError::input(format!("{}: line {}: {e}", planned.source, p.line))
            };
            if p.feature.is_some_and(|f| f != 1) {
                return Err(CliError::input(format!(
                    "{}: line {}, column `feature`: the simulated probe touches sphere 1 only",
                    planned.source, p.line
                )));
            }
            let up = nominal.forward(&p.pose.commands_mm).map_err(at)?.up;
            let tool = nominal.tool_forward(&up, p.pose.head_rad);
            Ok(tricept_plant::TouchTarget {
                feature: 1,
                tip_mm: tool.tip_mm,
                axis: tool.axis,
                approach: (centre - tool.tip_mm).normalize(),
            })
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    let data = probe
        .measure(plant, &targets, a.seed)
        .map_err(|e| CliError::input(format!("simulate: {}: {e}", planned.source)))?;
    let mut c = comments.to_vec();
    c.push(format!(
        "touch probe: sphere 1 at (mm) {}, radius {} mm; stylus {} mm ({} um off); {} um per touch",
        a.touch.touch_sphere_mm,
        a.touch.touch_sphere_radius_mm,
        a.touch.touch_stylus_radius_mm,
        a.touch_stylus_error_um,
        a.touch.touch_sigma_um
    ));
    crate::files::written(out, tricept_data::write_external_path(out, &data, &c))?;
    let features = serde_json::to_string_pretty(&probe.features_file(0.5))
        .map_err(|e| CliError::other(e.to_string()))?;
    crate::files::write_text(features_out, &(features + "\n"))
}
