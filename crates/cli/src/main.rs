//! `tricept`: the command-line front end. A thin layer over the library
//! crates: it parses arguments, loads files, calls one library function per
//! verb and prints the result as text or JSON.
//!
//! Exit codes: 0 success, 2 usage or input errors (bad arguments, bad files,
//! unreachable commands), 1 anything else. Errors go to stderr as one line;
//! results go to stdout.

mod cli_error;
mod kinematics_cmd;
mod output;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

use crate::cli_error::CliError;

/// Calibrate the Tricept parallel kinematic machine from its own sensors.
///
/// All lengths are in mm and all angles in rad unless a flag says otherwise.
#[derive(Debug, Parser)]
#[command(name = "tricept", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Options shared by every verb that works on a machine.
#[derive(Debug, Args, Clone)]
pub struct MachineArgs {
    /// Machine description (JSON); default: the paper's Table 1 machine.
    #[arg(long, value_name = "FILE")]
    pub machine: Option<PathBuf>,
    /// Print machine-readable JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Inverse kinematics: platform point O' (mm) to leg commands and UP joints.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept ik 0 0 750\n  tricept ik -120.5 80 700 --json\n  tricept ik 100 0 800 --machine fixtures/machines/tricept-paper.json"
    )]
    Ik {
        /// x of O' in the base frame, mm.
        x: f64,
        /// y of O' in the base frame, mm.
        y: f64,
        /// z of O' in the base frame, mm.
        z: f64,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// Forward kinematics: leg commands (mm) to UP joints and O'.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept fk 796.5 796.5 796.5\n  tricept fk 760 820 801 --json"
    )]
    Fk {
        /// Command of leg 1, mm.
        q1: f64,
        /// Command of leg 2, mm.
        q2: f64,
        /// Command of leg 3, mm.
        q3: f64,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// 5-DOF tool-pose inverse kinematics: tool tip (mm) and tool axis to
    /// leg commands and head angles.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept tool-ik 150 100 1080 0.2 -0.1 1\n  tricept tool-ik 0 0 1100 0 0 1 --json"
    )]
    ToolIk {
        /// Tool tip x, mm.
        x: f64,
        /// Tool tip y, mm.
        y: f64,
        /// Tool tip z, mm.
        z: f64,
        /// Tool axis x component (any length).
        ax: f64,
        /// Tool axis y component.
        ay: f64,
        /// Tool axis z component.
        az: f64,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// Print the machine description in use (JSON), e.g. to start a new file.
    Machine {
        #[command(flatten)]
        machine: MachineArgs,
    },
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Ik { x, y, z, machine } => kinematics_cmd::ik(&machine, [x, y, z]),
        Command::Fk {
            q1,
            q2,
            q3,
            machine,
        } => kinematics_cmd::fk(&machine, [q1, q2, q3]),
        Command::ToolIk {
            x,
            y,
            z,
            ax,
            ay,
            az,
            machine,
        } => kinematics_cmd::tool_ik(&machine, [x, y, z], [ax, ay, az]),
        Command::Machine { machine } => kinematics_cmd::print_machine(&machine),
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // clap prints help/version to stdout (exit 0) and usage errors
            // to stderr (exit 2).
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.message);
            ExitCode::from(e.code)
        }
    }
}
