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

mod args;
mod cli_error;
mod diagnose_cmd;
mod fusion_cmd;
mod ident_cmd;
mod kinematics_cmd;
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
    after_help = "Examples:\n  tricept ik 0 0 750\n  tricept simulate --out data.csv\n  tricept identify --data data.csv\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n\nExit codes: 0 success, 2 usage or input error, 1 anything else.\nData format: docs/data-format.md"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Inverse kinematics: platform point O' (mm) to leg commands and UP joints.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept ik 0 0 750\n  tricept ik -120.5 80 700 --json\n  tricept ik 100 0 800 --machine fixtures/machines/tricept-paper.json"
    )]
    Ik(kinematics_cmd::IkArgs),
    /// Forward kinematics: leg commands (mm) to UP joints and O'.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept fk 796.5 796.5 796.5\n  tricept fk 760 820 801 --json"
    )]
    Fk(kinematics_cmd::FkArgs),
    /// 5-DOF tool-pose inverse kinematics: tool tip (mm) and tool axis to
    /// leg commands and head angles.
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  tricept tool-ik 150 100 1080 0.2 -0.1 1\n  tricept tool-ik 0 0 1100 0 0 1 --json"
    )]
    ToolIk(kinematics_cmd::ToolIkArgs),
    /// Print the machine description in use (JSON), e.g. to start a new file.
    #[command(
        after_help = "Examples:\n  tricept machine > my-machine.json\n  tricept machine --machine fixtures/machines/tricept-paper-y-first.json"
    )]
    Machine(kinematics_cmd::MachineVerbArgs),
    /// What a pose set and the UP limb's sensors can identify: rank,
    /// singular values, observability indices, unidentifiable combinations.
    #[command(
        after_help = "Pose sets (--poses): grid (75 poses), grid:RINGS,PER_RING,LEVELS, random:N[,SEED], disc:SPACING[,Z], or a CSV file with columns x,y,z (mm).\n\nExamples:\n  tricept identifiability\n  tricept identifiability --poses random:30,1 --json\n  tricept identifiability --params full21"
    )]
    Identifiability(ident_cmd::IdentifiabilityArgs),
    /// Identify the geometric errors from measured data (CSV: q1,q2,q3,phi,theta,s),
    /// alone or fused with external measurements (laser tracker, ballbar,
    /// touch-offs) that also calibrate the head.
    #[command(
        after_help = "With --tracker, --ballbar, --touch, --head or --effects the fused identification runs (docs/hybrid.md): module, head (13 parameters) and each instrument's nuisance in one fit; exit code 3 when it completes but a source is not explained (reduced chi-square > 3) or it did not converge.\n\nExamples:\n  tricept simulate --out data.csv && tricept identify --data data.csv\n  tricept identify --data data.csv --json\n  tricept identify --data data.csv --write-machine identified.json\n  tricept identify --data data.csv --tracker points.csv --tracker-target tip --write-machine calibrated.json"
    )]
    Identify(ident_cmd::IdentifyArgs),
    /// Write a measured-data CSV from a simulated machine (Table 2 errors by
    /// default) with sensor noise, offsets and optional unmodelled effects.
    #[command(
        after_help = "Errors (--errors): table2, zero, random:MAG_MM[,SEED], or a JSON file {name: mm}.\nEffects (--effect, repeatable): a JSON object or @FILE, e.g. '{\"effect\":\"leg-lead\",\"ppm\":[50,-30,40]}'.\n\nExamples:\n  tricept simulate --out data.csv\n  tricept simulate --errors random:1.0,3 --poses random:100,2 --seed 9\n  tricept simulate --effect '{\"effect\":\"backlash\",\"um\":[6,5,8]}' --both-directions"
    )]
    Simulate(simulate_cmd::SimulateArgs),
    /// Does the geometric model explain the data? If not, which unmodelled
    /// effect does (leg-lead, backlash, thermal, scale-gain,
    /// encoder-eccentricity, ujoint-axes, tube-twist, compliance, outliers).
    #[command(
        after_help = "Examples:\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n  tricept diagnose --data fixtures/data/diagnose-pitch.csv --json --plots out/\n  tricept diagnose --data fixtures/data/diagnose-noisy.csv --noise-from-data\n\nExit codes: 0 a report (whatever its verdict), 2 data that cannot be diagnosed.\nMethod, vocabulary, generic dictionary, plausibility table: docs/diagnosis.md"
    )]
    Diagnose(diagnose_cmd::DiagnoseArgs),
    /// For a measurement campaign: how large must each unmodelled effect be
    /// before the diagnosis finds it, and what it does to the geometric
    /// parameters below that; with advice on the campaign.
    #[command(
        after_help = "Examples:\n  tricept detectability\n  tricept detectability --poses random:200,1 --both-directions --readings-per-pose 30 --temperature-drift 2"
    )]
    Detectability(diagnose_cmd::DetectabilityArgs),
    /// Identify from data, then compensate: corrected commands and the
    /// volumetric error on a plane before and after.
    #[command(
        after_help = "Without --truth only the correction the identified model predicts is known; with the true errors of simulated data (--truth table2 ...) the before/after error of the actual machine is reported.\n\nExamples:\n  tricept compensate --data data.csv --truth table2\n  tricept compensate --data data.csv --targets points.csv"
    )]
    Compensate(ident_cmd::CompensateArgs),
    /// Plan a few external measurements (tracker points, ballbar readings):
    /// which to take so that the tool tip is best known after touch-off,
    /// and the predicted accuracy against their number.
    #[command(
        after_help = "Criterion: the RMS over the evaluation tool poses of the predicted tool-tip standard deviation after touch-off (a Bayesian A-optimal design with the parameters' typical sizes as prior; docs/hybrid.md).\n\nExamples:\n  tricept plan --instrument tracker --k 5,12,30 --out points.csv\n  tricept plan --instrument ballbar --ballbar-pivot-mm 0,0,1250 --target-um 15"
    )]
    Plan(plan_cmd::PlanArgs),
}

fn run(cli: Cli) -> Result<(), CliError> {
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
        Command::Compensate(a) => ident_cmd::run_compensate(&a),
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
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", e.message);
            ExitCode::from(e.code)
        }
    }
}
