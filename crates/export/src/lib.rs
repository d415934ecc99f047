//! internal: use tricept-ident.
//!
//! `tricept-export`: a calibrated machine file translated into
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
//! - `control.rs`: the control families and models, with each model's
//!   sourced limits;
//! - `correction.rs`: the exact per-leg correction and the stroke;
//! - `setup.rs`: what each control's writer starts from and hands back;
//! - `linear.rs`: absolute tables read by linear interpolation
//!   (Sinumerik, Heidenhain);
//! - `sinumerik.rs`, `fanuc.rs`, `heidenhain.rs`: one writer per control;
//! - `geometry.rs`: the geometry table;
//! - `folder.rs`: the export folder checked before any work and written
//!   as one unit.
//!
//! [`plan`] is pure (the files as text and the summary); [`ExportPlan::write`]
//! writes them as one set. docs/controllers.md documents every format.

#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

use std::path::Path;

use tricept_kinematics::{Machine, MachineDescription};

pub mod control;
pub mod correction;
pub mod fanuc;
mod folder;
mod geometry;
pub mod heidenhain;
pub mod linear;
mod setup;
pub mod sinumerik;
mod types;

use control::{Controller, Limit};
pub use folder::{SUMMARY_FILE, check_out};
pub use types::{
    AxisSummary, ExportError, ExportOptions, ExportSummary, NotExported, SUMMARY_FORMAT_VERSION,
};

use setup::{ControlFiles, Setup};

/// The files of an export and its summary.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportPlan {
    /// The summary.
    pub summary: ExportSummary,
    /// File name and text of each file.
    pub files: Vec<(String, String)>,
}

impl ExportPlan {
    /// Adds a warning to the summary (and to its file): what the caller
    /// knows of the machine file (an old seal, say).
    pub fn warn(&mut self, warning: String) {
        self.summary.warnings.push(warning);
        let json = summary_json(&self.summary);
        if let Some((_, text)) = self.files.iter_mut().find(|(n, _)| n == SUMMARY_FILE) {
            *text = json;
        }
    }

    /// Writes the files into `dir` as one set: into a new folder beside
    /// it, then put in its place in one step, so that `dir` holds the
    /// previous export or this one, whole, never a mixture (a folder
    /// holding anything but an export is refused: [`check_out`]).
    pub fn write(&self, dir: &Path) -> Result<(), ExportError> {
        folder::replace(dir, &self.files)
    }
}

/// The export of the calibrated machine `description` for the control of
/// `options`: the files' text and the summary. Nothing is written.
///
/// Its steps: the options checked (`check_options`, `axis_names`),
/// what every control's writer starts from (`setup_of`), the control's
/// files and the geometry table (`control_files`), what they leave of
/// the machine's error ([`correction::left_by_files`]) and what they
/// cannot carry (`not_exported`), and the summary (`summary_of`).
pub fn plan(
    description: &MachineDescription,
    options: &ExportOptions,
) -> Result<ExportPlan, ExportError> {
    let Some(record) = &description.calibration else {
        return Err(ExportError::NoCalibration);
    };
    let names = axis_names(options)?;
    let warnings = check_options(options)?;
    let machine = description.build()?;
    let setup = setup_of(description, &machine, names, options)?;
    let control = control_files(description, &machine, &setup);
    let workspace_poses = machine.workspace.random_poses(200, 0x0e4b_0a7d);
    let (platform_error_um, compliance_um) =
        correction::left_by_files(&machine, &workspace_poses, &control.readings)?;
    let not_exported = not_exported(&setup, &control, record, compliance_um);
    let summary = summary_of(
        description,
        options,
        &control,
        platform_error_um,
        not_exported,
        warnings,
    );
    let mut files = control.files;
    files.push((SUMMARY_FILE.to_string(), summary_json(&summary)));
    Ok(ExportPlan { summary, files })
}

/// What every control's writer starts from: the legs' exact corrections
/// (their references checked), the axis names, the controller parameters.
fn setup_of<'a>(
    description: &MachineDescription,
    machine: &Machine,
    names: [String; 3],
    options: &'a ExportOptions,
) -> Result<Setup<'a>, ExportError> {
    let legs = correction::checked_leg_corrections(machine, options.reference_mm)?;
    let params = description.controller.unwrap_or_default();
    Ok(Setup {
        legs,
        names,
        leg_offsets_mm: machine.leg_offsets_mm,
        backlash_mm: params.backlash_um.map(|b| b * 1e-3),
        params,
        options,
        max_points: options
            .max_points
            .unwrap_or(options.control.default_max_points()),
    })
}

/// The control's files, by its family's writer, and the geometry table.
fn control_files(
    description: &MachineDescription,
    machine: &Machine,
    setup: &Setup,
) -> ControlFiles {
    let mut control = match setup.options.control.family() {
        Controller::Sinumerik => sinumerik::files(setup),
        Controller::Heidenhain => heidenhain::files(setup),
        Controller::Fanuc => fanuc::files(setup),
    };
    control.files.push((
        geometry::FILE.to_string(),
        geometry::table(description, machine, &control.axes),
    ));
    control
}

