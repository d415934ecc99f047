//! What can have changed: the candidates a check attributes a change to,
//! each a small group of parameters with its reading columns and its
//! effect on the platform.
//!
//! | candidate | parameters | reading columns | platform |
//! |---|---|---|---|
//! | `leg I` | `dqI_mm` (length: a slipped encoder or coupling), `leadI_ppm` (length proportional to the command), `p2_legI_um`, `p3_legI_um` (the quadratic and cubic Legendre shapes over the leg's command range in the workspace: a worn segment, a bent screw) | `J21[:, dq_I] (1, q_I 1e-6, P2(x_I) 1e-3, P3(x_I) 1e-3)` | `P21[:, dq_I]` times the same at `q_I(r)` |
//! | `base joint BI`, `platform joint AI` | `dxBI_mm`, `dyBI_mm`, `dzBI_mm` (or `A`) | the joint's three columns of `J21` | the same columns of `P21` |
//! | `thermal growth` (temperatures logged at the check and the calibration) | `expansion_ppm_per_k` | `sum_I J21[:, dq_I] q_I 1e-6 (T - T_cal)` | `sum_I P21[:, dq_I] q_I(r) 1e-6 (T - T_cal)` at the check's mean `T` |
//! | `thermal growth of the structure` (the check's mean temperature more than 0.1 K from the calibration's) | `structure_expansion_ppm_per_k` | `q4 1e-6 (T - T_cal)` on the scale (the machine scaled by `1 + alpha dT` reads its angles unchanged) | `r 1e-6 (T - T_cal)` at the platform point `r` |
//! | `common leg lead` (no temperatures) | `lead_ppm` | `sum_I J21[:, dq_I] q_I 1e-6` | `sum_I P21[:, dq_I] q_I(r) 1e-6` |
//! | `scale gain` | `scale_gain_ppm` | `s 1e-6` on the scale | none: the sensor, not the machine |
//! | `encoder gains` | `phi_gain_ppm`, `theta_gain_ppm` | `phi 1e-6`, `theta 1e-6` | none |
//!
//! The last rows but the structure's are the registry's: every effect or generic family whose
//! spec has a [`CheckRole`] (`thermal`, `leg-lead`'s common part,
//! `scale-gain`, `encoder-gain`) is a candidate with its name, parameters
//! and columns, when its condition on the logged temperatures holds.
//!
//! `J21` is the reading Jacobian of the 21 joint and length errors
//! (eq. 9), `P21` the platform point's ([`tricept_model::jacobian::position_error_jacobian`]),
//! both at the pose. A zero jump of a sensor is not a candidate: the
//! offsets are re-estimated at every check (a power cycle re-references
//! them), and their change is reported as such.

use nalgebra::Vector3;
use serde::Serialize;
use tricept_kinematics::up_limb::UpJoints;
use tricept_model::effects::{
    Basis, CheckColumns, CheckRole, CheckWhen, EffectName, GenericFamily, legendre_p2, legendre_p3,
    normalised_coordinate,
};
use tricept_model::jacobian::ErrorJacobian;

/// The name of the whole structure's thermal growth.
pub(crate) const STRUCTURE: &str = "thermal growth of the structure";

/// A campaign's mean temperature this close to the calibration's (K) is
/// the same: the structure's growth over it, at most 0.1 K times 11.5 ppm/K
/// times 1.3 m, is under 2 um, and a logger's noise alone moves a mean by
/// a few hundredths of a kelvin.
pub(crate) const SAME_TEMPERATURE_K: f64 = 0.1;

/// The most parameters a candidate has.
pub(crate) const MAX_PARAMETERS: usize = 4;

/// A leg's extra length (mm) per unit of each of its parameters at command
/// `q` (mm): the length itself, the lead (ppm of the command), and the
/// quadratic and cubic Legendre shapes (um) over the command range.
fn leg_shape(q: f64, (lo, hi): (f64, f64)) -> [f64; 4] {
    let x = normalised_coordinate(q, lo, hi);
    [1.0, q * 1e-6, legendre_p2(x) * 1e-3, legendre_p3(x) * 1e-3]
}

