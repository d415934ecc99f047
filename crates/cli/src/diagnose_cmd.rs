//! `tricept diagnose` and `tricept detectability`.

use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::{Map, json};
use tricept_diagnose::detect::{advise, realistic, term_detectability};
use tricept_diagnose::{DiagnoseError, DiagnoseOptions, Plausibility, deploy, diagnose};
use tricept_engine::GeometricModel;
use tricept_model::effects::EffectName;
use tricept_model::{GeometricErrors, ParameterSet};
use tricept_plant::{Campaign, Effect, Plant, PoseOrder};

use crate::args::{
    LoadedMachine, MachineArgs, NoiseArgs, load_with_noise, machine_with_noise, pose_targets,
    read_data,
};
use crate::cli_error::CliError;
use crate::machine_file;

/// `tricept diagnose`.
#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// Measured-data CSV (context columns temp_c, time_s, dir1..3 are used when present).
    #[arg(long, value_name = "FILE.csv")]
    pub data: PathBuf,
    /// Write residual plots (SVG) of the named causes into this directory.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Estimate the sensor noise from repeated poses (the same commands
    /// logged on separate visits, at least 10 degrees of freedom) and test
    /// against it (F tests) instead of the stated noise.
    #[arg(long)]
    pub noise_from_data: bool,
    /// Standard deviation of the logged temperature, K (default 0.02): its
    /// noise enters the final adequacy test of temperature terms.
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub temperature_noise: Option<f64>,
    /// Override physical ranges of the plausibility table: a JSON object
    /// such as `{"thermal.expansion_ppm_per_k": [20, 26]}` (aluminium legs).
    #[arg(long, value_name = "FILE.json")]
    pub plausibility: Option<PathBuf>,
    /// Search the effects of the vocabulary only, not the generic
    /// dictionary (for comparison; effects outside the vocabulary are then
    /// reported as unexplained).
    #[arg(long)]
    pub no_dictionary: bool,
    /// Write the calibrated machine of the final model: the geometry
    /// de-biased by every deployed cause, each named effect where it goes
    /// (the list below: the static leg effects applied by ik, fk, tool-ik
    /// and compensate, the UP limb's class-2 errors in its description, the
    /// dynamic effects as controller parameters), the generic leg errors
    /// that are functions of the leg command as per-leg compensation
    /// tables (leg_effects.tables, applied by ik, fk, tool-ik and
    /// compensate), sensor corrections and time terms recorded only, and a
    /// `calibration` record saying what it applies and what it records.
    /// A cause whose improvement is not above 2 sd is not deployed.
    /// Refused when the data are not explained (exit 3).
    #[arg(long, value_name = "FILE.json")]
    pub write_machine: Option<PathBuf>,
    /// Write the machine even when the data are not explained; the file
    /// says so.
    #[arg(long, requires = "write_machine")]
    pub force: bool,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept detectability`.
#[derive(Debug, Args)]
pub struct DetectabilityArgs {
    /// Pose set (as for `identifiability`; positions in mm).
    #[arg(long, default_value = "grid", conflicts_with = "data")]
    pub poses: String,
    /// Assess a logged campaign instead: its commands and their logged
    /// context (temperatures, times, approach directions) from this
    /// measured-data file; its readings are not used.
    #[arg(long, value_name = "FILE.csv")]
    pub data: Option<PathBuf>,
    /// Visit every pose twice, approaching from both directions.
    #[arg(long)]
    pub both_directions: bool,
    /// Temperature change over the campaign, K (0: no thermal signature;
    /// negative: cooling).
    #[arg(long, default_value_t = 2.0, value_name = "K")]
    pub temperature_drift: f64,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept diagnose`.
pub fn run_diagnose(a: &DiagnoseArgs) -> Result<u8, CliError> {
    let (machine, data) = (&a.machine, a.data.as_path());
    let loaded = load_with_noise(machine, &a.noise)?;
    let m = loaded.machine.clone();
    let dataset = read_data(data, &m)?;
    let source = data.display().to_string();
    let mut options = DiagnoseOptions::for_machine(&m);
    options.noise_from_data = a.noise_from_data;
    options.rank_reference = loaded.rank_reference()?;
    options.dictionary.enabled = !a.no_dictionary;
    if let Some(k) = a.temperature_noise {
        if !(k.is_finite() && k >= 0.0) {
            return Err(CliError::input(format!(
                "--temperature-noise: must be a non-negative number of kelvin, got {k}"
            )));
        }
        options.temperature_sigma_k = k;
    }
    if let Some(path) = &a.plausibility {
        let file = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| CliError::input(format!("{file}: {e}")))?;
        options.plausibility = Plausibility::with_overrides(&text)
            .map_err(|e| CliError::input(format!("{file}: {e}")))?;
    }
    let d = diagnose(&m, &dataset, &options).map_err(|e| diagnose_error(&source, e))?;
    if let Some(dir) = &a.plots {
        crate::files::create_dir(dir)?;
        for p in &d.plots {
            let path = dir.join(format!("residual-{}.svg", p.effect));
            let drawn = tricept_plot::scatter(
                &path,
                &tricept_plot::Axes {
                    title: &format!("{}: {}, before and after", p.effect, p.y_label),
                    x_label: &p.x_label,
                    y_label: &p.y_label,
                    log_x: false,
                    log_y: false,
                },
                &[
                    ("geometric model".to_string(), p.before.clone()),
                    (format!("with {}", p.effect), p.after.clone()),
                ],
            );
            crate::files::plotted(&path, drawn)?;
        }
    }
    let written = a.write_machine.as_ref().map(|path| {
        write_extended(
            path,
            data,
            &loaded,
            options.rank_reference.as_ref(),
            &dataset,
            &d,
            a.force,
        )
    });
    if machine.json {
        outln!("{}", d.to_json());
    } else {
        crate::output::write_text(&d.to_text(&source));
    }
    match written {
        Some(Err(e)) => Err(e),
        // The verdict in the exit code as in identify's: 3 when the final
        // model (geometric plus the named causes) leaves a misfit.
        _ if !d.final_adequate => {
            errln!(
                "diagnose: exit {}: the final model does not explain the data: {}",
                crate::cli_error::EXIT_INADEQUATE,
                d.unexplained
                    .as_deref()
                    .unwrap_or("a remainder is reported (see the report)")
            );
            Ok(crate::cli_error::EXIT_INADEQUATE)
        }
        _ => Ok(0),
    }
}

