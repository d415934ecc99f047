//! The computational machine model and its inverse kinematics.
//!
//! A [`Machine`] is a validated [`MachineDescription`] in the form the
//! solvers use: joint centres as vectors, the UP limb chain, limits. The same
//! type represents the nominal machine and an "actual" one with geometric
//! errors (see `tricept-model`), so simulated readings always come from this
//! exact model.
//!
//! Inverse kinematics of the parallel module (eq. 1 of the paper):
//! `q_i = |r + R a_0i - b_i| - dq_i`, with `R` and the UP joints from the UP
//! limb (`r = q4 R e_z` on an ideal joint).

use nalgebra::{Matrix3, Vector3};

use crate::description::{
    LegEffectsDescription, LoadsDescription, MachineDescription, Placement, SensorDescription,
    UpLimbDescription, WorkspaceDescription,
};
use crate::error::KinematicsError;
use crate::head::Head;
use crate::units::{arcsec_to_rad, rad_to_arcsec};
use crate::up_limb::{UpJoints, UpLimb, UpLimbPose};
use crate::workspace::Workspace;

/// Joint limits in solver form.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// Stroke of the actuated legs `[min, max]`, mm.
    pub leg_stroke_mm: [f64; 2],
    /// Stroke of the UP limb's prismatic joint `[min, max]`, mm.
    pub up_stroke_mm: [f64; 2],
    max_tilt_rad: f64,
    /// `cos(max_tilt_rad + slack)`: the smallest z of the unit limb axis.
    min_limb_axis_z: f64,
}

impl Limits {
    /// Limits from strokes (mm) and the largest tilt of the UP limb (rad).
    pub fn new(leg_stroke_mm: [f64; 2], up_stroke_mm: [f64; 2], max_tilt_rad: f64) -> Limits {
        Limits {
            leg_stroke_mm,
            up_stroke_mm,
            max_tilt_rad,
            min_limb_axis_z: (max_tilt_rad + LIMIT_SLACK).cos(),
        }
    }

    /// Largest tilt of the UP limb from the base z axis, rad.
    pub fn max_tilt_rad(&self) -> f64 {
        self.max_tilt_rad
    }
}

/// Standard deviations of one *logged* sensor value (the mean of
/// `readings_per_pose` readings).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorNoise {
    /// Encoder noise of one reading, rad.
    pub angle_rad: f64,
    /// Linear-scale noise of one reading, mm.
    pub length_mm: f64,
    /// Readings averaged into one logged value.
    pub readings_per_pose: u32,
}

impl SensorNoise {
    /// Builds from the description's units (arcsec, um).
    pub fn from_description(s: &SensorDescription) -> SensorNoise {
        SensorNoise {
            angle_rad: arcsec_to_rad(s.angle_noise_arcsec),
            length_mm: s.length_noise_um * 1e-3,
            readings_per_pose: s.readings_per_pose,
        }
    }

    /// Standard deviations `[phi, theta, s]` of one logged value
    /// (rad, rad, mm): single-reading noise divided by `sqrt(readings)`.
    pub fn logged_sigma(&self) -> [f64; 3] {
        let k = f64::from(self.readings_per_pose.max(1)).sqrt();
        [self.angle_rad / k, self.angle_rad / k, self.length_mm / k]
    }
}

/// Result of the inverse kinematics of the parallel module.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution {
    /// Commands of the three actuated legs, mm.
    pub legs_mm: [f64; 3],
    /// The UP limb's joint values.
    pub up: UpJoints,
}

/// Per-leg geometry at one configuration of the module.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegGeometry {
    /// The UP limb at this configuration.
    pub limb: UpLimbPose,
    /// Platform joint centres `A_i` in the base frame, mm.
    pub platform_joints_mm: [Vector3<f64>; 3],
    /// Geometric leg lengths `|A_i - B_i|` (actual, not commanded), mm.
    pub lengths_mm: [f64; 3],
    /// Unit leg vectors `w_i` from `B_i` to `A_i`.
    pub directions: [Vector3<f64>; 3],
}

impl LegGeometry {
    /// The paper's `J1` generalised to any UP chain: row `i` is
    /// `w_i^T dA_i/d(phi, theta, q4)`. On an ideal joint this is
    /// `[(b_i x w_i)^T J_theta, w_i^T w_4]` (eq. 9). It is also the Jacobian
    /// of the leg lengths with respect to the UP joints, used by FK.
    pub fn j1(&self) -> Matrix3<f64> {
        let limb = &self.limb;
        let [phi_axis, theta_axis] = limb.angle_axes;
        let [phi_pivot, theta_pivot] = limb.angle_pivots_mm;
        let twist = limb.twist_rate_rad_per_mm();
        let mut j1 = Matrix3::zeros();
        for i in 0..3 {
            // w^T (k x (A - p)) = k . ((A - p) x w): row i of w_i^T dA_i/dx.
            let a = &self.platform_joints_mm[i];
            let w = &self.directions[i];
            j1[(i, 0)] = phi_axis.dot(&(a - phi_pivot).cross(w));
            j1[(i, 1)] = theta_axis.dot(&(a - theta_pivot).cross(w));
            j1[(i, 2)] = w.dot(&limb.limb_axis);
            if twist != 0.0 {
                j1[(i, 2)] += twist * limb.limb_axis.dot(&(a - limb.position_mm).cross(w));
            }
        }
        j1
    }
}

