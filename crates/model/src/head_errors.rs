//! The error parameters of the 2-DOF head: a minimal set of 13 that moves a
//! nominal head ([`tricept_kinematics::head::Head`]) into any nearby actual one,
//! with an exact map (parameters to head) and the analytic Jacobian of any
//! point fixed to the spindle.
//!
//! The parameters are named in frames taken once from the *nominal* head
//! (unit axes `k1`, `k2`, tool direction `d`):
//!
//! ```text
//! n  = unit(k1 x k2)            common normal of the two axes
//! a1 = n x k1,  a2 = n x k2     the second normal to each axis
//! e  = unit(k2 - (k2.d) d)      tool frame: e, w = d x e
//! ```
//!
//! (default A/C head: `n = y'`, `a1 = x'`, `a2 = -z'`, `e = x'`, `w = y'`).
//!
//! | # | name | unit | applied to the nominal head |
//! |---|---|---|---|
//! | 0 | `ax1_tilt_a_rad` | rad | `k1 = unit(k1 + t0 a1 + t1 n)` |
//! | 1 | `ax1_tilt_n_rad` | rad | (the second tangent coordinate of the same) |
//! | 2 | `ax1_shift_a_mm` | mm | `p1 += s a1` |
//! | 3 | `ax1_shift_n_mm` | mm | `p1 += s n` |
//! | 4 | `ax2_tilt_a_rad` | rad | `k2 = unit(k2 + t a2)` (squareness of the axes) |
//! | 5 | `ax2_shift_a_mm` | mm | `p2 += s a2` |
//! | 6 | `ax2_shift_n_mm` | mm | `p2 += s n` (the axes' offset along their normal) |
//! | 7 | `h1_zero_rad` | rad | kinematic `h1` = command + value |
//! | 8 | `h2_zero_rad` | rad | kinematic `h2` = command + value |
//! | 9 | `tool_length_mm` | mm | `t += L d` |
//! | 10 | `tool_shift_e_mm` | mm | `t += s e` |
//! | 11 | `tool_shift_w_mm` | mm | `t += s w` |
//! | 12 | `tool_tilt_e_rad` | rad | `d = unit(d + t e)` |
//!
//! **Why 13, and why these.** A point moved along its own axis changes
//! nothing, so axis points shift only across their axis. Turning everything
//! after joint 1 about line 1 *is* a zero offset of `h1`; its component on
//! "`k2` tilts along `n`" is `|k1 x k2| != 0`, so that coordinate is left
//! out. Turning the tool about line 2 *is* a zero offset of `h2`; its
//! component on "`d` tilts along `w`" is `|k2 x d| != 0`, so that one is left
//! out too. 15 raw coordinates minus these two redundancies leave 13, the
//! count of a 2R chain on a known base less the tool's roll.
//!
//! **What a point measurement can see.** The tool tilt moves no point on the
//! tool axis' zero extension; a zero offset of `h2` moves the tool tip by
//! `k2 x (t - p2)` times the offset, a constant vector in the spindle frame,
//! i.e. exactly a tool-tip shift. So tip positions see at most 11 of the 13,
//! and a tracker target whose offset from the tip is unknown hides the whole
//! tool tip (8 left). Two known effector extensions along the tool make the
//! tilt and `h2`'s zero visible.
//!
//! Directions are tangent-plane coordinates (`k = unit(k_nom + t u)`), an
//! exact chart with a closed-form Jacobian, so the analytic Jacobian equals
//! central differences at any parameter values (tested in
//! `tests/head_errors.rs`).

use nalgebra::{Matrix3, Rotation3, SMatrix, Unit, Vector3};
use serde_json::{Map, Value};
use tricept_kinematics::head::Head;

use crate::error::ModelError;
use crate::params::{values_from_named_map, values_to_named_map};

/// Number of head parameters.
pub const N_HEAD: usize = 13;

/// Names of the head parameters, in order (units in the names).
pub const HEAD13_NAMES: [&str; N_HEAD] = [
    "ax1_tilt_a_rad",
    "ax1_tilt_n_rad",
    "ax1_shift_a_mm",
    "ax1_shift_n_mm",
    "ax2_tilt_a_rad",
    "ax2_shift_a_mm",
    "ax2_shift_n_mm",
    "h1_zero_rad",
    "h2_zero_rad",
    "tool_length_mm",
    "tool_shift_e_mm",
    "tool_shift_w_mm",
    "tool_tilt_e_rad",
];

