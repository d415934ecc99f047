//! What the registry says about an effect, once ([`EffectSpec`]), in the
//! types the simulator's tests, the diagnosis, the fused identification,
//! the calibration record and the CLI share: its parameters, how they enter
//! a model ([`Kind`]), what the data must log ([`Needs`]), where a fitted
//! value goes in a machine file ([`Deployment`]), its physical ranges
//! ([`Judged`]), its words and its residual plot ([`PlotAxes`]).
//!
//! A term linear in its parameters says what one unit of each parameter
//! adds to a leg length or a reading at a pose: a list of
//! `(parameter, Basis, value)` entries, the same interface for the effects
//! of the vocabulary and the generic terms of the diagnosis' dictionary.

use nalgebra::DMatrix;
use tricept_kinematics::description::{ControllerDescription, LegEffectsDescription};
use tricept_kinematics::{KinematicsError, Machine, up_limb::UpJoints};

use super::forms::{legendre_p2, legendre_p3};
use super::simulation::Simulation;

/// An effect of the vocabulary.
#[derive(Debug, Clone, Copy)]
pub struct EffectSpec {
    /// The report name (`leg-lead`): the `serde` name of its
    /// `EffectName` and the prefix of its parameters in a model
    /// (`leg-lead.lead1_ppm`).
    pub name: &'static str,
    /// Its physics in one phrase (the vocabulary's table, the CLI help).
    pub physics: &'static str,
    /// The unit a machine builder quotes it in.
    pub quoted_in: &'static str,
    /// Its parameters in a model, in order.
    pub parameters: &'static [Parameter],
    /// How the parameters enter the reading model.
    pub kind: Kind,
    /// What the data must log for the effect to be seen.
    pub needs: Needs,
    /// Where a fitted value goes in a calibrated machine file.
    pub deployment: Deployment,
    /// Whether the fused identification with external measurements
    /// (`tricept_engine::fusion`) can carry it: a [`Kind::Leg`] or
    /// [`Kind::Reading`] term that needs no logged context
    /// ([`Needs::Nothing`]), whose entries the fused model takes as its
    /// columns (a test of the registry checks that).
    pub fused: bool,
    /// Its physical ranges (the diagnosis' plausibility table).
    pub plausible: &'static [Judged],
    /// What a named cause is, in words a machine builder can act on (the
    /// diagnosis prints it before the estimates).
    pub description: &'static str,
    /// The axes of its residual plot.
    pub plot: PlotAxes,
    /// Realistic magnitudes in the model's parameterisation, at which the
    /// detectability of a campaign is analysed.
    pub realistic: fn(&Machine) -> Vec<Magnitude>,
    /// Effects it is known to be confused with, and what separates them.
    pub aliases: &'static [KnownAlias],
    /// How the plant simulator puts it into a machine.
    pub simulation: Simulation,
    /// Its common part, for an effect with one parameter per leg whose
    /// equal value on every leg is an alternative of its own.
    pub common_part: Option<CommonPart>,
    /// Whether `tricept check` considers it a candidate change, and how.
    pub check: Option<CheckRole>,
}

/// How `tricept check` considers an effect (or a generic family) as a
/// candidate change between a calibration and a check.
#[derive(Debug, Clone, Copy)]
pub struct CheckRole {
    /// Its name in a check's report (`scale gain`).
    pub name: &'static str,
    /// Its parameters in the check, units in the names.
    pub parameters: &'static [&'static str],
    /// When it is a candidate.
    pub when: CheckWhen,
    /// What one unit of each parameter changes at a pose.
    pub columns: CheckColumns,
}

/// When a [`CheckRole`] is a candidate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckWhen {
    /// Always.
    Always,
    /// When both the check and the calibration logged a temperature.
    WithTemperatures,
    /// When they did not both log one.
    WithoutTemperatures,
}

/// What one unit of a [`CheckRole`]'s parameters changes at a pose.
#[derive(Debug, Clone, Copy)]
pub enum CheckColumns {
    /// Every leg's length (one parameter), mm per unit, from the leg's
    /// command (mm) and the temperature since the calibration (K; 0 when
    /// not both logged one): it moves the platform.
    Legs(fn(f64, f64) -> f64),
    /// The readings, linearly in the parameters: the entries with the UP
    /// limb at its predicted joints ([`Basis::Reading`] only); the sensor,
    /// not the machine.
    Readings(fn(&UpJoints) -> Entries),
}

