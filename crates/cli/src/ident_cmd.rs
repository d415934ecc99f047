//! The self-calibration verbs `identifiability` and `identify`, and the
//! fit from a data file that `compensate` shares.

use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::{Map, Value, json};
use tricept_data::MeasuredPose;
use tricept_engine::{
    AccuracyModel, GeometricModel, IdentError, Identification, IdentifyOptions, PredictedAccuracy,
    Rejection, Verdict, identifiability, identify, identify_robust, likely_causes,
};
use tricept_kinematics::Machine;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_model::ParameterSet;

// The settings live in `args.rs`, below this verb and the fused path it
// hands external measurements to (`fusion_cmd.rs`).
use crate::args::{FitSettings, IdentifyArgs};
use crate::args::{
    MachineArgs, NoiseArgs, ParamArgs, load_with_noise, machine_with_noise, pose_targets,
    read_data, spinner,
};
use crate::cli_error::{CliError, EXIT_INADEQUATE, EXIT_NOT_CONVERGED};
use tricept_ident::LoadedMachine;
use tricept_ident::machine_file;

/// `tricept identifiability`.
#[derive(Debug, Args)]
pub struct IdentifiabilityArgs {
    /// Pose set (see below).
    #[arg(long, default_value = "grid", conflicts_with = "data")]
    pub poses: String,
    /// Assess a logged campaign instead: the commands of this
    /// measured-data file (its readings are not used).
    #[arg(long, value_name = "FILE.csv")]
    pub data: Option<PathBuf>,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

fn ident_error(source: &str, e: IdentError) -> CliError {
    match &e {
        IdentError::TooFewPoses { .. } | IdentError::TooFewDistinctPoses { .. } => {
            CliError::input(format!("{source}: {e}"))
        }
        IdentError::Kinematics {
            line, source: k, ..
        } => CliError::input(format!(
            "{source}: line {line}: the commands of this pose cannot be reached: {k}"
        )),
        _ => CliError::other(format!("{source}: {e}")),
    }
}

/// `tricept identifiability`.
pub fn run_identifiability(a: &IdentifiabilityArgs) -> Result<u8, CliError> {
    let (machine, poses) = (&a.machine, a.poses.as_str());
    let m = machine_with_noise(machine, &a.noise)?;
    let set = a.params.set()?;
    let commands = match &a.data {
        Some(path) => read_data(path, &m)?.poses,
        None => {
            let targets = pose_targets(poses, &m)?;
            let mut commands = Vec::with_capacity(targets.len());
            for (i, r) in targets.iter().enumerate() {
                let ik = m.inverse(r).map_err(|e| {
                    CliError::input(format!(
                        "--poses {poses}: pose {} ({:.3}, {:.3}, {:.3} mm): {e}",
                        i + 1,
                        r.x,
                        r.y,
                        r.z
                    ))
                })?;
                commands.push(MeasuredPose {
                    commands_mm: ik.legs_mm,
                    ..Default::default()
                });
            }
            commands
        }
    };
    let (poses, source) = match &a.data {
        Some(path) => (path.display().to_string(), path.display().to_string()),
        None => (poses.to_string(), format!("--poses {poses}")),
    };
    let poses = poses.as_str();
    let model = GeometricModel::new(m.clone(), set.clone());
    let report = identifiability(
        &model,
        &vec![0.0; set.len()],
        &commands,
        &IdentifyOptions::for_machine(&m),
    )
    .map_err(|e| ident_error(&source, e))?;
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
        crate::output::write_text(&report.to_text());
    }
    Ok(0)
}

/// A fit from a data file, with everything the outputs need.
pub struct Fit {
    /// The machine identified against.
    pub loaded: LoadedMachine,
    /// The model (increments on the loaded machine, with its rank rule).
    pub model: GeometricModel,
    /// The identification on the kept poses.
    pub id: Identification,
    /// Poses rejected as gross errors.
    pub rejected: Vec<Rejection>,
    /// The verdict, with the likely causes of an inconsistent fit and the
    /// advice of a campaign too small to calibrate added to its warnings.
    pub verdict: Verdict,
    /// The platform accuracy the fit predicts, against the machine's
    /// tolerance.
    pub accuracy: PredictedAccuracy,
    /// Mean logged structure temperature of the data, °C.
    pub temperature_c: Option<f64>,
}

impl Fit {
    /// The exit code the verdict calls for: 0 converged, adequate and
    /// worthwhile; 3 converged but inadequate, or a campaign too small to
    /// calibrate; 4 not converged.
    pub fn exit_code(&self) -> u8 {
        if !self.verdict.converged {
            EXIT_NOT_CONVERGED
        } else if !self.verdict.adequate || !self.accuracy.worthwhile {
            EXIT_INADEQUATE
        } else {
            0
        }
    }

