//! The one shape of every workflow's result ([`Outcome`]: an exit code,
//! why it is not 0, the text report and the JSON a verb prints), and of
//! every result that can write a machine file ([`WritesMachine`]: the
//! accuracy the file promises, the file written by one rule with
//! [`WriteOptions`] into a [`Written`]).
//!
//! Each result also has these methods as its own (callable without
//! importing the traits); [`outcome!`] implements the traits from them, so
//! the compiler checks that every result's methods have the one signature.

use std::path::{Path, PathBuf};

use serde_json::{Map, Value};

pub(crate) use crate::accuracy::Accuracy;
use crate::error::Error;
use crate::json_version::OUTPUT_FORMAT_VERSION;

/// What every workflow returns: its verdict as an exit code, why the code
/// is not 0, the text report and the JSON of the verb's `--json`.
///
/// Implemented by every workflow's result (`Calibration`,
/// `DiagnoseResult`, `CheckResult`, `Compensation`, `FleetResult`,
/// `Identifiability`, `DetectabilityReport`, `EffectList`, `Plan`,
/// `Export`, `Simulation`, `Report`, `PointSolution`), so a program can
/// handle any of them alike.
///
/// # Example
/// ```
/// use tricept_ident::Outcome;
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
///
/// /// Prints any workflow's result as the `tricept` binary does.
/// fn show(result: &impl Outcome) -> u8 {
///     print!("{}", result.report());
///     if let Some(why) = result.reason() {
///         eprintln!("exit {}: {why}", result.exit_code());
///     }
///     result.exit_code()
/// }
///
/// let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(data))?;
/// assert_eq!(show(&calibration), 0);
/// assert_eq!(calibration.to_json()["format_version"], 1);
/// assert_eq!(show(&tricept_ident::effects::effects(None)?), 0);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub trait Outcome {
    /// The process exit code of the verdict (0 ok, 3 the model does not
    /// explain the data or the result is refused for a reason, 4 not
    /// converged; [`crate::ErrorKind`] for the codes of errors).
    fn exit_code(&self) -> u8;

    /// Why the exit code is not 0, in one phrase (`None` when it is 0).
    /// The `tricept` binary prints it after `VERB: exit CODE: `.
    fn reason(&self) -> Option<&str>;

    /// The text report (what the verb prints).
    fn report(&self) -> String;

    /// The JSON (what the verb's `--json` prints): an object whose first
    /// key is `format_version`, or an array of such objects for a verb
    /// that prints one object per line.
    fn to_json(&self) -> Value;
}

/// A result that can write a calibrated machine file (or a batch's
/// prior): the accuracy the file promises and the one write rule.
///
/// # Example
/// ```
/// use std::path::Path;
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// use tricept_ident::kinematics::MachineDescription;
/// use tricept_ident::{Error, WriteOptions, WritesMachine};
///
/// /// Deploys any result that writes a machine file; returns its promise.
/// fn deploy(result: &impl WritesMachine, path: &Path) -> Result<Option<f64>, Error> {
///     result.write_machine(path, WriteOptions::default())?;
///     Ok(result.accuracy().map(|a| a.upper_mm))
/// }
///
/// let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(data))?;
/// let dir = std::env::temp_dir().join(format!("tricept-door-deploy-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let promised = deploy(&calibration, &dir.join("calibrated.json"))?;
/// let record = MachineDescription::from_file(&dir.join("calibrated.json"))?.calibration;
/// let recorded = record.and_then(|c| c.accuracy).map(|a| a.upper_mm);
/// assert!(promised.is_some() && recorded == promised); // the file states the promise
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait WritesMachine: Outcome {
    /// The accuracy the file it writes promises (`None` when it writes
    /// none, or states none).
    fn accuracy(&self) -> Option<&Accuracy>;

    /// Writes the machine file at `path` atomically by the one write rule:
    /// a result whose exit code is not 0 is refused (an error of that code,
    /// [`crate::ErrorCause::RefusedWrite`]) unless
    /// [`WriteOptions::force`], and the file then says it was forced.
    fn write_machine(&self, path: &Path, options: WriteOptions) -> Result<Written, Error>;
}

