//! `tricept diagnose` and `tricept detectability`.

use std::path::Path;

use tricept_diagnose::detect::{advise, detectability, realistic};
use tricept_diagnose::diagnose::{DiagnoseError, DiagnoseOptions, diagnose};
use tricept_ident::GeometricModel;
use tricept_model::{GeometricErrors, ParameterSet};
use tricept_plant::{Campaign, Effect, Plant, PoseOrder};

use crate::MachineArgs;
use crate::cli_error::CliError;
use crate::ident_cmd::{NoiseArgs, machine_with_noise, read_data};

/// `tricept diagnose`.
pub fn run_diagnose(
    machine: &MachineArgs,
    noise: &NoiseArgs,
    data: &Path,
    plots: Option<&Path>,
) -> Result<(), CliError> {
    let m = machine_with_noise(machine, noise)?;
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
    if let Some(dir) = plots {
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
        return Ok(());
    }
    outln!(
        "{}: the geometric model {}",
        source,
        if d.adequate {
            "explains the data (adequate)"
        } else {
            "does NOT explain the data"
        }
    );
    outln!(
        "geometric fit: chi2 {:.1} for {} dof (p = {:.2e}); residual rms phi {:.3} arcsec, theta {:.3} arcsec, s {:.3} um",
        d.chi_square,
        d.dof,
        d.chi_square_p_value,
        d.residual_rms_geometric[0],
        d.residual_rms_geometric[1],
        d.residual_rms_geometric[2]
    );
    if let Some(s) = d.structure.first() {
        outln!(
            "strongest residual structure: {} vs {} (r = {:+.2}, p = {:.1e})",
            s.channel,
            s.regressor,
            s.correlation,
            s.p_value
        );
    }
    for (i, c) in d.causes.iter().enumerate() {
        let ev = &c.evidence;
        outln!(
            "cause {}: {}   (chi2 drop {:.1} for {} dof, p = {:.1e}; BIC gain {:.1}{})",
            i + 1,
            c.effect,
            ev.delta_chi_square,
            ev.dof,
            ev.p_value,
            ev.delta_bic,
            match (ev.holdout_rms_without, ev.holdout_rms_with) {
                (Some(a), Some(b)) => format!("; held-out rms {a:.2} -> {b:.2}"),
                _ => String::new(),
            }
        );
        for p in &c.parameters {
            match p.std_dev {
                Some(sd) => outln!("    {:<40} {:>12.4} +- {:.4}", p.name, p.value, sd),
                None => outln!("    {:<40} {:>12.4}", p.name, p.value),
            }
        }
        if !c.rows.is_empty() {
            outln!("    lines: {:?}", c.rows);
        }
    }
    if let Some(u) = &d.unexplained {
        outln!("unexplained: {u}");
    }
    let mut bias = d.geometric_bias.clone();
    bias.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    if !d.causes.is_empty() {
        let text: Vec<String> = bias
            .iter()
            .take(4)
            .map(|(n, v)| format!("{n} {:+.4}", v))
            .collect();
        outln!(
            "bias the causes put into the geometric parameters (mm): {}",
            text.join(", ")
        );
    }
    let g = &d.gain;
    outln!(
        "gain: held-out rms {:.3} -> {:.3} (noise = 1); platform moved on the middle plane by {:.4} mm mean ({:.4} after touch-off), {:.4} mm max",
        g.holdout_rms_geometric,
        g.holdout_rms_extended,
        g.volumetric_mean_mm,
        g.volumetric_touched_mean_mm,
        g.volumetric_max_mm
    );
    Ok(())
}

/// `tricept detectability`.
pub fn run_detectability(
    machine: &MachineArgs,
    noise: &NoiseArgs,
    poses: &str,
    both_directions: bool,
    drift_k: f64,
) -> Result<(), CliError> {
    let m = machine_with_noise(machine, noise)?;
    let targets = tricept_plant::campaign::pose_set(poses, &m).map_err(CliError::input)?;
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
        return Ok(());
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
    Ok(())
}