/// A parameter of an effect in a model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parameter {
    /// Its name, unit in the name (`lead1_ppm`).
    pub name: &'static str,
    /// The unit (`ppm`).
    pub unit: &'static str,
    /// Its typical size as machines are built, in `unit`: the scale of
    /// priors and of invisible combinations.
    pub typical: f64,
}

impl std::fmt::Display for Parameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// A realistic magnitude of an effect: its parameter values and a label
/// (`50 ppm`).
#[derive(Debug, Clone, PartialEq)]
pub struct Magnitude {
    /// Values of the parameters, in order and in their units.
    pub values: Vec<f64>,
    /// What the values mean for a machine builder.
    pub label: &'static str,
}

/// Where one unit of a parameter goes: onto a leg length (`Leg(i)`, mm per
/// unit) or a reading (`Reading(c)`, rad or mm per unit; `c` 0 `phi`, 1
/// `theta`, 2 `s`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// Leg `i` (0-2).
    Leg(usize),
    /// Reading channel `c` (0-2).
    Reading(usize),
}

/// `(parameter, basis, value)`: per unit of the term's parameter
/// `parameter`, `value` is added to `basis`. A parameter may have several
/// entries (a thermal expansion lengthens all three legs).
pub type Entries = Vec<(usize, Basis, f64)>;

/// What a leg effect's entries may depend on at one pose.
#[derive(Debug, Clone, Copy)]
pub struct LegContext<'a> {
    /// The nominal machine (the gravity load is evaluated on it at the
    /// commands).
    pub nominal: &'a Machine,
    /// The commanded leg lengths, mm.
    pub commands_mm: [f64; 3],
    /// The sign of each leg's last motion, when logged.
    pub approach: Option<[i8; 3]>,
    /// The logged structure temperature, °C.
    pub temperature_c: Option<f64>,
}

/// How an effect's parameters enter the reading model.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// It changes the actual leg lengths, linearly in its parameters: the
    /// entries at a pose ([`Basis::Leg`] only).
    Leg(fn(&LegContext<'_>) -> Result<Entries, KinematicsError>),
    /// It changes the readings, linearly in its parameters: the entries
    /// with the UP limb at its actual joints ([`Basis::Reading`] only).
    Reading(fn(&UpJoints) -> Entries),
    /// It changes the UP limb's kinematics (class 2), not linearly: adds the
    /// parameters' errors to a machine.
    Kinematic(fn(&mut Machine, &[f64])),
    /// Gross errors of a few rows: screened row by row, never a term of a
    /// model.
    Rows,
}

impl Kind {
    /// `leg`, `reading`, `kinematic` or `rows`.
    pub fn label(&self) -> &'static str {
        match self {
            Kind::Leg(_) => "leg",
            Kind::Reading(_) => "reading",
            Kind::Kinematic(_) => "kinematic",
            Kind::Rows => "rows",
        }
    }
}

/// What a campaign must log (and vary) for a term to be seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Needs {
    /// The commands and readings alone.
    Nothing,
    /// A structure temperature that changes during the campaign (`temp_c`).
    Temperature,
    /// Each leg's approach direction, some leg approached from both sides
    /// (`dir1,dir2,dir3`).
    ApproachDirections,
    /// The order of the poses in time (`time_s`, or distinct file lines).
    PoseOrder,
    /// The direction each sensor moved since the previous pose (from the
    /// order of distinct file lines).
    SensorDirections,
    /// Every leg moving by more than 1 mm over the campaign.
    LegStrokes,
    /// The UP limb extending by more than 1 mm over the campaign.
    ScaleStroke,
}

impl Needs {
    /// The data columns it needs, if any.
    pub fn columns(self) -> Option<&'static str> {
        match self {
            Needs::Temperature => Some("temp_c"),
            Needs::ApproachDirections => Some("dir1,dir2,dir3"),
            Needs::PoseOrder => Some("time_s (or distinct line numbers)"),
            Needs::SensorDirections => Some("distinct line numbers"),
            Needs::Nothing | Needs::LegStrokes | Needs::ScaleStroke => None,
        }
    }

    /// What to log when a campaign cannot see the term.
    pub fn advice(self) -> Option<&'static str> {
        match self {
            Needs::ApproachDirections => {
                Some("visit poses from both approach directions (both_directions)")
            }
            Needs::Temperature => Some("log the structure temperature while it changes"),
            Needs::PoseOrder => Some("log the time of every pose"),
            Needs::Nothing | Needs::SensorDirections | Needs::LegStrokes | Needs::ScaleStroke => {
                None
            }
        }
    }

    /// Whether the term follows the campaign's clock: a temperature that
    /// rises while the campaign runs makes a change with temperature and a
    /// drift with time look alike.
    pub fn follows_time(self) -> bool {
        matches!(self, Needs::Temperature | Needs::PoseOrder)
    }
}

