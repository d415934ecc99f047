//! `export`: a calibrated machine file translated into the files a CNC
//! control loads (`tricept-export`): a typed [`ExportRequest`] to an
//! [`Export`] with its exit code, its JSON and its text report.
//!
//! # Example
//! ```no_run
//! use tricept_ident::MachineInput;
//! use tricept_ident::export::{Controller, ExportOptions, ExportRequest, export};
//! let request = ExportRequest::new(
//!     MachineInput::from("calibrated.json"),
//!     ExportOptions::new(Controller::Heidenhain),
//!     "export",
//! );
//! let exported = export(request)?;
//! assert!(exported.written() || exported.exit_code() != tricept_ident::EXIT_OK);
//! # Ok::<(), tricept_ident::Error>(())
//! ```

use std::path::PathBuf;

use crate::error::{EXIT_INADEQUATE, EXIT_OK, Error};
use crate::machine_input::MachineInput;

/// One leg axis of an export: its table's points, their spacing and range
/// (mm), and the error of the table's format (um).
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::export::{Controller, ExportOptions, ExportRequest, export};
/// let options = ExportOptions::new(Controller::Sinumerik);
/// let exported = export(ExportRequest::new(MachineInput::from("calibrated.json"), options, "export"))?;
/// for (i, axis) in exported.summary().axes.iter().enumerate() {
///     assert_eq!(usize::from(axis.leg), i + 1);
///     let span_mm = axis.step_mm * (axis.points as f64 - 1.0);
///     assert!((axis.max_mm - axis.min_mm - span_mm).abs() < 1e-6);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_export::AxisSummary;
/// An export's failure: a machine file without a calibration, an option
/// the control does not take, a failed write (not the input's fault).
///
/// # Example
/// ```
/// use tricept_ident::advanced::Classify;
/// use tricept_ident::export::ExportError;
/// use tricept_ident::{EXIT_INPUT, Error, ErrorKind};
/// let e = ExportError::NoCalibration;
/// assert_eq!(e.kind(), ErrorKind::Input);
/// let door = Error::from_library(e);
/// assert_eq!(door.exit_code(), EXIT_INPUT);
/// assert!(door.message().contains("no calibration"), "{}", door.message());
/// ```
#[doc(inline)]
pub use tricept_export::ExportError;
/// The control and the limits of an export ([`ExportRequest`]'s `options`).
///
/// # Example
/// ```
/// use tricept_ident::export::{Controller, ExportOptions};
/// let fanuc = ExportOptions::new(Controller::Fanuc);
/// let heidenhain = ExportOptions::new(Controller::Heidenhain);
/// assert_ne!(format!("{fanuc:?}"), format!("{heidenhain:?}"));
/// ```
#[doc(inline)]
pub use tricept_export::ExportOptions;
/// The summary an export writes beside the control's files: the control,
/// its limits, the files, the leg axes and what the files cannot carry.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::export::{Controller, ExportOptions, ExportRequest, export};
/// let options = ExportOptions::new(Controller::Sinumerik);
/// let exported = export(ExportRequest::new(MachineInput::from("calibrated.json"), options, "export"))?;
/// use tricept_ident::export::ControlModel;
/// let summary = exported.summary();
/// assert_eq!(summary.control, ControlModel::Sinumerik840dSl); // the family's model
/// assert_eq!(summary.axes.len(), 3);
/// assert_eq!(summary.within_tolerance, summary.limits.is_empty()); // nothing to raise
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_export::ExportSummary;
/// A part of the calibration the control's files cannot carry: what it is,
/// its size over the workspace (um) and why.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::export::{Controller, ExportOptions, ExportRequest, export};
/// let options = ExportOptions::new(Controller::Sinumerik);
/// let exported = export(ExportRequest::new(MachineInput::from("calibrated.json"), options, "export"))?;
/// for part in &exported.summary().not_exported {
///     assert!(part.size_um >= 0.0 && !part.why.is_empty(), "{}", part.what);
/// }
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_export::NotExported;
/// A control model's limits (`control_limits` of the export's summary): the
/// points per axis, and Fanuc's shared point numbers, value range and
/// magnification.
///
/// # Example
/// ```
/// use tricept_ident::export::{ControlLimits, ControlModel};
/// let sinumerik: ControlLimits = ControlModel::Sinumerik840dSl.limits();
/// assert_eq!(sinumerik.points_per_axis.value, 801);
/// assert!(sinumerik.point_numbers.is_none());
/// let fanuc = ControlModel::Fanuc0i.limits();
/// let shared = fanuc.point_numbers.map(|n| n.value as usize);
/// assert_eq!(shared.map(|n| n / 3), Some(ControlModel::Fanuc0i.default_max_points()));
/// ```
#[doc(inline)]
pub use tricept_export::control::ControlLimits;
/// A CNC control model (`--control`): its family, its limits, its name.
///
/// # Example
/// ```
/// use tricept_ident::export::{ControlModel, Controller};
/// let model: ControlModel = "fanuc-30i".parse()?;
/// assert_eq!(model.family(), Controller::Fanuc);
/// assert_eq!(model.to_string(), "fanuc-30i");
/// assert_eq!(ControlModel::of_family(Controller::Sinumerik), ControlModel::Sinumerik840dSl);
/// assert!(ControlModel::ALL.iter().all(|m| m.as_str().parse::<ControlModel>() == Ok(*m)));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[doc(inline)]
pub use tricept_export::control::ControlModel;
/// The CNC control an export writes for.
///
/// # Example
/// ```
/// use tricept_ident::export::{Controller, ExportOptions};
/// let options = ExportOptions::new(Controller::Sinumerik);
/// # let _ = options;
/// ```
#[doc(inline)]
pub use tricept_export::control::Controller;
/// One limit of a control model: its value, whether a source states it is the
/// most the control takes (`hard`), and its source.
///
/// # Example
/// ```
/// use tricept_ident::export::{ControlModel, Limit};
/// let tnc640: Limit = ControlModel::HeidenhainTnc640.limits().points_per_axis;
/// let tnc407: Limit = ControlModel::HeidenhainTnc407.limits().points_per_axis;
/// assert_eq!(tnc640.value, tnc407.value); // the TNC 407's documented value stands in
/// assert!(!tnc640.hard && tnc640.source.contains("not in the sources found"));
/// ```
#[doc(inline)]
pub use tricept_export::control::Limit;

