//! The export's vocabulary: its options, the summary of what was written
//! per axis and what the formats cannot carry, and the errors. Below every
//! writer; the root only re-exports it.

use serde::Serialize;
use tricept_kinematics::{KinematicsError, error::DescriptionError};

use crate::control::{ControlLimits, ControlModel, Controller};

/// A failure of an export.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The machine file has no calibration record.
    #[error(
        "the machine file holds no calibration: there is nothing to compensate beyond the nominal machine (export a machine file a calibration wrote: identify's or diagnose's `write_machine`)"
    )]
    NoCalibration,
    /// An axis name the control cannot accept.
    #[error("axis_names: `{name}` is not a {controller} axis name ({rule})")]
    AxisName {
        /// The name as given.
        name: String,
        /// The control.
        controller: &'static str,
        /// What the control accepts.
        rule: &'static str,
    },
    /// An option out of range or not for this control.
    #[error("{0}")]
    Options(String),
    /// One option out of range or not for this control: the option (its
    /// field of [`ExportOptions`], e.g. `max_points`) and why.
    #[error("{setting}: {why}")]
    Setting {
        /// The option's field name.
        setting: &'static str,
        /// Why it is refused.
        why: String,
    },
    /// The machine description cannot be built.
    #[error("the machine file: {0}")]
    Description(#[from] DescriptionError),
    /// The calibrated machine cannot reach a point of its workspace.
    #[error("the calibrated machine: {0}")]
    Kinematics(#[from] KinematicsError),
    /// The output folder cannot take the export (checked before any
    /// work): it is a file, or it holds files that are not an export, or
    /// the machine file itself.
    #[error("{path}: {why}")]
    Out {
        /// The output folder as given.
        path: String,
        /// Why.
        why: String,
    },
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
}

/// What the export is asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportOptions {
    /// The control model (its family says which files are written).
    pub control: ControlModel,
    /// The three leg axes' names (default: [`Controller::default_axis_names`]).
    pub axis_names: Option<[String; 3]>,
    /// The most compensation points per axis the control takes (default:
    /// [`ControlModel::default_max_points`]).
    pub max_points: Option<usize>,
    /// Fanuc: the detection unit, um (default 1).
    pub detection_unit_um: Option<f64>,
    /// Fanuc: the largest value of one pitch compensation point, in
    /// detection units times the magnification (default: the model's
    /// range, 7).
    pub max_increment: Option<u32>,
    /// The largest format error accepted, um.
    pub tolerance_um: f64,
    /// Each axis' reference point, mm (default: the legs' commands at the
    /// centre of the workspace).
    pub reference_mm: Option<[f64; 3]>,
}

impl ExportOptions {
    /// The defaults for `controller`'s model of [`ControlModel::of_family`],
    /// tolerance 1 um.
    pub fn new(controller: Controller) -> ExportOptions {
        ExportOptions::for_model(ControlModel::of_family(controller))
    }

    /// The defaults for `control`, tolerance 1 um.
    pub fn for_model(control: ControlModel) -> ExportOptions {
        ExportOptions {
            control,
            axis_names: None,
            max_points: None,
            detection_unit_um: None,
            max_increment: None,
            tolerance_um: 1.0,
            reference_mm: None,
        }
    }
}

/// One leg axis in the summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisSummary {
    /// The leg, 1 to 3.
    pub leg: u8,
    /// The control's axis name.
    pub axis: String,
    /// Compensation points written.
    pub points: usize,
    /// Their spacing, mm.
    pub step_mm: f64,
    /// The first point's position, mm.
    pub min_mm: f64,
    /// The last point's position, mm.
    pub max_mm: f64,
    /// Largest difference over the stroke between the control's reading
    /// of the written table and the exact correction, um.
    pub format_error_um: f64,
    /// The reference point, mm (the table reads zero there).
    pub reference_mm: f64,
    /// The constant taken out of the table (the leg's extra length at the
    /// reference point), mm; it is part of `zero_mm`.
    pub offset_mm: f64,
    /// The leg's zero for the PKM transformation: leg length = axis
    /// position + zero, mm (geometry.csv).
    pub zero_mm: f64,
}

/// What the control's files cannot carry.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotExported {
    /// What it is.
    pub what: String,
    /// Its size over the workspace, um.
    pub size_um: f64,
    /// Why it is not exported, and where it is.
    pub why: String,
}

/// The format version of the export's summary file this tricept writes
/// (`format_version` key), and the newest a report reads.
pub const SUMMARY_FORMAT_VERSION: u32 = 1;

/// The summary of an export (the JSON the verb prints).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExportSummary {
    /// The summary file's format version: [`SUMMARY_FORMAT_VERSION`] (a
    /// summary without it, written before it, is version 1).
    pub format_version: u32,
    /// The control's family (which files).
    pub controller: Controller,
    /// The control model.
    pub control: ControlModel,
    /// The model's limits, with their sources.
    pub control_limits: ControlLimits,
    /// The files, in the output directory.
    pub files: Vec<String>,
    /// The leg axes.
    pub axes: Vec<AxisSummary>,
    /// The largest displacement of the platform point that the axes'
    /// format errors cause together, over 200 workspace poses, um: a leg
    /// error moves the platform up to several times as far.
    pub platform_error_um: f64,
    /// What the files cannot carry.
    pub not_exported: Vec<NotExported>,
    /// Parameters to set on the control, one line each.
    pub parameters: Vec<String>,
    /// The tolerance on the format error, um.
    pub tolerance_um: f64,
    /// Whether the files are written: every axis' format error within the
    /// tolerance *and* nothing past the control's ranges (`limits` empty).
    /// A Fanuc table whose points exceed the control's range is `false`
    /// even when its format errors are within the tolerance.
    pub within_tolerance: bool,
    /// The limits to raise for the axes past the tolerance (or the
    /// control's ranges the files would exceed): nothing is written.
    pub limits: Vec<String>,
    /// Options past a limit the sources do not state as hard (the files
    /// are written: check the control's manual).
    pub warnings: Vec<String>,
    /// The calibration exported: its digest
    /// (`MachineDescription::calibration_digest`), by which a report tells
    /// an export of another calibration.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibration_digest: Option<String>,
}
