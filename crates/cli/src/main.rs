//! `tricept`: the command-line front end. A thin layer over the library
//! crates: it parses arguments, loads files, calls one library function per
//! verb and prints the result as text or JSON.
//!
//! Exit codes: 0 success, 2 usage or input errors (bad arguments, bad files,
//! unreachable commands), 1 anything else. Errors go to stderr as one line;
//! results go to stdout.

/// `println!` that ends the process quietly when stdout is closed (a
/// pipe into `head`, say) instead of panicking.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if writeln!(std::io::stdout().lock(), $($arg)*).is_err() {
            std::process::exit(0);
        }
    }};
}

mod cli_error;
mod diagnose_cmd;
mod ident_cmd;
mod kinematics_cmd;
mod output;
mod simulate_cmd;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

use crate::cli_error::CliError;
use crate::ident_cmd::{FitArgs, NoiseArgs, ParamArgs};

/// Calibrate the Tricept parallel kinematic machine from its own sensors.
///
/// All lengths are in mm and all angles in rad unless a flag says otherwise.
#[derive(Debug, Parser)]
#[command(
    name = "tricept",
    version,
    about,
    long_about = None,
    after_help = "Examples:\n  tricept ik 0 0 750\n  tricept simulate --out data.csv\n  tricept identify --data data.csv\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n\nExit codes: 0 success, 2 usage or input error, 1 anything else.\nData format: docs/data-format.md"
)]
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
    #[command(
        after_help = "Examples:\n  tricept machine > my-machine.json\n  tricept machine --machine fixtures/machines/tricept-paper-y-first.json"
    )]
    Machine {
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// What a pose set and the UP limb's sensors can identify: rank,
    /// singular values, observability indices, unidentifiable combinations.
    #[command(
        after_help = "Pose sets (--poses): grid (75 poses), grid:RINGS,PER_RING,LEVELS, random:N[,SEED], disc:SPACING[,Z], or a CSV file with columns x,y,z (mm).\n\nExamples:\n  tricept identifiability\n  tricept identifiability --poses random:30,1 --json\n  tricept identifiability --params full21"
    )]
    Identifiability {
        /// Pose set (see below).
        #[arg(long, default_value = "grid")]
        poses: String,
        #[command(flatten)]
        params: ParamArgs,
        #[command(flatten)]
        noise: NoiseArgs,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// Identify the geometric errors from measured data (CSV: q1,q2,q3,phi,theta,s).
    #[command(
        after_help = "Examples:\n  tricept simulate --out data.csv && tricept identify --data data.csv\n  tricept identify --data data.csv --json\n  tricept identify --data data.csv --write-machine identified.json"
    )]
    Identify {
        /// Measured-data CSV (see docs/data-format.md).
        #[arg(long, value_name = "FILE.csv")]
        data: PathBuf,
        /// Also write the identified machine as a description file.
        #[arg(long, value_name = "FILE.json")]
        write_machine: Option<PathBuf>,
        #[command(flatten)]
        fit: FitArgs,
        #[command(flatten)]
        params: ParamArgs,
        #[command(flatten)]
        noise: NoiseArgs,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// Write a measured-data CSV from a simulated machine (Table 2 errors by
    /// default) with sensor noise, offsets and optional unmodelled effects.
    #[command(
        after_help = "Errors (--errors): table2, zero, random:MAG_MM[,SEED], or a JSON file {name: mm}.\nEffects (--effect, repeatable): a JSON object or @FILE, e.g. '{\"effect\":\"leg-lead\",\"ppm\":[50,-30,40]}'.\n\nExamples:\n  tricept simulate --out data.csv\n  tricept simulate --errors random:1.0,3 --poses random:100,2 --seed 9\n  tricept simulate --effect '{\"effect\":\"backlash\",\"um\":[6,5,8]}' --both-directions"
    )]
    Simulate {
        /// True errors of the simulated machine.
        #[arg(long, default_value = "table2")]
        errors: String,
        /// Pose set (as for `identifiability`).
        #[arg(long, default_value = "grid")]
        poses: String,
        /// Seed of the sensor noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Visit every pose twice, approaching from both directions.
        #[arg(long)]
        both_directions: bool,
        /// An unmodelled effect (JSON object or @FILE); repeatable.
        #[arg(long = "effect", value_name = "JSON")]
        effects: Vec<String>,
        /// Output file (default: stdout).
        #[arg(long, value_name = "FILE.csv")]
        out: Option<PathBuf>,
        #[command(flatten)]
        params: ParamArgs,
        #[command(flatten)]
        noise: NoiseArgs,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// Does the geometric model explain the data? If not, which unmodelled
    /// effect does (leg-lead, backlash, thermal, scale-gain,
    /// encoder-eccentricity, ujoint-axes, tube-twist, compliance, outliers).
    #[command(
        after_help = "Examples:\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n  tricept diagnose --data data.csv --json --plots out/"
    )]
    Diagnose {
        /// Measured-data CSV (context columns temp_c, time_s, dir1..3 are used when present).
        #[arg(long, value_name = "FILE.csv")]
        data: PathBuf,
        /// Write residual plots (SVG) of the named causes into this directory.
        #[arg(long, value_name = "DIR")]
        plots: Option<PathBuf>,
        #[command(flatten)]
        noise: NoiseArgs,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// For a measurement campaign: how large must each unmodelled effect be
    /// before the diagnosis finds it, and what it does to the geometric
    /// parameters below that; with advice on the campaign.
    #[command(
        after_help = "Examples:\n  tricept detectability\n  tricept detectability --poses random:200,1 --both-directions --readings-per-pose 30 --temperature-drift 2"
    )]
    Detectability {
        /// Pose set (as for `identifiability`).
        #[arg(long, default_value = "grid")]
        poses: String,
        /// Visit every pose twice, approaching from both directions.
        #[arg(long)]
        both_directions: bool,
        /// Temperature change over the campaign, K (0: no thermal signature).
        #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
        temperature_drift: f64,
        #[command(flatten)]
        noise: NoiseArgs,
        #[command(flatten)]
        machine: MachineArgs,
    },
    /// Identify from data, then compensate: corrected commands and the
    /// volumetric error on a plane before and after.
    #[command(
        after_help = "Without --truth only the correction the identified model predicts is known; with the true errors of simulated data (--truth table2 ...) the before/after error of the actual machine is reported.\n\nExamples:\n  tricept compensate --data data.csv --truth table2\n  tricept compensate --data data.csv --targets points.csv"
    )]
    Compensate {
        /// Measured-data CSV.
        #[arg(long, value_name = "FILE.csv")]
        data: PathBuf,
        /// True errors of the machine that produced the data (simulations).
        #[arg(long, value_name = "ERRORS")]
        truth: Option<String>,
        /// An unmodelled effect of the true machine (JSON or @FILE, as for
        /// `simulate`); repeatable; used with --truth.
        #[arg(long = "truth-effect", value_name = "JSON")]
        truth_effects: Vec<String>,
        /// Plane of the error map, mm (default: the workspace's middle plane).
        #[arg(long, value_name = "Z_MM", allow_negative_numbers = true)]
        plane_z: Option<f64>,
        /// Lattice spacing of the error map, mm.
        #[arg(long, default_value_t = 10.0, value_name = "MM")]
        spacing: f64,
        /// Target points (CSV x,y,z) to print corrected leg commands for.
        #[arg(long, value_name = "FILE.csv")]
        targets: Option<PathBuf>,
        #[command(flatten)]
        fit: FitArgs,
        #[command(flatten)]
        params: ParamArgs,
        #[command(flatten)]
        noise: NoiseArgs,
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
        Command::Identifiability {
            poses,
            params,
            noise,
            machine,
        } => ident_cmd::run_identifiability(&machine, &noise, &params, &poses),
        Command::Identify {
            data,
            write_machine,
            fit,
            params,
            noise,
            machine,
        } => ident_cmd::run_identify(
            &machine,
            &noise,
            &params,
            &fit,
            &data,
            write_machine.as_deref(),
        ),
        Command::Simulate {
            errors,
            poses,
            seed,
            both_directions,
            effects,
            out,
            params,
            noise,
            machine,
        } => simulate_cmd::run(simulate_cmd::SimulateArgs {
            machine: &machine,
            noise: &noise,
            params: &params,
            errors: &errors,
            poses: &poses,
            seed,
            both_directions,
            effects: &effects,
            out: out.as_deref(),
        }),
        Command::Diagnose {
            data,
            plots,
            noise,
            machine,
        } => diagnose_cmd::run_diagnose(&machine, &noise, &data, plots.as_deref()),
        Command::Detectability {
            poses,
            both_directions,
            temperature_drift,
            noise,
            machine,
        } => diagnose_cmd::run_detectability(
            &machine,
            &noise,
            &poses,
            both_directions,
            temperature_drift,
        ),
        Command::Compensate {
            data,
            truth,
            truth_effects,
            plane_z,
            spacing,
            targets,
            fit,
            params,
            noise,
            machine,
        } => ident_cmd::run_compensate(
            &machine,
            &noise,
            &params,
            &fit,
            &data,
            truth.as_deref(),
            &truth_effects,
            plane_z,
            spacing,
            targets.as_deref(),
        ),
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
