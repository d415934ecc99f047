//! The simulation workflow (`tricept simulate`): measured data from a
//! simulated machine (true geometric errors, unmodelled effects, head
//! errors, sensor noise and offsets), and optionally what external
//! instruments (laser tracker, ballbar, touch probe) would measure on it.
//! Everything is returned in memory with the comment lines its file
//! carries; the caller writes the files as every verb writes them
//! ([`crate::advanced::files::write_path`],
//! [`crate::advanced::files::write_external_path`]).
//!
//! # Example
//! ```
//! use tricept_ident::MachineInput;
//! use tricept_ident::simulate::{SimulateRequest, simulate};
//! let sim = simulate(SimulateRequest::new())?;
//! assert!(!sim.data().poses.is_empty());
//! assert_eq!(sim.exit_code(), tricept_ident::EXIT_OK);
//! # Ok::<(), tricept_ident::Error>(())
//! ```

mod external_docs;

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

pub use self::external_docs::*;
use nalgebra::{Isometry3, Vector3};
use serde_json::{Value, json};
/// The fields every instrument's record shares ([`InstrumentRecord::reading`]):
/// where the machine stood, the row's standard deviation, the setup, the
/// temperature and the line in its file.
///
/// # Example
/// ```
/// use tricept_ident::simulate::{InstrumentRecord, TouchReading, TrackerPoint};
/// let point = TrackerPoint { setup: 2, temp_c: Some(20.5), line: 7, ..Default::default() };
/// let common = point.reading();
/// assert_eq!((common.setup, common.temp_c, common.line), (Some(2), Some(20.5), 7));
/// let touch = TouchReading { line: 3, ..Default::default() };
/// assert_eq!((touch.reading().setup, touch.reading().line), (None, 3)); // no setups
/// ```
#[doc(inline)]
pub use tricept_data::external::InstrumentRecord;
use tricept_data::{Dataset, external::PlannedPose, external::read_external_path};
use tricept_engine::model::GeometricModel;
use tricept_kinematics::Machine;
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_model::{ParameterSet, head_errors::HeadParameterSet};
use tricept_plant::{
    Campaign, Effect, Plant, PlantError, campaign::PoseOrder, instruments::Ballbar,
    instruments::TouchFeature, instruments::TouchProbe, instruments::TouchTarget,
    instruments::Tracker,
};

use crate::Setting;
use crate::error::{EXIT_OK, Error};
use crate::inputs::{Poses, TrueErrors, positive, random_spec};
use crate::machine_input::MachineInput;

/// Head errors of a simulated machine (`--head-errors`): `zero`,
/// `random:SCALE[,SEED]` (each of the 13 parameters SCALE times its
/// typical size, times 0.5-1, random sign), or a JSON file `{name: value}`.
///
/// # Example
/// ```
/// let h: tricept_ident::simulate::HeadErrors = "random:1,3".parse().unwrap();
/// assert_eq!(h.to_string(), "random:1,3");
/// assert!("random:x".parse::<tricept_ident::simulate::HeadErrors>().is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum HeadErrors {
    /// No head error.
    Zero,
    /// Random errors of `scale` times the typical sizes, drawn from `seed`.
    Random {
        /// Multiple of the typical sizes, 0 to 100.
        scale: f64,
        /// Seed of the draw.
        seed: u64,
    },
    /// A JSON file of the head parameters' values.
    File(PathBuf),
}

impl FromStr for HeadErrors {
    type Err = Error;

    fn from_str(s: &str) -> Result<HeadErrors, Error> {
        Ok(match s {
            "zero" => HeadErrors::Zero,
            s if s.starts_with("random:") => {
                let (scale, seed) = random_spec(
                    Setting::HeadErrors,
                    s,
                    100.0,
                    "random:SCALE[,SEED] with SCALE (times the typical sizes) from 0 to 100",
                )?;
                HeadErrors::Random { scale, seed }
            }
            path => HeadErrors::File(PathBuf::from(path)),
        })
    }
}