    /// Why the fit must not be deployed (`None` when it may): every exit
    /// code but 0 (see [`machine_file::write_rule`]).
    pub fn refusal(&self) -> Option<&'static str> {
        if !self.verdict.converged {
            Some("the fit did not converge")
        } else if self.verdict.inconsistent {
            Some("the data cannot come from the described machine")
        } else if !self.verdict.adequate {
            Some("the model does not explain the data")
        } else if !self.accuracy.worthwhile {
            Some("the campaign is too small to calibrate the machine")
        } else {
            None
        }
    }

    /// The reason of a non-zero exit code in one phrase, with the first
    /// likely cause when one was found (what stderr says).
    pub fn reason(&self) -> String {
        let why = self.refusal().unwrap_or("");
        match self
            .verdict
            .warnings
            .iter()
            .find_map(|w| w.strip_prefix("likely cause: "))
        {
            Some(cause) => format!("{why}; likely cause: {cause}"),
            None => why.to_string(),
        }
    }

    /// The identified machine.
    pub fn identified(&self) -> Machine {
        self.model.machine_at(&self.id.estimate)
    }
}

/// Reads `data` and identifies against the machine of `settings` (robust
/// unless `--no-robust`); the rank rule of a calibrated machine is its
/// nominal machine's.
pub fn fit_from_file(data: &Path, settings: &FitSettings) -> Result<Fit, CliError> {
    let tolerance_mm = settings.fit.tolerance_mm;
    if !(tolerance_mm.is_finite() && tolerance_mm > 0.0 && tolerance_mm <= 10.0) {
        return Err(CliError::input(format!(
            "--tolerance-mm: the manufacturing tolerance must be a number of mm above 0 and at most 10, got {tolerance_mm}"
        )));
    }
    let loaded = load_with_noise(&settings.machine, &settings.noise)?;
    let m = loaded.machine().clone();
    let set = settings.params.set()?;
    let dataset = read_data(data, &m)?;
    let mut model = GeometricModel::new(m.clone(), set.clone());
    if let Some(reference) = loaded.rank_reference()? {
        model = model.with_rank_reference(reference);
    }
    let options = IdentifyOptions::for_machine(&m);
    let source = data.display().to_string();
    let spin = spinner(
        format!(
            "identify: {} geometric parameters ({}) and 3 sensor offsets from {} poses: {}Gauss-Newton on the exact model",
            set.len(),
            set.label(),
            dataset.poses.len(),
            if settings.fit.no_robust {
                ""
            } else {
                "gross-error screen, then "
            }
        ),
        dataset.poses.len(),
    );
    let (id, rejected) = if settings.fit.no_robust {
        (
            identify(&model, &dataset, &options).map_err(|e| ident_error(&source, e))?,
            Vec::new(),
        )
    } else {
        identify_robust(&model, &dataset, &options).map_err(|e| ident_error(&source, e))?
    };
    spin.finish_and_clear();
    let mut verdict = id.verdict();
    if verdict.inconsistent {
        for c in likely_causes(&m, &set, &dataset, &options, id.stats.reduced_chi_square) {
            verdict.warnings.push(format!(
                "likely cause: {} (undone, the data fit with chi2/dof {:.2})",
                c.description, c.chi2_per_dof
            ));
        }
    }
    let accuracy = predicted_accuracy(&m, &set, &id, settings.fit.tolerance_mm)?;
    if !accuracy.worthwhile {
        verdict
            .warnings
            .push(campaign_advice(&m, &set, &accuracy, id.residuals.len())?);
    }
    Ok(Fit {
        loaded,
        model,
        id,
        rejected,
        verdict,
        accuracy,
        temperature_c: machine_file::mean_temperature_c(&dataset),
    })
}

/// Evaluation points of the predicted platform accuracy: the workspace's
/// polar grid of 2 rings of 8 points on 3 levels (51 points).
pub fn accuracy_points(m: &Machine) -> Vec<nalgebra::Vector3<f64>> {
    m.workspace.polar_grid(2, 8, 3)
}

/// The platform accuracy `id` predicts on `m`'s workspace against the
/// tolerance `tolerance_mm` per parameter.
fn predicted_accuracy(
    m: &Machine,
    set: &ParameterSet,
    id: &Identification,
    tolerance_mm: f64,
) -> Result<PredictedAccuracy, CliError> {
    let model =
        AccuracyModel::new(m, set, &accuracy_points(m), tolerance_mm).map_err(|e| match e {
            IdentError::Invalid(why) => CliError::input(format!("--tolerance-mm: {why}")),
            e => CliError::other(format!("predicted accuracy: {e}")),
        })?;
    model
        .assess(&id.covariance, id.design().fixed())
        .map_err(|e| CliError::other(format!("predicted accuracy: {e}")))
}

