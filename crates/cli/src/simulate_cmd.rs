//! `tricept simulate`: a measured-data CSV from a simulated machine.

use std::path::Path;

use tricept_ident::GeometricModel;
use tricept_plant::{Campaign, Effect, Plant, PoseOrder};

use crate::MachineArgs;
use crate::cli_error::CliError;
use crate::ident_cmd::{NoiseArgs, ParamArgs, machine_with_noise, parse_errors};

/// Everything `simulate` needs.
pub struct SimulateArgs<'a> {
    /// Machine and output format.
    pub machine: &'a MachineArgs,
    /// Noise overrides.
    pub noise: &'a NoiseArgs,
    /// Parameter set of `errors`.
    pub params: &'a ParamArgs,
    /// `table2`, `zero`, `random:MAG[,SEED]` or a JSON file.
    pub errors: &'a str,
    /// Pose set spec.
    pub poses: &'a str,
    /// Seed of the noise.
    pub seed: u64,
    /// Visit every pose from both directions.
    pub both_directions: bool,
    /// Effects, as JSON objects (inline or `@file`).
    pub effects: &'a [String],
    /// Output file (stdout when absent).
    pub out: Option<&'a Path>,
}

pub fn parse_effects(specs: &[String]) -> Result<Vec<Effect>, CliError> {
    let mut out = Vec::new();
    for spec in specs {
        let (text, origin) = match spec.strip_prefix('@') {
            Some(path) => (
                std::fs::read_to_string(path)
                    .map_err(|e| CliError::input(format!("{path}: {e}")))?,
                path.to_string(),
            ),
            None => (spec.clone(), "--effect".to_string()),
        };
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| CliError::input(format!("{origin}: {e}")))?;
        let items = match value {
            serde_json::Value::Array(a) => a,
            v => vec![v],
        };
        for item in items {
            out.push(
                serde_json::from_value(item)
                    .map_err(|e| CliError::input(format!("{origin}: {e}")))?,
            );
        }
    }
    Ok(out)
}

/// `tricept simulate`.
pub fn run(a: SimulateArgs<'_>) -> Result<(), CliError> {
    let m = machine_with_noise(a.machine, a.noise)?;
    let set = a.params.set()?;
    let values = parse_errors(a.errors, &set)?;
    let targets = tricept_plant::campaign::pose_set(a.poses, &m).map_err(CliError::input)?;
    let mut campaign = Campaign::from_targets(&m, targets, a.seed);
    if a.both_directions {
        campaign.order = PoseOrder::BothDirections;
    }
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&values));
    plant.effects = parse_effects(a.effects)?;
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
            m.sensors.angle_rad / tricept_kinematics::SensorNoise::ARCSEC,
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
    match a.out {
        Some(path) => tricept_data::write_path(path, &data, &comments)
            .map_err(|e| CliError::other(format!("{}: {e}", path.display()))),
        None => tricept_data::write_to(std::io::stdout().lock(), &data, &comments)
            .map_err(|e| CliError::other(format!("stdout: {e}"))),
    }
}