/// What kind of change a candidate is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CandidateKind {
    /// A leg's length (a slipped encoder or coupling, a worn screw).
    Leg,
    /// A base joint moved.
    BaseJoint,
    /// A platform joint moved.
    PlatformJoint,
    /// The legs' thermal state differs from the calibration's.
    Thermal,
    /// A sensor's gain changed (not the machine).
    Sensor,
}

/// One candidate change.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Its name in reports (`leg 1`, `base joint B2`, ...).
    pub name: String,
    /// Its kind.
    pub kind: CandidateKind,
    /// Parameter names with their units.
    pub parameters: Vec<String>,
    what: What,
}

#[derive(Debug, Clone, Copy)]
enum What {
    /// Leg `i` over its command range `(lo, hi)` in the workspace, mm.
    Leg(usize, (f64, f64)),
    Base(usize),
    Platform(usize),
    /// A change the registry declares, with the calibration's temperature
    /// when both logged one.
    Registry {
        role: &'static CheckRole,
        reference_c: Option<f64>,
    },
    /// The whole structure grown by the campaign's mean temperature change
    /// since the calibration, K.
    Structure(f64),
}

impl PartialEq for What {
    fn eq(&self, other: &What) -> bool {
        match (self, other) {
            (What::Leg(i, r), What::Leg(j, s)) => i == j && r == s,
            (What::Base(i), What::Base(j)) | (What::Platform(i), What::Platform(j)) => i == j,
            (What::Structure(a), What::Structure(b)) => a == b,
            (
                What::Registry {
                    role: a,
                    reference_c: x,
                },
                What::Registry {
                    role: b,
                    reference_c: y,
                },
            ) => a.name == b.name && x == y,
            _ => false,
        }
    }
}

/// The check roles of the registry, in its order: the effects', then the
/// generic families'.
fn registry_roles() -> impl Iterator<Item = &'static CheckRole> {
    let effects = EffectName::ALL
        .into_iter()
        .filter_map(|e| e.spec().check.as_ref());
    let generic = GenericFamily::ALL
        .into_iter()
        .filter_map(|g| g.spec().check.as_ref());
    effects.chain(generic)
}

impl What {
    /// The temperature change since the calibration at `temp_c` (0 unless
    /// both logged one).
    fn delta_k(&self, temp_c: Option<f64>) -> f64 {
        match (self, temp_c) {
            (
                What::Registry {
                    reference_c: Some(r),
                    ..
                },
                Some(t),
            ) => t - r,
            _ => 0.0,
        }
    }
}

/// What the columns of one pose are computed from.
pub(crate) struct PoseTerms<'a> {
    /// Reading Jacobian of the 21 errors at the pose.
    pub j21: &'a ErrorJacobian,
    /// Leg commands, mm.
    pub commands_mm: [f64; 3],
    /// Predicted readings without offsets (rad, rad, mm).
    pub readings: [f64; 3],
    /// Logged temperature, °C.
    pub temp_c: Option<f64>,
}

impl Candidate {
    fn new(name: String, kind: CandidateKind, parameters: &[String], what: What) -> Candidate {
        Candidate {
            name,
            kind,
            parameters: parameters.to_vec(),
            what,
        }
    }