/// Why a campaign cannot calibrate, and how many and which poses would.
fn campaign_advice(
    m: &Machine,
    set: &ParameterSet,
    a: &PredictedAccuracy,
    poses: usize,
) -> Result<String, CliError> {
    let model = AccuracyModel::new(m, set, &accuracy_points(m), a.tolerance_mm)
        .map_err(|e| CliError::other(format!("campaign advice: {e}")))?;
    let (optimal, random) = tricept_study::campaign::worthwhile_campaigns(m, set, &model)
        .map_err(|e| CliError::other(format!("campaign advice: {e}")))?;
    let fix = match (optimal, random) {
        (Some(o), Some(r)) => format!(
            "{} D-optimal poses (`--poses optimal:{}`, predicted {:.3} mm) or {} random poses over the workspace (`--poses random:{},1`, predicted {:.3} mm) would be worthwhile",
            o.poses, o.poses, o.predicted.after_rms_mm, r.poses, r.poses, r.predicted.after_rms_mm
        ),
        (Some(o), None) => format!(
            "{} D-optimal poses (`--poses optimal:{}`, predicted {:.3} mm) would be worthwhile",
            o.poses, o.poses, o.predicted.after_rms_mm
        ),
        _ => "no campaign of up to 200 poses of these sensors would be: better sensors or external measurements are needed (docs/hybrid.md)".to_string(),
    };
    Ok(format!(
        "this campaign cannot calibrate the machine: the predicted platform error after calibration is {:.3} mm rms (up to {:.3} mm), against {:.3} mm for a machine built to {} mm per parameter and not calibrated; a calibration must at least halve it. {poses} poses are too few or too poorly spread: {fix}",
        a.after_rms_mm, a.after_max_mm, a.before_rms_mm, a.tolerance_mm
    ))
}

/// One-line stderr summary of a non-zero verdict (scripts read the code,
/// people read this): the verb, the code and why.
pub fn report_exit(verb: &str, code: u8, why: &str) {
    if code == EXIT_INADEQUATE || code == EXIT_NOT_CONVERGED {
        errln!("{verb}: exit {code}: {why} (see the warnings)");
    }
}

/// Writes a calibrated machine file unless the fit must not be deployed
/// (then only with `force`, marked as forced). Returns an error when it
/// refuses.
fn write_calibrated(path: &Path, data: &Path, fit: &Fit, force: bool) -> Result<(), CliError> {
    let forced = crate::files::write_rule(
        &format!("--write-machine {}", path.display()),
        fit.exit_code(),
        &fit.reason(),
        force,
    )?;
    let d = machine_file::calibrated_description(
        &fit.loaded,
        &fit.identified(),
        &machine_file::FitRecord::of_identification(&fit.id),
        machine_file::Provenance {
            method: "identify",
            data_file: data,
            parameter_set: fit.model.parameter_set().label(),
            rejected_lines: fit.rejected.iter().map(|r| r.line).collect(),
            adequate: fit.verdict.adequate,
            forced,
            warnings: fit.verdict.warnings.clone(),
            effects: Map::new(),
            n_geometric: fit.id.names.len(),
            external: Vec::new(),
            temperature_c: fit.temperature_c,
        },
        None,
    )?;
    crate::files::write_machine(path, &d)
}

/// The rejected poses as JSON: 1-based pose number, file line, size.
pub fn rejected_json(rejected: &[Rejection]) -> Value {
    Value::Array(
        rejected
            .iter()
            .map(
                |r| json!({"pose": r.pose + 1, "line": r.line, "residual_sigma": r.residual_sigma}),
            )
            .collect(),
    )
}

