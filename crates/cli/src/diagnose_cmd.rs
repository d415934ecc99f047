//! `tricept diagnose` and `tricept detectability`.

use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::{Map, json};
use tricept_diagnose::detect::{advise, detectability, realistic};
use tricept_diagnose::{
    Candidate, DiagnoseError, DiagnoseOptions, ExtendedModel, REFERENCE_TEMPERATURE_C, diagnose,
};
use tricept_ident::{GeometricModel, IdentifyOptions, identify};
use tricept_kinematics::description::ControllerDescription;
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
    /// Write the calibrated machine of the final model: the geometric
    /// estimate with the static effects named (leg-lead, compliance: applied
    /// by ik, fk, tool-ik and compensate; ujoint-axes, tube-twist: in the
    /// UP limb's description), the dynamic ones as controller parameters
    /// (backlash per leg axis in um, thermal expansion in ppm/K from 20 °C),
    /// and a `calibration` record. Refused when the data are not explained.
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
    #[arg(long, default_value = "grid")]
    pub poses: String,
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
    let options = DiagnoseOptions::for_machine(&m);
    let d = diagnose(&m, &dataset, &options).map_err(|e| match e {
        DiagnoseError::TooFewPoses(_)
        | DiagnoseError::Ident(
            tricept_ident::IdentError::TooFewPoses { .. }
            | tricept_ident::IdentError::TooFewDistinctPoses { .. },
        ) => CliError::input(format!("{source}: {e}")),
        DiagnoseError::Ident(tricept_ident::IdentError::Kinematics {
            line, source: k, ..
        }) => CliError::input(format!(
            "{source}: line {line}: the commands of this pose cannot be reached: {k}"
        )),
        e => CliError::other(format!("{source}: {e}")),
    })?;
    if let Some(dir) = &a.plots {
        std::fs::create_dir_all(dir)
            .map_err(|e| CliError::other(format!("{}: {e}", dir.display())))?;
        for p in &d.plots {
            let path = dir.join(format!("residual-{}.svg", p.effect));
            tricept_plot::scatter(
                &path,
                &tricept_plot::Axes {
                    title: &format!("{}: residuals before and after", p.effect),
                    x_label: &p.x_label,
                    y_label: &p.y_label,
                    log_x: false,
                    log_y: false,
                },
                &[
                    ("geometric model".to_string(), p.before.clone()),
                    (format!("with {}", p.effect), p.after.clone()),
                ],
            )
            .map_err(|e| CliError::other(e.to_string()))?;
        }
    }
    let written = a
        .write_machine
        .as_ref()
        .map(|path| write_extended(path, data, &loaded, &dataset, &d, a.force));
    if machine.json {
        outln!("{}", d.to_json());
    } else {
        crate::output::write_text(&d.to_text(&source));
    }
    match written {
        Some(Err(e)) => Err(e),
        _ => Ok(0),
    }
}

/// The deployable model of a diagnosis, refitted on its clean poses for
/// the record's offsets, covariance and fit quality.
pub struct Deployed {
    /// The final model's identification.
    pub id: tricept_ident::Identification,
    /// The calibrated machine: geometry, class-2 effects, leg effects.
    pub machine: tricept_kinematics::Machine,
    /// The controller parameters of the dynamic effects, when any is named.
    pub controller: Option<ControllerDescription>,
}

