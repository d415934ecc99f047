//! The 2-DOF rotary head: forward kinematics to the tool tip and tool axis,
//! and the 5-DOF tool-pose inverse kinematics of the whole Tricept.
//!
//! The head is written in product-of-exponentials form in the platform frame
//! (see [`crate::description::HeadDescription`]). Head angles in every public function
//! are *commanded* angles, what a controller sends and `tricept tool-ik`
//! prints; the kinematic angle about each axis is the command plus the
//! head's `angle_offsets_rad` (zero on a nominal head). Because the platform orientation `R`
//! depends on where the platform is, a tool pose (tip + axis) cannot be
//! solved by first placing the platform and then the head: the tool-pose IK
//! solves the five unknowns `(phi, theta, q4, h1, h2)` jointly by a
//! Gauss-Newton iteration with an analytic Jacobian, seeded by a few
//! fixed-point rounds that use the closed-form head solution
//! ([`two_axis_pointing`], Paden-Kahan subproblem 2).

use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Unit, Vector3};

use crate::description::HeadDescription;
use crate::error::KinematicsError;
use crate::machine::Machine;
use crate::up_limb::UpJoints;

/// The head in solver form: unit axes, points on them, tool tip and axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Head {
    /// Unit direction of the first head axis (platform frame).
    pub axis1: Vector3<f64>,
    /// Point on the first axis, mm.
    pub axis1_point_mm: Vector3<f64>,
    /// Unit direction of the second head axis at `h1 = 0`.
    pub axis2: Vector3<f64>,
    /// Point on the second axis at `h1 = 0`, mm.
    pub axis2_point_mm: Vector3<f64>,
    /// Tool tip at zero head angles, mm.
    pub tool_tip_mm: Vector3<f64>,
    /// Unit tool axis at zero head angles.
    pub tool_direction: Vector3<f64>,
    /// Zero offsets of the head angles: kinematic = command + offset, rad.
    pub angle_offsets_rad: [f64; 2],
}

/// A tool pose: tip position and unit tool axis, in the base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPose {
    /// Tool tip, mm.
    pub tip_mm: Vector3<f64>,
    /// Unit tool axis.
    pub axis: Vector3<f64>,
}

/// Which of the (generically two) head solutions the tool-pose IK returns.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum HeadBranch {
    /// The solution with `h2 >= 0`.
    #[default]
    PositiveSecondAxis,
    /// The solution nearest (in angle) to the given head angles, rad.
    Nearest([f64; 2]),
}

/// Result of the 5-DOF tool-pose inverse kinematics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolIkSolution {
    /// Commands of the three actuated legs, mm.
    pub legs_mm: [f64; 3],
    /// The UP limb's joint values.
    pub up: UpJoints,
    /// Head angles `[h1, h2]`, rad.
    pub head_rad: [f64; 2],
    /// Platform point O', mm.
    pub platform_mm: Vector3<f64>,
    /// Gauss-Newton iterations used.
    pub iterations: u32,
    /// True at a head singularity (tool axis along the first head axis),
    /// where `h1` is arbitrary and was kept at its seed.
    pub head_singular: bool,
}

fn rot(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), angle).into_inner()
}

impl Head {
    /// Builds from a validated description (directions are normalised).
    pub fn from_description(d: &HeadDescription) -> Head {
        let v = Vector3::from;
        Head {
            axis1: v(d.axis1_direction).normalize(),
            axis1_point_mm: v(d.axis1_point_mm),
            axis2: v(d.axis2_direction).normalize(),
            axis2_point_mm: v(d.axis2_point_mm),
            tool_tip_mm: v(d.tool_tip_mm),
            tool_direction: v(d.tool_direction).normalize(),
            angle_offsets_rad: d.angle_offsets_rad,
        }
    }

    /// Back to the description form.
    pub fn to_description(&self) -> HeadDescription {
        let a = |v: &Vector3<f64>| [v.x, v.y, v.z];
        HeadDescription {
            axis1_direction: a(&self.axis1),
            axis1_point_mm: a(&self.axis1_point_mm),
            axis2_direction: a(&self.axis2),
            axis2_point_mm: a(&self.axis2_point_mm),
            tool_tip_mm: a(&self.tool_tip_mm),
            tool_direction: a(&self.tool_direction),
            angle_offsets_rad: self.angle_offsets_rad,
        }
    }

    /// Kinematic angles for commanded head angles `h` (rad): `h + offsets`.
    pub fn kinematic_angles(&self, h: [f64; 2]) -> [f64; 2] {
        [
            h[0] + self.angle_offsets_rad[0],
            h[1] + self.angle_offsets_rad[1],
        ]
    }