fn write_extended(
    path: &Path,
    data: &Path,
    loaded: &LoadedMachine,
    rank_reference: Option<&tricept_kinematics::Machine>,
    dataset: &tricept_data::Dataset,
    d: &tricept_diagnose::Diagnosis,
    force: bool,
) -> Result<(), CliError> {
    // What a machine file cannot hold: a misfit the final model leaves
    // (every named cause is deployed, or recorded, or reported as not
    // worth deploying).
    let mut problems = Vec::new();
    if !d.final_adequate {
        problems.push(match &d.unexplained {
            Some(u) => u.clone(),
            None => "the final model does not explain the data (a remainder is reported)".into(),
        });
    }
    // An alias is deployed with the member the final model carries; the
    // file's warnings name the alternatives and what would separate them
    // (an exact alias, such as a lead common to all legs against a scale
    // gain, is never separated by the machine's own sensors).
    let notes: Vec<String> = d
        .aliases
        .iter()
        .map(|a| {
            let names: Vec<&str> = a.effects.iter().map(|e| e.as_str()).collect();
            format!(
                "{} cannot be told apart{} ({}); the file deploys {}; to separate them: {}",
                names.join(" / "),
                if a.exact {
                    " by these sensors"
                } else {
                    " on this campaign"
                },
                a.why,
                a.in_model.as_str(),
                a.separate_by
            )
        })
        .collect();
    let forced = machine_file::write_rule(
        &format!("--write-machine {}", path.display()),
        if problems.is_empty() {
            0
        } else {
            crate::cli_error::EXIT_INADEQUATE
        },
        &problems.join("; "),
        force,
    )?;
    let deployed = deploy(&loaded.machine, rank_reference, dataset, d)
        .map_err(|e| CliError::other(e.to_string()))?;
    let g = ParameterSet::paper15().len();
    let mut effects = Map::new();
    for ((name, v), sd) in deployed
        .id
        .names
        .iter()
        .zip(&deployed.id.estimate)
        .zip(&deployed.id.std_dev)
        .skip(g)
    {
        effects.insert(name.clone(), json!({"value": v, "std_dev": sd}));
    }
    // The period of each periodic term, beside its amplitudes, and the
    // edges of each step beside its height.
    for t in &d.model_terms {
        if let (true, Some(p)) = (t.deployed, t.period_mm) {
            effects.insert(
                format!("{}.period_mm", t.effect),
                json!({"value": p, "std_dev": serde_json::Value::Null}),
            );
        }
        if let (true, Some(edges), [leg]) = (t.deployed, t.edges_mm, t.legs.as_slice()) {
            for (side, value) in ["from", "to"].into_iter().zip(edges) {
                let name = format!("{}.leg{leg}_{side}_mm", t.effect);
                // Its profile-likelihood half-width, when the report has it.
                let sd = d
                    .causes
                    .iter()
                    .flat_map(|c| &c.parameters)
                    .find(|p| p.name == name && p.value == value)
                    .and_then(|p| p.std_dev);
                effects.insert(name, json!({"value": value, "std_dev": sd}));
            }
        }
    }
    let rejected_lines = d.outlier_lines();
    let warnings = problems.into_iter().chain(notes).collect();
    let mut description = machine_file::calibrated_description(
        loaded,
        &deployed.machine,
        &machine_file::FitRecord::of_identification(&deployed.id),
        machine_file::Provenance {
            method: "diagnose",
            data_file: data,
            parameter_set: "paper15",
            rejected_lines,
            adequate: forced.is_none(),
            forced,
            warnings,
            effects,
            n_geometric: g,
            external: Vec::new(),
            temperature_c: machine_file::mean_temperature_c(dataset),
        },
        deployed.controller,
    )?;
    if let Some(c) = description.calibration.as_mut() {
        c.applies = deployed.applied;
        c.records = deployed.recorded;
    }
    machine_file::write(path, &description)
}