impl fmt::Display for HeadErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HeadErrors::Zero => f.write_str("zero"),
            HeadErrors::Random { scale, seed } => write!(f, "random:{scale},{seed}"),
            HeadErrors::File(p) => write!(f, "{}", p.display()),
        }
    }
}

impl HeadErrors {
    /// The values of the head's 13 parameters on `machine` (empty: zero).
    pub fn values(&self, machine: &Machine) -> Result<Vec<f64>, Error> {
        match self {
            HeadErrors::Zero => Ok(Vec::new()),
            HeadErrors::Random { scale, seed } => {
                Ok(tricept_plant::random_head_errors(*scale, *seed))
            }
            HeadErrors::File(path) => {
                let name = path.display();
                let text = tricept_data::bounded::read_json_text(path)
                    .map_err(|e| Error::unreadable(&name, e).in_setting(Setting::HeadErrors))?;
                HeadParameterSet::head13(&machine.head)
                    .parse_values(&text)
                    .map_err(|e| Error::invalid(Setting::HeadErrors, format!("{name}: {e}")))
            }
        }
    }
}

/// One `--truth-effect` value: a JSON object or an array of them, inline
/// or from `@FILE`, each effect validated ([`crate::parse_effects`]); a
/// typed flag value.
///
/// # Example
/// ```
/// let t: tricept_ident::simulate::TruthEffects = r#"{"effect":"leg-lead","ppm":[50,-30,40]}"#.parse().unwrap();
/// assert_eq!(t.effects().len(), 1);
/// assert!(t.to_string().starts_with("{"));
/// assert!(r#"{"effect":"nothing"}"#.parse::<tricept_ident::simulate::TruthEffects>().is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TruthEffects {
    spec: String,
    effects: Vec<Effect>,
}

impl FromStr for TruthEffects {
    type Err = Error;

    fn from_str(spec: &str) -> Result<TruthEffects, Error> {
        Ok(TruthEffects {
            spec: spec.to_string(),
            effects: crate::parse_effects(&[spec.to_string()])?,
        })
    }
}

impl fmt::Display for TruthEffects {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.spec)
    }
}

impl TruthEffects {
    /// The effects, validated.
    pub fn effects(&self) -> &[Effect] {
        &self.effects
    }
}

/// A laser tracker measuring the simulated machine at planned poses.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::simulate::{SimulateRequest, TrackerSimulation};
/// let mut request = SimulateRequest::new();
/// request.tracker = Some(TrackerSimulation {
///     poses: "tracker-poses.csv".into(),
///     frame_mm_rad: [0.0; 6],
///     target_mm: [0.0, 0.0, 120.0],
///     sigma_um: 5.0,
/// });
/// assert!(request.tracker.is_some());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TrackerSimulation {
    /// Poses (CSV `q1,q2,q3,h1,h2[,extension_mm]`, as `tricept plan --out`
    /// writes them).
    pub poses: PathBuf,
    /// Translation (mm) and rotation vector (rad) mapping the machine's
    /// base frame into the tracker's.
    pub frame_mm_rad: [f64; 6],
    /// The target's offset from the tool tip, mm.
    pub target_mm: [f64; 3],
    /// Noise of a coordinate, um.
    pub sigma_um: f64,
}

/// A ballbar read at planned poses.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::simulate::{SimulateRequest, BallbarSimulation};
/// let mut request = SimulateRequest::new();
/// request.ballbar = Some(BallbarSimulation {
///     poses: "ballbar-poses.csv".into(),
///     pivot_mm: [0.0, 0.0, 600.0],
///     length_error_um: 0.0,
///     sigma_um: 1.0,
/// });
/// assert!(request.ballbar.is_some());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct BallbarSimulation {
    /// Poses (CSV `q1,q2,q3,h1,h2`).
    pub poses: PathBuf,
    /// The pivot on the table, mm.
    pub pivot_mm: [f64; 3],
    /// The bar's reading minus the true distance, um.
    pub length_error_um: f64,
    /// Noise of a reading, um.
    pub sigma_um: f64,
}

