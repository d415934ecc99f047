//! The UP limb: the passive universal-prismatic chain that alone fixes the
//! platform's orientation, and whose three joints carry the sensors.
//!
//! For the x-first convention (the paper's eq. 8) the chain is
//!
//! ```text
//! R_limb = Rx(phi) S Ry(theta) S^T,     S = Rz(skew)
//! O2     = Rx(phi) (offset e_z)         (a point on the second axis)
//! r      = O2 + q4 R_limb e_z           (the platform point O')
//! R      = R_limb Rz(twist (q4 - q_ref)) (the platform orientation)
//! ```
//!
//! and for y-first the roles of x and y swap (`R_limb = Ry(theta) S Rx(phi) S^T`).
//! `skew`, `offset` and `twist` are the "class 2" errors of the paper (zero
//! on an ideal joint, where `R = Rx(phi) Ry(theta)` and `r = q4 R e_z`).
//! Angles in rad, lengths in mm.

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

use crate::description::{AxisOrder, UpLimbDescription};
use crate::error::KinematicsError;

/// Values of the UP limb's three passive joints: what its encoders and
/// linear scale read (before their zero offsets).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct UpJoints {
    /// Rotation about the U joint's x-type axis, rad.
    pub phi_rad: f64,
    /// Rotation about the U joint's y-type axis, rad.
    pub theta_rad: f64,
    /// Extension of the prismatic joint: distance from the U joint to O', mm.
    pub q4_mm: f64,
}

impl UpJoints {
    /// The three values as `[phi, theta, q4]` (rad, rad, mm).
    pub fn to_array(self) -> [f64; 3] {
        [self.phi_rad, self.theta_rad, self.q4_mm]
    }

    /// Builds from `[phi, theta, q4]` (rad, rad, mm).
    pub fn from_array(v: [f64; 3]) -> UpJoints {
        UpJoints {
            phi_rad: v[0],
            theta_rad: v[1],
            q4_mm: v[2],
        }
    }
}

/// The UP limb's kinematic chain (see the module docs for the formulas).
#[derive(Debug, Clone, PartialEq)]
pub struct UpLimb {
    /// Which U-joint axis is fixed to the base.
    pub axis_order: AxisOrder,
    /// Non-orthogonality of the two U-joint axes, rad.
    pub axis_skew_rad: f64,
    /// Distance between the two U-joint axes along their common normal, mm.
    pub axis_offset_mm: f64,
    /// Platform twist about the limb axis per mm of extension, rad/mm.
    pub twist_rad_per_mm: f64,
    /// Extension at which the twist is zero, mm.
    pub twist_reference_mm: f64,
}

/// Everything about the limb at one joint configuration, in the base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpLimbPose {
    /// Platform orientation `R` (O'x'y'z' relative to Oxyz).
    pub rotation: Matrix3<f64>,
    /// Platform point O', mm.
    pub position_mm: Vector3<f64>,
    /// Unit direction of the limb (prismatic) axis, `w4`.
    pub limb_axis: Vector3<f64>,
    /// `d/dphi` and `d/dtheta` of the orientation as angular-velocity
    /// vectors: columns are the rotation axes of `phi` and `theta`.
    pub angle_axes: [Vector3<f64>; 2],
    /// A point on each of those two axes, mm (the origin for the base-fixed
    /// axis; for the other, the origin displaced by the axis offset).
    pub angle_pivots_mm: [Vector3<f64>; 2],
    /// Twist rate copied from the limb, rad/mm.
    twist_rad_per_mm: f64,
}

impl UpLimbPose {
    /// Derivatives of a point rigidly attached to the platform, at world
    /// position `p` (mm), with respect to `(phi, theta, q4)`: columns in mm/rad,
    /// mm/rad and mm/mm.
    pub fn point_jacobian(&self, p: &Vector3<f64>) -> Matrix3<f64> {
        let [phi_axis, theta_axis] = self.angle_axes;
        let [phi_point, theta_point] = self.angle_pivots_mm;
        let d_phi = phi_axis.cross(&(p - phi_point));
        let d_theta = theta_axis.cross(&(p - theta_point));
        let d_q4 =
            self.limb_axis + self.twist_rad_per_mm * self.limb_axis.cross(&(p - self.position_mm));
        Matrix3::from_columns(&[d_phi, d_theta, d_q4])
    }