/// What to export, and where.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::export::{Controller, ExportOptions, ExportRequest, export};
/// let request = ExportRequest::new(
///     MachineInput::from("calibrated.json"),
///     ExportOptions::new(Controller::Heidenhain),
///     "export",
/// );
/// let exported = export(request)?;
/// assert!(exported.written() || exported.exit_code() != tricept_ident::EXIT_OK);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct ExportRequest {
    /// The calibrated machine file (read as written: an input without a
    /// file is refused).
    pub machine: MachineInput,
    /// The control and its limits.
    pub options: ExportOptions,
    /// The folder the files go into: missing, empty, or holding a
    /// previous export, which the new one replaces whole.
    pub out: PathBuf,
}

impl ExportRequest {
    /// The export of the calibrated machine file `machine` for the control
    /// and limits of `options` into the folder `out`.
    pub fn new(
        machine: impl Into<MachineInput>,
        options: ExportOptions,
        out: impl Into<PathBuf>,
    ) -> ExportRequest {
        ExportRequest {
            machine: machine.into(),
            options,
            out: out.into(),
        }
    }
}

/// The outcome of an export.
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::export::{Controller, ExportOptions, ExportRequest, export};
/// let request = ExportRequest::new(
///     MachineInput::from("calibrated.json"),
///     ExportOptions::new(Controller::Heidenhain),
///     "export",
/// );
/// let exported = export(request)?;
/// assert!(exported.written() || exported.exit_code() != tricept_ident::EXIT_OK);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Export {
    summary: ExportSummary,
    written: bool,
    out: PathBuf,
}

crate::outcome::outcome!(Export);

/// Why an export writes nothing.
const NOT_WRITTEN: &str =
    "a format error is past the tolerance or a control's range: nothing written (see the report)";

impl Export {
    /// The summary (the JSON of `--json` without `out` and `written`).
    pub fn summary(&self) -> &ExportSummary {
        &self.summary
    }

    /// Whether the files were written (not when a format error is past
    /// the tolerance).
    pub fn written(&self) -> bool {
        self.written
    }