/// A touch probe touching a reference sphere (feature 1) at planned
/// touches.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::simulate::{SimulateRequest, TouchSimulation};
/// let mut request = SimulateRequest::new();
/// request.touch = Some(TouchSimulation {
///     poses: "touch-poses.csv".into(),
///     sphere_mm: [0.0, 0.0, 700.0],
///     sphere_radius_mm: 12.5,
///     stylus_radius_mm: 1.5,
///     stylus_sigma_um: 1.0,
///     stylus_error_um: 0.0,
///     sigma_um: 1.0,
/// });
/// assert!(request.touch.is_some());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TouchSimulation {
    /// Planned touches (CSV `q1,q2,q3,h1,h2,x,y,z,feature`).
    pub poses: PathBuf,
    /// The sphere's true centre, mm.
    pub sphere_mm: [f64; 3],
    /// The sphere's radius, mm.
    pub sphere_radius_mm: f64,
    /// The stylus' nominal radius, mm.
    pub stylus_radius_mm: f64,
    /// Standard deviation of the stylus radius, um.
    pub stylus_sigma_um: f64,
    /// The stylus' true radius minus the nominal one, um.
    pub stylus_error_um: f64,
    /// Noise of a touch along the surface normal, um.
    pub sigma_um: f64,
}

/// What to simulate.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::simulate::{SimulateRequest, simulate};
/// let request = SimulateRequest::new()
///     .machine(MachineInput::default())
///     .poses("random:25,1".parse()?)
///     .seed(2);
/// let sim = simulate(request)?;
/// assert_eq!(sim.data().poses.len(), 25);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct SimulateRequest {
    /// The nominal machine and its stated sensor noise.
    pub machine: MachineInput,
    /// The parameter set of the true errors.
    pub parameter_set: ParameterSet,
    /// True geometric errors (default: Table 2).
    pub truth: TrueErrors,
    /// Unmodelled effects of the true machine.
    pub truth_effects: Vec<Effect>,
    /// Head errors of the true machine.
    pub head_errors: HeadErrors,
    /// The campaign's poses.
    pub poses: Poses,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// Visit every pose twice, approaching from both directions.
    pub both_directions: bool,
    /// Revisit the first N targets at the end of the campaign.
    pub revisit: usize,
    /// The true noise as a multiple of the stated noise.
    pub noise_factor: f64,
    /// A laser tracker's points too.
    pub tracker: Option<TrackerSimulation>,
    /// A ballbar's readings too.
    pub ballbar: Option<BallbarSimulation>,
    /// Touch-offs too.
    pub touch: Option<TouchSimulation>,
    /// The file the caller writes the data to
    /// ([`crate::advanced::files::write_path`]), named by the report and
    /// the JSON (default: none, the data stay in memory).
    pub out: Option<PathBuf>,
}

impl SimulateRequest {
    /// Table 2 errors on the Table 1 machine, the `grid` pose set, seed 1,
    /// the stated noise, no effect and no external instrument.
    pub fn new() -> SimulateRequest {
        SimulateRequest {
            machine: MachineInput::default(),
            parameter_set: ParameterSet::paper15(),
            truth: TrueErrors::Table2,
            truth_effects: Vec::new(),
            head_errors: HeadErrors::Zero,
            poses: Poses::grid(),
            seed: 1,
            both_directions: false,
            revisit: 0,
            noise_factor: 1.0,
            tracker: None,
            ballbar: None,
            touch: None,
            out: None,
        }
    }
}

impl Default for SimulateRequest {
    /// [`SimulateRequest::new`].
    fn default() -> SimulateRequest {
        SimulateRequest::new()
    }
}

