//! The terms an extended model can contain: effects of the vocabulary
//! (`Term::Catalogue`, their specs in [`tricept_model::effects`]) and
//! generic terms of the dictionary ([`GenericTerm`]), with the campaign
//! [`Frame`] that the generic terms are measured in.
//!
//! Every term linear in its parameters says the same thing at a pose:
//! per unit of each parameter, what it adds to a leg length (a *leg* term,
//! entering through `J1^-1 e_i`) or to a reading (a *reading* term,
//! entering directly): `(parameter, Basis, value)` entries
//! ([`tricept_model::effects::Entries`]). The generic terms' values are the
//! functional forms of [`tricept_model::effects`] in coordinates normalised
//! over the campaign (leg strokes on `[-1, 1]`, time on `[-1/2, 1/2]`,
//! temperature about its mean), frozen once on the full data set so that
//! every fit, cross-validation folds included, uses the same coordinates.

use std::collections::BTreeMap;

use tricept_data::{Dataset, MeasuredPose};
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{KinematicsError, Machine, up_limb::UpJoints};
pub use tricept_model::effects::GenericFamily;
use tricept_model::effects::{
    Basis, CHANNELS, CauseName, EffectName, Entries, Judgement, Kind, LegContext, Needs,
    encoder_gain_error_rad, legendre_p2, legendre_p3, legendre_p4, linear_drift,
    normalised_coordinate, periodic_extra_mm,
};

/// A logged temperature that varies by less than this over the campaign
/// (K) carries no usable thermal signature: a logger's own noise (0.02 K in
/// the plant simulator) spans about 0.1 K over a few hundred readings.
pub const MIN_TEMPERATURE_RANGE_K: f64 = 0.25;

/// Which legs or channel a generic term acts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Scope {
    /// One leg (0, 1, 2).
    Leg(u8),
    /// All three legs, each with its own coefficients.
    AllLegs,
    /// One reading channel (0 `phi`, 1 `theta`, 2 `s`).
    Channel(u8),
}

/// A generic term of the dictionary: a family, its scope and its
/// nonlinear parameters, found by a scan: the period of a `leg-periodic`
/// term, the edges of a `leg-step` term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenericTerm {
    /// The family.
    pub family: GenericFamily,
    /// Legs or channel.
    pub scope: Scope,
    /// Period of a `leg-periodic` term, mm.
    pub period_mm: Option<f64>,
    /// Edges of a `leg-step` term, leg command `[a, b]` (mm): the leg is
    /// longer by the step while its command is inside, both included.
    pub edges_mm: Option<[f64; 2]>,
}

/// A term of an extended model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Term {
    /// An effect of the vocabulary (any but `outliers`, which is handled by
    /// row screening).
    Catalogue(EffectName),
    /// A generic term.
    Generic(GenericTerm),
}

