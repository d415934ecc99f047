//! The terms an extended model can contain: effects of the vocabulary
//! ([`Candidate`]) and generic terms of the dictionary ([`GenericTerm`]),
//! with the campaign [`Frame`] that the generic terms are measured in.
//!
//! A generic term is linear in its parameters: each parameter adds, per
//! unit, a known value to one leg length (a *leg* term, entering like a
//! catalogue leg effect through `J1^-1 e_i`) or to one reading (a *reading*
//! term, entering directly). The values are the functional forms of
//! [`tricept_model::effects`] in coordinates normalised over the campaign
//! (leg strokes on `[-1, 1]`, time on `[-1/2, 1/2]`, temperature about its
//! mean), frozen once on the full data set so that every fit, cross-
//! validation folds included, uses the same coordinates.

use std::collections::BTreeMap;

use tricept_data::{Dataset, MeasuredPose};
use tricept_kinematics::units::RAD_PER_ARCSEC;
use tricept_kinematics::{Machine, UpJoints};
use tricept_model::effects::{
    CauseName, GenericFamily, encoder_gain_error_rad, legendre_p2, legendre_p3, linear_drift,
    normalised_coordinate, periodic_extra_mm,
};

use crate::model::{Candidate, MIN_TEMPERATURE_RANGE_K};

/// The names of the three reading channels.
pub const CHANNELS: [&str; 3] = ["phi", "theta", "s"];

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

/// A generic term of the dictionary: a family, its scope and, for
/// `leg-periodic`, the period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenericTerm {
    /// The family.
    pub family: GenericFamily,
    /// Legs or channel.
    pub scope: Scope,
    /// Period of a `leg-periodic` term, mm.
    pub period_mm: Option<f64>,
}

/// Where a unit of a parameter goes: onto a leg length (mm) or a reading
/// (rad or mm).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Basis {
    Leg(usize),
    Reading(usize),
}

/// A term of an extended model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Term {
    /// An effect of the vocabulary.
    Catalogue(Candidate),
    /// A generic term.
    Generic(GenericTerm),
}

impl Term {
    /// The name under which the term is reported.
    ///
    /// # Example
    /// ```
    /// use tricept_diagnose::{Candidate, GenericFamily, GenericTerm, Scope, Term};
    /// use tricept_model::effects::EffectName;
    /// let lead = Term::Catalogue(Candidate(EffectName::LegLead));
    /// let drift = Term::Generic(GenericTerm::new(GenericFamily::ReadingDrift, Scope::Channel(2)));
    /// assert_eq!(lead.name().to_string(), "leg-lead");
    /// assert_eq!(drift.params(), vec!["s_um".to_string()]);
    /// ```
    pub fn name(&self) -> CauseName {
        match self {
            Term::Catalogue(c) => CauseName::Catalogue(c.0),
            Term::Generic(g) => CauseName::Generic(g.family),
        }
    }

    /// Its parameter names (unit in the name), without the family prefix.
    pub fn params(&self) -> Vec<String> {
        match self {
            Term::Catalogue(c) => c.params().iter().map(|s| s.to_string()).collect(),
            Term::Generic(g) => g.params(),
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
        }
    }

