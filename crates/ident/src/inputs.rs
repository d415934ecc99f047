//! What every workflow takes in: a machine (a description file or the
//! embedded Table 1 machine, with sensor-noise overrides), measured data
//! checked against that machine, pose sets, true errors and effects of a
//! simulated machine, and the typed values of the CLI's flags (`X,Y,Z`
//! triples, head-angle lists), each parsed by [`std::str::FromStr`] so the
//! binary can use them as clap value parsers.
//!
//! Every problem is an [`Error`] of kind input (exit code 2) naming the
//! file, the line and the column, or the value at fault.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::linalg::Vector3;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{
    Machine, MachineDescription, error::DescriptionError, workspace::MAX_POSES, workspace::PoseSet,
    workspace::PoseSetError,
};
use tricept_model::ParameterSet;
use tricept_plant::Effect;

use crate::Setting;
use crate::error::{Classify, Error};
use crate::limits;

/// Sensor-noise overrides of a machine (default: the description's).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{SensorNoise, load_machine};
/// let noise = SensorNoise { angle_noise_arcsec: Some(2.0), ..SensorNoise::default() };
/// let loaded = load_machine(None, &noise).unwrap();
/// assert!((loaded.geometry().sensors.angle_rad - 2.0 / 206_264.806).abs() < 1e-9);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SensorNoise {
    /// Encoder noise of one reading (standard deviation), arcsec.
    pub angle_noise_arcsec: Option<f64>,
    /// Linear-scale noise of one reading (standard deviation), um.
    pub length_noise_um: Option<f64>,
    /// Readings averaged into one logged value.
    pub readings_per_pose: Option<u32>,
}

/// A machine as loaded: its description (with the calibration record of a
/// calibrated machine), the validated machine built from it (with the
/// noise overrides applied), where it came from, and the warnings its
/// record calls for (a forced or inadequate calibration).
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// let loaded = MachineInput::default().load()?;
/// assert!(loaded.path().is_none() && loaded.warnings().is_empty());
/// let m = loaded.commanding();
/// assert!(!m.has_leg_effects());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct LoadedMachine {
    pub(crate) description: MachineDescription,
    pub(crate) machine: Machine,
    source: String,
    path: Option<PathBuf>,
    pub(crate) warnings: Vec<String>,
}

impl LoadedMachine {
    /// The description as read.
    pub fn description(&self) -> &MachineDescription {
        &self.description
    }

    /// The validated machine, noise overrides applied (crate-internal:
    /// the fits and readers take the geometric machine).
    pub(crate) fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The geometric machine, noise overrides applied: what a data reader
    /// and a fit take. Its own kinematics ignore the leg effects of the
    /// file; command the machine through [`LoadedMachine::commanding`].
    pub fn geometry(&self) -> &Machine {
        &self.machine
    }