/// Where a fitted parameter goes in a calibrated machine file.
#[derive(Debug, Clone, Copy)]
pub enum Deployment {
    /// Static leg effects (`leg_effects`), applied by `ik`, `fk`,
    /// `tool-ik` and `compensate` ([`crate::ExtendedMachine`]).
    LegEffects(LegDeployment),
    /// Controller parameters (`controller`): dynamic effects that depend on
    /// the approach direction or the temperature, which the controller
    /// knows. Sets parameter `index` to `value`.
    Controller(fn(&mut ControllerDescription, usize, f64)),
    /// The UP limb's description: the model's machine carries it already.
    UpLimb,
    /// Sensor side: it changes the readings, not where the platform goes;
    /// recorded under `calibration.effects` only.
    Sensor,
    /// Rows set aside, not a parameter of a machine.
    SetAside,
    /// A leg error that is a function of the leg command (the generic
    /// periodic and polynomial leg terms): tabulated per leg in the
    /// machine's compensation tables (`leg_effects.tables`), applied by
    /// `ik`, `fk`, `tool-ik` and `compensate`.
    LegTable,
    /// A time term (legs drifting over the campaign): recorded under
    /// `calibration.effects` with the state it describes (the geometry is
    /// the machine's at the campaign's middle), not applied.
    Recorded,
}

impl Deployment {
    /// Where it goes, in words (the CLI help).
    pub fn label(&self) -> &'static str {
        match self {
            Deployment::LegEffects(_) => {
                "the machine's leg effects (applied by ik, fk, tool-ik and compensate)"
            }
            Deployment::Controller(_) => "controller parameters",
            Deployment::UpLimb => "the UP limb's description",
            Deployment::Sensor => "sensor side: recorded under calibration.effects",
            Deployment::SetAside => "set aside (not written)",
            Deployment::LegTable => {
                "per-leg compensation tables (leg_effects.tables, applied by ik, fk, tool-ik and compensate)"
            }
            Deployment::Recorded => {
                "a time term: recorded under calibration.effects with the campaign's middle, not applied"
            }
        }
    }
}

/// A static leg effect in a machine file.
#[derive(Debug, Clone, Copy)]
pub struct LegDeployment {
    /// Sets parameter `index` to `value` in the machine's leg effects.
    pub set: fn(&mut LegEffectsDescription, usize, f64),
    /// The extra length per mm of command of each leg (mm/mm) from the
    /// machine's leg effects with the UP limb at `up`; `None` when the
    /// effect is absent, or needs the pose and `up` is `None`.
    pub rate: fn(&Machine, Option<&UpJoints>) -> Option<[f64; 3]>,
}

/// A plausible range of a physical quantity, with its reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlausibleRange {
    /// The quantity (`lead_ppm`): the table key is `effect.quantity`.
    pub quantity: &'static str,
    /// Smallest plausible value.
    pub min: f64,
    /// Largest plausible value.
    pub max: f64,
    /// Unit.
    pub unit: &'static str,
    /// Why (material, tolerance, definition).
    pub why: &'static str,
    /// What a value outside the range whose negation lies inside it most
    /// likely means, when a sign convention of the data can flip it (empty:
    /// nothing is known, and the real cause is something else).
    pub if_negated: &'static str,
}

impl PlausibleRange {
    /// As a table entry (`tricept_model::plausibility::Range`).
    pub fn to_range(&self) -> crate::plausibility::Range {
        crate::plausibility::Range {
            min: self.min,
            max: self.max,
            unit: self.unit,
            why: self.why.to_string(),
        }
    }
}