/// `tricept identify`.
pub fn run_identify(a: &IdentifyArgs) -> Result<u8, CliError> {
    if a.external.any() {
        return crate::fusion_cmd::run(a);
    }
    let data = a.data.as_path();
    let fit = fit_from_file(data, &a.settings)?;
    let code = fit.exit_code();
    let written = a
        .write_machine
        .as_ref()
        .map(|path| write_calibrated(path, data, &fit, a.force));
    let id = &fit.id;
    if a.settings.machine.json {
        let mut v = id.to_json();
        if let Value::Object(o) = &mut v {
            // One standard deviation per estimate, with its unit: the
            // estimate's (what `std_dev` holds too, for scripts written
            // before), not the design's prediction at the starting point,
            // which `tricept identifiability` reports.
            let estimates: Map<String, Value> = id
                .names
                .iter()
                .zip(&id.estimate)
                .map(|(n, v)| (n.clone(), (*v).into()))
                .collect();
            let sd = o.get("std_dev").cloned().unwrap_or(Value::Null);
            o.insert("estimates_mm".into(), Value::Object(estimates));
            o.insert("std_dev_mm".into(), sd);
            o.insert("rejected".into(), rejected_json(&fit.rejected));
            o.insert("warnings".into(), fit.verdict.warnings.clone().into());
            o.insert(
                "predicted_accuracy".into(),
                serde_json::to_value(fit.accuracy).unwrap_or(Value::Null),
            );
            o.insert("worthwhile".into(), fit.accuracy.worthwhile.into());
            o.insert(
                "machine".into(),
                fit.loaded.description().name.clone().into(),
            );
            o.insert("data_file".into(), data.display().to_string().into());
        }
        outln!("{v}");
    } else {
        print_identification(&fit, data);
    }
    if let Some(Err(e)) = written {
        return Err(e);
    }
    report_exit("identify", code, &fit.reason());
    Ok(code)
}

fn print_identification(fit: &Fit, data: &Path) {
    let id = &fit.id;
    // What matters first: the verdict, its reason and the likely cause;
    // the estimates after.
    let a = &fit.accuracy;
    outln!(
        "verdict: {}, {}, {}",
        if fit.verdict.converged {
            "converged"
        } else {
            "NOT converged"
        },
        if fit.verdict.adequate {
            "adequate (the model explains the data to the sensor noise)"
        } else {
            "NOT adequate (the model does not explain the data)"
        },
        if a.worthwhile {
            "worthwhile (it at least halves the platform error)"
        } else {
            "NOT worthwhile (the campaign is too small to calibrate)"
        }
    );
    let (causes, others): (Vec<&String>, Vec<&String>) = fit
        .verdict
        .warnings
        .iter()
        .partition(|w| w.starts_with("likely cause"));
    for w in causes.iter().chain(&others) {
        outln!("WARNING: {w}");
    }
    outln!(
        "predicted platform error after calibration: {:.4} mm rms (up to {:.4} mm at one of {} points), against {:.4} mm without calibration ({} mm per parameter)",
        a.after_rms_mm,
        a.after_max_mm,
        a.points,
        a.before_rms_mm,
        a.tolerance_mm
    );
    for r in &fit.rejected {
        let why = match r.residual_sigma {
            Some(z) => format!("a reading {z:.1} noise standard deviations off (gross error)"),
            None => "the fitted machine cannot reach its commands".to_string(),
        };
        outln!(
            "rejected pose {} (line {} of {}): {why}",
            r.pose + 1,
            r.line,
            data.display()
        );
    }
    outln!(
        "{} poses of {} against `{}`, parameter set {}: {} in {} Gauss-Newton iterations",
        id.residuals.len(),
        data.display(),
        fit.loaded.description().name,
        fit.model.parameter_set().label(),
        if id.converged {
            "converged"
        } else {
            "NOT converged"
        },
        id.iterations
    );
    if !(fit.verdict.converged && fit.verdict.adequate && a.worthwhile) {
        outln!(
            "(the estimates below are not to be trusted as a calibration: see the verdict above)"
        );
    }
    outln!("{:>6} {:>12} {:>10}", "param", "estimate mm", "sd mm");
    for ((n, v), sd) in id.names.iter().zip(&id.estimate).zip(&id.std_dev) {
        match sd {
            Some(s) => outln!("{n:>6} {v:>12.5} {s:>10.5}"),
            None => outln!("{n:>6} {v:>12.5} {:>10}", "held"),
        }
    }
    let arcsec = RAD_PER_ARCSEC;
    outln!(
        "sensor offsets: phi {:.6} rad, theta {:.6} rad, s {:.4} mm",
        id.offsets[0],
        id.offsets[1],
        id.offsets[2]
    );
    let (z, j) = id.stats.max_standardised;
    outln!(
        "residual rms: phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um; chi2/dof {:.3} (dof {}, p = {:.2e}); largest {z:.1} sigma at pose {} (line {})",
        id.stats.rms[0] / arcsec,
        id.stats.rms[1] / arcsec,
        id.stats.rms[2] * 1e3,
        id.stats.reduced_chi_square,
        id.stats.dof,
        fit.verdict.chi_square_p_value,
        j + 1,
        id.lines.get(j).copied().unwrap_or(0)
    );
    crate::output::write_text(&id.report.to_text());
}
