//! `tricept simulate`: a measured-data CSV from a simulated machine.

use std::path::PathBuf;

use clap::Args;
use tricept_ident::GeometricModel;
use tricept_plant::{Campaign, Plant, PoseOrder};

use crate::args::{
    MachineArgs, NoiseArgs, ParamArgs, TruthArgs, machine_with_noise, parse_effects, parse_errors,
    pose_targets,
};
use crate::cli_error::CliError;

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
    /// Output file (default: stdout; with --json, a summary goes to stdout).
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
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
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&values));
    plant.effects = parse_effects(&a.truth.truth_effects)?;
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
            "pose set `{}` ({} poses{}), seed {}",
            a.poses,
            data.poses.len(),
            if a.both_directions {
                ", both approach directions"
            } else {
                ""
            },
            a.seed
        ),
        format!(
            "noise per reading: {:.3} arcsec, {:.3} um, mean of {}",
            m.sensors.angle_rad / tricept_kinematics::units::RAD_PER_ARCSEC,
            m.sensors.length_mm * 1e3,
            m.sensors.readings_per_pose
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
    match &a.out {
        Some(path) => {
            tricept_data::write_path(path, &data, &comments)
                .map_err(|e| CliError::other(format!("{}: {e}", path.display())))?;
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
                outln!(
                    "wrote {} poses to {} (machine `{}`, true errors `{truth}`, {} effect(s), seed {})",
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
