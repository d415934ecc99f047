//! Project automation in the style of rust-analyzer's `cargo xtask`.
//!
//! `cargo xtask <verb>`; see `cargo xtask --help`. Each verb reproduces a
//! figure or table that the docs quote, so anyone can rerun it.

mod check_rates;
mod checks;
mod fig3;
mod hybrid;
mod mutants;
mod report_sample;
mod reproduction;
mod study;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Debug, Parser)]
#[command(name = "cargo xtask", about = "Tricept project automation")]
struct Xtask {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// The Monte Carlo encoder-grade study (the paper's Fig. 4): the
    /// project's main job.
    EncoderStudy(study::StudyArgs),
    /// The gain of fusing the self-calibration with a few external
    /// measurements, on simulated machines: the tables and figures of
    /// docs/hybrid.md.
    Hybrid(hybrid::HybridArgs),
    /// The numbers behind the corrections of docs/reproduction.md and
    /// docs/identifiability.md: the paper's solve split by noise source,
    /// Fig. 3b with the paper's solve, mu over many random pose sets, the
    /// cost of differencing, the invisible-joint rule.
    Reproduction(reproduction::ReproductionArgs),
    /// Fig. 3 "before compensation" with the default conventions and every
    /// combination of the conventions the paper leaves open.
    Fig3Before {
        /// List every combination, not only the closest five.
        #[arg(long)]
        all: bool,
    },
    /// Fig. 3 before and after compensation: identification with the
    /// paper's noise, statistics over noise seeds, SVG maps in docs/figures.
    Fig3 {
        /// Number of noise seeds.
        #[arg(long, default_value_t = 200)]
        seeds: u64,
        /// Lattice spacing of the middle-plane map, mm.
        #[arg(long, default_value_t = 10.0)]
        spacing: f64,
        /// Directory of the SVG maps.
        #[arg(long, default_value = "docs/figures")]
        out: std::path::PathBuf,
    },
    /// Check that `cargo xtask encoder-study`, `cargo test --workspace`,
    /// `cargo run -p tricept-cli` and `cargo run -p
    /// tricept-example-downstream` build every third-party crate with the
    /// same features (one build); run by .ci/run after the tests.
    OneBuild,
    /// Check that Cargo.toml's rust-version (and the README's) is at least
    /// that of every locked dependency (`cargo metadata --locked`).
    Msrv,
    /// Mutation testing of the decision files (the verdict, the check, the
    /// diagnosis' selection and admission, the deployment, the controller
    /// export, atomic writes, the statistics) with cargo-mutants at a pinned
    /// version, installed when missing; see docs/testing.md.
    Mutants(mutants::MutantsArgs),
    /// The false-alarm rate and the power of `tricept check` on machines
    /// from the independent generator (tricept-truth), per scenario and
    /// pose count: the table of docs/check.md, "Measured rates".
    CheckRates(check_rates::CheckRatesArgs),
    /// The sample page of `tricept report` for the Table 2 fixture,
    /// docs/report-sample.html, from fixtures/report/ (`--inputs`: make
    /// the calibration, its checks and its export first).
    ReportSample(report_sample::ReportSampleArgs),
}

fn main() -> ExitCode {
    let args = Xtask::parse();
    let result = match args.command {
        Command::EncoderStudy(args) => study::run(args),
        Command::Hybrid(args) => hybrid::run(args),
        Command::Reproduction(args) => reproduction::run(args),
        Command::Fig3Before { all } => fig3::run(all),
        Command::Fig3 {
            seeds,
            spacing,
            out,
        } => fig3::run_compensation(seeds, &out, spacing),
        Command::OneBuild => checks::one_build(),
        Command::Msrv => checks::msrv(),
        Command::Mutants(args) => mutants::run(args),
        Command::CheckRates(args) => check_rates::run(args),
        Command::ReportSample(args) => report_sample::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