    /// The file name, or `the built-in Table 1 machine`.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The file it was loaded from (none: the embedded Table 1 machine).
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Warnings about the calibration the file holds (forced, not
    /// converged, not adequate), one line each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The machine whose structure decides the rank rule: the nominal
    /// machine a calibrated file was calibrated from, else none (this
    /// machine).
    pub fn rank_reference(&self) -> Result<Option<Machine>, Error> {
        match &self.description.calibration {
            None => Ok(None),
            Some(c) => c
                .nominal
                .build()
                .map(Some)
                .map_err(|e| description_error(&self.source, e)),
        }
    }

    /// The machine a calibrated file's data were identified against (its
    /// record's `relative_to_machine`, else its `nominal`) with this file's
    /// sensors, named `source`: what a rerun of its calibration starts
    /// from. `None` for a machine without a calibration record.
    pub(crate) fn identified_against(
        &self,
        source: String,
    ) -> Result<Option<LoadedMachine>, Error> {
        let Some(c) = &self.description.calibration else {
            return Ok(None);
        };
        let mut description = c
            .relative_to_machine
            .as_deref()
            .unwrap_or(&c.nominal)
            .clone();
        description.sensors = self.description.sensors.clone();
        let mut machine = description
            .build()
            .map_err(|e| description_error(&source, e))?;
        machine.sensors = self.machine.sensors;
        Ok(Some(LoadedMachine {
            description,
            machine,
            source,
            path: None,
            warnings: Vec::new(),
        }))
    }

    /// The nominal machine a calibrated file records, as a description
    /// without calibration of its own.
    pub fn nominal_description(&self) -> MachineDescription {
        match &self.description.calibration {
            Some(c) => (*c.nominal).clone(),
            None => {
                let mut d = self.description.clone();
                d.calibration = None;
                d
            }
        }
    }
}

/// The input error of a description that cannot be loaded, naming the
/// file (and the line and column of a JSON error), the description's
/// error its [`source`](std::error::Error::source).
pub fn description_error(path: &str, e: DescriptionError) -> Error {
    let message = match &e {
        DescriptionError::Json { source } => format!(
            "{path}: line {}, column {}: {}",
            source.line(),
            source.column(),
            strip_position(&source.to_string())
        ),
        DescriptionError::Io { .. } => e.to_string(),
        _ => format!("{path}: {e}"),
    };
    let error = match e.file_failure() {
        Some(f) => Error::input(message).with_file_failure(f),
        None => Error::input(message),
    };
    let error = match e.cause() {
        Some(cause) => error.with_cause(cause),
        None => error,
    };
    error.with_source(e)
}

/// serde_json appends " at line L column C"; the message states it up front.
fn strip_position(s: &str) -> String {
    match s.rfind(" at line ") {
        Some(i) => s[..i].to_string(),
        None => s.to_string(),
    }
}

/// Loads the machine file at `path`, or the embedded Table 1 machine, and
/// applies the noise overrides: the workspace must be reachable and a
/// calibration record must be intact (an edited calibrated file is
/// refused).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{SensorNoise, load_machine};
/// let loaded = load_machine(None, &SensorNoise::default()).unwrap();
/// assert_eq!(loaded.source(), "the built-in Table 1 machine");
/// assert!(loaded.warnings().is_empty());
/// ```
pub fn load_machine(path: Option<&Path>, noise: &SensorNoise) -> Result<LoadedMachine, Error> {
    let (description, source) = match path {
        None => (
            MachineDescription::paper(),
            "the built-in Table 1 machine".to_string(),
        ),
        Some(path) => {
            let source = path.display().to_string();
            (
                MachineDescription::from_file(path).map_err(|e| description_error(&source, e))?,
                source,
            )
        }
    };
    let mut loaded = LoadedMachine::from_description(description, source, noise)?;
    loaded.path = path.map(Path::to_path_buf);
    Ok(loaded)
}

impl LoadedMachine {
    /// A machine from a description in memory (one a program built, or a
    /// file's text read back), checked as a file is ([`load_machine`]): it
    /// must be valid, its workspace reachable and its calibration record,
    /// if it has one, intact. `source` names it in messages.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::LoadedMachine;
    /// use tricept_ident::advanced::SensorNoise;
    /// use tricept_ident::kinematics::MachineDescription;
    /// let mut d = MachineDescription::paper();
    /// let m = LoadedMachine::from_description(d.clone(), "mine", &SensorNoise::default()).unwrap();
    /// assert_eq!(m.source(), "mine");
    /// d.workspace.radius_mm = -1.0;
    /// assert!(LoadedMachine::from_description(d, "mine", &SensorNoise::default()).is_err());
    /// ```
    pub fn from_description(
        description: MachineDescription,
        source: impl Into<String>,
        noise: &SensorNoise,
    ) -> Result<LoadedMachine, Error> {
        let source = source.into();
        description
            .validate()
            .map_err(|e| description_error(&source, e))?;
        let mut machine = description
            .build()
            .map_err(|e| description_error(&source, e))?;
        if let Some((r, why)) = machine.unreachable_workspace_point() {
            let w = &machine.workspace;
            return Err(Error::input(format!(
                "{source}: the workspace (radius {} mm, z from {} to {} mm) is not within the machine's reach: at ({:.1}, {:.1}, {:.1}) mm: {why}; shrink `workspace` or correct `limits`",
                w.radius_mm, w.z_min_mm, w.z_max_mm, r.x, r.y, r.z
            )));
        }
        let notes = tricept_engine::record::check_calibration_record(&description)
            .map_err(|e| Error::with_context(&source, e))?;
        let mut warnings = Vec::new();
        if let Some(w) = notes.warning() {
            warnings.push(format!("{source}: {w}"));
        }
        if let Some(c) = &description.calibration {
            if c.forced {
                warnings.push(format!(
                    "{source} holds a calibration written although it is not to be trusted (forced) (converged: {}, adequate: {})",
                    c.converged, c.adequate
                ));
            } else if !c.converged {
                warnings.push(format!(
                    "{source} holds a calibration whose fit did not converge: its estimates are not a calibration"
                ));
            } else if !c.adequate {
                warnings.push(format!(
                    "{source} holds a calibration whose model did not explain its data (chi2/dof {:.2})",
                    c.chi2_per_dof
                ));
            }
        }
        apply_noise(&mut machine, noise)?;
        Ok(LoadedMachine {
            description,
            machine,
            source,
            path: None,
            warnings,
        })
    }

