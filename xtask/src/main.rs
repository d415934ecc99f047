//! Project automation in the style of rust-analyzer's `cargo xtask`.
//!
//! `cargo xtask <verb>`; see `cargo xtask --help`. Each verb reproduces a
//! figure or table that the docs quote, so anyone can rerun it.

mod fig3;

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
    /// Fig. 3 "before compensation" with the default conventions and every
    /// combination of the conventions the paper leaves open.
    Fig3Before {
        /// List every combination, not only the closest five.
        #[arg(long)]
        all: bool,
    },
}

fn main() -> ExitCode {
    let args = Xtask::parse();
    let result = match args.command {
        Command::Fig3Before { all } => fig3::run(all),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