/// Quantities of an effect judged by one range: each is a measure of the
/// fitted parameters with a label for messages (empty: the parameter's
/// name).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Judged {
    /// The range.
    pub range: PlausibleRange,
    /// The quantities it judges.
    pub of: &'static [(Measure, &'static str)],
}

/// A physical quantity computed from a term's fitted parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measure {
    /// Parameter `i` itself.
    Parameter(usize),
    /// The amplitude `sqrt(a^2 + b^2)` of a sine and cosine pair.
    Amplitude(usize, usize),
    /// The peak-to-valley over `[-1, 1]` of `a P2(x) + b P3(x)`.
    PeakToValley(usize, usize),
    /// A value known exactly (the period of a periodic term).
    Exact(f64),
}

impl Measure {
    /// The quantity and its standard deviation (delta method) for
    /// parameters `v` with covariance `cov` (missing entries count as 0).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use nalgebra::DMatrix;
use tricept_model::effects::Measure;
let cov = DMatrix::identity(2, 2);
let (a, sd) = Measure::Amplitude(0, 1).evaluate(&[3.0, 4.0], &cov);
assert!((a - 5.0).abs() < 1e-12 && (sd - 1.0).abs() < 1e-12);
// P2 alone: from -1/2 at 0 to 1 at +-1.
assert!((Measure::PeakToValley(0, 1).evaluate(&[2.0, 0.0], &cov).0 - 3.0).abs() < 1e-9);
```
"#
    )]
    pub fn evaluate(&self, v: &[f64], cov: &DMatrix<f64>) -> (f64, f64) {
        let c = |i: usize, j: usize| cov.get((i, j)).copied().unwrap_or(0.0);
        let value = |i: usize| v.get(i).copied().unwrap_or(f64::NAN);
        match *self {
            Measure::Parameter(i) => (value(i), c(i, i).max(0.0).sqrt()),
            Measure::Amplitude(a, b) => amplitude(value(a), value(b), c(a, a), c(a, b), c(b, b)),
            Measure::PeakToValley(a, b) => {
                peak_to_valley(value(a), value(b), c(a, a), c(a, b), c(b, b))
            }
            Measure::Exact(x) => (x, 0.0),
        }
    }
}

/// Amplitude `sqrt(a^2 + b^2)` and its standard deviation (delta method).
fn amplitude(a: f64, b: f64, caa: f64, cab: f64, cbb: f64) -> (f64, f64) {
    let r = a.hypot(b);
    if r == 0.0 {
        return (0.0, caa.max(cbb).max(0.0).sqrt());
    }
    let var = (a * a * caa + 2.0 * a * b * cab + b * b * cbb) / (r * r);
    (r, var.max(0.0).sqrt())
}

/// Peak-to-valley of `c2 P2(x) + c3 P3(x)` over `[-1, 1]` and its standard
/// deviation (delta method, numerical gradient).
fn peak_to_valley(c2: f64, c3: f64, c22: f64, c23: f64, c33: f64) -> (f64, f64) {
    let pv = |a: f64, b: f64| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..=200 {
            let x = -1.0 + 0.01 * i as f64;
            let y = a * legendre_p2(x) + b * legendre_p3(x);
            lo = lo.min(y);
            hi = hi.max(y);
        }
        hi - lo
    };
    let v = pv(c2, c3);
    let h = 1e-6 * (c2.abs() + c3.abs()).max(1e-3);
    let g2 = (pv(c2 + h, c3) - pv(c2 - h, c3)) / (2.0 * h);
    let g3 = (pv(c2, c3 + h) - pv(c2, c3 - h)) / (2.0 * h);
    let var = g2 * g2 * c22 + 2.0 * g2 * g3 * c23 + g3 * g3 * c33;
    (v, var.max(0.0).sqrt())
}

/// A judged quantity of a term, resolved for its legs and channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Judgement {
    /// The range it is judged by.
    pub range: PlausibleRange,
    /// How it is computed from the term's parameters.
    pub measure: Measure,
    /// What it is, for messages (`amplitude of leg 2`).
    pub label: String,
}

/// What a residual plot shows along its horizontal axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum XAxis {
    /// The command of leg `i`, mm.
    LegCommand(usize),
    /// The command of leg `i` modulo the term's period, mm.
    LegCommandModuloPeriod(usize),
    /// The approach direction of leg `i` (spread by the file line so that
    /// the points do not sit on each other).
    LegApproach(usize),
    /// The logged temperature, °C.
    Temperature,
    /// The tilt of the UP limb, deg.
    Tilt,
    /// The UP limb's extension `q4`, mm.
    Extension,
    /// The U-joint angle of channel `c` (0 `phi`, 1 `theta`), deg.
    Angle(usize),
    /// The line of the data file.
    Line,
    /// The logged time, or the pose's position in the file.
    Order,
}

/// What a residual plot shows along its vertical axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum YAxis {
    /// The length residual of leg `i` (`J1` times the joint residuals), um.
    LegResidual(usize),
    /// The mean of the three legs' length residuals, um.
    MeanLegResidual,
    /// The linear scale's residual, um.
    ScaleResidual,
    /// The residual of reading channel `c`, arcsec or um.
    Reading(usize),
    /// The largest residual of the pose in noise units.
    LargestResidualSigma,
}

/// The names of the three reading channels.
pub const CHANNELS: [&str; 3] = ["phi", "theta", "s"];

impl XAxis {
    /// The axis label.
    pub fn label(&self) -> String {
        match *self {
            XAxis::LegCommand(i) => format!("leg {} command (mm)", i + 1),
            XAxis::LegCommandModuloPeriod(i) => {
                format!("leg {} command modulo the period (mm)", i + 1)
            }
            XAxis::LegApproach(i) => format!("leg {} approach direction", i + 1),
            XAxis::Temperature => "temperature (°C)".into(),
            XAxis::Tilt => "tilt of the UP limb (deg)".into(),
            XAxis::Extension => "q4 (mm)".into(),
            XAxis::Angle(c) => format!("{} (deg)", CHANNELS[c.min(2)]),
            XAxis::Line => "line of the data file".into(),
            XAxis::Order => "time (s) or pose".into(),
        }
    }
}

impl YAxis {
    /// The axis label.
    pub fn label(&self) -> String {
        match *self {
            YAxis::LegResidual(i) => format!("leg {} length residual (um)", i + 1),
            YAxis::MeanLegResidual => "mean leg length residual (um)".into(),
            YAxis::ScaleResidual => "scale residual (um)".into(),
            YAxis::Reading(c) => format!(
                "{} residual ({})",
                CHANNELS[c.min(2)],
                if c == 2 { "um" } else { "arcsec" }
            ),
            YAxis::LargestResidualSigma => "largest |residual| (sigma)".into(),
        }
    }
}

/// The two axes of a residual plot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotAxes {
    /// Horizontal.
    pub x: XAxis,
    /// Vertical.
    pub y: YAxis,
}

/// A known confusion: another cause whose signature reads like this one's,
/// why, and what measurement separates them.
#[derive(Debug, Clone, Copy)]
pub struct KnownAlias {
    /// The other cause's report name (an effect or a generic family; a
    /// test of the registry checks that it is one).
    pub with: &'static str,
    /// Why they cannot be told apart.
    pub why: &'static str,
    /// What separates them.
    pub separate_by: &'static str,
    /// When the alias holds on every campaign by construction: how.
    pub structural: Option<Structural>,
}

/// An alias that holds on every campaign: the common part (the mean over
/// the legs) of the per-leg parameters of one effect reads exactly as the
/// declaring effect's single parameter, with the machine scaled (a scale
/// gain `g` reads like the machine scaled by `1 + g` with a lead `g` on
/// every leg).
#[derive(Debug, Clone, Copy)]
pub struct Structural {
    /// The effect whose per-leg parameters have the common part (its
    /// report name; it declares its [`CommonPart`]).
    pub common_of: &'static str,
    /// The change, per unit `g` of a machine scaled by `1 + g` (to first
    /// order), of each parameter of `common_of` and of the declaring
    /// effect's parameter, in their units.
    pub scaled_machine: (f64, f64),
    /// What a report says of a significant common part, from its mean and
    /// standard deviation.
    pub says: fn(f64, f64) -> String,
}

/// The common part of an effect with one parameter per leg: the same
/// value on every leg, an alternative of its own in the alias analysis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CommonPart {
    /// Its label as an alternative (`leg-lead (equal on all legs)`).
    pub label: &'static str,
    /// Its label as one side of a structural alias (`leg-lead (common
    /// part)`).
    pub as_alias: &'static str,
    /// Its one parameter (`lead_ppm (every leg)`).
    pub parameter: &'static str,
}