/// Typical sizes of the head errors of a machine as built, in the
/// parameters' units: 0.3 mrad axis tilts, 0.1 mm axis shifts, 0.5 mrad
/// angle zeros, 0.3 mm tool length (a presetter's repeatability on a tool
/// change is far better; an unmeasured tool is worse), 0.05 mm tool-tip
/// shifts, 0.3 mrad tool tilt. Used as prior standard deviations by
/// planning and as magnitudes of simulated heads.
pub const TYPICAL_HEAD_ERRORS: [f64; N_HEAD] = [
    3e-4, 3e-4, 0.1, 0.1, 3e-4, 0.1, 0.1, 5e-4, 5e-4, 0.3, 0.05, 0.05, 3e-4,
];

/// What is mounted in the spindle and measured: a point fixed to the
/// spindle, `extension_mm` along the tool axis beyond the tool tip and then
/// `offset_mm` (platform frame at zero head angles). The tool tip itself is
/// `Effector::default()`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Effector {
    /// Known extension along the tool axis, mm (e.g. a 100 mm SMR extension).
    pub extension_mm: f64,
    /// Offset of the measured point, mm, in the spindle frame at zero head
    /// angles (a tracker target's unknown offset, a ball's known one).
    pub offset_mm: Vector3<f64>,
}

/// The frames that name the parameters, from the nominal head.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Frames {
    n: Vector3<f64>,
    a1: Vector3<f64>,
    a2: Vector3<f64>,
    e: Vector3<f64>,
    w: Vector3<f64>,
}

/// Any unit vector perpendicular to `v` (unit).
fn perpendicular(v: &Vector3<f64>) -> Vector3<f64> {
    let trial = if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (trial - v * v.dot(&trial)).normalize()
}

impl Frames {
    fn of(head: &Head) -> Frames {
        let (k1, k2, d) = (head.axis1, head.axis2, head.tool_direction);
        // A validated description has non-parallel axes and a tool off axis
        // 2; a hand-built degenerate head still gets a frame (no panic),
        // though then the 13 coordinates are no longer minimal.
        let n = match k1.cross(&k2).try_normalize(1e-12) {
            Some(n) => n,
            None => perpendicular(&k1),
        };
        let e = match (k2 - d * k2.dot(&d)).try_normalize(1e-12) {
            Some(e) => e,
            None => perpendicular(&d),
        };
        Frames {
            n,
            a1: n.cross(&k1),
            a2: n.cross(&k2),
            e,
            w: d.cross(&e),
        }
    }
}

/// The 13 head error parameters of a nominal head (see the module docs).
///
/// # Example
/// ```
/// use tricept_kinematics::Machine;
/// use tricept_model::head_errors::HeadParameterSet;
/// let nominal = Machine::paper().head;
/// let set = HeadParameterSet::head13(&nominal);
/// let mut p = vec![0.0; 13];
/// p[set.index_of("tool_length_mm").unwrap()] = 0.25;
/// let actual = set.head_at(&p);
/// // The default head's tool points along z': the tip moves 0.25 mm along z'.
/// assert!((actual.tool_tip_mm.z - nominal.tool_tip_mm.z - 0.25).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct HeadParameterSet {
    nominal: Head,
    frames: Frames,
    names: Vec<String>,
}

/// Direction `unit(base + t u)` and its derivative with respect to `t`.
fn tangent_unit(base: &Vector3<f64>, u: &Vector3<f64>, t: f64) -> (Vector3<f64>, Vector3<f64>) {
    let v = base + u * t;
    let norm = v.norm();
    let k = v / norm;
    (k, (u - k * k.dot(u)) / norm)
}

fn rot(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), angle).into_inner()
}

/// Derivative of `Rot(k, angle) x` with respect to the axis vector `k`, in
/// direction `dk` (Rodrigues' formula differentiated).
fn rotation_axis_derivative(
    k: &Vector3<f64>,
    angle: f64,
    x: &Vector3<f64>,
    dk: &Vector3<f64>,
) -> Vector3<f64> {
    let (s, c) = angle.sin_cos();
    dk.cross(x) * s + (dk * k.dot(x) + k * dk.dot(x)) * (1.0 - c)
}

