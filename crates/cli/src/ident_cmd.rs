//! The self-calibration verbs `identifiability` and `identify`: flags in,
//! one call of the door (`tricept_ident::identifiability`,
//! `tricept_ident::calibrate`), the result out.

use std::path::PathBuf;

use clap::Args;
use tricept_ident::advanced::Poses;
use tricept_ident::calibrate::calibrate;
use tricept_ident::identifiability::{Campaign, IdentifiabilityRequest, assess_identifiability};
use tricept_ident::{DataInput, WriteOptions};

use crate::args::{IdentifyArgs, MachineArgs, NoiseArgs, ParamArgs};
use crate::cli_error::CliError;

/// `tricept identifiability`.
#[derive(Debug, Args)]
pub struct IdentifiabilityArgs {
    /// Pose set (see below).
    #[arg(long, default_value = "grid", conflicts_with = "data")]
    pub poses: Poses,
    /// Assess a logged campaign instead: the commands of this
    /// measured-data file (its readings are not used).
    #[arg(long, value_name = "FILE.csv")]
    pub data: Option<PathBuf>,
    #[command(flatten)]
    pub params: ParamArgs,
    #[command(flatten)]
    pub noise: NoiseArgs,
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `tricept identifiability`.
pub fn run_identifiability(a: &IdentifiabilityArgs) -> Result<u8, CliError> {
    let campaign = match &a.data {
        Some(path) => Campaign::Data(DataInput::File(path.clone())),
        None => Campaign::Poses(a.poses.clone()),
    };
    let mut request = IdentifiabilityRequest::new(campaign);
    request.machine = a.machine.input(&a.noise);
    request.parameter_set = a.params.params.clone();
    let result = assess_identifiability(request)?;
    crate::output::warn_all(result.machine_warnings());
    if a.machine.json {
        crate::output::write_json(result.to_json());
    } else {
        crate::output::write_text(&result.report());
    }
    Ok(0)
}

/// `tricept identify`.
pub fn run_identify(a: &IdentifyArgs) -> Result<u8, CliError> {
    let (request, spin) = a.prepare()?;
    let calibration = calibrate(request);
    spin.finish_and_clear();
    let calibration = calibration?;
    crate::output::warn_all(calibration.machine_warnings());
    let written = a
        .write_machine
        .as_ref()
        .map(|path| calibration.write_machine(path, WriteOptions::default().force(a.force)));
    if let Some(Ok(w)) = &written {
        if let Some(why) = w.forced() {
            errln!(
                "warning: --write-machine {}: written with --force although {why}",
                w.path().display()
            );
        }
        errln!("wrote {}", w.path().display());
    }
    if a.settings.machine.json {
        crate::output::write_json(calibration.to_json());
    } else {
        crate::output::write_text(&calibration.report());
    }
    for line in calibration.notices() {
        errln!("{line}");
    }
    if let Some(Err(e)) = written {
        return Err(e);
    }
    if let Some(why) = calibration.reason() {
        errln!("identify: exit {}: {why}", calibration.exit_code());
    }
    Ok(calibration.exit_code())
}