    /// The candidates of a check: every leg (over its command range in the
    /// workspace, `leg_ranges_mm`) and joint, the sensors' gains, and the
    /// legs' thermal growth when both the check and the calibration logged
    /// a temperature (`reference_c`), else a common lead of the legs.
    pub fn all(
        leg_ranges_mm: [(f64, f64); 3],
        reference_c: Option<f64>,
        check_has_temperature: bool,
    ) -> Vec<Candidate> {
        let mut v = Vec::new();
        for i in 0..3 {
            let n = i + 1;
            v.push(Candidate::new(
                format!("leg {n}"),
                CandidateKind::Leg,
                &[
                    format!("dq{n}_mm"),
                    format!("lead{n}_ppm"),
                    format!("p2_leg{n}_um"),
                    format!("p3_leg{n}_um"),
                ],
                What::Leg(i, leg_ranges_mm[i]),
            ));
        }
        for i in 0..3 {
            for (kind, place, letter, what) in [
                (CandidateKind::BaseJoint, "base", "B", What::Base(i)),
                (
                    CandidateKind::PlatformJoint,
                    "platform",
                    "A",
                    What::Platform(i),
                ),
            ] {
                let joint = format!("{letter}{}", i + 1);
                v.push(Candidate::new(
                    format!("{place} joint {joint}"),
                    kind,
                    &["x", "y", "z"].map(|a| format!("d{a}{joint}_mm")),
                    what,
                ));
            }
        }
        let both = reference_c.filter(|_| check_has_temperature);
        for role in registry_roles() {
            let applies = match role.when {
                CheckWhen::Always => true,
                CheckWhen::WithTemperatures => both.is_some(),
                CheckWhen::WithoutTemperatures => both.is_none(),
            };
            if !applies {
                continue;
            }
            let kind = match role.columns {
                CheckColumns::Legs(_) => CandidateKind::Thermal,
                CheckColumns::Readings(_) => CandidateKind::Sensor,
            };
            let parameters: Vec<String> = role.parameters.iter().map(|p| p.to_string()).collect();
            v.push(Candidate::new(
                role.name.into(),
                kind,
                &parameters,
                What::Registry {
                    role,
                    reference_c: both,
                },
            ));
        }
        v
    }

    /// The candidates of a check whose campaign's mean temperature is
    /// `check_c`: those of [`Candidate::all`], and when it differs from the
    /// calibration's (`reference_c`) by more than 0.1 K, the thermal growth of the whole
    /// structure (legs, base and platform joints and the UP limb grown
    /// alike, the scale reading the longer limb): a machine scaled by
    /// `1 + alpha dT` reads its angles unchanged and its scale `alpha dT q4`
    /// longer, and its platform point `r` moves by `alpha dT r`.
    ///
    /// # Example
    /// ```
    /// use tricept_check::candidates::Candidate;
    /// let ranges = [(700.0, 900.0); 3];
    /// let warm = Candidate::for_check(ranges, Some(20.0), Some(24.0));
    /// assert_eq!(warm.len(), Candidate::all(ranges, Some(20.0), true).len() + 1);
    /// assert!(warm.iter().any(|c| c.name == "thermal growth of the structure"));
    /// // At the calibration's temperature, or without one: none.
    /// assert_eq!(Candidate::for_check(ranges, Some(20.0), Some(20.05)).len(), warm.len() - 1);
    /// assert_eq!(Candidate::for_check(ranges, None, Some(24.0)).len(), warm.len() - 1);
    /// ```
    pub fn for_check(
        leg_ranges_mm: [(f64, f64); 3],
        reference_c: Option<f64>,
        check_c: Option<f64>,
    ) -> Vec<Candidate> {
        let mut v = Candidate::all(leg_ranges_mm, reference_c, check_c.is_some());
        if let (Some(r), Some(t)) = (reference_c, check_c)
            && (t - r).abs() > SAME_TEMPERATURE_K
        {
            v.push(Candidate::new(
                STRUCTURE.into(),
                CandidateKind::Thermal,
                &["structure_expansion_ppm_per_k".to_string()],
                What::Structure(t - r),
            ));
        }
        v
    }

    /// The temperature change (K) of the whole structure's thermal growth,
    /// `None` for every other candidate.
    pub(crate) fn structure_delta_k(&self) -> Option<f64> {
        match self.what {
            What::Structure(dt) => Some(dt),
            _ => None,
        }
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.parameters.len()
    }

    /// Never empty.
    pub fn is_empty(&self) -> bool {
        self.parameters.is_empty()
    }

    /// Whether its parameters are nested (each adds a shape to the ones
    /// before it: a leg's length, lead, then its quadratic and cubic
    /// shapes), so that its leading subsets are tested too.
    pub fn is_nested(&self) -> bool {
        self.kind == CandidateKind::Leg
    }

    /// Whether the change moves the platform (a sensor's does not).
    pub fn moves_the_platform(&self) -> bool {
        self.kind != CandidateKind::Sensor
    }

