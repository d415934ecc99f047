//! `tricept`: the command-line front end. A thin layer over the library
//! crates: it parses arguments, loads files, calls one library function per
//! verb and prints the result as text or JSON.
//!
//! Exit codes: 0 success, 2 usage or input errors (bad arguments, bad files,
//! unreachable commands), 1 anything else. Errors go to stderr as one line;
//! results go to stdout.

/// `println!` that stops printing quietly when stdout is closed (a pipe
/// into `head`, say) instead of panicking; see `output.rs`.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::output::write_line(format_args!($($arg)*))
    };
}

/// `eprintln!` that never panics.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::output::write_err_line(format_args!($($arg)*))
    };
}

mod args;
mod cli_error;
mod compensate_cmd;
mod diagnose_cmd;
mod fusion_cmd;
mod ident_cmd;
mod kinematics_cmd;
mod machine_file;
mod output;
mod plan_cmd;
mod simulate_cmd;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::cli_error::CliError;

/// Calibrate the Tricept parallel kinematic machine from its own sensors.
///
/// All lengths are in mm and all angles in rad unless a flag says otherwise.
#[derive(Debug, Parser)]
#[command(
    name = "tricept",
    version,
    about,
    long_about = None,
    after_help = "Examples:\n  tricept ik 0 0 750\n  tricept simulate --out data.csv\n  tricept identify --data data.csv --write-machine calibrated.json\n  tricept ik 0 0 750 --machine calibrated.json\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n\nExit codes: 0 success; 2 usage or input error; 3 (identify, compensate) the fit converged but the model does not explain the data (run `tricept diagnose`); 4 (identify, compensate) the fit did not converge; 1 anything else.\nData format: docs/data-format.md"
)]
#[command(subcommand_required = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Inverse kinematics: platform point O' (mm) to leg commands and UP joints.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept ik 0 0 750\n  tricept ik -120.5 80 700 --json\n  tricept ik 100 0 800 --machine calibrated.json\n  tricept ik --input points.csv > commands.csv"
    )]
    Ik(kinematics_cmd::IkArgs),
    /// Forward kinematics: leg commands (mm) to UP joints and O'.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept fk 796.5 796.5 796.5\n  tricept fk 760 820 801 --json\n  tricept fk --input commands.csv"
    )]
    Fk(kinematics_cmd::FkArgs),
    /// 5-DOF tool-pose inverse kinematics: tool tip (mm) and tool axis to
    /// leg commands and head angles.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept tool-ik 150 100 1080 0.2 -0.1 1\n  tricept tool-ik 0 0 1100 0 0 1 --json\n  tricept tool-ik --input tool-poses.csv"
    )]
    ToolIk(kinematics_cmd::ToolIkArgs),
    /// The machine description in use: a summary with units, or (--json)
    /// the description file, e.g. to start a new one.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept machine --json > my-machine.json\n  tricept machine --machine calibrated.json"
    )]
    Machine(kinematics_cmd::MachineVerbArgs),
    /// What a pose set and the UP limb's sensors can identify: rank,
    /// singular values, observability indices, unidentifiable combinations.
    #[command(
        allow_negative_numbers = true,
        after_help = "Pose sets (--poses): grid (75 poses), grid:RINGS,PER_RING,LEVELS, random:N[,SEED], disc:SPACING[,Z], or a CSV file with columns x,y,z (mm).\n\nExamples:\n  tricept identifiability\n  tricept identifiability --poses random:30,1 --json\n  tricept identifiability --params full21"
    )]
    Identifiability(ident_cmd::IdentifiabilityArgs),
    /// Identify the geometric errors from measured data (CSV: q1,q2,q3,phi,theta,s),
    /// alone or fused with external measurements (laser tracker, ballbar,
    /// touch-offs) that also calibrate the head.
    #[command(
        allow_negative_numbers = true,
        after_help = "Exit codes: 0 converged and adequate (the model explains the data to the sensor noise); 3 converged but the model does not explain the data (the report names `tricept diagnose`); 4 did not converge; 2 bad input. --write-machine refuses a fit that did not converge or data that cannot come from the machine (--force writes it, marked as forced).\n\nWith --tracker, --ballbar, --touch, --head or --effects the fused identification runs (docs/hybrid.md): module, head (13 parameters) and each instrument's nuisance in one fit, every source's records screened for gross errors (rejected by file and line); a tracker states where its target sits (--tracker-target tip|X,Y,Z|free, no default). Exit code 3 when it converges but is not to be trusted: a source whose rows cannot check the fit (too few redundant rows; the report says how many more points), a source the model does not explain (chi-square test at 0.001), or an estimate outside its plausible range (the likely cause, tested by refitting, is named); 4 when it does not converge. --write-machine prints the report and the warnings, then refuses such a fit unless --force.\n\nExamples:\n  tricept simulate --out data.csv && tricept identify --data data.csv\n  tricept identify --data data.csv --json\n  tricept identify --data data.csv --write-machine calibrated.json\n  tricept identify --data data.csv --tracker points.csv --tracker-target tip --write-machine calibrated.json"
    )]
    Identify(ident_cmd::IdentifyArgs),
    /// Write a measured-data CSV from a simulated machine (Table 2 errors by
    /// default) with sensor noise, offsets and optional unmodelled effects.
    #[command(
        allow_negative_numbers = true,
        after_help = "True errors (--truth): table2, zero, random:MAG_MM[,SEED], or a JSON file {name: mm}.\nEffects (--truth-effect, repeatable): a JSON object or @FILE, e.g. '{\"effect\":\"leg-lead\",\"ppm\":[50,-30,40]}' (see docs/diagnosis.md for every effect and its units).\n\nExamples:\n  tricept simulate --out data.csv\n  tricept simulate --truth random:1.0,3 --poses random:100,2 --seed 9 --out data.csv\n  tricept simulate --truth-effect '{\"effect\":\"backlash\",\"um\":[6,5,8]}' --both-directions --out data.csv\n  tricept simulate --head-errors random:1,3 --out data.csv --tracker-out t.csv --tracker-poses points.csv\n  tricept simulate --out data.csv --touch-out touch.csv --features-out features.json --touch-poses touches.csv"
    )]
    Simulate(simulate_cmd::SimulateArgs),
    /// Does the geometric model explain the data? If not, which unmodelled
    /// effect does (leg-lead, backlash, thermal, scale-gain,
    /// encoder-eccentricity, ujoint-axes, tube-twist, compliance, outliers).
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n  tricept diagnose --data data.csv --json --plots out/\n  tricept diagnose --data fixtures/data/diagnose-noisy.csv --noise-from-data\n  tricept diagnose --data data.csv --write-machine extended.json && tricept ik 0 0 750 --machine extended.json\n\nExit codes: 0 the final model explains the data (verdict adequate or explained), 3 it does not (partially-explained, unexplained: the report says what remains), 2 data that cannot be diagnosed.\nMethod, vocabulary, generic dictionary, plausibility table: docs/diagnosis.md"
    )]
    Diagnose(diagnose_cmd::DiagnoseArgs),
    /// For a measurement campaign: how large must each unmodelled effect be
    /// before the diagnosis finds it, and what it does to the geometric
    /// parameters below that; with advice on the campaign.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept detectability\n  tricept detectability --poses random:200,1 --both-directions --readings-per-pose 30 --temperature-drift 2"
    )]
    Detectability(diagnose_cmd::DetectabilityArgs),
    /// Identify from data, then compensate: corrected commands and the
    /// volumetric error on a plane before and after.
    #[command(
        allow_negative_numbers = true,
        after_help = "Without --truth only the correction the identified model predicts is known; with the true errors of simulated data (--truth table2 ...) the before/after error of the actual machine is reported. Exit codes as for identify (0, 3, 4, 2).\n\nExamples:\n  tricept compensate --data data.csv --truth table2 --map out/\n  tricept compensate --data data.csv --targets points.csv > commands.csv\n  tricept compensate --machine calibrated.json --table out/"
    )]
    Compensate(compensate_cmd::CompensateArgs),
    /// Plan a few external measurements (tracker points, ballbar readings,
    /// touch-offs on a reference sphere): which to take so that the tool tip
    /// (and with --extensions the tool axis) is best known after touch-off,
    /// the predicted accuracy against their number, the redundancy each
    /// leaves to check the fit, and the recommended number.
    #[command(
        allow_negative_numbers = true,
        after_help = "Criterion: the RMS over the evaluation tool poses of the predicted tool-tip standard deviation after touch-off (a Bayesian A-optimal design with the parameters' typical sizes as prior; with two or more --extensions the tool axis too; docs/hybrid.md). Recommended: the smallest k asked for that reaches --target-um and leaves at least 6 redundant rows per tracker station (4 per ballbar setup or touched sphere).\n\nExamples:\n  tricept plan --instrument tracker --tracker-target tip --k 5,12,30 --target-um 25 --out points.csv\n  tricept plan --instrument tracker --tracker-target tip --extensions 0,100 --k 20 --out points.csv\n  tricept plan --instrument ballbar --ballbar-pivot-mm 0,0,1250 --target-um 15\n  tricept plan --instrument touch --k 30 --out touches.csv"
    )]
    Plan(plan_cmd::PlanArgs),
}

/// Runs the verb; `Ok` carries the exit code of a result (0, or the
/// verdict of a fit: 3 inadequate, 4 not converged).
fn run(cli: Cli) -> Result<u8, CliError> {
    match cli.command {
        Command::Ik(a) => kinematics_cmd::ik(&a),
        Command::Fk(a) => kinematics_cmd::fk(&a),
        Command::ToolIk(a) => kinematics_cmd::tool_ik(&a),
        Command::Machine(a) => kinematics_cmd::print_machine(&a),
        Command::Identifiability(a) => ident_cmd::run_identifiability(&a),
        Command::Identify(a) => ident_cmd::run_identify(&a),
        Command::Simulate(a) => simulate_cmd::run(&a),
        Command::Diagnose(a) => diagnose_cmd::run_diagnose(&a),
        Command::Detectability(a) => diagnose_cmd::run_detectability(&a),
        Command::Compensate(a) => compensate_cmd::run_compensate(&a),
        Command::Plan(a) => plan_cmd::run(&a),
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
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            errln!("error: {}", e.message);
            ExitCode::from(e.code)
        }
    }
}