crate::request::setters!(SimulateRequest {
    machine: into MachineInput,
    parameter_set: ParameterSet,
    truth: TrueErrors,
    truth_effects: Vec<Effect>,
    head_errors: HeadErrors,
    poses: Poses,
    seed: u64,
    both_directions: bool,
    revisit: usize,
    noise_factor: f64,
    tracker: some TrackerSimulation,
    ballbar: some BallbarSimulation,
    touch: some TouchSimulation,
    out: some into PathBuf,
});

/// Simulated data in memory, each with the comment lines its file carries.
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::simulate::{SimulateRequest, simulate};
/// let mut request = SimulateRequest::new();
/// request.poses = "random:12,7".parse()?;
/// let sim = simulate(request)?;
/// assert_eq!(sim.data().poses.len(), 12);
/// assert!(sim.tracker().is_none() && sim.ballbar().is_none() && sim.touch().is_none());
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Simulation {
    data: Dataset,
    comments: Vec<String>,
    tracker: Option<(TrackerData, Vec<String>)>,
    ballbar: Option<(BallbarData, Vec<String>)>,
    touch: Option<(TouchData, Vec<String>, String)>,
    summary: Value,
    truth: String,
    out: Option<PathBuf>,
}

crate::outcome::outcome!(Simulation);

/// Simulates the request's campaign (and instruments); every problem of
/// the request is an input error (exit code 2).
///
/// # Example
/// ```
/// use tricept_ident::MachineInput;
/// use tricept_ident::simulate::{SimulateRequest, simulate};
/// let sim = simulate(SimulateRequest::new())?;
/// assert!(!sim.data().poses.is_empty());
/// assert_eq!(sim.exit_code(), tricept_ident::EXIT_OK);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
pub fn simulate(request: SimulateRequest) -> Result<Simulation, Error> {
    let loaded = request.machine.clone().load()?;
    let m = loaded.machine();
    let set = &request.parameter_set;
    let values = request.truth.values(set)?;
    let targets = request.poses.targets(m)?;
    let mut campaign = Campaign::from_targets(m, targets, request.seed);
    if request.both_directions {
        campaign.order = PoseOrder::BothDirections;
    }
    let factor = request.noise_factor;
    if !(factor.is_finite() && factor > 0.0) {
        return Err(Error::invalid(
            Setting::NoiseFactor,
            format!("must be a positive number, got {factor}"),
        ));
    }
    campaign.revisits = request.revisit;
    campaign.noise_factor = factor;
    let mut plant = Plant::geometric(m.clone(), set.to_errors(&values));
    plant.effects = request.truth_effects.clone();
    plant.head_errors = request.head_errors.values(m)?;
    let data = plant.simulate(&campaign).map_err(failed)?;
    let comments = comments(&request, m, &plant, &values, data.poses.len());
    let truth_mm = Value::Object(set.values_to_map(&values));
    let summary = json!({
        "poses": data.poses.len(),
        "seed": request.seed,
        "machine": m.name,
        "parameter_set": set.label(),
        "truth_mm": truth_mm,
        "truth_effects": plant.effects,
        "sensor_offsets": {"phi_rad": plant.sensor_offsets[0], "theta_rad": plant.sensor_offsets[1], "s_mm": plant.sensor_offsets[2]},
    });
    let tracker = match &request.tracker {
        Some(t) => Some(simulate_tracker(t, &plant, &comments, request.seed)?),
        None => None,
    };
    let ballbar = match &request.ballbar {
        Some(b) => Some(simulate_ballbar(b, &plant, &comments, request.seed)?),
        None => None,
    };
    let touch = match &request.touch {
        Some(t) => Some(simulate_touches(t, &plant, &comments, request.seed)?),
        None => None,
    };
    Ok(Simulation {
        data,
        comments,
        tracker,
        ballbar,
        touch,
        summary,
        truth: truth_label(&request.truth),
        out: request.out.clone(),
    })
}

/// A failed simulation: an input error.
fn failed(e: PlantError) -> Error {
    Error::input(format!("simulate: {e}"))
}

