//! The export's vocabulary: the controls, their options, the summary of
//! what was written per axis and what the formats cannot carry, and the
//! errors. Below every writer; the root only re-exports it.

use serde::Serialize;
use tricept_kinematics::{DescriptionError, KinematicsError};

use crate::control::{ControlLimits, ControlModel};

/// A failure of an export.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The machine file has no calibration record.
    #[error(
        "the machine file holds no calibration: there is nothing to compensate beyond the nominal machine (export a file written by `tricept diagnose --write-machine` or `tricept identify --write-machine`)"
    )]
    NoCalibration,
    /// An axis name the control cannot accept.
    #[error("--axis-names: `{name}` is not a {controller} axis name ({rule})")]
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

/// A CNC control.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Controller {
    /// Siemens Sinumerik (840D, 828D, 808D).
    Sinumerik,
    /// Fanuc (Series 0i, 16i/18i/21i, 30i).
    Fanuc,
    /// Heidenhain (TNC, iTNC, MANUALplus).
    Heidenhain,
}

impl Controller {
    /// Every control, in the order `--controller` lists them.
    pub const ALL: [Controller; 3] = [
        Controller::Sinumerik,
        Controller::Fanuc,
        Controller::Heidenhain,
    ];

    /// The name on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Controller::Sinumerik => "sinumerik",
            Controller::Fanuc => "fanuc",
            Controller::Heidenhain => "heidenhain",
        }
    }

    /// The axis names used without `--axis-names`.
    pub fn default_axis_names(self) -> [&'static str; 3] {
        match self {
            Controller::Sinumerik => ["X1", "Y1", "Z1"],
            Controller::Fanuc | Controller::Heidenhain => ["U", "V", "W"],
        }
    }

    /// Whether `name` is an axis name the control accepts, else what it
    /// accepts.
    pub(crate) fn check_axis_name(self, name: &str) -> Result<(), &'static str> {
        let b = name.as_bytes();
        let ok = match self {
            Controller::Sinumerik => {
                (1..=8).contains(&b.len())
                    && b[0].is_ascii_uppercase()
                    && b.iter()
                        .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || *c == b'_')
            }
            Controller::Fanuc => b.len() == 1 && b"XYZABCUVW".contains(&b[0]),
            Controller::Heidenhain => {
                (1..=2).contains(&b.len())
                    && b"XYZABCUVW".contains(&b[0])
                    && b[1..].iter().all(u8::is_ascii_digit)
            }
        };
        ok.then_some(()).ok_or(match self {
            Controller::Sinumerik => {
                "a machine axis name: 1 to 8 upper-case letters, digits or `_`, starting with a letter"
            }
            Controller::Fanuc => "one of the letters X Y Z A B C U V W (parameter 1020)",
            Controller::Heidenhain => "an axis key: X Y Z A B C U V or W, optionally one digit",
        })
    }
}

impl std::str::FromStr for Controller {
    type Err = String;
    fn from_str(s: &str) -> Result<Controller, String> {
        Controller::ALL
            .into_iter()
            .find(|c| c.as_str() == s.to_ascii_lowercase())
            .ok_or_else(|| {
                format!("unknown controller `{s}`: expected sinumerik, fanuc or heidenhain")
            })
    }
}

impl std::fmt::Display for Controller {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
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

/// The summary of an export (the JSON the verb prints).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExportSummary {
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
    /// Whether every axis' format error is within the tolerance.
    pub within_tolerance: bool,
    /// The limits to raise for the axes past the tolerance (or the
    /// control's ranges the files would exceed): nothing is written.
    pub limits: Vec<String>,
    /// Options past a limit the sources do not state as hard (the files
    /// are written: check the control's manual).
    pub warnings: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controllers_are_named_as_on_the_command_line() {
        let names = Controller::ALL.map(Controller::as_str);
        assert_eq!(names, ["sinumerik", "fanuc", "heidenhain"]);
        // Read back, in any case; an unknown name is refused.
        for (c, name) in Controller::ALL.into_iter().zip(names) {
            assert_eq!(name.parse::<Controller>(), Ok(c));
            assert_eq!(name.to_uppercase().parse::<Controller>(), Ok(c));
            assert_eq!(c.to_string(), name);
        }
        let e = "siemens".parse::<Controller>().unwrap_err();
        assert!(e.starts_with("unknown controller `siemens`"), "{e}");
    }

    #[test]
    fn axis_names_follow_each_control_s_rule() {
        let ok = |c: Controller, n: &str| c.check_axis_name(n).is_ok();
        // Sinumerik: 1 to 8 upper-case letters, digits or `_`, a letter first.
        for n in ["X1", "AX_3", "ABCDEFGH"] {
            assert!(ok(Controller::Sinumerik, n), "{n}");
        }
        for n in ["", "1X", "x1", "ABCDEFGHI", "A-1"] {
            assert!(!ok(Controller::Sinumerik, n), "{n}");
        }
        // Fanuc: one of X Y Z A B C U V W.
        assert!(ok(Controller::Fanuc, "U") && ok(Controller::Fanuc, "W"));
        for n in ["", "UV", "Q", "U1"] {
            assert!(!ok(Controller::Fanuc, n), "{n}");
        }
        // Heidenhain: such a letter and at most one digit.
        assert!(ok(Controller::Heidenhain, "U") && ok(Controller::Heidenhain, "V2"));
        for n in ["", "UA", "Q1", "U12", "2"] {
            assert!(!ok(Controller::Heidenhain, n), "{n}");
        }
    }
}
