//! The verb `fleet`: the machines of a batch calibrated together (flags
//! in, one call of the door, `tricept_ident::fleet`, the result out).

use std::path::PathBuf;

use clap::Args;
use tricept_ident::DataInput;
use tricept_ident::fleet::{FleetRequest, SolverKind, fleet};

use crate::args::{MachineArgs, NoiseArgs, ParamArgs};
use crate::cli_error::CliError;

/// `tricept fleet`.
#[derive(Debug, Args)]
pub struct FleetArgs {
    /// One measured-data CSV per machine of the batch (at least three
    /// whose data fit); repeatable.
    #[arg(long, value_name = "FILE.csv", required = true, num_args = 1..)]
    pub data: Vec<PathBuf>,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    /// The batch's nominal machine (--machine), and --json.
    #[command(flatten)]
    pub machine: MachineArgs,
    /// Manufacturing tolerance of each parameter, mm: each machine's
    /// campaign is judged worth deploying as `identify` judges it.
    #[arg(long, default_value_t = tricept_ident::advanced::DEFAULT_TOLERANCE_MM, value_name = "MM")]
    pub tolerance_mm: f64,
    /// The factorisation of the joint fit: schur (block elimination, the
    /// fast path), sparse-cholesky, sparse-qr or dense (small batches).
    #[arg(long, default_value = "schur", value_name = "KIND", value_parser = solver_kind)]
    pub solver: SolverKind,
    /// Write the batch's prior for a new machine of it (`identify
    /// --prior`), sealed, with its provenance.
    #[arg(long, value_name = "PRIOR.json")]
    pub write_prior: Option<PathBuf>,
    /// Write the prior even when the batch is not to be trusted (the file
    /// says so).
    #[arg(long, requires = "write_prior")]
    pub force: bool,
}

/// `--solver` as a solver kind (one line, exit 2, when unknown).
fn solver_kind(name: &str) -> Result<SolverKind, CliError> {
    name.parse().map_err(CliError::input)
}

/// `tricept fleet`.
pub fn run(a: &FleetArgs) -> Result<u8, CliError> {
    let mut request = FleetRequest::new(a.data.iter().cloned().map(DataInput::File).collect());
    request.machine = a.machine.input(&a.noise);
    request.parameter_set = a.params.params.clone();
    request.tolerance_mm = a.tolerance_mm;
    request.solver = a.solver;
    let result = fleet(request)?;
    let written = a.write_prior.as_ref().map(|path| {
        let options = tricept_ident::WriteOptions::default().force(a.force);
        (path, result.write_prior(path, options))
    });
    if let Some((path, Ok(w))) = &written {
        if let Some(why) = w.forced() {
            errln!(
                "warning: --write-prior {}: written with --force although {why}",
                path.display()
            );
        }
        errln!("wrote {}", path.display());
    }
    if a.machine.json {
        crate::output::write_json(result.to_json());
    } else {
        crate::output::write_text(&result.report());
    }
    if let Some((_, Err(e))) = written {
        return Err(e);
    }
    let code = result.exit_code();
    if let Some(why) = result.reason() {
        errln!("fleet: exit {code}: {why}");
    }
    Ok(code)
}