/// The label of the true errors, as `--truth` takes it.
fn truth_label(t: &TrueErrors) -> String {
    match t {
        TrueErrors::Table2 => "table2".into(),
        TrueErrors::Zero => "zero".into(),
        TrueErrors::Random { magnitude_mm, seed } => format!("random:{magnitude_mm},{seed}"),
        TrueErrors::File(p) => p.display().to_string(),
    }
}

/// Numbers as a flag takes them: `a,b,c`.
fn joined(v: &[f64]) -> String {
    v.iter().map(f64::to_string).collect::<Vec<_>>().join(",")
}

/// The comment lines of the simulated data file: who simulated what.
fn comments(
    r: &SimulateRequest,
    m: &Machine,
    plant: &Plant,
    values: &[f64],
    poses: usize,
) -> Vec<String> {
    let set = &r.parameter_set;
    let model = GeometricModel::new(m.clone(), set.clone());
    let mut comments = vec![
        format!(
            "simulated by tricept {} on `{}`",
            env!("CARGO_PKG_VERSION"),
            m.name
        ),
        format!(
            "pose set `{}` ({} poses{}{}), seed {}",
            r.poses,
            poses,
            if r.both_directions {
                ", both approach directions"
            } else {
                ""
            },
            if r.revisit > 0 {
                format!(", the first {} revisited at the end", r.revisit)
            } else {
                String::new()
            },
            r.seed
        ),
        format!(
            "noise per reading: {:.3} arcsec, {:.3} um, mean of {}{}",
            m.sensors.angle_rad / RAD_PER_ARCSEC,
            m.sensors.length_mm * 1e3,
            m.sensors.readings_per_pose,
            if r.noise_factor == 1.0 {
                String::new()
            } else {
                format!(" (stated; the true noise is {} times it)", r.noise_factor)
            }
        ),
        format!(
            "true errors ({}, mm): {}",
            model.parameter_set().label(),
            Value::Object(set.values_to_map(values))
        ),
        format!(
            "sensor zero offsets (phi rad, theta rad, s mm): {:?}",
            plant.sensor_offsets
        ),
    ];
    for e in &plant.effects {
        comments.push(format!(
            "effect: {}",
            serde_json::to_string(e).unwrap_or_default()
        ));
    }
    if !plant.head_errors.is_empty() {
        comments.push(format!(
            "head errors (head13): {}",
            Value::Object(HeadParameterSet::head13(&m.head).values_to_map(&plant.head_errors))
        ));
    }
    comments
}

/// The poses of a poses file (every record with its extension).
fn read_poses(path: &Path) -> Result<Vec<(ExternalPose, f64)>, Error> {
    Ok(read_external_path::<PlannedPose>(path)
        .map_err(|e| Error::input(e.to_string()))?
        .records
        .iter()
        .map(|p| (p.pose, p.extension_mm))
        .collect())
}

/// A tracker's points at its poses.
fn simulate_tracker(
    t: &TrackerSimulation,
    plant: &Plant,
    comments: &[String],
    seed: u64,
) -> Result<(TrackerData, Vec<String>), Error> {
    let f = t.frame_mm_rad;
    let tracker = Tracker {
        frame: Isometry3::new(
            Vector3::new(f[0], f[1], f[2]),
            Vector3::new(f[3], f[4], f[5]),
        ),
        target_offset_mm: Vector3::from(t.target_mm),
        sigma_um: positive(Setting::TrackerSigmaUm, t.sigma_um)?,
        setup: 1,
    };
    let data = tracker
        .measure(plant, &read_poses(&t.poses)?, seed)
        .map_err(failed)?;
    let mut c = comments.to_vec();
    c.push(format!(
        "tracker: frame (mm, rad) {}, target offset (mm) {}, {} um per coordinate",
        joined(&t.frame_mm_rad),
        joined(&t.target_mm),
        t.sigma_um
    ));
    Ok((data, c))
}

