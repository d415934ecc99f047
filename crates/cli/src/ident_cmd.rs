//! The self-calibration verbs: `identifiability`, `identify`, `compensate`.

use clap::Args;
use nalgebra::Vector3;
use serde_json::{Map, Value, json};
use tricept_data::{Dataset, MeasuredPose};
use tricept_ident::{
    GeometricModel, IdentError, Identification, IdentifyOptions, Rejection, corrected_commands,
    identifiability, identify, identify_robust,
};
use tricept_kinematics::{Machine, SensorNoise};
use tricept_model::{ErrorMap, MapStats, ParameterSet, volumetric_errors};

use crate::MachineArgs;
use crate::cli_error::CliError;
use crate::kinematics_cmd::load_machine;

/// Sensor-noise overrides (default: the machine description's).
#[derive(Debug, Args, Clone, Default)]
pub struct NoiseArgs {
    /// Encoder noise of one reading, arcsec.
    #[arg(long, value_name = "ARCSEC", allow_hyphen_values = true)]
    pub angle_noise_arcsec: Option<f64>,
    /// Linear-scale noise of one reading, um.
    #[arg(long, value_name = "UM", allow_hyphen_values = true)]
    pub length_noise_um: Option<f64>,
    /// Readings averaged into one logged value.
    #[arg(long, value_name = "N")]
    pub readings_per_pose: Option<u32>,
}

/// The parameter set to identify.
#[derive(Debug, Args, Clone)]
pub struct ParamArgs {
    /// Parameter set: `paper15` (the paper's 15, under its frame
    /// conventions) or `full21` (all joint and length errors; reports the
    /// rigid-body gauges as unidentifiable).
    #[arg(long, default_value = "paper15", value_name = "SET")]
    pub params: String,
}

impl ParamArgs {
    /// The parameter set named by `--params`.
    pub fn set(&self) -> Result<ParameterSet, CliError> {
        ParameterSet::by_label(&self.params).map_err(|e| CliError::input(format!("--params: {e}")))
    }
}

/// How to fit.
#[derive(Debug, Args, Clone, Default)]
pub struct FitArgs {
    /// Keep every pose: do not reject gross reading errors (by default,
    /// poses beyond the Bonferroni-corrected 0.1 % quantile of the
    /// standardised residuals are rejected and reported).
    #[arg(long)]
    pub no_robust: bool,
}

/// Loads the machine and applies the noise overrides.
pub fn machine_with_noise(args: &MachineArgs, noise: &NoiseArgs) -> Result<Machine, CliError> {
    let mut m = load_machine(args)?;
    let check = |flag: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(CliError::input(format!(
                "{flag}: must be a positive number, got {v}"
            )))
        }
    };
    if let Some(a) = noise.angle_noise_arcsec {
        m.sensors.angle_rad = check("--angle-noise-arcsec", a)? * SensorNoise::ARCSEC;
    }
    if let Some(l) = noise.length_noise_um {
        m.sensors.length_mm = check("--length-noise-um", l)? * 1e-3;
    }
    if let Some(k) = noise.readings_per_pose {
        if k == 0 {
            return Err(CliError::input("--readings-per-pose: must be at least 1"));
        }
        m.sensors.readings_per_pose = k;
    }
    Ok(m)
}

/// Reads a measured-data file; every problem is an input error naming
/// file, line and column.
pub fn read_data(path: &std::path::Path, machine: &Machine) -> Result<Dataset, CliError> {
    let file = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|e| CliError::input(format!("{file}: {e}")))?;
    // A progress bar over the bytes read (drawn only on a terminal).
    let size = f.metadata().map(|m| m.len()).unwrap_or(0);
    let bar = progress_bar(size, "reading");
    let data = tricept_data::read_from(bar.wrap_read(std::io::BufReader::new(f)), &file)
        .map_err(|e| CliError::input(e.to_string()))?;
    bar.finish_and_clear();
    // Commands the machine cannot take are input errors too, found here
    // with their line rather than deep inside the solver.
    let [lo, hi] = machine.limits.leg_stroke_mm;
    for p in &data.poses {
        for (i, q) in p.commands_mm.iter().enumerate() {
            if !(lo..=hi).contains(q) {
                return Err(CliError::input(format!(
                    "{}: line {}, column `q{}`: command {q} mm is outside the leg stroke [{lo}, {hi}] mm",
                    data.source,
                    p.line,
                    i + 1
                )));
            }
        }
    }
    Ok(data)
}

