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
mod check_cmd;
mod cli_error;
mod compensate_cmd;
mod diagnose_cmd;
mod docs_cmd;
mod effects_cmd;
mod export_cmd;
mod files;
mod flags;
mod fleet_cmd;
mod ident_cmd;
mod kinematics_cmd;
mod output;
mod plan_cmd;
mod report_cmd;
mod schema_cmd;
mod simulate_cmd;

use std::path::Path;
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
    after_help = "Examples:\n  tricept ik 0 0 750\n  tricept simulate --out data.csv\n  tricept identify --data data.csv --write-machine calibrated.json\n  tricept ik 0 0 750 --machine calibrated.json\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n\nExit codes: 0 success; 2 usage or input error; 3 (identify, compensate, diagnose) the fit converged but the model does not explain the data (run `tricept diagnose`), or the campaign is too small to calibrate; 4 (identify, compensate) the fit did not converge; 1 anything else, including a stdout that cannot be written (a full disk).\nDocumentation: `tricept docs` lists the pages (docs/*.md of the source, embedded); the data formats: `tricept docs data-format`."
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
        after_help = "Exit codes: 0 converged, adequate (the model explains the data to the sensor noise) and worthwhile; 3 converged but the model does not explain the data (the report names `tricept diagnose`), or the campaign is too small to calibrate (the report names the poses that would); 4 did not converge; 2 bad input. --write-machine writes only an exit-0 fit (--force writes any, marked as forced).\n\nWith --tracker, --ballbar, --touch, --head or --effects the fused identification runs (`tricept docs hybrid`): module, head (13 parameters) and each instrument's nuisance in one fit, every source's records screened for gross errors (rejected by file and line); a tracker states where its target sits (--tracker-target tip|X,Y,Z|free, no default). Exit code 3 when it converges but is not to be trusted: a source whose rows cannot check the fit (too few redundant rows; the report says how many more points), a source the model does not explain (chi-square test at 0.001), or an estimate outside its plausible range (the likely cause, tested by refitting, is named); 4 when it does not converge. --write-machine prints the report and the warnings, then refuses such a fit unless --force.\n\nExamples:\n  tricept simulate --out data.csv && tricept identify --data data.csv\n  tricept identify --data data.csv --json\n  tricept identify --data data.csv --write-machine calibrated.json\n  tricept identify --data data.csv --tracker points.csv --tracker-target tip --write-machine calibrated.json"
    )]
    Identify(args::IdentifyArgs),
    /// Write a measured-data CSV from a simulated machine (Table 2 errors by
    /// default) with sensor noise, offsets and optional unmodelled effects.
    #[command(
        allow_negative_numbers = true,
        after_help = "True errors (--truth): table2, zero, random:MAG_MM[,SEED], or a JSON file {name: mm}.\nEffects (--truth-effect, repeatable): a JSON object or @FILE, e.g. '{\"effect\":\"leg-lead\",\"ppm\":[50,-30,40]}' (`tricept effects` lists every effect with its keys, units and a typical example).\n\nExamples:\n  tricept simulate --out data.csv\n  tricept simulate --truth random:1.0,3 --poses random:100,2 --seed 9 --out data.csv\n  tricept simulate --truth-effect '{\"effect\":\"backlash\",\"um\":[6,5,8]}' --both-directions --out data.csv\n  tricept simulate --head-errors random:1,3 --out data.csv --tracker-out t.csv --tracker-poses points.csv\n  tricept simulate --out data.csv --touch-out touch.csv --features-out features.json --touch-poses touches.csv"
    )]
    Simulate(simulate_cmd::SimulateArgs),
    /// Does the geometric model explain the data? If not, which unmodelled
    /// effect of the vocabulary (listed below) or generic term does.
    #[command(
        allow_negative_numbers = true,
        after_help = format!("{}\n\n{}", diagnose_cmd::vocabulary_help(), "Examples:\n  tricept diagnose --data fixtures/data/diagnose-hidden-effect.csv\n  tricept diagnose --data data.csv --json --plots out/\n  tricept diagnose --data fixtures/data/diagnose-noisy.csv --noise-from-data\n  tricept diagnose --data data.csv --write-machine extended.json && tricept ik 0 0 750 --machine extended.json\n\nExit codes: 0 the final model explains the data (verdict adequate or explained), 3 it does not (partially-explained, unexplained: the report says what remains), 2 data that cannot be diagnosed.\nMethod, vocabulary, generic dictionary, plausibility table: `tricept docs diagnosis`")
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
    /// Has the machine changed since its calibration? A short check campaign
    /// from its own sensors tested against the calibrated machine file.
    #[command(
        allow_negative_numbers = true,
        after_help = "The sensor offsets are re-estimated (a power cycle re-references them); the test allows for the calibration's own uncertainty and the sensors' noise (`tricept docs check`).\n\nExit codes: 0 unchanged; 0 too, with a warning on stderr, when the readings are noisier than stated and no change stands out beyond that noise (verdict noisier-than-stated: state the noise with --angle-noise-arcsec/--length-noise-um or service the sensors) and when a gross reading was set aside (named by its line; the verdict comes from the other poses); 3 changed (the report names the most likely change, its size and what it does to the platform, or the candidates it cannot tell apart); 2 bad input, including a machine file without a calibration record and a campaign that cannot see a change.\n\nExamples:\n  tricept check --machine calibrated.json --data today.csv\n  tricept check --machine calibrated.json --data today.csv --history checks.jsonl --plot trends/\n  tricept check --machine calibrated.json --data today.csv --json"
    )]
    Check(check_cmd::CheckArgs),
    /// Plan a few external measurements (tracker points, ballbar readings,
    /// touch-offs on a reference sphere): which to take so that the tool tip
    /// (and with --extensions the tool axis) is best known after touch-off,
    /// the predicted accuracy against their number, the redundancy each
    /// leaves to check the fit, and the recommended number.
    #[command(
        allow_negative_numbers = true,
        after_help = "Criterion: the RMS over the evaluation tool poses of the predicted tool-tip standard deviation after touch-off (a Bayesian A-optimal design with the parameters' typical sizes as prior; with two or more --extensions the tool axis too; `tricept docs hybrid`). Recommended: the smallest k asked for that reaches --target-um and leaves at least 6 redundant rows per tracker station (4 per ballbar setup or touched sphere).\n\nExamples:\n  tricept plan --instrument tracker --tracker-target tip --k 5,12,30 --target-um 25 --out points.csv\n  tricept plan --instrument tracker --tracker-target tip --extensions 0,100 --k 20 --out points.csv\n  tricept plan --instrument ballbar --ballbar-pivot-mm 0,0,1250 --target-um 15\n  tricept plan --instrument touch --k 30 --out touches.csv"
    )]
    Plan(plan_cmd::PlanArgs),
    /// The documentation pages (data formats, conventions, diagnosis, ...),
    /// embedded: print one, or list them.
    #[command(
        after_help = "Examples:\n  tricept docs\n  tricept docs data-format | less\n  tricept docs docs/diagnosis.md"
    )]
    Docs(docs_cmd::DocsArgs),
    /// The effects the simulator can hide in a machine (`simulate
    /// --truth-effect`): each one's keys, units and a typical example, and
    /// whether the diagnosis names it or describes it generically.
    #[command(
        after_help = "The keys are the simulator's inputs, in the units a machine builder quotes; the diagnosis fits its own parameters (`tricept docs diagnosis`).\n\nExamples:\n  tricept effects\n  tricept effects compliance\n  tricept effects --json | head -1"
    )]
    Effects(effects_cmd::EffectsArgs),
    /// A batch of machines calibrated together: the batch's systematic
    /// error and its spread, each machine with the batch as its prior, the
    /// machines that do not belong, and the prior a new machine calibrates
    /// from (`identify --prior`).
    #[command(
        allow_negative_numbers = true,
        after_help = "A hierarchical model: each machine's errors are the batch mean plus its own deviation (spread estimated by REML); every reading of every machine in one fit on a sparse solver. A machine whose own data do not fit, or whose estimate lies beyond the spread (a chi-square test against the others, docs/fleet.md), is named and kept out.\n\nExit codes: 0 every machine fits and belongs; 3 a machine is kept out (named), or the batch is not one population; 4 the joint fit did not converge; 2 bad input (fewer than three machines whose data fit).\n\nExamples:\n  tricept fleet --data m1.csv --data m2.csv --data m3.csv --data m4.csv\n  tricept fleet --data m*.csv --json --write-prior batch.json && tricept identify --data new.csv --prior batch.json --write-machine new.json"
    )]
    Fleet(fleet_cmd::FleetArgs),
    /// Compensation files a CNC control loads (Sinumerik, Fanuc,
    /// Heidenhain) from a calibrated machine file, with the format error.
    #[command(
        allow_negative_numbers = true,
        after_help = "Exit codes: 0 written; 3 a format error past --tolerance-um, or a range of the control the files would exceed (nothing written; the report names the limit); 2 bad input, checked before any work (an unknown control, an option past the model's documented limit, an axis name the control cannot accept, a machine file without a calibration or edited after it, an --out that is a file, holds files that are not an export, or holds the machine file).\n\nThe files are written as one set: a folder holding a previous export is replaced whole, never mixed.\n\nExamples:\n  tricept export --machine calibrated.json --out cnc/                 (a Tricept's SINUMERIK 840D sl)\n  tricept export --machine calibrated.json --control heidenhain-itnc530 --out cnc/\n  tricept export --machine calibrated.json --control fanuc-0i --axis-names U,V,W --detection-unit-um 0.1 --out cnc/ --json\nFormats, signs, units and each model's limits with their sources: `tricept docs controllers`"
    )]
    Export(export_cmd::ExportArgs),
    /// One self-contained HTML page per calibrated machine: the verdict,
    /// the promise, what was found, the daily checks and the controller
    /// files, at a glance in a browser (prints to A4).
    #[command(
        after_help = "Exit codes: 0 written (verdict trusted, or use with caution); 3 written, and the page says not to trust the machine (a forced or inadequate calibration, or a last check that found it changed); 2 bad input: a machine file without a calibration or edited after it, a campaign whose SHA-256 is not the record's, a history or an export of another calibration (each names the file).\n\nExamples:\n  tricept report --machine calibrated.json --out page.html\n  tricept report --machine calibrated.json --data campaign.csv --history checks.jsonl --export cnc/ --out page.html\nThe page, its verdict rule and how to read its sources: `tricept docs report`"
    )]
    Report(report_cmd::ReportArgs),
    /// The JSON Schema of a file tricept writes (a machine file, a prior,
    /// a check history line, an export summary) or of a verb's --json
    /// output; without a name, the list.
    #[command(
        after_help = "Every file tricept writes carries `format_version` (an integer; a file without it is version 1, one newer than this tricept is refused with exit code 2): `tricept docs data-format`, \"Format versions and schemas\".\n\nExamples:\n  tricept schema\n  tricept schema machine > machine.schema.json\n  tricept schema identify"
    )]
    Schema(schema_cmd::SchemaArgs),
}