/// The Tricept module (3-UPS + UP) with its head: nominal or actual.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use nalgebra::Vector3;
use tricept_kinematics::Machine;
let m = Machine::paper();
let r = Vector3::new(120.0, -80.0, 760.0);
let ik = m.inverse(&r).unwrap();
let fk = m.forward(&ik.legs_mm).unwrap();
assert!((fk.position_mm - r).norm() < 1e-9);
```
"#
)]
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// Name from the description.
    pub name: String,
    /// Base joint centres `B_1..B_3` in Oxyz, mm (`B_4` is the origin).
    pub base_joints_mm: [Vector3<f64>; 3],
    /// Platform joint centres `A_1..A_3` in O'x'y'z', mm.
    pub platform_joints_mm: [Vector3<f64>; 3],
    /// Actual leg length = command + offset, mm (the `dq_i` errors).
    pub leg_offsets_mm: [f64; 3],
    /// The UP limb chain.
    pub up_limb: UpLimb,
    /// The workspace cylinder of O'.
    pub workspace: Workspace,
    /// Joint limits.
    pub limits: Limits,
    /// The 2-DOF head.
    pub head: Head,
    /// Sensor noise (one reading).
    pub sensors: SensorNoise,
    /// Masses and stiffness (for the compliance effect).
    pub loads: LoadsDescription,
    /// Static leg effects of a calibrated machine (lead, compliance). Plain
    /// data here: this crate's IK and FK are the geometric ones, and
    /// `tricept_model::ExtendedMachine` applies the effects.
    pub leg_effects: LegEffectsDescription,
}

/// Limits are checked with this slack (mm or rad) so that a configuration
/// exactly on a limit survives the rounding of an IK/FK round trip.
const LIMIT_SLACK: f64 = 1e-9;

impl Machine {
    /// The paper's Table 1 machine (embedded default).
    pub fn paper() -> Machine {
        Machine::from_validated(&MachineDescription::paper())
    }

    /// Builds from a description that [`MachineDescription::validate`] accepted.
    pub(crate) fn from_validated(d: &MachineDescription) -> Machine {
        let (base, platform) = d.joints_mm();
        Machine {
            name: d.name.clone(),
            base_joints_mm: base.map(Vector3::from),
            platform_joints_mm: platform.map(Vector3::from),
            leg_offsets_mm: d.leg_offsets_mm,
            up_limb: UpLimb::from_description(&d.up_limb),
            workspace: Workspace::from_description(&d.workspace),
            limits: Limits::new(
                d.limits.leg_stroke_mm,
                d.limits.up_stroke_mm,
                d.limits.max_tilt_deg.to_radians(),
            ),
            head: Head::from_description(&d.head),
            sensors: SensorNoise::from_description(&d.sensors),
            loads: d.loads.clone(),
            leg_effects: d.leg_effects.clone(),
        }
    }

    /// The first point of the workspace the machine cannot reach (its rim
    /// and half radius on the lowest, middle and highest planes, and the
    /// axis), with why; `None` when it reaches them all. A description
    /// whose workspace lies beyond its legs' stroke or its UP limb's tilt
    /// is wrong, and every verb would fail on it somewhere else.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
let mut m = tricept_kinematics::Machine::paper();
assert!(m.unreachable_workspace_point().is_none());
m.workspace.radius_mm = 900.0;
let (p, why) = m.unreachable_workspace_point().unwrap();
assert!(p.x.hypot(p.y) > 400.0, "{p} {why}");
```
"#
    )]
    pub fn unreachable_workspace_point(&self) -> Option<(Vector3<f64>, KinematicsError)> {
        self.workspace
            .polar_grid(2, 16, 3)
            .into_iter()
            .find_map(|r| self.inverse(&r).err().map(|e| (r, e)))
    }

    /// The description of this machine, with explicit joint coordinates
    /// (so that an identified machine can be written out and loaded again).
    pub fn to_description(&self) -> MachineDescription {
        let v3 = |v: &Vector3<f64>| [v.x, v.y, v.z];
        let w = &self.workspace;
        MachineDescription {
            format_version: crate::description::FORMAT_VERSION,
            name: self.name.clone(),
            notes: None,
            placement: Placement::Explicit(crate::description::ExplicitPlacement {
                base_joints_mm: self.base_joints_mm.each_ref().map(v3),
                platform_joints_mm: self.platform_joints_mm.each_ref().map(v3),
            }),
            up_limb: UpLimbDescription {
                axis_order: self.up_limb.axis_order,
                axis_skew_rad: self.up_limb.axis_skew_rad,
                axis_offset_mm: self.up_limb.axis_offset_mm,
                twist_rad_per_mm: self.up_limb.twist_rad_per_mm,
                twist_reference_mm: self.up_limb.twist_reference_mm,
            },
            leg_offsets_mm: self.leg_offsets_mm,
            workspace: WorkspaceDescription {
                radius_mm: w.radius_mm,
                height_mm: w.z_max_mm - w.z_min_mm,
                distance_mm: w.z_min_mm,
            },
            limits: crate::description::LimitsDescription {
                leg_stroke_mm: self.limits.leg_stroke_mm,
                up_stroke_mm: self.limits.up_stroke_mm,
                max_tilt_deg: self.limits.max_tilt_rad.to_degrees(),
            },
            head: self.head.to_description(),
            sensors: SensorDescription {
                // Rounded to 1e-9 arcsec so that 0.8 arcsec survives the
                // round trip through rad as 0.8.
                angle_noise_arcsec: (rad_to_arcsec(self.sensors.angle_rad) * 1e9).round() / 1e9,
                length_noise_um: self.sensors.length_mm * 1e3,
                readings_per_pose: self.sensors.readings_per_pose,
            },
            loads: self.loads.clone(),
            leg_effects: self.leg_effects.clone(),
            controller: None,
            calibration: None,
        }
    }

    /// The same machine with a different ideal U-joint axis order.
    pub fn with_axis_order(mut self, order: crate::description::AxisOrder) -> Machine {
        self.up_limb.axis_order = order;
        self
    }

    /// Leg geometry with the UP limb at `up`.
    #[inline]
    pub fn legs_at(&self, up: &UpJoints) -> LegGeometry {
        self.legs_for(self.up_limb.pose(up))
    }

    /// Leg geometry with the UP limb in pose `limb`.
    #[inline]
    pub fn legs_for(&self, limb: UpLimbPose) -> LegGeometry {
        let mut g = LegGeometry {
            limb,
            platform_joints_mm: [Vector3::zeros(); 3],
            lengths_mm: [0.0; 3],
            directions: [Vector3::zeros(); 3],
        };
        self.legs_into(limb, &mut g);
        g
    }

    /// [`Machine::legs_for`] written into an existing value.
    #[inline]
    pub(crate) fn legs_into(&self, limb: UpLimbPose, out: &mut LegGeometry) {
        for i in 0..3 {
            let a = limb.position_mm + limb.rotation * self.platform_joints_mm[i];
            let d = a - self.base_joints_mm[i];
            let n = d.norm();
            out.platform_joints_mm[i] = a;
            out.lengths_mm[i] = n;
            out.directions[i] = d / n;
        }
        out.limb = limb;
    }

    /// Leg commands that put the legs at the geometric lengths of `geometry`.
    pub fn commands_for(&self, geometry: &LegGeometry) -> [f64; 3] {
        std::array::from_fn(|i| geometry.lengths_mm[i] - self.leg_offsets_mm[i])
    }

    /// Inverse kinematics: platform point `r` (mm) to leg commands and UP
    /// joint values. Fails when `r` is not finite or outside the joint limits.
    pub fn inverse(&self, r: &Vector3<f64>) -> Result<IkSolution, KinematicsError> {
        for (what, v) in [("x", r.x), ("y", r.y), ("z", r.z)] {
            if !v.is_finite() {
                return Err(KinematicsError::NotFinite { what, value: v });
            }
        }
        let (up, frame) = self.up_limb.inverse_frame(r)?;
        let legs_mm: [f64; 3] = std::array::from_fn(|i| {
            let a = frame.position_mm + frame.rotation * self.platform_joints_mm[i];
            (a - self.base_joints_mm[i]).norm() - self.leg_offsets_mm[i]
        });
        self.check_limits(&legs_mm, &up, &frame.limb_axis)?;
        Ok(IkSolution { legs_mm, up })
    }

    /// Checks leg commands, UP stroke and tilt against the limits.
    pub(crate) fn check_limits(
        &self,
        legs_mm: &[f64; 3],
        up: &UpJoints,
        limb_axis: &Vector3<f64>,
    ) -> Result<(), KinematicsError> {
        self.check_commands(legs_mm)?;
        let [lo, hi] = self.limits.up_stroke_mm;
        if !(lo - LIMIT_SLACK..=hi + LIMIT_SLACK).contains(&up.q4_mm) {
            return Err(KinematicsError::OutOfReach {
                reason: format!(
                    "UP limb extension {:.3} mm is outside its stroke [{lo}, {hi}] mm",
                    up.q4_mm
                ),
            });
        }
        if limb_axis.z < self.limits.min_limb_axis_z {
            let tilt = limb_axis.z.clamp(-1.0, 1.0).acos();
            return Err(KinematicsError::OutOfReach {
                reason: format!(
                    "UP limb tilt {:.3} deg exceeds the limit {:.3} deg",
                    tilt.to_degrees(),
                    self.limits.max_tilt_rad.to_degrees()
                ),
            });
        }
        Ok(())
    }

    /// Checks leg commands against the leg stroke (with the same small
    /// slack as every solver): the one check that the data reader, the
    /// identification and the kinematics share.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::{KinematicsError, Machine};