impl HeadParameterSet {
    /// The 13 parameters of `nominal` (frames fixed from it).
    pub fn head13(nominal: &Head) -> HeadParameterSet {
        HeadParameterSet {
            nominal: nominal.clone(),
            frames: Frames::of(nominal),
            names: HEAD13_NAMES.iter().map(|s| s.to_string()).collect(),
        }
    }

    /// The nominal head.
    pub fn nominal(&self) -> &Head {
        &self.nominal
    }

    /// Parameter names, in order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Number of parameters (13).
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Never empty.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Index of a parameter by name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The actual head for parameter values `p` (exact; a slice shorter
    /// than 13 is padded with zeros, longer values are ignored).
    pub fn head_at(&self, p: &[f64]) -> Head {
        self.at(p).head
    }

    /// The head at parameter values `p` with what its point Jacobians need.
    pub fn at(&self, p: &[f64]) -> HeadAt {
        let v = |j: usize| p.get(j).copied().unwrap_or(0.0);
        let f = &self.frames;
        let h = &self.nominal;
        let base1 = h.axis1 + f.n * v(1);
        let (axis1, dk1_a) = tangent_unit(&base1, &f.a1, v(0));
        let base1 = h.axis1 + f.a1 * v(0);
        let (_, dk1_n) = tangent_unit(&base1, &f.n, v(1));
        let (axis2, dk2) = tangent_unit(&h.axis2, &f.a2, v(4));
        let (tool_direction, dd) = tangent_unit(&h.tool_direction, &f.e, v(12));
        let head = Head {
            axis1,
            axis1_point_mm: h.axis1_point_mm + f.a1 * v(2) + f.n * v(3),
            axis2,
            axis2_point_mm: h.axis2_point_mm + f.a2 * v(5) + f.n * v(6),
            tool_tip_mm: h.tool_tip_mm + h.tool_direction * v(9) + f.e * v(10) + f.w * v(11),
            tool_direction,
            angle_offsets_rad: [h.angle_offsets_rad[0] + v(7), h.angle_offsets_rad[1] + v(8)],
        };
        HeadAt {
            head,
            dk1: [dk1_a, dk1_n],
            dk2,
            dd,
            frames: self.frames,
            nominal_direction: h.tool_direction,
        }
    }

    /// The first-order change of the parameters when the whole head is
    /// scaled by `1 + g` about the platform's origin O', per unit `g`: axis
    /// points and tool tip grow, directions and zeros do not (a component
    /// of a point along its own axis is no change at all).
    ///
    /// # Example
    /// ```
    /// use tricept_model::head_errors::HeadParameterSet;
    /// let set = HeadParameterSet::head13(&tricept_kinematics::Machine::paper().head);
    /// let v = set.scale_direction();
    /// // Default head: A axis 150 mm out along z' (= -a2), tool tip 350 mm along z'.
    /// assert_eq!(v[set.index_of("ax2_shift_a_mm").unwrap()], -150.0);
    /// assert_eq!(v[set.index_of("tool_length_mm").unwrap()], 350.0);
    /// ```
    pub fn scale_direction(&self) -> Vec<f64> {
        let f = &self.frames;
        let h = &self.nominal;
        let (p1, p2, t) = (h.axis1_point_mm, h.axis2_point_mm, h.tool_tip_mm);
        let mut v = vec![0.0; N_HEAD];
        v[2] = p1.dot(&f.a1);
        v[3] = p1.dot(&f.n);
        v[5] = p2.dot(&f.a2);
        v[6] = p2.dot(&f.n);
        v[9] = t.dot(&h.tool_direction);
        v[10] = t.dot(&f.e);
        v[11] = t.dot(&f.w);
        v
    }

    /// Parses a JSON object `{name: value}` of head parameters (units in
    /// the names); missing names are zero.
    ///
    /// # Example
    /// ```
    /// use tricept_model::head_errors::HeadParameterSet;
    /// let set = HeadParameterSet::head13(&tricept_kinematics::Machine::paper().head);
    /// let p = set.parse_values(r#"{"h1_zero_rad": 5e-4}"#).unwrap();
    /// assert_eq!(p[7], 5e-4);
    /// assert!(set.parse_values(r#"{"dq1": 1}"#).is_err());
    /// ```
    pub fn parse_values(&self, json: &str) -> Result<Vec<f64>, ModelError> {
        let map = crate::params::parse_object(
            json,
            "expected a JSON object of head parameter name -> value",
        )?;
        values_from_named_map(&self.names, "head13", &map)
    }

    /// Values as a JSON map in the set's order.
    pub fn values_to_map(&self, p: &[f64]) -> Map<String, Value> {
        values_to_named_map(&self.names, p)
    }
}

/// A head at fixed parameter values, with the derivatives of its directions
/// (see [`HeadParameterSet::at`]).
#[derive(Debug, Clone, PartialEq)]
pub struct HeadAt {
    head: Head,
    dk1: [Vector3<f64>; 2],
    dk2: Vector3<f64>,
    dd: Vector3<f64>,
    frames: Frames,
    nominal_direction: Vector3<f64>,
}

/// Jacobian of a spindle point (platform frame) with respect to the 13
/// head parameters, mm per parameter unit.
pub type HeadJacobian = SMatrix<f64, 3, N_HEAD>;

impl HeadAt {
    /// The actual head.
    pub fn head(&self) -> &Head {
        &self.head
    }