    /// Platform twist about the limb axis per mm of extension, rad/mm.
    pub fn twist_rate_rad_per_mm(&self) -> f64 {
        self.twist_rad_per_mm
    }

    /// Derivatives of a platform-fixed direction `v` (unit) with respect to
    /// `(phi, theta, q4)`.
    pub fn direction_jacobian(&self, v: &Vector3<f64>) -> Matrix3<f64> {
        let [phi_axis, theta_axis] = self.angle_axes;
        Matrix3::from_columns(&[
            phi_axis.cross(v),
            theta_axis.cross(v),
            self.twist_rad_per_mm * self.limb_axis.cross(v),
        ])
    }
}

/// The part of [`UpLimbPose`] that IK needs, plus the second axis.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LimbFrame {
    pub rotation: Matrix3<f64>,
    pub position_mm: Vector3<f64>,
    pub limb_axis: Vector3<f64>,
    second_axis: Vector3<f64>,
    second_axis_point_mm: Vector3<f64>,
}

fn rot(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), angle).into_inner()
}

impl UpLimb {
    /// Builds the chain from its description.
    pub fn from_description(d: &UpLimbDescription) -> UpLimb {
        UpLimb {
            axis_order: d.axis_order,
            axis_skew_rad: d.axis_skew_rad,
            axis_offset_mm: d.axis_offset_mm,
            twist_rad_per_mm: d.twist_rad_per_mm,
            twist_reference_mm: d.twist_reference_mm,
        }
    }

    /// An ideal U joint (no class-2 errors) with the given axis order.
    pub fn ideal(axis_order: AxisOrder) -> UpLimb {
        UpLimb {
            axis_order,
            axis_skew_rad: 0.0,
            axis_offset_mm: 0.0,
            twist_rad_per_mm: 0.0,
            twist_reference_mm: 0.0,
        }
    }

    /// True when the limb has no class-2 errors (closed-form inverse applies).
    pub fn is_ideal(&self) -> bool {
        self.axis_skew_rad == 0.0 && self.axis_offset_mm == 0.0
    }

    /// The limb's geometry at joint values `j`.
    #[inline]
    pub fn pose(&self, j: &UpJoints) -> UpLimbPose {
        let (first_angle, second_angle) = match self.axis_order {
            AxisOrder::XFirst => (j.phi_rad, j.theta_rad),
            AxisOrder::YFirst => (j.theta_rad, j.phi_rad),
        };
        let (s1, c1) = small_sin_cos(first_angle);
        let (s2, c2) = small_sin_cos(second_angle);
        self.pose_from_trig([s1, c1, s2, c2], j.q4_mm)
    }

    /// [`UpLimb::pose`] from the sines and cosines `[s1, c1, s2, c2]` of the
    /// first (base-fixed) and second joint angles.
    #[inline]
    fn pose_from_trig(&self, trig: [f64; 4], q4_mm: f64) -> UpLimbPose {
        let frame = self.frame_from_trig(trig, q4_mm);
        let origin = Vector3::zeros();
        let (angle_axes, angle_pivots_mm) = match self.axis_order {
            AxisOrder::XFirst => (
                [Vector3::x(), frame.second_axis],
                [origin, frame.second_axis_point_mm],
            ),
            AxisOrder::YFirst => (
                [frame.second_axis, Vector3::y()],
                [frame.second_axis_point_mm, origin],
            ),
        };
        UpLimbPose {
            rotation: frame.rotation,
            position_mm: frame.position_mm,
            limb_axis: frame.limb_axis,
            angle_axes,
            angle_pivots_mm,
            twist_rad_per_mm: self.twist_rad_per_mm,
        }
    }