    /// The folder the files go into.
    pub fn out(&self) -> &std::path::Path {
        &self.out
    }

    /// 0 written; 3 a format error past the tolerance (nothing written).
    pub fn exit_code(&self) -> u8 {
        if self.written {
            EXIT_OK
        } else {
            EXIT_INADEQUATE
        }
    }

    /// Why the exit code is not 0 (`None` when it is 0): nothing was
    /// written.
    pub fn reason(&self) -> Option<&str> {
        (!self.written).then_some(NOT_WRITTEN)
    }

    /// The summary as JSON (what `tricept export --json` prints,
    /// `format_version` first), with `written` and the output folder.
    pub fn to_json(&self) -> serde_json::Value {
        let mut v = serde_json::to_value(&self.summary).unwrap_or_default();
        if let serde_json::Value::Object(o) = &mut v {
            o.insert("out".into(), self.out.display().to_string().into());
            o.insert("written".into(), self.written.into());
        }
        crate::outcome::versioned(v)
    }

    /// The text report (what `tricept export` prints).
    pub fn report(&self) -> String {
        let out = &self.out;
        let s = &self.summary;
        let mut t = format!(
            "{} export {} {}\n",
            s.control,
            if self.written {
                "written to"
            } else {
                "NOT written to"
            },
            out.display()
        );
        for a in &s.axes {
            t.push_str(&format!(
                "leg {} -> axis {}: {} points every {:.4} mm from {:.3} to {:.3} mm, format error {:.3} um; reference {:.3} mm, offset {:+.6} mm, zero {:.6} mm\n",
                a.leg, a.axis, a.points, a.step_mm, a.min_mm, a.max_mm, a.format_error_um, a.reference_mm, a.offset_mm, a.zero_mm
            ));
        }
        t.push_str(&format!(
            "platform: the format errors move the platform point by up to {:.3} um over the workspace\n",
            s.platform_error_um
        ));
        for p in &s.parameters {
            t.push_str(&format!("set: {p}\n"));
        }
        for n in &s.not_exported {
            t.push_str(&format!(
                "not exported: {} ({:.3} um): {}\n",
                n.what, n.size_um, n.why
            ));
        }
        for l in &s.limits {
            t.push_str(&format!("limit: {l}\n"));
        }
        for w in &s.warnings {
            t.push_str(&format!("warning: {w}\n"));
        }
        if self.written {
            t.push_str(&format!("files: {}\n", s.files.join(", ")));
        }
        t
    }
}

/// Checks the output folder (a folder or nothing, holding at most a
/// previous export and not the machine file), loads the calibrated machine
/// file (refusing one edited after its calibration), plans the export and,
/// when every axis is within the tolerance and the control's ranges,
/// writes the files as one set (the previous export or this one, whole).
///
/// # Example
/// ```no_run
/// use tricept_ident::MachineInput;
/// use tricept_ident::export::{Controller, ExportOptions, ExportRequest, export};
/// let request = ExportRequest::new(
///     MachineInput::from("calibrated.json"),
///     ExportOptions::new(Controller::Heidenhain),
///     "export",
/// );
/// let exported = export(request)?;
/// assert!(exported.written() || exported.exit_code() != tricept_ident::EXIT_OK);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn export(request: ExportRequest) -> Result<Export, Error> {
    let ExportRequest {
        machine,
        options,
        out,
    } = request;
    let Some(path) = machine.path().map(std::path::Path::to_path_buf) else {
        return Err(Error::input(
            "export: a calibrated machine file is needed (a machine file written by a calibration: identify's or diagnose's `write_machine`)",
        ));
    };
    let source = path.display().to_string();
    tricept_export::check_out(&out, &path)?;
    let loaded = machine.load()?;
    let mut plan = tricept_export::plan(loaded.description(), &options).map_err(|e| match e {
        ExportError::NoCalibration => Error::from(e).in_file(&source),
        e => Error::from(e),
    })?;
    for w in loaded.warnings() {
        plan.warn(format!("{source}: {w}"));
    }
    let written = plan.summary.within_tolerance;
    if written {
        plan.write(&out)?;
    }
    Ok(Export {
        summary: plan.summary,
        written,
        out,
    })
}
