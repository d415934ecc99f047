//! `tricept-export` (internal): a calibrated machine file translated into
//! the files a CNC control loads: Sinumerik, Fanuc or Heidenhain.
//!
//! Each Tricept leg is a CNC axis driven by a ball screw. What depends on a
//! leg's command alone (its lead and its deployed compensation table) goes
//! into the control's leadscrew or pitch-error compensation, zero at the
//! axis' reference point, the constant stated and put into the leg's zero;
//! backlash and thermal growth go into the control's own parameters; the
//! calibrated geometry (joints, leg zeros, UP limb) is written as a plain
//! table for the machine builder's PKM transformation (`geometry.csv`).
//! What a control cannot carry is listed with its size
//! ([`ExportSummary::not_exported`]).
//!
//! - `correction.rs`: the exact per-leg correction and the stroke;
//! - `linear.rs`: absolute tables read by linear interpolation
//!   (Sinumerik, Heidenhain);
//! - `sinumerik.rs`, `fanuc.rs`, `heidenhain.rs`: one writer per control;
//! - `geometry.rs`: the geometry table.
//!
//! [`plan`] is pure (the files as text and the summary); [`ExportPlan::write`]
//! writes them atomically. docs/controllers.md documents every format.

#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

use std::path::Path;

use tricept_kinematics::MachineDescription;

pub mod correction;
pub mod fanuc;
mod geometry;
pub mod heidenhain;
pub mod linear;
pub mod sinumerik;
mod types;

pub use types::{AxisSummary, Controller, ExportError, ExportOptions, ExportSummary, NotExported};

/// The files of an export and its summary.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportPlan {
    /// The summary.
    pub summary: ExportSummary,
    /// File name and text of each file.
    pub files: Vec<(String, String)>,
}

impl ExportPlan {
    /// Writes every file into `dir` (created when missing), each
    /// atomically.
    pub fn write(&self, dir: &Path) -> Result<(), ExportError> {
        let io = |path: &Path, source| ExportError::Io {
            path: path.display().to_string(),
            source,
        };
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        for (name, text) in &self.files {
            let path = dir.join(name);
            tricept_data::write_atomic(&path, |w| w.write_all(text.as_bytes()))
                .map_err(|e| io(&path, e))?;
        }
        Ok(())
    }
}

/// The summary JSON file's name.
pub const SUMMARY_FILE: &str = "export.json";