let m = Machine::paper();
assert!(m.check_commands(&[800.0; 3]).is_ok());
let e = m.check_commands(&[800.0, 100.0, 800.0]).unwrap_err();
assert!(matches!(e, KinematicsError::OutOfStroke { leg: 2, .. }));
```
"#
    )]
    pub fn check_commands(&self, legs_mm: &[f64; 3]) -> Result<(), KinematicsError> {
        let [lo, hi] = self.limits.leg_stroke_mm;
        for (i, &q) in legs_mm.iter().enumerate() {
            if !q.is_finite() {
                return Err(KinematicsError::NotFinite {
                    what: "leg command",
                    value: q,
                });
            }
            if !(lo - LIMIT_SLACK..=hi + LIMIT_SLACK).contains(&q) {
                return Err(KinematicsError::OutOfStroke {
                    leg: i + 1,
                    length_mm: q,
                    min_mm: lo,
                    max_mm: hi,
                });
            }
        }
        Ok(())
    }
}

impl MachineDescription {
    /// The validated computational form.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
let m = tricept_kinematics::MachineDescription::paper().build().unwrap();
assert!((m.base_joints_mm[2].x - 288.7).abs() < 1e-12);
```
"#
    )]
    pub fn build(&self) -> Result<Machine, crate::error::DescriptionError> {
        self.validate()?;
        Ok(Machine::from_validated(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_joints_are_on_their_circles() {
        let m = Machine::paper();
        let b = 288.7;
        let s3 = 3f64.sqrt() / 2.0;
        let expect = [
            Vector3::new(-b / 2.0, b * s3, 0.0),
            Vector3::new(-b / 2.0, -b * s3, 0.0),
            Vector3::new(b, 0.0, 0.0),
        ];
        for i in 0..3 {
            assert!((m.base_joints_mm[i] - expect[i]).norm() < 1e-12);
            assert!((m.platform_joints_mm[i] * b / 100.0 - expect[i]).norm() < 1e-12);
        }
        // The paper's frame convention: B1B2 parallel to y.
        let b1b2 = m.base_joints_mm[1] - m.base_joints_mm[0];
        assert!(b1b2.x.abs() < 1e-12 && b1b2.z.abs() < 1e-12);
    }

    #[test]
    fn ik_at_the_centre_is_symmetric() {
        let m = Machine::paper();
        let ik = m.inverse(&Vector3::new(0.0, 0.0, 750.0)).unwrap();
        // Every leg runs from radius 288.7 at z = 0 to radius 100 at z = 750.
        let expected = ((288.7f64 - 100.0).powi(2) + 750.0f64.powi(2)).sqrt();
        for q in ik.legs_mm {
            assert!((q - expected).abs() < 1e-9);
        }
        assert_eq!(ik.up.phi_rad, 0.0);
        assert_eq!(ik.up.theta_rad, 0.0);
    }

    #[test]
    fn ik_refuses_points_beyond_the_limits() {
        let m = Machine::paper();
        assert!(matches!(
            m.inverse(&Vector3::new(0.0, 0.0, 2000.0)),
            Err(KinematicsError::OutOfStroke { .. })
        ));
        // 45 degrees of tilt with every leg inside its stroke.
        let e = m.inverse(&Vector3::new(600.0, 0.0, 600.0)).unwrap_err();
        assert!(e.to_string().contains("tilt"), "{e}");
        assert!(matches!(
            m.inverse(&Vector3::new(f64::NAN, 0.0, 700.0)),
            Err(KinematicsError::NotFinite { .. })
        ));
    }

    #[test]
    fn logged_sigma_divides_by_root_readings() {
        let s = Machine::paper().sensors.logged_sigma();
        assert!((s[0] - arcsec_to_rad(0.8) / 3f64.sqrt()).abs() < 1e-18);
        assert!((s[2] - 0.5e-3 / 3f64.sqrt()).abs() < 1e-15);
    }
}