    /// Tool tip and axis in the platform frame at commanded head angles `h`
    /// (rad).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::Machine;
let mut head = Machine::paper().head;
let a = head.tool_in_platform([0.3, 0.2]);
// An angle zero offset of 0.01 rad: the command 0.29 reaches the same pose.
head.angle_offsets_rad = [0.01, 0.0];
let b = head.tool_in_platform([0.29, 0.2]);
assert!((a.tip_mm - b.tip_mm).norm() < 1e-12);
```
"#
    )]
    pub fn tool_in_platform(&self, h: [f64; 2]) -> ToolPose {
        self.tool_at_kinematic(self.kinematic_angles(h))
    }

    /// Where a point fixed to the spindle goes, in the platform frame, at
    /// commanded head angles `h` (rad); `point_mm` is the point at zero
    /// kinematic head angles (a tracker target or a ballbar ball mounted in
    /// the spindle: the tool tip plus its offset), mm.
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use tricept_kinematics::Machine;
let head = Machine::paper().head;
let h = [0.7, -0.4];
let p = head.spindle_point(h, &head.tool_tip_mm);
assert!((p - head.tool_in_platform(h).tip_mm).norm() < 1e-12);
```
"#
    )]
    pub fn spindle_point(&self, h: [f64; 2], point_mm: &Vector3<f64>) -> Vector3<f64> {
        let [h1, h2] = self.kinematic_angles(h);
        let r1 = rot(&self.axis1, h1);
        let r2 = rot(&self.axis2, h2);
        let p2 = self.axis2_point_mm + r2 * (point_mm - self.axis2_point_mm);
        self.axis1_point_mm + r1 * (p2 - self.axis1_point_mm)
    }

    /// Rotation of the spindle relative to the platform at commanded head
    /// angles `h` (rad): `Rot(axis1, h1) Rot(axis2, h2)` at the kinematic
    /// angles.
    pub fn spindle_rotation(&self, h: [f64; 2]) -> Matrix3<f64> {
        let [h1, h2] = self.kinematic_angles(h);
        rot(&self.axis1, h1) * rot(&self.axis2, h2)
    }

    /// Tool tip and axis in the platform frame at kinematic angles `h`.
    fn tool_at_kinematic(&self, h: [f64; 2]) -> ToolPose {
        let r1 = rot(&self.axis1, h[0]);
        let r2 = rot(&self.axis2, h[1]);
        let tip2 = self.axis2_point_mm + r2 * (self.tool_tip_mm - self.axis2_point_mm);
        let tip = self.axis1_point_mm + r1 * (tip2 - self.axis1_point_mm);
        ToolPose {
            tip_mm: tip,
            axis: r1 * r2 * self.tool_direction,
        }
    }
}

/// Paden-Kahan subproblem 2: the angles `(h1, h2)` with
/// `Rot(k1, h1) Rot(k2, h2) t = v` for unit vectors. Returns zero, one or two
/// solutions (none when `v` is out of the head's reach).
///
/// # Example
/// ```
/// use nalgebra::Vector3;
/// use tricept_kinematics::head::two_axis_pointing;
/// let (k1, k2, t) = (Vector3::z(), Vector3::x(), Vector3::z());
/// let v = Vector3::new(0.3, -0.4, 0.866).normalize();
/// for [h1, h2] in two_axis_pointing(&k1, &k2, &t, &v) {
///     let r = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(k1), h1)
///         * nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(k2), h2);
///     assert!((r * t - v).norm() < 1e-12);
/// }
/// ```
pub fn two_axis_pointing(
    k1: &Vector3<f64>,
    k2: &Vector3<f64>,
    t: &Vector3<f64>,
    v: &Vector3<f64>,
) -> Vec<[f64; 2]> {
    // The intermediate vector c = Rot(k2, h2) t = Rot(k1, -h1) v lies on
    // both cones: c.k2 = t.k2 and c.k1 = v.k1.
    let c12 = k1.dot(k2);
    let denom = c12 * c12 - 1.0;
    if denom.abs() < 1e-12 {
        return Vec::new();
    }
    let alpha = (c12 * k2.dot(t) - k1.dot(v)) / denom;
    let beta = (c12 * k1.dot(v) - k2.dot(t)) / denom;
    let n = k1.cross(k2);
    let gamma2 = (1.0 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c12) / n.norm_squared();
    if gamma2 < -1e-10 {
        return Vec::new();
    }
    let gamma = gamma2.max(0.0).sqrt();
    let signs: &[f64] = if gamma == 0.0 { &[1.0] } else { &[1.0, -1.0] };
    signs
        .iter()
        .map(|s| {
            let c = alpha * k1 + beta * k2 + s * gamma * n;
            [rotation_angle(k1, &c, v), rotation_angle(k2, t, &c)]
        })
        .collect()
}