/// The files a verb reads and writes, by flag (checked before it runs:
/// no output may be an input).
fn file_roles(command: &Command) -> files::FileRoles {
    let mut r = files::FileRoles::default();
    let machine = |r: &mut files::FileRoles, m: &args::MachineArgs| {
        if let Some(p) = &m.machine {
            r.input("--machine", p);
        }
    };
    // The true errors' file, and the effects' `@FILE`s.
    let truth_inputs = |r: &mut files::FileRoles, t: &args::TruthArgs| {
        if let Some(tricept_ident::advanced::TrueErrors::File(p)) = &t.truth {
            r.input("--truth", p);
        }
        for e in &t.truth_effects {
            r.input_if_file("--truth-effect", &e.to_string());
        }
    };
    match command {
        Command::Ik(a) => {
            machine(&mut r, &a.machine);
            stdin_or_input(&mut r, &a.input.input);
        }
        Command::Fk(a) => {
            machine(&mut r, &a.machine);
            stdin_or_input(&mut r, &a.input.input);
        }
        Command::ToolIk(a) => {
            machine(&mut r, &a.machine);
            stdin_or_input(&mut r, &a.input.input);
        }
        Command::Machine(a) => machine(&mut r, &a.machine),
        Command::Docs(_) | Command::Effects(_) | Command::Schema(_) => {}
        Command::Identifiability(a) => {
            machine(&mut r, &a.machine);
            r.inputs("--poses", a.poses.file().map(Path::to_path_buf).as_ref());
            r.inputs("--data", &a.data);
        }
        Command::Identify(a) => {
            machine(&mut r, &a.settings.machine);
            r.inputs("--data", &a.data);
            r.inputs("--prior", &a.prior);
            let x = &a.external;
            r.inputs("--tracker", &x.tracker);
            r.inputs("--ballbar", &x.ballbar);
            r.inputs("--touch", &x.touch);
            r.inputs("--features", &x.features);
            r.inputs("--plausibility", &x.plausibility);
            if let Some(p) = &a.write_machine {
                r.output("--write-machine", p);
            }
        }
        Command::Simulate(a) => {
            machine(&mut r, &a.machine);
            r.inputs("--poses", a.poses.file().map(Path::to_path_buf).as_ref());
            truth_inputs(&mut r, &a.truth);
            if let tricept_ident::simulate::HeadErrors::File(p) = &a.head_errors {
                r.input("--head-errors", p);
            }
            r.inputs("--tracker-poses", &a.tracker_poses);
            r.inputs("--ballbar-poses", &a.ballbar_poses);
            r.inputs("--touch-poses", &a.touch_poses);
            for (flag, p) in [
                ("--out", &simulate_cmd::out_file(a)),
                ("--tracker-out", &a.tracker_out),
                ("--ballbar-out", &a.ballbar_out),
                ("--touch-out", &a.touch_out),
                ("--features-out", &a.features_out),
            ] {
                if let Some(p) = p {
                    r.output(flag, p);
                }
            }
        }
        Command::Diagnose(a) => {
            machine(&mut r, &a.machine);
            r.input("--data", &a.data);
            r.inputs("--plausibility", &a.plausibility);
            if let Some(p) = &a.write_machine {
                r.output("--write-machine", p);
            }
            if let Some(d) = &a.plots {
                r.output_dir("--plots", d, "residual-", ".svg");
            }
        }
        Command::Detectability(a) => {
            machine(&mut r, &a.machine);
            r.inputs("--poses", a.poses.file().map(Path::to_path_buf).as_ref());
            r.inputs("--data", &a.data);
        }
        Command::Compensate(a) => {
            machine(&mut r, &a.settings.machine);
            r.inputs("--data", &a.data);
            r.inputs("--targets", &a.targets);
            truth_inputs(&mut r, &a.truth);
            if let Some(d) = &a.map {
                r.outputs_in("--map", d, compensate_cmd::MAP_FILES);
            }
            if let Some(d) = &a.table {
                r.outputs_in("--table", d, compensate_cmd::TABLE_FILES);
            }
        }
        Command::Check(a) => {
            machine(&mut r, &a.machine);
            r.input("--data", &a.data);
            if let Some(h) = &a.history {
                r.output("--history", h);
            }
            if let Some(d) = &a.plot {
                r.output_dir("--plot", d, "check-", ".svg");
            }
        }
        Command::Export(a) => {
            r.input("--machine", &a.machine);
        }
        Command::Report(a) => {
            r.input("--machine", &a.machine);
            r.inputs("--data", &a.data);
            r.inputs("--history", &a.history);
            if let Some(dir) = &a.export {
                r.input("--export", &dir.join(tricept_ident::report::EXPORT_SUMMARY));
            }
            r.output("--out", &a.out);
        }
        Command::Fleet(a) => {
            machine(&mut r, &a.machine);
            r.inputs("--data", &a.data);
            if let Some(p) = &a.write_prior {
                r.output("--write-prior", p);
            }
        }
        Command::Plan(a) => {
            machine(&mut r, &a.machine);
            r.inputs("--data", &a.data);
            r.inputs("--poses", a.poses.file().map(Path::to_path_buf).as_ref());
            r.inputs(
                "--candidates",
                a.candidates.file().map(Path::to_path_buf).as_ref(),
            );
            if let Some(p) = &a.out {
                r.output("--out", p);
            }
        }
    }
    r
}

