//! The machine as every workflow takes it: a description file (or the
//! embedded Table 1 machine) with sensor-noise overrides, loaded when the
//! workflow runs, or a machine the caller has loaded already (to read its
//! data with a progress display, say). One type for every request that
//! needs a machine, so a caller learns one way to give it.

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::inputs::{LoadedMachine, SensorNoise, load_machine};

/// The machine a workflow runs on.
///
/// [`MachineInput::new`] names a description file (none: the embedded
/// Table 1 machine) and the sensor-noise overrides; the workflow loads and
/// checks it (an edited calibrated file is refused, exit code 2). A machine
/// loaded already ([`MachineInput::load`]) converts with `From`.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::advanced::SensorNoise;
/// let noise = SensorNoise { angle_noise_arcsec: Some(2.0), ..SensorNoise::default() };
/// let input = MachineInput::new(None, noise);
/// assert!(input.path().is_none());
/// let loaded = input.load().unwrap();
/// assert_eq!(loaded.source(), "the built-in Table 1 machine");
/// assert!((loaded.geometry().sensors.angle_rad - 2.0 / 206_264.806).abs() < 1e-9);
/// // A loaded machine is an input too, and keeps where it came from.
/// assert!(MachineInput::from(loaded).path().is_none());
/// ```
#[derive(Debug, Clone)]
pub struct MachineInput {
    source: Source,
}

/// Where a [`MachineInput`]'s machine is.
#[derive(Debug, Clone)]
enum Source {
    /// A description file to load (none: Table 1), with noise overrides.
    File {
        path: Option<PathBuf>,
        noise: SensorNoise,
    },
    /// Loaded already, noise overrides applied.
    Loaded(Box<LoadedMachine>),
}

impl MachineInput {
    /// The machine described at `path` (none: the embedded Table 1
    /// machine) with the sensor-noise overrides `noise`: what `--machine`
    /// and the noise flags of every verb give.
    pub fn new(path: Option<PathBuf>, noise: SensorNoise) -> MachineInput {
        MachineInput {
            source: Source::File { path, noise },
        }
    }

    /// The description file, when the machine comes from one.
    pub fn path(&self) -> Option<&Path> {
        match &self.source {
            Source::File { path, .. } => path.as_deref(),
            Source::Loaded(loaded) => loaded.path(),
        }
    }

    /// The machine, loaded and checked (a file), or as loaded already:
    /// an input error naming the file when it cannot be loaded.
    pub fn load(self) -> Result<LoadedMachine, Error> {
        match self.source {
            Source::File { path, noise } => load_machine(path.as_deref(), &noise),
            Source::Loaded(loaded) => Ok(*loaded),
        }
    }
}

/// The embedded Table 1 machine with its stated sensor noise.
impl Default for MachineInput {
    fn default() -> MachineInput {
        MachineInput::new(None, SensorNoise::default())
    }
}

impl From<LoadedMachine> for MachineInput {
    fn from(loaded: LoadedMachine) -> MachineInput {
        MachineInput {
            source: Source::Loaded(Box::new(loaded)),
        }
    }
}

impl From<&Path> for MachineInput {
    fn from(path: &Path) -> MachineInput {
        MachineInput::new(Some(path.to_path_buf()), SensorNoise::default())
    }
}

impl From<PathBuf> for MachineInput {
    fn from(path: PathBuf) -> MachineInput {
        MachineInput::new(Some(path), SensorNoise::default())
    }
}

impl From<&str> for MachineInput {
    fn from(path: &str) -> MachineInput {
        MachineInput::from(PathBuf::from(path))
    }
}

impl From<String> for MachineInput {
    fn from(path: String) -> MachineInput {
        MachineInput::from(PathBuf::from(path))
    }
}

impl From<&String> for MachineInput {
    fn from(path: &String) -> MachineInput {
        MachineInput::from(PathBuf::from(path))
    }
}

/// A machine file by any name a program holds: `&str`, `String`, `&Path`,
/// `PathBuf` or `&PathBuf`.
///
/// # Example
/// ```
/// use std::path::PathBuf;
/// use tricept_ident::MachineInput;
/// let file = PathBuf::from("calibrated.json");
/// for input in [
///     MachineInput::from(&file),
///     MachineInput::from(file.clone()),
///     MachineInput::from(file.as_path()),
///     MachineInput::from("calibrated.json"),
///     MachineInput::from(String::from("calibrated.json")),
/// ] {
///     assert_eq!(input.path(), Some(file.as_path()));
/// }
/// ```
impl From<&PathBuf> for MachineInput {
    fn from(path: &PathBuf) -> MachineInput {
        MachineInput::from(path.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_that_is_not_there_is_an_input_error_naming_it() {
        let e = MachineInput::from("no/such/machine.json")
            .load()
            .unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert!(e.message().contains("no/such/machine.json"), "{e}");
    }

    /// Every request that needs a machine takes the one input, and a
    /// machine file that is not there is the same input error from every
    /// workflow, naming the file.
    #[test]
    fn a_missing_machine_file_is_the_same_error_from_every_workflow() {
        use crate::compensate::{Calibrated, CompensateRequest, compensate};
        use crate::export::{Controller, ExportOptions, ExportRequest, export};
        use crate::inputs::Poses;
        use crate::{calibrate, check, detectability, diagnosis, identifiability, plan, simulate};
        let missing = "no/such/calibrated.json";
        let machine = || MachineInput::from(missing);
        let mut c = calibrate::CalibrateRequest::new("data.csv");
        c.machine = machine();
        let mut i = identifiability::IdentifiabilityRequest::new(identifiability::Campaign::Poses(
            Poses::grid(),
        ));
        i.machine = machine();
        let mut p = plan::PlanRequest::new(plan::Instrument::Tracker);
        p.machine = machine();
        let errors = [
            ("calibrate", calibrate::calibrate(c).err()),
            (
                "identifiability",
                identifiability::assess_identifiability(i).err(),
            ),
            ("plan", plan::plan(p).err()),
            (
                "check",
                check::check(check::CheckRequest::new(machine(), "data.csv")).err(),
            ),
            (
                "diagnose",
                diagnosis::diagnose(diagnosis::DiagnoseRequest::new("data.csv").machine(machine()))
                    .err(),
            ),
            (
                "detectability",
                detectability::detectability(
                    detectability::DetectabilityRequest::new(Poses::grid()).machine(machine()),
                )
                .err(),
            ),
            (
                "simulate",
                simulate::simulate(simulate::SimulateRequest::new().machine(machine())).err(),
            ),
            (
                "compensate",
                compensate(CompensateRequest::new(Calibrated::MachineFile(machine()))).err(),
            ),
            (
                "export",
                export(ExportRequest {
                    machine: machine(),
                    options: ExportOptions::new(Controller::Sinumerik),
                    out: PathBuf::from("no/such/out"),
                })
                .err(),
            ),
        ];
        for (workflow, e) in errors {
            let Some(e) = e else {
                panic!("{workflow}: ran without its machine file");
            };
            assert_eq!(e.exit_code(), crate::EXIT_INPUT, "{workflow}: {e}");
            assert!(e.message().contains(missing), "{workflow}: {e}");
        }
    }

    #[test]
    fn the_noise_overrides_are_checked_when_the_machine_is_loaded() {
        let noise = SensorNoise {
            readings_per_pose: Some(0),
            ..SensorNoise::default()
        };
        let input = MachineInput::new(None, noise);
        let e = input.load().unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert!(
            e.setting() == Some(crate::Setting::ReadingsPerPose)
                && e.message().contains("readings_per_pose"),
            "{e}"
        );
    }
}