/// A ballbar's readings at its poses.
fn simulate_ballbar(
    b: &BallbarSimulation,
    plant: &Plant,
    comments: &[String],
    seed: u64,
) -> Result<(BallbarData, Vec<String>), Error> {
    let bar = Ballbar {
        pivot_mm: Vector3::from(b.pivot_mm),
        length_error_um: b.length_error_um,
        ball_offset_mm: Vector3::zeros(),
        sigma_um: positive(Setting::BallbarSigmaUm, b.sigma_um)?,
        setup: 1,
    };
    let poses: Vec<_> = read_poses(&b.poses)?.into_iter().map(|(p, _)| p).collect();
    let data = bar.measure(plant, &poses, seed).map_err(failed)?;
    let mut c = comments.to_vec();
    c.push(format!(
        "ballbar: pivot (mm) {}, length error {} um, {} um per reading",
        joined(&b.pivot_mm),
        b.length_error_um,
        b.sigma_um
    ));
    Ok((data, c))
}

/// Touch-offs on the reference sphere at the planned touches, and the
/// features file a user would write (JSON).
fn simulate_touches(
    t: &TouchSimulation,
    plant: &Plant,
    comments: &[String],
    seed: u64,
) -> Result<(TouchData, Vec<String>, String), Error> {
    let centre = Vector3::from(t.sphere_mm);
    let probe = TouchProbe {
        stylus_radius_mm: positive(Setting::TouchStylusRadiusMm, t.stylus_radius_mm)?,
        stylus_radius_error_um: t.stylus_error_um,
        stylus_radius_sigma_um: positive(Setting::TouchStylusSigmaUm, t.stylus_sigma_um)?,
        sigma_um: positive(Setting::TouchSigmaUm, t.sigma_um)?,
        features: vec![TouchFeature::Sphere {
            id: 1,
            centre_mm: centre,
            radius_mm: positive(Setting::TouchSphereRadiusMm, t.sphere_radius_mm)?,
        }],
    };
    let planned =
        read_external_path::<PlannedPose>(&t.poses).map_err(|e| Error::input(e.to_string()))?;
    let nominal = &plant.nominal;
    let targets = planned
        .records
        .iter()
        .map(|p| {
            let at = |e: tricept_kinematics::KinematicsError| {
                Error::input(format!("{}: line {}: {e}", planned.source, p.line))
            };
            if p.feature.is_some_and(|f| f != 1) {
                return Err(Error::input(format!(
                    "{}: line {}, column `feature`: the simulated probe touches sphere 1 only",
                    planned.source, p.line
                )));
            }
            let up = nominal.forward(&p.pose.commands_mm).map_err(at)?.up;
            let tool = nominal.tool_forward(&up, p.pose.head_rad);
            Ok(TouchTarget {
                feature: 1,
                tip_mm: tool.tip_mm,
                axis: tool.axis,
                approach: (centre - tool.tip_mm).normalize(),
            })
        })
        .collect::<Result<Vec<_>, Error>>()?;
    let data = probe
        .measure(plant, &targets, seed)
        .map_err(|e| Error::input(format!("simulate: {}: {e}", planned.source)))?;
    let mut c = comments.to_vec();
    c.push(format!(
        "touch probe: sphere 1 at (mm) {}, radius {} mm; stylus {} mm ({} um off); {} um per touch",
        joined(&t.sphere_mm),
        t.sphere_radius_mm,
        t.stylus_radius_mm,
        t.stylus_error_um,
        t.sigma_um
    ));
    let features = serde_json::to_string_pretty(&probe.features_file(0.5))
        .map_err(|e| Error::other(e.to_string()))?;
    Ok((data, c, features + "\n"))
}

impl Simulation {
    /// The measured data of the UP limb's sensors.
    pub fn data(&self) -> &Dataset {
        &self.data
    }

    /// The data file's comment lines (what was simulated).
    pub fn comments(&self) -> &[String] {
        &self.comments
    }

    /// The tracker's points and their file's comments, when asked for.
    pub fn tracker(&self) -> Option<(&TrackerData, &[String])> {
        self.tracker.as_ref().map(|(d, c)| (d, c.as_slice()))
    }