    /// The same machine with the sensor-noise overrides `noise` applied
    /// (each must be positive), as a file loaded with them would be.
    pub fn with_noise(mut self, noise: &SensorNoise) -> Result<LoadedMachine, Error> {
        apply_noise(&mut self.machine, noise)?;
        Ok(self)
    }
}

/// Applies sensor-noise overrides to a machine (each must be positive).
fn apply_noise(m: &mut Machine, noise: &SensorNoise) -> Result<(), Error> {
    if let Some(a) = noise.angle_noise_arcsec {
        m.sensors.angle_rad = at_most(
            Setting::AngleNoiseArcsec,
            positive(Setting::AngleNoiseArcsec, a)?,
            MAX_NOISE,
        )? * RAD_PER_ARCSEC;
    }
    if let Some(l) = noise.length_noise_um {
        m.sensors.length_mm = at_most(
            Setting::LengthNoiseUm,
            positive(Setting::LengthNoiseUm, l)?,
            MAX_NOISE,
        )? * 1e-3;
    }
    if let Some(k) = noise.readings_per_pose {
        if k == 0 {
            return Err(Error::invalid(
                Setting::ReadingsPerPose,
                "must be at least 1",
            ));
        }
        m.sensors.readings_per_pose = k;
    }
    Ok(())
}

/// The largest sensor noise an override may state (arcsec or um): an
/// encoder 10 000 arcsec (2.8 degrees) or a scale 10 mm off in one
/// reading is no sensor of this machine, and its weights would underflow.
pub const MAX_NOISE: f64 = 1e4;

/// `v` if it is at most `max`, else an input error naming `setting`.
fn at_most(setting: Setting, v: f64, max: f64) -> Result<f64, Error> {
    if v <= max {
        Ok(v)
    } else {
        Err(Error::invalid(
            setting,
            format!("must be at most {max}, got {v}"),
        ))
    }
}

/// `v` if it is a positive finite number, else an input error naming
/// `setting`.
pub fn positive(setting: Setting, v: f64) -> Result<f64, Error> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::invalid(
            setting,
            format!("must be a positive number, got {v}"),
        ))
    }
}

/// A set of target points (`--poses`): a generated [`PoseSet`]
/// (`grid`, `grid:R,P,L`, `random:N[,SEED]`, `disc:SPACING[,Z]`), the
/// D-optimal `optimal:N`, or a CSV file of `x,y,z` (mm).
///
/// # Example
/// ```
/// use tricept_ident::advanced::Poses;
/// use tricept_ident::kinematics::GeometricMachine;
/// let poses: Poses = "random:10,1".parse().unwrap();
/// assert_eq!(poses.targets(&GeometricMachine::paper()).unwrap().len(), 10);
/// assert!("optimal:0".parse::<Poses>().is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Poses {
    spec: String,
    kind: PosesKind,
}

#[derive(Debug, Clone, PartialEq)]
enum PosesKind {
    Optimal(usize),
    Set(PoseSet),
    File(PathBuf),
}

impl FromStr for Poses {
    type Err = Error;

    fn from_str(spec: &str) -> Result<Poses, Error> {
        let kind = if let Some(n) = spec.strip_prefix("optimal:") {
            let n: usize = n
                .parse()
                .ok()
                .filter(|n| (1..=MAX_POSES).contains(n))
                .ok_or_else(|| {
                    Error::invalid_value(
                        Setting::Poses,
                        format!("`{spec}`"),
                        format!("expected optimal:N with N a whole number from 1 to {MAX_POSES}"),
                    )
                })?;
            PosesKind::Optimal(n)
        } else {
            let set: PoseSet = spec
                .parse()
                .map_err(|e: PoseSetError| Error::input(e.to_string()))?;
            match set {
                PoseSet::File(path) => PosesKind::File(path),
                set => PosesKind::Set(set),
            }
        };
        Ok(Poses {
            spec: spec.to_string(),
            kind,
        })
    }
}