    /// The reading columns at one pose, written into `out[c][t]` for
    /// channel `c` and parameter `t`.
    pub(crate) fn columns(&self, p: &PoseTerms<'_>, out: &mut [[f64; MAX_PARAMETERS]; 3]) {
        *out = [[0.0; MAX_PARAMETERS]; 3];
        let j = p.j21;
        let q = p.commands_mm;
        for c in 0..3 {
            match self.what {
                What::Leg(i, range) => {
                    for (t, f) in leg_shape(q[i], range).iter().enumerate() {
                        out[c][t] = j[(c, 7 * i + 6)] * f;
                    }
                }
                What::Base(i) => {
                    for a in 0..3 {
                        out[c][a] = j[(c, 7 * i + a)];
                    }
                }
                What::Platform(i) => {
                    for a in 0..3 {
                        out[c][a] = j[(c, 7 * i + 3 + a)];
                    }
                }
                What::Registry { role, .. } => match role.columns {
                    CheckColumns::Legs(f) => {
                        let dt = self.what.delta_k(p.temp_c);
                        out[c][0] = (0..3).map(|i| j[(c, 7 * i + 6)] * f(q[i], dt)).sum();
                    }
                    CheckColumns::Readings(_) => {}
                },
                What::Structure(_) => {}
            }
        }
        if let What::Structure(dt) = self.what {
            out[2][0] = p.readings[2] * 1e-6 * dt;
        }
        if let What::Registry { role, .. } = self.what
            && let CheckColumns::Readings(f) = role.columns
        {
            let up = UpJoints {
                phi_rad: p.readings[0],
                theta_rad: p.readings[1],
                q4_mm: p.readings[2],
            };
            for (t, basis, value) in f(&up) {
                if let Basis::Reading(c) = basis
                    && c < 3
                    && t < MAX_PARAMETERS
                {
                    out[c][t] += value;
                }
            }
        }
    }

    /// The platform error (mm) a change `value` of this candidate causes at
    /// a target commanded with `commands_mm`, from the platform point's
    /// Jacobian `p21` there (`point_mm`, in the base frame); `temp_c` is
    /// the temperature of the machine (thermal growth).
    pub(crate) fn platform_error(
        &self,
        p21: &ErrorJacobian,
        point_mm: &Vector3<f64>,
        commands_mm: &[f64; 3],
        temp_c: Option<f64>,
        value: &[f64],
    ) -> Vector3<f64> {
        let v = |t: usize| value.get(t).copied().unwrap_or(0.0);
        let col = |f: usize| Vector3::new(p21[(0, f)], p21[(1, f)], p21[(2, f)]);
        let q = commands_mm;
        match self.what {
            What::Leg(i, range) => {
                let f = leg_shape(q[i], range);
                col(7 * i + 6) * (0..4).map(|t| v(t) * f[t]).sum::<f64>()
            }
            What::Base(i) => (0..3).map(|a| col(7 * i + a) * v(a)).sum(),
            What::Platform(i) => (0..3).map(|a| col(7 * i + 3 + a) * v(a)).sum(),
            What::Registry { role, .. } => match role.columns {
                CheckColumns::Legs(f) => {
                    let dt = self.what.delta_k(temp_c);
                    (0..3).map(|i| col(7 * i + 6) * f(q[i], dt) * v(0)).sum()
                }
                CheckColumns::Readings(_) => Vector3::zeros(),
            },
            What::Structure(dt) => point_mm * (1e-6 * dt * v(0)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_candidates_cover_every_leg_and_joint_once() {
        let ranges = [(700.0, 900.0); 3];
        let c = Candidate::all(ranges, Some(20.0), true);
        let names: Vec<&str> = c.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "leg 1",
                "leg 2",
                "leg 3",
                "base joint B1",
                "platform joint A1",
                "base joint B2",
                "platform joint A2",
                "base joint B3",
                "platform joint A3",
                "thermal growth",
                "scale gain",
                "encoder gains"
            ]
        );
        assert_eq!(c[4].parameters, ["dxA1_mm", "dyA1_mm", "dzA1_mm"]);
        assert!(
            Candidate::all(ranges, None, true)
                .iter()
                .any(|c| c.name == "common leg lead")
        );
    }
}