    /// Rotation, position and axes from the sines and cosines of the joint
    /// angles (the part of the pose that IK needs).
    #[inline]
    fn frame_from_trig(&self, trig: [f64; 4], q4_mm: f64) -> LimbFrame {
        let ez = Vector3::z();
        let [s1, c1, s2, c2] = trig;
        // Elementary rotations written out: this is the hot path of IK and FK.
        let rx = |s: f64, c: f64| Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c);
        let ry = |s: f64, c: f64| Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c);
        let (second_local, r1, mut r2) = match self.axis_order {
            AxisOrder::XFirst => (Vector3::y(), rx(s1, c1), ry(s2, c2)),
            AxisOrder::YFirst => (Vector3::x(), ry(s1, c1), rx(s2, c2)),
        };
        let mut second_in_first = second_local;
        let limb_rotation = if self.axis_skew_rad != 0.0 {
            // The second axis turned by the skew about the common normal z:
            // R2 = S R2_ideal S^T with S = Rz(skew).
            let (s, c) = self.axis_skew_rad.sin_cos();
            let skew = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
            second_in_first = skew * second_local;
            r2 = skew * r2 * skew.transpose();
            r1 * r2
        } else {
            // The products Rx Ry and Ry Rx written out (4 multiplications).
            match self.axis_order {
                AxisOrder::XFirst => {
                    Matrix3::new(c2, 0.0, s2, s1 * s2, c1, -s1 * c2, -c1 * s2, s1, c1 * c2)
                }
                AxisOrder::YFirst => {
                    Matrix3::new(c1, s1 * s2, s1 * c2, 0.0, c2, -s2, -s1, c1 * s2, c1 * c2)
                }
            }
        };
        let limb_axis = limb_rotation.column(2).into_owned();
        let second_axis_point_mm = if self.axis_offset_mm == 0.0 {
            Vector3::zeros()
        } else {
            r1 * (self.axis_offset_mm * ez)
        };
        let position_mm = second_axis_point_mm + q4_mm * limb_axis;
        let twist = self.twist_rad_per_mm * (q4_mm - self.twist_reference_mm);
        let rotation = if twist == 0.0 {
            limb_rotation
        } else {
            limb_rotation * rot(&ez, twist)
        };
        LimbFrame {
            rotation,
            position_mm,
            limb_axis,
            second_axis: r1 * second_in_first,
            second_axis_point_mm,
        }
    }

    /// The platform orientation when O' is at `r` (no inverse trigonometry
    /// on an ideal joint: used by FK's seed).
    pub(crate) fn rotation_at_point(
        &self,
        r: &Vector3<f64>,
    ) -> Result<Matrix3<f64>, KinematicsError> {
        if self.is_ideal() {
            let (q4, trig) = ideal_trig(self.axis_order, r)?;
            Ok(self.frame_from_trig(trig, q4).rotation)
        } else {
            Ok(self.pose(&self.inverse(r)?).rotation)
        }
    }

    /// Joint values that put O' at `r` (mm), with the limb's frame there.
    #[inline]
    pub(crate) fn inverse_frame(
        &self,
        r: &Vector3<f64>,
    ) -> Result<(UpJoints, LimbFrame), KinematicsError> {
        let (j, trig) = if self.is_ideal() {
            ideal_inverse_trig(self.axis_order, r)?
        } else {
            let j = self.inverse(r)?;
            let (first, second) = match self.axis_order {
                AxisOrder::XFirst => (j.phi_rad, j.theta_rad),
                AxisOrder::YFirst => (j.theta_rad, j.phi_rad),
            };
            let (s1, c1) = first.sin_cos();
            let (s2, c2) = second.sin_cos();
            (j, [s1, c1, s2, c2])
        };
        Ok((j, self.frame_from_trig(trig, j.q4_mm)))
    }

    /// Joint values that put O' at `r` (mm), with the limb's pose there.
    /// On an ideal joint the pose is built from the closed form's own sines
    /// and cosines (no second round of trigonometry: this is IK's hot path).
    #[inline]
    pub fn inverse_pose(
        &self,
        r: &Vector3<f64>,
    ) -> Result<(UpJoints, UpLimbPose), KinematicsError> {
        if self.is_ideal() {
            let (j, trig) = ideal_inverse_trig(self.axis_order, r)?;
            return Ok((j, self.pose_from_trig(trig, j.q4_mm)));
        }
        let j = self.inverse(r)?;
        Ok((j, self.pose(&j)))
    }

    /// Joint values that put O' at `r` (mm). Closed form for an ideal joint;
    /// Newton's method seeded by the closed form when class-2 errors are present.
    pub fn inverse(&self, r: &Vector3<f64>) -> Result<UpJoints, KinematicsError> {
        let seed = ideal_inverse_trig(self.axis_order, r)?.0;
        if self.is_ideal() {
            return Ok(seed);
        }
        let mut j = seed;
        for _ in 0..30 {
            let pose = self.pose(&j);
            let f = pose.position_mm - r;
            let jac = pose.point_jacobian(&pose.position_mm);
            let Some(inv) = jac.try_inverse() else {
                return Err(KinematicsError::Singular {
                    condition: f64::INFINITY,
                    limit: crate::error::SINGULARITY_CONDITION_LIMIT,
                });
            };
            let step = -(inv * f);
            j = UpJoints::from_array([j.phi_rad + step.x, j.theta_rad + step.y, j.q4_mm + step.z]);
            if step.z.abs() + j.q4_mm * (step.x.abs() + step.y.abs()) < 1e-11 {
                return Ok(j);
            }
        }
        Err(KinematicsError::NotConverged {
            solver: "UP limb inverse",
            iterations: 30,
            residual: (self.pose(&j).position_mm - r).norm(),
        })
    }
}