    /// The point of `effector` at commanded head angles `h` (rad), in the
    /// platform frame (mm), and its derivatives with respect to the 13
    /// parameters.
    ///
    /// # Example
    /// ```
    /// use tricept_model::{head_errors::Effector, head_errors::HeadParameterSet};
    /// let nominal = tricept_kinematics::Machine::paper().head;
    /// let set = HeadParameterSet::head13(&nominal);
    /// let (p, jac) = set.at(&[0.0; 13]).point_jacobian([0.4, 0.3], &Effector::default());
    /// assert!((p - nominal.tool_in_platform([0.4, 0.3]).tip_mm).norm() < 1e-12);
    /// // The tool tilt moves no point on the tool axis' zero extension.
    /// assert!(jac.column(12).norm() < 1e-12);
    /// ```
    pub fn point_jacobian(&self, h: [f64; 2], effector: &Effector) -> (Vector3<f64>, HeadJacobian) {
        let head = &self.head;
        let f = &self.frames;
        let [h1, h2] = head.kinematic_angles(h);
        let (k1, k2) = (head.axis1, head.axis2);
        let (p1, p2) = (head.axis1_point_mm, head.axis2_point_mm);
        let r1 = rot(&k1, h1);
        let r2 = rot(&k2, h2);
        let tool =
            head.tool_tip_mm + head.tool_direction * effector.extension_mm + effector.offset_mm;
        let v = tool - p2;
        let r2v = r2 * v;
        let w2 = p2 + r2v;
        let point = p1 + r1 * (w2 - p1);
        let r12 = r1 * r2;
        let mut jac = HeadJacobian::zeros();
        let mut set = |j: usize, c: Vector3<f64>| jac.set_column(j, &c);
        for (j, dk) in self.dk1.iter().enumerate() {
            set(j, rotation_axis_derivative(&k1, h1, &(w2 - p1), dk));
        }
        set(2, f.a1 - r1 * f.a1);
        set(3, f.n - r1 * f.n);
        set(4, r1 * rotation_axis_derivative(&k2, h2, &v, &self.dk2));
        set(5, r1 * (f.a2 - r2 * f.a2));
        set(6, r1 * (f.n - r2 * f.n));
        set(7, k1.cross(&(point - p1)));
        set(8, r1 * k2.cross(&r2v));
        set(9, r12 * self.nominal_direction);
        set(10, r12 * f.e);
        set(11, r12 * f.w);
        set(12, r12 * self.dd * effector.extension_mm);
        (point, jac)
    }

    /// Rotation of the spindle relative to the platform at commanded head
    /// angles `h` (what a target offset turns with).
    pub fn spindle_rotation(&self, h: [f64; 2]) -> Matrix3<f64> {
        self.head.spindle_rotation(h)
    }
}