impl fmt::Display for Poses {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.spec)
    }
}

impl Poses {
    /// The paper's grid of 75 poses (`grid`).
    pub fn grid() -> Poses {
        Poses {
            spec: "grid".to_string(),
            kind: PosesKind::Set(PoseSet::Grid {
                rings: 3,
                per_ring: 8,
                levels: 3,
            }),
        }
    }

    /// The CSV file of the poses, when the spec names one (neither a
    /// grid, a random set, a disc nor `optimal:N`).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::Poses;
    /// assert!("random:20,1".parse::<Poses>().unwrap().file().is_none());
    /// assert_eq!("p.csv".parse::<Poses>().unwrap().file().unwrap().to_str(), Some("p.csv"));
    /// ```
    pub fn file(&self) -> Option<&Path> {
        match &self.kind {
            PosesKind::File(p) => Some(p),
            _ => None,
        }
    }

    /// The target points on `machine`, mm.
    pub fn targets(&self, machine: &Machine) -> Result<Vec<Vector3>, Error> {
        match &self.kind {
            PosesKind::Optimal(n) => {
                tricept_study::campaign::d_optimal_targets(machine, &ParameterSet::paper15(), *n)
                    .map_err(|e| {
                        Error::naming(
                            crate::ErrorKind::Other,
                            Setting::Poses,
                            format!(" `{}`: {e}", self.spec),
                        )
                    })
            }
            PosesKind::Set(set) => Ok(set.generate(&machine.workspace).unwrap_or_default()),
            PosesKind::File(path) => Ok(tricept_data::targets::read_targets(path)?
                .into_iter()
                .map(Vector3::from)
                .collect()),
        }
    }
}

/// True geometric errors of a simulated machine (`--truth`): `table2`,
/// `zero`, `random:MAG_MM[,SEED]` (uniform in ±MAG_MM) or a JSON file
/// `{name: mm}`.
///
/// # Example
/// ```
/// use tricept_ident::advanced::{ParameterSet, TrueErrors};
/// let set = ParameterSet::paper15();
/// let e: TrueErrors = "random:0.1,3".parse().unwrap();
/// assert!(e.values(&set).unwrap().iter().all(|v| v.abs() <= 0.1));
/// assert!("random:x".parse::<TrueErrors>().is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum TrueErrors {
    /// The paper's Table 2.
    Table2,
    /// No error.
    Zero,
    /// Uniform in ±`magnitude_mm`, drawn from `seed`.
    Random {
        /// Half-width of the uniform distribution, mm.
        magnitude_mm: f64,
        /// Seed of the draw.
        seed: u64,
    },
    /// A JSON file of parameter values, mm or rad.
    File(PathBuf),
}

impl FromStr for TrueErrors {
    type Err = Error;

    fn from_str(s: &str) -> Result<TrueErrors, Error> {
        Ok(match s {
            "table2" => TrueErrors::Table2,
            "zero" => TrueErrors::Zero,
            s if s.starts_with("random:") => {
                let max = tricept_model::params::MAX_PARAMETER_ERROR.0;
                let (magnitude_mm, seed) = random_spec(
                    Setting::Truth,
                    s,
                    max,
                    &format!("random:MAG_MM[,SEED] with MAG_MM from 0 to {max} mm"),
                )?;
                TrueErrors::Random { magnitude_mm, seed }
            }
            path => TrueErrors::File(PathBuf::from(path)),
        })
    }
}

/// The size (from 0 to `max`) and seed (default 0) of a
/// `random:SIZE[,SEED]` spec, or an input error naming `flag` and saying
/// what was `expected`.
pub(crate) fn random_spec(
    setting: Setting,
    spec: &str,
    max: f64,
    expected: &str,
) -> Result<(f64, u64), Error> {
    let rest = spec.strip_prefix("random:").unwrap_or(spec);
    let mut parts = rest.split(',');
    let size: f64 = parts
        .next()
        .and_then(|t| t.parse().ok())
        .filter(|v: &f64| v.is_finite() && (0.0..=max).contains(v))
        .ok_or_else(|| {
            Error::invalid_value(setting, format!("`{spec}`"), format!("expected {expected}"))
        })?;
    let seed: u64 = match parts.next() {
        Some(t) => t.parse().map_err(|_| {
            Error::invalid_value(setting, format!("`{spec}`"), "SEED must be a whole number")
        })?,
        None => 0,
    };
    Ok((size, seed))
}

