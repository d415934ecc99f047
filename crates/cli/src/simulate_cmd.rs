//! `tricept simulate`: a measured-data CSV from a simulated machine.

use std::path::PathBuf;

use clap::Args;
use tricept_ident::GeometricModel;
use tricept_plant::{Campaign, Plant, PoseOrder};

use crate::args::{
    MachineArgs, NoiseArgs, ParamArgs, machine_with_noise, parse_effects, parse_errors,
    pose_targets,
};
use crate::cli_error::CliError;

/// `tricept simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// True errors of the simulated machine.
    #[arg(long, default_value = "table2")]
    pub errors: String,
    /// Pose set (as for `identifiability`).
    #[arg(long, default_value = "grid")]
    pub poses: String,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
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
    /// An unmodelled effect (JSON object or @FILE); repeatable.
    #[arg(long = "effect", value_name = "JSON")]
    pub effects: Vec<String>,
    /// Output file (default: stdout).
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
pub fn run(a: &SimulateArgs) -> Result<(), CliError> {
    let m = machine_with_noise(&a.machine, &a.noise)?;
    let set = a.params.set()?;
    let values = parse_errors(&a.errors, &set)?;
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
    plant.effects = parse_effects(&a.effects)?;
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
    match &a.out {
        Some(path) => tricept_data::write_path(path, &data, &comments)
            .map_err(|e| CliError::other(format!("{}: {e}", path.display()))),
        None => tricept_data::write_to(std::io::stdout().lock(), &data, &comments)
            .map_err(|e| CliError::other(format!("stdout: {e}"))),
    }
}