/// The `--input` of a kinematics verb: a file, or stdin (`-`).
fn stdin_or_input(r: &mut files::FileRoles, input: &Option<std::path::PathBuf>) {
    if let Some(p) = input.as_ref().filter(|p| p.as_os_str() != files::STDIO) {
        r.input("--input", p);
    }
}

/// Runs the verb; `Ok` carries the exit code of a result (0, or the
/// verdict of a fit: 3 inadequate, 4 not converged).
fn run(cli: Cli) -> Result<u8, CliError> {
    file_roles(&cli.command).check()?;
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
        Command::Docs(a) => docs_cmd::run(&a),
        Command::Effects(a) => effects_cmd::run(&a),
        Command::Check(a) => check_cmd::run(&a),
        Command::Export(a) => export_cmd::run(&a),
        Command::Report(a) => report_cmd::run(&a),
        Command::Fleet(a) => fleet_cmd::run(&a),
        Command::Schema(a) => schema_cmd::run(&a),
    }
}

/// The one-line message of a flag value refused by one of the door's
/// parsers (`tricept_ident::advanced::Triple`, `TrackerTargetSpec`, ...): the flag,
/// then the door's message (unless it names the flag already). `None` for
/// every other clap error, which clap prints itself.
fn value_error(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    use std::error::Error as _;
    if e.kind() != ErrorKind::ValueValidation {
        return None;
    }
    let ours = e.source()?.downcast_ref::<CliError>()?;
    let flag = match e.get(ContextKind::InvalidArg) {
        Some(ContextValue::String(arg)) => arg.split_whitespace().next().unwrap_or_default(),
        _ => "",
    };
    let message = flags::message(ours);
    Some(if flag.is_empty() || message.starts_with(flag) {
        message
    } else if ours.setting().is_some() {
        ours.message_naming(|_| flag)
    } else {
        format!("{flag}: {message}")
    })
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // A flag value the door's parser refused: one line naming the
            // flag, exit 2, as every input error.
            if let Some(line) = value_error(&e) {
                errln!("error: {line}");
                return ExitCode::from(tricept_ident::EXIT_INPUT);
            }
            // Usage errors go to stderr (exit 2), what they repeat of the
            // command line inert (a control character escaped); help and
            // version are output like any other (a full disk is a
            // failure, exit 1).
            if e.use_stderr() {
                for line in e.render().to_string().trim_end().lines() {
                    errln!("{line}");
                }
                return ExitCode::from(2);
            }
            output::write_text(&e.render().to_string());
            return match output::finish() {
                Some(err) => {
                    errln!("error: stdout: {err}: the output is incomplete");
                    ExitCode::from(cli_error::EXIT_OTHER)
                }
                None => ExitCode::SUCCESS,
            };
        }
    };
    // A write the library refused (an untrusted result): the flag that
    // named the file, and the one that writes it anyway.
    let write_flag = match &cli.command {
        Command::Identify(_) | Command::Diagnose(_) => "--write-machine ",
        Command::Fleet(_) => "--write-prior ",
        Command::Compensate(_) => "compensate --machine ",
        _ => "",
    };
    let code = match run(cli) {
        Ok(code) => code,
        Err(e) if e.cause() == tricept_ident::ErrorCause::RefusedWrite => {
            errln!(
                "error: {write_flag}{}; --force writes it anyway, marked as forced",
                flags::message(&e)
            );
            e.exit_code()
        }
        Err(e) => {
            errln!("error: {}", flags::message(&e));
            e.exit_code()
        }
    };
    // Output that did not reach stdout (a full disk, an I/O error; not a
    // closed pipe) makes the run a failure whatever it computed.
    match output::finish() {
        Some(e) => {
            errln!("error: stdout: {e}: the output is incomplete");
            ExitCode::from(cli_error::EXIT_OTHER)
        }
        None => ExitCode::from(code),
    }
}
