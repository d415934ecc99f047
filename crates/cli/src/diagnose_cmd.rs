//! `tricept diagnose` and `tricept detectability`.

use std::path::PathBuf;

use clap::Args;
use tricept_diagnose::detect::{advise, detectability, realistic};
use tricept_diagnose::{DiagnoseError, DiagnoseOptions, diagnose};
use tricept_ident::GeometricModel;
use tricept_model::{GeometricErrors, ParameterSet};
use tricept_plant::{Campaign, Effect, Plant, PoseOrder};

use crate::args::{MachineArgs, NoiseArgs, machine_with_noise, pose_targets, read_data};
use crate::cli_error::CliError;

/// `tricept diagnose`.
#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// Measured-data CSV (context columns temp_c, time_s, dir1..3 are used when present).
    #[arg(long, value_name = "FILE.csv")]
    pub data: PathBuf,
    /// Write residual plots (SVG) of the named causes into this directory.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept detectability`.
#[derive(Debug, Args)]
pub struct DetectabilityArgs {
    /// Pose set (as for `identifiability`).
    #[arg(long, default_value = "grid")]
    pub poses: String,
    /// Visit every pose twice, approaching from both directions.
    #[arg(long)]
    pub both_directions: bool,
    /// Temperature change over the campaign, K (0: no thermal signature).
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub temperature_drift: f64,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept diagnose`.
pub fn run_diagnose(a: &DiagnoseArgs) -> Result<u8, CliError> {
    let (machine, data) = (&a.machine, a.data.as_path());
    let m = machine_with_noise(machine, &a.noise)?;
    let dataset = read_data(data, &m)?;
    let source = data.display().to_string();
    let d = diagnose(&m, &dataset, &DiagnoseOptions::for_machine(&m)).map_err(|e| match e {
        DiagnoseError::TooFewPoses(_) => CliError::input(format!("{source}: {e}")),
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
    if machine.json {
        outln!("{}", d.to_json());
        return Ok(0);
    }
    crate::output::write_text(&d.to_text(&source));
    Ok(0)
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