/// The summary of an export (its file is [`SUMMARY_FILE`]).
fn summary_of(
    description: &MachineDescription,
    options: &ExportOptions,
    control: &ControlFiles,
    platform_error_um: f64,
    not_exported: Vec<NotExported>,
    warnings: Vec<String>,
) -> ExportSummary {
    let mut file_names: Vec<String> = control.files.iter().map(|(n, _)| n.clone()).collect();
    file_names.push(SUMMARY_FILE.to_string());
    ExportSummary {
        format_version: types::SUMMARY_FORMAT_VERSION,
        controller: options.control.family(),
        control: options.control,
        control_limits: options.control.limits(),
        files: file_names,
        axes: control.axes.clone(),
        platform_error_um,
        not_exported,
        parameters: control.parameters.clone(),
        tolerance_um: options.tolerance_um,
        within_tolerance: control.limits.is_empty(),
        limits: control.limits.clone(),
        warnings,
        calibration_digest: description.calibration_digest(),
    }
}

/// The summary file's text.
fn summary_json(summary: &ExportSummary) -> String {
    serde_json::to_string_pretty(summary).unwrap_or_default() + "\n"
}

/// The three axes' names: `axis_names` or the control's defaults, each
/// one the control accepts, none twice.
fn axis_names(options: &ExportOptions) -> Result<[String; 3], ExportError> {
    let c = options.control.family();
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
            return Err(ExportError::Setting {
                setting: "axis_names",
                why: format!("`{n}` is given twice"),
            });
        }
    }
    Ok(names)
}

/// What the control's files cannot carry, with its size: the legs'
/// gravity compliance (`compliance_um`), thermal growth where the control
/// has no place for it, and the diagnosis' sensor-side corrections.
fn not_exported(
    setup: &Setup,
    control: &ControlFiles,
    record: &tricept_kinematics::description::CalibrationRecord,
    compliance_um: f64,
) -> Vec<NotExported> {
    let mut not_exported = Vec::new();
    let compliance = compliance_um;
    if compliance > 0.0 {
        not_exported.push(NotExported {
            what: "leg_effects.compliance_um_per_kn_at_1m".into(),
            size_um: compliance,
            why: "the legs' gravity compliance depends on the pose, not on one axis' position: it stays in tricept's own kinematics (ik, compensate's table)".into(),
        });
    }
    let alpha = setup.params.thermal_expansion_ppm_per_k;
    if alpha != 0.0 && !control.carries_thermal {
        let longest = setup.legs.iter().map(|l| l.hi_mm).fold(0.0, f64::max);
        not_exported.push(NotExported {
            what: "thermal growth, per K".into(),
            size_um: alpha * 1e-6 * longest * 1e3,
            why: format!(
                "no per-axis thermal parameter of the {} control is documented in the sources used (docs/controllers.md): the legs grow {alpha:.3} ppm/K from {} degC",
                setup.options.control.family(),
                setup.params.reference_temperature_c
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
    not_exported
}

/// Checks the options' ranges, that the Fanuc-only ones are given to
/// Fanuc only, and each against the model's limits: past a hard limit
/// refused, past a stand-in a warning (returned).
fn check_options(o: &ExportOptions) -> Result<Vec<String>, ExportError> {
    let bad = |setting: &'static str, why: String| Err(ExportError::Setting { setting, why });
    if !(o.tolerance_um.is_finite() && o.tolerance_um > 0.0) {
        return bad(
            "tolerance_um",
            format!("must be a positive number, got {}", o.tolerance_um),
        );
    }
    if let Some(n) = o.max_points
        && !(3..=100_000).contains(&n)
    {
        return bad("max_points", format!("must lie from 3 to 100000, got {n}"));
    }
    if o.control.family() != Controller::Fanuc {
        if o.detection_unit_um.is_some() {
            return bad(
                "detection_unit_um",
                "applies to a fanuc control only".into(),
            );
        }
        if o.max_increment.is_some() {
            return bad("max_increment", "applies to a fanuc control only".into());
        }
    }
    if let Some(du) = o.detection_unit_um
        && !(du.is_finite() && du > 0.0 && du <= 100.0)
    {
        return bad(
            "detection_unit_um",
            format!("must lie in (0, 100] um, got {du}"),
        );
    }
    if o.max_increment == Some(0) {
        return bad("max_increment", "must be at least 1".into());
    }
    let limits = o.control.limits();
    let mut warnings = Vec::new();
    let mut against = |setting: &'static str, asked: Option<u64>, limit: Option<Limit>| {
        let (Some(asked), Some(limit)) = (asked, limit) else {
            return Ok(());
        };
        if asked <= limit.value {
            return Ok(());
        }
        let why = format!(
            "{asked} is past the {}'s {} ({})",
            o.control, limit.value, limit.source
        );
        if limit.hard {
            return Err(ExportError::Setting { setting, why });
        }
        warnings.push(format!("{setting}: {why}: check the control's manual"));
        Ok(())
    };
    against(
        "max_points",
        o.max_points.map(|n| n as u64),
        Some(limits.points_per_axis),
    )?;
    against(
        "max_increment",
        o.max_increment.map(u64::from),
        limits.value_range,
    )?;
    Ok(warnings)
}