impl TrueErrors {
    /// The values of `set`'s parameters (mm, rad).
    pub fn values(&self, set: &ParameterSet) -> Result<Vec<f64>, Error> {
        match self {
            TrueErrors::Table2 => Ok(set.table2()),
            TrueErrors::Zero => Ok(vec![0.0; set.len()]),
            TrueErrors::Random { magnitude_mm, seed } => Ok(tricept_plant::random_errors(
                set.len(),
                *magnitude_mm,
                *seed,
            )),
            TrueErrors::File(path) => {
                let name = path.display();
                let text = tricept_data::bounded::read_json_text(path)
                    .map_err(|e| Error::unreadable(&name, e))?;
                set.parse_values(&text)
                    .map_err(|e| Error::input(format!("{name}: {e}")).with_source(e))
            }
        }
    }
}

/// Parses `--truth-effect` values: JSON objects (or arrays of them),
/// inline or from `@FILE`, each validated.
///
/// # Example
/// ```
/// let effects = tricept_ident::advanced::parse_effects(&[r#"{"effect":"leg-lead","ppm":[50,-30,40]}"#.to_string()]).unwrap();
/// assert_eq!(effects.len(), 1);
/// assert!(tricept_ident::advanced::parse_effects(&["{\"effect\":\"nothing\"}".to_string()]).is_err());
/// ```
pub fn parse_effects(specs: &[String]) -> Result<Vec<Effect>, Error> {
    let mut out = Vec::new();
    for spec in specs {
        let (text, origin) = match spec.strip_prefix('@') {
            Some(path) => (
                tricept_data::bounded::read_json_text(Path::new(path))
                    .map_err(|e| Error::unreadable(path, e))?,
                path.to_string(),
            ),
            None => (spec.clone(), Setting::TruthEffect.name().to_string()),
        };
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
            // A bare effect name is the usual slip: say what to give.
            let typical = tricept_plant::effects::typical_effects()
                .into_iter()
                .find(|t| t.tag() == text.trim());
            match typical.and_then(|t| serde_json::to_string(&t).ok()) {
                Some(example) => Error::input(format!(
                    "{origin}: `{}` names an effect; give it with its magnitudes as a JSON object, e.g. '{example}' (`tricept effects` lists every effect's keys)",
                    text.trim()
                )),
                None => Error::input(format!("{origin}: {e}")),
            }
        })?;
        let items = match value {
            serde_json::Value::Array(a) => a,
            v => vec![v],
        };
        for item in items {
            let effect: Effect = serde_json::from_value(item)
                .map_err(|e| Error::input(format!("{origin}: {e}")).with_source(e))?;
            effect
                .validate()
                .map_err(|why| Error::input(format!("{origin}: {why}")))?;
            out.push(effect);
        }
    }
    Ok(out)
}

/// `count` comma-separated finite numbers within ±1e5
/// (mm, deg or rad), or an input error naming `label` (what the numbers
/// are).
///
/// # Example
/// ```
/// assert_eq!(tricept_ident::advanced::parse_numbers("at", "1,2.5,-3", 3).unwrap(), vec![1.0, 2.5, -3.0]);
/// assert!(tricept_ident::advanced::parse_numbers("at", "1,2", 3).is_err());
/// ```
pub fn parse_numbers(label: &str, text: &str, count: usize) -> Result<Vec<f64>, Error> {
    let values: Result<Vec<f64>, _> = text.split(',').map(|t| t.trim().parse::<f64>()).collect();
    match values {
        Ok(v) if v.len() == count && v.iter().all(|x| x.is_finite()) => {
            if let Some(x) = v.iter().find(|x| x.abs() > limits::MAX_COORDINATE) {
                return Err(Error::input(format!(
                    "{label}: {x} is beyond ±{} (mm, deg or rad): not a value for this machine",
                    limits::MAX_COORDINATE
                )));
            }
            Ok(v)
        }
        _ => Err(Error::input(format!(
            "{label}: expected {count} comma-separated numbers, got `{text}`"
        ))),
    }
}

/// An `X,Y,Z` triple (mm): a typed flag value.
///
/// # Example
/// ```
/// let t: tricept_ident::advanced::Triple = "0,0,1150".parse().unwrap();
/// assert_eq!(t.0, [0.0, 0.0, 1150.0]);
/// assert!("0,0".parse::<tricept_ident::advanced::Triple>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triple(pub [f64; 3]);