/// Paden-Kahan subproblem 1: the angle turning `p` into `q` about unit `k`.
fn rotation_angle(k: &Vector3<f64>, p: &Vector3<f64>, q: &Vector3<f64>) -> f64 {
    let pp = p - k * k.dot(p);
    let qp = q - k * k.dot(q);
    k.dot(&pp.cross(&qp)).atan2(pp.dot(&qp))
}

fn wrap_angle(a: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let w = a.rem_euclid(two_pi);
    if w > std::f64::consts::PI {
        w - two_pi
    } else {
        w
    }
}

/// Scale turning unit-vector residuals into mm for the joint residual.
const AXIS_SCALE_MM: f64 = 100.0;
const TOOL_MAX_ITERATIONS: u32 = 40;
/// A tool pose reached to this residual (mm, the axis scaled by 100 mm) is
/// solved, whatever the last step was.
const TOOL_RESIDUAL_DONE_MM: f64 = 1e-11;

impl Machine {
    /// Tool tip and axis in the base frame with the UP limb at `up` and the
    /// head at commanded angles `h` (rad).
    pub fn tool_forward(&self, up: &UpJoints, h: [f64; 2]) -> ToolPose {
        let limb = self.up_limb.pose(up);
        let local = self.head.tool_in_platform(h);
        ToolPose {
            tip_mm: limb.position_mm + limb.rotation * local.tip_mm,
            axis: limb.rotation * local.axis,
        }
    }