/// A progress bar on stderr; invisible when stderr is not a terminal or for
/// small jobs.
pub fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    if len < 20_000_000 {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {bytes}/{total_bytes} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(what.to_string());
    bar
}

/// A spinner on stderr while a long step runs (terminal only).
pub fn spinner(what: String, poses: usize) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget};
    if poses < 50_000 {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_message(what);
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
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
pub fn run_identifiability(
    machine: &MachineArgs,
    noise: &NoiseArgs,
    params: &ParamArgs,
    poses: &str,
) -> Result<(), CliError> {
    let m = machine_with_noise(machine, noise)?;
    let set = params.set()?;
    let targets = tricept_plant::campaign::pose_set(poses, &m).map_err(CliError::input)?;
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
    machine: &MachineArgs,
    noise: &NoiseArgs,
    params: &ParamArgs,
    fit: &FitArgs,
    data: &std::path::Path,
) -> Result<(Machine, GeometricModel, Identification, Vec<Rejection>), CliError> {
    let m = machine_with_noise(machine, noise)?;
    let set = params.set()?;
    let dataset = read_data(data, &m)?;
    let model = GeometricModel::new(m.clone(), set);
    let options = IdentifyOptions::for_machine(&m);
    let source = data.display().to_string();
    let spin = spinner(
        format!("identifying from {} poses", dataset.poses.len()),
        dataset.poses.len(),
    );
    let (id, rejected) = if fit.no_robust {
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
pub fn run_identify(
    machine: &MachineArgs,
    noise: &NoiseArgs,
    params: &ParamArgs,
    fit: &FitArgs,
    data: &std::path::Path,
    write_machine: Option<&std::path::Path>,
) -> Result<(), CliError> {
    let (_, model, id, rejected) = identify_from_file(machine, noise, params, fit, data)?;
    if let Some(path) = write_machine {
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
            r.residual_sigma
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
    let a = SensorNoise::ARCSEC;
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
        id.stats.max_standardized.0,
        id.stats.max_standardized.1 + 1
    );
    print!("{}", id.report.to_text());
    Ok(())
}

/// Parses `table2`, `zero`, `random:MAG[,SEED]` or a JSON file of
/// parameter values.
pub fn parse_errors(spec: &str, set: &ParameterSet) -> Result<Vec<f64>, CliError> {
    match spec {
        "table2" => Ok(set.table2()),
        "zero" => Ok(vec![0.0; set.len()]),
        s if s.starts_with("random:") => {
            let parts: Vec<&str> = s["random:".len()..].split(',').collect();
            let mag: f64 = parts[0]
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| {
                    CliError::input(format!("errors `{s}`: expected random:MAG_MM[,SEED]"))
                })?;
            let seed: u64 = match parts.get(1) {
                Some(t) => t.parse().map_err(|_| {
                    CliError::input(format!("errors `{s}`: SEED must be a whole number"))
                })?,
                None => 0,
            };
            Ok(tricept_plant::random_errors(set.len(), mag, seed))
        }
        path => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| CliError::input(format!("{path}: {e}")))?;
            set.parse_values(&text)
                .map_err(|e| CliError::input(format!("{path}: {e}")))
        }
    }
}

fn stats_json(s: &MapStats) -> Value {
    json!({"max_mm": s.max_mm, "min_mm": s.min_mm, "mean_mm": s.mean_mm, "rms_mm": s.rms_mm})
}

/// `tricept compensate`.
#[allow(clippy::too_many_arguments)]
pub fn run_compensate(
    machine: &MachineArgs,
    noise: &NoiseArgs,
    params: &ParamArgs,
    fit: &FitArgs,
    data: &std::path::Path,
    truth: Option<&str>,
    truth_effects: &[String],
    plane_z_mm: Option<f64>,
    spacing_mm: f64,
    targets: Option<&std::path::Path>,
) -> Result<(), CliError> {
    let (m, model, id, rejected) = identify_from_file(machine, noise, params, fit, data)?;
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
    if let Some(spec) = truth {
        let set = model.parameter_set();
        let mut plant =
            tricept_plant::Plant::geometric(m.clone(), set.to_errors(&parse_errors(spec, set)?));
        plant.effects = crate::simulate_cmd::parse_effects(truth_effects)?;
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
    if let Some(path) = targets {
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
