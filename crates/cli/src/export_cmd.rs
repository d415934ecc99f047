//! `tricept export`: a calibrated machine file to the files a CNC control
//! loads (`tricept_ident::export`): flags to an `ExportRequest`, one door
//! call, the report printed.

use std::path::PathBuf;

use clap::Args;
use tricept_ident::export::{ControlModel, Controller, ExportOptions, ExportRequest};

use crate::cli_error::CliError;

/// `tricept export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The calibrated machine file (`diagnose --write-machine`,
    /// `identify --write-machine`).
    #[arg(long, value_name = "CAL.json")]
    pub machine: PathBuf,
    /// The control's family: sinumerik, fanuc or heidenhain (its model
    /// without --control: sinumerik-840d-sl, fanuc-0i, heidenhain-tnc640).
    #[arg(long, value_parser = parse_controller, value_name = "FAMILY")]
    pub controller: Option<Controller>,
    /// The control model, whose limits the files keep:
    /// sinumerik-840d-sl (default: a Tricept's control), sinumerik-828d,
    /// sinumerik-808d, fanuc-0i, fanuc-30i, heidenhain-tnc640,
    /// heidenhain-itnc530, heidenhain-tnc407.
    #[arg(long, value_parser = parse_control, value_name = "MODEL")]
    pub control: Option<ControlModel>,
    /// The folder the files go into: missing (created), empty, or holding
    /// a previous export, which is replaced whole.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// The three leg axes' names on the control (default: X1,Y1,Z1 for
    /// sinumerik, U,V,W for fanuc and heidenhain).
    #[arg(long, value_parser = parse_three_names, value_name = "A,B,C")]
    pub axis_names: Option<[String; 3]>,
    /// The most compensation points per axis (default: the model's limit,
    /// `control_limits` in the JSON; fanuc: a third of its point numbers).
    #[arg(long, value_name = "N")]
    pub max_points: Option<usize>,
    /// Fanuc: the detection unit, um (default 1).
    #[arg(long, value_name = "UM")]
    pub detection_unit_um: Option<f64>,
    /// Fanuc: the largest value of one pitch compensation point, in
    /// detection units times the magnification (default: the model's
    /// range, 7).
    #[arg(long, value_name = "N")]
    pub max_increment: Option<u32>,
    /// The largest format error accepted, um: past it nothing is written
    /// and the exit code is 3.
    #[arg(long, default_value_t = 1.0, value_name = "UM")]
    pub tolerance_um: f64,
    /// Each leg axis' reference point, mm (default: the legs' commands at
    /// the centre of the workspace).
    #[arg(long, value_parser = parse_three_mm, value_name = "Q1,Q2,Q3", allow_hyphen_values = true)]
    pub reference_mm: Option<[f64; 3]>,
    /// Print machine-readable JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

fn parse_controller(s: &str) -> Result<Controller, String> {
    s.parse()
}

fn parse_control(s: &str) -> Result<ControlModel, String> {
    s.parse()
}

/// The model `--control` and `--controller` name together.
fn model(a: &ExportArgs) -> Result<ControlModel, CliError> {
    match (a.control, a.controller) {
        (Some(m), Some(c)) if m.family() != c => Err(CliError::input(format!(
            "--control {m} is a {} control, not {c} (--controller)",
            m.family()
        ))),
        (Some(m), _) => Ok(m),
        (None, Some(c)) => Ok(ControlModel::of_family(c)),
        (None, None) => Ok(ControlModel::default()),
    }
}

fn three<T>(s: &str, parse: impl Fn(&str) -> Result<T, String>) -> Result<[T; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [a, b, c] = parts.as_slice() else {
        return Err(format!("expected three comma-separated values, got `{s}`"));
    };
    Ok([parse(a)?, parse(b)?, parse(c)?])
}

fn parse_three_names(s: &str) -> Result<[String; 3], String> {
    three(s, |p| Ok(p.to_string()))
}

fn parse_three_mm(s: &str) -> Result<[f64; 3], String> {
    three(s, |p| {
        p.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{p}` is not a number of mm"))
    })
}

/// `tricept export`.
pub fn run(a: &ExportArgs) -> Result<u8, CliError> {
    let request = ExportRequest::new(
        a.machine.as_path(),
        ExportOptions {
            axis_names: a.axis_names.clone(),
            max_points: a.max_points,
            detection_unit_um: a.detection_unit_um,
            max_increment: a.max_increment,
            tolerance_um: a.tolerance_um,
            reference_mm: a.reference_mm,
            ..ExportOptions::for_model(model(a)?)
        },
        a.out.clone(),
    );
    let e = tricept_ident::export::export(request)?;
    if a.json {
        crate::output::write_json(e.to_json());
    } else {
        crate::output::write_text(&e.report());
    }
    Ok(e.exit_code())
}
