//! The kinematics verbs: `ik`, `fk`, `tool-ik` (one point from the command
//! line, or many from `--input FILE.csv|-`), and `machine`; the workflows
//! are the door's (`tricept_ident::kinematics::solve_point`,
//! `tricept_ident::kinematics::solve_batch`).
//!
//! A calibrated machine file's static leg effects (lead, compliance) are
//! applied (`tricept_ident::kinematics::ExtendedMachine`).

use std::path::PathBuf;

use clap::Args;
use tricept_ident::kinematics::{ExtendedMachine, Verb, machine_summary, solve_batch, solve_point};

use crate::args::{MachineArgs, load};
use crate::cli_error::CliError;
use crate::output::stdout_closed;

/// Where the points of a batch come from.
#[derive(Debug, Args, Clone)]
pub struct InputArgs {
    /// Read many points from a CSV file (`-`: stdin) with the verb's input
    /// columns (ik: x,y,z in mm; fk: q1,q2,q3 in mm; tool-ik: x,y,z in mm
    /// and ax,ay,az) and write CSV to stdout, the keys of --json as columns.
    #[arg(long, value_name = "FILE.csv")]
    pub input: Option<PathBuf>,
}

/// `tricept ik X Y Z`.
#[derive(Debug, Args)]
pub struct IkArgs {
    /// x of O' in the base frame, mm.
    #[arg(required_unless_present = "input")]
    pub x: Option<f64>,
    /// y of O' in the base frame, mm.
    #[arg(required_unless_present = "input")]
    pub y: Option<f64>,
    /// z of O' in the base frame, mm.
    #[arg(required_unless_present = "input")]
    pub z: Option<f64>,
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept fk Q1 Q2 Q3`.
#[derive(Debug, Args)]
pub struct FkArgs {
    /// Command of leg 1, mm.
    #[arg(required_unless_present = "input")]
    pub q1: Option<f64>,
    /// Command of leg 2, mm.
    #[arg(required_unless_present = "input")]
    pub q2: Option<f64>,
    /// Command of leg 3, mm.
    #[arg(required_unless_present = "input")]
    pub q3: Option<f64>,
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept tool-ik X Y Z AX AY AZ`.
#[derive(Debug, Args)]
pub struct ToolIkArgs {
    /// Tool tip x, mm.
    #[arg(required_unless_present = "input")]
    pub x: Option<f64>,
    /// Tool tip y, mm.
    #[arg(required_unless_present = "input")]
    pub y: Option<f64>,
    /// Tool tip z, mm.
    #[arg(required_unless_present = "input")]
    pub z: Option<f64>,
    /// Tool axis x component (unitless, any length).
    #[arg(required_unless_present = "input")]
    pub ax: Option<f64>,
    /// Tool axis y component (unitless).
    #[arg(required_unless_present = "input")]
    pub ay: Option<f64>,
    /// Tool axis z component (unitless).
    #[arg(required_unless_present = "input")]
    pub az: Option<f64>,
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept machine`.
#[derive(Debug, Args)]
pub struct MachineVerbArgs {
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// One point or a batch, for any of the three verbs.
fn kinematics(
    verb: Verb,
    point: &[Option<f64>],
    input: &InputArgs,
    machine: &MachineArgs,
) -> Result<u8, CliError> {
    let loaded = load(machine)?;
    if let Some(path) = &input.input {
        if point.iter().any(Option::is_some) {
            return Err(CliError::input(format!(
                "{}: give either a point on the command line or --input, not both",
                verb.name()
            )));
        }
        if machine.json {
            return Err(CliError::input(format!(
                "{} --input: the output is CSV (the --json keys as columns); leave out --json",
                verb.name()
            )));
        }
        return run_batch(verb, loaded.commanding().extended(), path);
    }
    let values: Vec<f64> = point.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
    let solution = solve_point(verb, &loaded, &values)?;
    if machine.json {
        crate::output::write_json(solution.to_json());
    } else {
        crate::output::write_text(&solution.report());
    }
    Ok(solution.exit_code())
}

/// Streams the points of `path` (`-`: stdin) to stdout as CSV.
fn run_batch(verb: Verb, m: &ExtendedMachine, path: &std::path::Path) -> Result<u8, CliError> {
    let out = std::io::BufWriter::with_capacity(1 << 16, crate::output::Stdout);
    let label = path.display().to_string();
    if path.as_os_str() == "-" {
        let stdin = std::io::stdin().lock();
        solve_batch(verb, m, stdin, "stdin", &label, out, stdout_closed)?;
    } else {
        let f = std::fs::File::open(path).map_err(|e| CliError::input(format!("{label}: {e}")))?;
        solve_batch(verb, m, f, &label, &label, out, stdout_closed)?;
    }
    Ok(0)
}

/// `tricept ik X Y Z`.
pub fn ik(a: &IkArgs) -> Result<u8, CliError> {
    kinematics(Verb::Ik, &[a.x, a.y, a.z], &a.input, &a.machine)
}

/// `tricept fk Q1 Q2 Q3`.
pub fn fk(a: &FkArgs) -> Result<u8, CliError> {
    kinematics(Verb::Fk, &[a.q1, a.q2, a.q3], &a.input, &a.machine)
}

/// `tricept tool-ik X Y Z AX AY AZ`.
pub fn tool_ik(a: &ToolIkArgs) -> Result<u8, CliError> {
    kinematics(
        Verb::ToolIk,
        &[a.x, a.y, a.z, a.ax, a.ay, a.az],
        &a.input,
        &a.machine,
    )
}

/// `tricept machine`: the description in use, as JSON (`--json`, the file
/// format) or as a summary with units.
pub fn print_machine(a: &MachineVerbArgs) -> Result<u8, CliError> {
    let loaded = load(&a.machine)?;
    if a.machine.json {
        outln!("{}", loaded.description().to_json());
    } else {
        crate::output::write_text(&machine_summary(&loaded));
        outln!("  (tricept machine --json prints the description file)");
    }
    Ok(0)
}