/// The vocabulary for `tricept diagnose --help`, from the registry: each
/// effect, its physics, its parameters (units in the names) and where
/// `--write-machine` puts it.
pub fn vocabulary_help() -> String {
    let lines: Vec<String> = EffectName::ALL
        .iter()
        .map(|e| {
            let s = e.spec();
            let params = e.parameter_names();
            format!(
                "  {}: {}{}; --write-machine: {}",
                s.name,
                s.physics.replace('`', ""),
                if params.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", params.join(", "))
                },
                s.deployment.label()
            )
        })
        .collect();
    format!("Effects of the vocabulary:\n{}", lines.join("\n"))
}

/// The CLI error of a failed diagnosis: everything the data cause is an
/// input error (exit 2), naming the file.
fn diagnose_error(source: &str, e: DiagnoseError) -> CliError {
    match e {
        DiagnoseError::Ident(tricept_engine::IdentError::Kinematics {
            line, source: k, ..
        }) => CliError::input(format!(
            "{source}: line {line}: the commands of this pose cannot be reached: {k}"
        )),
        DiagnoseError::Ident(
            tricept_engine::IdentError::TooFewPoses { .. }
            | tricept_engine::IdentError::TooFewDistinctPoses { .. },
        ) => CliError::input(format!("{source}: {e}")),
        DiagnoseError::Ident(e) => CliError::other(format!("{source}: {e}")),
        e => CliError::input(format!("{source}: {e}")),
    }
}

/// `tricept detectability`.
pub fn run_detectability(a: &DetectabilityArgs) -> Result<u8, CliError> {
    let (machine, poses, both_directions, drift_k) = (
        &a.machine,
        a.poses.as_str(),
        a.both_directions,
        a.temperature_drift,
    );
    let m = machine_with_noise(machine, &a.noise)?;
    let mut campaign = Campaign::from_targets(&m, Vec::new(), 1);
    let data = match &a.data {
        // A logged campaign: its poses with their own context.
        Some(path) => read_data(path, &m)?,
        None => {
            campaign.targets_mm = pose_targets(poses, &m)?;
            if both_directions {
                campaign.order = PoseOrder::BothDirections;
            }
            // The logged context of the campaign (times, temperature with
            // the stated drift, approach directions), on the nominal
            // machine.
            let mut plant = Plant::geometric(m.clone(), GeometricErrors::default());
            if drift_k != 0.0 {
                plant.effects = vec![Effect::from(tricept_plant::effects::Thermal {
                    drift_k,
                    expansion_ppm_per_k: 0.0,
                })];
            }
            plant
                .simulate(&campaign)
                .map_err(|e| CliError::input(format!("--poses {poses}: {e}")))?
        }
    };
    let sigma = campaign.noise.logged_sigma();
    let geometric = GeometricModel::new(m.clone(), ParameterSet::paper15());
    let mut rows = Vec::new();
    for (c, v, label) in realistic(&m) {
        if let Some(d) = term_detectability(&geometric, &c, &v, &data.poses, sigma, 1e-3) {
            let advice = advise(&d, data.poses.len(), campaign.noise.readings_per_pose);
            rows.push((label, d, advice));
        }
    }
    if machine.json {
        let v: Vec<serde_json::Value> = rows
            .iter()
            .map(|(label, d, advice)| serde_json::json!({"magnitude": label, "analysis": d, "advice": advice}))
            .collect();
        outln!(
            "{}",
            serde_json::json!({"poses": data.poses.len(), "readings_per_pose": campaign.noise.readings_per_pose, "effects": v})
        );
        return Ok(0);
    }
    match &a.data {
        Some(path) => outln!(
            "{} logged poses of {}, mean of {} readings, with their logged context",
            data.poses.len(),
            path.display(),
            campaign.noise.readings_per_pose
        ),
        None => outln!(
            "{} logged poses ({}{}), mean of {} readings, temperature drift {} K",
            data.poses.len(),
            poses,
            if both_directions {
                ", both approach directions"
            } else {
                ""
            },
            campaign.noise.readings_per_pose,
            drift_k
        ),
    }
    outln!(
        "| effect | magnitude | power | detectable from | geometric held-out rms | halved from | largest bias (mm) | advice |"
    );
    outln!("|---|---|---|---|---|---|---|---|");
    for (label, d, advice) in rows {
        let bias = d
            .bias
            .first()
            .map_or("-".to_string(), |(n, b)| format!("{n} {b:+.4}"));
        outln!(
            "| {} | {label} | {:.3} | x{:.2} | {:.2} | x{:.2} | {bias} | {advice} |",
            d.effect,
            d.power,
            d.detectable_multiple,
            d.expected_rms_geometric,
            d.halving_multiple
        );
    }
    outln!(
        "the stated sensor noise can be checked only against repeated poses: revisit at least {} poses on separate visits (`simulate --revisit`) to use `diagnose --noise-from-data`",
        tricept_diagnose::MIN_PURE_ERROR_DOF
    );
    Ok(0)
}