/// Fits the diagnosis' final model (its named causes on the geometric
/// model) on the poses it kept, and maps every parameter to where it goes
/// in a machine file.
pub fn deploy(
    nominal: &tricept_kinematics::Machine,
    data: &tricept_data::Dataset,
    d: &tricept_diagnose::Diagnosis,
) -> Result<Deployed, CliError> {
    let flagged: Vec<u64> = d
        .causes
        .iter()
        .filter(|c| c.effect == EffectName::Outliers)
        .flat_map(|c| c.rows.iter().copied())
        .collect();
    let clean = data.subset(|j| !flagged.contains(&data.poses[j].line));
    let candidates: Vec<Candidate> = d
        .causes
        .iter()
        .filter(|c| c.effect != EffectName::Outliers)
        .map(|c| Candidate(c.effect))
        .collect();
    let model = ExtendedModel::new(
        GeometricModel::new(nominal.clone(), ParameterSet::paper15()),
        &candidates,
    );
    let id = identify(&model, &clean, &IdentifyOptions::for_machine(nominal))
        .map_err(|e| CliError::other(format!("the diagnosis' final model: {e}")))?;
    let mut machine = model.machine_at(&id.estimate);
    let mut controller: Option<ControllerDescription> = None;
    for (name, value) in id.names.iter().zip(&id.estimate).skip(model.n_geometric()) {
        let v = *value;
        let leg = |i: usize| {
            name.ends_with(&format!("{}_ppm", i + 1)) || name.ends_with(&format!("{}_um", i + 1))
        };
        match name.split_once('.') {
            Some(("leg-lead", _)) => {
                for i in 0..3 {
                    if leg(i) {
                        machine.leg_effects.lead_ppm[i] = v;
                    }
                }
            }
            Some(("compliance", "compliance_um_per_kn_at_1m")) => {
                machine.leg_effects.compliance_um_per_kn_at_1m = v;
            }
            Some(("backlash", _)) => {
                let c = controller.get_or_insert_with(ControllerDescription::default);
                for i in 0..3 {
                    if leg(i) {
                        c.backlash_um[i] = v;
                    }
                }
            }
            Some(("thermal", "expansion_ppm_per_k")) => {
                let c = controller.get_or_insert_with(ControllerDescription::default);
                c.thermal_expansion_ppm_per_k = v;
                c.reference_temperature_c = REFERENCE_TEMPERATURE_C;
            }
            // In the machine's UP limb already (model.machine_at), or
            // sensor-side (they change readings, not where the platform
            // goes): recorded under `calibration.effects`.
            Some(("ujoint-axes" | "tube-twist" | "scale-gain" | "encoder-eccentricity", _)) => {}
            _ => {
                return Err(CliError::other(format!(
                    "the diagnosis named a parameter `{name}` that a machine file cannot hold"
                )));
            }
        }
    }
    Ok(Deployed {
        id,
        machine,
        controller,
    })
}

fn write_extended(
    path: &Path,
    data: &Path,
    loaded: &LoadedMachine,
    dataset: &tricept_data::Dataset,
    d: &tricept_diagnose::Diagnosis,
    force: bool,
) -> Result<(), CliError> {
    let unexplained = d.unexplained.is_some();
    if unexplained && !force {
        return Err(CliError::other(format!(
            "--write-machine {}: not written: no cause the diagnosis knows explains the data; --force writes the geometric fit anyway, marked as forced",
            path.display()
        )));
    }
    let deployed = deploy(&loaded.machine, dataset, d)?;
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
    let rejected_lines = d
        .causes
        .iter()
        .filter(|c| c.effect == EffectName::Outliers)
        .flat_map(|c| c.rows.iter().copied())
        .collect();
    let mut warnings = Vec::new();
    if let Some(u) = &d.unexplained {
        warnings.push(u.clone());
    }
    let description = machine_file::calibrated_description(
        loaded,
        &deployed.machine,
        &machine_file::FitRecord::of_identification(&deployed.id),
        machine_file::Provenance {
            method: "diagnose",
            data_file: data,
            parameter_set: "paper15",
            rejected_lines,
            adequate: !unexplained,
            forced: unexplained,
            warnings,
            effects,
            n_geometric: g,
            external: Vec::new(),
        },
        deployed.controller,
    )?;
    machine_file::write(path, &description)
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
    let targets = pose_targets(poses, &m)?;
    let mut campaign = Campaign::from_targets(&m, targets, 1);
    if both_directions {
        campaign.order = PoseOrder::BothDirections;
    }
    // The logged context of the campaign (times, temperature with the
    // stated drift, approach directions), on the nominal machine.
    let mut plant = Plant::geometric(m.clone(), GeometricErrors::default());
    if drift_k != 0.0 {
        plant.effects = vec![Effect::Thermal {
            drift_k,
            expansion_ppm_per_k: 0.0,
        }];
    }
    let data = plant
        .simulate(&campaign)
        .map_err(|e| CliError::input(format!("--poses {poses}: {e}")))?;
    let sigma = campaign.noise.logged_sigma();
    let geometric = GeometricModel::new(m.clone(), ParameterSet::paper15());
    let mut rows = Vec::new();
    for (c, v, label) in realistic(&m) {
        if let Some(d) = detectability(&geometric, c, &v, &data.poses, sigma, 1e-3) {
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
    outln!(
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
    );
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
    Ok(0)
}