    /// 5-DOF tool-pose inverse kinematics: tool tip (mm) and tool axis
    /// (any non-zero length) to leg commands and commanded head angles
    /// (kinematic angles minus the head's angle offsets).
    ///
    #[cfg_attr(
        any(doc, doctest),
        doc = r#"
# Example
```
use nalgebra::Vector3;
use tricept_kinematics::{head::HeadBranch, Machine};
let m = Machine::paper();
let tip = Vector3::new(150.0, 100.0, 1080.0);
let axis = Vector3::new(0.2, -0.1, 1.0);
let sol = m.tool_inverse(&tip, &axis, HeadBranch::default()).unwrap();
let back = m.tool_forward(&sol.up, sol.head_rad);
assert!((back.tip_mm - tip).norm() < 1e-9);
assert!((back.axis - axis.normalize()).norm() < 1e-12);
```
"#
    )]
    pub fn tool_inverse(
        &self,
        tip_mm: &Vector3<f64>,
        axis: &Vector3<f64>,
        branch: HeadBranch,
    ) -> Result<ToolIkSolution, KinematicsError> {
        for (what, v) in [
            ("tip x", tip_mm.x),
            ("tip y", tip_mm.y),
            ("tip z", tip_mm.z),
            ("axis x", axis.x),
            ("axis y", axis.y),
            ("axis z", axis.z),
        ] {
            if !v.is_finite() {
                return Err(KinematicsError::NotFinite { what, value: v });
            }
        }
        let n = axis.norm();
        if n < 1e-12 {
            return Err(KinematicsError::OutOfReach {
                reason: "the tool axis is the zero vector".into(),
            });
        }
        let d = axis / n;
        let (mut up, mut h, head_singular) = self.tool_seed(tip_mm, &d, branch)?;

        let finish = |up: UpJoints, h: [f64; 2], iterations: u32| {
            let offsets = self.head.angle_offsets_rad;
            let h = [wrap_angle(h[0] - offsets[0]), wrap_angle(h[1] - offsets[1])];
            let geometry = self.legs_at(&up);
            let legs_mm = self.commands_for(&geometry);
            self.check_limits(&legs_mm, &up, &geometry.limb.limb_axis)?;
            Ok(ToolIkSolution {
                legs_mm,
                up,
                head_rad: h,
                platform_mm: geometry.limb.position_mm,
                iterations,
                head_singular,
            })
        };
        for iteration in 1..=TOOL_MAX_ITERATIONS {
            let (residual, jac) = self.tool_residual(&up, h, tip_mm, &d);
            // Reached to rounding: near a head singularity the steps in h1
            // need not shrink while the pose is already exact.
            if residual.norm() <= TOOL_RESIDUAL_DONE_MM {
                return finish(up, h, iteration);
            }
            // Gauss-Newton with a tiny Levenberg term: at a head singularity
            // the h1 column vanishes and the damping keeps h1 at its seed.
            let jt = jac.transpose();
            let mut normal = jt * jac;
            let damping = 1e-14 * normal.trace().max(1.0);
            for k in 0..5 {
                normal[(k, k)] += damping;
            }
            let Some(chol) = normal.cholesky() else {
                return Err(KinematicsError::Singular {
                    condition: f64::INFINITY,
                    limit: crate::error::SINGULARITY_CONDITION_LIMIT,
                });
            };
            let step = -chol.solve(&(jt * residual));
            up.phi_rad += step[0];
            up.theta_rad += step[1];
            up.q4_mm += step[2];
            h[0] += step[3];
            h[1] += step[4];
            let size = step[2].abs()
                + up.q4_mm.abs() * (step[0].abs() + step[1].abs())
                + AXIS_SCALE_MM * (step[3].abs() + step[4].abs());
            if size < 1e-11 {
                let (residual, _) = self.tool_residual(&up, h, tip_mm, &d);
                if residual.norm() > 1e-8 {
                    return Err(KinematicsError::OutOfReach {
                        reason: format!(
                            "no head angles reach this tool axis (residual {:.3e})",
                            residual.norm()
                        ),
                    });
                }
                return finish(up, h, iteration);
            }
        }
        Err(KinematicsError::NotConverged {
            solver: "tool-pose inverse kinematics",
            iterations: TOOL_MAX_ITERATIONS,
            residual: self.tool_residual(&up, h, tip_mm, &d).0.norm(),
        })
    }

    /// Residual `[tip - p; 100 mm (axis - d)]` and its Jacobian with respect
    /// to `(phi, theta, q4, h1, h2)`, at kinematic head angles `h`.
    fn tool_residual(
        &self,
        up: &UpJoints,
        h: [f64; 2],
        tip_target: &Vector3<f64>,
        d: &Vector3<f64>,
    ) -> (SVector<f64, 6>, SMatrix<f64, 6, 5>) {
        let limb = self.up_limb.pose(up);
        let rot_p = limb.rotation;
        let r1 = rot(&self.head.axis1, h[0]);
        let local = self.head.tool_at_kinematic(h);
        let tip = limb.position_mm + rot_p * local.tip_mm;
        let axis = rot_p * local.axis;

        let mut res = SVector::<f64, 6>::zeros();
        res.fixed_rows_mut::<3>(0).copy_from(&(tip - tip_target));
        res.fixed_rows_mut::<3>(3)
            .copy_from(&(AXIS_SCALE_MM * (axis - d)));

        let mut jac = SMatrix::<f64, 6, 5>::zeros();
        jac.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&limb.point_jacobian(&tip));
        jac.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(AXIS_SCALE_MM * limb.direction_jacobian(&axis)));
        let k1 = rot_p * self.head.axis1;
        let p1 = limb.position_mm + rot_p * self.head.axis1_point_mm;
        let k2 = rot_p * r1 * self.head.axis2;
        let p2 = limb.position_mm
            + rot_p
                * (self.head.axis1_point_mm
                    + r1 * (self.head.axis2_point_mm - self.head.axis1_point_mm));
        jac.fixed_view_mut::<3, 1>(0, 3)
            .copy_from(&k1.cross(&(tip - p1)));
        jac.fixed_view_mut::<3, 1>(0, 4)
            .copy_from(&k2.cross(&(tip - p2)));
        jac.fixed_view_mut::<3, 1>(3, 3)
            .copy_from(&(AXIS_SCALE_MM * k1.cross(&axis)));
        jac.fixed_view_mut::<3, 1>(3, 4)
            .copy_from(&(AXIS_SCALE_MM * k2.cross(&axis)));
        (res, jac)
    }

    /// Seed for the tool-pose IK: three fixed-point rounds of "orientation
    /// from the platform point, head angles in closed form, platform point
    /// from the tip". Angles are kinematic throughout.
    fn tool_seed(
        &self,
        tip_mm: &Vector3<f64>,
        d: &Vector3<f64>,
        branch: HeadBranch,
    ) -> Result<(UpJoints, [f64; 2], bool), KinematicsError> {
        let reach = self.head.tool_tip_mm.norm();
        let mut r = tip_mm - reach * d;
        let mut h = [0.0, 0.0];
        let mut singular = false;
        let branch = match branch {
            HeadBranch::Nearest(h0) => HeadBranch::Nearest(self.head.kinematic_angles(h0)),
            b => b,
        };
        let reference = match branch {
            HeadBranch::Nearest(h0) => h0,
            HeadBranch::PositiveSecondAxis => [0.0, 0.0],
        };
        for _ in 0..3 {
            let up = self.up_limb.inverse(&r)?;
            let rot_p = self.up_limb.pose(&up).rotation;
            let local_d = rot_p.transpose() * d;
            let solutions = two_axis_pointing(
                &self.head.axis1,
                &self.head.axis2,
                &self.head.tool_direction,
                &local_d,
            );
            singular = self.head.axis1.cross(&local_d).norm() < 1e-9
                && self.head.axis1.cross(&self.head.tool_direction).norm() < 1e-9;
            let pick = match branch {
                HeadBranch::PositiveSecondAxis => solutions
                    .iter()
                    .copied()
                    .find(|s| s[1] >= 0.0)
                    .or_else(|| solutions.first().copied()),
                HeadBranch::Nearest(h0) => solutions.iter().copied().min_by(|a, b| {
                    let da = wrap_angle(a[0] - h0[0]).abs() + wrap_angle(a[1] - h0[1]).abs();
                    let db = wrap_angle(b[0] - h0[0]).abs() + wrap_angle(b[1] - h0[1]).abs();
                    da.total_cmp(&db)
                }),
            };
            let Some(mut sol) = pick else {
                return Err(KinematicsError::OutOfReach {
                    reason: "the head's two axes cannot point the tool along this axis".into(),
                });
            };
            if singular {
                sol[0] = reference[0];
            }
            h = sol;
            r = tip_mm - rot_p * self.head.tool_at_kinematic(h).tip_mm;
        }
        Ok((self.up_limb.inverse(&r)?, h, singular))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_jacobian_matches_finite_differences() {
        let m = Machine::paper();
        let up = UpJoints {
            phi_rad: 0.2,
            theta_rad: -0.15,
            q4_mm: 760.0,
        };
        let h = [0.4, -0.3];
        let target = Vector3::zeros();
        let d = Vector3::z();
        let (_, jac) = m.tool_residual(&up, h, &target, &d);
        let x0 = [up.phi_rad, up.theta_rad, up.q4_mm, h[0], h[1]];
        for k in 0..5 {
            let eps = if k == 2 { 1e-4 } else { 1e-7 };
            let eval = |s: f64| {
                let mut x = x0;
                x[k] += s;
                m.tool_residual(
                    &UpJoints::from_array([x[0], x[1], x[2]]),
                    [x[3], x[4]],
                    &target,
                    &d,
                )
                .0
            };
            let fd = (eval(eps) - eval(-eps)) / (2.0 * eps);
            let err = (fd - jac.column(k)).norm() / fd.norm().max(1.0);
            assert!(err < 1e-6, "column {k}: {err}");
        }
    }

    #[test]
    fn angle_offsets_turn_commands_into_kinematic_angles_both_ways() {
        let nominal = Machine::paper();
        let mut m = nominal.clone();
        m.head.angle_offsets_rad = [0.02, -0.015];
        let tip = Vector3::new(150.0, 100.0, 1080.0);
        let axis = Vector3::new(0.2, -0.1, 1.0);
        let a = nominal
            .tool_inverse(&tip, &axis, HeadBranch::default())
            .unwrap();
        let b = m.tool_inverse(&tip, &axis, HeadBranch::default()).unwrap();
        // Same kinematic angles, commands shifted by the offsets.
        assert!((a.head_rad[0] - (b.head_rad[0] + 0.02)).abs() < 1e-12);
        assert!((a.head_rad[1] - (b.head_rad[1] - 0.015)).abs() < 1e-12);
        assert!((a.legs_mm[0] - b.legs_mm[0]).abs() < 1e-9);
        let back = m.tool_forward(&b.up, b.head_rad);
        assert!((back.tip_mm - tip).norm() < 1e-9);
        // The nearest branch is chosen in commanded angles too.
        let c = m
            .tool_inverse(&tip, &axis, HeadBranch::Nearest(b.head_rad))
            .unwrap();
        assert!((c.head_rad[0] - b.head_rad[0]).abs() < 1e-9);
    }

    #[test]
    fn vertical_tool_at_the_centre_is_a_head_singularity_not_a_failure() {
        let m = Machine::paper();
        let tip = Vector3::new(0.0, 0.0, 1100.0);
        let sol = m
            .tool_inverse(&tip, &Vector3::z(), HeadBranch::default())
            .unwrap();
        assert!(sol.head_singular);
        let back = m.tool_forward(&sol.up, sol.head_rad);
        assert!((back.tip_mm - tip).norm() < 1e-9);
    }
}