impl Term {
    /// The name under which the term is reported.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_diagnose::{terms::GenericFamily, terms::GenericTerm, terms::Scope, terms::Term};
use tricept_model::effects::EffectName;
let lead = Term::Catalogue(EffectName::LegLead);
let drift = Term::Generic(GenericTerm::new(GenericFamily::ReadingDrift, Scope::Channel(2)));
assert_eq!(lead.name().to_string(), "leg-lead");
assert_eq!(drift.params(), vec!["s_um".to_string()]);
```
"#
    )]
    pub fn name(&self) -> CauseName {
        match self {
            Term::Catalogue(e) => CauseName::Catalogue(*e),
            Term::Generic(g) => CauseName::Generic(g.family),
        }
    }

    /// Its parameter names (unit in the name), without the family prefix.
    pub fn params(&self) -> Vec<String> {
        match self {
            Term::Catalogue(e) => e.parameter_names().iter().map(|s| s.to_string()).collect(),
            Term::Generic(g) => g.params(),
        }
    }

    /// Its number of parameters.
    pub fn param_count(&self) -> usize {
        match self {
            Term::Catalogue(e) => e.parameter_count(),
            Term::Generic(g) => g.params().len(),
        }
    }

    /// A short label of the term for messages (`leg-lead`,
    /// `reading-drift:s`).
    pub fn label(&self) -> String {
        match self {
            Term::Catalogue(e) => e.to_string(),
            Term::Generic(g) => g.label(),
        }
    }

    /// What the campaign must log for the term to be seen.
    pub fn needs(&self) -> Needs {
        self.name().needs()
    }

    /// Whether the campaign has what the term needs.
    pub fn available(&self, frame: &Frame) -> bool {
        match self {
            Term::Catalogue(_) => frame.supports(self.needs()),
            Term::Generic(g) => g.available(frame),
        }
    }

    /// The term's judged quantities, resolved for its legs, channel and
    /// period.
    pub fn judgements(&self) -> Vec<Judgement> {
        match self {
            Term::Catalogue(e) => e.judgements(),
            Term::Generic(g) => g.family.judgements(&g.legs(), g.channel(), g.period_mm),
        }
    }

    /// Whether the term changes leg lengths, readings or the kinematics.
    pub(crate) fn kind(&self) -> TermKind {
        match self {
            Term::Catalogue(e) => match e.spec().kind {
                Kind::Leg(_) => TermKind::Leg,
                Kind::Reading(_) => TermKind::Reading,
                Kind::Kinematic(_) => TermKind::Kinematic,
                Kind::Rows => TermKind::None,
            },
            Term::Generic(g) if g.acts_on_legs() => TermKind::Leg,
            Term::Generic(_) => TermKind::Reading,
        }
    }

    /// Per unit of each parameter, what a leg term adds to the leg lengths
    /// at `pose` (empty for the others); the nominal machine carries the
    /// gravity load of a compliance.
    pub(crate) fn leg_entries(
        &self,
        frame: &Frame,
        nominal: &Machine,
        pose: &MeasuredPose,
    ) -> Result<Entries, KinematicsError> {
        match self {
            Term::Catalogue(e) => match e.spec().kind {
                Kind::Leg(entries) => entries(&LegContext {
                    nominal,
                    commands_mm: pose.commands_mm,
                    approach: pose.approach,
                    temperature_c: pose.temp_c,
                }),
                Kind::Reading(_) | Kind::Kinematic(_) | Kind::Rows => Ok(Vec::new()),
            },
            Term::Generic(g) => Ok(g.leg_values(frame, pose)),
        }
    }

    /// Per unit of each parameter, what a reading term adds to the readings
    /// with the UP limb at `up` (empty for the others).
    pub(crate) fn reading_entries(
        &self,
        frame: &Frame,
        pose: &MeasuredPose,
        up: &UpJoints,
    ) -> Entries {
        match self {
            Term::Catalogue(e) => match e.spec().kind {
                Kind::Reading(entries) => entries(up),
                Kind::Leg(_) | Kind::Kinematic(_) | Kind::Rows => Vec::new(),
            },
            Term::Generic(g) => g.reading_values(frame, pose, up),
        }
    }

    /// Whether two terms act on overlapping parts of the machine within
    /// the same family (one of them makes the other redundant).
    pub fn overlaps(&self, other: &Term) -> bool {
        match (self, other) {
            (Term::Catalogue(a), Term::Catalogue(b)) => a == b,
            (Term::Generic(a), Term::Generic(b)) => {
                a.family == b.family
                    && match (a.scope, b.scope) {
                        (Scope::AllLegs, Scope::Leg(_) | Scope::AllLegs)
                        | (Scope::Leg(_), Scope::AllLegs) => true,
                        (x, y) => x == y,
                    }
                    && a.family != GenericFamily::LegPeriodic
            }
            _ => false,
        }
    }
}

/// How a term's parameters enter the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TermKind {
    Leg,
    Reading,
    Kinematic,
    /// Not a term of a model (outliers).
    None,
}

fn leg_label(i: usize) -> usize {
    i + 1
}

impl GenericTerm {
    /// A term without a period.
    pub fn new(family: GenericFamily, scope: Scope) -> GenericTerm {
        GenericTerm {
            family,
            scope,
            period_mm: None,
            edges_mm: None,
        }
    }

    /// Whether the term has the nonlinear parameters its family scans for
    /// (a period, edges); a group of the dictionary has none until scanned.
    pub fn is_scanned(&self) -> bool {
        match self.family {
            GenericFamily::LegPeriodic => self.period_mm.is_some(),
            GenericFamily::LegStep => self.edges_mm.is_some(),
            _ => true,
        }
    }

    /// Whether the term changes leg lengths (else readings).
    pub fn acts_on_legs(&self) -> bool {
        self.family.spec().acts_on_legs
    }

    /// The legs of a leg term.
    pub fn legs(&self) -> Vec<usize> {
        match self.scope {
            Scope::Leg(i) => vec![usize::from(i)],
            Scope::AllLegs => vec![0, 1, 2],
            Scope::Channel(_) => Vec::new(),
        }
    }

    /// The channel of a reading term.
    pub fn channel(&self) -> Option<usize> {
        match self.scope {
            Scope::Channel(c) => Some(usize::from(c)),
            _ => None,
        }
    }

    /// Parameter names (unit in the name).
    pub fn params(&self) -> Vec<String> {
        let ch = |suffix: &str| {
            let c = self.channel().unwrap_or(2);
            let unit = if c == 2 { "um" } else { "arcsec" };
            format!("{}_{unit}{suffix}", CHANNELS[c])
        };
        match self.family {
            GenericFamily::LegPeriodic => self
                .legs()
                .into_iter()
                .flat_map(|i| {
                    let i = leg_label(i);
                    [format!("leg{i}_sin_um"), format!("leg{i}_cos_um")]
                })
                .collect(),
            GenericFamily::LegPolynomial => self
                .legs()
                .into_iter()
                .flat_map(|i| {
                    let i = leg_label(i);
                    [
                        format!("leg{i}_p1_um"),
                        format!("leg{i}_p2_um"),
                        format!("leg{i}_p3_um"),
                    ]
                })
                .collect(),
            GenericFamily::LegStep => self
                .legs()
                .into_iter()
                .map(|i| format!("leg{}_um", leg_label(i)))
                .collect(),
            GenericFamily::LegDrift => self
                .legs()
                .into_iter()
                .map(|i| format!("leg{}_um", leg_label(i)))
                .collect(),
            GenericFamily::ReadingDrift | GenericFamily::ReadingHysteresis => vec![ch("")],
            GenericFamily::ReadingTemperature => vec![ch("_per_k")],
            GenericFamily::EncoderGain => {
                vec![format!("{}_ppm", CHANNELS[self.channel().unwrap_or(0)])]
            }
            GenericFamily::ScalePolynomial => vec!["p2_um".into(), "p3_um".into()],
        }
    }

    /// Unit of a reading parameter of channel `c` in rad or mm (arcsec or um).
    fn reading_unit(c: usize) -> f64 {
        if c == 2 { 1e-3 } else { RAD_PER_ARCSEC }
    }

    /// Per unit of each parameter (in order), what a leg term adds to a leg
    /// length, mm. Empty for reading terms.
    pub(crate) fn leg_values(&self, frame: &Frame, pose: &MeasuredPose) -> Entries {
        let q = pose.commands_mm;
        let mut out = Vec::new();
        let mut push = |i: usize, v: f64| out.push((out.len(), Basis::Leg(i), v));
        for i in self.legs() {
            if let Some(values) = self.family.leg_command_entries(
                q[i],
                self.period_mm,
                self.edges_mm,
                frame.leg_range_mm[i],
            ) {
                values.into_iter().for_each(|v| push(i, v));
            } else if self.family == GenericFamily::LegDrift {
                push(i, linear_drift(1e-3, frame.tau(pose).unwrap_or(0.0)));
            }
        }
        out
    }

    /// Per unit of each parameter (in order), what a reading term adds to
    /// its reading with the UP limb at `up`, rad or mm. Empty for leg terms.
    pub(crate) fn reading_values(
        &self,
        frame: &Frame,
        pose: &MeasuredPose,
        up: &UpJoints,
    ) -> Entries {
        let Some(c) = self.channel() else {
            return Vec::new();
        };
        let unit = GenericTerm::reading_unit(c);
        let b = Basis::Reading(c);
        match self.family {
            GenericFamily::ReadingDrift => {
                vec![(0, b, linear_drift(unit, frame.tau(pose).unwrap_or(0.0)))]
            }
            GenericFamily::ReadingTemperature => {
                vec![(0, b, unit * frame.delta_temperature_k(pose).unwrap_or(0.0))]
            }
            GenericFamily::ReadingHysteresis => {
                // A lagging sensor reads half its reversal error short in
                // the direction it moved.
                let dir = frame.direction(pose).map_or(0.0, |d| f64::from(d[c]));
                vec![(0, b, -0.5 * unit * dir)]
            }
            GenericFamily::EncoderGain => {
                let angle = if c == 0 { up.phi_rad } else { up.theta_rad };
                vec![(0, b, encoder_gain_error_rad(1.0, angle))]
            }
            GenericFamily::ScalePolynomial => {
                let [lo, hi] = frame.q4_range_mm;
                let x = normalised_coordinate(up.q4_mm, lo, hi);
                vec![(0, b, 1e-3 * legendre_p2(x)), (1, b, 1e-3 * legendre_p3(x))]
            }
            GenericFamily::LegPeriodic
            | GenericFamily::LegPolynomial
            | GenericFamily::LegStep
            | GenericFamily::LegDrift => Vec::new(),
        }
    }

    /// Whether the campaign has what the term needs.
    pub fn available(&self, frame: &Frame) -> bool {
        frame.supports(self.family.spec().needs)
    }

    /// Per-pose columns (direction, value) of the refinement of a generic
    /// leg term: the quartic Legendre part of a polynomial, the second
    /// harmonic of a periodic term (none for a step).
    pub(crate) fn refinement(
        &self,
        frame: &Frame,
        data: &Dataset,
    ) -> Option<Vec<(usize, Vec<f64>)>> {
        let g = self;
        let legs = g.legs();
        let poses = &data.poses;
        match g.family {
            GenericFamily::LegPolynomial => Some(
                legs.iter()
                    .flat_map(|&i| {
                        let [lo, hi] = frame.leg_range_mm[i];
                        let x: Vec<f64> = poses
                            .iter()
                            .map(|p| normalised_coordinate(p.commands_mm[i], lo, hi))
                            .collect();
                        [(i, x.iter().map(|x| 1e-3 * legendre_p4(*x)).collect())]
                    })
                    .collect(),
            ),
            GenericFamily::LegPeriodic => {
                let half = g.period_mm? / 2.0;
                Some(
                    legs.iter()
                        .flat_map(|&i| {
                            let q: Vec<f64> = poses.iter().map(|p| p.commands_mm[i]).collect();
                            [
                                (
                                    i,
                                    q.iter()
                                        .map(|q| periodic_extra_mm(1.0, 0.0, half, *q))
                                        .collect(),
                                ),
                                (
                                    i,
                                    q.iter()
                                        .map(|q| periodic_extra_mm(0.0, 1.0, half, *q))
                                        .collect(),
                                ),
                            ]
                        })
                        .collect(),
                )
            }
            GenericFamily::LegStep
            | GenericFamily::ReadingDrift
            | GenericFamily::ReadingTemperature
            | GenericFamily::LegDrift
            | GenericFamily::EncoderGain
            | GenericFamily::ScalePolynomial
            | GenericFamily::ReadingHysteresis => None,
        }
    }

    /// A short label of the group (`leg-polynomial:leg2`, `reading-drift:s`,
    /// `leg-periodic:legs@10.001mm`, `leg-step:leg1@718.4-958.0mm`).
    pub fn label(&self) -> String {
        let scope = match self.scope {
            Scope::Leg(i) => format!("leg{}", i + 1),
            Scope::AllLegs => "legs".into(),
            Scope::Channel(c) => CHANNELS[usize::from(c)].into(),
        };
        match (self.period_mm, self.edges_mm) {
            (Some(p), _) => format!("{}:{scope}@{p:.3}mm", self.family),
            (None, Some([a, b])) => format!("{}:{scope}@{a:.1}-{b:.1}mm", self.family),
            (None, None) => format!("{}:{scope}", self.family),
        }
    }
}

/// How the campaign orders its poses in time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrderAxis {
    /// The logged time (`time_s`) when every pose has it, else the file line.
    pub uses_time: bool,
    /// Its smallest value.
    pub first: f64,
    /// Its largest value.
    pub last: f64,
}

/// The coordinates of the generic terms for one campaign, frozen on the
/// full data set.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Smallest and largest command of each leg, mm.
    pub leg_range_mm: [[f64; 2]; 3],
    /// Smallest and largest UP-limb extension (nominal model), mm.
    pub q4_range_mm: [f64; 2],
    /// Time (or line) axis, when the poses are ordered.
    pub order: Option<OrderAxis>,
    /// Mean, smallest and largest logged temperature, when it varies by at
    /// least [`MIN_TEMPERATURE_RANGE_K`], °C.
    pub temperature: Option<[f64; 3]>,
    /// Sign of each sensor's change since the previous pose of the file
    /// (nominal joints of the commands), by line (empty without distinct
    /// lines).
    pub directions: BTreeMap<u64, [i8; 3]>,
    /// Whether every pose logs its legs' approach directions and some leg
    /// is approached from both sides.
    pub approach_reverses: bool,
    /// The correlation of the logged temperature with the time axis, when
    /// both vary ([`Frame::order`] and [`Frame::temperature`]): beyond
    /// [`TEMPERATURE_FOLLOWS_TIME`] a change with temperature and a drift
    /// with time cannot be told apart.
    pub temperature_time_r: Option<f64>,
}

/// The correlation (absolute) of the logged temperature with the campaign's
/// time beyond which temperature terms and time terms form one alias set.
pub const TEMPERATURE_FOLLOWS_TIME: f64 = 0.95;

impl Frame {
    /// A frame with no campaign: every generic term is zero in it.
    pub fn empty() -> Frame {
        Frame {
            leg_range_mm: [[0.0; 2]; 3],
            q4_range_mm: [0.0; 2],
            order: None,
            temperature: None,
            directions: BTreeMap::new(),
            approach_reverses: false,
            temperature_time_r: None,
        }
    }

    /// The frame of `data` on the nominal machine.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_diagnose::{terms::Frame, terms::GenericFamily, terms::Scope};
let m = tricept_kinematics::Machine::paper();
let data = tricept_data::read_path("../../fixtures/data/diagnose-pitch.csv".as_ref()).unwrap();
let frame = Frame::of(&m, &data);
// Time is logged: drifts can be searched; the temperature varies by 2 K.
assert!(frame.order.is_some_and(|o| o.uses_time));
let groups = frame.generic_groups();
assert!(groups.iter().any(|g| g.family == GenericFamily::ReadingDrift && g.scope == Scope::Channel(2)));
assert_eq!(groups[0].params()[0], "leg1_sin_um");
```
"#
    )]
    pub fn of(nominal: &Machine, data: &Dataset) -> Frame {
        let poses = &data.poses;
        let range = |v: &mut dyn Iterator<Item = f64>| {
            v.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], x| {
                [lo.min(x), hi.max(x)]
            })
        };
        let leg_range_mm =
            std::array::from_fn(|i| range(&mut poses.iter().map(|p| p.commands_mm[i])));
        let q4_range_mm = range(
            &mut poses
                .iter()
                .filter_map(|p| nominal.forward(&p.commands_mm).ok().map(|f| f.up.q4_mm)),
        );
        let distinct_lines = {
            let mut lines: Vec<u64> = poses.iter().map(|p| p.line).collect();
            lines.sort_unstable();
            lines.dedup();
            lines.len() == poses.len()
        };
        let times: Vec<f64> = poses.iter().filter_map(|p| p.time_s).collect();
        let order = if times.len() == poses.len() && !poses.is_empty() {
            let [first, last] = range(&mut times.iter().copied());
            (last > first).then_some(OrderAxis {
                uses_time: true,
                first,
                last,
            })
        } else if distinct_lines && poses.len() > 1 {
            let [first, last] = range(&mut poses.iter().map(|p| p.line as f64));
            Some(OrderAxis {
                uses_time: false,
                first,
                last,
            })
        } else {
            None
        };
        let temps: Vec<f64> = poses.iter().filter_map(|p| p.temp_c).collect();
        let temperature = (temps.len() == poses.len() && !temps.is_empty())
            .then(|| {
                let [lo, hi] = range(&mut temps.iter().copied());
                let mean = temps.iter().sum::<f64>() / temps.len() as f64;
                (hi - lo > MIN_TEMPERATURE_RANGE_K).then_some([mean, lo, hi])
            })
            .flatten();
        // The direction each sensor moved, from the nominal joints of the
        // commands (not from the noisy readings, whose noise would leak
        // into the regressor); moves below a micro-unit are no move.
        let mut directions = BTreeMap::new();
        if distinct_lines {
            let mut by_line: Vec<&MeasuredPose> = poses.iter().collect();
            by_line.sort_by_key(|p| p.line);
            let joints: Vec<Option<[f64; 3]>> = by_line
                .iter()
                .map(|p| {
                    nominal
                        .forward(&p.commands_mm)
                        .ok()
                        .map(|f| f.up.to_array())
                })
                .collect();
            for (k, w) in joints.windows(2).enumerate() {
                let (Some(a), Some(b)) = (w[0], w[1]) else {
                    continue;
                };
                let dead = [1e-9, 1e-9, 1e-6];
                let dir = std::array::from_fn(|c| {
                    let d = b[c] - a[c];
                    if d > dead[c] {
                        1
                    } else if d < -dead[c] {
                        -1
                    } else {
                        0
                    }
                });
                directions.insert(by_line[k + 1].line, dir);
            }
        }
        let approach_reverses = poses.iter().all(|p| p.approach.is_some())
            && (0..3).any(|i| {
                let dirs: Vec<i8> = poses
                    .iter()
                    .filter_map(|p| p.approach.map(|a| a[i]))
                    .collect();
                dirs.contains(&1) && dirs.contains(&-1)
            });
        let mut frame = Frame {
            leg_range_mm,
            q4_range_mm,
            order,
            temperature,
            directions,
            approach_reverses,
            temperature_time_r: None,
        };
        frame.temperature_time_r = frame.correlation_of_temperature_with_time(poses);
        frame
    }

    /// Pearson's correlation of the logged temperature with [`Frame::tau`]
    /// over `poses`, when both vary.
    fn correlation_of_temperature_with_time(&self, poses: &[MeasuredPose]) -> Option<f64> {
        self.temperature?;
        let pairs: Vec<(f64, f64)> = poses
            .iter()
            .filter_map(|p| Some((self.tau(p)?, p.temp_c?)))
            .collect();
        let n = pairs.len() as f64;
        if pairs.len() < 3 {
            return None;
        }
        let (mx, my) = pairs
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let (sxy, sxx, syy) = pairs.iter().fold((0.0, 0.0, 0.0), |(a, b, c), (x, y)| {
            (
                a + (x - mx) * (y - my),
                b + (x - mx).powi(2),
                c + (y - my).powi(2),
            )
        });
        let r = sxy / (sxx * syy).sqrt();
        r.is_finite().then_some(r)
    }

    /// Whether the logged temperature follows the campaign's time (|r|
    /// beyond [`TEMPERATURE_FOLLOWS_TIME`]).
    pub fn temperature_follows_time(&self) -> bool {
        self.temperature_time_r
            .is_some_and(|r| r.abs() > TEMPERATURE_FOLLOWS_TIME)
    }

    /// Whether the campaign has what a term needs (and, for the context
    /// columns, some variation in it).
    pub fn supports(&self, needs: Needs) -> bool {
        match needs {
            Needs::Nothing => true,
            Needs::Temperature => self.temperature.is_some(),
            Needs::ApproachDirections => self.approach_reverses,
            Needs::PoseOrder => self.order.is_some(),
            Needs::SensorDirections => !self.directions.is_empty(),
            Needs::LegStrokes => self.leg_range_mm.iter().all(|[lo, hi]| hi - lo > 1.0),
            Needs::ScaleStroke => self.q4_range_mm[1] - self.q4_range_mm[0] > 1.0,
        }
    }

    /// Position of `pose` on the time axis, `-1/2` at the first pose and
    /// `+1/2` at the last; `None` without an axis or outside the campaign's
    /// own poses.
    pub fn tau(&self, pose: &MeasuredPose) -> Option<f64> {
        let axis = self.order?;
        let t = if axis.uses_time {
            pose.time_s?
        } else {
            if pose.line == 0 {
                return None;
            }
            pose.line as f64
        };
        Some((t - axis.first) / (axis.last - axis.first) - 0.5)
    }

    /// Logged temperature minus the campaign's mean, K.
    pub fn delta_temperature_k(&self, pose: &MeasuredPose) -> Option<f64> {
        let [mean, _, _] = self.temperature?;
        Some(pose.temp_c? - mean)
    }

    /// Direction of each sensor's change since the previous pose.
    pub fn direction(&self, pose: &MeasuredPose) -> Option<[i8; 3]> {
        self.directions.get(&pose.line).copied()
    }

    /// Every generic group of the dictionary (periodic terms without their
    /// period) that the campaign supports, in a fixed order.
    pub fn generic_groups(&self) -> Vec<GenericTerm> {
        use GenericFamily as G;
        let mut out = vec![GenericTerm::new(G::LegPeriodic, Scope::AllLegs)];
        for i in 0..3 {
            out.push(GenericTerm::new(G::LegPolynomial, Scope::Leg(i)));
        }
        out.push(GenericTerm::new(G::LegPolynomial, Scope::AllLegs));
        for i in 0..3 {
            out.push(GenericTerm::new(G::LegStep, Scope::Leg(i)));
        }
        for c in 0..3 {
            out.push(GenericTerm::new(G::ReadingDrift, Scope::Channel(c)));
            out.push(GenericTerm::new(G::ReadingTemperature, Scope::Channel(c)));
            out.push(GenericTerm::new(G::ReadingHysteresis, Scope::Channel(c)));
        }
        out.push(GenericTerm::new(G::LegDrift, Scope::AllLegs));
        out.push(GenericTerm::new(G::EncoderGain, Scope::Channel(0)));
        out.push(GenericTerm::new(G::EncoderGain, Scope::Channel(1)));
        out.push(GenericTerm::new(G::ScalePolynomial, Scope::Channel(2)));
        out.into_iter().filter(|g| g.available(self)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_coordinates() {
        let poses: Vec<MeasuredPose> = (0..5)
            .map(|j| MeasuredPose {
                commands_mm: [700.0 + 50.0 * j as f64, 800.0, 900.0 - 10.0 * j as f64],
                time_s: Some(30.0 * j as f64),
                temp_c: Some(20.0 + 0.5 * j as f64),
                line: 2 + j as u64,
                ..Default::default()
            })
            .collect();
        let data = Dataset {
            poses,
            source: String::new(),
        };
        let f = Frame::of(&Machine::paper(), &data);
        assert_eq!(f.leg_range_mm[0], [700.0, 900.0]);
        assert_eq!(f.tau(&data.poses[0]), Some(-0.5));
        assert_eq!(f.tau(&data.poses[4]), Some(0.5));
        assert_eq!(f.delta_temperature_k(&data.poses[2]), Some(0.0));
        // Leg 2 never moves: no polynomial on it, so none on all legs.
        let groups = f.generic_groups();
        assert!(
            !groups
                .iter()
                .any(|g| g.family == GenericFamily::LegPolynomial)
        );
        assert!(
            groups
                .iter()
                .any(|g| g.family == GenericFamily::ReadingTemperature)
        );
        // A periodic term's unit values are its sine and cosine, in mm.
        let t = GenericTerm {
            family: GenericFamily::LegPeriodic,
            scope: Scope::AllLegs,
            period_mm: Some(10.0),
            edges_mm: None,
        };
        let v = t.leg_values(&f, &data.poses[0]);
        assert_eq!(v.len(), 6);
        assert_eq!(t.params()[1], "leg1_cos_um");
        assert!((v[1].2 - 1e-3).abs() < 1e-12); // cos(2 pi 700 / 10) = 1
    }
}