    /// Whether the term changes leg lengths (else readings).
    pub fn acts_on_legs(&self) -> bool {
        matches!(
            self.family,
            GenericFamily::LegPeriodic | GenericFamily::LegPolynomial | GenericFamily::LegDrift
        )
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
    pub(crate) fn leg_values(&self, frame: &Frame, pose: &MeasuredPose) -> Vec<(Basis, f64)> {
        let q = pose.commands_mm;
        let mut out = Vec::new();
        match self.family {
            GenericFamily::LegPeriodic => {
                let period = self.period_mm.unwrap_or(f64::INFINITY);
                for i in self.legs() {
                    out.push((Basis::Leg(i), periodic_extra_mm(1.0, 0.0, period, q[i])));
                    out.push((Basis::Leg(i), periodic_extra_mm(0.0, 1.0, period, q[i])));
                }
            }
            GenericFamily::LegPolynomial => {
                for i in self.legs() {
                    let [lo, hi] = frame.leg_range_mm[i];
                    let x = normalised_coordinate(q[i], lo, hi);
                    out.push((Basis::Leg(i), 1e-3 * x));
                    out.push((Basis::Leg(i), 1e-3 * legendre_p2(x)));
                    out.push((Basis::Leg(i), 1e-3 * legendre_p3(x)));
                }
            }
            GenericFamily::LegDrift => {
                let tau = frame.tau(pose).unwrap_or(0.0);
                for i in self.legs() {
                    out.push((Basis::Leg(i), linear_drift(1e-3, tau)));
                }
            }
            _ => {}
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
    ) -> Vec<(Basis, f64)> {
        let Some(c) = self.channel() else {
            return Vec::new();
        };
        let unit = GenericTerm::reading_unit(c);
        let b = Basis::Reading(c);
        match self.family {
            GenericFamily::ReadingDrift => {
                vec![(b, linear_drift(unit, frame.tau(pose).unwrap_or(0.0)))]
            }
            GenericFamily::ReadingTemperature => {
                vec![(b, unit * frame.delta_temperature_k(pose).unwrap_or(0.0))]
            }
            GenericFamily::ReadingHysteresis => {
                // A lagging sensor reads half its reversal error short in
                // the direction it moved.
                let dir = frame.direction(pose).map_or(0.0, |d| f64::from(d[c]));
                vec![(b, -0.5 * unit * dir)]
            }
            GenericFamily::EncoderGain => {
                let angle = if c == 0 { up.phi_rad } else { up.theta_rad };
                vec![(b, encoder_gain_error_rad(1.0, angle))]
            }
            GenericFamily::ScalePolynomial => {
                let [lo, hi] = frame.q4_range_mm;
                let x = normalised_coordinate(up.q4_mm, lo, hi);
                vec![(b, 1e-3 * legendre_p2(x)), (b, 1e-3 * legendre_p3(x))]
            }
            _ => Vec::new(),
        }
    }

    /// Whether the campaign has what the term needs.
    pub fn available(&self, frame: &Frame) -> bool {
        match self.family {
            GenericFamily::ReadingDrift | GenericFamily::LegDrift => frame.order.is_some(),
            GenericFamily::ReadingTemperature => frame.temperature.is_some(),
            GenericFamily::ReadingHysteresis => !frame.directions.is_empty(),
            GenericFamily::LegPolynomial => frame.leg_range_mm.iter().all(|[lo, hi]| hi - lo > 1.0),
            GenericFamily::ScalePolynomial => frame.q4_range_mm[1] - frame.q4_range_mm[0] > 1.0,
            _ => true,
        }
    }

    /// A short label of the group (`leg-polynomial:leg2`, `reading-drift:s`).
    pub fn label(&self) -> String {
        let scope = match self.scope {
            Scope::Leg(i) => format!("leg{}", i + 1),
            Scope::AllLegs => "legs".into(),
            Scope::Channel(c) => CHANNELS[usize::from(c)].into(),
        };
        match self.period_mm {
            Some(p) => format!("{}:{scope}@{p:.3}mm", self.family),
            None => format!("{}:{scope}", self.family),
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
}

impl Frame {
    /// A frame with no campaign: every generic term is zero in it.
    pub fn empty() -> Frame {
        Frame {
            leg_range_mm: [[0.0; 2]; 3],
            q4_range_mm: [0.0; 2],
            order: None,
            temperature: None,
            directions: BTreeMap::new(),
        }
    }

    /// The frame of `data` on the nominal machine.
    ///
    /// # Example
    /// ```
    /// use tricept_diagnose::{Frame, GenericFamily, Scope};
    /// let m = tricept_kinematics::Machine::paper();
    /// let data = tricept_data::read_path("../../fixtures/data/diagnose-pitch.csv".as_ref()).unwrap();
    /// let frame = Frame::of(&m, &data);
    /// // Time is logged: drifts can be searched; the temperature varies by 2 K.
    /// assert!(frame.order.is_some_and(|o| o.uses_time));
    /// let groups = frame.generic_groups();
    /// assert!(groups.iter().any(|g| g.family == GenericFamily::ReadingDrift && g.scope == Scope::Channel(2)));
    /// assert_eq!(groups[0].params()[0], "leg1_sin_um");
    /// ```
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
        Frame {
            leg_range_mm,
            q4_range_mm,
            order,
            temperature,
            directions,
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
        };
        let v = t.leg_values(&f, &data.poses[0]);
        assert_eq!(v.len(), 6);
        assert_eq!(t.params()[1], "leg1_cos_um");
        assert!((v[1].1 - 1e-3).abs() < 1e-12); // cos(2 pi 700 / 10) = 1
    }
}