/// Closed-form inverse of an ideal U joint, `r = q4 R e_z`, with the sines
/// and cosines `[s1, c1, s2, c2]` of the first and second joint angles.
fn ideal_inverse_trig(
    order: AxisOrder,
    r: &Vector3<f64>,
) -> Result<(UpJoints, [f64; 4]), KinematicsError> {
    let (q4, trig) = ideal_trig(order, r)?;
    let [s1, c1, s2, c2] = trig;
    // `+ 0.0` turns the -0.0 of atan(-0.0) into 0.0.
    let (first, second) = (angle_of(s1, c1) + 0.0, angle_of(s2, c2) + 0.0);
    let (phi_rad, theta_rad) = match order {
        AxisOrder::XFirst => (first, second),
        AxisOrder::YFirst => (second, first),
    };
    let j = UpJoints {
        phi_rad,
        theta_rad,
        q4_mm: q4,
    };
    Ok((j, trig))
}

/// `(sin x, cos x)`: Taylor series (Horner form, to x^17 and x^18) on
/// `|x| <= 0.8`, where the truncation error is below 1e-19 and the result
/// agrees with the standard library to a few units in the last place; the
/// standard library elsewhere. U-joint angles stay within about 0.7 rad, and
/// `pose` is evaluated several times per forward kinematics: this halves the
/// cost of the trigonometry there.
#[inline]
pub(crate) fn small_sin_cos(x: f64) -> (f64, f64) {
    if x.abs() > 0.8 {
        return x.sin_cos();
    }
    let x2 = x * x;
    // sin x = x (1 - x^2/3! + x^4/5! - ... + x^16/17!)
    const S: [f64; 9] = [
        1.0,
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
        1.0 / 355_687_428_096_000.0,
    ];
    // cos x = 1 - x^2/2! + x^4/4! - ... + x^18/18!
    const C: [f64; 10] = [
        1.0,
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 20_922_789_888_000.0,
        -1.0 / 6_402_373_705_728_000.0,
    ];
    let mut s = S[8];
    for k in (0..8).rev() {
        s = s * x2 + S[k];
    }
    let mut c = C[9];
    for k in (0..9).rev() {
        c = c * x2 + C[k];
    }
    (x * s, c)
}

/// `atan2(s, c)`, through the three-times cheaper `atan(s / c)` on the
/// half plane `c > 0` where they agree (every reachable U-joint angle).
#[inline]
fn angle_of(s: f64, c: f64) -> f64 {
    if c > 0.0 { (s / c).atan() } else { s.atan2(c) }
}

