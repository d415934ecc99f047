//! The self-calibration verbs: `identifiability`, `identify`, `compensate`.

use std::path::PathBuf;

use clap::Args;
use nalgebra::Vector3;
use serde_json::{Map, Value, json};
use tricept_data::MeasuredPose;
use tricept_ident::{
    GeometricModel, IdentError, Identification, IdentifyOptions, Rejection, corrected_commands,
    identifiability, identify, identify_robust,
};
use tricept_kinematics::Machine;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_model::{ErrorMap, MapStats, volumetric_errors};

use crate::args::{
    FitArgs, MachineArgs, NoiseArgs, ParamArgs, machine_with_noise, parse_effects, parse_errors,
    pose_targets, read_data, spinner,
};
use crate::cli_error::CliError;

/// `tricept identifiability`.
#[derive(Debug, Args)]
pub struct IdentifiabilityArgs {
    /// Pose set (see below).
    #[arg(long, default_value = "grid")]
    pub poses: String,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// The data and fit settings of `identify` and `compensate`.
#[derive(Debug, Args)]
pub struct DataFitArgs {
    /// Measured-data CSV (see docs/data-format.md).
    #[arg(long, value_name = "FILE.csv")]
    pub data: PathBuf,
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept identify`.
#[derive(Debug, Args)]
pub struct IdentifyArgs {
    #[command(flatten)]
    pub input: DataFitArgs,
    /// Also write the identified machine as a description file.
    #[arg(long, value_name = "FILE.json")]
    pub write_machine: Option<PathBuf>,
    /// External measurements and the head (the fused identification).
    #[command(flatten)]
    pub external: crate::fusion_cmd::ExternalArgs,
}

/// `tricept compensate`.
#[derive(Debug, Args)]
pub struct CompensateArgs {
    #[command(flatten)]
    pub input: DataFitArgs,
    /// True errors of the machine that produced the data (simulations).
    #[arg(long, value_name = "ERRORS")]
    pub truth: Option<String>,
    /// An unmodelled effect of the true machine (JSON or @FILE, as for
    /// `simulate`); repeatable; used with --truth.
    #[arg(long = "truth-effect", value_name = "JSON")]
    pub truth_effects: Vec<String>,
    /// Plane of the error map, mm (default: the workspace's middle plane).
    #[arg(long, value_name = "Z_MM", allow_negative_numbers = true)]
    pub plane_z: Option<f64>,
    /// Lattice spacing of the error map, mm.
    #[arg(long, default_value_t = 10.0, value_name = "MM")]
    pub spacing: f64,
    /// Target points (CSV x,y,z) to print corrected leg commands for.
    #[arg(long, value_name = "FILE.csv")]
    pub targets: Option<PathBuf>,
}

fn ident_error(source: &str, e: IdentError) -> CliError {
    match &e {
        IdentError::TooFewPoses { .. } => CliError::input(format!("{source}: {e}")),
        IdentError::Kinematics {
            line, source: k, ..
        } => CliError::input(format!(
            "{source}: line {line}: the commands of this pose cannot be reached: {k}"
        )),
        _ => CliError::other(format!("{source}: {e}")),
    }
}

/// `tricept identifiability`.
pub fn run_identifiability(a: &IdentifiabilityArgs) -> Result<(), CliError> {
    let (machine, poses) = (&a.machine, a.poses.as_str());
    let m = machine_with_noise(machine, &a.noise)?;
    let set = a.params.set()?;
    let targets = pose_targets(poses, &m)?;
    let mut commands = Vec::with_capacity(targets.len());
    for (i, r) in targets.iter().enumerate() {
        let ik = m.inverse(r).map_err(|e| {
            CliError::input(format!("--poses {poses}: pose {} ({r:?}): {e}", i + 1))
        })?;
        commands.push(MeasuredPose {
            commands_mm: ik.legs_mm,
            ..Default::default()
        });
    }
    let model = GeometricModel::new(m.clone(), set.clone());
    let report = identifiability(
        &model,
        &vec![0.0; set.len()],
        &commands,
        &IdentifyOptions::for_machine(&m),
    )
    .map_err(|e| ident_error(&format!("--poses {poses}"), e))?;
    if machine.json {
        let mut v = report.to_json();
        if let Value::Object(o) = &mut v {
            o.insert("parameter_set".into(), set.label().into());
            o.insert("axis_order".into(), m.up_limb.axis_order.to_string().into());
        }
        outln!("{v}");
    } else {
        outln!(
            "{} ({} U joint), parameter set {}, pose set `{poses}`",
            m.name,
            m.up_limb.axis_order,
            set.label()
        );
        print!("{}", report.to_text());
    }
    Ok(())
}

/// Loads data and identifies; shared by `identify` and `compensate`.
fn identify_from_file(
    a: &DataFitArgs,
) -> Result<(Machine, GeometricModel, Identification, Vec<Rejection>), CliError> {
    let data = a.data.as_path();
    let m = machine_with_noise(&a.machine, &a.noise)?;
    let set = a.params.set()?;
    let dataset = read_data(data, &m)?;
    let model = GeometricModel::new(m.clone(), set);
    let options = IdentifyOptions::for_machine(&m);
    let source = data.display().to_string();
    let spin = spinner(
        format!("identifying from {} poses", dataset.poses.len()),
        dataset.poses.len(),
    );
    let (id, rejected) = if a.fit.no_robust {
        (
            identify(&model, &dataset, &options).map_err(|e| ident_error(&source, e))?,
            Vec::new(),
        )
    } else {
        identify_robust(&model, &dataset, &options).map_err(|e| ident_error(&source, e))?
    };
    spin.finish_and_clear();
    Ok((m, model, id, rejected))
}

/// `tricept identify`.
pub fn run_identify(a: &IdentifyArgs) -> Result<(), CliError> {
    if a.external.any() {
        return crate::fusion_cmd::run(a);
    }
    let (machine, data) = (&a.input.machine, a.input.data.as_path());
    let (_, model, id, rejected) = identify_from_file(&a.input)?;
    if let Some(path) = &a.write_machine {
        let mut d = model.machine_at(&id.estimate).to_description();
        d.notes = Some(format!("identified from {}", data.display()));
        std::fs::write(path, d.to_json())
            .map_err(|e| CliError::other(format!("{}: {e}", path.display())))?;
    }
    if machine.json {
        let mut v = id.to_json();
        if let Value::Object(o) = &mut v {
            o.insert(
                "rejected".into(),
                serde_json::to_value(&rejected).unwrap_or(Value::Null),
            );
        }
        outln!("{v}");
        return Ok(());
    }
    for r in &rejected {
        outln!(
            "rejected line {} of {}: a reading {:.1} noise standard deviations off (gross error)",
            r.line,
            data.display(),
            r.residual_sigma.unwrap_or(f64::INFINITY)
        );
    }
    outln!(
        "{} poses, parameter set {}: {} in {} Gauss-Newton iterations",
        id.residuals.len(),
        model.parameter_set().label(),
        if id.converged {
            "converged"
        } else {
            "NOT converged"
        },
        id.iterations
    );
    outln!("{:>6} {:>12} {:>10}", "param", "estimate mm", "sd mm");
    for ((n, v), sd) in id.names.iter().zip(&id.estimate).zip(&id.std_dev) {
        match sd {
            Some(s) => outln!("{n:>6} {v:>12.5} {s:>10.5}"),
            None => outln!("{n:>6} {v:>12.5} {:>10}", "fixed"),
        }
    }
    let a = RAD_PER_ARCSEC;
    outln!(
        "offsets: phi {:.6} rad, theta {:.6} rad, s {:.4} mm",
        id.offsets[0],
        id.offsets[1],
        id.offsets[2]
    );
    outln!(
        "residual rms: phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um; chi2/dof {:.3} (dof {}); largest {:.1} sigma at pose {}",
        id.stats.rms[0] / a,
        id.stats.rms[1] / a,
        id.stats.rms[2] * 1e3,
        id.stats.reduced_chi_square,
        id.stats.dof,
        id.stats.max_standardised.0,
        id.stats.max_standardised.1 + 1
    );
    print!("{}", id.report.to_text());
    Ok(())
}

fn stats_json(s: &MapStats) -> Value {
    json!({"max_mm": s.max_mm, "min_mm": s.min_mm, "mean_mm": s.mean_mm, "rms_mm": s.rms_mm})
}

/// `tricept compensate`.
pub fn run_compensate(a: &CompensateArgs) -> Result<(), CliError> {
    let (machine, plane_z_mm, spacing_mm) = (&a.input.machine, a.plane_z, a.spacing);
    let (m, model, id, rejected) = identify_from_file(&a.input)?;
    let identified = model.machine_at(&id.estimate);
    let z = plane_z_mm.unwrap_or_else(|| m.workspace.mid_plane_z_mm());
    if !(spacing_mm.is_finite() && spacing_mm >= 1.0) {
        return Err(CliError::input("--spacing: must be at least 1 mm"));
    }
    let grid = m.workspace.disc_grid(z, spacing_mm);
    let mut out = Map::new();
    // What compensation changes, as the identified model sees it.
    let predicted = volumetric_errors(&m, &identified, &grid)
        .map_err(|e| CliError::other(format!("compensation map: {e}")))?;
    out.insert("plane_z_mm".into(), z.into());
    out.insert(
        "rejected_lines".into(),
        Value::Array(rejected.iter().map(|r| Value::from(r.line)).collect()),
    );
    out.insert("grid_points".into(), grid.len().into());
    out.insert(
        "predicted_correction".into(),
        stats_json(&predicted.stats()),
    );
    if let Some(spec) = &a.truth {
        let set = model.parameter_set();
        let mut plant =
            tricept_plant::Plant::geometric(m.clone(), set.to_errors(&parse_errors(spec, set)?));
        plant.effects = parse_effects(&a.truth_effects)?;
        // Where the actual machine goes when commanded by a model's IK.
        let map = |commanding: &tricept_kinematics::Machine| -> Result<ErrorMap, CliError> {
            let mut errors = Vec::with_capacity(grid.len());
            for r in &grid {
                let q = commanding
                    .inverse(r)
                    .map_err(|e| CliError::other(format!("compensation map: {e}")))?
                    .legs_mm;
                let reached = plant
                    .reach(&q)
                    .map_err(|e| CliError::other(format!("compensation map: {e}")))?;
                errors.push(reached - r);
            }
            Ok(ErrorMap {
                targets_mm: grid.clone(),
                errors_mm: errors,
            })
        };
        let (before, after) = (map(&m)?, map(&identified)?);
        let residual = after.without_mean_translation();
        let t = after.mean_translation_mm();
        out.insert("before".into(), stats_json(&before.stats()));
        out.insert("after".into(), stats_json(&after.stats()));
        out.insert(
            "after_without_translation".into(),
            stats_json(&residual.stats()),
        );
        out.insert("translation_mm".into(), json!([t.x, t.y, t.z]));
    }
    if let Some(path) = &a.targets {
        let points: Vec<Vector3<f64>> = tricept_data::read_targets(path)
            .map_err(|e| CliError::input(e.to_string()))?
            .into_iter()
            .map(Vector3::from)
            .collect();
        let commands = corrected_commands(&identified, &points)
            .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
        out.insert(
            "corrected_commands".into(),
            Value::Array(
                points
                    .iter()
                    .zip(&commands)
                    .map(|(r, q)| json!({"x": r.x, "y": r.y, "z": r.z, "q1": q[0], "q2": q[1], "q3": q[2]}))
                    .collect(),
            ),
        );
    }
    if machine.json {
        outln!("{}", Value::Object(out));
    } else {
        outln!(
            "compensation over the plane z = {z} mm ({} points, {spacing_mm} mm lattice)",
            grid.len()
        );
        for key in [
            "predicted_correction",
            "before",
            "after",
            "after_without_translation",
        ] {
            if let Some(s) = out.get(key) {
                outln!(
                    "{key:>26}: max {:.4} / min {:.4} / mean {:.4} mm",
                    s["max_mm"].as_f64().unwrap_or(f64::NAN),
                    s["min_mm"].as_f64().unwrap_or(f64::NAN),
                    s["mean_mm"].as_f64().unwrap_or(f64::NAN)
                );
            }
        }
        if let Some(t) = out.get("translation_mm") {
            outln!("{:>26}: {t} mm", "rigid translation");
        }
        if let Some(Value::Array(rows)) = out.get("corrected_commands") {
            outln!("x,y,z,q1,q2,q3");
            for r in rows {
                outln!(
                    "{},{},{},{},{},{}",
                    r["x"],
                    r["y"],
                    r["z"],
                    r["q1"],
                    r["q2"],
                    r["q3"]
                );
            }
        }
    }
    Ok(())
}