impl FromStr for Triple {
    type Err = Error;

    /// Its message names no flag: the caller's parser does.
    fn from_str(text: &str) -> Result<Triple, Error> {
        let v = parse_numbers("X,Y,Z", text, 3).map_err(|e| without_flag(e, "X,Y,Z"))?;
        Ok(Triple([v[0], v[1], v[2]]))
    }
}

/// A frame `X,Y,Z,RX,RY,RZ`: a translation (mm) and a rotation vector
/// (rad); a typed flag value.
///
/// # Example
/// ```
/// let f: tricept_ident::advanced::FrameMmRad = "1500,-800,200,0.1,0.2,0.3".parse().unwrap();
/// assert_eq!(f.0, [1500.0, -800.0, 200.0, 0.1, 0.2, 0.3]);
/// let e = "1,2,3".parse::<tricept_ident::advanced::FrameMmRad>().unwrap_err();
/// assert_eq!(e.message(), "expected 6 comma-separated numbers, got `1,2,3`");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameMmRad(pub [f64; 6]);

impl FromStr for FrameMmRad {
    type Err = Error;

    /// Its message names no flag: the caller's parser does.
    fn from_str(text: &str) -> Result<FrameMmRad, Error> {
        const NAME: &str = "X,Y,Z,RX,RY,RZ";
        let v = parse_numbers(NAME, text, 6).map_err(|e| without_flag(e, NAME))?;
        Ok(FrameMmRad([v[0], v[1], v[2], v[3], v[4], v[5]]))
    }
}

/// Head-angle lists `H1,H1,...:H2,H2,...` in degrees: a typed flag value.
///
/// # Example
/// ```
/// let h: tricept_ident::advanced::HeadAngles = "0,90:15,35".parse().unwrap();
/// assert_eq!((h.h1_deg.len(), h.h2_deg.len()), (2, 2));
/// assert!("0,90".parse::<tricept_ident::advanced::HeadAngles>().is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct HeadAngles {
    /// Angles of the first head axis, deg.
    pub h1_deg: Vec<f64>,
    /// Angles of the second head axis, deg.
    pub h2_deg: Vec<f64>,
}

impl FromStr for HeadAngles {
    type Err = Error;

    /// Its message names no flag: the caller's parser does.
    fn from_str(text: &str) -> Result<HeadAngles, Error> {
        parse_head_angles("H1S:H2S", text).map_err(|e| without_flag(e, "H1S:H2S"))
    }
}

/// `e` without the `flag: ` its message starts with.
fn without_flag(e: Error, flag: &str) -> Error {
    match e
        .message()
        .strip_prefix(flag)
        .and_then(|m| m.strip_prefix(": "))
    {
        Some(m) => Error::new(e.kind(), m),
        None => e,
    }
}

/// `H1S:H2S` lists of degrees, or an input error naming `flag`.
pub fn parse_head_angles(flag: &str, text: &str) -> Result<HeadAngles, Error> {
    let Some((a, b)) = text.split_once(':') else {
        return Err(Error::input(format!(
            "{flag}: expected `H1,H1,...:H2,H2,...` in degrees, got `{text}`"
        )));
    };
    Ok(HeadAngles {
        h1_deg: parse_list(flag, a)?,
        h2_deg: parse_list(flag, b)?,
    })
}

/// A list of angles in degrees, `a,b,c`, at most
/// [`limits::MAX_HEAD_ANGLES`].
fn parse_list(flag: &str, text: &str) -> Result<Vec<f64>, Error> {
    let n = text.split(',').count();
    if n > limits::MAX_HEAD_ANGLES {
        return Err(Error::input(format!(
            "{flag}: {n} angles; at most {} per head axis",
            limits::MAX_HEAD_ANGLES
        )));
    }
    parse_numbers(flag, text, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positive_takes_positive_finite_numbers_only() {
        assert!(positive(Setting::SigmaUm, 0.0).is_err());
        assert!(positive(Setting::SigmaUm, f64::NAN).is_err());
        assert_eq!(positive(Setting::SigmaUm, 2.5).unwrap(), 2.5);
        assert_eq!(
            positive(Setting::SigmaUm, -1.0).unwrap_err().message(),
            "sigma_um: must be a positive number, got -1"
        );
    }
}