/// `q4` and the sines and cosines `[s1, c1, s2, c2]` of the first and second
/// joint angles of an ideal U joint pointing at `r`, without trigonometry.
fn ideal_trig(order: AxisOrder, r: &Vector3<f64>) -> Result<(f64, [f64; 4]), KinematicsError> {
    let q4 = r.norm();
    if q4 < 1e-9 {
        return Err(KinematicsError::OutOfReach {
            reason: "the platform point coincides with the UP limb's U joint".into(),
        });
    }
    // Reciprocals instead of repeated divisions: this is IK's critical path.
    let u = r * (1.0 / q4);
    let trig = match order {
        // u = (sin t, -sin p cos t, cos p cos t); first angle phi.
        AxisOrder::XFirst => {
            let ct = (u.y * u.y + u.z * u.z).sqrt();
            let (sp, cp) = if ct > 0.0 {
                let inv = 1.0 / ct;
                (-u.y * inv, u.z * inv)
            } else {
                (0.0, 1.0)
            };
            [sp, cp, u.x, ct]
        }
        // u = (sin t cos p, -sin p, cos t cos p); first angle theta.
        AxisOrder::YFirst => {
            let cp = (u.x * u.x + u.z * u.z).sqrt();
            let (st, ct) = if cp > 0.0 {
                let inv = 1.0 / cp;
                (u.x * inv, u.z * inv)
            } else {
                (0.0, 1.0)
            };
            [st, ct, -u.y, cp]
        }
    };
    Ok((q4, trig))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limbs() -> Vec<UpLimb> {
        let mut v = vec![
            UpLimb::ideal(AxisOrder::XFirst),
            UpLimb::ideal(AxisOrder::YFirst),
        ];
        for order in [AxisOrder::XFirst, AxisOrder::YFirst] {
            v.push(UpLimb {
                axis_order: order,
                axis_skew_rad: 2e-4,
                axis_offset_mm: 0.05,
                twist_rad_per_mm: 1e-6,
                twist_reference_mm: 750.0,
            });
        }
        v
    }

    #[test]
    fn ideal_x_first_is_the_papers_eq_8() {
        let limb = UpLimb::ideal(AxisOrder::XFirst);
        let j = UpJoints {
            phi_rad: 0.3,
            theta_rad: -0.2,
            q4_mm: 800.0,
        };
        let pose = limb.pose(&j);
        let expected = rot(&Vector3::x(), 0.3) * rot(&Vector3::y(), -0.2);
        assert!((pose.rotation - expected).norm() < 1e-15);
        assert!((pose.position_mm - 800.0 * expected.column(2)).norm() < 1e-12);
        // J_theta of eq. 8: [1 0; 0 cos phi; 0 sin phi]
        assert!((pose.angle_axes[0] - Vector3::x()).norm() < 1e-15);
        assert!(
            (pose.angle_axes[1] - Vector3::new(0.0, 0.3f64.cos(), 0.3f64.sin())).norm() < 1e-15
        );
    }

    #[test]
    fn small_sin_cos_agrees_with_the_standard_library() {
        let mut worst: f64 = 0.0;
        for k in -20_000..=20_000 {
            let x = 0.9 * f64::from(k) / 20_000.0;
            let (s, c) = small_sin_cos(x);
            let (s0, c0) = x.sin_cos();
            worst = worst.max((s - s0).abs()).max((c - c0).abs());
        }
        assert!(worst < 4.0 * f64::EPSILON, "{worst:e}");
        assert_eq!(small_sin_cos(0.0), (0.0, 1.0));
    }

    #[test]
    fn inverse_round_trips_for_every_limb() {
        for limb in limbs() {
            for r in [
                Vector3::new(0.0, 0.0, 750.0),
                Vector3::new(300.0, -250.0, 650.0),
                Vector3::new(-400.0, 10.0, 850.0),
            ] {
                let j = limb.inverse(&r).unwrap();
                let back = limb.pose(&j).position_mm;
                assert!((back - r).norm() < 1e-9, "{limb:?} {r} -> {back}");
            }
        }
    }

    #[test]
    fn point_jacobian_matches_finite_differences() {
        for limb in limbs() {
            let j = UpJoints {
                phi_rad: 0.25,
                theta_rad: -0.35,
                q4_mm: 820.0,
            };
            let a = Vector3::new(60.0, -70.0, 5.0);
            let point = |j: &UpJoints| {
                let p = limb.pose(j);
                p.position_mm + p.rotation * a
            };
            let analytic = limb.pose(&j).point_jacobian(&point(&j));
            let x = j.to_array();
            for k in 0..3 {
                let h = if k == 2 { 1e-3 } else { 1e-6 };
                let mut plus = x;
                let mut minus = x;
                plus[k] += h;
                minus[k] -= h;
                let fd = (point(&UpJoints::from_array(plus)) - point(&UpJoints::from_array(minus)))
                    / (2.0 * h);
                let err = (fd - analytic.column(k)).norm() / fd.norm().max(1.0);
                assert!(err < 1e-7, "{limb:?} column {k}: {err}");
            }
        }
    }
}