/// The export of the calibrated machine `description` for the control of
/// `options`: the files' text and the summary. Nothing is written.
pub fn plan(
    description: &MachineDescription,
    options: &ExportOptions,
) -> Result<ExportPlan, ExportError> {
    let Some(record) = &description.calibration else {
        return Err(ExportError::NoCalibration);
    };
    let c = options.controller;
    let names: [String; 3] = match &options.axis_names {
        Some(n) => n.clone(),
        None => c.default_axis_names().map(String::from),
    };
    for (i, n) in names.iter().enumerate() {
        c.check_axis_name(n).map_err(|rule| ExportError::AxisName {
            name: n.clone(),
            controller: c.as_str(),
            rule,
        })?;
        if names[..i].contains(n) {
            return Err(ExportError::Options(format!(
                "--axis-names: `{n}` is given twice"
            )));
        }
    }
    check_options(options)?;
    let machine = description.build()?;
    let legs = correction::leg_corrections(&machine, options.reference_mm)?;
    correction::check_references(&legs)?;
    let max_points = options.max_points.unwrap_or(c.default_max_points());
    let controller_params = description.controller.unwrap_or_default();
    let backlash_mm = controller_params.backlash_um.map(|b| b * 1e-3);
    let mut parameters = Vec::new();
    let mut limits = Vec::new();
    let mut files = Vec::new();
    let mut axes = Vec::new();
    let mut carries_thermal = false;
    let summarise = |i: usize, points, step, min, max, error: f64, shift: f64| {
        let l = &legs[i];
        let offset = l.extra_mm(l.reference_mm) + shift;
        AxisSummary {
            leg: i as u8 + 1,
            axis: names[i].clone(),
            points,
            step_mm: step,
            min_mm: min,
            max_mm: max,
            format_error_um: error,
            reference_mm: l.reference_mm,
            offset_mm: offset,
            zero_mm: machine.leg_offsets_mm[i] + offset - 0.5 * backlash_mm[i],
        }
    };
    // Each leg's length as the control leaves it minus the exact one, mm,
    // at a leg command.
    let mut deviation: Vec<Box<dyn Fn(f64) -> f64>> = Vec::new();
    match c {
        Controller::Sinumerik | Controller::Heidenhain => {
            let resolution = match c {
                Controller::Sinumerik => 10f64.powi(-(sinumerik::DECIMALS as i32)),
                _ => 10f64.powi(-(heidenhain::DECIMALS as i32)),
            };
            let tables: Vec<linear::LinearTable> = legs
                .iter()
                .map(|l| linear::resample(l, max_points, resolution))
                .collect();
            for (t, l) in tables.iter().zip(&legs) {
                let (t, l) = (t.clone(), l.clone());
                deviation.push(Box::new(move |q| t.deviation_mm(&l, q)));
            }
            for (i, t) in tables.iter().enumerate() {
                axes.push(summarise(
                    i,
                    t.values_mm.len(),
                    t.step_mm,
                    t.start_mm,
                    t.end_mm(),
                    t.format_error_um,
                    t.shift_mm,
                ));
                if t.format_error_um > options.tolerance_um {
                    limits.push(format!(
                        "axis {}: format error {:.3} um past --tolerance-um {}: raise --max-points ({}) to {} (the deployed table's own spacing)",
                        names[i],
                        t.format_error_um,
                        options.tolerance_um,
                        match c {
                            Controller::Sinumerik => "MD38000 MM_ENC_COMP_MAX_POINTS",
                            _ => "the points a *.COM table takes",
                        },
                        t.points_needed
                    ));
                }
            }
            if c == Controller::Sinumerik {
                files.push((
                    "AX_EEC_INI.SPF".to_string(),
                    sinumerik::table_program(&tables, &names),
                ));
                files.push((
                    "MACHINE_DATA.TXT".to_string(),
                    sinumerik::machine_data(
                        &tables,
                        &names,
                        &backlash_mm,
                        controller_params.thermal_expansion_ppm_per_k,
                        controller_params.reference_temperature_c,
                    ),
                ));
                carries_thermal = true;
                for (i, ax) in names.iter().enumerate() {
                    parameters.push(format!("{ax}: MD32700 ENC_COMP_ENABLE[0] = 1; MD38000 MM_ENC_COMP_MAX_POINTS[0] >= {}; MD32450 BACKLASH[0] = {:.6} mm", tables[i].values_mm.len(), backlash_mm[i]));
                    if controller_params.thermal_expansion_ppm_per_k != 0.0 {
                        parameters.push(format!(
                            "{ax}: MD32750 TEMP_COMP_TYPE = 2 (position dependent); SD43900 TEMP_COMP_ABS_VALUE = 0; SD43920 TEMP_COMP_REF_POSITION = 0 mm; SD43910 TEMP_COMP_SLOPE = {:.6e} * (T - {} degC), set by the PLC",
                            -controller_params.thermal_expansion_ppm_per_k * 1e-6,
                            controller_params.reference_temperature_c
                        ));
                    }
                }
            } else {
                for (t, ax) in tables.iter().zip(&names) {
                    files.push((heidenhain::com_name(ax), heidenhain::com_table(t, ax)));
                }
                files.push((
                    heidenhain::CMA_NAME.to_string(),
                    heidenhain::cma_table(&names),
                ));
                files.push((
                    "MACHINE_PARAMETERS.TXT".to_string(),
                    heidenhain::machine_parameters(&names, &backlash_mm),
                ));
                for (i, ax) in names.iter().enumerate() {
                    parameters.push(format!(
                        "{ax}: MP_backLash = {:.4} mm; {} active in {}",
                        backlash_mm[i],
                        heidenhain::com_name(ax),
                        heidenhain::CMA_NAME
                    ));
                }
            }
        }
        Controller::Fanuc => {
            let du = options.detection_unit_um.unwrap_or(1.0);
            let cap = options.max_increment.unwrap_or(127);
            let mut next = 0;
            let mut fanuc_axes = Vec::new();
            for l in &legs {
                let a = fanuc::plan(l, max_points, next, du, cap);
                next = a.last_point + 1;
                fanuc_axes.push(a);
            }
            for (a, l) in fanuc_axes.iter().zip(&legs) {
                let (a, l) = (a.staircase(du), l.clone());
                deviation.push(Box::new(move |q| a.deviation_mm(&l, q)));
            }
            for (i, a) in fanuc_axes.iter().enumerate() {
                let start = a.reference_mm
                    + (a.first_point as f64 - a.reference_point as f64) * a.interval_mm;
                axes.push(summarise(
                    i,
                    a.increments.len(),
                    a.interval_mm,
                    start,
                    start + a.interval_mm * (a.increments.len() - 1) as f64,
                    a.format_error_um,
                    a.shift_mm,
                ));
                if a.clipped {
                    limits.push(format!(
                        "axis {}: a point's value exceeds --max-increment {cap} even at magnification {} (parameter 3623): raise --max-points or --max-increment",
                        names[i],
                        fanuc::MAX_MAGNIFICATION
                    ));
                } else if a.format_error_um > options.tolerance_um {
                    // A staircase misses by half a section's change plus
                    // half a unit: the sections shrink with the points.
                    let rounding_um = 0.5 * du * f64::from(a.magnification);
                    let lower = format!(
                        "lower --detection-unit-um ({du} um, magnification {}: half a unit is {rounding_um:.3} um)",
                        a.magnification
                    );
                    let remedy = if rounding_um >= options.tolerance_um {
                        lower
                    } else {
                        let points = a.increments.len() as f64 * (a.format_error_um - rounding_um)
                            / (options.tolerance_um - rounding_um);
                        format!(
                            "raise --max-points (the points of the axis) to more than {}, or {lower}",
                            points.ceil()
                        )
                    };
                    limits.push(format!(
                        "axis {}: format error {:.3} um past --tolerance-um {}: {remedy}",
                        names[i], a.format_error_um, options.tolerance_um
                    ));
                }
            }
            let backlash_units = controller_params
                .backlash_um
                .map(|b| (b / du).round() as i64);
            files.push(("PITCH.TXT".to_string(), fanuc::pitch_tape(&fanuc_axes)));
            files.push((
                "PARAM.TXT".to_string(),
                fanuc::parameter_tape(&fanuc_axes, &backlash_units),
            ));
            for (i, (a, ax)) in fanuc_axes.iter().zip(&names).enumerate() {
                parameters.push(format!(
                    "{ax} (axis {}): 1851 = {} (backlash, detection units of {du} um); 3620 = {}; 3621 = {}; 3622 = {}; 3623 = {}; 3624 = {} ({:.4} mm)",
                    i + 1,
                    backlash_units[i],
                    a.reference_point,
                    a.first_point,
                    a.last_point,
                    a.magnification,
                    a.interval_units,
                    a.interval_mm
                ));
            }
        }
    }
    files.push((
        geometry::FILE.to_string(),
        geometry::table(description, &machine, &axes),
    ));
    let workspace_poses = machine.workspace.random_poses(200, 0x0e4b_0a7d);
    let platform_error_um = correction::platform_error_um(&machine, &workspace_poses, &deviation)?;
    let mut not_exported = Vec::new();
    let compliance = correction::compliance_size_um(&machine, &workspace_poses)?;
    if compliance > 0.0 {
        not_exported.push(NotExported {
            what: "leg_effects.compliance_um_per_kn_at_1m".into(),
            size_um: compliance,
            why: "the legs' gravity compliance depends on the pose, not on one axis' position: it stays in tricept's own kinematics (ik, compensate --table)".into(),
        });
    }
    let alpha = controller_params.thermal_expansion_ppm_per_k;
    if alpha != 0.0 && !carries_thermal {
        let longest = legs.iter().map(|l| l.hi_mm).fold(0.0, f64::max);
        not_exported.push(NotExported {
            what: "thermal growth, per K".into(),
            size_um: alpha * 1e-6 * longest * 1e3,
            why: format!(
                "no per-axis thermal parameter of the {c} control is documented in the sources used (docs/controllers.md): the legs grow {alpha:.3} ppm/K from {} degC",
                controller_params.reference_temperature_c
            ),
        });
    }
    for line in record
        .records
        .iter()
        .filter(|r| r.contains("sensor correction"))
    {
        not_exported.push(NotExported {
            what: line.clone(),
            size_um: 0.0,
            why: "a correction of the UP limb's readings: it changes no position the control commands".into(),
        });
    }
    let mut file_names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    file_names.push(SUMMARY_FILE.to_string());
    let summary = ExportSummary {
        controller: c,
        files: file_names,
        axes,
        platform_error_um,
        not_exported,
        parameters,
        tolerance_um: options.tolerance_um,
        within_tolerance: limits.is_empty(),
        limits,
    };
    let json = serde_json::to_string_pretty(&summary).unwrap_or_default();
    files.push((SUMMARY_FILE.to_string(), json + "\n"));
    Ok(ExportPlan { summary, files })
}

/// Checks the options' ranges, and that the Fanuc-only ones are given to
/// Fanuc only.
fn check_options(o: &ExportOptions) -> Result<(), ExportError> {
    let bad = |m: String| Err(ExportError::Options(m));
    if !(o.tolerance_um.is_finite() && o.tolerance_um > 0.0) {
        return bad(format!(
            "--tolerance-um: must be a positive number, got {}",
            o.tolerance_um
        ));
    }
    if let Some(n) = o.max_points
        && !(3..=100_000).contains(&n)
    {
        return bad(format!("--max-points: must lie from 3 to 100000, got {n}"));
    }
    if o.controller != Controller::Fanuc {
        if o.detection_unit_um.is_some() {
            return bad("--detection-unit-um: applies to --controller fanuc only".into());
        }
        if o.max_increment.is_some() {
            return bad("--max-increment: applies to --controller fanuc only".into());
        }
    }
    if let Some(du) = o.detection_unit_um
        && !(du.is_finite() && du > 0.0 && du <= 100.0)
    {
        return bad(format!(
            "--detection-unit-um: must lie in (0, 100] um, got {du}"
        ));
    }
    if o.max_increment == Some(0) {
        return bad("--max-increment: must be at least 1".into());
    }
    Ok(())
}