    /// The ballbar's readings and their file's comments, when asked for.
    pub fn ballbar(&self) -> Option<(&BallbarData, &[String])> {
        self.ballbar.as_ref().map(|(d, c)| (d, c.as_slice()))
    }

    /// The touch-offs, their file's comments and the features file (JSON
    /// text), when asked for.
    pub fn touch(&self) -> Option<(&TouchData, &[String], &str)> {
        self.touch
            .as_ref()
            .map(|(d, c, f)| (d, c.as_slice(), f.as_str()))
    }

    /// Always 0: a simulation has no verdict.
    pub fn exit_code(&self) -> u8 {
        EXIT_OK
    }

    /// Always `None`: a simulation has no verdict.
    pub fn reason(&self) -> Option<&str> {
        None
    }

    /// The summary as JSON (what `tricept simulate --json --out FILE`
    /// prints, `format_version` first), naming the data file of the
    /// request's `out` (`null` without one).
    pub fn to_json(&self) -> Value {
        let out = self.out.as_ref().map(|p| p.display().to_string());
        let mut v = json!({"out": out});
        if let (Value::Object(o), Value::Object(s)) = (&mut v, &self.summary) {
            o.extend(s.clone());
        }
        crate::outcome::versioned(v)
    }

    /// The summary as text (what `tricept simulate --out FILE` prints on
    /// stderr), naming the data file of the request's `out`.
    pub fn report(&self) -> String {
        let to = match &self.out {
            Some(out) => format!("to {}", out.display()),
            None => "in memory".to_string(),
        };
        format!(
            "{} poses {to} (machine `{}`, true errors `{}`, {} effect(s), seed {})",
            self.data.poses.len(),
            self.summary["machine"].as_str().unwrap_or_default(),
            self.truth,
            self.summary["truth_effects"].as_array().map_or(0, Vec::len),
            self.summary["seed"]
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::{SensorNoise, load_machine};

    fn request() -> SimulateRequest {
        SimulateRequest::new().machine(load_machine(None, &SensorNoise::default()).unwrap())
    }

    #[test]
    fn head_errors_parse_and_print_back() {
        for spec in ["zero", "random:1,3", "random:0.5,0", "head.json"] {
            let h: HeadErrors = spec.parse().unwrap();
            assert_eq!(h.to_string(), spec);
        }
        for bad in ["random:x", "random:101", "random:1,y"] {
            let e = bad.parse::<HeadErrors>().unwrap_err();
            assert!(
                e.message().starts_with("head_errors `")
                    && e.setting() == Some(Setting::HeadErrors),
                "{}",
                e.message()
            );
        }
    }

    #[test]
    fn the_default_campaign_is_the_grid_and_a_seed_reproduces_it() {
        let a = simulate(request()).unwrap();
        assert_eq!(a.data().poses.len(), 75);
        assert!(a.comments()[1].starts_with("pose set `grid` (75 poses)"));
        let b = simulate(request()).unwrap();
        assert_eq!(a.data(), b.data());
        let mut other = request();
        other.seed = 2;
        assert_ne!(a.data(), simulate(other).unwrap().data());
        assert_eq!(a.to_json()["out"], Value::Null);
        assert!(a.report().starts_with("75 poses in memory"));
        let mut named = request();
        named.out = Some("d.csv".into());
        let named = simulate(named).unwrap();
        let v = named.to_json();
        assert_eq!(v["out"], "d.csv");
        assert_eq!(v["poses"], 75);
        assert!(named.report().contains("poses to d.csv"));
        assert!(named.report().contains("true errors `table2`"));
    }

    #[test]
    fn a_bad_noise_factor_is_an_input_error() {
        let mut r = request();
        r.noise_factor = 0.0;
        let e = simulate(r).unwrap_err();
        assert_eq!(e.exit_code(), crate::EXIT_INPUT);
        assert_eq!(e.setting(), Some(Setting::NoiseFactor));
    }
}