/// How a result writes its file.
///
/// # Example
/// ```
/// use tricept_ident::WriteOptions;
/// assert!(!WriteOptions::default().is_forced());
/// assert!(WriteOptions::default().force(true).is_forced());
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct WriteOptions {
    force: bool,
}

impl WriteOptions {
    /// Writes the file even when the result is not to be trusted (its exit
    /// code is not 0): the file then records why (default `false`: such a
    /// write is refused).
    #[must_use]
    pub fn force(mut self, force: bool) -> WriteOptions {
        self.force = force;
        self
    }

    /// Whether an untrusted result is written anyway.
    pub fn is_forced(&self) -> bool {
        self.force
    }
}

/// What a result wrote: which file, where, and why it was written although
/// not to be trusted (a forced write).
///
/// # Example
/// ```
/// use tricept_ident::WriteOptions;
/// use tricept_ident::calibrate::{CalibrateRequest, calibrate};
/// let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
/// let calibration = calibrate(CalibrateRequest::new(data))?;
/// let dir = std::env::temp_dir().join(format!("tricept-door-written-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let written = calibration.write_machine(&dir.join("m.json"), WriteOptions::default())?;
/// assert_eq!((written.what(), written.path()), ("machine file", dir.join("m.json").as_path()));
/// assert_eq!(written.forced(), None); // exit code 0: nothing to force
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct Written {
    what: &'static str,
    path: PathBuf,
    forced: Option<String>,
}

impl Written {
    pub(crate) fn new(what: &'static str, path: &Path, forced: Option<String>) -> Written {
        Written {
            what,
            path: path.to_path_buf(),
            forced,
        }
    }

    /// What was written: `"machine file"` or `"prior"`.
    pub fn what(&self) -> &'static str {
        self.what
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Why the file was written although its result is not to be trusted
    /// (written with [`WriteOptions::force`]); `None` for a trusted one.
    pub fn forced(&self) -> Option<&str> {
        self.forced.as_deref()
    }
}

/// `v` with `format_version` ([`OUTPUT_FORMAT_VERSION`]) as its first key
/// (an object without one; anything else as it is).
pub(crate) fn versioned(v: Value) -> Value {
    match v {
        Value::Object(map) if !map.contains_key("format_version") => {
            let mut out = Map::with_capacity(map.len() + 1);
            out.insert("format_version".into(), OUTPUT_FORMAT_VERSION.into());
            out.extend(map);
            Value::Object(out)
        }
        v => v,
    }
}

/// `v` without the `format_version` of an output (a result's JSON kept
/// inside another document, as the report page keeps its sources').
pub(crate) fn unversioned(mut v: Value) -> Value {
    if let Value::Object(o) = &mut v {
        o.shift_remove("format_version");
    }
    v
}

/// Implements [`Outcome`] (and, with `writes`, [`WritesMachine`]) for a
/// result from its own methods of the same names: a result whose method
/// has another signature does not compile.
macro_rules! outcome {
    ($($result:ty),+ $(,)?) => {$(
        impl $crate::outcome::Outcome for $result {
            fn exit_code(&self) -> u8 {
                <$result>::exit_code(self)
            }
            fn reason(&self) -> Option<&str> {
                <$result>::reason(self)
            }
            fn report(&self) -> String {
                <$result>::report(self)
            }
            fn to_json(&self) -> serde_json::Value {
                <$result>::to_json(self)
            }
        }
    )+};
    (writes $($result:ty),+ $(,)?) => {$(
        $crate::outcome::outcome!($result);
        impl $crate::outcome::WritesMachine for $result {
            fn accuracy(&self) -> Option<&$crate::outcome::Accuracy> {
                <$result>::accuracy(self)
            }
            fn write_machine(
                &self,
                path: &std::path::Path,
                options: $crate::outcome::WriteOptions,
            ) -> Result<$crate::outcome::Written, $crate::error::Error> {
                <$result>::write_machine(self, path, options)
            }
        }
    )+};
}
pub(crate) use outcome;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn versioned_puts_the_format_version_first_once() {
        let v = versioned(serde_json::json!({"a": 1}));
        assert_eq!(v.to_string(), r#"{"format_version":1,"a":1}"#);
        assert_eq!(versioned(v.clone()), v);
        assert_eq!(versioned(Value::Null), Value::Null);
    }
}
